"""Testbed statistics: the order leak, distinct frequencies, the nearest-bone gap and the visible
motion against hand-computable cases; the stored Gaussian order carries no bone label."""

from types import SimpleNamespace

import numpy as np
import pytest

from physgs.camera import look_at
from physgs.config import load
from physgs.testbed.stats import nearest_bone_gap
from physgs.testbed import stats
from physgs.testbed.dataset import load_observed, load_truth, simulate_tree
from oracles import simulate_trees, tiny_testbed

CFG = load("config/trees.yaml", "default")


# --------------------------------------------------------------------------------------------
# Order leak


def test_neighbour_share_by_hand():
    assert stats.neighbour_bone_share([0, 0, 1, 1, 2]) == pytest.approx(2 / 4)
    assert stats.neighbour_bone_share([3, 3, 3]) == 1.0
    assert stats.neighbour_bone_share([0, 1, 0, 1]) == 0.0
    assert np.isnan(stats.neighbour_bone_share([5]))


def test_expected_share_is_the_mean_over_random_orders():
    labels = np.repeat([0, 1, 2, 3], [50, 30, 15, 5])
    n, N = np.array([50, 30, 15, 5]), 100
    p = (n * (n - 1)).sum() / (N * (N - 1))
    assert stats.expected_neighbour_share(labels) == pytest.approx(p, rel=1e-12)
    rng = np.random.default_rng(0)
    mc = np.mean([stats.neighbour_bone_share(rng.permutation(labels)) for _ in range(4000)])
    assert mc == pytest.approx(p, abs=4 * np.sqrt(p * (1 - p) / (N - 1) / 4000) + 1e-3)


@pytest.fixture(scope="module")
def sims():
    return simulate_trees(CFG)


def test_stored_gaussian_order_carries_no_bone_label(sims):
    for t, s in sims.items():
        tr = s.truth
        vb = np.asarray(tr.vertex_bone)
        N = vb.size
        gv = np.asarray(tr.gaussian_vertex)
        np.testing.assert_array_equal(np.sort(gv), np.arange(N))  # a permutation
        np.testing.assert_array_equal(gv[tr.vertex_gaussian], np.arange(N))  # with its inverse
        # expectation under a random order, computed here from the bone sizes
        n = np.bincount(vb).astype(float)
        p = (n * (n - 1)).sum() / (N * (N - 1.0))
        se = np.sqrt(p * (1 - p) / (N - 1))
        share = stats.neighbour_bone_share(vb[gv])  # bone labels in stored Gaussian order
        assert abs(share - p) <= 4 * se + 1e-12, (t, share, p, se)
        # control: mesh order groups vertices by bone, far above chance (the test has power)
        assert stats.neighbour_bone_share(vb) > p + 50 * se, t


def test_permutation_is_seeded_and_its_own_stream():
    tb, pre = CFG["testbed"], CFG["presets"]["sparse"]
    a = simulate_tree(tb, pre, seed=0, tree="sparse").truth
    b = simulate_tree(tb, pre, seed=0, tree="sparse").truth
    c = simulate_tree(tb, pre, seed=1, tree="sparse").truth
    np.testing.assert_array_equal(a.gaussian_vertex, b.gaussian_vertex)
    assert not np.array_equal(a.gaussian_vertex, c.gaussian_vertex)
    assert not np.array_equal(a.gaussian_vertex, np.arange(a.gaussian_vertex.size))


# --------------------------------------------------------------------------------------------
# Frequencies


def test_distinct_count_with_exact_and_near_duplicates():
    om = np.array([2.0, 3.0, 2.0, 3.0 * (1 + 1e-12), 5.0, 5.0 * (1 + 1e-6)])
    assert stats.distinct_count(om) == 4  # 2, 3 (with its round-off twin), 5, 5.000005
    assert stats.distinct_count(om, rtol=1e-5) == 3
    assert stats.distinct_count(np.array([1.0])) == 1


def test_median_gap_two_bones_closed_form():
    # bones at 1 and 2, omega log-uniform on [1, 2]: gap = min(x - 1, (2 - x) / 2), whose CDF is
    # ln((1 + g) / (1 - g)) / ln 2, so the median is (sqrt 2 - 1) / (sqrt 2 + 1)
    g = stats.median_nearest_bone_gap(np.array([1.0, 2.0, 2.0]))
    assert g == pytest.approx((np.sqrt(2) - 1) / (np.sqrt(2) + 1), abs=1e-5)


