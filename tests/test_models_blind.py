"""Ours with a learned forcing (physgs.models.blind): the convolution against ours'
integrator, the forcing's fixed scale, recovery of a known forcing's shape on a small scene,
no forcing beyond the window, and the wind never read (NaN wind, same model)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import torch

from physgs.models.base import ModelContext
from physgs.models.blind import BlindOscillatorPrior, ForcingNotDefined, causal_convolve
from physgs.models.oscillator import integrate_forcing

FPS, N_TRAIN, LEAD = 24, 120, 24
CANON = {"opacity": 0.1, "color": 0.5, "knn": 3, "scale_factor": 1.0}


def _ctx(nan_wind_stats: bool = True) -> ModelContext:
    xyz = np.random.default_rng(0).uniform(-1, 1, (60, 3)).astype(np.float32)
    xyz[:30, 2] -= 2.0  # two clear clusters: two parts
    nan = float("nan")
    return ModelContext(xyz, FPS, N_TRAIN, LEAD, nan, nan, nan, np.array([0.0, 1.0, 0.0]), nan)


def _model(seed: int = 0, forcing_hz: float = 1.5) -> BlindOscillatorPrior:
    return BlindOscillatorPrior(
        _ctx(),
        CANON,
        K=2,
        omega_hz=[0.1, 3.0],
        zeta=[0.01, 0.5],
        omega_init_hz=0.7,
        zeta_init=0.1,
        substeps=2,
        forcing_hz=forcing_hz,
        seed=seed,
    )


def test_convolution_equals_integrating_the_forcing():
    """theta = h * f (the response to a unit sample, convolved) is ours' RK4 run on f itself."""
    om = torch.tensor([3.0, 6.0], dtype=torch.float64)
    ze = torch.tensor([0.05, 0.2], dtype=torch.float64)
    g = torch.tensor([1.0, 2.0], dtype=torch.float64)
    f = torch.tensor(np.random.default_rng(1).normal(size=200))
    e = torch.zeros(201, dtype=torch.float64)
    e[1] = 1.0
    r0 = integrate_forcing(om, ze, g, e[1:], 1 / 24, 2)  # unit sample 0
    r1 = integrate_forcing(om, ze, g, e, 1 / 24, 2)  # unit sample 1
    direct = integrate_forcing(om, ze, g, f, 1 / 24, 2)
    got = causal_convolve(r0, r1[:, 1:], f)
    np.testing.assert_allclose(got.detach().numpy(), direct.detach().numpy(), atol=1e-12)


def test_forcing_scale_is_fixed():
    m = _model()
    with torch.no_grad():
        f1 = m.forcing().clone()
        m.forcing_coef.mul_(7.0)
        f2 = m.forcing()
    np.testing.assert_allclose(f1.numpy(), f2.numpy(), atol=1e-12)
    assert abs(float((f1**2).mean()) - 1.0) < 1e-9 and abs(float(f1.mean())) < 1e-9


def test_blind_prior_recovers_a_known_forcing():
    """Two parts (0.5 and 1.1 Hz) driven by one known band-limited forcing: fitting the prior's
    angles to theirs (omega, zeta, gain and forcing all free, from ours' initial values and a
    random forcing) recovers the forcing's shape, correlation above 0.9 over the window."""
    target_model = _model(seed=1)
    with torch.no_grad():
        b = target_model.bounds
        target_model.omega_raw.copy_(torch.tensor([b.omega_raw(2 * np.pi * f) for f in (0.5, 1.1)]))
        target_model.zeta_raw.fill_(b.zeta_raw(0.08))
        target_model.gain_raw.fill_(0.05)
        target = target_model.part_theta(None)  # [2, N]
        f_true = target_model.forcing()
    m = _model(seed=0)
    with torch.no_grad():
        m.gain_raw.fill_(0.01)
    opt = torch.optim.Adam([m.forcing_coef, m.omega_raw, m.zeta_raw, m.gain_raw], lr=0.05)
    win = slice(LEAD, LEAD + N_TRAIN)
    for _ in range(600):
        opt.zero_grad()
        loss = ((m.part_theta(None)[:, win] - target[:, win]) ** 2).mean() / target.var()
        loss.backward()
        opt.step()
    with torch.no_grad():
        f = m.forcing()
    before = abs(np.corrcoef(_model(seed=0).forcing().detach()[win], f_true[win])[0, 1])
    after = abs(np.corrcoef(f[win], f_true[win])[0, 1])
    assert after > 0.9 and after > before + 0.3, (before, after, float(loss))


def test_no_forcing_beyond_the_window():
    m = _model()
    wind = torch.zeros(LEAD + N_TRAIN + 10)
    m.gaussians_at(N_TRAIN - 1, wind)  # the window's last frame is defined
    with pytest.raises(ForcingNotDefined, match="not defined"):
        m.gaussians_at(N_TRAIN, wind)


