"""Dataset: a tiny end-to-end build, the interface fields, load errors, no partial outputs."""
import copy
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from physgs.config import load
from physgs.testbed import dataset, kinematics
from physgs.testbed.dataset import DatasetError, build_dataset, load_observed, load_truth, save_dataset

ROOT = Path(__file__).resolve().parents[1]
CFG = load(ROOT / "config/trees.yaml", "quick")


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    tb = copy.deepcopy(CFG["testbed"])
    tb.update(n_train=20, n_tail=4, resolution=16, supersample=1, heldout_azimuths_deg=[-30, 60])
    obs, tru = build_dataset(tb, CFG["presets"]["sparse"], seed=0, tree="sparse", progress=False)
    d = tmp_path_factory.mktemp("tb")
    save_dataset(obs, tru, d / "observed.npz", d / "truth.npz")
    return tb, d


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
    # canonical positions = vertices posed at recorded frame 0 of the training wind
    np.testing.assert_allclose(o.canonical_xyz, kinematics.pose_vertices(t, t.theta[0, L]), atol=1e-6)
    # the tree is in every frame, and never touches the image border (framing with margin)
    assert o.masks.reshape(C * F, -1).any(axis=1).all()
    for m in (o.masks, o.heldout_masks):
        assert not (m[..., 0, :].any() or m[..., -1, :].any() or m[..., :, 0].any() or m[..., :, -1].any())
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
    return subprocess.run([sys.executable, "-m", "snakemake", "--cores", "1", "testbed",
                           "--config", "profile=quick"], cwd=tmp_path, capture_output=True, text=True)


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
