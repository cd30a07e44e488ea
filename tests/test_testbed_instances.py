"""tab_testbed over tree instances (``testbed_seeds``): each preset's statistics as the mean and
spread over its instances, the paper's figures beside them through the preset's role."""

from __future__ import annotations

import numpy as np
import pytest

from physgs.report import testbed
from physgs.report.output import Plan


def _stats(gap: float, span: float, cover: float) -> dict:
    return {
        "bones": 22,
        "distinct_frequencies": 22,
        "f_min_hz": 0.35,
        "f_median_hz": 0.8,
        "f_max_hz": 0.35 * span,
        "f_span": span,
        "clamped": 0,
        "nearest_bone_gap": gap,
        "swing_deg_median": 2.0,
        "visible_px_median": 3.0,
        "visible_below_px_fraction": 0.1,
        "height_fill": 0.8,
        "coverage": cover,
        "order_share": 0.5,
        "order_share_random": 0.4,
    }


def test_the_mean_and_spread_over_instances_by_hand():
    """Gaps 5%, 6%, 10% over three instances: mean 7%, sample sd sqrt(((2)^2 + 1^2 + 3^2) / 2) =
    sqrt(7) points; the paper's sparse gap (5.40%) and bones (22) beside, through role.paper."""
    inst = [_stats(0.05, 4.0, 0.10), _stats(0.06, 4.2, 0.12), _stats(0.10, 4.4, 0.14)]
    t = testbed.tab_testbed(
        {"oak": inst[0]}, ["oak"], instances={"oak": inst}, paper_trees={"oak": "sparse"}
    )
    r = t.df.iloc[0]
    assert r["instances"] == 3
    assert r["nearest_bone_gap_pct"] == pytest.approx(7.0)
    assert r["nearest_bone_gap_pct_sd"] == pytest.approx(np.sqrt(7.0))
    assert r["f_span"] == pytest.approx(4.2) and r["f_span_sd"] == pytest.approx(0.2)
    assert r["coverage_pct"] == pytest.approx(12.0) and r["coverage_pct_sd"] == pytest.approx(2.0)
    assert r["paper_nearest_bone_gap_pct"] == 5.40 and r["paper_bones"] == 22
    assert "$\\pm$" in t.tex and "3 instances" in t.tex


def test_one_instance_is_the_papers_protocol():
    t = testbed.tab_testbed({"oak": _stats(0.05, 4.0, 0.1)}, ["oak"])
    r = t.df.iloc[0]
    assert r["instances"] == 1 and np.isnan(r["nearest_bone_gap_pct_sd"])
    assert np.isnan(r["paper_nearest_bone_gap_pct"])  # no role.paper: no paper figure
    assert "One instance per tree" in t.tex


@pytest.mark.parametrize("seeded", [False, True])
def test_tab_testbed_reads_every_instance_with_testbed_seeds(seeded):
    plan = Plan(trees=["sparse"], configs={}, seeds=[0, 1, 2], testbed_seeds=seeded)
    got = testbed.TAB_TESTBED.needs(plan, [])
    inst = [("instance_stats", "sparse", s) for s in (0, 1, 2)]
    assert got == [("stats", "sparse"), *(inst if seeded else [])]
