"""The damping testbed variant (physgs.testbed.variant): per-bone zeta, a gust dropping to calm
inside the training window, free decays against the closed form; the faithful variant unchanged.

Physics only (simulate_tree, no rendering), on the quick profile's sparse tree with a 10 s
training window (240 frames at 24 fps) holding the gust (2-3 s) and a 5 s calm (3-8 s).
"""

import copy

import numpy as np
import pytest
import scipy.stats

from physgs.config import load
from physgs.testbed import kinematics, physics, variant
from physgs.testbed.dataset import Truth, load_truth, save_dataset, simulate_tree

CFG = load("config/trees.yaml", "quick")
PRESET = CFG["presets"]["sparse"]
N_TRAIN, FPS = 240, 24
START_S, CALM_S = 3.0, 5.0
#: a deliberate transient: every bone's free-decay amplitude at the calm start is at least this
#: fraction of its RMS angle over the training window (measured: 1.0 to 2.9 on this tree)
MIN_CALM_START_AMPLITUDE = 0.5
#: the closed-form free decay reproduces the simulator to this fraction of the bone's amplitude
#: (float64 step matrices; round-off of order 1e-14 per step, amplified by fitting B from a step)
FREE_DECAY_RTOL = 1e-9


def _tb(variant_name="damping", **over):
    tb = copy.deepcopy(CFG["testbed"])
    tb.update(n_train=N_TRAIN, n_tail=12, variant=variant_name, **over)
    tb["damping"]["transient"].update(start_s=START_S, calm_s=CALM_S)
    return tb


def _sim(tb, seed=0):
    return simulate_tree(tb, PRESET, seed=seed, tree="sparse")


@pytest.fixture(scope="module")
def damped():
    return _sim(_tb())


def _arrays(sim):
    return {**{k: getattr(sim.truth, k) for k in Truth.__dataclass_fields__}, "wind": sim.wind}


# --- faithful: today's testbed, unchanged -------------------------------------------------------


def test_faithful_variant_is_the_default_code_path():
    """variant: faithful, and no variant keys at all, build the same arrays bit for bit: one zeta
    for every bone, the lead-in from omega_min, the unmodified wind."""
    tb = _tb("faithful")
    legacy = {k: v for k, v in tb.items() if k not in ("variant", "damping")}
    sim = _sim(tb)
    a, b = _arrays(sim), _arrays(_sim(legacy))
    assert a.keys() == b.keys()
    for k in a:
        assert np.array_equal(a[k], b[k]) and np.asarray(a[k]).dtype == np.asarray(b[k]).dtype, k
    tr = sim.truth
    np.testing.assert_array_equal(tr.zeta, np.full(len(tr.omega), tb["zeta"]))
    assert tr.lead_in_frames == physics.lead_in_frames(
        tr.omega.min(), tb["zeta"], tb["lead_in_tau"], FPS
    )
    # the damping block is not read by the faithful variant
    odd = copy.deepcopy(tb)
    odd["damping"]["zeta_range"] = [0.5, 0.9]
    odd["damping"]["transient"]["start_s"] = 1.5
    assert all(np.array_equal(v, _arrays(_sim(odd))[k]) for k, v in a.items())
    assert variant.effective_settings(odd) == legacy


def test_the_zeta_stream_changes_nothing_else_in_the_tree(damped):
    """Same seed: geometry, frequencies, mesh and Gaussian order equal the faithful tree's."""
    f = _sim(_tb("faithful")).truth
    d = damped.truth
    for k in (
        "omega",
        "bone_head",
        "bone_tail",
        "bone_parent",
        "rest_vertices",
        "faces",
        "vertex_bone",
        "vertex_colors",
        "gaussian_vertex",
        "omega_clamped",
        "tip_vertices",
    ):
        np.testing.assert_array_equal(getattr(f, k), getattr(d, k), err_msg=k)
    # the wind before the gust is the same realisation, bit for bit (the lead-ins differ)
    L_f, L_d = f.lead_in_frames, d.lead_in_frames
    m = min(L_f, L_d)
    j_gust = int(round((START_S - CFG["testbed"]["damping"]["transient"]["gust_s"]) * FPS))
    sf = _sim(_tb("faithful"))
    np.testing.assert_array_equal(
        sf.wind[:, L_f - m : L_f + j_gust + 1], damped.wind[:, L_d - m : L_d + j_gust + 1]
    )
    assert not np.array_equal(sf.wind[:, L_f + j_gust + 1], damped.wind[:, L_d + j_gust + 1])


# --- damping: zeta per bone -----------------------------------------------------------------


