"""The tracks control's jobs as the Snakemake rules call them (``workflow/rules/tracks.smk``).

- rule ``track`` calls [`track_condition`][physgs.tracks.track.track_condition] (one condition's
  training-camera video, observed only), whose module imports no torch;
- ``fit_job``: rule ``fit_tracks``, the oscillators of one configuration fitted to its tracks
  (observed wind only), refusing a K above the tracks it can group, with the key named;
- ``evaluate_job``: rule ``tracks_evaluate`` (reads the truth): the tracker's error, recovery
  through ours' matcher, and the predicted tracks' pixel errors beyond the window and under the
  unseen winds, beside a motionless prediction and beside ours' Gaussians at the same points.
"""

from __future__ import annotations

import numpy as np

from physgs.evaluate.adapter import model_means_fn
from physgs.tracks.fit import FitSettings, Oscillators, TrackFit, fit_tracks, predict_tracks
from physgs.tracks.recover import TracksRecovery, recover_tracks
from physgs.tracks.score import associate, model_point_tracks, motion_errors, score_tracker
from physgs.tracks.track import Tracks


def fit_job(tracks: list[Tracks], observed, job: dict) -> tuple[TrackFit, Oscillators]:
    """Fit the oscillators of one configuration.

    Args:
        tracks: one per condition of ``job["conditions"]``, in that order.
        observed (Observed): the dataset.
        job: [`fit_job`][physgs.tracks.settings.fit_job] of the settings.

    Returns:
        ``(fit, oscillators)``.

    Raises:
        ValueError: naming ``job["K_key"]`` when K exceeds the tracks long enough to fit
            (>= min_track_frames frames), which is only known once the video is tracked; also when
            the track files do not match the conditions.
    """
    if len(tracks) != len(job["conditions"]):
        raise ValueError(
            f"fit_job: {len(tracks)} track files for conditions {job['conditions']}; the rule "
            "must pass one per fitted condition"
        )
    K, n_min = int(job["K"]), int(job["min_track_frames"])
    lengths = np.sort(np.concatenate([tr.length() for tr in tracks]))[::-1]  # [P] longest first
    n_long = int((lengths >= n_min).sum())
    if K > n_long:
        # the largest min_track_frames that keeps K tracks: the K-th longest track's length
        frames_fix = (
            f", or lower tracks/min_track_frames (now {n_min}) to at most {int(lengths[K - 1])}"
            if len(lengths) >= K and lengths[K - 1] > 0
            else ""
        )
        raise ValueError(
            f"{job['K_key']} = {K} parts exceeds the {n_long} tracks of >= {n_min} frames "
            f"(tracks/min_track_frames) that the tracker kept in conditions {job['conditions']}: "
            f"k-means cannot make {K} groups. Lower {job['K_key']}"
            + ("" if job["K_key"] == "tracks/K" else " or set tracks/K (the tracks control alone)")
            + frames_fix
            + ", or drop the configuration from tracks/configs"
        )
    settings = FitSettings(
        K=K,
        iterations=int(job["iterations"]),
        lr=float(job["lr"]),
        min_track_frames=n_min,
        min_tracks=int(job["min_tracks"]),
        kmeans_n_init=int(job["kmeans_n_init"]),
        seed=int(job["seed"]),
    )
    osc = Oscillators.from_config(job["ours"], observed)
    fit = fit_tracks(tracks, list(job["conditions"]), observed.wind, osc, settings)
    return fit, osc


def motion_cases(observed) -> list[tuple[str, int, np.ndarray]]:
    """(name, condition, recorded frames) scored for motion: "tail" (the training wind's frames
    n_train..F-1, beyond the window) and "wind<c>" (condition c >= 1's window frames).

    Args:
        observed (Observed): the dataset.

    Returns:
        ``(name, condition, frames)`` per case, frames an int array.
    """
    T = int(observed.n_train)
    F = T + int(observed.n_tail)
    out = [("tail", 0, np.arange(T, F))]
    out += [(f"wind{c}", c, np.arange(T)) for c in range(1, len(observed.conditions))]
    return out


def _fitted(fit: TrackFit) -> np.ndarray:
    """[P] the tracks with a prediction: in a part that has an estimate."""
    lab = fit.labels[0]
    return (lab >= 0) & fit.estimated[np.maximum(lab, 0)]


