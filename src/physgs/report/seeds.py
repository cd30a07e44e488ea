"""The .tex cells over training seeds: mean +- sd, and paired differences with their 95%
interval, bold when decided (the statistics: ``physgs.statistics``, re-exported here).

A difference between two models is taken per seed first (the two share the seed's
initialisation stream, k-means and frame draws), then summarised.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from physgs.statistics import MAX_SEEDS, decided, decided_best, finite, interval, log_interval
from physgs.statistics import seeds_to_decide

#: the statistics (``physgs.statistics``) stay importable from here, beside the cells
__all__ = [
    "MAX_SEEDS",
    "UNDECIDED",
    "decided_best",
    "difference",
    "finite",
    "interval",
    "log_interval",
    "pm",
    "seeds_to_decide",
]

UNDECIDED = r"$^{\dagger}$"  # .tex mark of a difference whose interval contains 0 (or one seed)


def pm(values: Sequence[float], fmt: str, bold: bool = False) -> str:
    """.tex cell 'mean $\\pm$ sd' (the mean alone with one seed, '--' with none).

    Args:
        values: per-seed values.
        fmt: the number format (e.g. ``'.2f'``).
        bold: wrap the cell in ``\\textbf``.

    Returns:
        The cell's LaTeX.
    """
    m, sd, _, _ = interval(values)
    if not np.isfinite(m):
        return "--"
    s = format(m, fmt) + (rf" $\pm$ {format(sd, fmt)}" if np.isfinite(sd) else "")
    return rf"\textbf{{{s}}}" if bold else s


def difference(values: Sequence[float], fmt: str) -> str:
    """.tex cell of a paired difference, '$+1.23$ [0.80, 1.66]': bold when decided, else
    marked ``UNDECIDED``; '--' without a finite value.

    Args:
        values: per-seed paired differences.
        fmt: the number format (e.g. ``'.2f'``).

    Returns:
        The cell's LaTeX.
    """
    m, _, lo, hi = interval(values)
    if not np.isfinite(m):
        return "--"
    s = f"${format(m, '+' + fmt)}$"
    if np.isfinite(lo):
        s += f" [{format(lo, fmt)}, {format(hi, fmt)}]"
    return rf"\textbf{{{s}}}" if decided(values) else s + UNDECIDED
