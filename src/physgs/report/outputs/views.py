"""The outputs that score rendered images: tab_psnr, tab_fit, tab_transfer, tab_margin,
fig_temporal, fig_teaser and fig_results. Each reads the evaluations of the models of its roles,
trained in the base configuration."""

from __future__ import annotations

from typing import Sequence

import numpy as np
import pandas as pd

from physgs.evaluate.splits import load_eval
from physgs.evaluate.trajectories import load_trajectories
from physgs.experiments.recipe import heldout_split
from physgs.models.registry import BASE_CONFIG, BLIND_CONFIG, blind_priors, models_of
from physgs.report import paper, tables
from physgs.report.claim_cells import roles_of
from physgs.report.outputs.base import Columns, Output

#: the roles of the methods compared on images, and of the references shown beside them
METHODS = ("control", "field", "prior")
REFERENCES = ("reference",)
#: tab_margin: the wind-conditioned field every prior's margin is taken against
MARGIN_BASELINE = "mlp_wind"


def _evals(kinds: Sequence[str], roles: Sequence[str]):
    """needs(plan, seeds): ``kinds`` of every model of ``roles`` on every tree, per seed."""

    def needs(plan, seeds):
        return [
            (k, t, m, BASE_CONFIG, s)
            for s in seeds
            for k in kinds
            for t in plan.trees
            for m in models_of(*roles)
        ]

    return needs


def _conditions(cfg: dict) -> dict:
    return {"conditions": [float(c) for c in cfg["testbed"]["conditions"]]}


def _teaser_settings(cfg: dict) -> dict:
    """The conditions, and the trees' roles: the teaser shows the tree standing for the paper's."""
    return {**_conditions(cfg), "roles": roles_of(cfg["presets"], cfg["trees"])}


def summaries(path, trees, models, seeds) -> dict:
    """{seed: {(tree, model): summary}} of the models trained in the base configuration.

    Args:
        path (Callable[..., str]): the need -> file function of
            [`reader`][physgs.report.outputs.base.reader].
        trees (Sequence[str]): the trees.
        models (Sequence[str]): the models.
        seeds (Sequence[int]): the training seeds.

    Returns:
        ``{seed: {(tree, model): summary}}``, each summary split -> mean (dB; centroid errors px).
    """
    return {
        s: {
            (t, m): load_eval(path("eval", t, m, BASE_CONFIG, s)).summary()
            for t in trees
            for m in models
        }
        for s in seeds
    }


def fit_row(eval_path, loss_path, n_train: int, holdout_every: int) -> dict:
    """One tab_fit row from a model's evaluation and loss log: fit and held-out-frame PSNR (dB,
    training camera and wind, frames < n_train), view and time PSNR (dB), training seconds and
    iterations used (NaN without a loss log).

    Args:
        eval_path (str | Path): the model's evaluation ``.npz``.
        loss_path (str | Path | None): its loss log CSV (its last ``seconds``), or None.
        n_train: training-window length, frames.
        holdout_every: the held-out stride (0: no held-out frames, ``heldout`` NaN).

    Returns:
        ``fit``, ``heldout``, ``view``, ``time`` (dB), ``train_s`` (s) and ``iterations``.
    """
    ev = load_eval(eval_path)
    cam = np.asarray(ev.camera_psnr[0, :n_train], dtype=np.float64)  # [n_train] dB
    if holdout_every:
        trained, held = heldout_split(n_train, holdout_every)
    else:
        trained, held = np.arange(n_train), np.arange(0)
    s = ev.summary()
    log = (
        pd.read_csv(loss_path, usecols=["iteration", "seconds"])
        if loss_path is not None
        else pd.DataFrame({"iteration": [np.nan], "seconds": [np.nan]})
    )
    return {
        "fit": float(cam[trained].mean()),
        "heldout": float(cam[held].mean()) if held.size else float("nan"),
        "view": s["view"],
        "time": s["time"],
        "train_s": float(log["seconds"].iloc[-1]),
        "iterations": float(log["iteration"].iloc[-1]) + 1,
    }


