"""Dataset: a tiny end-to-end build, the interface fields, load errors, no partial outputs,
Gaussians stored in a permuted order, framing."""

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from physgs.testbed import dataset, kinematics, scene, stats
from physgs.testbed.dataset import DatasetError, load_observed, load_truth, save_dataset
from oracles import tiny_testbed

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    # at 16 px a 0.9 fill leaves under a pixel of margin; 0.75 keeps the border test meaningful
    return tiny_testbed(tmp_path_factory.mktemp("tb"), resolution=16, fill_height=0.75)


def test_roundtrip_matches_interface(tiny):
    tb, d = tiny
    o, t = load_observed(d / "observed.npz"), load_truth(d / "truth.npz")
    C, F, L = 3, 24, o.lead_in_frames
    assert (o.fps, o.n_train, o.n_tail) == (24, 20, 4)
    assert o.wind.shape == (C, L + F) and o.wind.dtype == np.float32
    assert o.frames.shape == (C, F, 16, 16, 3) and o.frames.dtype == np.uint8
    assert o.masks.shape == (C, F, 16, 16) and o.masks.dtype == bool
    np.testing.assert_array_equal(o.heldout_frame_idx, [0, 10])
    assert o.heldout_frames.shape == (2, 2, 16, 16, 3) and len(o.heldout_cameras) == 2
    assert t.theta.shape == (C, L + F, 22)
    np.testing.assert_array_equal(o.conditions, tb["conditions"])
    # canonical positions = vertices posed at recorded frame 0 of the training wind, in Gaussian
    # order: Gaussian i is mesh vertex gaussian_vertex[i]
    posed = kinematics.pose_vertices(t, t.theta[0, L])
    np.testing.assert_allclose(o.canonical_xyz, posed[t.gaussian_vertex], atol=1e-6)
    np.testing.assert_allclose(
        o.canonical_xyz, kinematics.pose_gaussians(t, t.theta[0, L]), atol=1e-6
    )
    np.testing.assert_allclose(o.canonical_xyz[t.vertex_gaussian], posed, atol=1e-6)
    assert not np.array_equal(t.gaussian_vertex, np.arange(len(posed)))
    # the observed file holds no permutation and no bone label
    with np.load(d / "observed.npz") as z:
        assert not {"gaussian_vertex", "vertex_gaussian", "vertex_bone"} & set(z.files)
    # framing: the swept tree spans fill_height of the training image's height
    lo, hi = stats.swept_image_extent(t, o.train_camera)
    assert (hi[1] - lo[1]) / 16 == pytest.approx(tb["fill_height"], abs=1e-6)
    # the tree is in every frame, and never touches the image border (framing with margin)
    assert o.masks.reshape(C * F, -1).any(axis=1).all()
    for m in (o.masks, o.heldout_masks):
        assert not (
            m[..., 0, :].any() or m[..., -1, :].any() or m[..., :, 0].any() or m[..., :, -1].any()
        )
    # held-out azimuths really are different viewpoints on the same orbit
    c0 = o.train_camera.center
    for a, cam in zip(o.heldout_azimuths_deg, o.heldout_cameras):
        ang = np.degrees(np.arctan2(cam.center[0], -cam.center[1]) - np.arctan2(c0[0], -c0[1]))
        assert abs(ang - a) < 1.0


