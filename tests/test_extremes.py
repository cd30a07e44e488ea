"""Numerics at the extremes: damping, step size, wind, K, precision, degenerate matches.

Oracles are independent of the solver: scipy.signal.lsim (exact first-order-hold solution by
matrix exponential, float64) and closed-form step responses. Bounds are derived in each test.
"""

import math
from types import SimpleNamespace

import numpy as np
import pytest
import torch

from physgs.models import build_model
from physgs.models.oscillator import (
    STABILITY_GUARD,
    StabilityError,
    fastest_rate,
    integrate,
    required_substeps,
)
from physgs.recovery.record import score_recovery
from physgs.recovery.run import recover_model
from oracles import gusty_wind, model_context, quick_models_cfg, step_response, t64, wind_lsim

FPS = 24
DT = 1.0 / FPS
LEAD_IN = 205  # the testbed's lead-in: 1.5 / (0.08 * 2 pi 0.35 Hz) s at 24 fps
T_REC = LEAD_IN + 350  # the whole recording: lead-in + 300 training + 50 tail frames
EPS32 = float(np.finfo(np.float32).eps)


def _rel(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max())


def _rk4_bound(omega_h, zeta, n_steps):
    """Relative error bound of RK4 on a forced oscillator.

    RK4's one-step error on the modes e^{lambda h} is |z|^5/120 (z = lambda h, |z| = omega h
    for zeta <= 1). A stable response forgets errors over ~1/(zeta omega h) steps, so they add up
    to at most (omega h)^5/120 * min(n_steps, 1/(zeta omega h)); a factor 2 covers the forcing
    interpolation and the non-asymptotic part.
    """
    return 2 * omega_h**5 / 120 * min(n_steps, 1.0 / (zeta * omega_h))


# -- damping extremes --------------------------------------------------------------------------


def test_nearly_undamped_matches_lsim_and_closed_form():
    zeta, omega, n = 1e-4, 2 * math.pi * 0.7, 4
    wind = gusty_wind(T_REC)
    th = integrate(t64(omega), t64(zeta), t64(0.02), wind, 6.0, DT, n)[0].numpy()
    ref = wind_lsim(omega, zeta, 0.02, wind, 6.0, DT)
    assert np.isfinite(th).all()
    assert _rel(th, ref) < _rk4_bound(omega * DT / n, zeta, n * (T_REC - 1))
    # step response of a nearly undamped oscillator keeps its amplitude over the recording
    v, g = 5.0, 0.02
    t = np.arange(T_REC) * DT
    step = integrate(t64(omega), t64(zeta), t64(g), np.full(T_REC, v), 0.0, DT, n)[0].numpy()
    exact = step_response(omega, zeta, g * v**2, t)
    assert _rel(step, exact) < _rk4_bound(omega * DT / n, zeta, n * (T_REC - 1))


@pytest.mark.parametrize("zeta", [1.0, 2.5])
def test_critically_and_over_damped_match_closed_form_and_lsim(zeta):
    omega, g, v, n = 2 * math.pi * 1.2, 0.05, 5.0, 4
    t = np.arange(T_REC) * DT
    F = g * v**2
    if zeta == 1.0:
        exact = F / omega**2 * (1 - np.exp(-omega * t) * (1 + omega * t))
    else:
        s1 = -omega * (zeta - math.sqrt(zeta**2 - 1))  # slow pole
        s2 = -omega * (zeta + math.sqrt(zeta**2 - 1))  # stiff pole
        exact = F / omega**2 * (1 + (s2 * np.exp(s1 * t) - s1 * np.exp(s2 * t)) / (s1 - s2))
    step = integrate(t64(omega), t64(zeta), t64(g), np.full(T_REC, v), 0.0, DT, n)[0].numpy()
    # no oscillation to accumulate phase error; the stiff pole's |lambda| h sets the error
    lam_h = float(fastest_rate(omega, zeta)) * DT / n
    assert _rel(step, exact) < lam_h**5 / 120 * 50
    assert np.all(np.diff(step) >= -1e-15)  # critically/over-damped step response never overshoots
    # turbulent wind: the error now also carries the forcing's slope, so check the order instead
    # (error / 16 per halving of h, RK4) and an absolute level against lsim
    wind = gusty_wind(T_REC, seed=3)
    ref = wind_lsim(omega, zeta, g, wind, 6.0, DT)
    errs = [
        _rel(integrate(t64(omega), t64(zeta), t64(g), wind, 6.0, DT, k)[0].numpy(), ref)
        for k in (4, 8, 16)
    ]
    assert errs[-1] < 1e-6
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all((ratios > 12) & (ratios < 20)), ratios


