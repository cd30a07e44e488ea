"""Output-only modal analysis: covariance-driven stochastic subspace identification (SSI-cov).

pyOMA-2 (``pyoma2``, MIT) builds the block Hankel matrix of output covariances, identifies a
state-space model at every model order of the range, and labels each pole stable or not by its
soft criteria (frequency, damping and shape change from the next lower order). This module only
wraps it: it feeds a [T, C] channel matrix, keeps the stable poles, and groups them across model
orders into modes (a physical mode reappears at nearly the same frequency at every order above
the one that first resolves it; a spurious pole wanders). No input is read: the method assumes
broadband excitation and nothing else.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SSISettings:
    """SSI-cov settings (their values and how they were chosen: docs/blind.md).

    block_rows: block rows of the covariance Hankel matrix (its time lags reach
    ``block_rows / fs`` s); order_max: the highest model order (states; a mode takes two);
    order_step: orders tried in steps of this; err_fn, err_xi, err_phi: pyOMA-2's soft
    stability criteria (relative frequency change, relative damping change, 1 - MAC between
    successive orders); xi_max: poles damped above this are discarded (hard criterion);
    min_stable: a mode needs stable poles at this many model orders at least (its cluster
    gathers poles within ``err_fn`` of their neighbour in frequency).
    """

    block_rows: int = 20
    order_max: int = 40
    order_step: int = 2
    err_fn: float = 0.05
    err_xi: float = 0.2
    err_phi: float = 0.05
    xi_max: float = 0.2
    min_stable: int = 5


class RecordError(ValueError):
    """A record that cannot carry the requested model: ``key`` (a config key path, ``/``-joined)
    and ``msg`` apart, so a config check can name the key without parsing the text."""

    def __init__(self, key: str, msg: str):
        """Keep the key and the message; the text is ``"<key> <msg>"``."""
        super().__init__(f"{key} {msg}")
        self.key, self.msg = key, msg


def check_record(n_samples: int, n_channels: int, s: SSISettings, key: str = "oma/ssi") -> None:
    """Stop before any work when the record cannot carry the requested model.

    SSI-cov needs ``2 * block_rows`` lags with samples to spare (each covariance averages
    ``n_samples - 2 block_rows`` products; at least as many again as lags), and a model order no
    higher than ``(block_rows - 1) * n_channels``: the rows of the observability matrix less one
    block, from which pyOMA-2's ``SSI_fast`` takes the square ``R[:n, :n]`` of each order n (a
    higher order fails there with "Last 2 dimensions of the array must be square"). Raises
    ValueError naming the key (``<key>/block_rows`` or ``<key>/order_max``).

    Args:
        n_samples: samples per channel in the record.
        n_channels: channels SSI reads.
        s: the SSI settings.
        key: the config section named in the error.

    Raises:
        RecordError: naming the key and what the record lacks.
    """
    if n_channels < 1:
        raise RecordError(key, "has no channels to identify from (0 channels)")
    if n_samples < 4 * s.block_rows:
        raise RecordError(
            f"{key}/block_rows",
            f"= {s.block_rows} needs a record of at least 4 x {s.block_rows} ="
            f" {4 * s.block_rows} samples; this one has {n_samples}",
        )
    if s.order_max > (s.block_rows - 1) * n_channels:
        raise RecordError(
            f"{key}/order_max",
            f"= {s.order_max} exceeds (block_rows - 1) x channels ="
            f" {s.block_rows - 1} x {n_channels} = {(s.block_rows - 1) * n_channels}, the highest"
            " order the Hankel matrix can carry",
        )
    if s.min_stable > s.order_max // s.order_step:
        raise RecordError(
            f"{key}/min_stable",
            f"= {s.min_stable} exceeds the {s.order_max // s.order_step} model"
            " orders tried (order_max / order_step)",
        )


@dataclass(frozen=True)
class Stabilisation:
    """The stabilisation diagram: every pole at every order tried.

    freq_hz [P, O] (NaN where no pole), stable [P, O] bool, orders [O].
    """

    freq_hz: np.ndarray
    stable: np.ndarray
    orders: np.ndarray


@dataclass(frozen=True)
class Modes:
    """Identified modes, in order of frequency.

    freq_hz [M]; zeta [M] (damping ratio); shape [M, C] complex, unit norm, rotated so its
    largest entry is real and positive; n_stable [M]: model orders at which it was stable;
    freq_spread [M]: the relative interquartile range of its stable poles' frequencies.
    """

    freq_hz: np.ndarray
    zeta: np.ndarray
    shape: np.ndarray
    n_stable: np.ndarray
    freq_spread: np.ndarray
    stab: Stabilisation

    @property
    def n_modes(self) -> int:
        """The number of identified modes, M."""
        return int(self.freq_hz.size)


def _normalise(phi: np.ndarray) -> np.ndarray:
    """Unit-norm complex shape rotated so its largest entry is real positive."""
    phi = np.asarray(phi, np.complex128)
    k = int(np.argmax(np.abs(phi)))
    phi = phi * np.exp(-1j * np.angle(phi[k]))
    return phi / np.linalg.norm(phi)


def group_stable_poles(
    freq: np.ndarray, xi: np.ndarray, phi: np.ndarray, stable: np.ndarray, s: SSISettings
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cluster stable poles along frequency into modes.

    Poles sorted by frequency are cut where two neighbours differ by more than ``err_fn``
    (relative); a cluster is a mode when it holds stable poles of at least ``min_stable`` distinct
    orders. Its frequency and damping are the medians over its poles, its shape the pole of the
    highest order nearest its frequency.

    Args:
        freq: [P, O] pole frequencies, Hz.
        xi: [P, O] pole damping ratios.
        phi: [P, O, C] pole shapes.
        stable: [P, O] bool.
        s: the SSI settings (``err_fn``, ``min_stable``).

    Returns:
        ``(freq_hz [M], zeta [M], shape [M, C], n_stable [M], freq_spread [M])``.
    """
    p_idx, o_idx = np.nonzero(stable & np.isfinite(freq))
    order = np.argsort(freq[p_idx, o_idx])
    p_idx, o_idx = p_idx[order], o_idx[order]
    f = freq[p_idx, o_idx]
    if f.size == 0:
        C = phi.shape[-1]
        e = np.zeros(0)
        return e, e, np.zeros((0, C), np.complex128), np.zeros(0, np.int64), e
    cuts = np.flatnonzero(np.diff(f) / f[:-1] > s.err_fn) + 1
    out = ([], [], [], [], [])
    for grp in np.split(np.arange(f.size), cuts):
        n_ord = np.unique(o_idx[grp]).size
        if n_ord < s.min_stable:
            continue
        fg = f[grp]
        fm = float(np.median(fg))
        best = grp[np.lexsort((np.abs(fg - fm), -o_idx[grp]))[0]]  # highest order, then nearest
        q75, q25 = np.percentile(fg, [75, 25])
        out[0].append(fm)
        out[1].append(float(np.median(xi[p_idx[grp], o_idx[grp]])))
        out[2].append(_normalise(phi[p_idx[best], o_idx[best]]))
        out[3].append(n_ord)
        out[4].append(float((q75 - q25) / fm))
    C = phi.shape[-1]
    return (
        np.asarray(out[0], np.float64),
        np.asarray(out[1], np.float64),
        np.asarray(out[2], np.complex128).reshape(-1, C),
        np.asarray(out[3], np.int64),
        np.asarray(out[4], np.float64),
    )