def test_masks_agree_with_projected_geometry(tiny):
    _, d = tiny
    o = load_observed(d / "observed.npz")
    uv, z = o.train_camera.project(o.canonical_xyz.astype(np.float64))
    assert (z > 0).all()
    px = np.floor(uv).astype(int)
    inside = (px >= 0).all(1) & (px < 16).all(1)
    assert inside.all()
    # the silhouette of frame 0 lies inside the projected vertices' bounding box (+1 px) and
    # every mask pixel is covered by some projected vertex's pixel neighbourhood
    ys, xs = np.nonzero(o.masks[0, 0])
    assert len(ys) > 0
    assert xs.min() >= px[:, 0].min() - 1 and xs.max() <= px[:, 0].max() + 1
    assert ys.min() >= px[:, 1].min() - 1 and ys.max() <= px[:, 1].max() + 1
    near = np.zeros((16, 16), bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            near[np.clip(px[:, 1] + dy, 0, 15), np.clip(px[:, 0] + dx, 0, 15)] = True
    assert near[ys, xs].all()


def test_missing_and_corrupt_files_name_the_file_and_fix(tmp_path, tiny):
    with pytest.raises(DatasetError, match=r"does not exist.*snakemake"):
        load_observed(tmp_path / "nope.npz")
    bad = tmp_path / "observed.npz"
    bad.write_bytes(b"not a zip file at all")
    with pytest.raises(DatasetError, match=r"observed\.npz is corrupt.*rebuild"):
        load_observed(bad)
    _, d = tiny
    z = dict(np.load(d / "truth.npz"))
    del z["omega"]
    np.savez(tmp_path / "truth.npz", **z)
    with pytest.raises(DatasetError, match=r"lacks \['omega'\]"):
        load_truth(tmp_path / "truth.npz")
    z = dict(np.load(d / "truth.npz"))
    z["gaussian_vertex"] = z["gaussian_vertex"].copy()
    z["gaussian_vertex"][:2] = z["gaussian_vertex"][0]  # not a permutation any more
    np.savez(tmp_path / "truth.npz", **z)
    with pytest.raises(DatasetError, match=r"gaussian_vertex is not a permutation.*rebuild"):
        load_truth(tmp_path / "truth.npz")


@pytest.mark.parametrize(
    "key, edit, says",
    [
        ("heldout_frames", lambda a: np.where(a == a.flat[0], np.nan, a), "NaN or infinite"),
        ("heldout_camera_viewmat", lambda a: a + np.inf, "NaN or infinite"),
        ("wind", lambda a: a * np.nan, "NaN or infinite"),
        ("background", lambda a: a + np.nan, "NaN or infinite"),
        ("frames", lambda a: a.astype(np.float32), "dtype float32, expected uint8"),
        ("heldout_masks", lambda a: a.astype(np.float64), "dtype float64, expected bool"),
        ("heldout_frame_idx", lambda a: a + 0.5, "dtype float64, expected integer"),
    ],
)
def test_every_array_of_observed_is_checked_naming_the_file_and_the_array(
    tmp_path, tiny, key, edit, says
):
    _, d = tiny
    z = dict(np.load(d / "observed.npz"))
    z[key] = edit(z[key].astype(np.float64) if "NaN" in says else z[key])
    np.savez(tmp_path / "observed.npz", **z)
    with pytest.raises(DatasetError) as e:
        load_observed(tmp_path / "observed.npz")
    msg = str(e.value)
    assert str(tmp_path / "observed.npz") in msg and f"{key} " in msg and says in msg, msg
    assert "rebuild" in msg


def _box(w, d, h):
    g = np.array(np.meshgrid([-w / 2, w / 2], [-d / 2, d / 2], [0.0, h])).reshape(3, -1).T
    return g + [0.3, -0.2, 0.0]


def test_framing_fills_the_training_height_exactly():
    pts = _box(1.0, 1.0, 3.0)
    cams = scene.frame_cameras(pts, [0.0, -30, 30], fov_deg=40, resolution=128, fill_height=0.9)
    uv, z = cams[0].project(pts)
    assert np.ptp(uv[:, 1]) / 128 == pytest.approx(0.9, abs=1e-9)
    assert uv[:, 1].min() == pytest.approx(128 - uv[:, 1].max(), abs=1e-6)  # centred
    # every camera on one orbit (same distance and height) about the box's vertical centre line
    c = np.array([0.3, -0.2])
    r = [np.linalg.norm(cam.center[:2] - c) for cam in cams]
    np.testing.assert_allclose(r, r[0], rtol=1e-12)
    np.testing.assert_allclose([cam.center[2] for cam in cams], cams[0].center[2], rtol=1e-12)
    for cam in cams:
        uv, _ = cam.project(pts)
        assert (uv >= 0.5).all() and (uv <= 127.5).all()
    # a smaller fill moves the camera back; the field of view never changes
    far = scene.frame_cameras(pts, [0.0], fov_deg=40, resolution=128, fill_height=0.6)[0]
    assert np.linalg.norm(far.center[:2] - c) > r[0] and far.fy == cams[0].fy


def test_framing_shifts_the_camera_height_for_a_held_out_view():
    # a tree whose top reaches toward the camera at +60 degrees: that view clips when the
    # training view is centred, so the camera rises (the training view stays at 0.9 of its height)
    u = 1.2 * np.array([np.sin(np.pi / 3), -np.cos(np.pi / 3)])  # toward the +60 camera
    c = np.array([0.3, -0.2])
    pts = np.concatenate([_box(0.4, 0.4, 2.0), [[*(c + u), 3.0], [*(c - u), 0.0]]])
    cams = scene.frame_cameras(pts, [0.0, 60], fov_deg=40, resolution=128, fill_height=0.9)
    uv, _ = cams[0].project(pts)
    assert np.ptp(uv[:, 1]) / 128 == pytest.approx(0.9, abs=1e-9)
    assert uv[:, 1].min() > 128 - uv[:, 1].max() + 4  # no longer centred: the camera rose
    uv, _ = cams[1].project(pts)
    assert uv[:, 1].min() == pytest.approx(0.5, abs=1e-6)  # just inside the +60 view's margin


def test_framing_error_names_the_key_and_the_fix():
    flat = _box(6.0, 0.2, 1.0)  # wide and low: it leaves the image sideways at 0.9 height fill
    with pytest.raises(
        scene.FramingError,
        match=r"testbed\.fill_height = 0\.9.*training camera.*lower "
        r"testbed\.fill_height.*at most 0\.\d+ fits",
    ):
        scene.frame_cameras(flat, [0.0], fov_deg=40, resolution=128, fill_height=0.9)
    deep = _box(0.5, 6.0, 3.0)  # deep along the training axis: side views see it wide
    with pytest.raises(scene.FramingError, match=r"held-out view at azimuth [+-]60 deg"):
        scene.frame_cameras(deep, [0.0, -60, 60], fov_deg=40, resolution=128, fill_height=0.9)
    msg = ""
    try:
        scene.frame_cameras(deep, [0.0, -60, 60], fov_deg=40, resolution=128, fill_height=0.9)
    except scene.FramingError as e:
        msg = str(e)
    best = float(msg.split("at most ")[1].split(" ")[0])
    scene.frame_cameras(deep, [0.0, -60, 60], fov_deg=40, resolution=128, fill_height=best - 1e-3)
    with pytest.raises(scene.FramingError, match=r"must lie in \(0, 1\)"):
        scene.frame_cameras(deep, [0.0], fov_deg=40, resolution=128, fill_height=1.2)


def test_failed_save_leaves_nothing(tmp_path, monkeypatch):
    calls = []
    real = np.savez_compressed

    def flaky(f, **kw):
        calls.append(1)
        if len(calls) == 2:
            raise OSError("disk full")
        real(f, **kw)

    monkeypatch.setattr(dataset.np, "savez_compressed", flaky)
    with pytest.raises(OSError):
        save_dataset({"a": np.zeros(3)}, {"b": np.ones(2)}, tmp_path / "o.npz", tmp_path / "t.npz")
    assert list(tmp_path.iterdir()) == []


def _workdir(tmp_path, edit):
    for p in ("Snakefile", "config", "workflow"):
        src = ROOT / p
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / p)
    cfg = yaml.safe_load((tmp_path / "config/trees.yaml").read_text())
    edit(cfg)
    (tmp_path / "config/trees.yaml").write_text(yaml.safe_dump(cfg))
    return subprocess.run(
        [sys.executable, "-m", "snakemake", "--cores", "1", "testbed", "--config", "profile=quick"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )


def test_schema_violation_stops_the_workflow(tmp_path):
    r = _workdir(tmp_path, lambda c: c["presets"]["sparse"].update(taper=1.5))
    assert r.returncode != 0
    assert "taper" in r.stderr + r.stdout
    assert not (tmp_path / "results").exists()


def test_unreachable_bone_count_stops_with_cause_and_leaves_nothing(tmp_path):
    def edit(c):
        c["trees"] = ["sparse"]
        c["presets"]["sparse"]["levels"][0]["curve_res"] = 5

    r = _workdir(tmp_path, edit)
    out = r.stderr + r.stdout
    assert r.returncode != 0
    assert "yields 23 animated bones but declares bones: 22" in out
    assert not list(tmp_path.glob("results/**/*.npz*"))  # no dataset file, partial or whole
