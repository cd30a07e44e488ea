"""tab_parts and fig_parts: the paper's prior (``ours``: spatial k-means, independent parts
about fixed pivots) beside its topology-aware variants (``ours_topo``: parts cut along the tree;
``ours_chain``: the same, each riding on its parent), per tree, seed and configuration of
``parts_study``. tab_parts_k (a study): the smallest K at which the chained prior matches ours.
"""

from __future__ import annotations

from functools import partial
from itertools import product
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.evaluate.metrics import ceiling_fraction
from physgs.evaluate.parts import load_segmentations
from physgs.experiments.kmatch import matched_k
from physgs.intermediate import read_json
from physgs.models.registry import BASE_CONFIG, PAPER_MODEL, REFERENCE_NAMES, config_label, label
from physgs.recovery.record import load_null, load_recovery
from physgs.report import latex
from physgs.report import seeds as seedstats
from physgs.report.images import fit_row, fit_settings
from physgs.report.output import Columns, Output
from physgs.report.table_captions import caption
from physgs.report.tables import Table, seed_rows, seeds_of, tree_label
from physgs.testbed.variant import damping_id

COLUMNS = (
    "purity",
    "fit_psnr_db",
    "ceiling_frac",
    "view_psnr_db",
    "time_psnr_db",
    "trusted",
    "omega_rel_err_pct",
    "omega_null_rel_err_pct",
    "zeta_rel_err_pct",
    "zeta_null_rel_err_pct",
    "train_s",
)
#: The model every variant is compared with (the paper's prior).
BASELINE = PAPER_MODEL


def row(
    fit: Mapping[str, float],
    static_fit: float,
    ceiling_fit: float,
    recovery,
    null,
    damping_recovery=None,
    purity: float = float("nan"),
) -> dict[str, float]:
    """One tab_parts row.

    Args:
        fit: the model's ``images.fit_row`` (dB, seconds).
        static_fit: the same seed's static pose's fit, dB.
        ceiling_fit: the same seed's true-motion fit, dB.
        recovery (RecoveryRecord): the model's record on the faithful testbed.
        null (NullResult): the null of its K.
        damping_recovery (RecoveryRecord | None): its record on the damping testbed, or None.
        purity: the segmentation's overall purity (fraction).

    Returns:
        ``COLUMNS`` -> value (%, dB, seconds; the zeta errors NaN without ``damping_recovery``).

    Raises:
        ValueError: when ``damping_recovery`` has no damping scores.
    """
    zeta = zeta_null = np.nan
    if damping_recovery is not None:
        sc, nl = damping_recovery.damping_scores, damping_recovery.damping_null
        if sc is None or nl is None:
            raise ValueError(
                "tab_parts: a damping-testbed recovery has no damping scores; re-run its "
                "recovery rule with damping params"
            )
        zeta, zeta_null = 100 * sc.median_rel_err, 100 * nl.median_median_rel_err
    return {
        "purity": float(purity),
        "fit_psnr_db": fit["fit"],
        "ceiling_frac": float(ceiling_fraction(fit["fit"], static_fit, ceiling_fit)),
        "view_psnr_db": fit["view"],
        "time_psnr_db": fit["time"],
        "trusted": float(recovery.match.n_trusted),
        "omega_rel_err_pct": 100 * recovery.match.median_rel_err,
        "omega_null_rel_err_pct": 100 * null.median_median_rel_err,
        "zeta_rel_err_pct": zeta,
        "zeta_null_rel_err_pct": zeta_null,
        "train_s": fit["train_s"],
    }


