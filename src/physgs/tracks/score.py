"""The tracker scored against ground truth (evaluation only: reads ``truth.npz``, never an input).

Each track is associated with one mesh vertex at its seed frame: among the vertices whose
projection falls within ``ASSOC_RADIUS_PX`` of the track's seed position, the one nearest the
camera (the visible surface; a vertex behind it projects just as near). With none that close, the
vertex nearest in pixels. The vertex's projected path under the same condition's true bone angles
is the track's truth; the track error is the pixel distance on the frames the track is valid.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from physgs.testbed import kinematics
from physgs.tracks.track import Tracks

#: pixels within which the front-most vertex is taken over the nearest one
ASSOC_RADIUS_PX = 1.0


def project_vertices(truth, camera, condition: int, frames: np.ndarray) -> np.ndarray:
    """[F, N, 2] px: every mesh vertex (mesh order) projected by ``camera`` at recorded frames
    ``frames`` [F] of ``condition`` (true bone angles ``truth.theta[condition, L + j]``).

    Args:
        truth (Truth): the dataset's ground truth.
        camera (Camera): the camera.
        condition: the wind condition's index.
        frames: [F] recorded-frame indices.

    Returns:
        [F, N, 2] pixel positions.
    """
    L = int(truth.lead_in_frames)
    V = kinematics.pose_vertices(truth, truth.theta[condition, L + np.asarray(frames)])  # [F, N, 3]
    F, N = V.shape[:2]
    uv, _ = camera.project(V.reshape(-1, 3))
    return uv.reshape(F, N, 2)


def associate(truth, camera, tracks: Tracks, condition: int) -> np.ndarray:
    """[P] mesh vertex index of each track (see the module docstring), at its seed frame.

    Args:
        truth (Truth): the dataset's ground truth.
        camera (Camera): the camera the tracks were made in.
        tracks: the tracks.
        condition: the wind condition's index of their video.

    Returns:
        [P] int64 vertex indices.
    """
    L = int(truth.lead_in_frames)
    out = np.empty(tracks.n_tracks, np.int64)
    first = tracks.first_xy()  # [P, 2]
    for t0 in np.unique(tracks.start):
        sel = np.flatnonzero(tracks.start == t0)
        V = kinematics.pose_vertices(truth, truth.theta[condition, L + int(t0)])  # [N, 3]
        uv, z = camera.project(V)
        d = np.linalg.norm(first[sel, None, :] - uv[None], axis=-1)  # [p, N]
        near = d <= ASSOC_RADIUS_PX
        front = np.where(near, z[None], np.inf).argmin(axis=1)
        out[sel] = np.where(near.any(axis=1), front, d.argmin(axis=1))
    return out


def truth_tracks(truth, camera, vertices: np.ndarray, condition: int, frames) -> np.ndarray:
    """[P, F, 2] px: vertices [P] (mesh order) projected at recorded frames [F] of condition.

    Args:
        truth (Truth): the dataset's ground truth.
        camera (Camera): the camera.
        vertices: [P] mesh vertex indices.
        condition: the wind condition's index.
        frames (ArrayLike): [F] recorded-frame indices.

    Returns:
        [P, F, 2] pixel positions.
    """
    uv = project_vertices(truth, camera, condition, frames)  # [F, N, 2]
    return np.transpose(uv[:, np.asarray(vertices)], (1, 0, 2))


@dataclass(frozen=True)
class TrackerScore:
    """One video's tracker error. median_px / p90_px: median and 90th percentile over every
    (track, frame) where the track is valid in the window; share_kept: fraction of the tracks
    seeded at frame 0 that are still valid at the window's last frame; n_tracks: tracks ever
    started; n_seed0: tracks seeded at frame 0; mean_length: mean valid frames per track;
    median_start_px: median error at the seed frame (the association's own offset: the nearest
    vertex is not the tracked point). disp_median_px / disp_p90_px: the same over the error of the
    displacement since the seed frame (x(t) - x(t0) against gt(t) - gt(t0)), which removes that
    constant offset and scores the motion the oscillators are fitted to.
    """

    median_px: float
    p90_px: float
    disp_median_px: float
    disp_p90_px: float
    share_kept: float
    n_tracks: int
    n_seed0: int
    mean_length: float
    median_start_px: float

    def to_dict(self) -> dict:
        """The score as a plain dict (field name -> value).

        Returns:
            Field name -> value.
        """
        return asdict(self)


def track_errors(tracks: Tracks, gt: np.ndarray) -> np.ndarray:
    """[P, T] px distance between tracks and their truth gt [P, T, 2]; NaN where not valid.

    Args:
        tracks: the tracks, xy [P, T, 2] px.
        gt: [P, T, 2] their true paths, px.

    Returns:
        [P, T] errors, px.
    """
    e = np.linalg.norm(tracks.xy - gt, axis=-1)
    return np.where(tracks.valid, e, np.nan)


def score_tracker(tracks: Tracks, truth, camera, condition: int = 0) -> TrackerScore:
    """Score tracks [P, T] of ``condition``'s training-camera video over its T frames.

    Args:
        tracks: the tracks of the video.
        truth (Truth): the dataset's ground truth.
        camera (Camera): the training camera.
        condition: the video's wind condition.

    Returns:
        The [`TrackerScore`][physgs.tracks.score.TrackerScore] (NaN scores without tracks).
    """
    T = tracks.xy.shape[1]
    if tracks.n_tracks == 0:
        nan = float("nan")
        return TrackerScore(nan, nan, nan, nan, 0.0, 0, 0, 0.0, nan)
    verts = associate(truth, camera, tracks, condition)
    gt = truth_tracks(truth, camera, verts, condition, np.arange(T))  # [P, T, 2]
    e = track_errors(tracks, gt)
    ev = e[np.isfinite(e)]
    rows = np.arange(tracks.n_tracks)
    disp = Tracks(tracks.xy - tracks.xy[rows, tracks.start][:, None], tracks.valid, tracks.start)
    ed = track_errors(disp, gt - gt[rows, tracks.start][:, None])
    ed = ed[np.isfinite(ed)]
    s0 = tracks.start == 0
    e0 = e[np.arange(tracks.n_tracks), tracks.start]
    return TrackerScore(
        float(np.median(ev)),
        float(np.percentile(ev, 90)),
        float(np.median(ed)),
        float(np.percentile(ed, 90)),
        float(tracks.valid[s0, T - 1].mean()) if s0.any() else 0.0,
        tracks.n_tracks,
        int(s0.sum()),
        float(tracks.length().mean()),
        float(np.median(e0)),
    )


def motion_errors(
    pred: np.ndarray,
    tracks: Tracks,
    truth,
    camera,
    condition: int,
    frames,
    fit_condition: int = 0,
    seed_xy: np.ndarray | None = None,
) -> dict:
    """Pixel errors of predicted tracks at recorded frames, against their associated vertices'
    true paths.

    Args:
        pred: [P, F, 2] predicted positions, px (rows NaN for unfitted tracks).
        tracks: the tracks (seeded in the video of ``fit_condition``).
        truth (Truth): the dataset's ground truth.
        camera (Camera): the training camera.
        condition: the wind condition of ``frames``.
        frames (ArrayLike): [F] recorded-frame indices.
        fit_condition: the condition whose video the tracks come from.
        seed_xy: [P, 2] px, the position the offset is measured from, in place of the tracked one
            at each seed frame: a model scored at the tracked points
            ([`model_point_tracks`][physgs.tracks.score.model_point_tracks]) passes its own
            position at the seed frame, so its motion error is, like the tracks control's, the
            error of its displacement since the seed frame.

    Returns:
        ``{"median_px": raw position error, "motion_median_px": error after removing each
            track's association offset (track minus vertex at its seed frame, measured once in
            the fitted video: the vertex is not the tracked point), "static_median_px": the same
            for a motionless prediction at each track's mean tracked position (the no-physics
            baseline), "n_tracks"}``; NaN errors and 0 tracks when no row is fitted.
    """
    ok = np.isfinite(pred).all(axis=(1, 2))
    if not ok.any():
        nan = float("nan")
        return {"median_px": nan, "motion_median_px": nan, "static_median_px": nan, "n_tracks": 0}
    verts = associate(truth, camera, tracks, fit_condition)[ok]
    gt = truth_tracks(truth, camera, verts, condition, frames)  # [p, F, 2]
    rows = np.flatnonzero(ok)
    st = tracks.start[rows]
    seed_gt = np.stack(
        [
            truth_tracks(truth, camera, verts[i : i + 1], fit_condition, [st[i]])[0, 0]
            for i in range(len(rows))
        ]
    )  # [p, 2]
    seed = tracks.xy[rows, st] if seed_xy is None else np.asarray(seed_xy, np.float64)[rows]
    offset = seed - seed_gt  # [p, 2]
    still = np.nanmean(np.where(tracks.valid[rows, :, None], tracks.xy[rows], np.nan), axis=1)
    p = pred[ok]
    return {
        "median_px": float(np.median(np.linalg.norm(p - gt, axis=-1))),
        "motion_median_px": float(np.median(np.linalg.norm(p - gt - offset[:, None], axis=-1))),
        "static_median_px": float(
            np.median(np.linalg.norm(still[:, None] - gt - offset[:, None], axis=-1))
        ),
        "n_tracks": int(ok.sum()),
    }


def model_point_tracks(
    means_fn, truth, camera, vertices: np.ndarray, condition: int, frames
) -> np.ndarray:
    """A Gaussian model's prediction at the tracked points' mesh vertices.

    The projection by ``camera`` of each vertex's Gaussian (``truth.vertex_gaussian``: the observed
    Gaussians are stored in a random order) at recorded ``frames`` of ``condition``.

    Args:
        means_fn (Callable): ``means_fn(frame, condition) -> [N, 3]`` world units
            ([`model_means_fn`][physgs.evaluate.adapter.model_means_fn]).
        truth (Truth): the dataset's ground truth.
        camera (Camera): the camera.
        vertices: [P] mesh vertex indices ([`associate`][physgs.tracks.score.associate]).
        condition: the wind condition's index.
        frames (ArrayLike): [F] recorded-frame indices.

    Returns:
        [P, F, 2] pixel positions.
    """
    gauss = np.asarray(truth.vertex_gaussian, np.int64)[np.asarray(vertices, np.int64)]
    frames = np.asarray(frames, np.int64)
    xyz = np.stack([np.asarray(means_fn(int(j), condition))[gauss] for j in frames], axis=1)
    uv, _ = camera.project(xyz.reshape(-1, 3).astype(np.float64))
    return uv.reshape(len(gauss), len(frames), 2)
