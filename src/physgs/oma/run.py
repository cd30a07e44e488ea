"""Output-only modal analysis of one tree's training video, and its recovery record.

``identify_video`` reads the frames of the training window and the background colour, nothing
else (never the wind: ``tests/test_oma.py`` replaces it by NaN). ``recover_oma`` is evaluation:
each part with a mode is integrated as ours' oscillator (omega, zeta from the mode, ours'
solver) under the training wind over the training window, exactly as the untrained null draws
are, and pushed through ours' matcher and trusted-part rule, so its row and the null's compare
like with like.
"""

from __future__ import annotations

import dataclasses
import json
import time
from dataclasses import asdict, dataclass, replace

import numpy as np

from physgs.atomic import atomic_path, write_json
from physgs.oma.channels import Channels, FlowSettings, flow_channels, principal_channels
from physgs.oma.intervals import coverage, interval_hits, relative_scores, sigma_trusted
from physgs.oma.parts import PartModes, assign_modes, cell_parts
from physgs.oma.ssi import (
    Modes,
    RecordError,
    SSISettings,
    Stabilisation,
    check_record,
    identify_records,
)
from physgs.recovery.record import recovery_dict, score_recovery, with_damping_scores


@dataclass(frozen=True)
class OMASettings:
    """flow: the channels; components: principal components SSI reads; ssi: SSI-cov;
    omega_hz: ours' frequency bounds (Hz): a mode outside them is not a part's estimate, as
    ours cannot reach it either."""

    flow: FlowSettings
    components: int
    ssi: SSISettings
    omega_hz: tuple[float, float]

    @staticmethod
    def from_config(oma: dict, ours: dict) -> "OMASettings":
        """The settings from the config's ``oma`` section and ours' frequency bounds.

        Args:
            oma: config ``oma`` (``flow``, ``components``, ``ssi``).
            ours: config ``models.ours`` (its ``omega_hz`` [lo, hi], Hz).

        Returns:
            The settings.
        """
        return OMASettings(
            FlowSettings(**oma["flow"]),
            int(oma["components"]),
            SSISettings(**oma["ssi"]),
            (float(ours["omega_hz"][0]), float(ours["omega_hz"][1])),
        )


@dataclass(frozen=True)
class Identification:
    """The channels' geometry and the modes identified from them."""

    channels: Channels
    modes: Modes
    seconds: float  # wall time of flow + SSI


@dataclass(frozen=True)
class Records:
    """The records SSI reads: each video's cell channels projected on the principal components of
    all records together."""

    channels: Channels  # the first video's (its cells serve every record)
    projected: list[np.ndarray]  # one [T, P] per video
    load: np.ndarray  # [P, C] the principal components over the cell channels


def projected_records(videos: list[np.ndarray], background, s: OMASettings) -> Records:
    """Flow channels of each video's window frames (the first video's cells for all), centred, and
    their projection on the principal components of all records together.

    Args:
        videos: one [T, H, W, 3] uint8 array per record (the training window's frames).
        background (ArrayLike): [3] the background colour (the foreground mask's reference).
        s: the analysis' settings (``flow``, ``components``).

    Returns:
        The [`Records`][physgs.oma.run.Records].
    """
    chans = [flow_channels(v, background, s.flow, reference=videos[0][0]) for v in videos]
    ys = [c.y - c.y.mean(axis=0) for c in chans]
    stacked = np.concatenate(ys)  # [sum T, C]
    _, load = principal_channels(stacked, min(s.components, *stacked.shape))
    return Records(chans[0], [y @ load.T for y in ys], load)


