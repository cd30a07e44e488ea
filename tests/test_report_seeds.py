"""Seed statistics (physgs.statistics) against scipy: intervals, decisions, the best; the .tex
cells over seeds (physgs.report.seeds)."""

import numpy as np
import pytest
from scipy import stats

from physgs import statistics as S
from physgs.report import seeds


def test_interval_matches_scipy_t_interval():
    v = np.array([0.3, 0.9, 0.5, 1.4, 0.2])
    m, sd, lo, hi = S.interval(v)
    elo, ehi = stats.t.interval(0.95, len(v) - 1, loc=v.mean(), scale=stats.sem(v))
    assert (m, sd) == pytest.approx((v.mean(), v.std(ddof=1)))
    assert (lo, hi) == pytest.approx((elo, ehi))


def test_one_seed_gives_no_interval_and_decides_nothing():
    m, sd, lo, hi = S.interval([2.0])
    assert m == 2.0 and np.isnan(sd) and np.isnan(lo) and np.isnan(hi)
    assert not S.decided([2.0])
    assert seeds.pm([2.0], ".2f") == "2.00"
    assert seeds.difference([2.0], ".2f") == "$+2.00$" + seeds.UNDECIDED


@pytest.mark.parametrize(
    "values, want",
    [
        ([1.0, 1.1, 0.9], True),
        ([-1.0, -1.1, -0.9], True),
        ([1.0, -0.8, 0.5], False),
        ([0.0, 0.0], False),
        ([np.nan, 1.0], False),
    ],
)
def test_decided_when_the_interval_excludes_zero(values, want):
    assert S.decided(values) is want


def test_decided_best_needs_a_decided_gap_to_the_runner_up():
    rng = np.random.default_rng(0)
    shared = rng.normal(0, 3, size=(6, 1))  # a seed-wide offset: pairing removes it
    clear = shared + np.array([[1.0, 0.0, -1.0]]) + rng.normal(0, 0.01, size=(6, 3))
    assert S.decided_best(clear) == 0
    assert S.decided_best(-clear, higher=False) == 0
    tied = shared + rng.normal(0, 1.0, size=(6, 3))
    tied[:, 1] = tied[:, 0] + np.array([0.5, -0.5, 0.4, -0.4, 0.1, -0.1])
    assert S.decided_best(tied[:, :2]) is None
    assert S.decided_best(clear[:1]) is None  # one seed


def test_paired_refuses_unequal_seed_counts():
    with pytest.raises(ValueError, match="one value per seed"):
        S.paired([1.0, 2.0], [1.0])
