"""Recovery on a real testbed tree (physics only, no frames): known answers."""

from types import SimpleNamespace

import numpy as np
import pytest
import torch

import physgs.config
from physgs.models.oscillator import integrate
from physgs.recovery.matcher import match_parts, training_window
from physgs.recovery.null import draw_null_omegas
from physgs.testbed.stats import nearest_bone_gap
from physgs.recovery.record import bone_window, run_null, score_recovery
from physgs.testbed.dataset import simulate_tree


@pytest.fixture(scope="module")
def sparse():
    # the default record (300 frames): the quick profile's 2.5 s window cannot tell apart two
    # bones whose frequencies differ by 0.6%, and this test needs every part matched to itself
    cfg = physgs.config.load("config/trees.yaml", "default")
    sim = simulate_tree(cfg["testbed"], cfg["presets"]["sparse"], seed=cfg["seed"], tree="sparse")
    tr = sim.truth
    obs = SimpleNamespace(
        wind=sim.wind,
        lead_in_frames=int(tr.lead_in_frames),
        n_train=int(cfg["testbed"]["n_train"]),
        fps=int(tr.fps),
        vbar=tr.vbar,
    )
    return tr, obs


def test_parts_that_are_bones_are_recovered_exactly(sparse):
    tr, obs = sparse
    pick = np.array([0, 5, 10, 15, len(tr.omega) - 1])
    om = torch.as_tensor(tr.omega[pick], dtype=torch.float64)
    wind = torch.as_tensor(obs.wind[0], dtype=torch.float64)
    # any vbar error is a constant force offset: it shifts theta by a constant and leaves the
    # correlation unchanged, so the record's mean stands in for the nominal speed here
    theta = integrate(
        om, torch.full_like(om, 0.08), torch.ones_like(om), wind, float(wind.mean()), 1 / obs.fps, 2
    ).numpy()
    rec = score_recovery(
        theta, tr.omega[pick], np.full(5, 0.08), tr, obs.lead_in_frames, obs.n_train
    )
    m = rec.match
    # integrated from rest over a 1.5 tau_max lead-in, the slowest bones keep a trace of their
    # start transient (exp(-1.5) at omega_min), so the match is near, not exactly, perfect
    assert m.n_trusted == 5 and np.all(m.corr > 0.995)
    np.testing.assert_allclose(m.omega_true, tr.omega[pick], rtol=1e-12)
    assert m.median_rel_err < 1e-12
    assert rec.damping.median_zeta == pytest.approx(0.08)
    assert bone_window(tr, obs.lead_in_frames, obs.n_train).shape == (len(tr.omega), obs.n_train)


def test_null_on_sparse_tree_is_seeded_and_bounded_by_the_grid(sparse):
    tr, obs = sparse
    a = run_null(tr, obs, n_parts=32, zeta_init=0.1, substeps=2, seed=0)
    b = run_null(tr, obs, n_parts=32, zeta_init=0.1, substeps=2, seed=0)
    np.testing.assert_array_equal(a.median_rel_err, b.median_rel_err)
    assert a.omega.shape == (8, 32)
    assert tr.omega.min() <= a.omega.min() and a.omega.max() <= tr.omega.max()
    assert np.all(np.isfinite(a.median_rel_err))
    # per part, the matched bone is never closer than the nearest bone: rel_err >= gap (one draw,
    # rebuilt here with the same solver and matcher)
    om = draw_null_omegas(tr.omega, 32, 8, 0)[0]
    w = torch.as_tensor(obs.wind[0], dtype=torch.float64)
    th = integrate(
        torch.as_tensor(om),
        torch.full((32,), 0.1, dtype=torch.float64),
        torch.ones(32, dtype=torch.float64),
        w,
        float(obs.vbar[0]),
        1 / obs.fps,
        2,
    ).numpy()
    m = match_parts(
        training_window(th, obs.lead_in_frames, obs.n_train),
        bone_window(tr, obs.lead_in_frames, obs.n_train),
        om,
        tr.omega,
    )
    assert m.median_rel_err == a.median_rel_err[0]
    assert np.all(m.rel_err >= nearest_bone_gap(om, tr.omega) - 1e-12)
    # over trusted parts only, the median error can sit below the median gap (trust favours parts
    # near a bone; the paper's sparse tree: null 4.5% against a 5.4% gap), but not far below
    assert a.median_median_rel_err >= 0.5 * a.nearest_bone_gap
