"""The chained prior (physgs.models.chain, ours_chain): forward kinematics against independent
oracles (a two-link arm by hand and by scipy Rotation, the testbed's own skinning), exact
gradients (gradcheck in float64, and against a pure-torch composition of single rotations),
registry wiring and recovery reading each part's own angle."""

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from physgs.models import build_model, load_checkpoint, save_checkpoint
from physgs.models.chain import chain_deform, chain_deform_from, depth_levels
from physgs.models.gaussians import rotate_about_pivot
from physgs.models.registry import (
    MODEL_NAMES,
    configs_for,
    model_settings,
    spec_of,
    training_jobs,
)
from physgs.testbed.kinematics import pose_points
from oracles import model_context, quick_config, quick_models_cfg

ID_Q = torch.tensor([[1.0, 0.0, 0.0, 0.0]], dtype=torch.float64)


def t64(x):
    return torch.tensor(np.asarray(x, dtype=np.float64))


def test_two_link_arm_by_hand():
    # link 0 pivots at the origin, link 1 at (1, 0, 0), both about z; the tip (2, 0, 0) of link 1
    # lands at (cos a + cos(a + b), sin a + sin(a + b), 0)
    a, b = 0.3, -0.7
    means = t64([[2.0, 0.0, 0.0], [0.5, 0.0, 0.0]])
    labels = torch.tensor([1, 0])
    axis = t64([[0, 0, 1], [0, 0, 1]])
    pivot = t64([[0, 0, 0], [1, 0, 0]])
    m, _ = chain_deform(
        means, ID_Q.expand(2, 4), labels, axis, t64([a, b]), pivot, depth_levels([-1, 0])
    )
    tip = [np.cos(a) + np.cos(a + b), np.sin(a) + np.sin(a + b), 0.0]
    assert np.allclose(m[0].numpy(), tip, atol=1e-14)
    assert np.allclose(m[1].numpy(), [0.5 * np.cos(a), 0.5 * np.sin(a), 0.0], atol=1e-14)


