"""Wind-driven damped oscillators integrated by classic RK4 (differentiable).

Each part k obeys
    theta'' + 2 zeta_k omega_k theta' + omega_k^2 theta = gain_k * (v(t)^2 - vbar^2),
from rest (theta = theta' = 0) at wind sample 0; v^2 is interpolated linearly between the wind
samples (first-order hold, as scipy.signal.lsim does). Each sample interval dt is split into
``substeps`` RK4 steps of h = dt / substeps.

Two paths compute the same numbers:
- ``backend="fast"``: a numba kernel integrates the state together with its forward sensitivities
  to (omega, zeta, gain) through the same RK4 stages. For an explicit Runge-Kutta method this is
  the exact derivative of the discrete scheme, so gradients match autograd through the reference
  to rounding. Wrapped in a torch.autograd.Function.
- ``backend="reference"``: plain torch operations, differentiated by autograd (slow; for tests).
- ``backend="lti"``: the same discrete scheme solved in closed form on any device. The system is
  linear and time-invariant, so one sample interval of RK4 (``substeps`` steps, forcing linear
  between samples) is x_{j+1} = A x_j + G0 u_j + G1 u_{j+1} with per-part 2x2 A and 2-vectors
  G0, G1 that RK4's stage algebra gives exactly; theta is then a causal convolution of the forcing
  with e1' A^k G0 and e1' A^k G1 (powers by doubling, convolution by FFT), differentiated by
  autograd. No loop over samples and no host copy: the path a GPU training takes.
- ``backend="auto"``: ``fast`` for parameters on the CPU, ``lti`` elsewhere.
"""

from __future__ import annotations

import math

import numba
import numpy as np
import torch

#: Largest omega * h (rad) the solver accepts. RK4's real-axis stability limit for this system is
#: about 2.8; staying near 1 keeps both stability and a small phase error.
STABILITY_GUARD = 1.0

#: Relative slack on the guard. A model keeps omega in float32 while its substeps are computed
#: from the float64 bound, so omega at the top of its band can exceed the bound by a float32
#: rounding (~1e-7); without slack a step chosen by required_substeps exactly at the guard would
#: be refused mid-training. 1e-6 is far too small to matter for stability (limit ~2.8).
GUARD_RTOL = 1e-6


class StabilityError(ValueError):
    """The RK4 step h = dt / substeps is too long for the largest omega."""


def fastest_rate(omega, zeta):
    """Largest eigenvalue magnitude |lambda| of theta'' + 2 zeta omega theta' + omega^2 theta = 0.

    Underdamped and critical (zeta <= 1): |lambda| = omega. Over-damped: the stiff real pole
    omega (zeta + sqrt(zeta^2 - 1)), about 2 zeta omega, which RK4 must resolve too: guarding
    omega alone lets it blow up.

    Args:
        omega (np.ndarray | float): natural frequencies, rad/s (scalar or array).
        zeta (np.ndarray | float): damping ratios, dimensionless (broadcastable to omega).

    Returns:
        (np.ndarray): |lambda|, rad/s, float64, the broadcast shape.
    """
    omega = np.asarray(omega, dtype=np.float64)
    zeta = np.asarray(zeta, dtype=np.float64)
    return omega * np.where(zeta > 1.0, zeta + np.sqrt(np.maximum(zeta * zeta - 1.0, 0.0)), 1.0)


def required_substeps(omega_max: float, dt: float, limit: float = STABILITY_GUARD) -> int:
    """Smallest number of RK4 substeps per sample with omega_max * dt / substeps <= limit.

    Args:
        omega_max: the fastest rate, rad/s (for over-damped parts pass
            [`fastest_rate`][physgs.models.oscillator.fastest_rate]).
        dt: seconds between wind samples.
        limit: bound on omega * h, rad (h = dt / substeps).

    Returns:
        The substeps, >= 1 (with the same slack, GUARD_RTOL, as ``integrate``'s check, so the
            count is always accepted there).

    Raises:
        ValueError: omega_max, dt or limit not > 0.
    """
    if not (omega_max > 0 and dt > 0 and limit > 0):
        raise ValueError(
            f"required_substeps needs omega_max > 0, dt > 0 and limit > 0; got "
            f"omega_max={omega_max}, dt={dt}, limit={limit}"
        )
    # Same slack as integrate's check, so the count returned is always accepted there, and exact
    # multiples (e.g. omega*dt == 2*limit) stay at the lower count.
    return max(1, math.ceil(omega_max * dt / (limit * (1.0 + GUARD_RTOL))))


