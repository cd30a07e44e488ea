"""Fast numba path against the PyTorch reference; determinism; gsplat dispatch (GPU only)."""

import numpy as np
import pytest
import torch

from physgs.render import rasterization
from physgs.render.scenes import random_scene


def render_with_grads(backend, scene, dtype, seed=0):
    """Outputs and gradients of a random weighted sum of rgb, alpha and depth."""
    means, quats, scales, opac, colors, cam, bg = scene
    params = [
        x.detach().to(dtype).requires_grad_(True) for x in (means, quats, scales, opac, colors, bg)
    ]
    out = rasterization(*params[:5], cam, params[5], backend=backend)
    g = torch.Generator().manual_seed(seed)
    H, W = cam.height, cam.width
    w = [
        torch.rand(s, generator=g, dtype=torch.float64).to(dtype)
        for s in ((H, W, 3), (H, W), (H, W))
    ]
    loss = (out.rgb * w[0]).sum() + (out.alpha * w[1]).sum() + (out.depth * w[2]).sum()
    loss.backward()
    return [out.rgb, out.alpha, out.depth] + [p.grad for p in params]


NAMES = ["rgb", "alpha", "depth", "means", "quats", "scales", "opacities", "colors", "background"]


@pytest.fixture(scope="module")
def scene():
    # 400 Gaussians over a 45x38 image: partial tiles, overlaps, the transmittance stop.
    return random_scene(400, 45, 38, seed=7, dtype=torch.float64, opacity_range=(0.1, 0.95))


def test_fast_matches_reference_float64(scene):
    ref = render_with_grads("reference", scene, torch.float64)
    fast = render_with_grads("fast", scene, torch.float64)
    assert ref[1].max() > 0.999 and ref[1].min() < 0.01  # dense and empty regions both present
    for name, a, b in zip(NAMES, ref, fast):
        scale = max(1.0, a.abs().max().item())
        np.testing.assert_allclose(
            b.detach().numpy(), a.detach().numpy(), rtol=0, atol=1e-10 * scale, err_msg=name
        )


@pytest.mark.parametrize(
    "n, spacing, label",
    [
        (600, 0.15, "pixel-sized"),  # tree-like: footprints of one to three rows (row trimming)
        (60, 4.0, "tile-wide"),  # spans as wide as a tile (exp stepped across 16 pixels)
    ],
)
def test_fast_matches_reference_across_footprint_sizes(n, spacing, label):
    # The fast kernels trim each footprint to the rows its 1/255 contour reaches and step
    # exp(-sigma / 2) along a row by multiplication; both must stay within 1e-12 of the float64
    # reference (scaled by the largest value of each output), from sub-pixel to tile-wide spans.
    means, quats, scales, opac, colors, cam, bg = random_scene(
        n, 48, 40, seed=3, dtype=torch.float64, opacity_range=(0.05, 0.95)
    )
    scales = scales * spacing * torch.linspace(0.3, 3.0, n, dtype=torch.float64)[:, None] ** 0.5
    scales[:, 0] *= 3.0  # elongated, rotated ellipses: row spans far from their box
    scene = (means, quats, scales, opac, colors, cam, bg)
    ref = render_with_grads("reference", scene, torch.float64)
    fast = render_with_grads("fast", scene, torch.float64)
    assert ref[1].max() > 0.5, label  # something is drawn
    for name, a, b in zip(NAMES, ref, fast):
        scale = max(1.0, a.abs().max().item())
        np.testing.assert_allclose(
            b.detach().numpy(), a.detach().numpy(), rtol=0, atol=1e-12 * scale, err_msg=name
        )


@pytest.mark.parametrize("D", [1, 2, 5])
def test_fast_matches_reference_for_other_channel_counts(scene, D):
    # The kernels unroll RGB (D = 3); every other channel count takes their generic loops.
    means, quats, scales, opac, colors, cam, bg = scene
    g = torch.Generator().manual_seed(D)
    colors = torch.rand((colors.shape[0], D), generator=g, dtype=torch.float64)
    bg = torch.rand(D, generator=g, dtype=torch.float64)
    grads = {}
    for backend in ("reference", "fast"):
        params = [x.detach().requires_grad_(True) for x in (means, quats, scales, opac, colors, bg)]
        out = rasterization(*params[:5], cam, params[5], backend=backend)
        w = torch.rand(
            out.rgb.shape, generator=torch.Generator().manual_seed(0), dtype=out.rgb.dtype
        )
        ((out.rgb * w).sum() + out.alpha.sum() + out.depth.sum()).backward()
        grads[backend] = [out.rgb, out.alpha, out.depth] + [p.grad for p in params]
    assert grads["fast"][0].shape[-1] == D
    for name, a, b in zip(NAMES, grads["reference"], grads["fast"]):
        scale = max(1.0, a.abs().max().item())
        np.testing.assert_allclose(
            b.detach().numpy(), a.detach().numpy(), rtol=0, atol=1e-10 * scale, err_msg=name
        )


def test_float32_paths_close_to_float64_reference(scene):
    # float32 inputs go through float64 kernels: the fast path's only error is the final cast.
    scene32 = [x.float() if isinstance(x, torch.Tensor) else x for x in scene]
    scene64 = [x.double() if isinstance(x, torch.Tensor) else x for x in scene32]
    ref = render_with_grads("reference", scene64, torch.float64)
    fast = render_with_grads("fast", scene32, torch.float32)
    ref32 = render_with_grads("reference", scene32, torch.float32)
    for name, a, b, c in zip(NAMES, ref, fast, ref32):
        assert b.dtype == torch.float32 and c.dtype == torch.float32, name
        scale = max(1.0, a.abs().max().item())
        np.testing.assert_allclose(
            b.detach().double().numpy(), a.detach().numpy(), rtol=0, atol=1e-5 * scale, err_msg=name
        )
        # the float32 reference itself accumulates in float32: looser, but still close
        np.testing.assert_allclose(
            c.detach().double().numpy(), a.detach().numpy(), rtol=0, atol=1e-4 * scale, err_msg=name
        )


