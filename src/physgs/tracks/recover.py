"""Recovery of the tracks control's oscillators against the truth file (evaluation only), through
the same matcher, trusted-part rule and records as ours (``physgs.recovery``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physgs.recovery.record import RecoveryRecord, score_recovery
from physgs.tracks.fit import Oscillators, TrackFit, part_theta


@dataclass(frozen=True)
class TracksRecovery:
    """record: ours' recovery record over all K parts (a part with no estimate has theta = 0, so
    the matcher leaves it untrusted and it still counts in n_parts); no_estimate: indices of the
    parts that had fewer than the minimum of fitted tracks (``FitSettings.min_tracks``)."""

    record: RecoveryRecord
    no_estimate: np.ndarray
    median_zeta: float  # over the parts with an estimate (a part without one keeps zeta_init)

    @property
    def n_no_estimate(self) -> int:
        return int(self.no_estimate.size)

    def to_dict(self) -> dict:
        m = self.record.match
        return {
            "n_parts": int(m.n_parts),
            "n_trusted": int(m.n_trusted),
            "median_rel_err": float(m.median_rel_err),
            "loglog_r2": float(m.loglog_r2),
            "median_zeta": self.median_zeta,
            "n_no_estimate": self.n_no_estimate,
            "no_estimate": self.no_estimate.tolist(),
        }


def recover_tracks(fit: TrackFit, osc: Oscillators, observed, truth) -> TracksRecovery:
    """Match the fitted parts to bones under the training wind over the training window."""
    th = part_theta(fit, osc, np.asarray(observed.wind[0], np.float64))  # [K, L+F]
    rec = score_recovery(
        th, fit.omega, fit.zeta, truth, int(observed.lead_in_frames), int(observed.n_train)
    )
    if np.any(rec.match.trusted & ~fit.estimated):  # theta = 0 correlates with nothing
        raise RuntimeError("a part with no estimate was matched as trusted; its theta is not 0")
    zeta = np.asarray(fit.zeta, np.float64)[fit.estimated]
    med = float(np.median(zeta)) if zeta.size else float("nan")
    return TracksRecovery(rec, np.flatnonzero(~fit.estimated), med)
