"""The bounded parameterisation of an oscillator's omega and zeta, shared by every method that fits
the wind-driven oscillators (ours, and the 2D-track control, [`physgs.tracks.fit`][]).

- omega = exp(log lo + (log hi - log lo) * sigmoid(raw)), rad/s, inside [omega_lo, omega_hi];
- zeta = zeta_lo + (zeta_hi - zeta_lo) * sigmoid(raw);
- both start at their configured initial value (the raw value that maps to it);
- the drag forcing's mean speed of a condition is vbar = vbar_ratio * mean(its observed wind).

One parameterisation for both methods, so a difference in recovery between them is not a
difference in bounds, initialisation or the map from raw parameters.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch


def _logit(p: float) -> float:
    return math.log(p / (1.0 - p))


@dataclass(frozen=True)
class OscillatorBounds:
    """Bounds and initial values: omega_lo < omega_init < omega_hi in rad/s (all > 0);
    zeta_lo < zeta_init < zeta_hi (dimensionless, > 0)."""

    omega_lo: float
    omega_hi: float
    zeta_lo: float
    zeta_hi: float
    omega_init: float
    zeta_init: float

    @staticmethod
    def from_config(
        omega_hz, zeta, omega_init_hz: float, zeta_init: float, key: str = "models.ours"
    ) -> OscillatorBounds:
        """From the config's units.

        Args:
            omega_hz (Sequence[float]): ``[lo, hi]`` natural-frequency bounds, Hz.
            zeta (Sequence[float]): ``[lo, hi]`` damping-ratio bounds.
            omega_init_hz: initial natural frequency, Hz, strictly inside ``omega_hz``.
            zeta_init: initial damping ratio, strictly inside ``zeta``.
            key: the config section named in the error.

        Returns:
            The bounds in rad/s (omega) and dimensionless (zeta).

        Raises:
            ValueError: unless 0 < lo < init < hi for both.
        """
        lo, hi = (2 * math.pi * float(f) for f in omega_hz)
        zlo, zhi = (float(z) for z in zeta)
        w0 = 2 * math.pi * float(omega_init_hz)
        if not (0 < lo < w0 < hi):
            raise ValueError(
                f"{key} needs 0 < omega_hz[0] < omega_init_hz < omega_hz[1]; "
                f"got {omega_hz}, {omega_init_hz}"
            )
        if not (0 < zlo < zeta_init < zhi):
            raise ValueError(
                f"{key} needs 0 < zeta[0] < zeta_init < zeta[1]; got {zeta}, {zeta_init}"
            )
        return OscillatorBounds(lo, hi, zlo, zhi, w0, float(zeta_init))

    def omega_raw(self, omega: float) -> float:
        """The raw value whose omega is ``omega`` (rad/s, strictly inside the bounds).

        Args:
            omega: natural frequency, rad/s, strictly inside the bounds.

        Returns:
            The unconstrained raw value (logit of its log-position between the bounds).
        """
        lo, hi = math.log(self.omega_lo), math.log(self.omega_hi)
        return _logit((math.log(omega) - lo) / (hi - lo))

    def zeta_raw(self, zeta: float) -> float:
        """The raw value whose zeta is ``zeta`` (strictly inside the bounds).

        Args:
            zeta: damping ratio, strictly inside the bounds.

        Returns:
            The unconstrained raw value (logit of its position between the bounds).
        """
        return _logit((zeta - self.zeta_lo) / (self.zeta_hi - self.zeta_lo))

    def omega_raw_init(self) -> float:
        """The raw value whose omega is omega_init.

        Returns:
            The raw value (a float).
        """
        return self.omega_raw(self.omega_init)

    def zeta_raw_init(self) -> float:
        """The raw value whose zeta is zeta_init.

        Returns:
            The raw value (a float).
        """
        return self.zeta_raw(self.zeta_init)

    def omega(self, raw: torch.Tensor) -> torch.Tensor:
        """[K] natural frequencies, rad/s, from raw [K].

        Args:
            raw: [K] unconstrained values.

        Returns:
            [K] omega in (omega_lo, omega_hi), log omega linear in sigmoid(raw), rad/s.
        """
        lo, hi = math.log(self.omega_lo), math.log(self.omega_hi)
        return torch.exp(lo + (hi - lo) * torch.sigmoid(raw))

    def zeta(self, raw: torch.Tensor) -> torch.Tensor:
        """[K] damping ratios (dimensionless), from raw [K].

        Args:
            raw: [K] unconstrained values.

        Returns:
            [K] zeta in (zeta_lo, zeta_hi), linear in sigmoid(raw).
        """
        return self.zeta_lo + (self.zeta_hi - self.zeta_lo) * torch.sigmoid(raw)


def condition_vbar(vbar_ratio: float, wind) -> float:
    """m/s: the mean speed subtracted in the drag forcing v^2 - vbar^2 of one condition, the
    record's mean (wind [L+F] m/s) times the ratio frozen from the training condition
    (``ModelContext.vbar_ratio``).

    Args:
        vbar_ratio: the ratio frozen from the training condition.
        wind (ArrayLike): [L+F] the condition's observed wind, m/s.

    Returns:
        vbar, m/s.
    """
    return float(vbar_ratio) * float(torch.as_tensor(wind, dtype=torch.float64).mean())
