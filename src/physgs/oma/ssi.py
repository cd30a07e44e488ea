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
    gathers poles within ``err_fn`` of their neighbour in frequency); nb: data blocks per
    record of pyOMA-2's covariance estimate of the Hankel matrix (the poles' standard
    deviations, [`physgs.oma.uncertainty`][]).
    """

    block_rows: int = 20
    order_max: int = 40
    order_step: int = 2
    err_fn: float = 0.05
    err_xi: float = 0.2
    err_phi: float = 0.05
    xi_max: float = 0.2
    min_stable: int = 5
    nb: int = 5


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
    ValueError naming the key (``<key>/block_rows``, ``<key>/order_max``, ``<key>/nb`` (2 to half
    the Hankel matrix's columns, so every data block holds two) or ``<key>/min_stable``).

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
    if not 2 <= s.nb <= (n_samples - 2 * s.block_rows + 1) // 2:
        raise RecordError(
            f"{key}/nb",
            f"= {s.nb} needs 2 to {(n_samples - 2 * s.block_rows + 1) // 2} data blocks of at"
            f" least 2 samples each in a record of {n_samples} samples",
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

    freq_hz [P, O] (NaN where no pole), stable [P, O] bool, orders [O]; freq_std [P, O] (Hz)
    and zeta_std [P, O]: each pole's standard deviations (NaN where none).
    """

    freq_hz: np.ndarray
    stable: np.ndarray
    orders: np.ndarray
    freq_std: np.ndarray | None = None
    zeta_std: np.ndarray | None = None


@dataclass(frozen=True)
class Modes:
    """Identified modes, in order of frequency.

    freq_hz [M]; zeta [M] (damping ratio); shape [M, C] complex, unit norm, rotated so its
    largest entry is real and positive; n_stable [M]: model orders at which it was stable;
    freq_spread [M]: the relative interquartile range of its stable poles' frequencies;
    freq_std [M] (Hz) and zeta_std [M]: its standard deviations (the median of its stable
    poles', [`physgs.oma.uncertainty`][]).
    """

    freq_hz: np.ndarray
    zeta: np.ndarray
    shape: np.ndarray
    n_stable: np.ndarray
    freq_spread: np.ndarray
    stab: Stabilisation
    freq_std: np.ndarray
    zeta_std: np.ndarray

    def select(self, keep: np.ndarray) -> "Modes":
        """The modes where ``keep`` holds, with the same stabilisation diagram.

        Args:
            keep: [M] bool.

        Returns:
            The kept modes.
        """
        return Modes(
            self.freq_hz[keep],
            self.zeta[keep],
            self.shape[keep],
            self.n_stable[keep],
            self.freq_spread[keep],
            self.stab,
            self.freq_std[keep],
            self.zeta_std[keep],
        )

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
    freq: np.ndarray,
    xi: np.ndarray,
    phi: np.ndarray,
    stable: np.ndarray,
    s: SSISettings,
    freq_std: np.ndarray | None = None,
    xi_std: np.ndarray | None = None,
) -> tuple[np.ndarray, ...]:
    """Cluster stable poles along frequency into modes.

    Poles sorted by frequency are cut where two neighbours differ by more than ``err_fn``
    (relative); a cluster is a mode when it holds stable poles of at least ``min_stable`` distinct
    orders. Its frequency and damping are the medians over its poles, its shape the pole of the
    highest order nearest its frequency, its standard deviations the medians of its poles'.

    Args:
        freq: [P, O] pole frequencies, Hz.
        xi: [P, O] pole damping ratios.
        phi: [P, O, C] pole shapes.
        stable: [P, O] bool.
        s: the SSI settings (``err_fn``, ``min_stable``).
        freq_std: [P, O] the poles' frequency standard deviations, Hz (None: NaN).
        xi_std: [P, O] the poles' damping standard deviations (None: NaN).

    Returns:
        ``(freq_hz [M], zeta [M], shape [M, C], n_stable [M], freq_spread [M], freq_std [M],
            zeta_std [M])``.
    """
    nan = np.full(freq.shape, np.nan)
    freq_std = nan if freq_std is None else freq_std
    xi_std = nan if xi_std is None else xi_std
    p_idx, o_idx = np.nonzero(stable & np.isfinite(freq))
    order = np.argsort(freq[p_idx, o_idx])
    p_idx, o_idx = p_idx[order], o_idx[order]
    f = freq[p_idx, o_idx]
    if f.size == 0:
        C = phi.shape[-1]
        e = np.zeros(0)
        return e, e, np.zeros((0, C), np.complex128), np.zeros(0, np.int64), e, e, e
    cuts = np.flatnonzero(np.diff(f) / f[:-1] > s.err_fn) + 1
    out = ([], [], [], [], [], [], [])
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
        out[5].append(_median_finite(freq_std[p_idx[grp], o_idx[grp]]))
        out[6].append(_median_finite(xi_std[p_idx[grp], o_idx[grp]]))
    C = phi.shape[-1]
    return (
        np.asarray(out[0], np.float64),
        np.asarray(out[1], np.float64),
        np.asarray(out[2], np.complex128).reshape(-1, C),
        np.asarray(out[3], np.int64),
        np.asarray(out[4], np.float64),
        np.asarray(out[5], np.float64),
        np.asarray(out[6], np.float64),
    )