def fit_settings(cfg: dict) -> dict:
    """What ``fit_row`` reads: the training window's length and its held-out stride.

    Args:
        cfg: the resolved config.

    Returns:
        ``n_train`` and ``holdout_every``.
    """
    return {
        "n_train": int(cfg["testbed"]["n_train"]),
        "holdout_every": int(cfg["train"]["holdout_every"]),
    }


# ---- tables --------------------------------------------------------------------------------
def _tab_psnr(path, settings, inputs, out):
    seeds = settings["seeds"]
    return tables.tab_psnr(
        summaries(path, settings["trees"], models_of(*METHODS, *REFERENCES), seeds),
        settings["trees"],
        settings["bones"],
        models=models_of(*METHODS),
        digits=settings["digits"],
        references=models_of(*REFERENCES),
    )


def _fit_needs(plan, seeds):
    """tab_fit's: every method's and reference's evaluation and loss log, and the forcing-free
    priors' (``plan.blind``, trained in ``BLIND_CONFIG``)."""
    blind = [
        (k, t, m, BLIND_CONFIG, s)
        for s in seeds
        for k in ("eval", "loss")
        for t in plan.trees
        for m in plan.blind
    ]
    return _evals(("eval", "loss"), METHODS + REFERENCES)(plan, seeds) + blind


def _fit_table_settings(cfg: dict) -> dict:
    return {**fit_settings(cfg), "blind": list(blind_priors(cfg["models"]["configs"]))}


def _tab_fit(path, settings, inputs, out):
    n, every = int(settings["n_train"]), int(settings["holdout_every"])
    config = {m: BASE_CONFIG for m in models_of(*METHODS, *REFERENCES)}
    config.update({m: BLIND_CONFIG for m in settings.get("blind", [])})
    rows = {
        s: {
            (t, m): fit_row(path("eval", t, m, c, s), path("loss", t, m, c, s), n, every)
            for t in settings["trees"]
            for m, c in config.items()
        }
        for s in settings["seeds"]
    }
    return tables.tab_fit(
        rows,
        settings["trees"],
        settings["bones"],
        (*models_of(*METHODS), *settings.get("blind", [])),
        models_of(*REFERENCES)[0],
        digits=settings["digits"],
        holdout_every=every,
    )


def _tab_transfer(path, settings, inputs, out):
    return tables.tab_transfer(
        summaries(path, settings["trees"], models_of(*METHODS), settings["seeds"]),
        settings["trees"],
        settings["bones"],
        settings["conditions"],
        models=models_of(*METHODS),
        digits=settings["digits"],
    )


def _margin_models() -> tuple[str, ...]:
    return (MARGIN_BASELINE, *models_of("prior"))


def _tab_margin(path, settings, inputs, out):
    return tables.tab_margin(
        summaries(path, settings["trees"], _margin_models(), settings["seeds"]),
        settings["trees"],
        settings["bones"],
        settings["conditions"],
        priors=models_of("prior"),
        baseline=MARGIN_BASELINE,
        digits=settings["digits"],
    )


#: tab_psnr's CSV: one row per model id (a difference row: ``<prior>-static``,
#: ``<prior>-best_field``), two columns per tree
PSNR_COLUMNS = Columns(
    keys=("seed", "model"), values=("{tree}_view", "{tree}_time"), about=("reference", "difference")
)

TAB_PSNR = Output(
    "tab_psnr",
    "table",
    _evals(("eval",), METHODS + REFERENCES),
    _tab_psnr,
    columns=PSNR_COLUMNS,
)
FIT_COLUMNS = Columns(
    keys=("seed", "tree", "model"),
    values=(
        "fit_psnr_db",
        "heldout_psnr_db",
        "ceiling_frac",
        "heldout_ceiling_frac",
        "view_psnr_db",
        "time_psnr_db",
        "iterations",
    ),
    timing=("train_s",),
    about=("bones", "reference"),
)

TAB_FIT = Output(
    "tab_fit",
    "table",
    _fit_needs,
    _tab_fit,
    settings=_fit_table_settings,
    columns=FIT_COLUMNS,
)
#: tab_transfer's CSV: one column per model id; the wind (``condition``) is a numeric key
TRANSFER_COLUMNS = Columns(
    keys=("seed", "split", "tree", "condition"), values=("{model}",), about=("bones",)
)

