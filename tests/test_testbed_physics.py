"""Ground-truth oscillators against independent oracles; lead-in; wind spectrum; conditions."""

import copy

import numpy as np
import pytest

from physgs.config import load
from physgs.testbed import physics
from physgs.testbed.dataset import simulate_tree
from physgs.testbed.wind import make_wind
from oracles import forced_lsim, free_response

CFG = load("config/trees.yaml", "quick")
TB = CFG["testbed"]


def test_simulate_matches_lsim_with_linear_interpolated_forcing():
    rng = np.random.default_rng(3)
    fps, T = 24, 400
    omega = 2 * np.pi * np.array([0.35, 0.8, 1.5])
    zeta = np.array([0.08, 0.08, 0.2])
    u = rng.normal(size=(T, 3)) * omega**2 * 0.01  # ~0.01 rad quasi-static scale
    th = physics.simulate(omega, zeta, u, 1.0 / fps)
    assert np.abs(th).max() > 1e-3
    for b in range(3):
        y = forced_lsim(omega[b], zeta[b], u[:, b], 1.0 / fps)
        np.testing.assert_allclose(th[:, b], y, atol=1e-6, rtol=0)


def test_unforced_response_matches_closed_form():
    omega, zeta, th0, fps = np.array([2 * np.pi * 0.6]), np.array([0.08]), 0.05, 24
    T = 300
    th = physics.simulate(omega, zeta, np.zeros((T, 1)), 1.0 / fps, x0=np.array([[th0, 0.0]]))
    t = np.arange(T) / fps
    exact = free_response(omega[0], zeta[0], th0, t)
    np.testing.assert_allclose(th[:, 0], exact, atol=1e-9, rtol=0)


@pytest.fixture(scope="module")
def sparse_sims():
    p = CFG["presets"]["sparse"]
    out = {}
    for tau in (1.5, 3.0):
        tb = copy.deepcopy(TB)
        tb["lead_in_tau"] = tau
        out[tau] = simulate_tree(tb, p, seed=CFG["seed"], tree="sparse")
    return out


def test_doubling_lead_in_leaves_recorded_window_unchanged(sparse_sims):
    a, b = sparse_sims[1.5].truth, sparse_sims[3.0].truth
    assert b.lead_in_frames >= 2 * a.lead_in_frames - 1
    wa, wb = a.theta[:, a.lead_in_frames :], b.theta[:, b.lead_in_frames :]
    assert np.abs(wa - wb).max() < 1e-6
    # the same wind realisation extends backwards
    np.testing.assert_array_equal(
        sparse_sims[1.5].wind[:, a.lead_in_frames :], sparse_sims[3.0].wind[:, b.lead_in_frames :]
    )
    # control: started from rest instead of the steady state, a start transient is there
    tr = a
    u = sparse_sims[1.5].wind.astype(np.float64) ** 2 - tr.vbar[:, None] ** 2
    rest = physics.simulate(tr.omega, tr.zeta, u[:, :, None] * tr.gain, 1.0 / tr.fps)
    assert np.abs(rest[:, tr.lead_in_frames :] - wa).max() > 1e-4


def test_periodic_steady_state_equals_long_run_from_rest():
    rng = np.random.default_rng(5)
    P, dt = 240, 1 / 24
    omega, zeta = 2 * np.pi * np.array([0.35, 1.2]), np.array([0.08, 0.08])
    one = rng.normal(size=(P, 2))
    u = np.concatenate([np.tile(one, (12, 1)), one[:1]])  # 12 periods (120 s), periodic
    x0 = physics.periodic_steady_state(omega, zeta, u[: P + 1], dt)
    ss = physics.simulate(omega, zeta, u[: P + 1], dt, x0=x0)
    long = physics.simulate(omega, zeta, u, dt)  # transient decays by exp(-0.176 * 110) ~ 4e-9
    np.testing.assert_allclose(long[-P - 1 :], ss, atol=1e-9 * np.abs(ss).max())


def test_lead_in_is_one_and_a_half_tau_max(sparse_sims):
    tr = sparse_sims[1.5].truth
    tau_max = 1.0 / (TB["zeta"] * tr.omega.min())
    assert tr.lead_in_frames == int(np.ceil(1.5 * tau_max * tr.fps))


def test_conditions_are_exact_rescalings(sparse_sims):
    s = sparse_sims[1.5]
    cond = np.asarray(TB["conditions"])
    assert cond[0] == 1.0
    for c in range(1, len(cond)):
        np.testing.assert_allclose(s.wind[c], s.wind[0].astype(np.float64) * cond[c], rtol=1e-6)
    np.testing.assert_allclose(s.truth.vbar, cond * TB["wind"]["v0"], rtol=1e-15)
    # truth minus the response from rest to g (v^2 - vbar^2) must be a free oscillation, which
    # obeys D[k+1] = 2 exp(-zeta w h) cos(w_d h) D[k] - exp(-2 zeta w h) D[k-1] exactly
    tr = s.truth
    h = 1.0 / tr.fps
    u = s.wind.astype(np.float64) ** 2 - tr.vbar[:, None] ** 2
    D = tr.theta - physics.simulate(tr.omega, tr.zeta, u[:, :, None] * tr.gain, h)
    wd = tr.omega * np.sqrt(1 - tr.zeta**2)
    a1 = 2 * np.exp(-tr.zeta * tr.omega * h) * np.cos(wd * h)
    a2 = np.exp(-2 * tr.zeta * tr.omega * h)
    resid = D[:, 2:] - a1 * D[:, 1:-1] + a2 * D[:, :-2]
    assert np.abs(D).max() > 1e-4  # the steady-state start is not rest
    assert np.abs(resid).max() < 1e-10


def test_wind_spectrum_flat_inside_band_and_zero_outside():
    w = TB["wind"]
    wf = make_wind(
        v0=w["v0"],
        turbulence_intensity=w["turbulence_intensity"],
        f_lo_hz=w["f_lo_hz"],
        f_hi_hz=w["f_hi_hz"],
        seed_seq=np.random.SeedSequence(7),
        period_s=60.0,
    )
    fs, n = 32.0, 32 * 60  # exactly one period: every component falls on an FFT bin
    v = wf.speed(np.arange(n) / fs)
    assert abs(v.mean() - w["v0"]) < 1e-9
    assert abs(v.std() - w["v0"] * w["turbulence_intensity"]) < 1e-9
    P = np.abs(np.fft.rfft(v - v.mean())) ** 2
    f = np.fft.rfftfreq(n, 1 / fs)
    band = (f >= w["f_lo_hz"] - 1e-9) & (f <= w["f_hi_hz"] + 1e-9)
    assert P[~band].sum() < 1e-20 * P.sum()
    assert P[band].std() / P[band].mean() < 1e-6  # flat
    assert band.sum() == round((w["f_hi_hz"] - w["f_lo_hz"]) * 60) + 1
