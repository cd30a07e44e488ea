"""Per-part damping scores (physgs.recovery.damping_scores) against hand-built answers and
scipy / numpy references; the untrained damping null."""

import json

import numpy as np
import pytest
import scipy.stats

from physgs.recovery.damping_scores import (
    MIN_CORR_PARTS,
    DampingNull,
    DampingScores,
    damping_null,
    damping_scores,
    draw_null_zetas,
    log_correlation,
    loglog_exponent,
    score_match,
)
from physgs.recovery.matcher import match_parts
from physgs.recovery.null import draw_null_omegas

ZETA_RANGE = (0.03, 0.2)


def _truth(B=40, seed=0):
    """omega [B] rad/s over the 0.35-1.5 Hz band and zeta [B] log-uniform on ZETA_RANGE."""
    rng = np.random.default_rng(seed)
    omega = 2 * np.pi * np.exp(rng.uniform(np.log(0.35), np.log(1.5), B))
    zeta = np.exp(rng.uniform(*np.log(ZETA_RANGE), B))
    return omega, zeta


def test_hand_built_scores():
    bone = np.array([0, 1, 2, 3, 1])
    trusted = np.array([True, True, True, False, True])
    zeta_b = np.array([0.05, 0.1, 0.2, 0.03])
    omega_b = np.array([2.0, 4.0, 6.0, 8.0])
    zeta_hat = np.array([0.06, 0.1, 0.1, 0.5, 0.15])  # part 3 (untrusted) is far off: ignored
    omega_hat = np.array([2.0, 4.0, 6.0, 8.0, 4.0])
    s = damping_scores(bone, trusted, zeta_hat, omega_hat, zeta_b, omega_b)
    assert s.n_trusted == 4
    # relative errors 0.2, 0, 0.5, 0.5 -> median 0.35
    assert s.median_rel_err == pytest.approx(0.35, abs=1e-12)
    ref = scipy.stats.pearsonr(np.log([0.06, 0.1, 0.1, 0.15]), np.log([0.05, 0.1, 0.2, 0.1]))
    assert s.log_corr == pytest.approx(ref[0], abs=1e-12)
    om = np.array([2.0, 4.0, 6.0, 4.0])
    p_ref = np.polyfit(np.log(om), np.log(np.array([0.06, 0.1, 0.1, 0.15]) * om), 1)[0]
    assert s.gamma_exponent == pytest.approx(p_ref, abs=1e-12)
    p_true = np.polyfit(np.log(om), np.log(np.array([0.05, 0.1, 0.2, 0.1]) * om), 1)[0]
    assert s.gamma_exponent_true == pytest.approx(p_true, abs=1e-12)


@pytest.mark.parametrize("p", [0.0, 0.4, 1.0, 2.0])
def test_gamma_exponent_of_an_exact_power_law(p):
    """gamma_hat = c omega_hat^p exactly: p comes back; p = 1 is a constant ratio, p = 0 a
    frequency-independent decay rate (the paper's diagnosis)."""
    omega = 2 * np.pi * np.linspace(0.35, 1.5, 9)
    zeta_hat = 0.3 * omega**p / omega  # gamma = 0.3 omega^p
    assert loglog_exponent(omega, zeta_hat * omega) == pytest.approx(p, abs=1e-12)


def test_constant_ratio_truth_has_exponent_one_and_a_rate_model_zero():
    omega, _ = _truth()
    B = len(omega)
    bone, trusted = np.arange(B), np.ones(B, bool)
    const = np.full(B, 0.08)
    rate_model = 0.6 / omega  # decay rate 0.6 / s at every frequency
    s = damping_scores(bone, trusted, rate_model, omega, const, omega)
    assert s.gamma_exponent_true == pytest.approx(1.0, abs=1e-12)
    assert s.gamma_exponent == pytest.approx(0.0, abs=1e-12)
    assert s.log_corr == 0.0  # the constant truth has no spread: no ranking to recover


