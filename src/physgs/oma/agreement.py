"""Agreement of modes identified from independent records of one system.

Used to choose SSI's settings on training data alone (``benchmarks/oma.py settings``): the
three winds' training videos of a tree are three records of the same structure, so a setting
whose modes come back from every record is preferred to one whose modes do not.
"""

from __future__ import annotations

import numpy as np


def reproduced_modes(modes: list[tuple[np.ndarray, np.ndarray]]) -> tuple[int, int]:
    """Count the modes that every other record reproduces, summed over the records.

    A mode (f, zeta) of one record is reproduced by another record when that record holds a
    mode (f', zeta') within the pair's half-power half-bandwidth,
    ``|f - f'| <= (zeta + zeta') / 2 * (f + f') / 2``: responses closer than that cannot be
    told apart.

    Args:
        modes: per record, (freq_hz [M_r] in Hz, zeta [M_r], damping ratios).

    Returns:
        (reproduced, found): modes reproduced by every other record, and modes found, each
        summed over the records.
    """
    hit = found = 0
    for r, (f, z) in enumerate(modes):
        f, z = np.asarray(f, np.float64), np.asarray(z, np.float64)
        found += f.size
        for fi, zi in zip(f, z):
            ok = True
            for q, (g, w) in enumerate(modes):
                if q == r:
                    continue
                g, w = np.asarray(g, np.float64), np.asarray(w, np.float64)
                tol = 0.5 * (zi + w) * 0.5 * (fi + g)  # [M_q] half-power half-bandwidths (Hz)
                ok = ok and bool(np.any(np.abs(g - fi) <= tol))
            hit += ok
    return hit, found