def test_over_damped_stiff_pole_is_guarded_not_blown_up():
    """omega*h = 1 passes the omega guard, but zeta = 2.5's stiff pole (4.79 omega) does not:
    before the fix RK4 returned ~1e207 here without a word."""
    with pytest.raises(StabilityError, match=r"zeta 2.5.*substeps >= 5"):
        integrate(t64(24.0), t64(2.5), t64(1.0), np.full(50, 6.0), 0.0, DT, 1)
    n = required_substeps(float(fastest_rate(24.0, 2.5)), DT)
    th = integrate(t64(24.0), t64(2.5), t64(1.0), np.full(400, 6.0), 0.0, DT, n)[0]
    assert float(th[-1]) == pytest.approx(36.0 / 24.0**2, rel=1e-6)  # static deflection F/omega^2


def test_model_substeps_cover_an_over_damped_zeta_bound():
    cfg = quick_models_cfg()
    cfg["ours"]["zeta"] = [0.01, 3.0]  # a config that allows over-damped parts
    model = build_model("ours", _ctx()[0], cfg)
    hi = 2 * math.pi * cfg["ours"]["omega_hz"][1]
    assert fastest_rate(hi, 3.0) * model.dt / model.substeps <= STABILITY_GUARD
    with torch.no_grad():
        model.omega_raw.fill_(60.0)
        model.zeta_raw.fill_(60.0)
        model.gain_raw.fill_(0.1)
    theta = model.part_theta(torch.tensor(_ctx()[1]))
    assert torch.isfinite(theta).all() and theta.abs().max() < 1.0


# -- step size at the band's ends ---------------------------------------------------------------


@pytest.mark.parametrize("omega", [2 * math.pi * 0.1, 2 * math.pi * 3.0, 24.0])
@pytest.mark.parametrize("zeta", [0.01, 0.08, 0.5])
def test_band_ends_at_the_coarsest_allowed_step_stay_within_the_rk4_bound(omega, zeta):
    """The coarsest step integrate accepts is required_substeps' (omega h <= guard; 24 rad/s is
    exactly at the guard with one step per frame). Accuracy there is bounded, not exact: at
    omega h = 1 and zeta = 0.08 RK4 is ~7% off lsim; see _rk4_bound."""
    n = required_substeps(omega, DT)
    assert omega * DT / n <= STABILITY_GUARD and (n == 1 or omega * DT / (n - 1) > STABILITY_GUARD)
    wind = gusty_wind(T_REC, seed=1)
    th = integrate(t64(omega), t64(zeta), t64(1.0), wind, 6.0, DT, n)[0].numpy()
    ref = wind_lsim(omega, zeta, 1.0, wind, 6.0, DT)
    assert _rel(th, ref) < _rk4_bound(omega * DT / n, zeta, n * (T_REC - 1))


def test_beyond_the_guard_stops_naming_omega_step_and_substeps():
    om = 24.0 * 1.01  # just beyond omega h = 1 at one step per frame
    with pytest.raises(StabilityError) as e:
        integrate(t64(om), t64(0.1), t64(1.0), gusty_wind(20), 6.0, DT, 1)
    msg = str(e.value)
    assert "24.24" in msg and "0.04167" in msg and "substeps >= 2" in msg
    integrate(t64(om), t64(0.1), t64(1.0), gusty_wind(20), 6.0, DT, 2)  # the named fix works


def test_float32_omega_at_the_top_of_the_band_passes_the_guard():
    """Bug found here: omega is float32 in the model, its substeps come from the float64 bound.
    With the band's top at omega h = 5 - 3e-7 per frame, required_substeps gives 5 but the
    float32 omega at saturation rounds to 120.0000076 rad/s > 5 * 24, and the guard refused it
    mid-training. The guard now allows float32 rounding (GUARD_RTOL)."""
    cfg = quick_models_cfg()
    cfg["ours"].update(omega_hz=[0.1, 119.999964 / (2 * math.pi)], substeps=1, rk4_guard=1.0)
    model = build_model("ours", _ctx()[0], cfg)
    assert model.substeps == 5
    with torch.no_grad():
        model.omega_raw.fill_(60.0)  # sigmoid saturates: omega at the band's top
        model.gain_raw.fill_(0.05)
    assert float(model.omega.detach().max()) * model.dt / 5 > 1.0  # the float32 rounding is there
    assert torch.isfinite(model.part_theta(torch.tensor(_ctx()[1]))).all()