@numba.njit(cache=True, inline="always")
def _rhs(th, w, tho, wo, thz, wz, thg, wg, om, ze, g, u):
    """Time derivative of (theta, theta') and of its sensitivities to omega, zeta, gain."""
    c = 2.0 * ze * om
    o2 = om * om
    return (
        w,
        g * u - c * w - o2 * th,
        wo,
        -c * wo - o2 * tho - 2.0 * ze * w - 2.0 * om * th,
        wz,
        -c * wz - o2 * thz - 2.0 * om * w,
        wg,
        -c * wg - o2 * thg + u,
    )


@numba.njit(cache=True)
def _rk4_sens_kernel(omega, zeta, gain, u, dt, substeps, theta_out, sens_out):
    """theta_out [K, T], sens_out [3, K, T] (d theta / d omega, zeta, gain), filled in place."""
    K = omega.shape[0]
    T = u.shape[0]
    h = dt / substeps
    for k in range(K):
        om = omega[k]
        ze = zeta[k]
        g = gain[k]
        y = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        theta_out[k, 0] = 0.0
        sens_out[0, k, 0] = 0.0
        sens_out[1, k, 0] = 0.0
        sens_out[2, k, 0] = 0.0
        for j in range(T - 1):
            u0 = u[j]
            du = u[j + 1] - u[j]
            for s in range(substeps):
                ua = u0 + du * (s / substeps)
                ub = u0 + du * ((s + 0.5) / substeps)
                uc = u0 + du * ((s + 1.0) / substeps)
                k1 = _rhs(y[0], y[1], y[2], y[3], y[4], y[5], y[6], y[7], om, ze, g, ua)
                y2 = (
                    y[0] + 0.5 * h * k1[0],
                    y[1] + 0.5 * h * k1[1],
                    y[2] + 0.5 * h * k1[2],
                    y[3] + 0.5 * h * k1[3],
                    y[4] + 0.5 * h * k1[4],
                    y[5] + 0.5 * h * k1[5],
                    y[6] + 0.5 * h * k1[6],
                    y[7] + 0.5 * h * k1[7],
                )
                k2 = _rhs(y2[0], y2[1], y2[2], y2[3], y2[4], y2[5], y2[6], y2[7], om, ze, g, ub)
                y3 = (
                    y[0] + 0.5 * h * k2[0],
                    y[1] + 0.5 * h * k2[1],
                    y[2] + 0.5 * h * k2[2],
                    y[3] + 0.5 * h * k2[3],
                    y[4] + 0.5 * h * k2[4],
                    y[5] + 0.5 * h * k2[5],
                    y[6] + 0.5 * h * k2[6],
                    y[7] + 0.5 * h * k2[7],
                )
                k3 = _rhs(y3[0], y3[1], y3[2], y3[3], y3[4], y3[5], y3[6], y3[7], om, ze, g, ub)
                y4 = (
                    y[0] + h * k3[0],
                    y[1] + h * k3[1],
                    y[2] + h * k3[2],
                    y[3] + h * k3[3],
                    y[4] + h * k3[4],
                    y[5] + h * k3[5],
                    y[6] + h * k3[6],
                    y[7] + h * k3[7],
                )
                k4 = _rhs(y4[0], y4[1], y4[2], y4[3], y4[4], y4[5], y4[6], y4[7], om, ze, g, uc)
                f = h / 6.0
                y = (
                    y[0] + f * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
                    y[1] + f * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
                    y[2] + f * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2]),
                    y[3] + f * (k1[3] + 2.0 * k2[3] + 2.0 * k3[3] + k4[3]),
                    y[4] + f * (k1[4] + 2.0 * k2[4] + 2.0 * k3[4] + k4[4]),
                    y[5] + f * (k1[5] + 2.0 * k2[5] + 2.0 * k3[5] + k4[5]),
                    y[6] + f * (k1[6] + 2.0 * k2[6] + 2.0 * k3[6] + k4[6]),
                    y[7] + f * (k1[7] + 2.0 * k2[7] + 2.0 * k3[7] + k4[7]),
                )
            theta_out[k, j + 1] = y[0]
            sens_out[0, k, j + 1] = y[2]
            sens_out[1, k, j + 1] = y[4]
            sens_out[2, k, j + 1] = y[6]