def _median_finite(x: np.ndarray) -> float:
    """Median of the finite entries (NaN when none)."""
    x = x[np.isfinite(x)]
    return float(np.median(x)) if x.size else float("nan")


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


@dataclass(frozen=True)
class Poles:
    """Every pole SSI-cov found at every order tried, with pyOMA-2's labels and uncertainty.

    freq [P, O] Hz, xi [P, O], phi [P, O, C] complex, lam [P, O] complex continuous-time
    eigenvalues (1/s), freq_std [P, O] Hz, xi_std [P, O], stable [P, O] bool (pyOMA-2's soft
    criteria), orders [O]; NaN where no pole survived the hard criteria.
    """

    freq: np.ndarray
    xi: np.ndarray
    phi: np.ndarray
    lam: np.ndarray
    freq_std: np.ndarray
    xi_std: np.ndarray
    stable: np.ndarray
    orders: np.ndarray

    def stabilisation(self) -> Stabilisation:
        """The stabilisation diagram of these poles.

        Returns:
            The [`Stabilisation`][physgs.oma.ssi.Stabilisation] with the poles' sigmas.
        """
        return Stabilisation(self.freq, self.stable, self.orders, self.freq_std, self.xi_std)


def ssi_poles(ys: list[np.ndarray], fs: float, s: SSISettings) -> Poles:
    """SSI-cov through pyOMA-2's functions: the poles of every order and their uncertainty.

    Several records of the same channels (the same cells of one camera under each wind) give one
    system: pyOMA-2 builds each record's block Hankel matrix of output covariances and its
    covariance from ``s.nb`` data blocks; their mean (the covariances averaged over the records,
    each a stationary stretch of the same system) goes through its SSI and pole computation, as
    its ``SSI`` algorithm does for one, and the blocks of all records give the mean's
    covariance ([`combine_blocks`][physgs.oma.uncertainty.combine_blocks]).

    Args:
        ys: records [T_i, C] of the same C channels (any unit; each is centred here), at ``fs``.
        fs: sampling rate (Hz).
        s: the settings (``check_record`` runs first on each record).

    Returns:
        The [`Poles`][physgs.oma.ssi.Poles].

    Raises:
        ValueError: on records of different channel counts, non-finite or non-2-D records, or a
            record that cannot carry the settings (``RecordError``, naming the key).
    """
    # here: pyOMA-2 and scipy (~1 s); the config checks import this module to plan jobs
    from pyoma2.functions import gen, ssi

    from physgs.oma.uncertainty import combine_blocks, pole_std

    if not ys or len({np.shape(y)[1] if np.ndim(y) == 2 else -1 for y in ys}) != 1:
        raise ValueError("identify_records needs records [T_i, C] of one channel count C")
    hs, ts = [], []
    for y in ys:
        y = np.asarray(y, np.float64)
        if y.ndim != 2 or not np.all(np.isfinite(y)):
            raise ValueError(f"identify needs a finite [T, C] channel matrix, got {y.shape}")
        check_record(*y.shape, s)
        yt = (y - y.mean(axis=0)).T  # [C, T]
        h, t = ssi.build_hank(
            Y=yt, Yref=yt, br=int(s.block_rows), method="cov", calc_unc=True, nb=int(s.nb)
        )
        hs.append(h)
        ts.append(t)
    H = np.mean(hs, axis=0)
    T = combine_blocks(ts)
    obs, A, C, _ = ssi.SSI_fast(H, int(s.block_rows), int(s.order_max), step=int(s.order_step))
    freq, xi, phi, lam = ssi.SSI_poles(
        obs,
        A,
        C,
        int(s.order_max),
        1.0 / float(fs),
        step=int(s.order_step),
        HC=True,
        xi_max=float(s.xi_max),
    )[:4]
    lab = gen.SC_apply(
        freq, xi, phi, 0, int(s.order_max), int(s.order_step), s.err_fn, s.err_xi, s.err_phi
    )
    freq, xi = np.asarray(freq, np.float64), np.asarray(xi, np.float64)  # [P, O]
    f_std, z_std = pole_std(
        H, T, obs, A, C[0].shape[0], int(s.order_max), int(s.order_step), 1.0 / float(fs), freq
    )
    orders = np.arange(0, s.order_max + 1, s.order_step)[: freq.shape[1]]
    return Poles(
        freq,
        xi,
        np.asarray(phi, np.complex128),
        np.asarray(lam, np.complex128),
        f_std,
        z_std,
        np.asarray(lab) == 1,
        orders,
    )


def identify_records(ys: list[np.ndarray], fs: float, s: SSISettings) -> Modes:
    """SSI-cov of several records of one system ([`ssi_poles`][physgs.oma.ssi.ssi_poles]) and
    its modes ([`group_stable_poles`][physgs.oma.ssi.group_stable_poles]).

    Args:
        ys: records [T_i, C] of the same C channels (any unit; each is centred here), at ``fs``.
        fs: sampling rate (Hz).
        s: the settings (``check_record`` runs first on each record).

    Returns:
        ``Modes``: frequencies (Hz), damping ratios, shapes over the C channels, their standard
            deviations, and the stabilisation diagram.
    """
    p = ssi_poles(ys, fs, s)
    fm, zm, sh, ns, spread, fsd, zsd = group_stable_poles(
        p.freq, p.xi, p.phi, p.stable, s, p.freq_std, p.xi_std
    )
    return Modes(fm, zm, sh, ns, spread, p.stabilisation(), fsd, zsd)
