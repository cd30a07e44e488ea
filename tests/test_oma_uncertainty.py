"""The modes' standard deviations against pyOMA-2's own propagation and against the spread of many
independent records of one ``scipy.signal.lsim`` system (the oracle of ``test_oma_ssi.py``).

Oracle of the sigmas: 24 records of the same two-mode system (0.6 and 1.2 Hz, zeta 0.04 and
0.08, four channels), each 150 s, identified one by one; the sample standard deviation of their
estimates is the truth a sigma must match. With 20-24 records that spread is itself known to
about +-16% (1 / sqrt(2 x 19)); the sigmas are conservative on the more damped mode (measured
median sigma / spread 0.95-1.2 at 0.6 Hz, 1.9-2.6 at 1.2 Hz), so the test allows a factor of 3
either way. The intervals' coverage on these long
records must hold the truth at least 0.8 of the time (0.95 expected; with 40 intervals or more,
0.8 is over 4 binomial standard errors below it).
"""

import logging

import numpy as np
import pytest
from pyoma2.functions import ssi as pyssi

from physgs.oma.intervals import REL_SIGMA_MAX, coverage, interval_hits, sigma_trusted
from physgs.oma.ssi import SSISettings, identify, ssi_poles
from physgs.oma.uncertainty import combine_blocks, pole_std
from test_oma_ssi import FS, simulate

FREQ, ZETA = [0.6, 1.2], [0.04, 0.08]
S = SSISettings(block_rows=12, order_max=16, nb=10, min_stable=3)
FACTOR = 3.0  # sigma / spread allowed either way (measured: 0.95 to 2.6, docs/blind.md)


@pytest.fixture(autouse=True)
def _quiet():
    logging.disable(logging.INFO)  # pyoma2 logs every stage
    yield
    logging.disable(logging.NOTSET)


@pytest.fixture(scope="module")
def records():
    """[R, 2] frequencies, damping ratios and their sigmas of the 24 independent 150 s records
    that show both modes and nothing else (at least 20 must)."""
    logging.disable(logging.INFO)
    out = []
    for seed in range(24):
        m = identify(simulate(FREQ, ZETA, 4, 150.0, 100 + seed, shape_seed=9), FS, S)
        if m.n_modes == 2:
            out.append((m.freq_hz, m.zeta, m.freq_std, m.zeta_std))
    assert len(out) >= 20, len(out)
    return [np.array(x) for x in zip(*out)]


def test_pole_std_is_pyoma2s_propagation():
    """At every even order, the same sigmas as pyOMA-2's SSI_poles (run at step 1, where it
    fills every singular vector); at step 2 pyOMA-2 drops every other singular vector's share
    and its sigmas come out smaller (the reason this module computes them itself)."""
    y = simulate([0.5, 0.9], [0.03, 0.05], 3, 100.0, 0)
    yt = (y - y.mean(0)).T
    H, T = pyssi.build_hank(yt, yt, 8, "cov", calc_unc=True, nb=20)
    obs1, A1, C1, _ = pyssi.SSI_fast(H, 8, 12, step=1)
    ref = pyssi.SSI_poles(obs1, A1, C1, 12, 1 / FS, step=1, xi_max=0.2, calc_unc=True, H=H, T=T)
    obs, A, C, _ = pyssi.SSI_fast(H, 8, 12, step=2)
    f2, *_, f2_std, _, _ = pyssi.SSI_poles(
        obs, A, C, 12, 1 / FS, step=2, xi_max=0.2, calc_unc=True, H=H, T=T
    )
    fs, zs = pole_std(H, T, obs, A, 3, 12, 2, 1 / FS, f2)
    for k, nn in enumerate(range(2, 13, 2), start=1):
        np.testing.assert_allclose(fs[:, k], ref[4][:, nn], rtol=1e-3, equal_nan=True)
        np.testing.assert_allclose(zs[:, k], ref[5][:, nn], rtol=1e-3, equal_nan=True)
    ok = np.isfinite(fs[:, 3:])
    assert np.median(f2_std[:, 3:][ok] / fs[:, 3:][ok]) < 0.9


def test_records_combine_as_their_mean():
    """The mean of R records' Hankel matrices has covariance (1/R^2) sum of theirs."""
    rng = np.random.default_rng(0)
    ts = [rng.normal(size=(30, 5)), rng.normal(size=(30, 7))]
    T = combine_blocks(ts)
    np.testing.assert_allclose(T @ T.T, (ts[0] @ ts[0].T + ts[1] @ ts[1].T) / 4)


def test_sigmas_match_the_spread_of_independent_records(records):
    f, z, fs, zs = records
    for k in range(2):
        for est, sd in ((f[:, k], fs[:, k]), (z[:, k], zs[:, k])):
            ratio = np.median(sd) / est.std(ddof=1)
            assert 1 / FACTOR < ratio < FACTOR, (k, ratio)