def test_against_scipy_on_random_data():
    rng = np.random.default_rng(7)
    omega_b, zeta_b = _truth(B=30)
    K = 50
    bone = rng.integers(0, 30, K)
    trusted = rng.uniform(size=K) < 0.7
    zeta_hat = zeta_b[bone] * np.exp(0.3 * rng.standard_normal(K))
    omega_hat = omega_b[bone] * np.exp(0.1 * rng.standard_normal(K))
    s = damping_scores(bone, trusted, zeta_hat, omega_hat, zeta_b, omega_b)
    t, b = trusted, bone[trusted]
    assert s.n_trusted == t.sum()
    assert s.median_rel_err == pytest.approx(
        np.median(np.abs(zeta_hat[t] - zeta_b[b]) / zeta_b[b]), rel=1e-12
    )
    assert s.log_corr == pytest.approx(
        scipy.stats.pearsonr(np.log(zeta_hat[t]), np.log(zeta_b[b]))[0], abs=1e-12
    )
    lr = scipy.stats.linregress(np.log(omega_hat[t]), np.log(zeta_hat[t] * omega_hat[t]))
    assert s.gamma_exponent == pytest.approx(lr.slope, abs=1e-12)
    lr = scipy.stats.linregress(np.log(omega_b[b]), np.log(zeta_b[b] * omega_b[b]))
    assert s.gamma_exponent_true == pytest.approx(lr.slope, abs=1e-12)
    assert s.log_corr > 0.5  # 30% log noise on a 6.7x range: clearly recovered


def test_undefined_scores_are_nan():
    zb, ob = np.array([0.05, 0.1, 0.2]), np.array([2.0, 4.0, 6.0])
    none = damping_scores([0, 1, 2], [False] * 3, [0.1] * 3, [2.0, 4.0, 6.0], zb, ob)
    assert none.n_trusted == 0
    assert np.isnan(
        [none.median_rel_err, none.log_corr, none.gamma_exponent, none.gamma_exponent_true]
    ).all()
    two = damping_scores([0, 1, 2], [True, True, False], [0.1, 0.2, 0.3], [2.0, 4.0, 6.0], zb, ob)
    assert two.n_trusted == 2 < MIN_CORR_PARTS
    assert np.isnan(two.log_corr) and np.isfinite(two.median_rel_err)
    assert np.isfinite(two.gamma_exponent)  # two points make a line
    same_omega = damping_scores([0, 1, 2], [True] * 3, [0.1, 0.2, 0.3], [4.0] * 3, zb, ob)
    assert np.isnan(same_omega.gamma_exponent)
    assert np.isnan(log_correlation([0.1, 0.2], [0.1, 0.3]))
    with pytest.raises(ValueError, match="positive"):
        damping_scores([0], [True], [-0.1], [2.0], zb, ob)
    with pytest.raises(ValueError, match="matched bone"):
        damping_scores([5], [True], [0.1], [2.0], zb, ob)


def test_score_match_reads_the_matcher_result():
    """Parts that replay three of four bones' trajectories: the matcher's bones and trust feed
    the scores exactly as the arrays would."""
    t = np.arange(200) / 24
    omega_b = 2 * np.pi * np.array([0.4, 0.7, 1.1, 1.4])
    zeta_b = np.array([0.03, 0.06, 0.12, 0.2])
    bones = np.sin(omega_b[:, None] * t + np.arange(4)[:, None])  # [B, T]
    rng = np.random.default_rng(2)
    parts = np.stack([bones[2], bones[0], bones[3], rng.standard_normal(200)])  # [K, T]
    omega_hat = omega_b[[2, 0, 3, 1]] * 1.05
    m = match_parts(parts, bones, omega_hat, omega_b)
    np.testing.assert_array_equal(m.trusted, [True, True, True, False])
    zeta_hat = np.array([0.1, 0.04, 0.25, 0.5])
    s = score_match(m, zeta_hat, zeta_b, omega_b)
    assert s == damping_scores(m.bone, m.trusted, zeta_hat, omega_hat, zeta_b, omega_b)
    rel = np.abs(zeta_hat[:3] - zeta_b[[2, 0, 3]]) / zeta_b[[2, 0, 3]]
    assert s.median_rel_err == pytest.approx(np.median(rel), rel=1e-12)


