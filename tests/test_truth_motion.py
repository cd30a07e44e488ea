"""The true-motion reference (truth_motion): the canonical Gaussians moved by the ground-truth
skinning. A hand-built 4-bone tree (two levels of children, so angles accumulate) with a permuted
Gaussian order, three exactly rescaled wind conditions, and frames rendered from its true motion.

Oracles: ``kinematics.pose_gaussians`` for the means; scipy's Rotation about the swing axis by the
cumulative-angle difference (``kinematics.cumulative_angle``) for the orientations.
"""

from __future__ import annotations

import copy
from types import SimpleNamespace

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from physgs.camera import look_at
from physgs.evaluate.adapter import model_means_fn, model_render_fn
from physgs.experiments import fit, job_spec, train_and_save
from physgs.models import (
    MODEL_NAMES,
    REFERENCES,
    TruthMotionModel,
    build_model,
    configs_for,
    load_checkpoint,
    model_settings,
    training_jobs,
)
from physgs.models.registry import label
from physgs.render import rasterization, render_state
from physgs.testbed import kinematics
from physgs.train import photometric_loss
from oracles import rotation_wxyz

FPS, N_TRAIN, N_TAIL, LEAD_IN, RES = 24, 8, 2, 6, 24
F = N_TRAIN + N_TAIL
COND = np.array([1.0, 0.84, 0.71])
CANON = {"opacity": 0.1, "color": 0.5, "knn": 3, "scale_factor": 1.0}
LR = {
    "means": 1.6e-4,
    "quats": 1e-3,
    "scales": 5e-3,
    "opacities": 5e-2,
    "colors": 1e-2,
    "deform": 8e-4,
    "physics": 5e-2,
    "pivot": 1.6e-4,
}


def _train_cfg(iterations=30, warmup=10):
    return {
        "iterations": iterations,
        "warmup": warmup,
        "ssim_weight": 0.2,
        "lr": dict(LR),
        "lr_final_ratio": 0.01,
        "backend": "fast",
    }


def _cfg():
    """The slice of a resolved config that job_spec reads."""
    return {
        "seed": 0,
        "train": _train_cfg(),
        "models": {
            "canonical": dict(CANON),
            "mlp": {"pos_bands": 2},
            "configs": {
                "single": {"conditions": "train", "K": 4},
                "joint32": {"conditions": "all", "K": 4},
            },
        },
    }


def make_pair(seed: int = 0):
    """(observed, truth): a tiny skinned tree in the testbed's file layout."""
    rng = np.random.default_rng(seed)
    head = np.array([[0, 0, 0], [0, 0, 1.0], [0, 0, 1.0], [0.35, 0.1, 1.6]])
    tail = np.array([[0, 0, 1.0], [0.35, 0.1, 1.6], [-0.3, -0.1, 1.5], [0.55, 0.2, 2.0]])
    parent = np.array([-1, 0, 0, 1])
    B, per = len(parent), 20
    vb = np.repeat(np.arange(B), per)  # mesh order groups vertices by bone
    s = np.tile(np.linspace(0.05, 0.95, per), B)[:, None]
    rest = head[vb] + s * (tail - head)[vb] + 0.04 * rng.standard_normal((B * per, 3))
    t = np.arange(-LEAD_IN, F) / FPS
    f = np.array([0.6, 0.9, 1.2, 1.4])
    amp = np.array([0.08, 0.15, 0.12, 0.2])
    unit = amp * np.sin(2 * np.pi * f * t[:, None] + rng.uniform(0, 2 * np.pi, B)) + 0.05
    theta = COND[:, None, None] * unit[None]  # [C, L+F, B]; nonzero at frame 0
    gv = rng.permutation(B * per)
    truth = SimpleNamespace(
        theta=theta,
        bone_head=head,
        bone_tail=tail,
        bone_parent=parent,
        swing_axis=kinematics.swing_axis(40.0),
        vertex_bone=vb,
        rest_vertices=rest,
        gaussian_vertex=gv,
        vertex_gaussian=np.argsort(gv),
        lead_in_frames=LEAD_IN,
        fps=FPS,
    )
    canonical = kinematics.pose_gaussians(truth, theta[0, LEAD_IN]).astype(np.float32)
    wind = (COND[:, None] * (6.0 + 1.5 * rng.standard_normal(LEAD_IN + F))).astype(np.float32)
    cam = look_at((0.0, -5.0, 1.0), (0.0, 0.0, 1.0), fov_deg=40, width=RES, height=RES)
    palette = np.array([[0.4, 0.25, 0.1], [0.2, 0.6, 0.2], [0.1, 0.5, 0.3], [0.6, 0.7, 0.1]])
    col = torch.tensor(palette[vb[gv]], dtype=torch.float32)
    n = len(gv)
    q = torch.tensor([[1.0, 0, 0, 0]]).repeat(n, 1)
    sc, op = torch.full((n, 3), 0.06), torch.full((n,), 0.8)
    frames = np.empty((3, F, RES, RES, 3), np.uint8)
    for c in range(3):
        posed = kinematics.pose_gaussians(truth, theta[c, LEAD_IN:])  # [F, N, 3]
        for j in range(F):
            out = rasterization(
                torch.tensor(posed[j], dtype=torch.float32),
                q,
                sc,
                op,
                col,
                cam,
                [1.0, 1.0, 1.0],
                backend="fast",
                return_depth=False,
            )
            frames[c, j] = np.round(out.rgb.numpy() * 255).astype(np.uint8)
    observed = SimpleNamespace(
        fps=FPS,
        n_train=N_TRAIN,
        n_tail=N_TAIL,
        lead_in_frames=LEAD_IN,
        conditions=COND,
        vbar=6.0 * COND,
        wind=wind,
        frames=frames,
        train_camera=cam,
        background=np.ones(3),
        canonical_xyz=canonical,
    )
    return observed, truth


