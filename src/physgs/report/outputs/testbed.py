"""tab_testbed: the testbed's statistics per tree (no model: it reads no training seed)."""

from __future__ import annotations

from physgs.report import tables
from physgs.report.claim_cells import roles_of
from physgs.report.outputs.base import Columns, Output
from physgs.testbed.stats import load_stats


def _tab_testbed(path, settings, inputs, out):
    trees, seeds = settings["trees"], settings["instances"]
    return tables.tab_testbed(
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
        *(f"{c}_sd" for c in tables.INSTANCE_SPREAD),
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
