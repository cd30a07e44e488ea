"""Cameras that frame the tree: every camera on one horizontal orbit (one distance, one height)
about the vertical line through the centre of the tree's swept extent, looking horizontally.

Framing (``testbed.fill_height``): the swept extent (every posed vertex over every recorded frame of
every condition) spans exactly ``fill_height`` of the training camera's image height. The field of
view stays as configured; the camera moves (distance D from the orbit axis, height h). The training
view is centred vertically where every held-out view allows it; where a held-out view would clip (a
branch nearer to that camera projects higher), h shifts just enough to keep it in. Every camera,
training and held-out, must see the whole swept extent at least ``margin_px`` pixels inside its
border, or [`FramingError`][physgs.testbed.scene.FramingError] names ``testbed.fill_height`` and the
largest value that fits.
"""

from __future__ import annotations

import numpy as np

from physgs.camera import Camera, look_at


class FramingError(ValueError):
    """The tree cannot be framed as configured; the message names the key and the fix."""


def convex_hull_points(chunks) -> np.ndarray:
    """Vertices [K, 3] of the convex hull of all points in ``chunks`` (an iterable of [..., 3]).

    Every framing constraint (in front of a camera, inside its image) is a half-space in world
    coordinates, so it holds for a point set exactly when it holds for its hull's vertices.

    Args:
        chunks (Iterable[ArrayLike]): point sets of shape [..., 3], hulled one after another.

    Returns:
        [K, 3] hull vertices (all points where the set is flat or too small for a hull).
    """
    # here: scipy; the config checks import this module (via testbed.dataset) to plan jobs
    from scipy.spatial import ConvexHull, QhullError

    keep = np.empty((0, 3))
    for c in chunks:
        pts = np.concatenate([keep, np.asarray(c, dtype=np.float64).reshape(-1, 3)])
        try:
            keep = pts[ConvexHull(pts).vertices]
        except (QhullError, ValueError):  # flat or too few points: keep them all
            keep = pts
    return keep


def _rotate_z(points: np.ndarray, centre_xy: np.ndarray, deg: float) -> np.ndarray:
    """Points turned by -deg about the vertical line through centre_xy (so a camera at azimuth deg
    sees them as the azimuth-0 camera sees the result)."""
    a = np.deg2rad(deg)
    c, s = np.cos(a), np.sin(a)
    x, y = points[:, 0] - centre_xy[0], points[:, 1] - centre_xy[1]
    return np.stack([c * x + s * y + centre_xy[0], -s * x + c * y + centre_xy[1], points[:, 2]], 1)


def orbit_cameras(
    centre_xy, distance: float, height: float, azimuths_deg, *, fov_deg: float, resolution: int
) -> list[Camera]:
    """Square cameras at ``distance`` (m) from the vertical line through centre_xy [2] (m), at
    ``height`` (m), looking horizontally at it. Azimuth 0 sits on -y looking along +y; azimuths in
    degrees, counter-clockwise seen from above.

    Args:
        centre_xy (ArrayLike): [2] the orbit axis' (x, y), m.
        distance: horizontal distance from the axis, m.
        height: camera height (z), m.
        azimuths_deg (Iterable[float]): the cameras' azimuths, degrees.
        fov_deg: field of view, degrees.
        resolution: image side, px.

    Returns:
        One [`Camera`][physgs.camera.Camera] per azimuth.
    """
    c = np.asarray(centre_xy, dtype=np.float64)
    cams = []
    for a in azimuths_deg:
        ar = np.deg2rad(float(a))
        eye = np.array([c[0] + distance * np.sin(ar), c[1] - distance * np.cos(ar), height])
        cams.append(
            look_at(eye, [c[0], c[1], height], fov_deg=fov_deg, width=resolution, height=resolution)
        )
    return cams


def _violation(cam: Camera, points: np.ndarray, margin_px: float):
    """None if every point is in front of ``cam`` and inside its image with margin_px to spare;
    else (u, v, depth) of the worst point."""
    uv, z = cam.project(points)
    over = np.maximum.reduce(
        [
            margin_px - uv[:, 0],
            uv[:, 0] - (cam.width - margin_px),
            margin_px - uv[:, 1],
            uv[:, 1] - (cam.height - margin_px),
        ]
    )
    over = np.where(z > cam.near, over, np.inf)
    i = int(np.argmax(over))
    return None if over[i] <= 1e-6 else (float(uv[i, 0]), float(uv[i, 1]), float(z[i]))  # round-off


