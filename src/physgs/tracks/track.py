"""Point tracks through one camera's video: OpenCV pyramidal Lucas-Kanade (no ground truth).

Input: the frames of one condition seen by the training camera (``observed.frames[c]``, [T, H, W, 3]
uint8) and the background colour (``observed.background``, [3] in [0, 1]); nothing else.

Method:
- foreground = pixels whose colour differs from the background by more than ``fg_tol`` grey
  levels in any channel, dilated by ``fg_dilate_px`` (corners on a thin branch sit on its edge);
- seeds: ``cv2.goodFeaturesToTrack`` (Shi-Tomasi) inside the foreground of the seed frame;
- each track is followed from its seed frame by ``cv2.calcOpticalFlowPyrLK`` with the seed frame
  as the template (``reference="seed"``, the previous estimate as the initial flow), so the
  error does not accumulate frame to frame: the swings are a few degrees, and the appearance of a
  patch at frame t stays close to its appearance at the seed frame. ``reference="previous"``
  chains frame to frame (the classic KLT; drifts) for comparison;
- forward-backward check: each new position is tracked back into the template frame; a track
  whose round trip misses its start by more than ``fb_max_px`` ends there, as does one that
  leaves the image or the (dilated) foreground, or whose LK status fails. A lost track never
  resumes (a re-found point is a new track);
- re-seeding: every ``reseed_every`` frames, new seeds are detected in the current frame away
  (``min_distance_px``) from the live tracks, up to ``max_tracks`` live tracks.

Pixel convention: the package's ([`physgs.camera`][]): pixel centres at integer + 0.5. OpenCV puts
them at integers, so positions are shifted by +0.5 px on the way out.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

#: OpenCV pixel centres are at integers, the package's at integer + 0.5
CV_TO_PX = 0.5


@dataclass(frozen=True)
class TrackSettings:
    """Tracker settings (chosen for 128 px frames of a tree that sways a few pixels per frame).

    win_px: LK window side (px); 11 covers a leaf cluster or a junction of thin branches
      without averaging over neighbouring branches that move differently.
    levels: pyramid levels above full resolution (2: 128 -> 32 px, enough for the few-pixel
      displacements between a template frame and any later frame).
    fb_max_px: forward-backward round-trip error (px) above which a track is lost.
    max_tracks: most live tracks at once; quality, min_distance_px, block_px: Shi-Tomasi's
      relative corner quality, spacing (px) and neighbourhood (px).
    reseed_every: frames between re-seeding passes.
    fg_tol: grey levels (0-255) from the background colour that count as foreground;
      fg_dilate_px: its dilation (px).
    reference: "seed" (template = the track's seed frame) or "previous" (frame to frame).
    lk_iters, lk_eps: LK termination (iterations, px).
    """

    win_px: int = 11
    levels: int = 2
    fb_max_px: float = 0.5
    max_tracks: int = 600
    quality: float = 0.01
    min_distance_px: float = 3.0
    block_px: int = 5
    reseed_every: int = 10
    fg_tol: int = 12
    fg_dilate_px: int = 1
    reference: str = "seed"
    lk_iters: int = 30
    lk_eps: float = 0.01

    def __post_init__(self):
        """Check the settings.

        Raises:
            ValueError: an unknown ``reference``, an even or too small ``win_px``, or a non-positive
                ``fb_max_px``, ``reseed_every`` or ``max_tracks``.
        """
        if self.reference not in ("seed", "previous"):
            raise ValueError(
                f"tracks.reference must be 'seed' or 'previous', got {self.reference!r}"
            )
        if self.win_px < 3 or self.win_px % 2 == 0:
            raise ValueError(f"tracks.win_px must be an odd integer >= 3, got {self.win_px}")
        if not (self.fb_max_px > 0 and self.reseed_every >= 1 and self.max_tracks >= 1):
            raise ValueError(
                "tracks.fb_max_px must be > 0, reseed_every >= 1 and max_tracks >= 1; got "
                f"{self.fb_max_px}, {self.reseed_every}, {self.max_tracks}"
            )

    def to_dict(self) -> dict:
        """The settings as a plain dict (field name -> value).

        Returns:
            Field name -> value.
        """
        return asdict(self)


@dataclass(frozen=True)
class Tracks:
    """Point tracks of one video. xy [P, T, 2] float64 px (x right, y down, pixel centres at
    integer + 0.5; NaN where not valid); valid [P, T] bool (a track is valid on one contiguous
    run of frames starting at its seed frame); start [P] int, the seed frame."""

    xy: np.ndarray
    valid: np.ndarray
    start: np.ndarray

    @property
    def n_tracks(self) -> int:
        """The number of tracks, P."""
        return int(self.xy.shape[0])

    def length(self) -> np.ndarray:
        """[P] frames each track is valid on.

        Returns:
            [P] int counts.
        """
        return self.valid.sum(axis=1)

    def first_xy(self) -> np.ndarray:
        """[P, 2] px, each track's position at its seed frame.

        Returns:
            [P, 2] positions, px.
        """
        return self.xy[np.arange(self.n_tracks), self.start]


def to_gray(frames: np.ndarray) -> np.ndarray:
    """[T, H, W, 3] uint8 RGB -> [T, H, W] uint8 luminance (OpenCV's weights).

    Args:
        frames: [T, H, W, 3] uint8 RGB.

    Returns:
        [T, H, W] uint8.

    Raises:
        ValueError: for another shape or dtype.
    """
    import cv2  # here: the workflow imports this module (Tracks) to plan jobs

    frames = np.asarray(frames)
    if frames.ndim != 4 or frames.shape[-1] != 3 or frames.dtype != np.uint8:
        raise ValueError(f"frames must be [T, H, W, 3] uint8, got {frames.shape} {frames.dtype}")
    return np.stack([cv2.cvtColor(f, cv2.COLOR_RGB2GRAY) for f in frames])


def foreground(frames: np.ndarray, background, tol: int, dilate_px: int) -> np.ndarray:
    """[T, H, W] bool: pixels of frames [T, H, W, 3] uint8 more than ``tol`` grey levels away from
    the background colour ([3] in [0, 1]) in some channel, dilated by ``dilate_px`` px.

    Args:
        frames: [T, H, W, 3] uint8.
        background (ArrayLike): [3] background colour in [0, 1].
        tol: grey levels (0..255) a foreground pixel differs by.
        dilate_px: dilation radius, px (0: none).

    Returns:
        [T, H, W] bool mask.
    """
    import cv2  # here: the workflow imports this module (Tracks) to plan jobs

    bg = np.round(np.asarray(background, dtype=np.float64) * 255.0).astype(np.int16)
    fg = (np.abs(frames.astype(np.int16) - bg).max(axis=-1) > tol).astype(np.uint8)
    if dilate_px > 0:
        kern = np.ones((2 * dilate_px + 1, 2 * dilate_px + 1), np.uint8)
        fg = np.stack([cv2.dilate(m, kern) for m in fg])
    return fg.astype(bool)


def _seeds(gray, fg, live_xy, s: TrackSettings, n_max: int) -> np.ndarray:
    """[n, 2] float32 OpenCV-pixel corners in ``fg`` [H, W] away from live_xy [m, 2]."""
    import cv2  # here: the workflow imports this module (Tracks) to plan jobs

    if n_max <= 0:
        return np.zeros((0, 2), np.float32)
    mask = fg.astype(np.uint8) * 255
    r = int(np.ceil(s.min_distance_px))
    for x, y in np.round(live_xy).astype(int):
        cv2.circle(mask, (int(x), int(y)), r, 0, -1)
    pts = cv2.goodFeaturesToTrack(
        gray,
        maxCorners=n_max,
        qualityLevel=s.quality,
        minDistance=s.min_distance_px,
        mask=mask,
        blockSize=s.block_px,
    )
    return np.zeros((0, 2), np.float32) if pts is None else pts.reshape(-1, 2).astype(np.float32)


def track_video(frames: np.ndarray, background, settings: TrackSettings | None = None) -> Tracks:
    """Track points through frames [T, H, W, 3] uint8 (one condition, training camera) over a
    background of colour ``background``. Deterministic (no random state).

    Args:
        frames: [T, H, W, 3] uint8.
        background (ArrayLike): [3] background colour in [0, 1].
        settings: the tracker's settings (default ``TrackSettings()``).

    Returns:
        The [`Tracks`][physgs.tracks.track.Tracks], P the number of tracks ever started (0 when
            nothing is tracked).
    """
    import cv2  # here: the workflow imports this module (Tracks) to plan jobs

    s = settings or TrackSettings()
    gray = to_gray(frames)  # [T, H, W]
    T, H, W = gray.shape
    fg = foreground(np.asarray(frames), background, s.fg_tol, s.fg_dilate_px)  # [T, H, W]
    lk = {
        "winSize": (s.win_px, s.win_px),
        "maxLevel": s.levels,
        "criteria": (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, s.lk_iters, s.lk_eps),
    }
    xs: list[np.ndarray] = []  # per track: [T, 2] float64 OpenCV px, NaN where not valid
    starts: list[int] = []
    live: list[int] = []  # indices of live tracks

    def add_seeds(t: int):
        cur = np.array([xs[i][t] for i in live]).reshape(-1, 2)
        new = _seeds(gray[t], fg[t], cur, s, s.max_tracks - len(live))
        for p in new:
            x = np.full((T, 2), np.nan)
            x[t] = p
            xs.append(x)
            starts.append(t)
            live.append(len(xs) - 1)

    add_seeds(0)
    for t in range(1, T):
        if live:
            idx = np.array(live)
            if s.reference == "seed":
                # one LK call per seed frame: the template is the frame the track began on
                groups = [
                    idx[np.array([starts[i] for i in idx]) == t0]
                    for t0 in sorted({starts[i] for i in idx})
                ]
            else:
                groups = [idx]
            keep = []
            for g in groups:
                t0 = starts[g[0]] if s.reference == "seed" else t - 1
                p0 = np.array([xs[i][t0] for i in g], np.float32).reshape(-1, 1, 2)
                guess = np.array([xs[i][t - 1] for i in g], np.float32).reshape(-1, 1, 2)
                p1, st1, _ = cv2.calcOpticalFlowPyrLK(
                    gray[t0], gray[t], p0, guess.copy(), flags=cv2.OPTFLOW_USE_INITIAL_FLOW, **lk
                )
                pb, st2, _ = cv2.calcOpticalFlowPyrLK(gray[t], gray[t0], p1, None, **lk)
                fb = np.linalg.norm((pb - p0).reshape(-1, 2), axis=1)
                q = p1.reshape(-1, 2).astype(np.float64)
                xi, yi = np.round(q[:, 0]).astype(int), np.round(q[:, 1]).astype(int)
                inside = (xi >= 0) & (xi < W) & (yi >= 0) & (yi < H)
                on_fg = np.zeros(len(g), bool)
                on_fg[inside] = fg[t, yi[inside], xi[inside]]
                ok = (st1.ravel() == 1) & (st2.ravel() == 1) & (fb <= s.fb_max_px) & on_fg
                ok &= np.isfinite(q).all(axis=1)
                for i, good, qi in zip(g, ok, q):
                    if good:
                        xs[i][t] = qi
                        keep.append(int(i))
            live = sorted(keep)
        if t % s.reseed_every == 0:
            add_seeds(t)
    if not xs:
        return Tracks(np.zeros((0, T, 2)), np.zeros((0, T), bool), np.zeros(0, np.int64))
    xy = np.stack(xs) + CV_TO_PX  # [P, T, 2] package px
    valid = np.isfinite(xy).all(axis=-1)
    return Tracks(xy, valid, np.asarray(starts, np.int64))


def track_condition(observed, condition: int, settings: dict) -> Tracks:
    """Tracks of condition ``condition``'s training-camera video over the training window
    (frames 0..n_train-1: what a method may train on).

    Args:
        observed (Observed): the dataset.
        condition: the wind condition's index.
        settings: [`TrackSettings`][physgs.tracks.track.TrackSettings] fields.

    Returns:
        The [`Tracks`][physgs.tracks.track.Tracks].

    Raises:
        ValueError: for a condition the dataset does not have.
    """
    if not 0 <= condition < len(observed.conditions):
        raise ValueError(f"condition {condition} is not one of the {len(observed.conditions)}")
    frames = np.asarray(observed.frames[condition, : int(observed.n_train)])
    return track_video(frames, observed.background, TrackSettings(**settings))