def test_model_omega_beyond_the_band_is_clamped_to_its_ends_with_finite_gradients():
    ctx, w = _ctx()
    cfg = quick_models_cfg()
    model = build_model("ours", ctx, cfg, config="single")
    lo, hi = (2 * math.pi * f for f in cfg["ours"]["omega_hz"])
    with torch.no_grad():
        model.omega_raw[::2] = 1e4
        model.omega_raw[1::2] = -1e4
        model.gain_raw.fill_(0.05)
    om = model.omega.detach().double()
    np.testing.assert_allclose(om[::2], hi, rtol=1e-6)
    np.testing.assert_allclose(om[1::2], lo, rtol=1e-6)
    theta = model.part_theta(torch.tensor(w))
    theta.square().sum().backward()
    assert torch.isfinite(theta).all() and torch.isfinite(model.gain_raw.grad).all()
    assert torch.isfinite(model.omega_raw.grad).all()


# -- wind extremes ------------------------------------------------------------------------------


def test_zero_wind_gives_exactly_zero_theta_and_the_canonical_pose():
    th = integrate(
        t64([0.7, 5.0, 18.0]),
        t64([1e-4, 0.08, 2.5]),
        t64([1.0, -2.0, 3.0]),
        np.zeros(T_REC),
        0.0,
        DT,
        5,
    )
    assert torch.equal(th, torch.zeros_like(th))
    ctx, _ = _ctx()
    model = build_model("ours", ctx, quick_models_cfg())
    with torch.no_grad():
        model.gain_raw.fill_(0.3)  # a model that does move under wind
        model.axis_raw.add_(0.3 * torch.randn_like(model.axis_raw))
    zero = torch.zeros(T_REC)
    s = model.gaussians_at(300, zero)
    c = model.canonical_state()
    assert torch.equal(s.means, c.means)
    assert torch.allclose(
        s.quats / s.quats.norm(dim=-1, keepdim=True),
        c.quats / c.quats.norm(dim=-1, keepdim=True),
        atol=0,
    )


def test_three_times_the_training_wind_is_finite_and_scales_as_the_drag_law():
    """Forcing is gain (v^2 - vbar^2): tripling v (and so its mean vbar) multiplies it by 9."""
    omega, zeta, g = (
        t64([2 * math.pi * 0.35, 2 * math.pi * 1.5]),
        t64([0.08, 0.08]),
        t64([0.01, 0.01]),
    )
    w1 = gusty_wind(T_REC)
    w3 = 3.0 * w1
    th1 = integrate(omega, zeta, g, w1, float(w1.mean()), DT, 2).numpy()
    th3 = integrate(omega, zeta, g, w3, float(w3.mean()), DT, 2).numpy()
    assert np.isfinite(th3).all()
    np.testing.assert_allclose(th3, 9.0 * th1, rtol=1e-10, atol=1e-14 * np.abs(th3).max())
    for k in range(2):
        ref = wind_lsim(float(omega[k]), 0.08, 0.01, w3, float(w3.mean()), DT)
        assert _rel(th3[k], ref) < _rk4_bound(float(omega[k]) * DT / 2, 0.08, 2 * (T_REC - 1))


# -- number of parts ----------------------------------------------------------------------------


def test_one_part_works_end_to_end():
    ctx, w = _ctx()
    model = build_model(
        "ours", ctx, quick_models_cfg() | {"configs": {"single": {"conditions": "train", "K": 1}}}
    )
    assert model.K == 1 and torch.equal(model.part_labels, torch.zeros(200, dtype=torch.long))
    with torch.no_grad():
        model.gain_raw.fill_(0.05)
    theta = model.part_theta(torch.tensor(w))
    assert theta.shape == (1, w.size) and theta.abs().max() > 0
    s = model.gaussians_at(100, torch.tensor(w))
    s.means.sum().backward()
    assert torch.isfinite(s.means).all() and model.gain_raw.grad is not None

    # rigid: one rotation about one pivot keeps every pairwise distance
    def dist(x):
        return torch.cdist(x, x, compute_mode="donot_use_mm_for_euclid_dist")

    assert torch.allclose(dist(s.means), dist(model.canonical_state().means), atol=1e-5)


def test_more_parts_than_gaussians_stops_naming_k_and_n():
    ctx, _ = _ctx(n=20)
    cfg = quick_models_cfg()
    cfg["configs"]["single"]["K"] = 21
    with pytest.raises(ValueError, match=r"K = 21 parts exceeds the 20 Gaussians"):
        build_model("ours", ctx, cfg)


# -- precision ----------------------------------------------------------------------------------