def _bisect(f, lo: float, hi: float, n: int = 60) -> float:
    """Root of f, decreasing and changing sign on [lo, hi] (lo: f >= 0, hi: f < 0)."""
    for _ in range(n):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) >= 0 else (lo, mid)
    return 0.5 * (lo + hi)


def frame_cameras(
    points: np.ndarray,
    azimuths_deg,
    *,
    fov_deg: float,
    resolution: int,
    fill_height: float,
    margin_px: float = 0.5,
) -> list[Camera]:
    """Orbit cameras (one per azimuth; the first is the training camera, which is framed).

    The orbit's axis is the vertical line through the centre of the points' horizontal bounding
    box. Distance D and height h are chosen so that, in the first camera, the points span exactly
    ``fill_height`` of the image height (field of view fixed), centred vertically unless a held-out
    view needs h shifted (see the module docstring).

    Args:
        points: [K, 3] the swept extent, m: every posed vertex over the whole recording (or the
            vertices of its convex hull).
        azimuths_deg (Iterable[float]): the cameras' azimuths, degrees.
        fov_deg: field of view, degrees.
        resolution: image side, px.
        fill_height: fraction in (0, 1) of the training image's height the points span.
        margin_px: the smallest distance a point may keep from an image border, px.

    Returns:
        One [`Camera`][physgs.camera.Camera] per azimuth.

    Raises:
        FramingError: for ``fill_height`` outside (0, 1), or when a camera sees a point closer than
            ``margin_px`` to its border (or behind it); the message names ``testbed.fill_height``
            and the largest value that fits.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    az = [float(a) for a in azimuths_deg]
    if not 0.0 < fill_height < 1.0:
        raise FramingError(
            f"testbed.fill_height = {fill_height} must lie in (0, 1) (fraction of the "
            "training image height the swept tree spans); fix config/trees.yaml"
        )
    centre = 0.5 * (pts[:, :2].min(axis=0) + pts[:, :2].max(axis=0))
    tan = np.tan(np.deg2rad(fov_deg) / 2)
    # each camera's view of the points as the azimuth-0 camera's: y = depth offset, z = height
    views = [_rotate_z(pts, centre, a) for a in az]
    z = pts[:, 2]
    dy = np.stack([v[:, 1] - centre[1] for v in views])  # [A, K]
    dy0 = dy[0]
    s_max = tan * (1.0 - 2.0 * margin_px / resolution)  # largest |y / depth| inside the margin
    span = float(np.ptp(z)) + 1.0

    def h_range(D):  # camera heights keeping every view's points inside vertically
        depth = D + dy
        return float(np.max(z - s_max * depth)), float(np.min(z + s_max * depth))

    def height(D):  # centred in the training view, clamped into the feasible range
        depth = D + dy0
        hc = _bisect(
            lambda h: np.max((z - h) / depth) - np.max((h - z) / depth),
            float(z.min()) - span,
            float(z.max()) + span,
        )
        lo, hi = h_range(D)
        return min(max(hc, lo), hi) if lo <= hi else hc

    def fill(D, h):  # vertical extent in the training image, fraction of its height
        depth = D + dy0
        return float(np.max((z - h) / depth) + np.max((h - z) / depth)) / (2 * tan)

    d_min = float(np.max(-dy)) + 1e-6  # every point in front of every camera
    d_max = d_min + 1.0
    while fill(d_max, height(d_max)) > 0.1 * fill_height:
        d_max = d_min + 2 * (d_max - d_min)

    def build(f):
        D = _bisect(lambda D: fill(D, height(D)) - f, d_min, d_max)
        return orbit_cameras(centre, D, height(D), az, fov_deg=fov_deg, resolution=resolution)

    def first_bad(cams):
        for a, cam in zip(az, cams):
            v = _violation(cam, pts, margin_px)
            if v is not None:
                return a, v
        return None

    cams = build(fill_height)
    bad = first_bad(cams)
    if bad is None:
        return cams
    lo, hi = 0.0, fill_height  # the largest fill that fits, for the message
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if first_bad(build(mid)) is None else (lo, mid)
    a, (u, v, zz) = bad
    which = "the training camera" if a == az[0] else f"the held-out view at azimuth {a:+g} deg"
    raise FramingError(
        f"testbed.fill_height = {fill_height}: the tree's swept extent (every frame, every "
        f"condition) leaves {which} (a vertex reaches pixel ({u:.1f}, {v:.1f}) at depth {zz:.2f} m "
        f"of a {resolution}x{resolution} image, {margin_px:g} px margin required); lower "
        f"testbed.fill_height in config/trees.yaml (at most {lo:.3f} fits every view)"
    )