@pytest.mark.parametrize("mode", ["no_grad", "inference_mode", "no input requires grad"])
def test_forward_only_path_renders_the_same_and_keeps_no_graph(scene, mode):
    # Evaluation renders without autograd: the fast path then skips the autograd Function (no
    # node, no saved state) and must give the very same images as the differentiable call.
    means, quats, scales, opac, colors, cam, bg = scene
    params = [x.detach().requires_grad_(True) for x in (means, quats, scales, opac, colors)]
    ref = rasterization(*params, cam, bg, backend="fast")
    assert ref.rgb.grad_fn is not None
    if mode == "no_grad":
        with torch.no_grad():
            out = rasterization(*params, cam, bg, backend="fast")
    elif mode == "inference_mode":
        with torch.inference_mode():
            out = rasterization(*params, cam, bg, backend="fast")
    else:
        out = rasterization(*(p.detach() for p in params), cam, bg, backend="fast")
    for a, b in zip((ref.rgb, ref.alpha, ref.depth), (out.rgb, out.alpha, out.depth)):
        assert b.grad_fn is None and not b.requires_grad
        assert torch.equal(a.detach(), b)


def test_fast_is_deterministic():
    scene = random_scene(3000, 64, 64, seed=11, dtype=torch.float32)
    first = render_with_grads("fast", scene, torch.float32)
    second = render_with_grads("fast", scene, torch.float32)
    assert first[0].abs().sum() > 0
    for name, a, b in zip(NAMES, first, second):
        assert torch.equal(a, b), name


@pytest.mark.skipif(not torch.cuda.is_available(), reason="gsplat backend needs a CUDA GPU")
def test_gsplat_matches_fast():
    pytest.importorskip("gsplat")
    scene = random_scene(2000, 64, 64, seed=5, dtype=torch.float32)
    means, quats, scales, opac, colors, cam, bg = scene
    cpu = rasterization(*scene[:5], cam, bg, backend="fast")
    gpu = rasterization(*(x.cuda() for x in scene[:5]), cam, bg.cuda(), backend="auto")
    # gsplat cuts footprints at 3 sigma where the CPU path uses the exact 1/255 contour.
    for a, b in zip((cpu.rgb, cpu.alpha, cpu.depth), (gpu.rgb, gpu.alpha, gpu.depth)):
        np.testing.assert_allclose(b.cpu().numpy(), a.numpy(), atol=2e-2)


def test_work_count_matches_a_per_pixel_count(scene):
    # The benchmark's work count: pairs composited before transmittance saturates, counted here
    # independently per pixel (numpy, the reference's projection, every Gaussian in depth order).
    from physgs.render.constants import ALPHA_MAX, ALPHA_MIN, T_MIN
    from physgs.render.fast import work_count
    from physgs.render.project import project_gaussians

    means, quats, scales, opac, colors, cam, bg = scene
    work = work_count(means, quats, scales, opac, colors, cam, bg)
    proj = project_gaussians(means, quats, scales, cam)
    keep = proj.valid.numpy()
    m2, con = proj.means2d.numpy()[keep], proj.conics.numpy()[keep]
    o, z = opac.numpy()[keep], proj.depths.numpy()[keep]
    order = np.argsort(z, kind="stable")
    m2, con, o = m2[order], con[order], o[order]
    pairs = 0
    for py in range(cam.height):
        for px in range(cam.width):
            d = np.array([px + 0.5, py + 0.5]) - m2  # [n, 2]
            sigma = con[:, 0] * d[:, 0] ** 2 + 2 * con[:, 1] * d[:, 0] * d[:, 1]
            sigma += con[:, 2] * d[:, 1] ** 2
            a = np.minimum(ALPHA_MAX, o * np.exp(-0.5 * sigma))
            a = a[a >= ALPHA_MIN]
            T = np.cumprod(np.concatenate([[1.0], 1.0 - a]))  # T before each, then after
            stop = np.flatnonzero(T[1:] < T_MIN)
            pairs += int(stop[0]) if stop.size else a.size
    assert work["pairs"] == pairs > 1000
    assert work["footprint_pixels"] >= work["pairs"]
    assert work["gaussians"] == 400 and work["rows"] <= work["footprint_pixels"]


def test_without_depth_the_same_images_and_gradients_bit_for_bit(scene):
    # Oracle: the with-depth path under a loss that does not read the depth (whose gradient is
    # then zero): skipping the depth's terms must change no bit of the images or the gradients.
    means, quats, scales, opac, colors, cam, bg = scene
    w = torch.rand(
        cam.height, cam.width, colors.shape[1], generator=torch.Generator().manual_seed(1)
    )
    got = []
    for with_depth in (True, False):
        ps = [x.clone().double().requires_grad_(True) for x in (means, quats, scales, opac, colors)]
        out = rasterization(*ps, cam, bg.double(), return_depth=with_depth, backend="fast")
        assert (out.depth is None) == (not with_depth)
        ((out.rgb * w).sum() + 0.3 * out.alpha.sum()).backward()
        got.append([out.rgb.detach(), out.alpha.detach(), *(p.grad for p in ps)])
    for a, b in zip(*got):
        assert torch.equal(a, b)