TAB_TRANSFER = Output(
    "tab_transfer",
    "table",
    _evals(("eval",), METHODS),
    _tab_transfer,
    settings=_conditions,
    columns=TRANSFER_COLUMNS,
)
MARGIN_COLUMNS = Columns(
    keys=("seed", "model", "tree"), values=("margin_{wind}",), about=("bones",)
)

TAB_MARGIN = Output(
    "tab_margin",
    "table",
    lambda plan, seeds: [
        ("eval", t, m, BASE_CONFIG, s) for s in seeds for t in plan.trees for m in _margin_models()
    ],
    _tab_margin,
    settings=_conditions,
    columns=MARGIN_COLUMNS,
)


# ---- figures -------------------------------------------------------------------------------
def teaser_tree(trees: Sequence[str], roles: dict | None = None) -> str:
    """The tree the teaser shows: the one whose preset stands for the paper's teaser tree
    (``paper.TEASER_TREE``, its clearest case) if built, else the last.

    Args:
        trees: the trees built.
        roles: tree -> its preset's role (``claim_cells.roles_of``); None: none declared.

    Returns:
        The tree's name.
    """
    stand_in = [t for t in trees if ((roles or {}).get(t) or {}).get("paper") == paper.TEASER_TREE]
    return stand_in[0] if stand_in else trees[-1]


def _fig_temporal(path, settings, inputs, out):
    from physgs.report import figures  # matplotlib: not for the workflow's planning imports

    curves = {
        (t, m): np.stack(
            [load_eval(path("eval", t, m, BASE_CONFIG, s)).temporal_psnr for s in settings["seeds"]]
        )
        for t in settings["trees"]
        for m in models_of(*METHODS, *REFERENCES)
    }
    figures.fig_temporal(curves, settings["trees"], int(settings["n_train"]), out)


def _fig_teaser(path, settings, inputs, out):
    from physgs.report import figures

    t, s0 = teaser_tree(settings["trees"], settings.get("roles")), settings["seeds"][0]
    evals = {m: load_eval(path("eval", t, m, BASE_CONFIG, s0)) for m in models_of(*METHODS)}
    base = figures.best_baseline(
        {m: e.summary() for m, e in evals.items()},
        key="time",
        exclude=models_of("control", "prior"),
    )
    shown = (*models_of("prior"), base)  # every prior beside the best learned field
    traj = {m: load_trajectories(path("traj", t, m, BASE_CONFIG, s0)) for m in shown}
    cen = {m: evals[m].centroid_err for m in shown}
    figures.fig_teaser(
        traj, cen, settings["conditions"], out, title=f"{t} tree, training seed {s0}"
    )


def _fig_results(path, settings, inputs, out):
    from physgs.report import figures

    s0, models = settings["seeds"][0], models_of(*METHODS)
    rows, images = [], {}
    for t in settings["trees"]:
        panels = {m: np.load(path("panels", t, m, BASE_CONFIG, s0)) for m in models}
        for split in ("time", "view", "wind"):
            row = f"{t}: unseen {split}"
            rows.append(row)
            images[(row, "gt")] = (panels["ours"][f"{split}_gt"], None)
            for m in models:
                images[(row, m)] = (panels[m][f"{split}_pred"], float(panels[m][f"{split}_psnr"]))
    figures.fig_results(rows, ["gt", *models], images, out)


FIG_TEMPORAL = Output(
    "fig_temporal",
    "figure",
    _evals(("eval",), METHODS + REFERENCES),
    _fig_temporal,
    settings=lambda cfg: {"n_train": int(cfg["testbed"]["n_train"])},
)
FIG_TEASER = Output(
    "fig_teaser",
    "figure",
    _evals(("eval", "traj"), METHODS),
    _fig_teaser,
    settings=_teaser_settings,
    seeds="first",
)
FIG_RESULTS = Output(
    "fig_results",
    "figure",
    _evals(("eval", "panels"), METHODS),
    _fig_results,
    settings=_conditions,
    seeds="first",
)
