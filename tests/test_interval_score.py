"""Uncertainty that can be wrong: the interval score (Gneiting and Raftery 2007) against
hand-computed cases, and coverage claims that fail where the intervals are too narrow (they miss)
or too wide (they cover, but score worse than the untrained null's draw range)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from physgs.oma.intervals import interval_score, relative_scores
from physgs.oma.run import interval_block
from physgs.report import claims
from physgs.report.recovery import interval_cells
from roles import ROLES


@pytest.mark.parametrize(
    "lo, hi, x, want",
    [
        (0.9, 1.1, 1.0, 0.2),  # covers: the width alone
        (1.1, 1.3, 1.0, 0.2 + 40 * 0.1),  # misses below by 0.1: 2 / 0.05 = 40 per unit
        (0.5, 0.7, 1.0, 0.2 + 40 * 0.3),  # misses above by 0.3
        (1.0, 1.0, 1.0, 0.0),  # a point on the truth
    ],
)
def test_interval_score_by_hand(lo, hi, x, want):
    assert interval_score([lo], [hi], [x])[0] == pytest.approx(want)


def test_relative_scores_by_hand():
    """Two parts: truth 1.0 with 1.0 +- 1.96 * 0.05 (covers: width 0.196, over 1.0), and truth
    2.5 with 2.0 and no sigma (a point: misses by 0.5, 40 * 0.5 = 20, over 2.5 = 8). Mean
    (0.196 + 8) / 2 = 4.098. The null's range (0.5, 3.0) covers both: 2.5 / 1.0 and 2.5 / 2.5,
    mean 1.75."""
    r = relative_scores([1.0, 2.0], [0.05, np.nan], [1.0, 2.5], (0.5, 3.0))
    assert r["score"] == pytest.approx(4.098, abs=1e-3)  # 1.96 vs 1.959964: 4e-6
    assert r["null_score"] == pytest.approx(1.75) and r["n"] == 2
    assert np.isnan(relative_scores([1.0], [0.1], [1.0], None)["null_score"])


ZETA_RANGE = (0.02, 0.2)


def _block(seed: int, sd_factor: float, n: int = 40) -> dict:
    """A damping testbed's intervals block: n trusted parts, each on its own bone, the estimates
    off the truth by a relative error of sd 10% (omega and zeta alike), and each interval's sigma
    ``sd_factor`` times the estimate (0.1: honest; 0.001: too narrow; 3: too wide)."""
    rng = np.random.default_rng(seed)
    z_true = np.exp(rng.uniform(*np.log(ZETA_RANGE), n))
    w_true = np.exp(rng.uniform(np.log(2.0), np.log(9.0), n))
    z, w = (t * (1 + 0.1 * rng.standard_normal(n)) for t in (z_true, w_true))
    pm = SimpleNamespace(
        omega=w, zeta=z, omega_std=sd_factor * w, zeta_std=sd_factor * z, estimated=np.ones(n, bool)
    )
    match = SimpleNamespace(bone=np.arange(n), trusted=np.ones(n, bool))
    truth = SimpleNamespace(omega=w_true, zeta=z_true)
    ranges = {"omega": (w_true.min(), w_true.max()), "zeta": ZETA_RANGE}
    return interval_block(pm, match, truth, ranges)


def _tab_damping(sd_factor: float) -> pd.DataFrame:
    rows = [
        {
            "seed": s,
            "tree": "sparse",
            "testbed": "damping",
            "config": "single",
            "method": "oma",
            "trained_minus_null_pp": -5.0,
            **interval_cells(SimpleNamespace(intervals=_block(s, sd_factor))),
        }
        for s in range(3)
    ]
    return pd.DataFrame(rows)


def _ledger(sd_factor: float) -> pd.DataFrame:
    tabs = {"tab_damping": _tab_damping(sd_factor)}
    return claims.ledger(claims.measure(tabs, {}, ["sparse"], roles=ROLES)).set_index("id")


def test_honest_intervals_cover_and_beat_the_null():
    df = _ledger(0.1)
    for q in ("frequency", "damping"):
        assert df.loc[f"oma_{q}_interval_covers/sparse", "verdict"] == "holds"
        assert df.loc[f"oma_{q}_interval_score/sparse", "verdict"] == "holds"
        assert df.loc[f"oma_{q}_interval_informative/sparse", "verdict"] == "holds"


def test_intervals_too_narrow_fail_to_cover():
    """sigma 0.1% of the value against errors of 10%: almost every interval misses."""
    df = _ledger(0.001)
    for q in ("frequency", "damping"):
        r = df.loc[f"oma_{q}_interval_covers/sparse"]
        assert r["measured"] < 0.2 and r["verdict"] == "fails"


def test_intervals_too_wide_cover_but_do_not_hold():
    """sigma 3x the value: every interval covers (the old claim held), the half-width is 5.9x
    the value (not informative) and the width costs more than the null's draw range: the
    coverage claim fails on its companion."""
    df = _ledger(3.0)
    for q in ("frequency", "damping"):
        r = df.loc[f"oma_{q}_interval_covers/sparse"]
        assert r["measured"] == 1.0
        assert r["verdict"].startswith("fails: covers, but oma_") and r["requires"]
        assert df.loc[f"oma_{q}_interval_score/sparse", "verdict"] == "fails"
        w = df.loc[f"oma_{q}_interval_informative/sparse"]
        assert w["measured"] == pytest.approx(1.959964 * 3.0) and w["verdict"] == "fails"


def test_a_record_without_scores_leaves_coverage_undecided():
    """A table made before the scores (NaN columns): the coverage no longer holds on its own."""
    d = _tab_damping(0.1)
    d[[c for c in d.columns if c.endswith("interval_score")]] = np.nan
    df = claims.ledger(claims.measure({"tab_damping": d}, {}, ["sparse"], roles=ROLES)).set_index(
        "id"
    )
    v = df.loc["oma_damping_interval_covers/sparse", "verdict"]
    assert v.startswith("undecided: covers, but oma_damping_interval_score/sparse undecided")
