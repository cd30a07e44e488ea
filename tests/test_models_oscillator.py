"""RK4 oscillator solver against independent oracles (scipy lsim, closed form), gradients, guard."""

import numpy as np
import pytest
import torch

from physgs.models.oscillator import StabilityError, integrate, required_substeps
from oracles import gusty_wind, step_response, t64, wind_lsim

FPS = 24
DT = 1.0 / FPS


def test_rk4_matches_lsim_with_fourth_order_convergence():
    wind = gusty_wind(240)
    omega, zeta, gain = 2 * np.pi * 1.2, 0.08, 0.05
    ref = wind_lsim(omega, zeta, gain, wind, 6.0, DT)
    errs = []
    for n in (1, 2, 4, 8):
        th = integrate(t64(omega), t64(zeta), t64(gain), wind, 6.0, DT, n)[0].numpy()
        errs.append(np.abs(th - ref).max())
    assert errs[-1] < 1e-6 * np.abs(ref).max()
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all((ratios > 12) & (ratios < 20)), ratios  # 2^4 = 16 per halving


@pytest.mark.parametrize("zeta", [0.08, 0.5])
def test_matches_closed_form_unforced_response(zeta):
    # Constant wind with vbar = 0 gives a constant forcing F = gain v^2. Started from rest, the
    # solution is the static deflection F/omega^2 plus the closed-form UNFORCED (homogeneous)
    # response released from theta0 = -F/omega^2, theta0' = 0:
    #   theta_free(t) = theta0 exp(-zeta omega t) (cos wd t + zeta omega / wd sin wd t).
    T, v, omega, gain = 200, 5.0, 4.0, 0.02
    th = integrate(t64(omega), t64(zeta), t64(gain), np.full(T, v), 0.0, DT, 4)[0].numpy()
    t = np.arange(T) * DT
    exact = step_response(omega, zeta, gain * v**2, t)
    assert np.abs(th - exact).max() < 1e-6 * np.abs(exact).max()


def test_fast_and_reference_agree_in_value_and_gradient():
    wind = gusty_wind(60, seed=1)
    p = [
        torch.tensor(a, dtype=torch.float64, requires_grad=True)
        for a in ([3.0, 7.0, 11.0], [0.05, 0.1, 0.3], [0.01, -0.02, 0.03])
    ]
    weights = torch.randn(3, 60, dtype=torch.float64, generator=torch.Generator().manual_seed(0))
    grads = []
    for backend in ("fast", "reference"):
        th = integrate(*p, wind, 6.0, DT, 2, backend=backend)
        (th * weights).sum().backward()
        grads.append([q.grad.clone() for q in p])
        for q in p:
            q.grad = None
        if backend == "fast":
            th_fast = th.detach()
    th_ref = th.detach()
    assert torch.allclose(th_fast, th_ref, rtol=1e-12, atol=1e-14)
    for gf, gr in zip(*grads):
        assert torch.allclose(gf, gr, rtol=1e-10, atol=1e-14)


def test_gradcheck_float64():
    wind = gusty_wind(40, seed=2)

    def f(om, ze, g):
        return integrate(om, ze, g, wind, 6.0, DT, 2)

    args = tuple(
        torch.tensor(a, dtype=torch.float64, requires_grad=True)
        for a in ([2.5, 8.0], [0.08, 0.2], [0.02, -0.01])
    )
    assert torch.autograd.gradcheck(f, args, eps=1e-6, atol=1e-7, rtol=1e-5)


def test_starts_at_rest_and_keeps_float32():
    om = torch.tensor([5.0, 9.0])
    th = integrate(
        om, torch.tensor([0.1, 0.1]), torch.tensor([0.1, 0.1]), gusty_wind(30), 6.0, DT, 1
    )
    assert th.dtype == torch.float32 and th.shape == (2, 30)
    assert torch.all(th[:, 0] == 0) and torch.all(th[:, 1:].abs().sum(1) > 0)