def test_zeta_per_bone_is_log_uniform_in_range_and_seeded(damped):
    lo, hi = CFG["testbed"]["damping"]["zeta_range"]
    z = damped.truth.zeta
    assert z.shape == damped.truth.omega.shape
    assert (z >= lo).all() and (z <= hi).all()
    # log-spread, not a constant: the log std of a log-uniform draw is log(hi/lo)/sqrt(12)
    assert np.std(np.log(z)) > 0.5 * np.log(hi / lo) / np.sqrt(12)
    u = np.log(z / lo) / np.log(hi / lo)
    assert scipy.stats.kstest(u, "uniform").pvalue > 0.01
    np.testing.assert_array_equal(_sim(_tb()).truth.zeta, z)  # reproducible
    other = _sim(_tb(), seed=1).truth.zeta
    assert not np.allclose(other[:5], z[:5])


def test_zeta_draw_is_log_uniform_against_its_quantiles():
    """draw_zeta alone: 20000 draws, the empirical CDF of log zeta against the uniform's."""
    z = variant.draw_zeta([0.03, 0.2], 20000, np.random.SeedSequence(4))
    u = np.log(z / 0.03) / np.log(0.2 / 0.03)
    np.testing.assert_allclose(
        np.quantile(u, [0.1, 0.25, 0.5, 0.75, 0.9]), [0.1, 0.25, 0.5, 0.75, 0.9], atol=0.015
    )
    with pytest.raises(ValueError, match="zeta_range"):
        variant.draw_zeta([0.2, 0.03], 3, np.random.SeedSequence(0))


def test_lead_in_uses_the_slowest_decay_rate(damped):
    tr = damped.truth
    rate = (tr.zeta * tr.omega).min()
    assert tr.lead_in_frames == int(np.ceil(CFG["testbed"]["lead_in_tau"] / rate * FPS))
    # slower than omega_min at the median zeta would give
    assert tr.lead_in_frames > physics.lead_in_frames(
        tr.omega.min(), np.median(tr.zeta), CFG["testbed"]["lead_in_tau"], FPS
    )


def test_truth_file_keeps_zeta_per_bone(damped, tmp_path):
    truth = {k: getattr(damped.truth, k) for k in Truth.__dataclass_fields__}
    truth["format_version"] = 2
    save_dataset({"unused": np.zeros(1)}, truth, tmp_path / "o.npz", tmp_path / "t.npz")
    np.testing.assert_array_equal(load_truth(tmp_path / "t.npz").zeta, damped.truth.zeta)


# --- damping: the gust dropping to calm ------------------------------------------------------


def test_calm_window_has_no_forcing_and_the_wind_is_shared_by_every_condition(damped):
    tr, L = damped.truth, damped.truth.lead_in_frames
    j0, j1 = variant.calm_frames(variant.transient_of(_tb()), FPS)
    assert (j0, j1) == (START_S * FPS, (START_S + CALM_S) * FPS + 1)
    assert j1 <= N_TRAIN  # inside the recorded training window
    v0 = CFG["testbed"]["wind"]["v0"]
    np.testing.assert_array_equal(damped.wind[0, L + j0 : L + j1], v0)  # exactly the mean speed
    u = physics.drag_forcing(damped.wind.astype(np.float64), tr.vbar)  # [C, L+F]
    assert np.abs(u[:, L + j0 : L + j1]).max() < 1e-6 * np.abs(u).max()
    # turbulence before the gust and after the ramp back, and a gust above the mean
    assert np.std(u[0, L : L + j0 - FPS]) > 0.1 * np.abs(u).max()
    assert np.std(u[0, L + j1 + FPS : L + N_TRAIN]) > 0.1 * np.abs(u).max()
    gust = damped.wind[0, L + j0 - FPS : L + j0]
    assert gust.max() > v0 * 1.2
    # the observed wind is one series, each condition a rescaling of it
    for c, k in enumerate(damped.conditions):
        np.testing.assert_allclose(damped.wind[c], damped.wind[0].astype(np.float64) * k, rtol=1e-6)


def _through(two, omega, zeta, h):
    """(A, B) [B] of the free response e^{-zeta w t} (A cos w_d t + B sin w_d t) through two
    consecutive samples two [2, B] (t = 0 and h); its amplitude at t = 0 is hypot(A, B)."""
    g, wd = zeta * omega, omega * np.sqrt(1 - zeta**2)
    return two[0], (two[1] * np.exp(g * h) - two[0] * np.cos(wd * h)) / np.sin(wd * h)