def test_median_gap_is_the_null_controls_gap(sims):
    om = sims["medium"].truth.omega
    rng = np.random.default_rng(1)
    draws = np.exp(rng.uniform(np.log(om.min()), np.log(om.max()), 200_000))
    mc = np.median(nearest_bone_gap(draws, om))
    assert stats.median_nearest_bone_gap(om) == pytest.approx(mc, rel=0.02)


# --------------------------------------------------------------------------------------------
# Visible motion


def _toy(theta_window):
    """Bone 0: vertical, (0,0,0)->(0,0,1); bone 1: horizontal child, (0,0,1)->(L,0,1); bone 2: a
    child of 1 without vertices. Swing axis along the camera's viewing axis (+y), so every motion
    stays in the image plane at depth Z: pixel displacement = fx * world displacement / Z."""
    Lb = 0.8
    head = np.array([[0, 0, 0], [0, 0, 1], [Lb, 0, 1.0]])
    tail = np.array([[0, 0, 1], [Lb, 0, 1], [Lb + 0.1, 0, 1.0]])
    rest = np.array([[0.0, 0, 0.5], [0, 0, 1], [Lb / 2, 0, 1], [Lb, 0, 1]])
    th = np.asarray(theta_window, float)
    truth = SimpleNamespace(
        bone_head=head,
        bone_tail=tail,
        bone_parent=np.array([-1, 0, 1]),
        swing_axis=np.array([0.0, 1.0, 0.0]),
        rest_vertices=rest,
        vertex_bone=np.array([0, 0, 1, 1]),
        lead_in_frames=2,
        theta=np.concatenate([np.zeros((1, 2, 3)), th[None]], axis=1),
    )
    return truth, Lb


def test_visible_motion_of_a_horizontal_bone_by_hand():
    Z = 10.0
    cam = look_at((0, -Z, 0.5), (0, 0, 0.5), fov_deg=40, width=128, height=128)
    t = np.linspace(0, 2 * np.pi, 50)
    th = np.stack([0.02 * np.sin(t), 0.05 * np.cos(t) + 0.01, 0.3 * np.sin(t)], 1)  # [T, B]
    truth, Lb = _toy(th)
    vis = stats.visible_motion_px(truth, cam, n_train=len(t))
    d1 = th[:, 1].max() - th[:, 1].min()
    d0 = th[:, 0].max() - th[:, 0].min()
    # bone 1 rotates its tip (L from its head) through d1: chord 2 L sin(d1 / 2), fx L sin... / Z
    assert vis[1] == pytest.approx(cam.fx * 2 * Lb * np.sin(d1 / 2) / Z, rel=1e-9)
    # bone 0 carries the whole tree; its farthest vertex is the tip, sqrt(L^2 + 1) from its head
    assert vis[0] == pytest.approx(cam.fx * 2 * np.hypot(Lb, 1) * np.sin(d0 / 2) / Z, rel=1e-9)
    assert vis[2] == 0.0  # no vertex: nothing to see
    # the familiar small-angle form: theta in [-a, a] moves the tip by about fx 2 L a / Z
    a = 0.01
    vis_a = stats.visible_motion_px(
        _toy(np.stack([0 * t, a * np.sin(t), 0 * t], 1))[0], cam, len(t)
    )
    assert vis_a[1] == pytest.approx(cam.fx * 2 * Lb * np.sin(a * np.sin(t).max()) / Z, rel=1e-9)
    assert vis_a[1] == pytest.approx(cam.fx * 2 * Lb * a / Z, rel=1e-3)


def test_visible_motion_is_the_largest_excursion_over_frame_pairs():
    # brute force: every pair of frames, bone alone, perspective camera off-axis
    cam = look_at((3.0, -6.0, 1.5), (0, 0, 0.7), fov_deg=40, width=96, height=96)
    rng = np.random.default_rng(2)
    th = rng.normal(0, 0.05, (12, 3))
    truth, _ = _toy(th)
    truth.swing_axis = np.array([np.sqrt(0.5), np.sqrt(0.5), 0.0])
    vis = stats.visible_motion_px(truth, cam, n_train=12)
    for b in range(2):
        best = 0.0
        for i in range(12):
            for j in range(12):
                ta, tb = np.zeros(3), np.zeros(3)
                ta[b], tb[b] = th[i, b], th[j, b]
                best = max(best, stats.subtree_excursion_px(truth, cam, ta, tb)[b])
        assert vis[b] == pytest.approx(best, rel=2e-3)