@pytest.fixture(scope="module")
def pair():
    return make_pair()


@pytest.fixture(scope="module")
def trained(pair, tmp_path_factory):
    """A truth_motion job trained and saved through the recipe (the workflow's path)."""
    observed, truth = pair
    d = tmp_path_factory.mktemp("ref")
    ck, lg = d / "truth_motion_single.pt", d / "truth_motion_single.loss.csv"
    before = build_model("truth_motion", observed, {"canonical": CANON}, truth=truth)
    res = train_and_save(
        observed,
        job_spec(_cfg(), "truth_motion", "single"),
        checkpoint_path=ck,
        loss_path=lg,
        progress=False,
        truth=truth,
    )
    return SimpleNamespace(before=before, result=res, checkpoint=ck, loss=lg)


def _model(pair):
    observed, truth = pair
    return build_model(
        "truth_motion", observed, model_settings(_cfg()["models"], "truth_motion"), truth=truth
    )


def _winds(observed):
    return [torch.tensor(w) for w in observed.wind]


def _dphi(truth, c, j):
    """Oracle: each Gaussian's rotation angle from the canonical pose, Gaussian order [N]."""
    Phi = kinematics.cumulative_angle(truth.bone_parent, truth.theta[:, LEAD_IN:])  # [C, F, B]
    bone = truth.vertex_bone[truth.gaussian_vertex]
    return (Phi[c, j] - Phi[0, 0])[bone]


# ---------------------------------------------------------------------------------------------


def test_means_follow_the_true_motion(pair):
    """(a) every frame of every condition: the means are pose_gaussians of that column."""
    observed, truth = pair
    model = _model(pair)
    winds = _winds(observed)
    with torch.no_grad():
        for c in range(3):
            want = kinematics.pose_gaussians(truth, truth.theta[c, LEAD_IN:])  # [F, N, 3]
            for j in range(F):
                got = model.gaussians_at(j, winds[c]).means
                assert got.dtype == torch.float32
                np.testing.assert_allclose(
                    got.numpy(), want[j], atol=1e-5, rtol=0, err_msg=f"condition {c}, frame {j}"
                )
    # the motion is real: the tree moves by centimetres between frames and conditions
    assert (
        np.abs(
            kinematics.pose_gaussians(truth, truth.theta[2, LEAD_IN + 5]) - observed.canonical_xyz
        ).max()
        > 0.02
    )