def check_channels(rec: Records, s: OMASettings) -> None:
    """Stop when the records the video gave cannot carry the SSI model, naming why.

    The config check at load ([`physgs.config_checks.oma_is_runnable`][]) assumes
    ``oma/components`` channels; the video can give fewer (two per cell of ``oma/flow/cell_px``
    px whose foreground share reaches ``oma/flow/min_fg``), which only the frames tell.

    Args:
        rec: the projected records.
        s: the analysis' settings.

    Raises:
        RecordError: naming ``oma/ssi/...`` and the cells, channels and components behind it.
    """
    n_samples = min(y.shape[0] for y in rec.projected)
    n_read = rec.projected[0].shape[1]
    try:
        check_record(n_samples, n_read, s.ssi)
    except RecordError as e:
        n_cells = rec.channels.n_cells
        raise RecordError(
            e.key,
            f"{e.msg}. The video gives {n_cells} cell(s) of oma/flow/cell_px = {s.flow.cell_px} px"
            f" with a foreground share of at least oma/flow/min_fg = {s.flow.min_fg}, so"
            f" {2 * n_cells} channels and {n_read} components for SSI (oma/components ="
            f" {s.components}): lower {e.key}, or lower oma/flow/cell_px for more cells",
        ) from None


def in_bounds(m: Modes, omega_hz: tuple[float, float]) -> np.ndarray:
    """Which modes lie inside ours' frequency bounds.

    Args:
        m: identified modes.
        omega_hz: ours' bounds (lo, hi), Hz.

    Returns:
        [M] bool.
    """
    return (m.freq_hz >= omega_hz[0]) & (m.freq_hz <= omega_hz[1])


def identify_video(
    videos: list[np.ndarray], background, fps: float, s: OMASettings
) -> Identification:
    """The records of every video ([`projected_records`][physgs.oma.run.projected_records]),
    SSI-cov over them together ([`identify_records`][physgs.oma.ssi.identify_records]), and the
    modes inside ours' bounds, their shapes mapped back over the cell channels.

    Args:
        videos: one [T, H, W, 3] uint8 array per record (the training window's frames).
        background (ArrayLike): [3] the background colour (the foreground mask's reference).
        fps: frame rate, frames/s.
        s: the analysis' settings.

    Returns:
        The [`Identification`][physgs.oma.run.Identification]: the first video's channels, the
            modes in ``s.omega_hz`` (Hz), and the wall time, s.
    """
    t0 = time.perf_counter()
    rec = projected_records(videos, background, s)
    check_channels(rec, s)
    m = identify_records(rec.projected, fps, s.ssi)
    keep = in_bounds(m, s.omega_hz)
    kept = m.select(keep)
    modes = replace(kept, shape=kept.shape @ rec.load)  # [M, C] over the cell channels
    return Identification(rec.channels, modes, time.perf_counter() - t0)


def save_identification(path, ident: Identification, s: OMASettings) -> None:
    """Write an identification and its settings to ``path`` (a ``.npz``) atomically.

    The channels' displacements are not stored, only their geometry.

    Args:
        path (str | os.PathLike): the ``.npz`` file to write.
        ident: the channels' geometry, the modes and the seconds it took.
        s: the settings it was made with (stored as JSON).
    """
    m, ch = ident.modes, ident.channels
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(
                fh,
                freq_hz=m.freq_hz,
                zeta=m.zeta,
                shape=m.shape,
                n_stable=m.n_stable,
                freq_spread=m.freq_spread,
                freq_std=m.freq_std,
                zeta_std=m.zeta_std,
                stab_freq_hz=m.stab.freq_hz,
                stab_freq_std=m.stab.freq_std,
                stab_zeta_std=m.stab.zeta_std,
                stab_stable=m.stab.stable,
                stab_orders=m.stab.orders,
                cell_xy=ch.cell_xy,
                channel_cell=ch.channel_cell,
                seconds=ident.seconds,
                settings=json.dumps(asdict(s)),
            )


def load_identification(path) -> Identification:
    """Read the identification that [save_identification][physgs.oma.run.save_identification] wrote.

    Args:
        path (str | os.PathLike): the ``.npz`` file.

    Returns:
        The identification; its channels' displacements ``y`` are empty ([0, C]).
    """
    with np.load(path) as d:
        modes = Modes(
            d["freq_hz"],
            d["zeta"],
            d["shape"],
            d["n_stable"],
            d["freq_spread"],
            Stabilisation(
                d["stab_freq_hz"],
                d["stab_stable"],
                d["stab_orders"],
                d["stab_freq_std"],
                d["stab_zeta_std"],
            ),
            d["freq_std"],
            d["zeta_std"],
        )
        ch = Channels(np.zeros((0, d["channel_cell"].size)), d["cell_xy"], d["channel_cell"])
        return Identification(ch, modes, float(d["seconds"]))


