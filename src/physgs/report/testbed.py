"""tab_testbed: the testbed's statistics per tree (no model: it reads no training seed), its
builder and its declaration."""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.report import latex, paper
from physgs.report.claim_cells import roles_of
from physgs.report.output import Columns, Output
from physgs.report.tables import Table, check_keys
from physgs.testbed.stats import load_stats


#: tab_testbed's statistics that vary from one tree instance to the next: each gets a
#: ``<col>_sd`` column, its spread over the instances (``testbed_seeds``)
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


def _testbed_row(s: Mapping) -> dict:
    """One instance's statistics in tab_testbed's columns (percentages as percent)."""
    return {
        "distinct_frequencies": int(s["distinct_frequencies"]),
        "f_min_hz": s["f_min_hz"],
        "f_median_hz": s["f_median_hz"],
        "f_max_hz": s["f_max_hz"],
        "f_span": s["f_span"],
        "clamped": int(s["clamped"]),
        "nearest_bone_gap_pct": 100 * s["nearest_bone_gap"],
        "swing_deg_median": s["swing_deg_median"],
        "visible_px_median": s["visible_px_median"],
        "visible_below_px_pct": 100 * s["visible_below_px_fraction"],
        "height_fill_pct": 100 * s["height_fill"],
        "coverage_pct": 100 * s["coverage"],
        "order_share": s["order_share"],
        "order_share_random": s["order_share_random"],
    }


def tab_testbed(
    stats: Mapping[str, Mapping],
    trees: Sequence[str],
    digits: int = 2,
    instances: Mapping[str, Sequence[Mapping]] | None = None,
    paper_trees: Mapping[str, str | None] | None = None,
) -> Table:
    """The testbed's statistics per tree
    ([`testbed_stats`][physgs.testbed.stats.testbed_stats]), beside the paper's figures where it
    gives them ([`physgs.report.paper`][physgs.report.paper]).

    Columns: bones; distinct natural frequencies; f min / median / max (Hz) and span; bones
    clamped into the band; median nearest-bone gap (%); median per-bone swing (degrees); how
    visible each bone's own motion is in the training camera (median pixels, % under 1 px);
    the training frame's height filled by the swept tree and pixels covered (%). With tree
    instances (``testbed_seeds``: one per training seed), each is the mean over a tree's
    instances, ``<col>_sd`` its spread (sample sd; ``INSTANCE_SPREAD``) and ``instances`` their
    number; without, the one instance's (sd NaN, ``instances`` 1).

    Args:
        stats: tree -> its statistics (as [`load_stats`][physgs.testbed.stats.load_stats] reads
            them): the one instance's.
        trees: the trees, in row order.
        digits: decimals shown in the .tex.
        instances: tree -> each instance's statistics (``testbed_seeds``); None or a tree left
            out: the one instance of ``stats``.
        paper_trees: tree -> the paper's tree it stands for (its preset's ``role.paper``), whose
            figures go beside it; None or a tree left out: none.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    check_keys(list(trees), stats, "tab_testbed")
    rows = []
    for t in trees:
        per = [_testbed_row(x) for x in ((instances or {}).get(t) or [stats[t]])]
        inst = pd.DataFrame(per)
        mean = {c: float(inst[c].mean()) for c in inst.columns}
        sd = {
            f"{c}_sd": float(inst[c].std(ddof=1)) if len(inst) > 1 else np.nan
            for c in INSTANCE_SPREAD
        }
        pt = (paper_trees or {}).get(t)
        rows.append(
            {
                "tree": t,
                "bones": int(stats[t]["bones"]),
                "paper_bones": paper.BONES.get(pt),
                **mean,
                "paper_f_span": paper.FREQUENCY_SPAN,
                "paper_nearest_bone_gap_pct": paper.NEAREST_BONE_GAP_PCT.get(pt, np.nan),
                "instances": len(per),
                **sd,
            }
        )
    df = pd.DataFrame(rows)
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
    cap = (
        r"The testbed. Distinct $f$: distinct natural frequencies; Span: max/min frequency "
        + f"(paper: $\\sim${paper.FREQUENCY_SPAN}$\\times$)"
        + r"; Gap: median nearest-bone gap, the "
        r"paper's in brackets; Swing: median RMS of each bone's own angle over the window; "
        r"Visible: median image displacement caused by a bone's own angle alone, acting on its "
        r"subtree, in training-camera pixels, and the share of bones under 1\,px (no method "
        r"can recover those); Height: training-image height spanned by the swept tree."
        + (
            f" Each value is the mean over a tree's {int(df['instances'].max())} instances "
            r"(one per training seed), the gap $\pm$ its sd over them (the CSV: every "
            r"statistic's)."
            if (df["instances"] > 1).any()
            else " One instance per tree (the paper's protocol)."
        )
    )
    return Table("tab_testbed", df, latex.render(cells, cap, "tab:testbed"))


# ---- the declaration -----------------------------------------------------------------------


def _tab_testbed(path, settings, inputs, out):
    trees, seeds = settings["trees"], settings["instances"]
    return tab_testbed(
        {t: load_stats(path("stats", t)) for t in trees},
        trees,
        digits=settings["digits"],
        instances={t: [load_stats(path("instance_stats", t, s)) for s in seeds] for t in trees}
        if seeds
        else None,
        paper_trees={t: r.get("paper") for t, r in settings["roles"].items()},
    )


def _settings(cfg: dict) -> dict:
    """The trees' roles (the paper's tree beside each) and the instances' testbed seeds (the
    training seeds with ``testbed_seeds``; none without)."""
    seeds = [int(s) for s in cfg["seeds"]] if cfg["testbed_seeds"] else []
    return {"roles": roles_of(cfg["presets"], cfg["trees"]), "instances": seeds}


def _needs(plan, seeds):
    one = [("stats", t) for t in plan.trees]
    if not plan.testbed_seeds:
        return one
    return one + [("instance_stats", t, int(s)) for t in plan.trees for s in plan.seeds]


#: tab_testbed's CSV: one row per tree (no seed: the testbed's, or the mean over its instances),
#: the paper's values beside
TESTBED_COLUMNS = Columns(
    keys=("tree",),
    values=(
        "distinct_frequencies",
        "f_min_hz",
        "f_median_hz",
        "f_max_hz",
        "f_span",
        "paper_f_span",
        "clamped",
        "nearest_bone_gap_pct",
        "paper_nearest_bone_gap_pct",
        "swing_deg_median",
        "visible_px_median",
        "visible_below_px_pct",
        "height_fill_pct",
        "coverage_pct",
        "order_share",
        "order_share_random",
        # spreads over the tree's instances (NaN with one)
        *(f"{c}_sd" for c in INSTANCE_SPREAD),
    ),
    about=("bones", "paper_bones", "instances"),
)

TAB_TESTBED = Output(
    "tab_testbed",
    "table",
    _needs,
    _tab_testbed,
    settings=_settings,
    seeds="none",
    columns=TESTBED_COLUMNS,
)
