"""Damping recovery: median zeta_hat and decay rate gamma_hat = zeta_hat * omega_hat vs omega_hat.

Ground truth is a constant damping ratio, i.e. gamma = zeta * omega (slope zeta, log-log
exponent 1). A model that fits a frequency-independent decay *rate* instead shows slope ~ 0
and log-log exponent ~ 0 (the paper's finding).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physgs.records import JsonRecord


@dataclass(frozen=True)
class DampingResult(JsonRecord):
    """zeta [K] (dimensionless), omega [K] and gamma [K] in rad/s (gamma in 1/s).

    median_zeta: median of zeta_hat. slope, intercept: least-squares gamma = intercept +
    slope * omega (slope dimensionless, intercept 1/s); truth: slope = zeta_true, intercept 0.
    loglog_exponent: p in gamma ~ omega^p (truth 1; a constant decay rate gives 0).
    """

    zeta: np.ndarray
    omega: np.ndarray
    gamma: np.ndarray
    median_zeta: float
    slope: float
    intercept: float
    loglog_exponent: float
    zeta_true: float


def damping_summary(
    omega_hat: np.ndarray, zeta_hat: np.ndarray, zeta_true: float, mask: np.ndarray | None = None
) -> DampingResult:
    """Summarise recovered damping over the parts selected by ``mask``.

    Fits need at least 2 parts with distinct omega; otherwise slope and exponent are NaN.

    Args:
        omega_hat: [K] natural frequencies, rad/s.
        zeta_hat: [K] damping ratios, dimensionless.
        zeta_true: the testbed's constant damping ratio.
        mask: [K] bool, the parts to summarise; None: all.

    Returns:
        The [`DampingResult`][physgs.recovery.damping.DampingResult]: gamma = zeta omega (1/s)
            per part, its least-squares line in omega and its log-log exponent.
    """
    omega = np.asarray(omega_hat, dtype=np.float64)
    zeta = np.asarray(zeta_hat, dtype=np.float64)
    if omega.shape != zeta.shape or omega.ndim != 1:
        raise ValueError(f"omega_hat {omega.shape} and zeta_hat {zeta.shape} must both be [K]")
    if mask is not None:
        omega, zeta = omega[np.asarray(mask, bool)], zeta[np.asarray(mask, bool)]
    if omega.size == 0:
        raise ValueError("damping_summary: no parts selected")
    if np.any(omega <= 0) or np.any(zeta <= 0):
        raise ValueError("omega_hat and zeta_hat must be positive")
    gamma = zeta * omega
    if omega.size >= 2 and np.ptp(omega) > 0:
        slope, intercept = np.polyfit(omega, gamma, 1)
        expo = np.polyfit(np.log(omega), np.log(gamma), 1)[0]
    else:
        slope = intercept = expo = float("nan")
    return DampingResult(
        zeta,
        omega,
        gamma,
        float(np.median(zeta)),
        float(slope),
        float(intercept),
        float(expo),
        float(zeta_true),
    )