def identify(y: np.ndarray, fs: float, s: SSISettings) -> Modes:
    """SSI-cov of one record (``identify_records`` of ``[y]``).

    Args:
        y: [T, C] the record's channels.
        fs: sampling rate, Hz.
        s: the SSI settings.

    Returns:
        The [`Modes`][physgs.oma.ssi.Modes].
    """
    return identify_records([y], fs, s)


def identify_records(ys: list[np.ndarray], fs: float, s: SSISettings) -> Modes:
    """SSI-cov through pyOMA-2's functions, and its modes.

    Several records of the same channels (the same cells of one camera under each wind) give one
    system: pyOMA-2 builds each record's block Hankel matrix of output covariances, and their
    mean (the covariances averaged over the records, each a stationary stretch of the same
    system) goes through its SSI and pole computation, as its ``SSI`` algorithm does for one.

    Args:
        ys: records [T_i, C] of the same C channels (any unit; each is centred here), at ``fs``.
        fs: sampling rate (Hz).
        s: the settings (``check_record`` runs first on each record).

    Returns:
        ``Modes``: frequencies (Hz), damping ratios, shapes over the C channels, and the
            stabilisation diagram.
    """
    from pyoma2.functions import gen, ssi

    if not ys or len({np.shape(y)[1] if np.ndim(y) == 2 else -1 for y in ys}) != 1:
        raise ValueError("identify_records needs records [T_i, C] of one channel count C")
    hs = []
    for y in ys:
        y = np.asarray(y, np.float64)
        if y.ndim != 2 or not np.all(np.isfinite(y)):
            raise ValueError(f"identify needs a finite [T, C] channel matrix, got {y.shape}")
        check_record(*y.shape, s)
        yt = (y - y.mean(axis=0)).T  # [C, T]
        hs.append(ssi.build_hank(Y=yt, Yref=yt, br=int(s.block_rows), method="cov")[0])
    H = np.mean(hs, axis=0)
    obs, A, C, _ = ssi.SSI_fast(H, int(s.block_rows), int(s.order_max), step=int(s.order_step))
    freq, xi, phi, *_ = ssi.SSI_poles(
        obs,
        A,
        C,
        int(s.order_max),
        1.0 / float(fs),
        step=int(s.order_step),
        HC=True,
        xi_max=float(s.xi_max),
    )
    lab = gen.SC_apply(
        freq, xi, phi, 0, int(s.order_max), int(s.order_step), s.err_fn, s.err_xi, s.err_phi
    )
    freq, xi = np.asarray(freq, np.float64), np.asarray(xi, np.float64)  # [P, O]
    phi = np.asarray(phi, np.complex128)  # [P, O, C]
    stable = np.asarray(lab) == 1
    orders = np.arange(0, s.order_max + 1, s.order_step)[: freq.shape[1]]
    fm, zm, sh, ns, spread = group_stable_poles(freq, xi, phi, stable, s)
    return Modes(fm, zm, sh, ns, spread, Stabilisation(freq, stable, orders))