def test_orientations_rotate_with_the_bone_chain(pair):
    """(b) the quaternion change (frame j of condition c relative to canonical) rotates a vector
    as scipy's rotation about the swing axis by the cumulative-angle difference."""
    observed, truth = pair
    model = _model(pair)
    rng = np.random.default_rng(1)
    q0 = Rotation.random(model.canonical.n, random_state=2).as_quat()  # (x, y, z, w)
    with torch.no_grad():  # non-identity canonical orientations make the check stronger
        model.canonical.quats.copy_(torch.tensor(q0[:, [3, 0, 1, 2]], dtype=torch.float32))
    R0 = rotation_wxyz(model.canonical.quats.detach().numpy())
    axis = np.asarray(truth.swing_axis)
    v = rng.standard_normal((model.canonical.n, 3))
    winds = _winds(observed)
    for c, j in [(0, 0), (0, 5), (1, 3), (2, 9)]:
        with torch.no_grad():
            q = model.gaussians_at(j, winds[c]).quats.numpy()
        change = rotation_wxyz(q) * R0.inv()
        want = Rotation.from_rotvec(axis[None] * _dphi(truth, c, j)[:, None]).apply(v)
        np.testing.assert_allclose(
            change.apply(v), want, atol=1e-5, rtol=0, err_msg=f"condition {c}, frame {j}"
        )
    assert np.abs(_dphi(truth, 2, 9)).max() > 0.05  # the check is not vacuous


def test_frame_zero_of_the_training_condition_is_the_canonical_pose(pair):
    """(c) exactly, bit for bit, whatever the canonical parameters are."""
    observed, _ = pair
    model = _model(pair)
    with torch.no_grad():
        model.canonical.means.add_(0.01 * torch.randn_like(model.canonical.means))
        model.canonical.quats.copy_(torch.randn_like(model.canonical.quats))
        g = model.gaussians_at(0, torch.tensor(observed.wind[0]))
    c = model.canonical
    assert torch.equal(g.means, c.means) and torch.equal(g.quats, c.quats)
    st = model.canonical_state()
    for k in ("scales", "opacities", "colors"):
        assert torch.equal(getattr(g, k), getattr(st, k))


def test_training_lowers_the_loss_and_changes_only_appearance(pair, trained):
    """(e) the recipe trains it like every model (same loop, warm-up, schedule); only canonical
    parameters move, and the trained canonical set is still moved by the same true motion."""
    observed, truth = pair
    res = trained.result
    model = res.model
    assert isinstance(model, TruthMotionModel)
    assert res.log[0]["phase"] == "warmup" and res.log[-1]["phase"] == "deform"
    assert len(res.log) == 30

    def loss(m):
        with torch.no_grad():
            tot = 0.0
            for j in range(N_TRAIN):
                s = m.gaussians_at(j, torch.tensor(observed.wind[0]))
                out = render_state(s, observed.train_camera, observed.background, backend="fast")
                tgt = torch.from_numpy(observed.frames[0, j]).float() / 255
                tot += float(photometric_loss(out.rgb, tgt)[0])
        return tot

    assert loss(model) < 0.9 * loss(trained.before)
    # no parameter outside the canonical set, and the motion buffers are untouched
    assert {n.split(".")[0] for n, _ in model.named_parameters()} == {"canonical"}
    sd0, sd1 = trained.before.state_dict(), model.state_dict()
    assert sd0.keys() == sd1.keys()
    moved = {k for k in sd0 if not torch.equal(sd0[k], sd1[k])}
    assert moved and all(k.startswith("canonical.") for k in moved), moved
    assert {"canonical.color_logits", "canonical.opacity_logits"} <= moved
    # the trained canonical set still follows the truth: drift from the canonical positions
    # is carried along rigidly (oracle: pose_gaussians plus the scipy-rotated drift)
    drift = model.canonical.means.detach().numpy().astype(np.float64) - observed.canonical_xyz
    axis = np.asarray(truth.swing_axis)
    for c, j in [(0, 4), (2, 7)]:
        with torch.no_grad():
            got = model.gaussians_at(j, torch.tensor(observed.wind[c])).means.numpy()
        rot = Rotation.from_rotvec(axis[None] * _dphi(truth, c, j)[:, None])
        want = kinematics.pose_gaussians(truth, truth.theta[c, LEAD_IN + j]) + rot.apply(drift)
        np.testing.assert_allclose(got, want, atol=1e-5, rtol=0)


