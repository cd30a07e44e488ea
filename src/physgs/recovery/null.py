"""Untrained null control for frequency recovery (the protocol, section 4).

Draw omega log-uniformly over the ground-truth range, keep zeta at the model's initial value,
integrate with the model's own solver under the same observed wind, and push the result
through the same matcher. If the null scores like the trained model, the metric cannot tell
whether recovery happened (dense skeletons tile the frequency axis too finely).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physgs.records import JsonRecord, floats
from physgs.recovery.matcher import TRUST_THRESHOLD, match_parts, restricted, training_window
from physgs.testbed.stats import nearest_bone_gap  # the testbed's own definition

N_DRAWS = 8


def draw_null_omegas(omega_bones: np.ndarray, n_parts: int, n_draws: int, seed: int) -> np.ndarray:
    """Draw natural frequencies log-uniformly over the bones' range, seeded.

    Args:
        omega_bones: [B] the bones' natural frequencies, rad/s (> 0).
        n_parts: K, frequencies per draw.
        n_draws: D, draws.
        seed: the generator's seed (same seed, same draws).

    Returns:
        [D, K] rad/s, log-uniform on [min omega_bones, max omega_bones].
    """
    lo, hi = np.log(np.min(omega_bones)), np.log(np.max(omega_bones))
    rng = np.random.default_rng(seed)
    return np.exp(rng.uniform(lo, hi, size=(n_draws, n_parts)))


@dataclass(frozen=True)
class NullResult(JsonRecord):
    """Null control: per-draw scores [D] and their medians; rel. errors and gaps as fractions."""

    n_trusted: np.ndarray  # [D]
    median_rel_err: np.ndarray = floats()  # [D] (NaN in a draw with no trusted part)
    loglog_r2: np.ndarray = floats()  # [D]
    omega: np.ndarray = floats()  # [D, K] rad/s drawn
    n_parts: int
    nearest_bone_gap: float  # median over draws and parts
    seed: int
    n_trusted_visible: np.ndarray | None = floats(default=None)  # [D] restricted to visible bones
    median_rel_err_visible: np.ndarray | None = floats(default=None)  # [D]

    @property
    def median_n_trusted(self) -> float:
        """Median over draws of the trusted parts."""
        return float(np.median(self.n_trusted))

    @property
    def median_median_rel_err(self) -> float:
        """Median over draws of each draw's median relative error (draws with none trusted skipped)."""
        v = self.median_rel_err[np.isfinite(self.median_rel_err)]
        return float(np.median(v)) if v.size else float("nan")

    @property
    def median_n_trusted_visible(self) -> float:
        """Median over draws of the parts trusted on visible bones (NaN without visibility)."""
        v = self.n_trusted_visible
        return float(np.median(v)) if v is not None else float("nan")

    @property
    def median_median_rel_err_visible(self) -> float:
        """Median over draws of the median error on visible bones (NaN without visibility)."""
        v = self.median_rel_err_visible
        v = v[np.isfinite(v)] if v is not None else np.array([])
        return float(np.median(v)) if v.size else float("nan")

    @property
    def median_loglog_r2(self) -> float:
        """Median over draws of the log-log R^2 of omega against the bones' (NaN draws skipped)."""
        v = self.loglog_r2[np.isfinite(self.loglog_r2)]
        return float(np.median(v)) if v.size else float("nan")


def null_control(
    omega_bones: np.ndarray,
    bone_theta: np.ndarray,
    wind: np.ndarray,
    *,
    n_parts: int,
    zeta_init: float,
    vbar: float,
    dt: float,
    substeps: int,
    lead_in_frames: int,
    n_train: int,
    seed: int,
    n_draws: int = N_DRAWS,
    gain: float = 1.0,
    threshold: float = TRUST_THRESHOLD,
    bone_visible: np.ndarray | None = None,
) -> NullResult:
    """Run the untrained null through the trained model's solver and the matcher.

    Each draw integrates [`physgs.models.oscillator.integrate`][] with drawn omega and zeta =
    ``zeta_init``; ``gain`` only scales theta, which correlation ignores.

    Args:
        omega_bones: [B] the bones' natural frequencies, rad/s.
        bone_theta: [B, n_train] the bones' angles over the training window at the training wind,
            rad.
        wind: [L+F] the training condition's observed wind at the frame rate, m/s, lead-in first.
        n_parts: K, parts per draw.
        zeta_init: damping ratio of every drawn oscillator (the model's initial value).
        vbar: the condition's mean wind speed, m/s, as the trained model uses it.
        dt: seconds per wind sample, 1 / fps.
        substeps: RK4 substeps per sample, as the trained model uses them.
        lead_in_frames: L, wind samples before recorded frame 0.
        n_train: training frames.
        seed: seeds the draws (same seed, same draws).
        n_draws: D, draws.
        gain: the oscillators' force gain, rad / m^2.
        threshold: |corr| at or above which a match is trusted.
        bone_visible: [B] bool, bones whose own motion is visible; when given each draw is also
            scored on them alone.

    Returns:
        The [`NullResult`][physgs.recovery.null.NullResult]: per-draw scores [D], the draws
            [D, K] rad/s and the median nearest-bone gap.
    """
    import torch  # here, not at the top: reading a null record needs no torch

    from physgs.models.oscillator import integrate  # the trained model's own solver (torch too)

    omega_bones = np.asarray(omega_bones, dtype=np.float64)
    draws = draw_null_omegas(omega_bones, n_parts, n_draws, seed)  # [D, K]
    w = torch.as_tensor(np.asarray(wind), dtype=torch.float64)
    n_tr, med, r2, vis = [], [], [], []
    for om in draws:
        with torch.no_grad():
            theta = integrate(
                torch.as_tensor(om),
                torch.full((n_parts,), float(zeta_init), dtype=torch.float64),
                torch.full((n_parts,), float(gain), dtype=torch.float64),
                w,
                float(vbar),
                float(dt),
                int(substeps),
            )  # [K, L+F]
        part = training_window(theta.detach().cpu().numpy(), lead_in_frames, n_train)
        m = match_parts(part, bone_theta, om, omega_bones, threshold)
        n_tr.append(m.n_trusted)
        med.append(m.median_rel_err)
        r2.append(m.loglog_r2)
        if bone_visible is not None:
            vis.append(restricted(m, bone_visible))
    gap = float(np.median(nearest_bone_gap(draws, omega_bones)))
    v_n, v_med = (np.asarray(x, float) for x in zip(*vis)) if vis else (None, None)
    return NullResult(
        np.asarray(n_tr),
        np.asarray(med),
        np.asarray(r2),
        draws,
        int(n_parts),
        gap,
        int(seed),
        v_n,
        v_med,
    )