class _RK4Sensitivity(torch.autograd.Function):
    """theta [K, T] from (omega, zeta, gain) [K]; backward contracts the stored sensitivities."""

    @staticmethod
    def forward(ctx, omega, zeta, gain, u, dt, substeps):  # u: [T] float64 numpy
        om = omega.detach().cpu().double().numpy()
        ze = zeta.detach().cpu().double().numpy()
        g = gain.detach().cpu().double().numpy()
        K, T = om.shape[0], u.shape[0]
        theta = np.empty((K, T))
        sens = np.empty((3, K, T))
        _rk4_sens_kernel(om, ze, g, u, float(dt), int(substeps), theta, sens)
        ctx.save_for_backward(torch.from_numpy(sens).to(omega.dtype))
        return torch.from_numpy(theta).to(dtype=omega.dtype, device=omega.device)

    @staticmethod
    def backward(ctx, grad_theta):  # grad_theta [K, T]
        (sens,) = ctx.saved_tensors  # [3, K, T]
        g = (sens.to(grad_theta.device) * grad_theta.unsqueeze(0)).sum(-1)  # [3, K]
        return g[0], g[1], g[2], None, None, None


def _reference(omega, zeta, gain, u, dt, substeps):
    """Plain-torch RK4 (autograd), vectorised over parts. u: [T] tensor -> theta [K, T]."""
    h = dt / substeps
    th = torch.zeros_like(omega)
    w = torch.zeros_like(omega)
    c = 2.0 * zeta * omega
    o2 = omega * omega

    def rhs(th, w, uu):
        return w, gain * uu - c * w - o2 * th

    out = [th]
    for j in range(u.shape[0] - 1):
        u0, du = u[j], u[j + 1] - u[j]
        for s in range(substeps):
            ua, ub, uc = (u0 + du * ((s + a) / substeps) for a in (0.0, 0.5, 1.0))
            k1 = rhs(th, w, ua)
            k2 = rhs(th + 0.5 * h * k1[0], w + 0.5 * h * k1[1], ub)
            k3 = rhs(th + 0.5 * h * k2[0], w + 0.5 * h * k2[1], ub)
            k4 = rhs(th + h * k3[0], w + h * k3[1], uc)
            th = th + h / 6.0 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            w = w + h / 6.0 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        out.append(th)
    return torch.stack(out, dim=1)


def _lti(omega, zeta, gain, u, dt, substeps):
    """RK4's discrete scheme as a linear recurrence, solved by FFT convolution. u: [T] tensor on
    omega's device and dtype -> theta [K, T]."""
    K, T = omega.shape[0], u.shape[0]
    h = dt / substeps
    zero = torch.zeros_like(omega)
    # N = h M for the state (theta, theta'), M = [[0, 1], [-omega^2, -2 zeta omega]]
    N = torch.stack(
        [
            torch.stack([zero, zero + h], -1),
            torch.stack([-h * omega**2, -2 * h * zeta * omega], -1),
        ],
        -2,
    )  # [K, 2, 2]
    eye = torch.eye(2, dtype=omega.dtype, device=omega.device).expand(K, 2, 2)
    N2 = N @ N
    N3 = N2 @ N
    P = eye + N + N2 / 2 + N3 / 6 + N3 @ N / 24  # one step on the state
    # one step's response to the forcing at its start (Ra) and end (Rc) for a unit gain (the
    # mid-step stages read their mean): h/6 (k1 + 2 k2 + 2 k3 + k4)'s forcing terms
    b = torch.stack([zero, torch.ones_like(omega)], -1)[..., None]  # [K, 2, 1]
    Ra = (h / 6 * (3 * eye + 2 * N + 0.75 * N2 + 0.25 * N3) @ b)[..., 0]  # [K, 2]
    Rc = (h / 6 * (3 * eye + N + 0.25 * N2) @ b)[..., 0]
    A, G0, G1 = eye, torch.zeros_like(Ra), torch.zeros_like(Ra)
    for m in range(substeps):  # the forcing at substep m's ends, between samples j and j + 1
        a0, c0 = 1 - m / substeps, 1 - (m + 1) / substeps
        G0 = (P @ G0[..., None])[..., 0] + a0 * Ra + c0 * Rc
        G1 = (P @ G1[..., None])[..., 0] + (1 - a0) * Ra + (1 - c0) * Rc
        A = P @ A
    L = T - 1
    if L == 0:
        return omega.new_zeros((K, 1))
    rows = eye[:, :1, :]  # e1' A^k for k < 1: [K, 1, 2]
    step = A  # A^(rows' length)
    while rows.shape[1] < L:  # doubling: e1' A^(k + n) = (e1' A^k) A^n
        rows = torch.cat([rows, rows @ step], 1)
        step = step @ step
    rows = rows[:, :L]  # [K, L, 2]
    a = (rows * G0[:, None, :]).sum(-1)  # [K, L] the response to u_j, k samples on
    c = (rows * G1[:, None, :]).sum(-1)  # [K, L] the response to u_{j+1}
    n = 2 * L
    conv = torch.fft.irfft(
        torch.fft.rfft(a, n=n) * torch.fft.rfft(u[:L], n=n)
        + torch.fft.rfft(c, n=n) * torch.fft.rfft(u[1:], n=n),
        n=n,
    )[:, :L]  # theta at samples 1 .. T-1
    return gain[:, None] * torch.cat([omega.new_zeros((K, 1)), conv], 1)


