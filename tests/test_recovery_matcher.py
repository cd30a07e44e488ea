"""Matcher and damping summary on constructed trajectories with known answers (scipy oracle)."""

import numpy as np
import pytest
from scipy import stats

from physgs.recovery import damping_summary, loglog_r2, match_parts, pearson_matrix
from oracles import forced_lsim


@pytest.fixture(scope="module")
def bones():
    rng = np.random.default_rng(0)
    dt, T = 1 / 24, 600
    forcing = rng.standard_normal(T)
    omega = 2 * np.pi * np.array([0.35, 0.5, 0.7, 1.0, 1.5])
    theta = np.stack([forced_lsim(w, 0.08, forcing, dt) for w in omega])[:, 200:]
    return omega, theta


def test_pearson_matches_numpy(bones):
    _, theta = bones
    np.testing.assert_allclose(pearson_matrix(theta[:3], theta), np.corrcoef(theta)[:3], atol=1e-12)


def test_copies_with_noise_and_sign_flips_match_exactly(bones):
    omega, theta = bones
    rng = np.random.default_rng(1)
    perm = np.array([3, 0, 4, 4, 1, 2])
    sign = np.array([1, -1, 1, -1, -1, 1])
    parts = sign[:, None] * 2.5 * theta[perm] + 0.05 * theta.std() * rng.standard_normal(
        (6, theta.shape[1])
    )
    omega_hat = omega[perm] * np.array([1.1, 0.95, 1.0, 1.02, 0.8, 1.3])
    m = match_parts(parts, theta, omega_hat, omega)
    np.testing.assert_array_equal(m.bone, perm)
    assert m.trusted.all() and m.n_trusted == 6 and np.all(m.corr > 0.99)
    expected = np.abs(omega_hat - omega[perm]) / omega[perm]  # 0.1, 0.05, 0, 0.02, 0.2, 0.3
    np.testing.assert_allclose(m.rel_err, expected, atol=1e-12)
    assert m.median_rel_err == pytest.approx(0.075)
    r = stats.pearsonr(np.log(omega_hat), np.log(omega[perm]))[0]
    assert m.loglog_r2 == pytest.approx(r**2, abs=1e-12)


def test_constant_and_unrelated_parts_untrusted_never_nan(bones):
    omega, theta = bones
    rng = np.random.default_rng(2)
    parts = np.stack(
        [
            np.full(theta.shape[1], 0.3),
            np.zeros(theta.shape[1]),
            rng.standard_normal(theta.shape[1]),
            theta[2],
        ]
    )
    m = match_parts(parts, theta, np.full(4, 3.0), omega)
    assert np.all(np.isfinite(m.corr)) and np.all(np.isfinite(m.rel_err))
    assert m.corr[0] == 0 and m.corr[1] == 0
    np.testing.assert_array_equal(m.trusted, [False, False, False, True])
    assert m.n_trusted == 1
    assert m.median_rel_err == pytest.approx(abs(3.0 - omega[2]) / omega[2])
    assert np.isnan(m.loglog_r2)  # undefined with one trusted part
    none = match_parts(parts[:2], theta, np.full(2, 3.0), omega)
    assert none.n_trusted == 0 and np.isnan(none.median_rel_err)


def test_threshold_is_inclusive():
    t = np.linspace(0, 10, 400)
    u = np.sin(t) - np.sin(t).mean()
    u /= np.linalg.norm(u)
    v = np.cos(3 * t) - np.cos(3 * t).mean()
    v -= (v @ u) * u  # centred, orthogonal to u: corr(c u + sqrt(1-c^2) v, u) = c exactly
    v /= np.linalg.norm(v)
    for c, ok in [(0.7 + 1e-9, True), (0.7 - 1e-6, False)]:
        part = c * u + np.sqrt(1 - c**2) * v
        m = match_parts(part[None], u[None], np.array([1.0]), np.array([1.0]))
        assert m.corr[0] == pytest.approx(c, abs=1e-12)
        assert bool(m.trusted[0]) is ok


def test_loglog_r2_degenerate_is_zero_not_nan():
    assert loglog_r2(np.array([1.0, 2.0, 3.0]), np.array([2.0, 2.0, 2.0])) == 0.0


def test_damping_constant_ratio_and_constant_rate():
    omega = 2 * np.pi * np.array([0.4, 0.6, 0.9, 1.4])
    d = damping_summary(omega, np.full(4, 0.08), zeta_true=0.08)
    assert d.median_zeta == pytest.approx(0.08)
    assert d.slope == pytest.approx(0.08) and d.intercept == pytest.approx(0.0, abs=1e-12)
    assert d.loglog_exponent == pytest.approx(1.0)
    rate = 0.4  # 1/s, frequency-independent decay rate: zeta = rate / omega
    d2 = damping_summary(omega, rate / omega, zeta_true=0.08)
    assert d2.slope == pytest.approx(0.0, abs=1e-12) and d2.intercept == pytest.approx(rate)
    assert d2.loglog_exponent == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(d2.gamma, rate)
    assert d2.median_zeta == pytest.approx(np.median(rate / omega))
    with pytest.raises(ValueError, match="positive"):
        damping_summary(omega, -np.ones(4), 0.08)


def test_restricted_scores_only_parts_on_visible_bones():
    from physgs.recovery.matcher import MatchResult, restricted

    m = MatchResult(
        bone=np.array([0, 1, 2, 2]),
        corr=np.array([0.9, 0.9, 0.5, 0.95]),
        trusted=np.array([True, True, False, True]),
        omega_hat=np.ones(4),
        omega_true=np.ones(4),
        rel_err=np.array([0.01, 0.20, 0.50, 0.03]),
        n_trusted=3,
        n_parts=4,
        median_rel_err=0.03,
        loglog_r2=float("nan"),
    )
    # bone 1 invisible: the trusted parts on bones 0 and 2 remain (errors 0.01 and 0.03)
    n, med = restricted(m, np.array([True, False, True]))
    assert n == 2 and med == pytest.approx(0.02)
    assert restricted(m, np.ones(3, bool)) == (3, pytest.approx(0.03))  # everything visible
    n, med = restricted(m, np.zeros(3, bool))
    assert n == 0 and np.isnan(med)
