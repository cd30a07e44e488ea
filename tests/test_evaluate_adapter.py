"""The model adapter wires wind, camera and background through to evaluate(): a dataset whose
frames are renders of the model itself scores a perfect (infinite) PSNR and zero centroid error."""

from types import SimpleNamespace

import numpy as np
import torch

import physgs.config
from physgs.camera import orbit_camera
from physgs.evaluate import evaluate, model_means_fn, model_render_fn
from physgs.models import ModelContext, build_model
from physgs.render import rasterization


def test_self_rendered_dataset_scores_perfectly():
    rng = np.random.default_rng(0)
    n, L, n_train, n_tail, H = 60, 8, 3, 2, 12
    F = n_train + n_tail
    xyz = (rng.normal(size=(n, 3)) * [0.3, 0.3, 0.6] + [0.0, 0.0, 1.0]).astype(np.float32)
    wind = 6.0 + rng.standard_normal((3, L + F))
    ctx = ModelContext(
        xyz,
        24,
        n_train,
        L,
        float(wind[0].mean()),
        float(wind[0].std()),
        float((wind[0] ** 2 - wind[0].mean() ** 2).std()),
        np.array([0.0, 1.0, 0.0]),
    )
    model = build_model("static", ctx, physgs.config.load("config/trees.yaml", "quick")["models"])
    cam = orbit_camera(0, radius=4, height=1, target=(0, 0, 1), fov_deg=50, width=H, height_px=H)
    hcam = orbit_camera(30, radius=4, height=1, target=(0, 0, 1), fov_deg=50, width=H, height_px=H)
    bg = np.array([1.0, 1.0, 1.0])

    def draw(camera):
        g = model.gaussians_at(0, torch.as_tensor(wind[0], dtype=torch.float32))
        with torch.no_grad():
            out = rasterization(g.means, g.quats, g.scales, g.opacities, g.colors, camera, bg)
        return np.round(out.rgb.clamp(0, 1).numpy() * 255).astype(np.uint8), out.alpha.numpy()

    img, alpha = draw(cam)
    himg, _ = draw(hcam)
    obs = SimpleNamespace(
        fps=24,
        n_train=n_train,
        n_tail=n_tail,
        lead_in_frames=L,
        conditions=np.array([1.0, 0.84, 0.71]),
        wind=wind,
        frames=np.broadcast_to(img, (3, F, H, H, 3)),
        masks=np.broadcast_to(alpha > 0.5, (3, F, H, H)),
        train_camera=cam,
        heldout_azimuths_deg=np.array([30.0]),
        heldout_cameras=[hcam],
        heldout_frame_idx=np.array([0, 2]),
        heldout_frames=np.broadcast_to(himg, (1, 2, H, H, 3)),
        background=bg,
    )
    res = evaluate(model_render_fn(model, obs), obs)
    # only uint8 quantisation separates render and frame: PSNR above 50 dB everywhere
    assert np.all(res.camera_psnr > 50) and np.all(res.view_psnr > 50)
    # soft alpha vs thresholded mask of the same render: sub-pixel centroid difference
    assert np.all(res.centroid_err < 0.5)
    np.testing.assert_allclose(model_means_fn(model, obs)(4, 2), xyz, atol=1e-6)


def test_render_cache_never_leaks_across_frames_or_wind():
    """The adapter deforms each (frame, condition) once; its renders equal uncached ones."""
    rng = np.random.default_rng(1)
    n, L, n_train, n_tail, H = 40, 160, 3, 2, 12
    xyz = (rng.normal(size=(n, 3)) * [0.3, 0.3, 0.6] + [0.0, 0.0, 1.0]).astype(np.float32)
    w0 = 6.0 + 1.5 * rng.standard_normal(L + n_train + n_tail)
    wind = np.stack([w0, 0.71 * w0])
    ctx = ModelContext(
        xyz,
        24,
        n_train,
        L,
        float(w0.mean()),
        float(w0.std()),
        float((w0**2 - w0.mean() ** 2).std()),
        np.array([0.0, 1.0, 0.0]),
    )
    cfg = physgs.config.load("config/trees.yaml", "quick")["models"]
    cam = orbit_camera(0, radius=4, height=1, target=(0, 0, 1), fov_deg=50, width=H, height_px=H)
    obs = SimpleNamespace(wind=wind, background=np.ones(3))
    for name in ("ours", "mlp"):
        model = build_model(name, ctx, cfg, config="single")
        with torch.no_grad():  # move off the canonical pose so frames and winds differ
            for p in model.parameters():
                if p.ndim >= 1 and p.shape[0] in (n,):
                    continue
                p.add_(0.05 * torch.randn_like(p))
        seen: dict = {}
        fn = model_render_fn(model, obs, means_seen=seen)
        for j, c in [(0, 0), (0, 1), (1, 1), (1, 0), (0, 0)]:
            got = fn(j, c, cam)[0]
            g = model.gaussians_at(j, torch.as_tensor(wind[c], dtype=torch.float32))
            with torch.no_grad():
                ref = (
                    rasterization(
                        g.means, g.quats, g.scales, g.opacities, g.colors, cam, np.ones(3)
                    )
                    .rgb.clamp(0, 1)
                    .numpy()
                )
            np.testing.assert_allclose(got, ref, atol=1e-6, err_msg=f"{name} frame {j} cond {c}")
        if name == "ours":  # the wind matters to ours, so the two conditions must differ
            assert np.abs(fn(1, 0, cam)[0] - fn(1, 1, cam)[0]).max() > 1e-4
        # the training wind's deformations are kept for the tips, and handed back unchanged
        assert sorted(seen) == [(0, 0), (1, 0)]
        fresh, reuse = model_means_fn(model, obs), model_means_fn(model, obs, seen)
        for j in (0, 1):
            assert np.array_equal(reuse(j, 0), fresh(j, 0)) and reuse(j, 0) is seen[(j, 0)]
