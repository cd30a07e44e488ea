"""Broadband wind: one turbulence realisation with a flat spectrum over [f_lo, f_hi] Hz.

The speed is a sum of equal-amplitude cosines on a frequency grid of spacing df with random
phases, so it is defined at every time t (seconds; t = 0 at recorded frame 1) and a longer
lead-in extends the same realisation backwards without changing the recorded window.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


PERIOD_S = 60.0  # the realisation repeats every PERIOD_S seconds (frequency grid 1 / PERIOD_S)


class WindError(ValueError):
    """Wind settings that cannot be used; the message names the key and the fix."""


@dataclass(frozen=True)
class WindField:
    """freqs [K] (Hz), phases [K] (rad), v0 (m/s mean), ti (std / mean)."""

    freqs: np.ndarray
    phases: np.ndarray
    v0: float
    ti: float

    def speed(self, t: np.ndarray) -> np.ndarray:
        """Wind speed (m/s) at times t [T] (s) -> [T]; unit-variance turbulence scaled by v0*ti.

        Args:
            t: [T] times, s.

        Returns:
            [T] wind speed, m/s.
        """
        t = np.asarray(t, dtype=np.float64)
        K = len(self.freqs)
        s = np.zeros_like(t)
        for k0 in range(0, K, 256):  # chunked to bound memory at [T, 256]
            f, ph = self.freqs[k0 : k0 + 256], self.phases[k0 : k0 + 256]
            s += np.cos(2 * np.pi * t[:, None] * f[None, :] + ph[None, :]).sum(1)
        return self.v0 * (1.0 + self.ti * np.sqrt(2.0 / K) * s)


def make_wind(
    *,
    v0: float,
    turbulence_intensity: float,
    f_lo_hz: float,
    f_hi_hz: float,
    seed_seq: np.random.SeedSequence,
    period_s: float = PERIOD_S,
) -> WindField:
    """A flat-spectrum realisation on the grid f = k / period_s inside [f_lo_hz, f_hi_hz].

    Args:
        v0: mean wind speed, m/s.
        turbulence_intensity: the speed's standard deviation over its mean.
        f_lo_hz: the band's lower edge, Hz.
        f_hi_hz: the band's upper edge, Hz.
        seed_seq: seeds the phases.
        period_s: the realisation's period, s; must exceed the whole record (lead-in included)
            so the record never repeats.

    Returns:
        The [`WindField`][physgs.testbed.wind.WindField]: frequencies on the grid, uniform phases.

    Raises:
        WindError: for an empty band.
    """
    if not 0 < f_lo_hz < f_hi_hz:
        raise WindError(
            f"wind band [{f_lo_hz}, {f_hi_hz}] Hz is empty; set 0 < f_lo_hz < f_hi_hz "
            "in testbed.wind of config/trees.yaml"
        )
    k = np.arange(np.ceil(f_lo_hz * period_s - 1e-9), np.floor(f_hi_hz * period_s + 1e-9) + 1)
    freqs = k / period_s
    phases = np.random.default_rng(seed_seq).uniform(0, 2 * np.pi, len(freqs))
    return WindField(freqs, phases, float(v0), float(turbulence_intensity))
