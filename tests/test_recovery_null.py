"""Null control against an independent oracle (scipy lsim + numpy corrcoef)."""

import numpy as np
import pytest
from scipy import stats

from physgs.recovery.null import draw_null_omegas, null_control
from physgs.testbed.stats import nearest_bone_gap
from oracles import forced_lsim


def test_draws_log_uniform_seeded_and_in_range():
    ob = np.array([2.0, 3.0, 9.0])
    d = draw_null_omegas(ob, 32, 8, seed=3)
    assert d.shape == (8, 32) and d.min() >= 2.0 and d.max() <= 9.0
    np.testing.assert_array_equal(d, draw_null_omegas(ob, 32, 8, seed=3))
    assert not np.array_equal(d, draw_null_omegas(ob, 32, 8, seed=4))
    big = draw_null_omegas(ob, 4000, 1, seed=0)[0]
    assert stats.kstest((np.log(big) - np.log(2)) / np.log(4.5), "uniform").pvalue > 0.01


def test_nearest_bone_gap_hand_values():
    ob = np.array([1.0, 2.0, 4.0])
    np.testing.assert_allclose(
        nearest_bone_gap(np.array([1.1, 1.6, 3.0, 4.0]), ob), [0.1, 0.2, 0.25, 0.0]
    )


def test_null_control_matches_oracle():
    pytest.importorskip("physgs.models.oscillator")
    rng = np.random.default_rng(0)
    fps, L, n_train = 24, 240, 200
    dt = 1 / fps
    T = L + n_train + 10
    wind = 6.0 + 1.5 * rng.standard_normal(T)
    vbar = 6.0
    u = wind**2 - vbar**2  # lsim's first-order hold = the solver's linear v^2 interpolation
    omega_b = 2 * np.pi * np.geomspace(0.35, 1.5, 12)
    bone_theta = np.stack([forced_lsim(w, 0.08, u, dt) for w in omega_b])[:, L : L + n_train]
    K, D, zeta0, seed = 5, 8, 0.15, 11
    res = null_control(
        omega_b,
        bone_theta,
        wind,
        n_parts=K,
        zeta_init=zeta0,
        vbar=vbar,
        dt=dt,
        substeps=2,
        lead_in_frames=L,
        n_train=n_train,
        seed=seed,
        n_draws=D,
    )
    draws = draw_null_omegas(omega_b, K, D, seed)
    np.testing.assert_array_equal(res.omega, draws)
    exp_n, exp_med, exp_r2 = [], [], []
    for om in draws:
        parts = np.stack([forced_lsim(w, zeta0, u, dt) for w in om])[:, L : L + n_train]
        c = np.abs(np.corrcoef(parts, bone_theta)[:K, K:])
        best = c.argmax(1)
        ok = c[np.arange(K), best] >= 0.7
        rel = np.abs(om - omega_b[best]) / omega_b[best]
        exp_n.append(ok.sum())
        exp_med.append(np.median(rel[ok]) if ok.any() else np.nan)
        exp_r2.append(
            stats.pearsonr(np.log(om[ok]), np.log(omega_b[best][ok]))[0] ** 2
            if ok.sum() >= 3
            else np.nan
        )
    np.testing.assert_array_equal(res.n_trusted, exp_n)
    np.testing.assert_allclose(res.median_rel_err, exp_med, rtol=1e-9)
    np.testing.assert_allclose(res.loglog_r2, exp_r2, rtol=1e-9)
    assert res.median_median_rel_err == pytest.approx(np.nanmedian(exp_med))
    assert res.nearest_bone_gap == pytest.approx(
        np.median(np.min(np.abs(draws[..., None] - omega_b) / omega_b, axis=-1))
    )
    # a random frequency sits near some bone on this grid, and the matcher finds that bone
    assert res.median_n_trusted >= K - 1
    assert res.median_median_rel_err < 0.15