def _free_decay(theta, omega, zeta, h):
    """Closed-form homogeneous solution through the first two samples of theta [T, B], at
    t = k h, k < T. Independent of the testbed's simulator. Returns (prediction [T, B],
    amplitude hypot(A, B) [B] at sample 0)."""
    A, B = _through(theta[:2], omega, zeta, h)
    g, wd = zeta * omega, omega * np.sqrt(1 - zeta**2)
    t = np.arange(len(theta))[:, None] * h
    return np.exp(-g * t) * (A * np.cos(wd * t) + B * np.sin(wd * t)), np.hypot(A, B)


def test_every_bone_decays_freely_through_the_calm(damped):
    tr, L = damped.truth, damped.truth.lead_in_frames
    j0, j1 = variant.calm_frames(variant.transient_of(_tb()), FPS)
    calm = tr.theta[0, L + j0 : L + j1]  # [T, B], the training wind
    pred, amp = _free_decay(calm, tr.omega, tr.zeta, 1.0 / FPS)
    np.testing.assert_allclose(calm, pred, rtol=0, atol=FREE_DECAY_RTOL * amp.max())
    assert np.all(np.abs(calm - pred).max(0) <= FREE_DECAY_RTOL * amp)
    # the decay starts from a visible swing: a deliberate transient, not a residue
    rms = np.sqrt(np.mean(tr.theta[0, L : L + N_TRAIN] ** 2, axis=0))
    assert (amp >= MIN_CALM_START_AMPLITUDE * rms).all(), (amp / rms).min()
    # and it really is a decay at each bone's own rate: the envelope shrinks by exp(-zeta w T)
    T = (j1 - j0 - 2) / FPS  # from the calm's first sample to its last but one
    env = np.hypot(*_through(calm[-2:], tr.omega, tr.zeta, 1.0 / FPS))
    np.testing.assert_allclose(env / amp, np.exp(-tr.zeta * tr.omega * T), rtol=1e-6)
    # control: the faithful variant's wind over the same frames forces the bones
    f = _sim(_tb("faithful")).truth
    fc = f.theta[0, f.lead_in_frames + j0 : f.lead_in_frames + j1]
    fp, famp = _free_decay(fc, f.omega, f.zeta, 1.0 / FPS)
    assert np.abs(fc - fp).max() > 100 * FREE_DECAY_RTOL * famp.max()


def test_start_state_is_the_steady_state_of_the_unmodified_wind():
    """Doubling the lead-in leaves the recorded window unchanged (the start state is the
    infinite-past response, the transient sits at the same recorded times)."""
    a, b = _sim(_tb()), _sim(_tb(lead_in_tau=3.0))
    La, Lb = a.truth.lead_in_frames, b.truth.lead_in_frames
    assert Lb >= 2 * La - 1
    wa, wb = a.truth.theta[:, La:], b.truth.theta[:, Lb:]
    assert np.abs(wa - wb).max() < 1e-6 * np.abs(wa).max()
    np.testing.assert_array_equal(a.wind[:, La:], b.wind[:, Lb:])


def test_the_record_before_the_gust_does_not_depend_on_the_transient(damped):
    """Causality: moving the transient later changes nothing before the first gust, so the start
    state is the unmodified wind's (a steady state of the shaped wind, made periodic, would move
    with the gust). Compared before the rms calibration, which the transient does move."""
    late = _tb()
    late["damping"]["transient"]["start_s"] = START_S + 1.5  # calm 4.5-9.5 s, still in the window
    b = _sim(late)
    a, L = damped, damped.truth.lead_in_frames
    assert b.truth.lead_in_frames == L
    j = int(round((START_S - CFG["testbed"]["damping"]["transient"]["gust_s"]) * FPS))
    np.testing.assert_array_equal(a.wind[:, : L + j + 1], b.wind[:, : L + j + 1])
    unit_a, unit_b = a.truth.theta / a.truth.g0, b.truth.theta / b.truth.g0
    np.testing.assert_allclose(unit_a[:, : L + j + 1], unit_b[:, : L + j + 1], rtol=1e-12, atol=0)
    assert not np.allclose(unit_a[:, L + j + FPS], unit_b[:, L + j + FPS], rtol=1e-3)


def test_rms_swing_calibration_is_unchanged(damped):
    tr, L = damped.truth, damped.truth.lead_in_frames
    world = kinematics.cumulative_angle(tr.bone_parent, tr.theta[0, L : L + N_TRAIN])
    rms_deg = np.degrees(np.sqrt(np.mean(world**2)))
    assert rms_deg == pytest.approx(CFG["testbed"]["rms_swing_deg"], rel=1e-9)


def test_a_transient_before_the_record_is_refused():
    tb = _tb()
    tb["damping"]["transient"].update(start_s=0.5)  # the 1 s gust would start at -0.5 s
    with pytest.raises(ValueError, match="start_s"):
        _sim(tb)
