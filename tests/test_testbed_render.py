"""Mesh renderer against analytic cases; determinism."""

import numpy as np
import trimesh

from physgs.camera import look_at
from physgs.testbed import raycast


def test_sphere_silhouette_radius_within_one_pixel():
    rho, D, R = 0.5, 4.0, 96
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=rho)
    cam = look_at([0.0, -D, 0.0], [0.0, 0.0, 0.0], fov_deg=30.0, width=R, height=R)
    rays = raycast.RayBundle(cam, 4)
    fc = np.full((len(sphere.faces), 3), 0.5)
    _, alpha = raycast.render_mesh(sphere.vertices, sphere.faces, fc, rays, [1, 1, 1])
    r_px = np.sqrt(alpha.sum() / np.pi)
    exact = cam.fx * rho / np.sqrt(D**2 - rho**2)  # tangent cone of a sphere
    assert abs(r_px - exact) < 1.0, (r_px, exact)
    ys, xs = np.nonzero(alpha > 0.5)
    assert abs(xs.mean() + 0.5 - cam.cx) < 0.5 and abs(ys.mean() + 0.5 - cam.cy) < 0.5


def test_lambert_plus_ambient_shading_of_a_flat_quad():
    # a large quad facing the camera; its normal is (0, -1, 0) up to sign
    v = np.array([[-5, 0, -5], [5, 0, -5], [5, 0, 5], [-5, 0, 5.0]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    col = np.array([0.8, 0.4, 0.2])
    cam = look_at([0.0, -3.0, 0.0], [0.0, 0.0, 0.0], fov_deg=40.0, width=8, height=8)
    rgb, alpha = raycast.render_mesh(
        v, f, np.stack([col, col]), raycast.RayBundle(cam, 2), [1, 1, 1], ambient=0.3
    )
    expect = col * (0.3 + 0.7 * abs(raycast.LIGHT_DIR[1]))
    np.testing.assert_allclose(rgb, np.broadcast_to(expect, rgb.shape), atol=1e-6)
    assert (alpha == 1).all()


def test_background_where_nothing_is_hit_and_determinism():
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.3)
    cam = look_at([0.0, -3.0, 0.0], [0.0, 0.0, 0.0], fov_deg=40.0, width=32, height=32)
    rays = raycast.RayBundle(cam, 3)
    fc = np.random.default_rng(0).uniform(size=(len(sphere.faces), 3))
    a = raycast.render_mesh(sphere.vertices, sphere.faces, fc, rays, [0.2, 0.4, 0.6])
    b = raycast.render_mesh(sphere.vertices, sphere.faces, fc, rays, [0.2, 0.4, 0.6])
    np.testing.assert_array_equal(a[0], b[0])
    np.testing.assert_array_equal(a[1], b[1])
    np.testing.assert_allclose(a[0][0, 0], [0.2, 0.4, 0.6], atol=1e-7)
    assert a[1][0, 0] == 0 and a[1][16, 16] == 1


def _tree_like_mesh(rng, n_quads=400, offset=(40.0, -7.0, 3.0)):
    """Many small leaf quads in a crown far from the origin, plus vertices no face uses (trimesh
    sizes its precision box from the referenced ones only)."""
    centres = rng.normal(size=(n_quads, 1, 3)) * 0.6 + np.asarray(offset)
    corners = rng.normal(size=(n_quads, 4, 3)) * 0.05
    v = (centres + corners).reshape(-1, 3)
    base = 4 * np.arange(n_quads)[:, None]
    f = np.concatenate([base + [0, 1, 2], base + [0, 2, 3]])
    stray = rng.normal(size=(7, 3)) * 50.0  # unreferenced, far out
    return np.concatenate([v, stray]), f


def test_first_hits_match_trimesh_intersects_first():
    # the oracle: trimesh's own Embree query, which first_hits reproduces float for float
    from trimesh.ray.ray_pyembree import RayMeshIntersector

    rng = np.random.default_rng(3)
    v, f = _tree_like_mesh(rng)
    target = v[: len(f) * 2 // 3].mean(axis=0)
    cam = look_at(target + [0.0, -3.0, 0.4], target, fov_deg=40.0, width=48, height=40)
    rays = raycast.RayBundle(cam, 3)
    ours = raycast.first_hits(v, f, rays)
    ref = RayMeshIntersector(trimesh.Trimesh(v, f, process=False)).intersects_first(
        rays.origins, rays.dirs
    )
    assert 0.05 < (ref >= 0).mean() < 0.95  # a scene with hits and misses
    np.testing.assert_array_equal(ours, ref)


def test_supersampled_pixels_are_the_mean_of_their_rays():
    # per-pixel mean of the s x s rays, against numpy's two-axis mean of the [H, s, W, s] rays
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.4)
    cam = look_at([0.0, -3.0, 0.0], [0.0, 0.0, 0.0], fov_deg=30.0, width=20, height=12)
    rays = raycast.RayBundle(cam, 3)
    fc = np.random.default_rng(1).uniform(size=(len(sphere.faces), 3))
    rgb, alpha = raycast.render_mesh(sphere.vertices, sphere.faces, fc, rays, [0.2, 0.4, 0.6])
    tri = raycast.first_hits(sphere.vertices, sphere.faces, rays)
    hit = (tri >= 0).reshape(12, 3, 20, 3)
    np.testing.assert_array_equal(alpha, hit.mean(axis=(1, 3)).astype(np.float32))
    assert 0 < alpha.mean() < 1 and 0 < ((alpha > 0) & (alpha < 1)).sum()  # edge pixels too
    # a background pixel and a covered one, by hand
    np.testing.assert_allclose(rgb[0, 0], [0.2, 0.4, 0.6], atol=1e-7)
    i, j = np.argwhere(alpha == 1)[0]
    t = tri.reshape(12, 3, 20, 3)[i, :, j, :].ravel()
    f = sphere.faces[t]
    v = sphere.vertices
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    shade = 0.35 + 0.65 * np.abs(n @ raycast.LIGHT_DIR)
    np.testing.assert_allclose(rgb[i, j], (fc[t] * shade[:, None]).mean(axis=0), atol=1e-6)
