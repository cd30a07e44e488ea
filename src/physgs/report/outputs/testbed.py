"""tab_testbed: the testbed's statistics per tree (no model: it reads no training seed)."""

from __future__ import annotations

from physgs.report import tables
from physgs.report.outputs.base import Columns, Output
from physgs.testbed.stats import load_stats


def _tab_testbed(path, settings, inputs, out):
    trees = settings["trees"]
    return tables.tab_testbed(
        {t: load_stats(path("stats", t)) for t in trees}, trees, digits=settings["digits"]
    )


#: tab_testbed's CSV: one row per tree (no seed: the testbed's), the paper's values beside
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
    ),
    about=("bones", "paper_bones"),
)

TAB_TESTBED = Output(
    "tab_testbed",
    "table",
    lambda plan, seeds: [("stats", t) for t in plan.trees],
    _tab_testbed,
    seeds="none",
    columns=TESTBED_COLUMNS,
)
