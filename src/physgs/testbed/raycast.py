"""Mesh renderer for ground-truth frames: trimesh + Embree ray casting, Lambertian + ambient
shading with per-face colours, constant background, s x s supersampling, silhouette coverage."""

from __future__ import annotations

import numpy as np
import trimesh
from trimesh.ray.ray_pyembree import RayMeshIntersector

from physgs.camera import Camera

LIGHT_DIR = np.array([-0.4, -0.6, 0.7]) / np.linalg.norm([-0.4, -0.6, 0.7])  # toward the light


class RayBundle:
    """Primary rays of one camera, cached across frames: origins, dirs [H*s*W*s, 3]."""

    def __init__(self, camera: Camera, supersample: int):
        """Cast the camera's primary rays once.

        Args:
            camera: the camera.
            supersample: s, rays per pixel side (s x s per pixel).
        """
        o, d = camera.rays(supersample)
        self.camera, self.s = camera, int(supersample)
        self.origins = o.reshape(-1, 3)
        self.dirs = d.reshape(-1, 3)


def render_mesh(
    vertices: np.ndarray,
    faces: np.ndarray,
    face_colors: np.ndarray,
    rays: RayBundle,
    background,
    *,
    ambient: float = 0.35,
    light_dir: np.ndarray = LIGHT_DIR,
):
    """Render a triangle mesh.

    Shading: colour * (ambient + (1 - ambient) |n . l|), two-sided (leaves are single quads).

    Args:
        vertices: [N, 3] posed vertices, m.
        faces: [M, 3] vertex indices.
        face_colors: [M, 3] in [0, 1].
        rays: the camera's primary rays.
        background (ArrayLike): [3] colour in [0, 1].
        ambient: the ambient share of the shading.
        light_dir: [3] unit light direction.

    Returns:
        (tuple[np.ndarray, np.ndarray]): ``(rgb, alpha)``: rgb [H, W, 3] float32 in [0, 1], alpha
            [H, W] float32 = covered fraction of each pixel.

    Raises:
        RuntimeError: when Embree ray casting is not installed.
    """
    if not trimesh.ray.has_embree:
        raise RuntimeError("Embree ray casting unavailable: pip install embreex")
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    tri = RayMeshIntersector(mesh).intersects_first(rays.origins, rays.dirs)  # [R], -1 = miss
    hit = tri >= 0
    f = faces[tri[hit]]  # normals of the hit faces only (trimesh computes all of them)
    n = np.cross(vertices[f[:, 1]] - vertices[f[:, 0]], vertices[f[:, 2]] - vertices[f[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    shade = ambient + (1 - ambient) * np.abs(n @ light_dir)
    bg = np.asarray(background, dtype=np.float64)
    col = np.broadcast_to(bg, (len(tri), 3)).copy()
    col[hit] = face_colors[tri[hit]] * shade[:, None]
    cam, s = rays.camera, rays.s
    H, W = cam.height, cam.width
    rgb = col.reshape(H, s, W, s, 3).mean(axis=(1, 3))
    alpha = hit.reshape(H, s, W, s).mean(axis=(1, 3))
    return rgb.astype(np.float32), alpha.astype(np.float32)


def to_uint8(rgb: np.ndarray) -> np.ndarray:
    """[..., 3] float in [0, 1] -> uint8 (rounded).

    Args:
        rgb: [..., 3] floats in [0, 1] (clipped).

    Returns:
        [..., 3] uint8.
    """
    return np.clip(np.rint(rgb * 255.0), 0, 255).astype(np.uint8)