def models_at_tracks(models: dict, fit: TrackFit, tracks0: Tracks, observed, truth) -> dict:
    """Each trained Gaussian model's prediction of the fitted tracked points, scored as the
    control's, each model's displacement measured since each track's seed frame.

    Args:
        models: name -> trained model (``gaussians_at``).
        fit: the tracks control's fit.
        tracks0: the tracks of condition 0.
        observed (Observed): the dataset.
        truth (Truth): its ground truth.

    Returns:
        ``{case: {name: motion_errors}}``, cases from
            [`motion_cases`][physgs.tracks.run.motion_cases], errors from
            [`motion_errors`][physgs.tracks.score.motion_errors].
    """
    cam = observed.train_camera
    fitted = _fitted(fit)
    verts = associate(truth, cam, tracks0, 0)
    rows = np.arange(tracks0.n_tracks)
    out: dict = {name: {} for name, _, _ in motion_cases(observed)}
    for key, model in models.items():
        means = model_means_fn(model, observed)
        seed_xy = np.full((tracks0.n_tracks, 2), np.nan)  # the model at each seed frame
        for t0 in np.unique(tracks0.start[fitted]):
            sel = rows[fitted & (tracks0.start == t0)]
            seed_xy[sel] = model_point_tracks(means, truth, cam, verts[sel], 0, [t0])[:, 0]
        for name, c, frames in motion_cases(observed):
            po = np.full((tracks0.n_tracks, len(frames), 2), np.nan)  # [P, F, 2]
            po[fitted] = model_point_tracks(means, truth, cam, verts[fitted], c, frames)
            out[name][key] = motion_errors(po, tracks0, truth, cam, c, frames, 0, seed_xy=seed_xy)
    return out


def evaluate_job(
    fit: TrackFit,
    osc: Oscillators,
    tracks0: Tracks,
    observed,
    truth,
    *,
    bone_visible=None,
    damping: dict | None = None,
    min_tracks: int = -1,
    ours=None,
) -> tuple[TracksRecovery, dict]:
    """Score one fit against the truth.

    Args:
        fit: the fit.
        osc: its oscillators.
        tracks0: the tracks of condition 0 (the fit's first entry).
        observed (Observed): the dataset.
        truth (Truth): its ground truth.
        bone_visible (np.ndarray | None): [B] bool; also score the parts matched to visible bones.
        damping: ``{zeta_range, seed}`` to score the damping too.
        min_tracks: the fewest tracks a part needed.
        ours (OscillatorPrior | None): ours' trained model in the same configuration (None: not
            scored).

    Returns:
        ``(recovery, scores)``: scores = {"tracker": ``TrackerScore`` dict of tracks0, "fit": {K,
            seconds, loop_seconds, rms_px, n_fitted, n_estimated}, and per motion case
            ([`motion_cases`][physgs.tracks.run.motion_cases]) {"tracks": motion_errors of the
            control, "ours": the same of ours' Gaussians at the same tracked points
            ([`models_at_tracks`][physgs.tracks.run.models_at_tracks])}}.

    Raises:
        ValueError: when the fit's first condition is not the training one.
    """
    if fit.conditions[0] != 0:
        raise ValueError(f"the fit's first condition is {fit.conditions[0]}, not the training one")
    cam = observed.train_camera
    rec = recover_tracks(
        fit, osc, observed, truth, bone_visible=bone_visible, damping=damping, min_tracks=min_tracks
    )
    fitted = _fitted(fit)
    scores: dict = {
        "tracker": score_tracker(tracks0, truth, cam, 0).to_dict(),
        "fit": {
            "K": int(len(fit.omega)),
            "seconds": float(fit.seconds),
            "loop_seconds": float(fit.loop_seconds),
            "rms_px": float(fit.rms_px),
            "n_fitted": int(fitted.sum()),
            "n_estimated": int(fit.estimated.sum()),
        },
    }
    at = models_at_tracks({"ours": ours}, fit, tracks0, observed, truth) if ours is not None else {}
    for name, c, frames in motion_cases(observed):
        pred = predict_tracks(fit, osc, 0, observed.wind[c], frames)  # [P, F, 2]
        scores[name] = {"tracks": motion_errors(pred, tracks0, truth, cam, c, frames, 0)}
        if ours is not None:
            scores[name]["ours"] = at[name]["ours"]
    return rec, scores
