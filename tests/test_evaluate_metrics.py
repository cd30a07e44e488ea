"""Metrics and splits against hand-computed values."""

from types import SimpleNamespace

import numpy as np
import pytest

from physgs.camera import orbit_camera
from physgs.evaluate import (
    EvalResult,
    centroid_error,
    evaluate,
    load_eval,
    psnr,
    silhouette_centroid,
)


def test_psnr_hand_computed():
    gt = np.zeros((4, 5, 3))
    pred = np.zeros((4, 5, 3))
    pred[0, 0, 0] = 1.0  # one channel of one pixel off by 1: mse = 1/60
    assert psnr(pred, gt) == pytest.approx(10 * np.log10(60.0), abs=1e-12)


def test_psnr_uint8_and_per_frame():
    gt = np.full((2, 3, 3, 3), 100, np.uint8)
    pred = gt.astype(np.float64) / 255.0
    pred[1] += 0.1
    out = psnr(pred, gt)
    assert out.shape == (2,)
    assert np.isinf(out[0]) and out[1] == pytest.approx(20.0, abs=1e-9)


def test_psnr_rejects_bad_input():
    with pytest.raises(ValueError, match="shape"):
        psnr(np.zeros((2, 2, 3)), np.zeros((3, 2, 3)))
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        psnr(np.full((2, 2, 3), 2.0), np.zeros((2, 2, 3)))


def disk(h, w, cx, cy, r):
    ys, xs = np.indices((h, w)) + 0.5
    return (xs - cx) ** 2 + (ys - cy) ** 2 <= r**2


def test_centroid_of_drawn_disk():
    m = disk(64, 80, cx=30.0, cy=20.0, r=9.0)  # symmetric about the pixel-centre grid
    np.testing.assert_allclose(silhouette_centroid(m), [30.0, 20.0], atol=1e-12)
    shifted = disk(64, 80, cx=33.0, cy=24.0, r=9.0).astype(float)
    assert centroid_error(shifted, m) == pytest.approx(5.0, abs=1e-12)


def test_centroid_empty_raises():
    with pytest.raises(ValueError, match="empty silhouette"):
        silhouette_centroid(np.zeros((4, 4)))


def fake_observed(rng):
    H = W = 16
    C, n_train, n_tail = 3, 6, 2
    F = n_train + n_tail
    cam = orbit_camera(0, radius=5, height=1, target=(0, 0, 1), fov_deg=40, width=W, height_px=H)
    az = [-15.0, 15.0]
    hcams = [
        orbit_camera(a, radius=5, height=1, target=(0, 0, 1), fov_deg=40, width=W, height_px=H)
        for a in az
    ]
    hidx = np.array([0, 3])
    masks = np.zeros((C, F, H, W), bool)
    for c in range(C):
        for j in range(F):
            masks[c, j] = disk(H, W, 8.0, 8.0 + 0.0 * j, 3.0)
    return SimpleNamespace(
        fps=24,
        n_train=n_train,
        n_tail=n_tail,
        lead_in_frames=4,
        conditions=np.array([1.0, 0.84, 0.71]),
        frames=rng.integers(60, 190, (C, F, H, W, 3), dtype=np.uint8),
        masks=masks,
        train_camera=cam,
        heldout_azimuths_deg=np.array(az),
        heldout_cameras=hcams,
        heldout_frame_idx=hidx,
        heldout_frames=rng.integers(60, 190, (2, 2, H, W, 3), dtype=np.uint8),
    )


def test_evaluate_routes_every_split(tmp_path):
    obs = fake_observed(np.random.default_rng(0))
    H, W = obs.frames.shape[2:4]

    def render_fn(j, c, cam):
        # offset encodes (condition, frame) so a mis-routed frame changes the score
        if cam is obs.train_camera:
            delta = 0.01 * (1 + c) * (1 + (j >= obs.n_train))
            rgb = obs.frames[c, j] / 255.0 + delta
            alpha = disk(H, W, 8.0 + c, 8.0, 3.0).astype(float)  # centroid off by c px
        else:
            a = [i for i, hc in enumerate(obs.heldout_cameras) if hc is cam][0]
            m = list(obs.heldout_frame_idx).index(j)
            rgb = obs.heldout_frames[a, m] / 255.0 + 0.05
            alpha = np.ones((H, W))
            assert c == 0
        return rgb, alpha

    res = evaluate(render_fn, obs)

    def db(d):
        return -10 * np.log10(d**2)

    np.testing.assert_allclose(res.view_psnr, db(0.05), atol=1e-9)
    np.testing.assert_allclose(res.time_psnr, db(0.02), atol=1e-9)
    np.testing.assert_allclose(res.temporal_psnr[: obs.n_train], db(0.01), atol=1e-9)
    np.testing.assert_allclose(res.train_timestamps_psnr[2], db(0.03), atol=1e-9)
    np.testing.assert_allclose(res.beyond_window_psnr[1], db(0.04), atol=1e-9)
    np.testing.assert_allclose(
        res.centroid_err, np.array([0.0, 1.0, 2.0])[:, None] * np.ones((1, 8)), atol=1e-9
    )
    s = res.summary()
    assert s["beyond_c2"] == pytest.approx(db(0.06)) and s["centroid_c1"] == pytest.approx(1.0)
    res.save(tmp_path / "e.npz")
    back = load_eval(tmp_path / "e.npz")
    assert isinstance(back, EvalResult) and back.n_train == obs.n_train
    np.testing.assert_array_equal(back.camera_psnr, res.camera_psnr)


def test_evaluate_rejects_wrong_render_size():
    obs = fake_observed(np.random.default_rng(1))
    with pytest.raises(ValueError, match="render_fn returned"):
        evaluate(lambda j, c, cam: (np.zeros((8, 8, 3)), np.ones((8, 8))), obs)