def test_stability_guard_names_the_fix():
    om = torch.tensor([2.0, 30.0])
    z = torch.tensor([0.1, 0.1])
    with pytest.raises(StabilityError, match=r"substeps >= 2"):
        integrate(om, z, z, gusty_wind(10), 6.0, DT, 1)  # 30/24 = 1.25 > 1
    n = required_substeps(30.0, DT, 1.0)
    assert n == 2 and 30.0 * DT / n <= 1.0
    assert required_substeps(24.0, DT, 1.0) == 1  # exactly at the guard is allowed
    assert required_substeps(100.0, 0.1, 0.5) == 20
    integrate(om, z, z, gusty_wind(10), 6.0, DT, n)  # no error
    with pytest.raises(ValueError, match="omega must be > 0"):
        integrate(torch.tensor([-1.0]), z[:1], z[:1], gusty_wind(10), 6.0, DT, 1)


# ---- the closed-form path (backend "lti": the GPU's) --------------------------------------------
@pytest.mark.parametrize("substeps", [1, 2, 3])
def test_lti_is_rk4s_own_scheme_against_lsim_and_the_reference(substeps):
    """The closed form solves the same discrete RK4 scheme: it equals the plain-torch RK4 to
    rounding (and so sits at RK4's own distance from scipy's exact lsim), an over-damped part
    included, for T not a power of two."""
    wind = gusty_wind(203, seed=3)
    om, ze, g = (
        t64([2 * np.pi * 0.4, 2 * np.pi * 1.2, 6.0]),
        t64([0.03, 0.08, 1.4]),
        t64([0.05] * 3),
    )
    lti = integrate(om, ze, g, wind, 6.0, DT, substeps, backend="lti")
    ref = integrate(om, ze, g, wind, 6.0, DT, substeps, backend="reference")
    assert lti.shape == (3, 203) and torch.all(lti[:, 0] == 0)
    assert torch.allclose(lti, ref, rtol=0, atol=1e-13 * float(ref.abs().max()))
    exact = np.stack([wind_lsim(o, z, 0.05, wind, 6.0, DT) for o, z in zip(om.numpy(), ze.numpy())])
    rk4_err = np.abs(ref.numpy() - exact).max()
    assert np.abs(lti.numpy() - exact).max() == pytest.approx(rk4_err, rel=1e-6, abs=1e-15)


def test_lti_gradients_are_autograds_through_the_reference():
    wind = gusty_wind(90, seed=4)
    weights = torch.randn(3, 90, dtype=torch.float64, generator=torch.Generator().manual_seed(2))
    grads = {}
    for backend in ("lti", "reference"):
        p = [
            t64(a).requires_grad_()
            for a in ([3.0, 7.0, 11.0], [0.05, 0.1, 0.3], [0.01, -0.02, 0.03])
        ]
        (integrate(*p, wind, 6.0, DT, 2, backend=backend) * weights).sum().backward()
        grads[backend] = [q.grad for q in p]
    for a, b in zip(grads["lti"], grads["reference"]):
        assert torch.allclose(a, b, rtol=1e-10, atol=1e-14)


def test_auto_takes_numba_on_the_cpu_and_keeps_the_dtype():
    om, ze, g = torch.tensor([5.0, 9.0]), torch.tensor([0.1, 0.2]), torch.tensor([0.1, 0.1])
    wind = gusty_wind(50)
    auto = integrate(om, ze, g, wind, 6.0, DT, 2, backend="auto")
    assert torch.equal(auto, integrate(om, ze, g, wind, 6.0, DT, 2, backend="fast"))
    lti = integrate(om, ze, g, wind, 6.0, DT, 2, backend="lti")
    assert lti.dtype == torch.float32
    assert torch.allclose(lti, auto, rtol=0, atol=1e-5 * float(auto.abs().max()))
    with pytest.raises(ValueError, match="backend must be one of"):
        integrate(om, ze, g, wind, 6.0, DT, 2, backend="gpu")
