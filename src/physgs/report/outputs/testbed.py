"""tab_testbed: the testbed's statistics per tree (no model: it reads no training seed)."""

from __future__ import annotations

from physgs.report import tables
from physgs.report.outputs.base import Output
from physgs.testbed.stats import load_stats


def _tab_testbed(path, settings, inputs, out):
    trees = settings["trees"]
    return tables.tab_testbed(
        {t: load_stats(path("stats", t)) for t in trees}, trees, digits=settings["digits"]
    )


TAB_TESTBED = Output(
    "tab_testbed",
    "table",
    lambda plan, seeds: [("stats", t) for t in plan.trees],
    _tab_testbed,
    seeds="none",
)