#: the integrators ``integrate`` and ``integrate_forcing`` accept
BACKENDS = ("fast", "reference", "lti", "auto")


def _resolve(backend: str, omega: torch.Tensor) -> str:
    """``auto``: numba for parameters on the CPU, the closed form elsewhere."""
    if backend == "auto":
        return "fast" if omega.device.type == "cpu" else "lti"
    return backend


def _home(backend: str, omega: torch.Tensor) -> torch.device:
    """Where the forcing is kept: on omega's device for the closed form, else the host."""
    return omega.device if backend == "lti" else torch.device("cpu")


def _check_args(omega, zeta, gain, dt, substeps, backend) -> None:
    """The shape, step and backend checks ``integrate`` and ``integrate_forcing`` share."""
    if backend not in BACKENDS:
        raise ValueError(f"integrate: backend must be one of {BACKENDS}, got {backend!r}")
    if not (omega.ndim == 1 and omega.shape == zeta.shape == gain.shape):
        raise ValueError(
            "integrate: omega, zeta and gain must be 1-D tensors of one length K; got shapes "
            f"{tuple(omega.shape)}, {tuple(zeta.shape)}, {tuple(gain.shape)}"
        )
    if isinstance(substeps, bool) or int(substeps) != substeps or substeps < 1:
        raise ValueError(f"integrate: substeps must be a positive integer, got {substeps!r}")
    if not dt > 0:
        raise ValueError(f"integrate: dt must be > 0 seconds, got {dt}")


def integrate(
    omega: torch.Tensor,
    zeta: torch.Tensor,
    gain: torch.Tensor,
    wind,
    vbar: float,
    dt: float,
    substeps: int,
    *,
    guard: float = STABILITY_GUARD,
    backend: str = "fast",
) -> torch.Tensor:
    """Swing angles of K wind-driven damped oscillators, from rest at wind sample 0.

    Solves theta'' + 2 zeta omega theta' + omega^2 theta = gain (v(t)^2 - vbar^2), v^2 linear
    between samples. Differentiable w.r.t. omega, zeta and gain (not the wind).

    Args:
        omega: [K] natural frequencies, rad/s (> 0).
        zeta: [K] damping ratios, dimensionless (>= 0).
        gain: [K] force gains, rad / m^2.
        wind (torch.Tensor | np.ndarray): [T] wind speed, m/s, sampled every ``dt`` (tensor or
            array; not differentiated).
        vbar: m/s, the speed whose square is subtracted from v^2.
        dt: seconds between wind samples.
        substeps: RK4 steps per sample.
        guard: bound on |lambda| * h, rad.
        backend: ``"fast"`` (numba with forward sensitivities), ``"reference"`` (torch autograd),
            ``"lti"`` (closed form on omega's device) or ``"auto"`` (fast on the CPU, else lti).

    Returns:
        theta [K, T], rad, dtype of omega; theta[:, j] at sample j.

    Raises:
        StabilityError: max |lambda| * dt / substeps > guard, |lambda| =
            [`fastest_rate`][physgs.models.oscillator.fastest_rate] (= omega unless over-damped).
        ValueError: shapes that differ, a non-positive omega, dt or substeps, a negative zeta, a
            wind that is not a finite [T] series, or an unknown backend.
    """
    _check_args(omega, zeta, gain, dt, substeps, backend)
    backend = _resolve(backend, omega)
    # the wind stays where its integrator runs: no host copy on a GPU
    w = torch.as_tensor(wind).detach().to(_home(backend, omega), torch.float64)
    if w.ndim != 1 or w.shape[0] < 1 or not torch.isfinite(w).all():
        raise ValueError(
            f"integrate: wind must be a finite 1-D series [T] in m/s; got shape {tuple(w.shape)}"
        )
    u = w * w - float(vbar) ** 2  # [T] forcing before the gain, m^2/s^2
    return integrate_forcing(
        omega, zeta, gain, u, dt, substeps, guard=guard, backend=backend, _checked=True
    )