def test_intervals_cover_the_truth_on_long_records(records):
    f, z, fs, zs = records
    for est, sd, truth in ((f, fs, FREQ), (z, zs, ZETA)):
        c = coverage(interval_hits(est.ravel(), sd.ravel(), np.tile(truth, len(est))))
        assert c.n >= 40 and c.fraction >= 0.8, c
        assert c.lo <= 0.95 <= c.hi or c.fraction > 0.95, c


def test_sigma_rule_trusts_the_oracles_modes_and_refuses_a_short_records_spurious_ones():
    """Every true mode of the long records passes (relative damping sigma under 1/1.96); of a
    10 s record's poles, those far from both modes (spurious) mostly do not."""
    logging.disable(logging.INFO)
    p = ssi_poles([simulate(FREQ, ZETA, 4, 150.0, 7, shape_seed=9)], FS, S)
    true_pole = np.zeros(p.freq.shape, bool)
    for fr in FREQ:
        true_pole |= np.abs(p.freq - fr) / fr < 0.05
    ok = sigma_trusted(p.xi, p.xi_std)
    high = p.orders[None, :] >= 8  # the orders that resolve both modes
    assert ok[true_pole & high].mean() > 0.8
    spurious = np.isfinite(p.freq) & ~true_pole & high
    assert spurious.sum() >= 5 and ok[spurious].mean() < 0.5
    assert REL_SIGMA_MAX == pytest.approx(1 / 1.959964, rel=1e-5)


def test_coverage_counts_with_its_binomial_interval():
    c = coverage([True] * 19 + [False])
    assert (c.k, c.n, c.fraction) == (19, 20, 0.95)
    assert c.lo == pytest.approx(0.7513, abs=1e-3) and c.hi == pytest.approx(0.9987, abs=1e-3)
    assert interval_hits([1.0, 1.0, 1.0], [0.1, 0.1, np.nan], [1.19, 1.2, 1.0]).tolist() == [
        True,
        False,
        False,
    ]


def test_pyoma2_clustering_preset_runs_on_the_same_poles():
    """pyOMA-2's Dederichs preset, the best of its presets on the oracle (docs/blind.md), finds
    the three oracle modes from the poles the grouping reads, with their sigmas; an unknown
    preset is refused by name."""
    from physgs.oma.clustering import cluster_modes
    from test_oma_ssi import tolerances

    freq, zeta = [0.5, 0.9, 1.4], [0.03, 0.05, 0.08]
    s = SSISettings(block_rows=20, order_max=40, nb=10)
    p = ssi_poles([simulate(freq, zeta, 6, 200.0, 0)], FS, s)
    m = cluster_modes(p, s, "Dederichs")
    assert m.n_modes == 3, m.freq_hz
    for f, z, fh in zip(freq, zeta, m.freq_hz):
        assert abs(fh - f) / f < tolerances(f, z, 200.0)[0], (f, fh)
    assert np.all(m.freq_std > 0) and np.all(m.zeta_std > 0)
    with pytest.raises(ValueError, match="Magalhaes"):
        cluster_modes(p, s, "Magalhaes")


def test_interval_block_scores_the_trusted_parts_against_their_bones():
    """Three parts: two trusted with a mode (one interval holds its bone's omega, the other
    misses it), one trusted without a mode (not scored); the sigma rule keeps the part whose
    damping sigma is under 1/1.96 of its zeta."""
    from types import SimpleNamespace

    from physgs.oma.parts import PartModes
    from physgs.oma.run import interval_block

    nan = np.nan
    pm = PartModes(
        np.zeros(3, int),
        np.array([0, 1]),
        np.array([0, 1, -1]),
        omega=np.array([6.0, 8.0, nan]),
        zeta=np.array([0.05, 0.10, nan]),
        omega_std=np.array([0.1, 0.1, nan]),
        zeta_std=np.array([0.03, 0.04, nan]),
    )
    match = SimpleNamespace(bone=np.array([1, 0, 0]), trusted=np.array([True, True, True]))
    truth = SimpleNamespace(omega=np.array([9.0, 6.1]), zeta=np.array([0.2, 0.06]))
    b = interval_block(pm, match, truth)
    assert b["coverage"]["omega"]["k"] == 1 and b["coverage"]["omega"]["n"] == 2
    assert b["coverage"]["zeta"]["k"] == 1  # 0.05 +- 0.059 holds 0.06; 0.10 +- 0.078 not 0.2
    assert b["sigma_trusted"] == [False, True, False] and b["n_both_trusted"] == 1
    assert b["median_rel_std"]["zeta"] == pytest.approx(0.5)  # of 0.6 and 0.4


def test_more_data_blocks_than_the_record_holds_stops_naming_the_key():
    """100 samples and 12 block rows leave 77 Hankel columns: 38 blocks of two at most."""
    from physgs.oma.ssi import check_record

    check_record(100, 4, SSISettings(block_rows=12, order_max=16, nb=38))
    with pytest.raises(ValueError, match="oma/ssi/nb") as e:
        check_record(100, 4, SSISettings(block_rows=12, order_max=16, nb=39))
    assert "2 to 38" in e.value.msg