# --- the untrained null --------------------------------------------------------------------


def test_null_draws_are_log_uniform_in_range_and_seeded():
    d = draw_null_zetas(ZETA_RANGE, 50, 400, seed=3)
    assert d.shape == (400, 50)
    assert d.min() >= ZETA_RANGE[0] and d.max() <= ZETA_RANGE[1]
    u = (np.log(d) - np.log(ZETA_RANGE[0])) / np.log(ZETA_RANGE[1] / ZETA_RANGE[0])
    np.testing.assert_allclose(np.quantile(u, [0.1, 0.5, 0.9]), [0.1, 0.5, 0.9], atol=0.01)
    np.testing.assert_array_equal(d, draw_null_zetas(ZETA_RANGE, 50, 400, seed=3))
    assert not np.allclose(d, draw_null_zetas(ZETA_RANGE, 50, 400, seed=4))
    # its own stream: not the frequency null's draws mapped onto the same range
    om = draw_null_omegas(np.array(ZETA_RANGE), 50, 400, seed=3)
    assert not np.allclose(d, om)


def test_null_is_scored_like_the_model_against_the_same_matching():
    omega_b, zeta_b = _truth()
    rng = np.random.default_rng(1)
    K = 32
    bone = rng.integers(0, len(omega_b), K)
    trusted = rng.uniform(size=K) < 0.75
    omega_hat = omega_b[bone] * np.exp(0.05 * rng.standard_normal(K))
    null = damping_null(bone, trusted, omega_hat, zeta_b, omega_b, ZETA_RANGE, seed=5, n_draws=6)
    assert null.zeta.shape == (6, K) and null.n_trusted == trusted.sum()
    np.testing.assert_array_equal(null.zeta, draw_null_zetas(ZETA_RANGE, K, 6, seed=5))
    for i, z in enumerate(null.zeta):
        s = damping_scores(bone, trusted, z, omega_hat, zeta_b, omega_b)
        assert (null.median_rel_err[i], null.log_corr[i], null.gamma_exponent[i]) == (
            s.median_rel_err,
            s.log_corr,
            s.gamma_exponent,
        )
    back = DampingNull.from_dict(json.loads(json.dumps(null.to_dict())))
    np.testing.assert_array_equal(back.zeta, null.zeta)
    assert back.median_log_corr == null.median_log_corr and back.seed == 5


def test_null_has_no_ranking_and_a_ratio_exponent_and_a_recovering_model_beats_it():
    """Draws independent of the truth: log correlation about 0 and gamma exponent about 1
    (averaged over many draws); a model with 10% log error beats it on every score."""
    omega_b, zeta_b = _truth(B=60, seed=2)
    B = len(omega_b)
    bone, trusted = np.arange(B), np.ones(B, bool)
    null = damping_null(bone, trusted, omega_b, zeta_b, omega_b, ZETA_RANGE, seed=0, n_draws=300)
    # r of independent samples: sd about 1/sqrt(B) = 0.13 per draw, 0.008 over 300 draws
    assert abs(null.log_corr.mean()) < 0.04
    assert abs(null.gamma_exponent.mean() - 1.0) < 0.1
    rng = np.random.default_rng(9)
    good = damping_scores(
        bone, trusted, zeta_b * np.exp(0.1 * rng.standard_normal(B)), omega_b, zeta_b, omega_b
    )
    assert good.log_corr > np.quantile(null.log_corr, 0.99)
    assert good.median_rel_err < np.quantile(null.median_rel_err, 0.01)


def test_scores_round_trip_through_json():
    s = damping_scores([0, 1], [True, False], [0.1, 0.2], [2.0, 4.0], [0.05, 0.1], [2.0, 4.0])
    back = DampingScores.from_dict(json.loads(json.dumps(s.to_dict())))
    assert back.n_trusted == 1 and back.median_rel_err == pytest.approx(1.0)
    assert np.isnan([back.log_corr, back.gamma_exponent, back.gamma_exponent_true]).all()
