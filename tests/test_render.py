"""Rasterizer numerics: closed forms, gradcheck, occlusion, an independent dense oracle, extremes."""

import numpy as np
import pytest
import torch

from physgs.camera import Camera, look_at
from physgs.models.gaussians import GaussianState
from physgs.render import rasterization, render_state
from physgs.render.scenes import random_scene
from oracles import pixel_centres, rotation_wxyz

BACKENDS = ["reference", "fast"]
F64 = torch.float64


def axis_camera(w=24, h=20, f=30.0, near=0.01):
    """Camera at the origin looking down +z (R = I, t = 0)."""
    return Camera(np.eye(3), np.zeros(3), f, f, w / 2, h / 2, w, h, near)


def gaussians(means, scales, opac, colors, quats=None):
    means = torch.tensor(means, dtype=F64)
    n = means.shape[0]
    quats = (
        torch.tensor([[1.0, 0, 0, 0]] * n, dtype=F64)
        if quats is None
        else torch.tensor(quats, dtype=F64)
    )
    return [
        means,
        quats,
        torch.tensor(scales, dtype=F64),
        torch.tensor(opac, dtype=F64),
        torch.tensor(colors, dtype=F64),
    ]


@pytest.mark.parametrize("backend", BACKENDS)
def test_isotropic_alpha_profile_matches_closed_form(backend):
    # On the optical axis an isotropic Gaussian (scale s at depth d) projects to a circle of
    # variance (f s / d)^2 + 0.3 px^2 centred on the principal point.
    cam = axis_camera(w=40, h=36, f=50.0)
    d, s, o = 4.0, 0.2, 0.8
    g = gaussians([[0.0, 0.0, d]], [[s, s, s]], [o], [[0.2, 0.5, 0.9]])
    bg = [1.0, 0.0, 0.3]
    out = rasterization(*g, cam, bg, backend=backend)
    var = (cam.fx * s / d) ** 2 + 0.3
    xx, yy = pixel_centres(cam)
    r2 = (xx - cam.cx) ** 2 + (yy - cam.cy) ** 2
    a = np.minimum(0.99, o * np.exp(-0.5 * r2 / var))
    a[a < 1 / 255] = 0.0
    assert (a == 0).any() and (a > 0.5).any()  # the profile and its 1/255 cut-off are in frame
    np.testing.assert_allclose(out.alpha.numpy(), a, atol=1e-12)
    rgb = a[..., None] * np.array([0.2, 0.5, 0.9]) + (1 - a[..., None]) * np.array(bg)
    np.testing.assert_allclose(out.rgb.numpy(), rgb, atol=1e-12)
    np.testing.assert_allclose(out.depth.numpy(), d * a, atol=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
def test_nearer_gaussian_occludes_farther(backend):
    cam = axis_camera()
    red, green = [1.0, 0, 0], [0, 1.0, 0]
    o = 0.95
    near_g = [[0.0, 0.0, 2.0], [0.3] * 3, o, red]
    far_g = [[0.0, 0.0, 4.0], [0.6] * 3, o, green]  # same angular size, farther
    bg = np.array([0.0, 0.0, 1.0])
    imgs = []
    for pair in ([near_g, far_g], [far_g, near_g]):  # input order must not matter
        g = gaussians(*[[p[i] for p in pair] for i in range(4)])
        imgs.append(rasterization(*g, cam, bg, backend=backend).rgb.numpy())
    np.testing.assert_array_equal(imgs[0], imgs[1])
    xx, yy = pixel_centres(cam)
    r2 = (xx - cam.cx) ** 2 + (yy - cam.cy) ** 2
    var = (cam.fx * 0.3 / 2.0) ** 2 + 0.3
    a = np.minimum(0.99, o * np.exp(-0.5 * r2 / var))  # both project identically
    expect = (
        a[..., None] * red
        + (1 - a[..., None]) * a[..., None] * green
        + ((1 - a) ** 2)[..., None] * bg
    )
    i, j = cam.height // 2, cam.width // 2
    np.testing.assert_allclose(imgs[0][i, j], expect[i, j], atol=1e-12)
    assert imgs[0][i, j, 0] > 0.9 and imgs[0][i, j, 1] < 0.06


def dense_oracle(means, quats, scales, opac, colors, cam, bg):
    """Independent float64 numpy renderer: every Gaussian at every pixel, no tiles, scipy's
    quaternion convention (x, y, z, w), plain loops over depth order."""
    means, quats, scales, opac, colors, bg = (
        np.asarray(x, np.float64) for x in (means, quats, scales, opac, colors, bg)
    )
    Rw = rotation_wxyz(quats).as_matrix()
    cov3 = Rw @ (scales[:, :, None] ** 2 * np.transpose(Rw, (0, 2, 1)))
    pc = means @ cam.R.T + cam.t
    xx, yy = pixel_centres(cam)
    H, W = cam.height, cam.width
    T = np.ones((H, W))
    rgb = np.zeros((H, W, 3))
    dep = np.zeros((H, W))
    done = np.zeros((H, W), bool)
    # Jacobian clamp: image-edge tangent + 0.3 tan(half fov); tan(half fov) = W / (2 fx), H / (2 fy)
    lx = (cam.cx / cam.fx + 0.15 * W / cam.fx, (W - cam.cx) / cam.fx + 0.15 * W / cam.fx)
    ly = (cam.cy / cam.fy + 0.15 * H / cam.fy, (H - cam.cy) / cam.fy + 0.15 * H / cam.fy)
    for i in np.argsort(pc[:, 2], kind="stable"):
        x, y, z = pc[i]
        if z <= cam.near:
            continue
        tx, ty = z * np.clip(x / z, -lx[0], lx[1]), z * np.clip(y / z, -ly[0], ly[1])
        J = np.array([[cam.fx / z, 0, -cam.fx * tx / z**2], [0, cam.fy / z, -cam.fy * ty / z**2]])
        cov2 = J @ cam.R @ cov3[i] @ cam.R.T @ J.T + 0.3 * np.eye(2)
        inv = np.linalg.inv(cov2)
        dx = xx - (cam.fx * x / z + cam.cx)
        dy = yy - (cam.fy * y / z + cam.cy)
        q = inv[0, 0] * dx**2 + 2 * inv[0, 1] * dx * dy + inv[1, 1] * dy**2
        a = np.minimum(0.99, opac[i] * np.exp(-0.5 * q))
        a[(a < 1 / 255) | done] = 0.0
        stop = T * (1 - a) < 1e-4
        done |= stop
        a[stop] = 0.0
        rgb += (a * T)[..., None] * colors[i]
        dep += a * T * z
        T = T * (1 - a)
    return rgb + T[..., None] * bg, 1 - T, dep


@pytest.mark.parametrize("backend", BACKENDS)
def test_matches_independent_dense_oracle(backend):
    # Odd image size (partial tiles), opaque-ish Gaussians (transmittance cut-off reached).
    means, quats, scales, opac, colors, cam, bg = random_scene(
        120, 37, 29, seed=3, dtype=F64, opacity_range=(0.3, 0.97)
    )
    out = rasterization(means, quats, scales, opac, colors, cam, bg, backend=backend)
    rgb, alpha, dep = dense_oracle(means, quats, scales, opac, colors, cam, bg)
    assert alpha.max() > 0.999  # the T < 1e-4 stop is exercised
    np.testing.assert_allclose(out.rgb.numpy(), rgb, atol=1e-9)
    np.testing.assert_allclose(out.alpha.numpy(), alpha, atol=1e-9)
    np.testing.assert_allclose(out.depth.numpy(), dep, atol=1e-9)


@pytest.mark.parametrize("backend", BACKENDS)
def test_gradcheck_tiny_scene(backend):
    # Gaussians wide compared with the 6x5 image and opacities <= 0.6: no pixel sits near the
    # 1/255 skip, the 0.99 clamp or the transmittance stop, so the image is smooth in the inputs.
    cam = look_at([0.3, -3.0, 0.2], [0, 0, 0], fov_deg=25, width=6, height=5)
    rng = np.random.default_rng(0)
    g = [
        torch.tensor(x, dtype=F64, requires_grad=True)
        for x in (
            rng.uniform(-0.2, 0.2, (3, 3)),
            rng.normal(size=(3, 4)),
            rng.uniform(0.3, 0.6, (3, 3)),
            rng.uniform(0.3, 0.6, 3),
            rng.uniform(0, 1, (3, 3)),
            [0.2, 0.4, 0.7],
        )
    ]

    def f(m, q, s, o, c, bg):
        out = rasterization(m, q, s, o, c, cam, bg, backend=backend)
        return out.rgb, out.alpha, out.depth

    rgb, alpha, _ = f(*g)
    assert alpha.min() > 0.03 and alpha.max() > 0.3  # not empty; every pixel far above 1/255
    # Full Jacobians for the hand-written fast backward; random projections suffice for autograd.
    assert torch.autograd.gradcheck(
        f, g, eps=1e-6, atol=1e-7, rtol=1e-5, fast_mode=backend == "reference"
    )


EXTREMES = {
    "behind_camera": ([[0.0, 0.0, -2.0]], [[0.3] * 3]),
    "at_near_plane": ([[0.0, 0.0, 0.01]], [[0.001] * 3]),
    "just_past_near": ([[0.001, 0.0, 0.0101]], [[0.001] * 3]),
    "tiny_scale": ([[0.05, 0.02, 2.0]], [[1e-9] * 3]),
    "huge_scale": ([[0.0, 0.0, 3.0]], [[1e3] * 3]),
    "needle": ([[0.0, 0.0, 3.0]], [[1e3, 1e-6, 1e-6]]),
    "off_screen": ([[50.0, 0.0, 2.0]], [[0.1] * 3]),
    "fills_frame": ([[0.0, 0.0, 2.0]], [[5.0] * 3]),
}


@pytest.mark.parametrize("case", sorted(EXTREMES))
def test_extremes_are_finite_and_agree(case):
    means, scales = EXTREMES[case]
    # a normal Gaussian alongside, so the gradients have something to flow through
    means = means + [[0.1, -0.1, 3.0]]
    scales = scales + [[0.2] * 3]
    cam = axis_camera()
    quats = np.random.default_rng(1).normal(size=(2, 4)) if case == "needle" else None
    res = {}
    for backend in BACKENDS:
        g = gaussians(means, scales, [0.7, 0.5], [[0.9, 0.1, 0.1], [0.1, 0.9, 0.1]], quats)
        for x in g:
            x.requires_grad_(True)
        out = rasterization(*g, cam, [0.1, 0.2, 0.3], backend=backend)
        (out.rgb.sum() + out.alpha.sum() + 0.1 * out.depth.sum()).backward()
        vals = [out.rgb, out.alpha, out.depth] + [x.grad for x in g]
        assert all(torch.isfinite(v).all() for v in vals), case
        res[backend] = vals
    tol = 1e-6 if case == "needle" else 1e-9  # the needle's 2D covariance is ill-conditioned
    for a, b in zip(res["reference"], res["fast"]):
        np.testing.assert_allclose(a.detach().numpy(), b.detach().numpy(), rtol=tol, atol=tol)
    out_g = res["fast"]
    if case in ("behind_camera", "off_screen", "at_near_plane"):
        assert not out_g[3][0].any() and not out_g[6][0].any()  # culled: zero gradients
    if case == "fills_frame":
        assert (out_g[1] > 1 / 255).all()


@pytest.mark.parametrize("backend", BACKENDS)
def test_transparent_and_empty_scenes_show_background(backend):
    cam = axis_camera()
    bg = torch.tensor([0.25, 0.5, 0.75], dtype=F64)
    for opac in ([0.0, 1e-3], None):  # all below 1/255; then no Gaussians at all
        if opac is None:
            g = [torch.zeros((0, k), dtype=F64) for k in (3, 4, 3)] + [
                torch.zeros(0, dtype=F64),
                torch.zeros((0, 3), dtype=F64),
            ]
        else:
            g = gaussians([[0, 0, 2.0], [0.1, 0, 3.0]], [[0.3] * 3] * 2, opac, [[1.0, 0, 0]] * 2)
        for x in g:
            x.requires_grad_(True)
        out = rasterization(*g, cam, bg, backend=backend)
        assert torch.equal(out.rgb, bg.expand(cam.height, cam.width, 3))
        assert not out.alpha.any() and not out.depth.any()
        out.rgb.sum().backward()
        assert all(x.grad is not None and not x.grad.any() for x in g)


def test_bad_inputs_name_the_cause():
    cam = axis_camera()
    g = gaussians([[0, 0, 2.0]], [[0.3] * 3], [0.5], [[1.0, 0, 0]])
    with pytest.raises(ValueError, match="NaN"):
        rasterization(g[0] * float("nan"), *g[1:], cam, [0, 0, 0])
    with pytest.raises(ValueError, match="scales must be >= 0"):
        rasterization(g[0], g[1], -g[2], *g[3:], cam, [0, 0, 0])
    with pytest.raises(ValueError, match="opacities must lie in"):
        rasterization(*g[:3], g[3] + 1, g[4], cam, [0, 0, 0])
    with pytest.raises(ValueError, match="quats has shape"):
        rasterization(g[0], g[1][:, :3], *g[2:], cam, [0, 0, 0])
    with pytest.raises(ValueError, match="background"):
        rasterization(*g, cam, [0, 0])
    with pytest.raises(ValueError, match="unknown backend"):
        rasterization(*g, cam, [0, 0, 0], backend="cuda")
    with pytest.raises(ValueError, match="cast all inputs alike"):
        rasterization(g[0].float(), *g[1:], cam, [0, 0, 0])
    if not torch.cuda.is_available():
        with pytest.raises(RuntimeError, match="gsplat"):
            rasterization(*g, cam, [0, 0, 0], backend="gsplat")


def test_render_state_passes_each_field_to_its_argument():
    # An anisotropic, rotated, half-transparent Gaussian: swapping any two of the five fields
    # changes the image, so this pins the field order against the closed-form alpha profile.
    cam = axis_camera(w=40, h=36, f=50.0)
    d, sx, sy, o = 4.0, 0.3, 0.1, 0.6
    half = np.sqrt(0.5)
    g = gaussians([[0.0, 0.0, d]], [[sx, sy, 0.05]], [o], [[0.2, 0.5, 0.9]], [[half, 0, 0, half]])
    out = render_state(GaussianState(*g), cam, [0.0, 0.0, 0.0], backend="reference")
    # (w, z) = (cos 45, sin 45): 90 degrees about the optical axis turns x onto the image y
    vx, vy = (cam.fx * sy / d) ** 2 + 0.3, (cam.fy * sx / d) ** 2 + 0.3
    xx, yy = pixel_centres(cam)
    a = np.minimum(0.99, o * np.exp(-0.5 * ((xx - cam.cx) ** 2 / vx + (yy - cam.cy) ** 2 / vy)))
    a = np.where(a < 1 / 255, 0.0, a)
    np.testing.assert_allclose(out.alpha.numpy(), a, atol=2e-3)
    np.testing.assert_allclose(out.rgb.numpy(), a[..., None] * np.array([0.2, 0.5, 0.9]), atol=2e-3)
    assert out.depth is None
