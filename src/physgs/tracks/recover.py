"""Recovery of the tracks control's oscillators against the truth file (evaluation only), through
the same matcher, trusted-part rule and records as ours ([`physgs.recovery`][])."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from physgs.atomic import write_json
from physgs.intermediate import read_json
from physgs.recovery.record import (
    RecoveryRecord,
    recovery_dict,
    score_recovery,
    with_damping_scores,
)
from physgs.tracks.fit import Oscillators, TrackFit, part_theta


@dataclass(frozen=True)
class TracksRecovery:
    """record: ours' recovery record over all K parts (a part with no estimate has theta = 0, so
    the matcher leaves it untrusted and it still counts in n_parts); no_estimate: indices of the
    parts that had fewer than the minimum of fitted tracks (``FitSettings.min_tracks``)."""

    record: RecoveryRecord
    no_estimate: np.ndarray
    median_zeta: float  # over the parts with an estimate (a part without one keeps zeta_init)
    #: [K] fitted tracks per part (every fitted condition) and the fewest a part needed
    n_tracks: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0, np.int64))
    min_tracks: int = -1

    @property
    def n_no_estimate(self) -> int:
        """The number of parts without an estimate."""
        return int(self.no_estimate.size)

    def to_dict(self) -> dict:
        """The tracks control's summary: match scores, median zeta, the parts' track counts.

        Returns:
            ``n_parts``, ``n_trusted``, ``median_rel_err``, ``loglog_r2``, ``median_zeta``,
                ``n_no_estimate``, ``no_estimate``, ``n_tracks_per_part`` and ``min_tracks``.
        """
        m = self.record.match
        return {
            "n_parts": int(m.n_parts),
            "n_trusted": int(m.n_trusted),
            "median_rel_err": float(m.median_rel_err),
            "loglog_r2": float(m.loglog_r2),
            "median_zeta": self.median_zeta,
            "n_no_estimate": self.n_no_estimate,
            "no_estimate": self.no_estimate.tolist(),
            "n_tracks_per_part": [int(n) for n in self.n_tracks],
            "min_tracks": int(self.min_tracks),
        }


def recover_tracks(
    fit: TrackFit,
    osc: Oscillators,
    observed,
    truth,
    bone_visible=None,
    damping: dict | None = None,
    min_tracks: int = -1,
) -> TracksRecovery:
    """Match the fitted parts to bones under the training wind over the training window.

    Args:
        fit: the fit.
        osc: its oscillators.
        observed (Observed): the dataset.
        truth (Truth): its ground truth.
        bone_visible (np.ndarray | None): [B] bool: also score the parts matched to visible bones
            (as ours' recovery).
        damping: ``{zeta_range, seed}`` to also score each trusted part's zeta against its bone's
            and against the untrained draw from zeta_range
            ([`physgs.recovery.damping_scores`][physgs.recovery.damping_scores], tab_damping),
            exactly as [`recover_model`][physgs.recovery.run.recover_model] does for ours.
        min_tracks: the fewest tracks a part needed (recorded beside each part's count).

    Returns:
        The [`TracksRecovery`][physgs.tracks.recover.TracksRecovery]: the record, the parts
            without an estimate and the median zeta of those with one.

    Raises:
        RuntimeError: if a part without an estimate were matched as trusted.
    """
    th = part_theta(fit, osc, np.asarray(observed.wind[0], np.float64))  # [K, L+F]
    rec = score_recovery(
        th, fit.omega, fit.zeta, truth, int(observed.lead_in_frames), int(observed.n_train)
    )
    if np.any(rec.match.trusted & ~fit.estimated):  # theta = 0 correlates with nothing
        raise RuntimeError("a part with no estimate was matched as trusted; its theta is not 0")
    if bone_visible is not None:
        rec = rec.with_visibility(bone_visible)
    if damping is not None:
        rec = with_damping_scores(rec, np.asarray(fit.zeta, np.float64), truth, damping)
    zeta = np.asarray(fit.zeta, np.float64)[fit.estimated]
    med = float(np.median(zeta)) if zeta.size else float("nan")
    return TracksRecovery(
        rec, np.flatnonzero(~fit.estimated), med, np.asarray(fit.n_tracks), int(min_tracks)
    )


def save_tracks_recovery(path, rec: TracksRecovery) -> None:
    """Ours' recovery record ([`physgs.recovery.record.load_recovery`][] reads it) plus a
    ``tracks`` block: the parts with no estimate (too few tracks), each part's track count
    and the minimum, so a part left out of the trusted count is never silently dropped.

    Args:
        path (str | Path): the JSON to write.
        rec: the tracks control's recovery.
    """
    write_json(path, {**recovery_dict(rec.record), "tracks": rec.to_dict()})


def load_tracks_block(path) -> dict:
    """The ``tracks`` block of a record written by ``save_tracks_recovery``.

    Args:
        path (str | Path): the JSON record.

    Returns:
        The block's dict.

    Raises:
        IntermediateFileError: when the file is missing, corrupt or lacks the block.
    """
    return read_json(path, ("tracks",), rule="tracks_evaluate")["tracks"]