def test_swing_is_rms_of_own_angle():
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    truth, _ = _toy(np.stack([0.1 * np.sin(t), 0 * t, 0.02 + 0 * t], 1))
    sw = stats.bone_swing_deg(truth, n_train=400)
    np.testing.assert_allclose(sw, np.degrees([0.1 / np.sqrt(2), 0.0, 0.02]), rtol=1e-9)


# --------------------------------------------------------------------------------------------
# Everything, on a tiny built dataset


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    tb, d = tiny_testbed(tmp_path_factory.mktemp("tbstats"), resolution=24, fill_height=0.8)
    return tb, load_observed(d / "observed.npz"), load_truth(d / "truth.npz")


def test_testbed_stats_fields(tiny):
    tb, o, t = tiny
    s = stats.testbed_stats(o, t)
    B = t.omega.size
    assert s["bones"] == B == 22
    assert s["distinct_frequencies"] == 22  # clone variation: no exact clones
    assert s["f_min_hz"] <= s["f_median_hz"] <= s["f_max_hz"]
    assert s["f_span"] == pytest.approx(s["f_max_hz"] / s["f_min_hz"])
    assert s["clamped"] == int(t.omega_clamped.sum())
    assert s["visible_px"].shape == s["swing_deg"].shape == s["visible"].shape == (B,)
    np.testing.assert_array_equal(s["visible"], s["visible_px"] >= 1.0)
    assert s["visible_below_px_fraction"] == pytest.approx(np.mean(s["visible_px"] < 1.0))
    assert s["height_fill"] == pytest.approx(tb["fill_height"], abs=1e-6)  # framed exactly
    assert 0 < s["width_fill"] < 1 and 0 < s["coverage"] < 1
    assert s["coverage"] == pytest.approx(o.masks[0, :20].mean())
    assert s["mesh_order_share"] > 0.8 and s["order_share"] < 3 * s["order_share_random"]


def test_displacement_energy_below_splits_two_tones_by_their_amplitudes():
    """Oracle: two sinusoids on exact rFFT bins (1 Hz, amplitude 1; 3 Hz, amplitude 2) carry
    energies in the ratio 1 : 4, so a cutoff between them keeps 1/5 of the energy."""
    from physgs.testbed.stats import displacement_energy_below

    fps, T = 24.0, 240
    t = np.arange(T) / fps
    x = np.zeros((T, 2, 3))
    x[:, 0, 0] = np.sin(2 * np.pi * 1.0 * t)
    x[:, 1, 2] = 2.0 * np.cos(2 * np.pi * 3.0 * t) + 5.0  # the offset is removed
    share = displacement_energy_below(x, fps, [0.5, 2.0, 3.0, 12.0])
    np.testing.assert_allclose(share, [0.0, 0.2, 1.0, 1.0], atol=1e-12)
    with pytest.raises(ValueError, match="do not move"):
        displacement_energy_below(np.ones((T, 2, 3)), fps, [1.0])


def test_time_band_top_matches_the_encodings_fastest_sine():
    """The encoding's top feature sin(2^(b-1) pi t) completes 2^(b-1)/2 cycles over t in [0, 1]:
    count its zero crossings over the window and convert to Hz."""
    import torch
    from physgs.models.encoding import fourier
    from physgs.testbed.stats import time_band_top_hz

    n, fps, bands = 300, 24.0, 4
    t = torch.linspace(0, 1, 20001)[:, None].double()
    top = fourier(t, bands)[:, 1 + 2 * (bands - 1)]  # [x, (sin, cos) per band]: the last sine
    crossings = int((np.diff(np.sign(top.numpy()[1:-1])) != 0).sum())  # 2 per cycle
    assert time_band_top_hz(bands, n, fps) == pytest.approx(
        (crossings + 1) / 2 / ((n - 1) / fps), rel=1e-9
    )