def test_three_links_with_own_axes_match_scipy_rotations():
    rng = np.random.default_rng(0)
    axis = rng.normal(size=(3, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    theta = rng.uniform(-0.8, 0.8, 3)
    pivot = rng.normal(size=(3, 3))
    x = rng.normal(size=(3, 3))  # one point per part of the chain 0 <- 1 <- 2
    R = [Rotation.from_rotvec(axis[p] * theta[p]) for p in range(3)]

    def rot(p, y):  # rotation by theta_p about axis_p through the canonical pivot c_p
        return pivot[p] + R[p].apply(y - pivot[p])

    oracle = np.array([rot(0, x[0]), rot(0, rot(1, x[1])), rot(0, rot(1, rot(2, x[2])))])
    q = torch.tensor(rng.normal(size=(3, 4)))
    m, qn = chain_deform(
        t64(x), q, torch.arange(3), t64(axis), t64(theta), t64(pivot), depth_levels([-1, 0, 1])
    )
    assert np.allclose(m.numpy(), oracle, atol=1e-12)
    # orientation: world rotation R0 R1 R2 applied to the Gaussian's own quaternion
    Rw = R[0] * R[1] * R[2]
    own = Rotation.from_quat(q[2].numpy()[[1, 2, 3, 0]])  # scipy: scalar last
    want = (Rw * own).as_quat()[[3, 0, 1, 2]]
    got = qn[2].numpy() / np.linalg.norm(qn[2].numpy())
    assert np.allclose(got, want, atol=1e-12) or np.allclose(got, -want, atol=1e-12)


def test_matches_the_testbeds_own_skinning():
    # a random bone tree, parents numbered first, every bone about the tree's one swing axis:
    # parts = bones, pivots = bone heads, so the chained prior must pose exactly as the testbed
    rng = np.random.default_rng(1)
    B = 9
    parent = np.array([-1] + [int(rng.integers(0, b)) for b in range(1, B)])
    head = rng.normal(size=(B, 3))
    tail = head + rng.normal(size=(B, 3))
    bone = rng.integers(0, B, 50)
    pts = rng.normal(size=(50, 3))
    axis = np.array([0.6, -0.8, 0.0])
    theta = rng.uniform(-0.4, 0.4, B)
    oracle = pose_points(pts, bone, head, tail, parent, axis, theta)
    m, _ = chain_deform(
        t64(pts),
        ID_Q.expand(50, 4),
        torch.tensor(bone),
        t64(np.tile(axis, (B, 1))),
        t64(theta),
        t64(head),
        depth_levels(parent),
    )
    assert np.allclose(m.numpy(), oracle, atol=1e-12)


def _reference(means, quats, labels, axis, theta, pivot, parent):
    """Pure torch, no accumulated matrices: each Gaussian rotated by its own part about that
    part's canonical pivot, then by each ancestor in turn, up to the root."""
    out_m, out_q = [], []
    for i in range(means.shape[0]):
        m, q, p = means[i : i + 1], quats[i : i + 1], int(labels[i])
        while p >= 0:
            m, q = rotate_about_pivot(m, q, axis[p : p + 1], theta[p : p + 1], pivot[p : p + 1])
            p = int(parent[p])
        out_m.append(m)
        out_q.append(q)
    return torch.cat(out_m), torch.cat(out_q)


def _random_chain(seed, K=5, N=12):
    rng = np.random.default_rng(seed)
    parent = np.array([-1] + [int(rng.integers(0, p)) for p in range(1, K)])
    axis = rng.normal(size=(K, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    args = [
        t64(rng.normal(size=(N, 3))).requires_grad_(),  # means
        t64(rng.normal(size=(N, 4))).requires_grad_(),  # quats
        t64(axis).requires_grad_(),
        t64(rng.uniform(-1, 1, K)).requires_grad_(),  # theta
        t64(rng.normal(size=(K, 3))).requires_grad_(),  # pivot
    ]
    return parent, torch.tensor(rng.integers(0, K, N)), args


def test_values_and_gradients_match_the_pure_torch_reference():
    parent, labels, (m, q, a, th, pv) = _random_chain(2)
    levels = depth_levels(parent)
    w = torch.randn(12, 7, dtype=torch.float64, generator=torch.Generator().manual_seed(0))
    outs, grads = [], []
    for f in (
        lambda: chain_deform(m, q, labels, a, th, pv, levels),
        lambda: _reference(m, q, labels, a, th, pv, parent),
    ):
        nm, nq = f()
        outs.append(torch.cat([nm, nq], 1).detach())
        grads.append(torch.autograd.grad((torch.cat([nm, nq], 1) * w).sum(), [m, q, a, th, pv]))
    assert torch.allclose(outs[0], outs[1], atol=1e-12)
    for g0, g1 in zip(*grads):
        assert torch.allclose(g0, g1, atol=1e-11)


def test_gradcheck_float64():
    parent, labels, args = _random_chain(3, K=4, N=6)
    levels = depth_levels(parent)

    def f(m, q, a, th, pv):
        return chain_deform(m, q, labels, a, th, pv, levels)

    assert torch.autograd.gradcheck(f, tuple(args), eps=1e-6, atol=1e-7, rtol=1e-5)


def test_zero_angles_leave_the_gaussians_exactly_in_place():
    parent, labels, (m, q, a, th, pv) = _random_chain(4)
    nm, nq = chain_deform(m, q, labels, a, torch.zeros_like(th), pv, depth_levels(parent))
    assert torch.equal(nm, m) and torch.equal(nq, q)


# -- the model ------------------------------------------------------------------------------------


def test_registry_variants_train_like_ours_but_stay_out_of_the_tables():
    cfg = quick_models_cfg()
    # the chained prior is a method of every table; the topology variant a study's
    assert "ours_chain" in MODEL_NAMES and "ours_topo" not in MODEL_NAMES
    assert all(m in MODEL_NAMES for m, _ in training_jobs(cfg["configs"]))
    assert spec_of("ours_chain").chain and spec_of("ours_topo").parts == "topology"
    assert configs_for("ours_chain", cfg["configs"]) == tuple(cfg["configs"])
    assert model_settings(cfg, "ours_chain")["topology"] == cfg["topology"]
    assert "topology" not in model_settings(cfg, "ours")  # ours' jobs do not rerun on its edit


def test_chained_model_poses_by_its_parts_and_reloads(tmp_path):
    ctx, wind = model_context(300, seed=5, lead_in=40)
    cfg = quick_models_cfg()
    cfg["omega_search"][
        "models"
    ] = []  # the oscillators from the start (the bank: test_omega_search)
    model = build_model("ours_chain", ctx, cfg, K=6)
    assert model.chain and model.part_parent[0] == -1
    with torch.no_grad():
        model.gain_raw.copy_(torch.linspace(-0.5, 0.5, 6))
    theta_all = model.part_theta(torch.as_tensor(wind))  # [K, L+F] own angles
    # recovery reads part_theta: each part's OWN oscillator response, not the sum along its chain
    from physgs.models.oscillator import integrate

    vbar = model.vbar_ratio * float(np.mean(wind))
    own = integrate(model.omega, model.zeta, model.gain, wind, vbar, model.dt, model.substeps)
    assert torch.allclose(theta_all, own)
    st = model.deform(10, torch.as_tensor(wind))
    c = model.canonical
    ref_m, _ = _reference(
        c.means.double(),
        c.quats.double(),
        model.part_labels,
        model.axis.double(),
        theta_all[:, model.lead_in + 10].double(),
        model.pivot.double(),
        model.part_parent.numpy(),
    )
    assert torch.allclose(st.means.double(), ref_m, atol=1e-5)
    assert not torch.allclose(st.means, c.means)  # it moved
    path = tmp_path / "m.pt"
    save_checkpoint(
        path,
        model,
        name="ours_chain",
        config="single",
        seed=0,
        models_cfg=cfg,
        train_cfg={},
        stats={},
    )
    back = load_checkpoint(path)
    assert torch.equal(back.part_parent, model.part_parent)
    assert torch.equal(back.deform(10, torch.as_tensor(wind)).means, st.means)


def test_chain_needs_topology_parts():
    ctx, _ = model_context(100, seed=6, lead_in=10)
    from physgs.models.ours import OscillatorPrior

    o = quick_models_cfg()["ours"]
    kw = {k: o[k] for k in ("omega_hz", "zeta", "omega_init_hz", "zeta_init", "substeps")}
    with pytest.raises(ValueError, match="topology parts"):
        OscillatorPrior(ctx, quick_models_cfg()["canonical"], K=3, chain=True, **kw)


def test_chained_swing_counts_the_descendants(swaying):
    # a chained part's own rotation carries its descendants: its image swing is theirs too
    from physgs.models.visibility import part_image_swing

    cfg = quick_models_cfg()
    model = build_model("ours_chain", swaying, cfg, K=4)
    swing = part_image_swing(model, swaying, probe_rad=0.05)
    xyz = swaying.canonical_xyz.astype(np.float64)
    lab = model.part_labels.numpy()
    parent = model.part_parent.numpy()
    uv0, _ = swaying.train_camera.project(xyz)

    def ancestors_or_self(q):
        out = set()
        while q >= 0:
            out.add(q)
            q = int(parent[q])
        return out

    for p in range(4):
        moved = np.array([p in ancestors_or_self(int(q)) for q in lab])  # p or below
        ax = model.axis[p].detach().double().numpy()
        c = model.pivot[p].detach().double().numpy()
        best = 0.0
        for a in (0.05, -0.05):
            R = Rotation.from_rotvec(a * ax).as_matrix()
            uv, _ = swaying.train_camera.project((xyz[moved] - c) @ R.T + c)
            best = max(best, np.linalg.norm(uv - uv0[moved], axis=1).max())
        assert swing[p] == pytest.approx(best, rel=1e-6)
        assert moved.sum() >= (lab == p).sum()


def test_from_frame0_undoes_frame_0s_chained_transform_as_scipy_rotations_do():
    # the canonical points are the pose at angles theta0: their rest pose is T(theta0)^-1 of
    # them, then T(theta) moves them; built here from scipy rotations, point by point
    rng = np.random.default_rng(3)
    axis = rng.normal(size=(3, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    theta, theta0 = rng.uniform(-0.6, 0.6, 3), rng.uniform(-0.6, 0.6, 3)
    pivot = rng.normal(size=(3, 3))
    x = rng.normal(size=(3, 3))  # one point per part of the chain 0 <- 1 <- 2

    def world(th):  # [(rotation, translation)] of each part's chained map x -> R x + t
        out = []
        for p in range(3):
            R = Rotation.from_rotvec(axis[p] * th[p])
            own = (R, pivot[p] - R.apply(pivot[p]))
            if p:
                Rq, tq = out[p - 1]
                own = (Rq * own[0], Rq.apply(own[1]) + tq)
            out.append(own)
        return out

    now, then = world(theta), world(theta0)
    oracle = np.array(
        [now[p][0].apply(then[p][0].inv().apply(x[p] - then[p][1])) + now[p][1] for p in range(3)]
    )
    q = torch.tensor(rng.normal(size=(3, 4)))
    args = (t64(x), q, torch.arange(3), t64(axis))
    lv = depth_levels([-1, 0, 1])
    m, qn = chain_deform_from(*args, t64(theta), t64(theta0), t64(pivot), lv)
    assert np.allclose(m.numpy(), oracle, atol=1e-12)
    own = Rotation.from_quat(q[2].numpy()[[1, 2, 3, 0]])
    want = (now[2][0] * then[2][0].inv() * own).as_quat()[[3, 0, 1, 2]]
    got = qn[2].numpy() / np.linalg.norm(qn[2].numpy())
    assert np.allclose(got, want, atol=1e-12) or np.allclose(got, -want, atol=1e-12)
    # not the turn by the angles' differences: the two differ beyond first order
    diff, _ = chain_deform(*args, t64(theta - theta0), t64(pivot), lv)
    assert not np.allclose(diff.numpy(), oracle, atol=1e-3)
    same, _ = chain_deform_from(*args, t64(theta0), t64(theta0), t64(pivot), lv)
    assert np.allclose(same.numpy(), x, atol=1e-14)


@pytest.mark.parametrize("pose", ["frame0", "frame0_angles"])
def test_frame0_poses_put_frame_0_on_the_canonical_set(pose):
    # the canonical Gaussians are the pose at recorded frame 0: in either frame-0 pose frame 0
    # is exactly there, and frame j moves by the chained transforms from frame 0's angles
    ctx, wind = model_context(200, seed=6, lead_in=40)
    cfg = quick_models_cfg()
    cfg["omega_search"]["models"] = []
    cfg["topology"]["canonical_pose"] = pose
    model = build_model("ours_chain", ctx, cfg, K=5)
    with torch.no_grad():
        model.gain_raw.copy_(torch.linspace(-0.6, 0.6, 5))
    w = torch.as_tensor(wind)
    theta = model.part_theta(w)  # [K, L+F]
    th0, th7 = theta[:, model.lead_in], theta[:, model.lead_in + 7]
    assert th0.abs().max() > 1e-3  # the oscillators are not at rest there
    c = model.canonical
    assert torch.allclose(model.deform(0, w).means, c.means, atol=1e-6)
    st = model.deform(7, w)
    args = (c.means, c.quats, model.part_labels, model.axis)
    if pose == "frame0":
        ref, _ = chain_deform_from(*args, th7, th0, model.pivot, model.levels)
    else:
        ref, _ = chain_deform(*args, th7 - th0, model.pivot, model.levels)
    assert torch.allclose(st.means, ref, atol=1e-6)
    cfg["topology"]["canonical_pose"] = "rest"  # frame 0 is turned by theta(frame 0)
    absolute = build_model("ours_chain", ctx, cfg, K=5)
    with torch.no_grad():
        absolute.gain_raw.copy_(torch.linspace(-0.6, 0.6, 5))
    assert not torch.allclose(absolute.deform(0, w).means, absolute.canonical.means, atol=1e-4)


def test_frame0_offset_turns_the_rest_pose_by_a_learned_angle():
    # frame0_offset: the rest pose is frame 0's transform at theta(frame 0) + offset undone, so
    # at offset 0 it is frame0, and otherwise frame 0 sits at T(theta0) T(theta0 + offset)^-1
    ctx, wind = model_context(200, seed=6, lead_in=40)
    cfg = quick_models_cfg()
    cfg["omega_search"]["models"] = []
    cfg["topology"]["canonical_pose"] = "frame0_offset"
    model = build_model("ours_chain", ctx, cfg, K=5)
    with torch.no_grad():
        model.gain_raw.copy_(torch.linspace(-0.6, 0.6, 5))
    w = torch.as_tensor(wind)
    c = model.canonical
    assert torch.allclose(model.deform(0, w).means, c.means, atol=1e-6)
    offset = torch.tensor([0.1, -0.2, 0.0, 0.05, 0.3])
    with torch.no_grad():
        model.pose_offset.copy_(offset)
    th0 = model.part_theta(w)[:, model.lead_in]
    args = (c.means, c.quats, model.part_labels, model.axis)
    ref, _ = chain_deform_from(*args, th0, th0 + offset, model.pivot, model.levels)
    got = model.deform(0, w).means
    assert torch.allclose(got, ref, atol=1e-6)
    assert not torch.allclose(got, c.means, atol=1e-3)
    lr = quick_config()["train"]["lr"]
    trained = {id(p) for g in model.param_groups(lr) for p in g["params"]}
    assert id(model.pose_offset) in trained
    got.sum().backward()
    assert model.pose_offset.grad.abs().max() > 0


def test_canonical_pose_is_validated_and_old_checkpoints_keep_theirs():
    import physgs.config
    from physgs.models.families import canonical_pose_of

    with pytest.raises(physgs.config.ConfigError, match="canonical_pose"):
        physgs.config.apply_overrides(quick_config(), ["models.topology.canonical_pose=frame1"])
    assert canonical_pose_of({"knn": 10}) == "rest"
    assert canonical_pose_of({"knn": 10, "from_frame0": True}) == "frame0_angles"
    assert canonical_pose_of({"knn": 10, "canonical_pose": "frame0"}) == "frame0"
