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
    ctx = ModelContext(xyz, 24, n_train, L, float(wind[0].mean()), float(wind[0].std()),
                       float((wind[0] ** 2 - wind[0].mean() ** 2).std()), np.array([0.0, 1.0, 0.0]))
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
        fps=24, n_train=n_train, n_tail=n_tail, lead_in_frames=L, conditions=np.array([1.0, 0.84, 0.71]),
        wind=wind, frames=np.broadcast_to(img, (3, F, H, H, 3)),
        masks=np.broadcast_to(alpha > 0.5, (3, F, H, H)), train_camera=cam,
        heldout_azimuths_deg=np.array([30.0]), heldout_cameras=[hcam], heldout_frame_idx=np.array([0, 2]),
        heldout_frames=np.broadcast_to(himg, (1, 2, H, H, 3)), background=bg)
    res = evaluate(model_render_fn(model, obs), obs)
    # only uint8 quantisation separates render and frame: PSNR above 50 dB everywhere
    assert np.all(res.camera_psnr > 50) and np.all(res.view_psnr > 50)
    # soft alpha vs thresholded mask of the same render: sub-pixel centroid difference
    assert np.all(res.centroid_err < 0.5)
    np.testing.assert_allclose(model_means_fn(model, obs)(4, 2), xyz, atol=1e-6)