def test_float32_against_float64_over_the_whole_recording():
    """Drift bound: each float32 RK4 step rounds the state at ~eps32 relative; the errors are
    independent from step to step, so over N steps they grow like sqrt(N) eps32 (a random walk;
    the damped system only shrinks them). 10 sqrt(N) eps32 = 4e-5 for N = 1108 steps: the
    float32 reference path must stay inside it, lightest damping and both band ends included.
    The fast path integrates in float64 whatever the parameter dtype and rounds once at the end,
    so its float32 output must be within one float32 ulp (eps32 relative)."""
    om = np.array([2 * math.pi * 0.1, 2 * math.pi * 0.35, 2 * math.pi * 1.5, 2 * math.pi * 3.0])
    om = np.tile(om, 3).astype(np.float32).astype(np.float64)  # same omegas in both precisions
    ze = np.repeat([0.01, 0.08, 0.5], 4)
    wind = gusty_wind(T_REC, seed=2)
    n_sub = 2
    args64 = (t64(om), t64(ze), t64(np.ones(12)))
    args32 = tuple(a.float() for a in args64)
    ref = integrate(*args64, wind, 6.0, DT, n_sub).numpy()  # [12, T] float64
    ref_lsim_ok = _rel(ref[5], wind_lsim(om[5], ze[5], 1.0, wind, 6.0, DT)) < 1e-4
    assert ref_lsim_ok  # the float64 baseline itself is right
    scale = np.abs(ref).max(axis=1)
    ref32 = (
        integrate(
            *args32, torch.tensor(wind, dtype=torch.float32), 6.0, DT, n_sub, backend="reference"
        )
        .double()
        .numpy()
    )
    drift = np.abs(ref32 - ref).max(axis=1) / scale
    assert np.all(drift < 10 * math.sqrt(n_sub * (T_REC - 1)) * EPS32), drift
    fast32 = integrate(*args32, wind, 6.0, DT, n_sub)
    assert fast32.dtype == torch.float32
    assert np.all(np.abs(fast32.double().numpy() - ref).max(axis=1) / scale <= EPS32)


# -- the matcher on a constant trajectory -------------------------------------------------------


def _truth(B=6, seed=0):
    rng = np.random.default_rng(seed)
    omega = 2 * math.pi * np.linspace(0.35, 1.5, B)
    wind = gusty_wind(T_REC, seed=seed)
    theta = np.stack([wind_lsim(o, 0.08, 1.0, wind, float(wind.mean()), DT) for o in omega], 1)
    return SimpleNamespace(omega=omega, zeta=np.full(B, 0.08), theta=theta[None], rng=rng), wind


def test_matcher_on_constant_trajectories_gives_no_nan_and_trusts_nothing_there():
    truth, wind = _truth()
    moving = truth.theta[0][:, [1, 4]].T  # two parts that are bones
    const = np.stack([np.zeros(T_REC), np.full(T_REC, 0.3)])  # silent / offset-only parts
    part = np.concatenate([moving, const])  # [4, T]
    om = np.concatenate([truth.omega[[1, 4]], [3.0, 5.0]])
    rec = score_recovery(part, om, np.full(4, 0.1), truth, LEAD_IN, 300)
    m = rec.match
    assert np.all(np.isfinite(m.corr)) and np.all(np.isfinite(m.rel_err))
    assert m.trusted.tolist() == [True, True, False, False]
    assert np.all(m.corr[2:] == 0.0)
    assert m.median_rel_err == pytest.approx(0.0, abs=1e-12)
    # all parts constant: nothing trusted; the median over zero parts is undefined (NaN, shown
    # as '--'), never a number made up from 0/0
    none = score_recovery(const, om[2:], np.full(2, 0.1), truth, LEAD_IN, 300).match
    assert none.n_trusted == 0 and np.all(none.corr == 0.0) and math.isnan(none.median_rel_err)


def test_untrained_model_recovery_is_untrusted_not_nan():
    truth, wind = _truth()
    ctx, _ = _ctx()
    model = build_model("ours", ctx, quick_models_cfg())  # gain 0: theta is exactly 0
    obs = SimpleNamespace(wind=wind[None], lead_in_frames=LEAD_IN, n_train=300)
    rec = recover_model(model, obs, truth)
    assert rec.match.n_trusted == 0 and np.all(np.isfinite(rec.match.corr))
    assert np.isfinite(rec.damping.median_zeta)


# -- fixtures -----------------------------------------------------------------------------------


def _ctx(n=200, seed=0):
    return model_context(n, seed, LEAD_IN, wind=gusty_wind(T_REC, seed=seed))
