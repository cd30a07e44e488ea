"""tab_testbed: the testbed's statistics per tree (no model: it reads no training seed)."""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.report import latex, paper
from physgs.report.claim_cells import roles_of
from physgs.report.output import Columns, Output
from physgs.report.table_captions import caption
from physgs.report.tables import Table, check_keys
from physgs.testbed.stats import load_stats

#: the statistics that vary from one tree instance to the next: each gets a ``<col>_sd`` column,
#: its spread over the instances (``testbed_seeds``)
INSTANCE_SPREAD = (
    "distinct_frequencies",
    "f_min_hz",
    "f_median_hz",
    "f_max_hz",
    "f_span",
    "clamped",
    "nearest_bone_gap_pct",
    "swing_deg_median",
    "visible_px_median",
    "visible_below_px_pct",
    "height_fill_pct",
    "coverage_pct",
)
#: an instance's statistics in tab_testbed (a tree's row: their mean), and their spreads' columns
STATS = (*INSTANCE_SPREAD, "order_share", "order_share_random")
SPREADS = tuple(f"{c}_sd" for c in INSTANCE_SPREAD)
#: the percentage columns -> the fraction they show
PERCENT = {
    "nearest_bone_gap_pct": "nearest_bone_gap",
    "visible_below_px_pct": "visible_below_px_fraction",
    "height_fill_pct": "height_fill",
    "coverage_pct": "coverage",
}


def _testbed_row(s: Mapping) -> dict:
    """One instance's statistics in tab_testbed's columns (percentages as percent)."""
    return {c: 100 * s[PERCENT[c]] if c in PERCENT else s[c] for c in STATS}


def tab_testbed(
    stats: Mapping[str, Mapping],
    trees: Sequence[str],
    digits: int = 2,
    instances: Mapping[str, Sequence[Mapping]] | None = None,
    paper_trees: Mapping[str, str | None] | None = None,
) -> Table:
    """The testbed's statistics per tree (``testbed.stats.testbed_stats``), beside the paper's
    figures where it gives them (``report.paper``).

    With tree instances (``testbed_seeds``: one per training seed), each statistic is the mean
    over a tree's instances, ``<col>_sd`` its sample sd (``INSTANCE_SPREAD``) and ``instances``
    their number; without, the one instance's (sd NaN, ``instances`` 1).

    Args:
        stats: tree -> the one instance's statistics (as ``load_stats`` reads them).
        trees: the trees, in row order.
        digits: decimals shown in the .tex.
        instances: tree -> each instance's statistics; None or a tree left out: ``stats``'.
        paper_trees: tree -> the paper's tree it stands for (its preset's ``role.paper``);
            None or a tree left out: none.

    Returns:
        The table: one row per tree.
    """
    check_keys(list(trees), stats, "tab_testbed")

    def row(t):  # the mean over the tree's instances (or its one), the paper's values beside
        inst = pd.DataFrame([_testbed_row(x) for x in (instances or {}).get(t) or [stats[t]]])
        pt = (paper_trees or {}).get(t)
        return {
            "tree": t,
            "bones": int(stats[t]["bones"]),
            "paper_bones": paper.BONES.get(pt),
            **{c: float(inst[c].mean()) for c in inst.columns},
            "paper_f_span": paper.FREQUENCY_SPAN,
            "paper_nearest_bone_gap_pct": paper.NEAREST_BONE_GAP_PCT.get(pt, np.nan),
            "instances": len(inst),
            **{f"{c}_sd": float(inst[c].std(ddof=1)) for c in INSTANCE_SPREAD},  # one: NaN
        }

    df = pd.DataFrame([row(t) for t in trees])
    fmt = f".{int(digits)}f"
    paper_gap = [
        "--" if not np.isfinite(x) else format(x, fmt) for x in df["paper_nearest_bone_gap_pct"]
    ]
    spread = [  # over the tree's instances, where there are several
        f" $\\pm$ {sd:{fmt}}" if n > 1 else ""
        for sd, n in zip(df["nearest_bone_gap_pct_sd"], df["instances"])
    ]
    cells = pd.DataFrame(
        {
            "Bones": df["bones"].astype(str),
            "Distinct $f$": df["distinct_frequencies"].astype(str),
            "$f$ min / med / max (Hz)": [
                f"{r.f_min_hz:.3f} / {r.f_median_hz:.3f} / {r.f_max_hz:.3f}"
                for r in df.itertuples()
            ],
            "Span": [f"{x:.2f}$\\times$" for x in df["f_span"]],
            "Clamped": df["clamped"].astype(str),
            "Gap (paper)": [
                f"{g:{fmt}}{sd}\\% ({p}\\%)"
                for g, sd, p in zip(df["nearest_bone_gap_pct"], spread, paper_gap)
            ],
            r"Swing ($^\circ$)": [f"{x:{fmt}}" for x in df["swing_deg_median"]],
            "Visible (px)": [f"{x:{fmt}}" for x in df["visible_px_median"]],
            r"$<$1\,px": [f"{x:.0f}\\%" for x in df["visible_below_px_pct"]],
            "Height": [f"{x:.0f}\\%" for x in df["height_fill_pct"]],
        }
    ).set_axis(pd.Index(df["tree"].str.capitalize(), name="Tree"))
    n = int(df["instances"].max())
    each = "tab_testbed_instances" if (df["instances"] > 1).any() else "tab_testbed_one"
    cap = caption("tab_testbed", each, span=paper.FREQUENCY_SPAN, n=n)
    return Table("tab_testbed", df, latex.render(cells, cap, "tab:testbed"))


# ---- the declaration -----------------------------------------------------------------------
def _tab_testbed(path, settings, inputs, out):
    trees, seeds = settings["trees"], settings["instances"]
    stats = {t: load_stats(path("stats", t)) for t in trees}
    each = {t: [load_stats(path("instance_stats", t, s)) for s in seeds] for t in trees}
    paper_trees = {t: r.get("paper") for t, r in settings["roles"].items()}
    return tab_testbed(stats, trees, settings["digits"], each if seeds else None, paper_trees)


def _settings(cfg: dict) -> dict:
    """The trees' roles (the paper's tree beside each) and the instances' testbed seeds (the
    training seeds with ``testbed_seeds``; none without)."""
    seeds = [int(s) for s in cfg["seeds"]] if cfg["testbed_seeds"] else []
    return {"roles": roles_of(cfg["presets"], cfg["trees"]), "instances": seeds}


def _needs(plan, seeds):
    each = [("instance_stats", t, int(s)) for t in plan.trees for s in plan.seeds]
    return [("stats", t) for t in plan.trees] + (each if plan.testbed_seeds else [])


TAB_TESTBED = Output(
    "tab_testbed",
    "table",
    _needs,
    _tab_testbed,
    settings=_settings,
    seeds="none",
    # one row per tree (no seed: the testbed's, or the mean over its instances), the paper's
    # values beside, and the spreads over the tree's instances (NaN with one)
    columns=Columns(
        keys=("tree",),
        values=(*STATS, "paper_f_span", "paper_nearest_bone_gap_pct", *SPREADS),
        about=("bones", "paper_bones", "instances"),
    ),
)
