"""Files of the tracks control: one video's tracks, and one fit with the oscillators it used.

Both are .npz written atomically ([`physgs.atomic.save_npz`][]). A fit file carries the
``Oscillators`` it was fitted with (bounds, RK4 substeps, frame rate, lead-in, calibration ratio,
gain, guard), so its evaluation integrates exactly the fitted model without reading the config.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np

from physgs.atomic import save_npz
from physgs.intermediate import read_npz, refuse
from physgs.tracks.track import Tracks

if TYPE_CHECKING:  # the fit's module imports torch: the tracker's job reads tracks only
    from physgs.tracks.fit import Oscillators, TrackFit

#: the scalar fields of ``Oscillators`` besides its bounds
_OSC_SCALARS = ("substeps", "fps", "lead_in", "vbar_ratio", "gain", "guard")
#: the workflow rules that write each file (named when one cannot be read)
TRACKS_RULE, FIT_RULE = "track", "fit_tracks"


def save_tracks(path, tracks: Tracks, condition: int) -> None:
    """Tracks of condition ``condition``'s training-camera video (``Tracks`` fields, px).

    Args:
        path (str | Path): the ``.npz`` to write.
        tracks: the tracks.
        condition: the wind condition's index.
    """
    save_npz(
        path,
        xy=tracks.xy,
        valid=tracks.valid,
        start=tracks.start,
        condition=np.int64(condition),
    )


def load_tracks(path) -> tuple[Tracks, int]:
    """(Tracks, condition index) from ``save_tracks``.

    Args:
        path (str | Path): the ``.npz``.

    Returns:
        ``(tracks, condition)``.

    Raises:
        IntermediateFileError: when the file is missing, corrupt or inconsistent (it is removed).
    """
    d = read_npz(path, ("xy", "valid", "start", "condition"), rule=TRACKS_RULE)
    xy, valid, start = d["xy"], d["valid"], d["start"]
    P = xy.shape[0] if xy.ndim == 3 else -1
    if not (
        xy.ndim == 3 and xy.shape[2] == 2 and valid.shape == xy.shape[:2] and start.shape == (P,)
    ):
        raise refuse(
            path,
            f"is inconsistent (xy {xy.shape}, valid {valid.shape}, start {start.shape})",
            TRACKS_RULE,
        )
    return Tracks(xy, valid.astype(bool), start), int(d["condition"])


def save_fit(path, fit: TrackFit, osc: Oscillators, K_key: str, min_tracks: int) -> None:
    """A fit and its oscillators.

    Args:
        path (str | Path): the ``.npz`` to write.
        fit: the fit.
        osc: its oscillators.
        K_key: the config key that set K (named by the evaluation).
        min_tracks: the fewest tracks a part needed for an estimate.
    """
    arrays = {
        "omega": fit.omega,
        "zeta": fit.zeta,
        "estimated": fit.estimated,
        "n_tracks": fit.n_tracks,
        "conditions": np.asarray(fit.conditions, np.int64),
        "loss_px2": fit.loss_px2,
        "seconds": np.float64(fit.seconds),
        "loop_seconds": np.float64(fit.loop_seconds),
        "rms_px": np.float64(fit.rms_px),
        "K_key": np.str_(K_key),
        "min_tracks": np.int64(min_tracks),
    }
    for i in range(len(fit.conditions)):
        arrays[f"labels_{i}"], arrays[f"c_{i}"], arrays[f"d_{i}"] = (
            fit.labels[i],
            fit.c[i],
            fit.d[i],
        )
    for f in dataclasses.fields(osc.bounds):
        arrays[f"bounds_{f.name}"] = np.float64(getattr(osc.bounds, f.name))
    for name in _OSC_SCALARS:
        arrays[f"osc_{name}"] = np.asarray(getattr(osc, name))
    save_npz(path, **arrays)


def load_fit(path) -> tuple[TrackFit, Oscillators, dict]:
    """(TrackFit, Oscillators, {"K_key", "min_tracks"}) from ``save_fit``.

    Args:
        path (str | Path): the ``.npz``.

    Returns:
        ``(fit, oscillators, {"K_key", "min_tracks"})``.

    Raises:
        IntermediateFileError: when the file is missing, corrupt or lacks an entry (it is removed).
    """
    # here: these load torch; the tracker's job and the workflow's planning import this module
    from physgs.models.oscillator_params import OscillatorBounds
    from physgs.tracks.fit import Oscillators, TrackFit

    scalars = ["omega", "zeta", "estimated", "n_tracks", "conditions", "loss_px2", "seconds"]
    scalars += ["loop_seconds", "rms_px", "K_key", "min_tracks"]
    scalars += [f"bounds_{f.name}" for f in dataclasses.fields(OscillatorBounds)]
    d = read_npz(path, scalars + [f"osc_{name}" for name in _OSC_SCALARS], rule=FIT_RULE)
    n = len(d["conditions"])
    absent = [k for i in range(n) for k in (f"labels_{i}", f"c_{i}", f"d_{i}") if k not in d]
    if absent:
        raise refuse(path, f"lacks {absent}", FIT_RULE)
    fit = TrackFit(
        d["omega"],
        d["zeta"],
        d["estimated"].astype(bool),
        d["n_tracks"],
        [d[f"labels_{i}"] for i in range(n)],
        [d[f"c_{i}"] for i in range(n)],
        [d[f"d_{i}"] for i in range(n)],
        [int(c) for c in d["conditions"]],
        d["loss_px2"],
        float(d["seconds"]),
        float(d["loop_seconds"]),
        float(d["rms_px"]),
    )
    bounds = OscillatorBounds(
        **{f.name: float(d[f"bounds_{f.name}"]) for f in dataclasses.fields(OscillatorBounds)}
    )
    scal = {name: d[f"osc_{name}"].item() for name in _OSC_SCALARS}
    osc = Oscillators(
        bounds,
        int(scal["substeps"]),
        int(scal["fps"]),
        int(scal["lead_in"]),
        float(scal["vbar_ratio"]),
        float(scal["gain"]),
        float(scal["guard"]),
    )
    return fit, osc, {"K_key": str(d["K_key"]), "min_tracks": int(d["min_tracks"])}