def test_the_wind_is_never_read():
    """Same Gaussians and angles with the observed wind replaced by NaN, and the blind prior
    built from an Observed whose wind is NaN (the context skips the wind)."""
    m = _model()
    with torch.no_grad():
        m.gain_raw.fill_(0.05)
        w = torch.linspace(3.0, 9.0, LEAD + N_TRAIN + 10)
        a = m.gaussians_at(40, w).means
        b = m.gaussians_at(40, torch.full_like(w, float("nan"))).means
    assert torch.equal(a, b) and float((a - m.canonical_state().means).abs().max().detach()) > 0
    from physgs.models.base import context_from_observed

    obs = dataclasses.make_dataclass("Obs", ["wind"])(np.full((3, 50), np.nan))
    with pytest.raises(AttributeError):  # gets past the wind (NaN) to the camera it lacks
        context_from_observed(obs, wind=False)
    with pytest.raises(ValueError, match="wind"):
        context_from_observed(obs, wind=True)


def test_evaluation_says_not_defined_beyond_the_window_and_under_other_winds():
    """Through ours' render callback the blind prior refuses frames past the window and every
    other condition; the evaluation turns each refusal into NaN (never a score) and keeps the
    frames it does predict."""
    from types import SimpleNamespace

    from physgs.evaluate.adapter import model_render_fn
    from physgs.evaluate.splits import evaluate
    from physgs.models.undefined import NotDefined

    m = _model()
    fn = model_render_fn(
        m, SimpleNamespace(wind=np.zeros((2, LEAD + N_TRAIN + 10)), background=[1, 1, 1])
    )
    with pytest.raises(NotDefined):
        fn(5, 1, None)
    with pytest.raises(NotDefined):
        fn(N_TRAIN, 0, None)

    def render(frame, cond, cam):  # predicts condition 0 inside a 2-frame window
        if not (cond == 0 and frame < 2):
            raise NotDefined("beyond")
        return np.full((4, 4, 3), 0.5), np.ones((4, 4))

    rng = np.random.default_rng(0)
    obs = SimpleNamespace(
        frames=rng.integers(0, 255, (2, 4, 4, 4, 3), dtype=np.uint8),
        masks=np.ones((2, 4, 4, 4), bool),
        n_train=2,
        n_tail=2,
        train_camera=None,
        heldout_cameras=[None],
        heldout_frame_idx=np.array([1]),
        heldout_frames=rng.integers(0, 255, (1, 1, 4, 4, 3), dtype=np.uint8),
        conditions=np.array([1.0, 0.8]),
        heldout_azimuths_deg=np.array([0.0]),
    )
    s = evaluate(render, obs).summary()
    assert np.isnan(s["time"]) and np.isnan(s["train_c1"]) and np.isnan(s["beyond_c0"])
    assert np.isfinite(s["train_c0"]) and np.isfinite(s["view"])


def test_undefined_splits_are_the_ones_outside_the_window_and_wind():
    """The NaN summary keys evaluate_checkpoint accepts for the blind prior, and none for ours'
    kind of model (every frame defined): a NaN there would still stop the job as corrupt."""
    from types import SimpleNamespace

    from physgs.evaluate.run import undefined_splits

    obs = SimpleNamespace(
        n_train=N_TRAIN, conditions=[1.0, 0.8], heldout_frame_idx=np.arange(9, N_TRAIN, 10)
    )
    assert undefined_splits(_model(), obs) == {
        "time",
        "beyond_c0",
        "centroid_c0",
        "train_c1",
        "beyond_c1",
        "centroid_c1",
    }
    assert undefined_splits(SimpleNamespace(defined=lambda j, c: True), obs) == set()


def test_a_training_frame_needs_only_the_window_up_to_it():
    # Oracle: the whole window's theta, computed without autograd; the training path (autograd
    # on, upto = lead-in + frame + 1) integrates and convolves only that much.
    m = _model(seed=3)
    with torch.no_grad():
        m.gain_raw.add_(torch.randn(m.gain_raw.shape, generator=torch.Generator().manual_seed(0)))
        full = m.part_theta().clone()  # [K, L + n_train]
    for frame in (0, 37, N_TRAIN - 1):
        upto = LEAD + frame + 1
        part = m.part_theta(upto=upto)
        assert part.shape == (2, upto) and part.requires_grad
        np.testing.assert_allclose(part.detach().numpy(), full[:, :upto].numpy(), atol=1e-12)
    # and the deformation of a frame is the same either way
    s = m.deform(37, torch.zeros(LEAD + N_TRAIN))
    with torch.no_grad():
        s0 = m.deform(37, torch.zeros(LEAD + N_TRAIN))
    np.testing.assert_allclose(s.means.detach().numpy(), s0.means.numpy(), atol=1e-6)