def part_modes(ident: Identification, K: int, seed: int, n_init: int) -> PartModes:
    """The cells' K parts (k-means, training seed) and each part's mode.

    Args:
        ident: the identification.
        K: number of parts.
        seed: the training seed (k-means).
        n_init: k-means restarts.

    Returns:
        The [`PartModes`][physgs.oma.parts.PartModes].

    Raises:
        ValueError: when K exceeds the foreground cells.
    """
    parts = cell_parts(ident.channels.cell_xy, K, seed, n_init)
    m = ident.modes
    return assign_modes(
        m.freq_hz, m.zeta, m.shape, ident.channels.channel_cell, parts, K, m.freq_std, m.zeta_std
    )


def recover_oma(
    pm: PartModes,
    observed,
    truth,
    solver: dict,
    bone_visible=None,
    damping: dict | None = None,
):
    """Ours' recovery record for the parts' modal estimates (evaluation: reads wind and truth).

    A part without a mode keeps ours' initial values and theta = 0.

    Args:
        pm: the parts' modes.
        observed (Observed): the dataset (training wind, vbar, fps, frame counts).
        truth (Truth): its ground truth.
        solver: ours' settings ([`null_settings`][physgs.recovery.run.null_settings]: omega_hz,
            zeta, zeta_init, substeps, rk4_guard).
        bone_visible (np.ndarray | None): [B] bool; restricts the scores to visible bones.
        damping: settings of the damping scores (``zeta_range``, ``seed``); None: none.

    Returns:
        (tuple[RecoveryRecord, dict]): ``(record, block)``: the
            [`RecoveryRecord`][physgs.recovery.record.RecoveryRecord] (its ``intervals``:
            [`interval_block`][physgs.oma.run.interval_block]) and the record's ``oma`` block (part and mode counts, the parts without an estimate, each mode's part, the
            median zeta).

    Raises:
        RuntimeError: if a part without a mode were matched as trusted.
    """
    # here: torch and the solver, which identification (the same module) never needs
    import torch

    from physgs.models.oscillator import integrate
    from physgs.models.ours import settings_substeps

    dt = 1.0 / float(observed.fps)
    sub = settings_substeps(solver, dt)
    est = pm.estimated
    K = est.size
    omega = np.where(est, pm.omega, 2 * np.pi * float(np.sqrt(np.prod(solver["omega_hz"]))))
    zeta = np.where(est, pm.zeta, float(solver["zeta_init"]))
    zeta = np.clip(zeta, *solver["zeta"])  # ours' bounds: the solver's guard holds
    wind = np.asarray(observed.wind[0], np.float64)  # [L+F]
    with torch.no_grad():
        th = integrate(
            torch.as_tensor(omega),
            torch.as_tensor(zeta),
            torch.ones(K, dtype=torch.float64),
            wind,
            float(np.asarray(observed.vbar)[0]),
            dt,
            sub,
            guard=float(solver["rk4_guard"]),  # the guard the substeps were sized for
        ).numpy()  # [K, L+F]
    th[~est] = 0.0  # no estimate: correlates with nothing, never trusted
    rec = score_recovery(
        th, omega, zeta, truth, int(observed.lead_in_frames), int(observed.n_train)
    )
    if np.any(rec.match.trusted & ~est):
        raise RuntimeError("a part with no mode was matched as trusted; its theta is not 0")
    if bone_visible is not None:
        rec = rec.with_visibility(bone_visible)
    if damping is not None:
        rec = with_damping_scores(rec, zeta, truth, damping)
    null_ranges = {  # the untrained nulls' draw ranges: omega over the bones', zeta the testbed's
        "omega": (float(np.min(truth.omega)), float(np.max(truth.omega))),
        "zeta": tuple(damping["zeta_range"]) if damping is not None else None,
    }
    rec = dataclasses.replace(rec, intervals=interval_block(pm, rec.match, truth, null_ranges))
    block = {
        "n_parts": int(K),
        "n_modes": int(pm.mode_part.size),
        "n_no_estimate": int((~est).sum()),
        "no_estimate": np.flatnonzero(~est).tolist(),
        "mode_part": pm.mode_part.tolist(),
        "median_zeta": float(np.median(pm.zeta[est])) if est.any() else float("nan"),
    }
    return rec, block


