"""The off-screen clamp of the perspective Jacobian, against an oracle built from the field of view.

3DGS (``computeCov2D``) and gsplat (``persp_proj``) evaluate the EWA Jacobian at x/z, y/z clamped
to 1.3 tan(fov / 2) for a centred principal point, so a Gaussian centred just outside the image
(x/z between 1.3 and 1.6 tan(fov / 2)) is splatted with the Jacobian of the clamped point. The
oracle here takes those limits from the camera's field-of-view *angle* (not from the rasterizer's
0.5 W / fx), builds J Sigma J^T + 0.3 I in float64 numpy with scipy's rotations, and splats one
Gaussian. An earlier version clamped at 1.6 tan(fov / 2); the clamped cases below fail under it.
"""

import numpy as np
import pytest
import torch

from physgs.camera import look_at
from physgs.render import kernels, rasterization
from physgs.render.fast import camera_arrays
from physgs.render.project import project_gaussians
from oracles import pixel_centres, rotation_wxyz

F64 = torch.float64
FOV_TAN_HALF_0P5 = float(np.degrees(2 * np.arctan(0.5)))  # vertical fov with tan(fov / 2) = 0.5
COLOR = np.array([0.9, 0.3, 0.1])
BG = np.array([0.1, 0.2, 0.6])


def centred_camera(fov_deg, width, height):
    """At the origin looking down +z (R = I, t = 0), vertical fov ``fov_deg``, square pixels,
    principal point at the image centre."""
    cam = look_at(
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        up=(0.0, -1.0, 0.0),
        fov_deg=fov_deg,
        width=width,
        height=height,
    )
    assert np.allclose(cam.R, np.eye(3)) and np.allclose(cam.t, 0.0)
    return cam


def limits_from_fov(fov_deg, width, height):
    """(x, y) tangent limits: 1.3 x tan of the half field of view, from the fov angle."""
    tan_half_y = np.tan(np.radians(fov_deg) / 2)
    tan_half_x = tan_half_y * width / height  # square pixels, centred principal point
    return 1.3 * tan_half_x, 1.3 * tan_half_y


def oracle(cam, mean, quat, scale, opacity, lim):
    """One Gaussian (camera frame = world frame) splatted in float64.

    lim: (x, y) tangent limits of the Jacobian's evaluation point, or None for no clamp.
    Returns (cov2d [2, 2] px^2 incl. the 0.3 px^2 dilation, alpha [H, W], rgb [H, W, 3]).
    """
    x, y, z = mean
    R = rotation_wxyz(quat).as_matrix()  # scipy: x, y, z, w
    sigma = R @ np.diag(np.square(scale)) @ R.T
    u, v = x / z, y / z
    if lim is not None:
        u, v = np.clip(u, -lim[0], lim[0]), np.clip(v, -lim[1], lim[1])
    f = cam.fx
    J = np.array([[f / z, 0.0, -f * u / z], [0.0, f / z, -f * v / z]])
    cov = J @ sigma @ J.T + 0.3 * np.eye(2)
    mx, my = f * x / z + cam.width / 2, f * y / z + cam.height / 2
    xx, yy = pixel_centres(cam)
    d = np.stack([xx - mx, yy - my], axis=-1)
    q = np.einsum("...i,ij,...j->...", d, np.linalg.inv(cov), d)
    alpha = np.minimum(0.99, opacity * np.exp(-0.5 * q))
    alpha[alpha < 1 / 255] = 0.0
    rgb = alpha[..., None] * COLOR + (1 - alpha[..., None]) * BG
    return cov, alpha, rgb