def tab_parts(
    per_seed: Mapping[int, Mapping[tuple[str, str, str], Mapping[str, float]]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    models: Sequence[str],
    configs: Mapping[str, str],
    digits: int = 2,
) -> Table:
    """The parts study per tree, model and configuration.

    Args:
        per_seed: ``per_seed[seed][(tree, model, config)]``: a ``row``.
        trees: the trees.
        bones: tree -> its bone count.
        models: ids in row order (``ours`` first).
        configs: name -> LaTeX label.
        digits: decimals shown in the .tex.

    Returns:
        The table: one CSV row per seed and row; the .tex mean +- sd over seeds and each
            variant's paired fit-fraction difference from ours' (pp, 95% interval).
    """
    keys = [(t, m, c) for t in trees for c in configs for m in models]
    seeds = seeds_of(per_seed, "tab_parts", keys)

    def one(s, t, m, c):
        return {"tree": t, "bones": bones[t], "model": m, "config": c, **per_seed[s][(t, m, c)]}

    df = seed_rows(seeds, keys, one)
    col, fmt = partial(latex.cells, df), f".{int(digits)}f"
    frac = latex.by_seed(df, "ceiling_frac")  # less ours' in the same tree and configuration
    vs_ours = [
        seedstats.difference(100 * (frac[:, i] - frac[:, keys.index((t, BASELINE, c))]), ".0f")
        if m != BASELINE and BASELINE in models
        else ""
        for i, (t, m, c) in enumerate(keys)
    ]
    omega, omega_null, zeta, zeta_null = (
        col(f"{q}_rel_err_pct", f, r"\%")
        for q, f in (("omega", ".1f"), ("omega_null", ".1f"), ("zeta", ".0f"), ("zeta_null", ".0f"))
    )
    ceiling, omega_head = r"Of ceiling", r"Med.\ rel.\ err.\ $\hat\omega$"
    rows = [(tree_label(t, bones[t]), configs[c], label(m)) for t, m, c in keys]
    cells = pd.DataFrame(
        {
            ("", "Purity"): col("purity", ".2f"),
            (ceiling, "Fit"): col("ceiling_frac", ".0f", r"\%", scale=100),
            (ceiling, r"$-$ ours (pp)"): vs_ours,
            ("", "View"): col("view_psnr_db", fmt),
            ("", "Time"): col("time_psnr_db", fmt),
            (omega_head, "trained / null"): [f"{a} / {b}" for a, b in zip(omega, omega_null)],
            (r"Med.\ rel.\ err.\ $\hat\zeta$", "damping testbed: trained / null"): [
                "--" if a == "--" else f"{a} / {b}" for a, b in zip(zeta, zeta_null)
            ],
            ("", "Train (s)"): col("train_s", ".0f"),
        },
        index=pd.MultiIndex.from_tuples(rows, names=["Tree", "Config", "Parts"]),
    )
    cap = caption("tab_parts") + latex.seed_note(len(seeds))
    return Table("tab_parts", df, latex.render(cells, cap, "tab:parts"))


def fig_parts(records: Mapping, trees: Sequence[str], outputs: Sequence[str], title: str = ""):
    """One row per tree, one panel per model: its canonical Gaussians from the side (x, z; m),
    coloured by part, each pivot a black dot joined to its parent's; the title gives the purity.

    Args:
        records: tree -> its parts record ({key: np.ndarray}:
            ``physgs.evaluate.parts.segmentation_record``).
        trees: the trees, one row each.
        outputs: the paths to write (pdf, png).
        title: the figure's title.
    """
    import matplotlib.pyplot as plt

    from physgs.report.figures import _axes, _finish, _texts

    cols = max(len(records[t]["models"]) for t in trees)
    fig, axes = _axes(len(trees), cols, 3.0 * len(trees))  # the page's width: FONT_PT reads true
    cmap = plt.get_cmap("tab20")
    for r, t in enumerate(trees):
        rec, xyz = records[t], records[t]["xyz"]
        for j, m in enumerate(str(x) for x in rec["models"]):
            ax = axes[r, j]
            lab, piv, par = rec[f"{m}/labels"], rec[f"{m}/pivots"], rec[f"{m}/parent"]
            ax.scatter(xyz[:, 0], xyz[:, 2], s=1.5, c=cmap(lab % 20), linewidths=0)
            for p in np.flatnonzero(par >= 0):
                q = par[p]
                ax.plot([piv[p, 0], piv[q, 0]], [piv[p, 2], piv[q, 2]], "k-", lw=0.7)
            ax.plot(piv[:, 0], piv[:, 2], "k.", ms=3)
            head = f"{t}: {label(m)}\nK={lab.max() + 1}, purity {float(rec[f'{m}/overall']):.2f}"
            _texts(ax, head, "x (m)", "height z (m)" if j == 0 else None)
            ax.set_aspect("equal")
        for j in range(len(rec["models"]), cols):
            axes[r, j].axis("off")
    _finish(fig, outputs, title, dpi=150)


def tab_parts_k(
    per_seed: Mapping, trees: Sequence, bones: Mapping, base_k: int, tie_db: float, digits: int = 2
) -> Table:
    """The smallest K at which the chained prior matches ours (``experiments.kmatch``).

    Args:
        per_seed: ``per_seed[seed][tree]``: {"ours": held-out dB of ours at ``base_k``, "chain":
            {K: held-out dB of the chained prior}} (``base_k`` among the chain's K).
        trees: the trees.
        bones: tree -> its bone count.
        base_k: ours' K.
        tie_db: the tolerance of a match, dB.
        digits: decimals shown in the .tex.

    Returns:
        The table: one CSV row per seed, tree and (model, K), with that seed's matched K (NaN
            where none matches); the .tex mean +- sd over seeds and each seed's matched K.
    """
    seeds = seeds_of(per_seed, "tab_parts_k", trees)
    recs = []
    for s, t in product(seeds, trees):
        r = per_seed[s][t]
        chain = {int(k): float(v) for k, v in r["chain"].items()}
        m = matched_k(chain, float(r["ours"]), tie_db)
        points = [("ours", int(base_k), float(r["ours"]))]
        points += [("ours_chain", k, chain[k]) for k in sorted(chain)]
        about, found = {"seed": s, "tree": t, "bones": bones[t]}, float("nan") if m is None else m
        recs += [
            about | {"model": model, "K": k, "heldout_psnr_db": v, "matched_k": float(found)}
            for model, k, v in points
        ]
    df = pd.DataFrame(recs)
    first = latex.rows(df)
    ks = sorted(int(k) for k in first.loc[first["model"] == "ours_chain", "K"].unique())
    psnr = np.reshape(latex.cells(df, "heldout_psnr_db", f".{int(digits)}f"), (len(trees), -1))
    matched = [  # each seed's
        ", ".join("--" if not np.isfinite(x) else str(int(x)) for x in mk)
        for mk in latex.by_seed(df, "matched_k")[:, :: 1 + len(ks)].T
    ]
    heads = [(rf"Ours ($K{{=}}{base_k}$)", "held-out (dB)")]
    heads += [("Chained topology parts", rf"$K{{=}}{k}$") for k in ks]
    cells = pd.DataFrame(
        psnr,
        index=pd.Index([tree_label(t, bones[t]) for t in trees], name="Tree"),
        columns=pd.MultiIndex.from_tuples(heads),
    )
    cells[("", "matched $K$")] = matched
    cap = caption("tab_parts_k", base_k=base_k, tie_db=f"{tie_db:g}")
    cap += latex.seed_note(len(seeds), decides=False)
    return Table("tab_parts_k", df, latex.render(cells, cap, "tab:parts_k"))


# ---- the declarations ----------------------------------------------------------------------
#: The rows the parts study's fit fraction needs (the static pose's and the ceiling's).
FIT_FRAME = ("static", REFERENCE_NAMES[0])


def _parts_needs(plan, seeds):
    """Each prior's evaluation, loss log and recovery on each tree (and damping testbed), the
    null of each K, the static pose's and the ceiling's fit, and the segmentation record."""
    priors, configs = [BASELINE, *plan.parts_models], plan.parts_configs
    damping_trees = [t for t in plan.damping_trees if t in plan.trees]
    out = []
    for s, t in product([int(x) for x in seeds], plan.trees):
        out += [(k, t, m, BASE_CONFIG, s) for m in FIT_FRAME for k in ("eval", "loss")]
        for c, m in product(configs, priors):
            out += [(k, t, m, c, s) for k in ("eval", "loss", "recovery")]
            out += [("recovery", damping_id(t), m, c, s)] if t in damping_trees else []
        out += list(dict.fromkeys(("null", t, int(configs[c]["K"]), s) for c in configs))
        out.append(("parts", t, s))
    return out


def _parts_settings(cfg: dict) -> dict:
    study, configs = cfg["parts_study"], cfg["models"]["configs"]
    return {
        "models": [BASELINE, *study["models"]],
        "configs": {c: config_label(c, configs[c]) for c in study["configs"]},
        "K": {c: int(configs[c]["K"]) for c in study["configs"]},
        "damping_trees": [t for t in cfg["damping_benchmark"]["trees"] if t in cfg["trees"]],
        **fit_settings(cfg),
    }


def _tab_parts(path, settings, inputs, out):
    trees, models, configs = settings["trees"], settings["models"], settings["configs"]
    n, every = int(settings["n_train"]), int(settings["holdout_every"])

    def fit(t, m, c, s):
        return fit_row(path("eval", t, m, c, s), path("loss", t, m, c, s), n, every)

    rows = {s: {} for s in settings["seeds"]}
    for s, t in product(rows, trees):
        static, ceiling = (fit(t, m, BASE_CONFIG, s)["fit"] for m in FIT_FRAME)
        seg = load_segmentations(path("parts", t, s))
        damp = damping_id(t) if t in settings["damping_trees"] else None
        for c in configs:
            null = load_null(path("null", t, int(settings["K"][c]), s))
            for m in models:
                rec = load_recovery(path("recovery", t, m, c, s))
                drec = load_recovery(path("recovery", damp, m, c, s)) if damp else None
                purity = float(seg[f"{m}/overall"]) if c == BASE_CONFIG else float("nan")
                rows[s][(t, m, c)] = row(fit(t, m, c, s), static, ceiling, rec, null, drec, purity)
    return tab_parts(rows, trees, settings["bones"], models, configs, digits=settings["digits"])


TAB_PARTS = Output(
    "tab_parts",
    "table",
    _parts_needs,
    _tab_parts,
    settings=_parts_settings,
    in_report=lambda plan: bool(plan.parts_models),
    # keys, values (all but train_s), timing, about
    columns=Columns(("seed", "tree", "model", "config"), COLUMNS[:-1], ("train_s",), ("bones",)),
)


def _fig_parts(path, settings, inputs, out):
    trees, s0 = settings["trees"], settings["seeds"][0]
    recs = {t: load_segmentations(path("parts", t, s0)) for t in trees}
    fig_parts(recs, trees, out, title=f"parts of each prior (single), training seed {s0}")


FIG_PARTS = Output(
    "fig_parts",
    "figure",
    lambda plan, seeds: [("parts", t, int(seeds[0])) for t in plan.trees],
    _fig_parts,
    settings=lambda cfg: {"models": [BASELINE, *cfg["parts_study"]["models"]]},
    seeds="first",
    in_report=lambda plan: bool(plan.parts_models),
)


def _kmatch_needs(plan, seeds):
    """Ours' and the chained prior's evaluation in the base configuration (their held-out
    frames) and the chained prior's kmatch points at each smaller K."""
    out = []
    for s, t in product([int(x) for x in seeds], plan.trees):
        out += [("eval", t, m, BASE_CONFIG, s) for m in (BASELINE, "ours_chain")]
        out += [("kmatch", t, int(k), s) for k in plan.k_candidates]
    return out


def _kmatch_settings(cfg: dict) -> dict:
    return {
        "models": [BASELINE, *cfg["parts_study"]["models"]],
        "K": int(cfg["models"]["configs"][BASE_CONFIG]["K"]),
        "k_candidates": [int(k) for k in cfg["parts_study"]["k_candidates"]],
        "tie_db": float(cfg["models"]["kselect"]["tie_db"]),
        **fit_settings(cfg),
    }


def _tab_parts_k(path, settings, inputs, out):
    n, every, K = int(settings["n_train"]), int(settings["holdout_every"]), int(settings["K"])

    def held(m, t, s):
        return fit_row(path("eval", t, m, BASE_CONFIG, s), None, n, every)["heldout"]

    def chain(t, s):  # the chained prior's held-out dB at each K
        out = {K: held("ours_chain", t, s)}
        for k in settings["k_candidates"]:
            point = read_json(path("kmatch", t, int(k), s), ("heldout_psnr",), rule="kmatch_point")
            out[int(k)] = float(point["heldout_psnr"])
        return out

    trees, tie = settings["trees"], float(settings["tie_db"])
    rows = {
        s: {t: {"ours": held(BASELINE, t, s), "chain": chain(t, s)} for t in trees}
        for s in settings["seeds"]
    }
    return tab_parts_k(rows, trees, settings["bones"], K, tie, digits=settings["digits"])


TAB_PARTS_K = Output(
    "tab_parts_k",
    "table",
    _kmatch_needs,
    _tab_parts_k,
    settings=_kmatch_settings,
    seeds="studies",
    in_report=lambda plan: False,  # a study: the `studies` target (Snakefile)
    # the chained prior at several K (a numeric key)
    columns=Columns(
        ("seed", "tree", "model", "K"), ("heldout_psnr_db", "matched_k"), about=("bones",)
    ),
)
