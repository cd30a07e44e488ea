"""Ground-truth bone physics: natural frequencies from geometry, gains, and the exact response
of theta'' + 2 zeta omega theta' + omega^2 theta = u(t) to a forcing u sampled at the frame rate
and linear between samples (first-order hold), which is also what the models' RK4 solver sees.

The system is linear time-invariant, so each frame step is exact: x_{k+1} = Phi x_k + G0 u_k +
G1 (u_{k+1} - u_k) / h with Phi, G0, G1 from one augmented matrix exponential (Van Loan).
The wind is periodic, so the start state can be the exact periodic steady state (no transient).
"""

from __future__ import annotations

import numpy as np


def calibrate_omega(
    radius: np.ndarray, length: np.ndarray, band_hz
) -> tuple[np.ndarray, float, np.ndarray]:
    """Natural frequencies from geometry, omega_b = c r_b / L_b^2, one c per tree.

    c centres the bones' frequencies (geometric mean of the extremes) on the band; bones that
    still fall outside it are clamped into it.

    Args:
        radius: [B] bone radii, m.
        length: [B] bone lengths, m.
        band_hz (tuple[float, float]): (lo, hi), Hz, 0 < lo < hi.

    Returns:
        (omega [B] rad/s clamped into the band, c in rad/s * m, clamped [B] bool: the bones whose
            raw c r / L^2 fell outside the band).

    Raises:
        ValueError: the band is not 0 < lo < hi.
    """
    lo, hi = (2 * np.pi * float(f) for f in band_hz)
    if not 0 < lo < hi:
        raise ValueError(f"band_hz {band_hz} must satisfy 0 < lo < hi (Hz); fix testbed.band_hz")
    q = np.asarray(radius, float) / np.asarray(length, float) ** 2
    c = float(np.sqrt(lo * hi / (q.min() * q.max())))
    raw = c * q
    tol = 1e-9 * hi
    clamped = (raw < lo - tol) | (raw > hi + tol)
    return np.clip(raw, lo, hi), c, clamped


def foh_matrices(omega: np.ndarray, zeta: np.ndarray, dt: float):
    """Exact one-step matrices of each oscillator under a piecewise-linear input (Van Loan).

    x_{k+1} = Phi x_k + G0 u_k + G1 (u_{k+1} - u_k) / dt, x = (theta, theta').

    Args:
        omega: [B] natural frequencies, rad/s.
        zeta: [B] damping ratios.
        dt: the step, s.

    Returns:
        (tuple[np.ndarray, ...]): (Phi [B, 2, 2], G0 [B, 2], G1 [B, 2]), float64.
    """
    B = len(omega)
    M = np.zeros((B, 4, 4))
    M[:, 0, 1] = 1.0
    M[:, 1, 0] = -(omega**2)
    M[:, 1, 1] = -2 * zeta * omega
    M[:, 1, 2] = 1.0  # input u
    M[:, 2, 3] = 1.0  # du/dt (constant over a step)
    import torch  # here, not at the top: the config checks import this module to plan jobs

    E = torch.linalg.matrix_exp(torch.from_numpy(M * dt)).numpy()  # batched, float64
    return E[:, :2, :2], E[:, :2, 2], E[:, :2, 3]


def simulate(
    omega: np.ndarray, zeta: np.ndarray, u: np.ndarray, dt: float, x0: np.ndarray | None = None
) -> np.ndarray:
    """Exact response of each oscillator to its forcing (first-order hold).

    Args:
        omega: [B] natural frequencies, rad/s.
        zeta: [B] damping ratios (or a scalar).
        u: [..., T, B] forcing, rad/s^2, at samples t_k = k dt, linear between samples.
        dt: seconds between samples.
        x0: [..., B, 2] initial (theta rad, theta' rad/s); None: rest.

    Returns:
        theta [..., T, B], rad; theta[..., k, :] at sample k.
    """
    omega = np.asarray(omega, float)
    zeta = np.broadcast_to(np.asarray(zeta, float), omega.shape)
    u = np.asarray(u, float)
    Phi, G0, G1 = foh_matrices(omega, zeta, dt)
    T = u.shape[-2]
    x = np.zeros(u.shape[:-2] + (len(omega), 2)) if x0 is None else np.array(x0, float)
    out = np.empty(u.shape)
    out[..., 0, :] = x[..., 0]
    for k in range(T - 1):
        uk, du = u[..., k, :], (u[..., k + 1, :] - u[..., k, :]) / dt
        x = np.einsum("bij,...bj->...bi", Phi, x) + G0 * uk[..., None] + G1 * du[..., None]
        out[..., k + 1, :] = x[..., 0]
    return out


def periodic_steady_state(
    omega: np.ndarray, zeta: np.ndarray, u_period: np.ndarray, dt: float
) -> np.ndarray:
    """State at sample 0 of the periodic steady state (the infinite-past response).

    From rest the state after one period is r; the steady state solves x = Phi^P x + r exactly, so a
    simulation started there carries no start transient at all.

    Args:
        omega: [B] natural frequencies, rad/s.
        zeta: [B] damping ratios (or a scalar).
        u_period: [..., P+1, B] one full period of the forcing, rad/s^2 (sample P equals sample 0).
        dt: seconds between samples.

    Returns:
        [..., B, 2] (theta rad, theta' rad/s).
    """
    P = u_period.shape[-2] - 1
    Phi, _, _ = foh_matrices(
        np.asarray(omega, float), np.broadcast_to(np.asarray(zeta, float), np.shape(omega)), dt
    )
    r = _final_state(omega, zeta, u_period, dt)  # one period from rest
    PhiP = np.linalg.matrix_power(Phi, P)  # [B, 2, 2]
    A = np.eye(2) - PhiP
    A = np.broadcast_to(A, r.shape[:-1] + (2, 2))  # [..., B, 2, 2]
    return np.linalg.solve(A, r[..., None])[..., 0]


def _final_state(omega, zeta, u, dt) -> np.ndarray:
    """(theta, theta') [..., B, 2] after the last sample of u [..., T, B], from rest."""
    Phi, G0, G1 = foh_matrices(
        np.asarray(omega, float), np.broadcast_to(np.asarray(zeta, float), np.shape(omega)), dt
    )
    x = np.zeros(u.shape[:-2] + (u.shape[-1], 2))
    for k in range(u.shape[-2] - 1):
        uk, du = u[..., k, :], (u[..., k + 1, :] - u[..., k, :]) / dt
        x = np.einsum("bij,...bj->...bi", Phi, x) + G0 * uk[..., None] + G1 * du[..., None]
    return x


def drag_forcing(wind: np.ndarray, vbar: np.ndarray) -> np.ndarray:
    """Unit-gain drag forcing v^2 - vbar^2.

    Args:
        wind: [C, T] wind speed per condition, m/s.
        vbar: [C] each condition's mean speed, m/s.

    Returns:
        [C, T] forcing, m^2/s^2.
    """
    return wind**2 - np.asarray(vbar)[:, None] ** 2


def lead_in_frames(omega_min: float, zeta: float, lead_in_tau: float, fps: int) -> int:
    """Frames of lead-in, ceil(lead_in_tau * tau_max * fps) with tau_max = 1 / (zeta omega_min).

    Args:
        omega_min: the slowest natural frequency, rad/s.
        zeta: the damping ratio.
        lead_in_tau: lead-in length in units of the slowest decay time tau_max.
        fps: frames per second.

    Returns:
        The lead-in, frames.
    """
    return int(np.ceil(lead_in_tau / (zeta * omega_min) * fps))