# name: (fov_deg, width, height, (x/z, y/z), z, scale, quat (w, x, y, z), clamped by 1.3 tan?)
CASES = {
    # the range: x/z in (0.65, 0.8) for tan(fov / 2) = 0.5
    "right": (
        FOV_TAN_HALF_0P5,
        32,
        32,
        (0.72, 0.1),
        3.0,
        (0.15, 0.2, 0.8),
        (0.95, 0.1, -0.2, 0.15),
        True,
    ),
    "left": (
        FOV_TAN_HALF_0P5,
        32,
        32,
        (-0.78, -0.05),
        2.5,
        (0.12, 0.15, 0.7),
        (0.9, -0.1, 0.3, 0.05),
        True,
    ),
    "corner": (
        FOV_TAN_HALF_0P5,
        32,
        32,
        (0.7, -0.7),
        3.0,
        (0.3, 0.35, 0.9),
        (0.8, 0.2, 0.1, -0.3),
        True,
    ),
    # wide image, 60 degree vertical fov: only y clamped (lim_y = 0.75, lim_x = 1.25)
    "below": (60.0, 40, 24, (0.3, 0.84), 2.0, (0.15, 0.1, 0.6), (0.9, 0.3, 0.0, 0.2), True),
    # just off-screen but inside 1.3 tan(fov / 2): no clamp, old and new agree
    "inside": (
        FOV_TAN_HALF_0P5,
        32,
        32,
        (0.6, 0.2),
        3.0,
        (0.15, 0.2, 0.8),
        (0.95, 0.1, -0.2, 0.15),
        False,
    ),
}


def case_inputs(name, opacity=0.9):
    fov, W, H, (u, v), z, scale, quat, clamped = CASES[name]
    cam = centred_camera(fov, W, H)
    mean = np.array([u * z, v * z, z])
    quat = np.asarray(quat) / np.linalg.norm(quat)
    tensors = [
        torch.tensor(np.asarray(a, dtype=np.float64)[None], dtype=F64)
        for a in (mean, quat, scale, opacity, COLOR)
    ]
    return cam, mean, quat, np.asarray(scale), tensors, limits_from_fov(fov, W, H), clamped


@pytest.mark.parametrize("name", sorted(CASES))
def test_projected_covariance_matches_fov_oracle(name):
    cam, mean, quat, scale, g, lim, clamped = case_inputs(name)
    cov, _, _ = oracle(cam, mean, quat, scale, 0.9, lim)
    want = np.array([cov[0, 0], cov[0, 1], cov[1, 1]])
    # reference backend (torch)
    proj = project_gaussians(g[0], g[1], g[2], cam)
    assert bool(proj.valid[0])
    np.testing.assert_allclose(proj.cov2d[0].numpy(), want, rtol=1e-12, atol=1e-12)
    # fast backend (numba kernel)
    n = 1
    m2, con, dep, cov2d, valid = (
        np.empty((n, 2)),
        np.empty((n, 3)),
        np.empty(n),
        np.empty((n, 3)),
        np.empty(n, np.bool_),
    )
    kernels.project_forward(
        *(np.ascontiguousarray(x.numpy()) for x in g[:3]),
        *camera_arrays(cam),
        cam.near,
        0.3,
        m2,
        con,
        dep,
        cov2d,
        valid,
    )
    assert valid[0]
    np.testing.assert_allclose(cov2d[0], want, rtol=1e-12, atol=1e-12)
    # the case tests what it says: the clamp changes the covariance (or, inside, does not)
    cov_free, _, _ = oracle(cam, mean, quat, scale, 0.9, None)
    if clamped:
        assert np.abs(cov_free - cov).max() > 0.05 * np.abs(cov).max()
    else:
        assert np.array_equal(cov_free, cov)


@pytest.mark.parametrize("backend", ["reference", "fast"])
@pytest.mark.parametrize("name", sorted(CASES))
def test_alpha_and_rgb_match_fov_oracle(name, backend):
    cam, mean, quat, scale, g, lim, clamped = case_inputs(name)
    _, alpha, rgb = oracle(cam, mean, quat, scale, 0.9, lim)
    assert alpha.max() > 0.1 and (alpha == 0).any()  # visible in the image, cut off at 1/255
    out = rasterization(*g, cam, BG, backend=backend)
    np.testing.assert_allclose(out.alpha.numpy(), alpha, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out.rgb.numpy(), rgb, rtol=0, atol=1e-12)
    if clamped:  # an unclamped (or 1.6 tan(fov / 2)) Jacobian would be visibly off
        _, alpha_free, _ = oracle(cam, mean, quat, scale, 0.9, None)
        assert np.abs(alpha_free - alpha).max() > 0.03