def interval_block(pm: PartModes, match, truth, null_ranges: dict | None = None) -> dict:
    """Each part's estimate with its standard deviations, the coverage of the trusted parts'
    95% intervals (evaluation: the matched bones' true omega and zeta), and how many parts
    each trust rule keeps (the matcher's trajectory correlation; the modes' own relative
    damping sigma, [`sigma_trusted`][physgs.oma.intervals.sigma_trusted]).

    Args:
        pm: the parts' modes (zeta before ours' bounds clip it).
        match (MatchResult): the matcher's result (``bone``, ``trusted``).
        truth (Truth): the ground truth (``omega`` [B] rad/s, ``zeta`` [B]).
        null_ranges: ``omega`` (rad/s) and ``zeta``: the ``(lo, hi)`` the untrained nulls draw
            from (None: not drawn), for the interval scores; None: no null scores.

    Returns:
        ``omega``, ``zeta``, ``omega_std``, ``zeta_std`` (per part, NaN where none),
            ``sigma_trusted`` (per part), ``n_sigma_trusted``, ``n_both_trusted``,
            ``median_rel_std`` (``omega``, ``zeta``: sigma / value over the trusted parts) and
            ``coverage`` (``omega`` and ``zeta``: k, n, fraction and its 95% interval over the
            matcher's trusted parts with an estimate) and ``interval_score`` (``omega`` and
            ``zeta``: the mean relative interval score of the same parts' 95% intervals and of
            the null's draw range, [`relative_scores`][physgs.oma.intervals.relative_scores]).
    """
    bone = np.asarray(match.bone)
    scored = np.asarray(match.trusted) & pm.estimated
    w_true = np.asarray(truth.omega, np.float64)[bone]
    z_true = np.asarray(truth.zeta, np.float64)[bone]
    s_trust = sigma_trusted(pm.zeta, pm.zeta_std)

    def nan_list(x):  # NaN where a part has no mode (written as NaN, as the record's others)
        return [float(v) for v in np.asarray(x, float)]

    return {
        "omega": nan_list(pm.omega),
        "zeta": nan_list(pm.zeta),
        "omega_std": nan_list(pm.omega_std),
        "zeta_std": nan_list(pm.zeta_std),
        "sigma_trusted": s_trust.tolist(),
        "n_sigma_trusted": int(s_trust.sum()),
        "n_both_trusted": int((s_trust & np.asarray(match.trusted)).sum()),
        "median_rel_std": {  # over the trusted parts with an estimate (NaN: none)
            "omega": _median_or_nan(pm.omega_std[scored] / pm.omega[scored]),
            "zeta": _median_or_nan(pm.zeta_std[scored] / pm.zeta[scored]),
        },
        "interval_score": {
            q: relative_scores(
                getattr(pm, q)[scored],
                getattr(pm, f"{q}_std")[scored],
                t[scored],
                (null_ranges or {}).get(q),
            )
            for q, t in (("omega", w_true), ("zeta", z_true))
        },
        "coverage": {
            "omega": coverage(
                interval_hits(pm.omega[scored], pm.omega_std[scored], w_true[scored])
            ).to_dict(),
            "zeta": coverage(
                interval_hits(pm.zeta[scored], pm.zeta_std[scored], z_true[scored])
            ).to_dict(),
        },
    }


def _median_or_nan(x: np.ndarray) -> float:
    """Median of the finite entries; NaN when there is none."""
    x = x[np.isfinite(x)]
    return float(np.median(x)) if x.size else float("nan")


def save_oma_recovery(path, rec, block: dict) -> None:
    """Ours' recovery record (``load_recovery`` reads it) plus an ``oma`` block.

    Args:
        path (str | Path): the JSON to write.
        rec (RecoveryRecord): the record.
        block: the ``oma`` block.
    """
    write_json(path, {**recovery_dict(rec), "oma": block})
