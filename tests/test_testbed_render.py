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