@pytest.mark.parametrize("name", sorted(CASES))
def test_fast_gradients_match_reference_on_clamped_gaussian(name):
    cam, *_, g, _, _ = case_inputs(name)
    gen = torch.Generator().manual_seed(0)
    w = [
        torch.rand(s, generator=gen, dtype=F64)
        for s in ((cam.height, cam.width, 3), (cam.height, cam.width), (cam.height, cam.width))
    ]
    grads = {}
    for backend in ("reference", "fast"):
        params = [x.clone().requires_grad_(True) for x in g]
        bg = torch.tensor(BG, dtype=F64, requires_grad=True)
        out = rasterization(*params, cam, bg, backend=backend)
        loss = (out.rgb * w[0]).sum() + (out.alpha * w[1]).sum() + (out.depth * w[2]).sum()
        loss.backward()
        grads[backend] = [p.grad.numpy() for p in params] + [bg.grad.numpy()]
    for label, a, b in zip(
        ["means", "quats", "scales", "opacities", "colors", "background"],
        grads["reference"],
        grads["fast"],
    ):
        assert np.isfinite(a).all() and np.abs(a).max() > 0, label
        np.testing.assert_allclose(
            b, a, rtol=0, atol=1e-10 * max(1.0, np.abs(a).max()), err_msg=label
        )


def test_fast_gradcheck_through_the_clamp():
    # Tiny image, wide Gaussian centred off-screen at x/z = 0.72, y/z = -0.7 (both clamped at
    # 0.65), opacity 0.5: every pixel far above 1/255 and below 0.99, so the image is smooth in
    # the inputs and finite differences check the clamped branch of the hand-written backward.
    cam = centred_camera(FOV_TAN_HALF_0P5, 8, 8)
    z = 3.0
    g = [
        torch.tensor(x, dtype=F64, requires_grad=True)
        for x in (
            [[0.72 * z, -0.7 * z, z]],
            [[0.9, 0.2, -0.1, 0.3]],
            [[2.2, 2.5, 3.0]],
            [0.5],
            [[0.2, 0.7, 0.4]],
            BG,
        )
    ]

    def f(m, q, s, o, c, bg):
        out = rasterization(m, q, s, o, c, cam, bg, backend="fast")
        return out.rgb, out.alpha, out.depth

    alpha = f(*g)[1]
    assert alpha.min() > 0.02
    proj = project_gaussians(*(x.detach() for x in g[:3]), cam)
    assert proj.means2d[0, 0] > cam.width and proj.means2d[0, 1] < 0  # centred off-screen
    assert torch.autograd.gradcheck(f, g, eps=1e-6, atol=1e-7, rtol=1e-5)


@pytest.mark.skipif(not torch.cuda.is_available(), reason="gsplat backend needs a CUDA GPU")
@pytest.mark.parametrize("name", ["right", "below"])
def test_gsplat_matches_fov_oracle(name):
    # gsplat applies the same clamp. Opacity 0.3 keeps the 1/255 contour inside gsplat's
    # 3-sigma footprint; float32 arithmetic, hence the tolerance (the old constant is off by
    # more than 0.01 here).
    pytest.importorskip("gsplat")
    cam, mean, quat, scale, g, lim, _ = case_inputs(name, opacity=0.3)
    _, alpha, _ = oracle(cam, mean, quat, scale, 0.3, lim)
    out = rasterization(
        *(x.float().cuda() for x in g), cam, torch.tensor(BG).float().cuda(), backend="gsplat"
    )
    np.testing.assert_allclose(out.alpha.cpu().double().numpy(), alpha, rtol=0, atol=2e-3)