def integrate_forcing(
    omega: torch.Tensor,
    zeta: torch.Tensor,
    gain: torch.Tensor,
    u,
    dt: float,
    substeps: int,
    *,
    guard: float = STABILITY_GUARD,
    backend: str = "fast",
    _checked: bool = False,
) -> torch.Tensor:
    """Swing angles under a forcing given directly instead of a wind.

    As [`integrate`][physgs.models.oscillator.integrate], for theta'' + 2 zeta omega theta' +
    omega^2 theta = gain u(t), from rest at sample 0, u linear between samples. Differentiable
    w.r.t. omega, zeta and gain (not u).

    Args:
        omega: [K] natural frequencies, rad/s (> 0).
        zeta: [K] damping ratios, dimensionless (>= 0).
        gain: [K] force gains, rad/s^2 per unit of u (rad / m^2 for u in m^2/s^2).
        u (torch.Tensor | np.ndarray): [T] forcing (``integrate``'s v^2 - vbar^2, m^2/s^2), sampled
            every ``dt``.
        dt: seconds between samples.
        substeps: RK4 steps per sample.
        guard: bound on |lambda| * h, rad.
        backend: as ``integrate``.
        _checked: the arguments were already checked (``integrate`` passes True).

    Returns:
        theta [K, T], rad per unit of gain x u, dtype of omega.

    Raises:
        StabilityError: as ``integrate``.
        ValueError: as ``integrate`` (u instead of the wind).
    """
    if not _checked:
        _check_args(omega, zeta, gain, dt, substeps, backend)
    backend = _resolve(backend, omega)
    u = torch.as_tensor(u).detach().to(_home(backend, omega), torch.float64)
    if u.ndim != 1 or u.shape[0] < 1 or not torch.isfinite(u).all():
        raise ValueError(
            f"integrate: the forcing must be a finite 1-D series [T]; got {tuple(u.shape)}"
        )
    if omega.numel() == 0:
        return omega.new_zeros((0, u.shape[0]))
    om_min, ze_min = float(omega.detach().min()), float(zeta.detach().min())
    if not om_min > 0:
        raise ValueError(
            f"integrate: omega must be > 0 rad/s; got min {om_min}"
            + (" (NaN: a parameter upstream is NaN)" if math.isnan(om_min) else "")
        )
    if not ze_min >= 0:
        raise ValueError(
            f"integrate: zeta must be >= 0; got min {ze_min}"
            + (" (NaN: a parameter upstream is NaN)" if math.isnan(ze_min) else "")
        )
    # Guard the fastest eigenvalue, not omega alone: an over-damped part's stiff pole is faster.
    rates = fastest_rate(
        omega.detach().cpu().double().numpy(), zeta.detach().cpu().double().numpy()
    )
    i = int(np.argmax(rates))
    rate, om_i, ze_i = float(rates[i]), float(omega.detach()[i]), float(zeta.detach()[i])
    h = dt / substeps
    if rate * h > guard * (1.0 + GUARD_RTOL):
        need = required_substeps(rate, dt, guard)
        raise StabilityError(
            f"RK4 step outside the stability guard: part {i} with omega {om_i:.4g} rad/s and "
            f"zeta {ze_i:.3g} has fastest rate |lambda| = {rate:.4g} rad/s; x step "
            f"h = dt/substeps = {dt:.4g}/{substeps} = {h:.4g} s gives |lambda|*h = {rate * h:.3g} "
            f"> {guard}; use substeps >= {need} (or lower the omega / zeta upper bounds)"
        )
    if backend == "reference":
        return _reference(omega, zeta, gain, u.to(omega.dtype), float(dt), int(substeps))
    if backend == "lti":
        u = u.to(device=omega.device, dtype=omega.dtype)
        return _lti(omega, zeta, gain, u, float(dt), int(substeps))
    return _RK4Sensitivity.apply(omega, zeta, gain, u.numpy(), float(dt), int(substeps))
