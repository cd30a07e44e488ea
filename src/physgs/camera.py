"""Pinhole cameras shared by the mesh renderer (testbed) and the Gaussian rasterizer.

Conventions (OpenCV): camera x right, y down, z forward (into the scene). World frame: z up,
the tree stands at the origin. A camera maps a world point X to camera coordinates
``R @ X + t`` and to pixels ``(fx * x / z + cx, fy * y / z + cy)``, pixel centres at
integer + 0.5 (pixel (0, 0) covers [0, 1) x [0, 1)).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Camera:
    """A pinhole camera.

    R: [3, 3] world-to-camera rotation; t: [3] world-to-camera translation (world units).
    fx, fy, cx, cy: intrinsics in pixels. width, height: image size in pixels.
    near: near-plane depth (world units); geometry closer than this is not drawn.
    """

    R: np.ndarray  # [3, 3]
    t: np.ndarray  # [3]
    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int
    near: float = 0.01

    @property
    def viewmat(self) -> np.ndarray:
        """[4, 4] world-to-camera matrix."""
        m = np.eye(4)
        m[:3, :3] = self.R
        m[:3, 3] = self.t
        return m

    @property
    def K(self) -> np.ndarray:
        """[3, 3] intrinsic matrix (pixels)."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def center(self) -> np.ndarray:
        """[3] camera centre in world coordinates."""
        return -self.R.T @ self.t

    def project(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Project world points X [N, 3] -> (pixels [N, 2], depth [N]) .

        Args:
            X: [N, 3] world points, world units.

        Returns:
            ``(uv, z)``: uv [N, 2] pixel coordinates (px, pixel centres at integer + 0.5) and z [N]
                depth along the optical axis, world units (not clipped at ``near``; z <= 0 gives
                meaningless pixels).
        """
        Xc = X @ self.R.T + self.t
        z = Xc[:, 2]
        uv = np.stack([self.fx * Xc[:, 0] / z + self.cx, self.fy * Xc[:, 1] / z + self.cy], axis=1)
        return uv, z

    def rays(self, supersample: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """World-space rays through the pixel grid.

        Args:
            supersample: s, sub-pixel samples per pixel side: an s x s regular grid inside each
                pixel.

        Returns:
            ``(origins, directions)``: origins [H*s, W*s, 3] (the camera centre, world units) and
                unit directions [H*s, W*s, 3], row-major (image row = y).
        """
        s = supersample
        u = (np.arange(self.width * s) + 0.5) / s
        v = (np.arange(self.height * s) + 0.5) / s
        uu, vv = np.meshgrid(u, v)
        d_cam = np.stack([(uu - self.cx) / self.fx, (vv - self.cy) / self.fy, np.ones_like(uu)], -1)
        d_world = d_cam @ self.R  # R^T applied to row vectors
        d_world /= np.linalg.norm(d_world, axis=-1, keepdims=True)
        o = np.broadcast_to(self.center, d_world.shape).copy()
        return o, d_world

    def to_dict(self) -> dict[str, np.ndarray]:
        """Flat arrays for np.savez.

        Returns:
            ``viewmat`` [4, 4], ``intrinsics`` [4] (fx, fy, cx, cy in px), ``size`` [2] (width,
                height in px) and ``near`` (a 0-d array, world units).
        """
        return {
            "viewmat": self.viewmat,
            "intrinsics": np.array([self.fx, self.fy, self.cx, self.cy]),
            "size": np.array([self.width, self.height]),
            "near": np.array(self.near),
        }

    @staticmethod
    def from_dict(d: dict) -> "Camera":
        """The camera that [to_dict][physgs.camera.Camera.to_dict] wrote.

        Args:
            d: mapping with ``viewmat`` [4, 4] (world to camera), ``intrinsics`` [4] (fx, fy, cx, cy
                in px), ``size`` [2] (width, height in px) and ``near`` (scene units).

        Returns:
            The camera.
        """
        v = np.asarray(d["viewmat"], dtype=np.float64)
        fx, fy, cx, cy = (float(x) for x in np.asarray(d["intrinsics"]))
        w, h = (int(x) for x in np.asarray(d["size"]))
        return Camera(v[:3, :3].copy(), v[:3, 3].copy(), fx, fy, cx, cy, w, h, float(d["near"]))


def look_at(
    eye, target, up=(0.0, 0.0, 1.0), *, fov_deg: float, width: int, height: int, near: float = 0.01
) -> Camera:
    """Camera at ``eye`` looking at ``target`` (OpenCV axes: z forward, y down).

    Args:
        eye (ArrayLike): [3] camera centre, world units.
        target (ArrayLike): [3] the point the optical axis passes through, world units.
        up (ArrayLike): [3] world up (image up is its projection).
        fov_deg: vertical field of view, degrees.
        width: image width, px.
        height: image height, px.
        near: near-plane depth, world units.

    Returns:
        The camera: square pixels (fx = fy), principal point at the image centre.

    Raises:
        ValueError: the viewing direction is parallel to ``up``.
    """
    eye, target, up = (np.asarray(a, dtype=np.float64) for a in (eye, target, up))
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(z, up)  # right = forward x up (y points down)
    if np.linalg.norm(x) < 1e-9:
        raise ValueError("look_at: viewing direction is parallel to 'up'; choose another up vector")
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    R = np.stack([x, y, z])
    t = -R @ eye
    f = 0.5 * height / np.tan(np.deg2rad(fov_deg) / 2)
    return Camera(R, t, f, f, width / 2, height / 2, width, height, near)


def orbit_camera(
    azimuth_deg: float,
    *,
    radius: float,
    height: float,
    target,
    fov_deg: float,
    width: int,
    height_px: int,
) -> Camera:
    """Camera on a circle about the world z axis; azimuth 0 sits on the -y axis looking toward +y.

    Args:
        azimuth_deg: degrees, counter-clockwise seen from above.
        radius: distance from the z axis, world units.
        height: the camera centre's z, world units.
        target (ArrayLike): [3] the point looked at, world units.
        fov_deg: vertical field of view, degrees.
        width: image width, px.
        height_px: image height, px.

    Returns:
        The camera, from [`physgs.camera.look_at`][] with world z up.
    """
    a = np.deg2rad(azimuth_deg)
    target = np.asarray(target, dtype=np.float64)
    eye = np.array([radius * np.sin(a), -radius * np.cos(a), height])
    return look_at(eye, target, fov_deg=fov_deg, width=width, height=height_px)