def test_checkpoint_round_trip_needs_no_truth(pair, trained):
    """(d) load_checkpoint rebuilds it from its own buffers; the evaluation adapters use it as
    any model."""
    observed, truth = pair
    m = load_checkpoint(trained.checkpoint)
    assert isinstance(m, TruthMotionModel) and not m.training
    assert m.checkpoint_info["model"] == "truth_motion"
    assert m.checkpoint_info["models_cfg"] == {"canonical": CANON}
    winds = _winds(observed)
    with torch.no_grad():
        for c, j in [(0, 0), (0, 7), (1, 2), (2, 9)]:
            a, b = trained.result.model.gaussians_at(j, winds[c]), m.gaussians_at(j, winds[c])
            for k in ("means", "quats", "scales", "opacities", "colors"):
                assert torch.equal(getattr(a, k), getattr(b, k)), (c, j, k)
    means = model_means_fn(m, observed)(3, 1)
    drift = m.canonical.means.detach().numpy().astype(np.float64) - observed.canonical_xyz
    rot = Rotation.from_rotvec(np.asarray(truth.swing_axis)[None] * _dphi(truth, 1, 3)[:, None])
    want = kinematics.pose_gaussians(truth, truth.theta[1, LEAD_IN + 3]) + rot.apply(drift)
    np.testing.assert_allclose(means, want, atol=1e-5, rtol=0)
    rgb, alpha = model_render_fn(m, observed, backend="fast")(3, 1, observed.train_camera)
    assert rgb.shape == (RES, RES, 3) and alpha.max() > 0


def test_building_without_truth_names_truth_npz(pair):
    """(f) the reference cannot be built, or fit, without the ground truth."""
    observed, _ = pair
    with pytest.raises(ValueError, match=r"truth\.npz"):
        build_model("truth_motion", observed, {"canonical": CANON})
    with pytest.raises(ValueError, match=r"truth\.npz"):
        fit(observed, job_spec(_cfg(), "truth_motion", "single"), progress=False)


def test_a_wind_of_no_recorded_condition_raises(pair):
    """(g) the condition is found from the wind; an unknown wind is an error, not a guess."""
    observed, truth = pair
    model = _model(pair)
    w = torch.tensor(observed.wind[0])
    with pytest.raises(ValueError, match="matches none of the 3 recorded conditions"):
        model.gaussians_at(2, 0.9 * w)
    with pytest.raises(ValueError, match="columns"):
        model.gaussians_at(2, w[1:])
    # float64 copies of a recorded wind still identify it
    g = model.gaussians_at(2, torch.tensor(observed.wind[2], dtype=torch.float64))
    np.testing.assert_allclose(
        g.means.detach().numpy(),
        kinematics.pose_gaussians(truth, truth.theta[2, LEAD_IN + 2]),
        atol=1e-5,
    )
    assert model.use_wind  # it reads the condition: evaluation must not share frames across them


def test_truth_of_another_dataset_is_refused(pair):
    observed, truth = pair
    other = copy.copy(truth)
    other.theta = truth.theta + 0.1  # a different motion: frame 0 is not the canonical pose
    with pytest.raises(ValueError, match="does not belong"):
        build_model("truth_motion", observed, {"canonical": CANON}, truth=other)
    short = copy.copy(truth)
    short.theta = truth.theta[:, 1:]
    with pytest.raises(ValueError, match="does not belong"):
        build_model("truth_motion", observed, {"canonical": CANON}, truth=short)


def test_registry_keeps_methods_apart_from_the_reference(pair):
    observed, truth = pair
    assert "truth_motion" not in MODEL_NAMES and "truth_motion" in REFERENCES
    assert MODEL_NAMES == ("static", "mlp", "mlp_wind", "d3dgs", "d3dgs_wind", "ours", "ours_chain")
    assert all(m != "truth_motion" for m, _ in training_jobs(["single", "joint32"]))
    assert configs_for("truth_motion", ["single", "joint32"]) == ("single",)
    assert label("truth_motion") == "True motion (ceiling)"
    assert model_settings(_cfg()["models"], "truth_motion") == {"canonical": CANON}
    spec = job_spec(_cfg(), "truth_motion", "single")
    assert spec["model"] == "truth_motion" and spec["K"] is None
    assert spec["conditions"] == "train" and spec["settings"] == {"canonical": CANON}
    with pytest.raises(ValueError, match="not trained in configuration"):
        job_spec(_cfg(), "truth_motion", "joint32")
    # methods never read the truth
    with pytest.raises(ValueError, match="method"):
        build_model("static", observed, {"canonical": CANON}, truth=truth)
    with pytest.raises(ValueError, match="method"):
        fit(observed, job_spec(_cfg(), "static", "single"), truth=truth, progress=False)
    # the motion is fixed: only the canonical groups are optimised, as for the static model
    m = _model(pair)
    static = build_model("static", observed, {"canonical": CANON})
    g_ref, g_static = m.param_groups(LR), static.param_groups(LR)
    assert [(g["name"], g["lr"]) for g in g_ref] == [(g["name"], g["lr"]) for g in g_static]
