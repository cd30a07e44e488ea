"""Statistics over training seeds: every table's mean +- sd, and paired differences with their
95% interval, decided only when the interval excludes 0.

A table's CSV holds one row per seed (a ``seed`` column); its .tex shows the mean +- sd over
seeds. A difference between two models is taken per seed first (the two share the seed's
initialisation stream, k-means and frame draws) and then summarised (Student's t on the mean of
the paired differences). With one seed there is no interval, so nothing is decided.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

LEVEL = 0.95  # two-sided confidence level of every interval
UNDECIDED = r"$^{\dagger}$"  # .tex mark of a difference whose interval contains 0 (or one seed)


def finite(values: Sequence[float]) -> np.ndarray:
    """The finite values of ``values``, flattened, as float64.

    Args:
        values (Sequence[float]): per-seed values; NaN and infinity are dropped.

    Returns:
        np.ndarray: the finite values, ``[n]``.
    """
    return np.asarray([x for x in np.asarray(values, dtype=np.float64).ravel() if np.isfinite(x)])


def interval(values: Sequence[float], level: float = LEVEL) -> tuple[float, float, float, float]:
    """(mean, sd, low, high) over seeds, NaNs dropped; the interval is Student's t on the mean
    (sd and bounds NaN with one value, all NaN with none).

    Args:
        values: per-seed values.
        level: the interval's coverage.

    Returns:
        ``(mean, sd, low, high)``.
    """
    v = finite(values)
    if v.size == 0:
        return (np.nan,) * 4
    m = float(v.mean())
    if v.size == 1:
        return m, np.nan, np.nan, np.nan
    from scipy import stats  # here: the workflow plans with modules that import this one

    sd = float(v.std(ddof=1))
    h = float(stats.t.ppf(0.5 + level / 2, v.size - 1)) * sd / np.sqrt(v.size)
    return m, sd, m - h, m + h


def decided(values: Sequence[float], level: float = LEVEL) -> bool:
    """Whether the interval of the mean excludes 0 (False with fewer than two seeds, or when the
    differences are all exactly 0).

    Args:
        values: per-seed values (e.g. paired differences).
        level: the interval's coverage.

    Returns:
        True when decided.
    """
    _, _, lo, hi = interval(values, level)
    return bool(np.isfinite(lo) and (lo > 0 or hi < 0))


def paired(a: Sequence[float], b: Sequence[float]) -> np.ndarray:
    """Per-seed differences a - b [S] (a, b [S] in the same seed order).

    Args:
        a: [S] values.
        b: [S] values.

    Returns:
        [S] differences.

    Raises:
        ValueError: when the shapes differ.
    """
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(
            f"paired differences need one value per seed on both sides, got {a.shape} and {b.shape}"
        )
    return a - b


def decided_best(values: np.ndarray, higher: bool = True, level: float = LEVEL) -> int | None:
    """Column of values [S, M] (seeds x candidates) whose mean is best, when its paired
    difference to the runner-up is decided; None otherwise (ties, one seed, all NaN).

    Args:
        values: [S, M] per-seed values of M candidates.
        higher: True when higher is better.
        level: the interval's coverage.

    Returns:
        The best column's index, or None.
    """
    v = np.asarray(values, dtype=np.float64)
    means = np.array([np.nanmean(c) if np.isfinite(c).any() else np.nan for c in v.T])
    if np.isfinite(means).sum() < 2:
        return None
    order = np.argsort(-means if higher else means, kind="stable")
    order = [i for i in order if np.isfinite(means[i])]
    best, second = order[0], order[1]
    d = paired(v[:, best], v[:, second])
    return int(best) if decided(d if higher else -d, level) else None


def pm(values: Sequence[float], fmt: str, bold: bool = False) -> str:
    """.tex cell 'mean $\\pm$ sd' (just the mean with one seed, '--' with none).

    Args:
        values: per-seed values.
        fmt: the number format (e.g. ``'.2f'``).
        bold: wrap the cell in ``\textbf``.

    Returns:
        The cell's LaTeX.
    """
    m, sd, _, _ = interval(values)
    if not np.isfinite(m):
        return "--"
    s = format(m, fmt) + (rf" $\pm$ {format(sd, fmt)}" if np.isfinite(sd) else "")
    return rf"\textbf{{{s}}}" if bold else s


def difference(values: Sequence[float], fmt: str) -> str:
    """.tex cell of a paired difference: '$+1.23$ [0.80, 1.66]', bold when decided, marked
    with a dagger when not (the interval contains 0, or one seed gives none).

    Args:
        values: per-seed paired differences.
        fmt: the number format (e.g. ``'.2f'``).

    Returns:
        The cell's LaTeX (``'--'`` without a finite value).
    """
    m, _, lo, hi = interval(values)
    if not np.isfinite(m):
        return "--"
    s = f"${format(m, '+' + fmt)}$"
    if np.isfinite(lo):
        s += f" [{format(lo, fmt)}, {format(hi, fmt)}]"
    return rf"\textbf{{{s}}}" if decided(values) else s + UNDECIDED
