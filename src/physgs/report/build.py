"""Collect per-job result files into the tables and figures (what the report rules call).

File layout (shared with workflow/rules/*.smk through these templates, relative to the
working directory): evaluation of a (tree, model, config) job in ``EVAL`` / ``TRAJ`` /
``PANELS``, recovery of ours in ``RECOVERY`` and the null control in ``NULL``.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from physgs.evaluate.splits import load_eval
from physgs.evaluate.trajectories import load_trajectories
from physgs.recovery.record import load_null, load_recovery
from physgs.report import figures, tables

EVAL = "results/eval/{tree}/{model}_{config}.npz"
TRAJ = "results/eval/{tree}/{model}_{config}.traj.npz"
PANELS = "results/eval/{tree}/{model}_{config}.panels.npz"
RECOVERY = "results/recovery/{tree}/ours_{config}.json"
NULL = "results/recovery/{tree}/null_{config}.json"

TABLES = ("tab_psnr", "tab_null", "tab_transfer", "tab_margin")
FIGURES = ("fig_temporal", "fig_teaser", "fig_results", "fig_damping")
# which models each output needs (all `single`); tab_null and fig_damping need ours' recovery
NEEDS_MODELS = {
    "tab_psnr": tables.MODELS, "tab_transfer": tables.MODELS,
    "tab_margin": ("mlp_wind", "ours"), "fig_temporal": tables.MODELS,
    "fig_teaser": tables.MODELS, "fig_results": tables.MODELS,
}


def _eval_paths(name: str, trees: Sequence[str]) -> list[str]:
    models = NEEDS_MODELS.get(name, ())
    return [EVAL.format(tree=t, model=m, config="single") for t in trees for m in models]


def inputs_for(name: str, trees: Sequence[str], configs: Sequence[str]) -> list[str]:
    """The files one table or figure reads: exactly what its rule must declare as input."""
    files = _eval_paths(name, trees)
    if name == "fig_teaser":
        files += [TRAJ.format(tree=t, model=m, config="single") for t in trees for m in tables.MODELS]
    if name == "fig_results":
        files += [PANELS.format(tree=t, model=m, config="single") for t in trees for m in tables.MODELS]
    if name in ("tab_null", "fig_damping"):
        files += [RECOVERY.format(tree=t, config=c) for t in trees for c in configs]
    if name == "tab_null":
        files += [NULL.format(tree=t, config=c) for t in trees for c in configs]
    return files


def _summaries(trees, models):
    return {(t, m): load_eval(EVAL.format(tree=t, model=m, config="single")).summary()
            for t in trees for m in models}


def make_table(name: str, cfg: dict, tex_path, csv_path) -> tables.Table:
    """Build table ``name`` from the result files and write its .tex and .csv."""
    trees, configs = cfg["trees"], list(cfg["models"]["configs"])
    bones = {t: int(cfg["presets"][t]["bones"]) for t in trees}
    conditions = cfg["testbed"]["conditions"]
    if name == "tab_psnr":
        table = tables.tab_psnr(_summaries(trees, tables.MODELS), trees, bones)
    elif name == "tab_transfer":
        table = tables.tab_transfer(_summaries(trees, tables.MODELS), trees, bones, conditions)
    elif name == "tab_margin":
        table = tables.tab_margin(_summaries(trees, ("mlp_wind", "ours")), trees, bones, conditions)
    elif name == "tab_null":
        rec = {(t, c): load_recovery(RECOVERY.format(tree=t, config=c)) for t in trees for c in configs}
        null = {(t, c): load_null(NULL.format(tree=t, config=c)) for t in trees for c in configs}
        table = tables.tab_null(rec, null, trees, bones, configs)
    else:
        raise ValueError(f"unknown table '{name}'; choose one of {TABLES}")
    tables.write_table(table, tex_path, csv_path)
    return table


def _teaser_tree(trees: Sequence[str]) -> str:
    """The tree the teaser shows: medium if built (the paper's clearest case), else the last."""
    return "medium" if "medium" in trees else trees[-1]


def make_figure(name: str, cfg: dict, outputs: Sequence[str]) -> None:
    """Build figure ``name`` from the result files, written to every path in ``outputs``."""
    trees, configs = cfg["trees"], list(cfg["models"]["configs"])
    if name == "fig_temporal":
        evals = {(t, m): load_eval(EVAL.format(tree=t, model=m, config="single"))
                 for t in trees for m in tables.MODELS}
        curves = {k: e.temporal_psnr for k, e in evals.items()}
        figures.fig_temporal(curves, trees, int(cfg["testbed"]["n_train"]), outputs)
    elif name == "fig_teaser":
        t = _teaser_tree(trees)
        summ = {m: load_eval(EVAL.format(tree=t, model=m, config="single")).summary()
                for m in tables.MODELS}
        base = figures.best_baseline(summ, key="time")
        shown = ("ours", base)
        traj = {m: load_trajectories(TRAJ.format(tree=t, model=m, config="single")) for m in shown}
        cen = {m: load_eval(EVAL.format(tree=t, model=m, config="single")).centroid_err
               for m in shown}
        figures.fig_teaser(traj, cen, cfg["testbed"]["conditions"], outputs, title=f"{t} tree")
    elif name == "fig_results":
        rows, images = [], {}
        for t in trees:
            panels = {m: np.load(PANELS.format(tree=t, model=m, config="single")) for m in tables.MODELS}
            for split in ("time", "view", "wind"):
                row = f"{t}: unseen {split}"
                rows.append(row)
                images[(row, "gt")] = (panels["ours"][f"{split}_gt"], None)
                for m in tables.MODELS:
                    images[(row, m)] = (panels[m][f"{split}_pred"], float(panels[m][f"{split}_psnr"]))
        figures.fig_results(rows, ["gt", *tables.MODELS], images, outputs)
    elif name == "fig_damping":
        damping = {(t, c): load_recovery(RECOVERY.format(tree=t, config=c)).damping
                   for t in trees for c in configs}
        figures.fig_damping(damping, trees, configs, float(cfg["testbed"]["zeta"]), outputs)
    else:
        raise ValueError(f"unknown figure '{name}'; choose one of {FIGURES}")
