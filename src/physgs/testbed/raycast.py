"""Mesh renderer for ground-truth frames: Embree ray casting, Lambertian + ambient shading with
per-face colours, constant background, s x s supersampling, silhouette coverage.

The rays go to Embree (`embreex`) the way trimesh's `RayMeshIntersector.intersects_first` sends
them, float for float: the mesh is shifted to its lowest corner and scaled to a 100-unit box before
Embree's single precision sees it. Calling Embree here, rather than through trimesh, builds one
scene per frame without trimesh's per-call mesh hashing, bounds caching and ray normalisation
(the camera's rays are the same every frame): about a fifth of a testbed's time
(`benchmarks/testbed.py`). `tests/test_testbed_render.py` checks the hits against trimesh's.
"""

from __future__ import annotations

import numpy as np
import trimesh

from physgs.camera import Camera

try:
    from embreex import rtcore_scene
    from embreex.mesh_construction import TriangleMesh
except ImportError:  # raised with the fix at the first render (render_mesh)
    rtcore_scene = TriangleMesh = None

#: trimesh's precision box: a mesh is scaled so that its bounding-box diagonal is this long.
_BOX = 100.0

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
        # as Embree takes them (trimesh's casts): float32 origins, float32 unit directions
        self.origins32 = np.array(self.origins, dtype=np.float32).astype(np.float64)
        self.unit_dirs32 = trimesh.util.unitize(np.array(self.dirs, dtype=np.float32)).astype(
            np.float32
        )


def first_hits(vertices: np.ndarray, faces: np.ndarray, rays: RayBundle) -> np.ndarray:
    """The first triangle each ray hits (what trimesh's ``intersects_first`` returns).

    Args:
        vertices: [N, 3] vertices, m.
        faces: [M, 3] vertex indices.
        rays: the camera's primary rays.

    Returns:
        [R] int32 index into ``faces`` of each ray's first hit; -1 for a miss.

    Raises:
        RuntimeError: when Embree ray casting (``embreex``) is not installed.
    """
    if rtcore_scene is None:
        raise RuntimeError("Embree ray casting unavailable: pip install embreex")
    v = np.array(vertices, dtype=np.float64)
    used = np.zeros(len(v), dtype=bool)
    used[faces.ravel()] = True
    ref = v if used.all() else v[used]  # trimesh's bounds: referenced vertices only
    diag = float((np.ptp(np.array([ref.min(axis=0), ref.max(axis=0)]), axis=0) ** 2).sum() ** 0.5)
    scale = _BOX / diag if diag >= trimesh.tol.zero else _BOX
    origin = v.min(axis=0)
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(
        scene=scene,
        vertices=((v - origin) * scale).astype(np.float32),
        indices=np.asarray(faces).astype(np.int32),
    )
    return scene.run(((rays.origins32 - origin) * scale).astype(np.float32), rays.unit_dirs32)


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
    tri = first_hits(vertices, faces, rays)  # [R], -1 = miss
    hit = tri >= 0
    th = tri[hit]
    f = faces[th]  # normals of the hit faces only (trimesh computes all of them)
    n = np.cross(vertices[f[:, 1]] - vertices[f[:, 0]], vertices[f[:, 2]] - vertices[f[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    shade = ambient + (1 - ambient) * np.abs(n @ light_dir)
    bg = np.asarray(background, dtype=np.float64)
    col = np.broadcast_to(bg, (len(tri), 3)).copy()
    col[hit] = face_colors[th] * shade[:, None]
    cam, s = rays.camera, rays.s
    H, W = cam.height, cam.width
    # the s x s rays of a pixel: rows first (contiguous), then the columns; 3x numpy's
    # two-axis mean, equal to it within rounding (1e-16)
    rgb = col.reshape(H, s, W * s * 3).sum(axis=1).reshape(H, W, s, 3).sum(axis=2) / (s * s)
    # hit counts (exact in any order), summed the same way over bytes
    n_hit = hit.view(np.uint8).reshape(H, s, W * s).sum(axis=1, dtype=np.int32)
    alpha = n_hit.reshape(H, W, s).sum(axis=2) / (s * s)
    return rgb.astype(np.float32), alpha.astype(np.float32)


def to_uint8(rgb: np.ndarray) -> np.ndarray:
    """[..., 3] float in [0, 1] -> uint8 (rounded).

    Args:
        rgb: [..., 3] floats in [0, 1] (clipped).

    Returns:
        [..., 3] uint8.
    """
    return np.clip(np.rint(rgb * 255.0), 0, 255).astype(np.uint8)
