"""Cameras that frame the tree: one orbit radius for every azimuth, chosen so the tree and its
motion in every frame of every condition stay inside the image with a margin."""
from __future__ import annotations

import numpy as np

from physgs.camera import Camera, orbit_camera


def frame_cameras(lo: np.ndarray, hi: np.ndarray, max_horizontal: float, azimuths_deg, *,
                  fov_deg: float, resolution: int, margin: float = 1.08) -> list[Camera]:
    """Orbit cameras (one per azimuth, degrees) looking horizontally at the box centre.

    lo, hi [3]: bounds (m) of every posed vertex over the whole recording; max_horizontal: the
    largest horizontal distance (m) of any posed vertex from the box's vertical centre line.
    The distance D from the centre line satisfies, for a vertex at most r_h sideways and h_z above
    or below the centre, max(r_h, h_z) / (D - r_h) <= tan(fov/2) / margin.
    """
    c = 0.5 * (np.asarray(lo) + np.asarray(hi))
    hz = 0.5 * (hi[2] - lo[2])
    rh = float(max_horizontal)
    tan = np.tan(np.deg2rad(fov_deg) / 2)
    D = rh + max(rh, hz) * margin / tan
    cams = []
    for a in azimuths_deg:
        ar = np.deg2rad(a)
        eye_dir = np.array([np.sin(ar), -np.cos(ar), 0.0])
        eye = c + D * eye_dir
        cams.append(orbit_camera(a, radius=float(np.linalg.norm(eye[:2])), height=float(c[2]),
                                 target=c, fov_deg=fov_deg, width=resolution, height_px=resolution))
    return cams
