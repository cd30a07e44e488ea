"""Model only what the scene requires: image swing, freezing, and K chosen from the data."""

import copy
import math
from types import SimpleNamespace

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from physgs.models import build_model, load_checkpoint
from physgs.experiments import job_spec, train_and_save
from physgs.experiments.kselect import (
    PARAMS_PER_PART,
    auto_job,
    bic,
    choose_bic,
    choose_heldout,
    heldout_split,
    load_selection,
    save_selection,
    select_k,
)
from physgs.models.visibility import freeze_invisible, freeze_schedule, part_image_swing
from physgs.recovery.run import recover_model
from physgs.train import train_model
from oracles import quick_train_cfg


@pytest.fixture(scope="module")
def data(swaying):
    return swaying


def _cfg(K=4, iterations=16, warmup=4):
    return quick_train_cfg(iterations, warmup, K=K)


# -- image swing --------------------------------------------------------------------------------


def test_probe_swing_matches_an_independent_projection(data):
    model = build_model("ours", data, _cfg(K=4)["models"])
    with torch.no_grad():
        model.axis_raw.copy_(torch.tensor([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [1.0, 1.0, 0]]))
    swing = part_image_swing(model, data, probe_rad=0.05)
    xyz = data.canonical_xyz.astype(np.float64)
    lab = model.part_labels.numpy()
    uv0, _ = data.train_camera.project(xyz)
    for k in range(4):
        ax = model.axis[k].detach().double().numpy()
        p = model.pivot[k].detach().double().numpy()
        pts = xyz[lab == k]
        best = 0.0
        for a in (0.05, -0.05):
            R = Rotation.from_rotvec(a * ax).as_matrix()
            uv, _ = data.train_camera.project((pts - p) @ R.T + p)
            best = max(best, np.linalg.norm(uv - uv0[lab == k], axis=1).max())
        assert swing[k] == pytest.approx(best, rel=1e-6, abs=1e-9)
    # a rotation about the viewing axis (y here) of points near the pivot moves them least
    assert np.all(swing > 0)


def test_swing_under_theta_is_zero_for_a_silent_model_and_grows_with_gain(data):
    model = build_model("ours", data, _cfg(K=4)["models"])
    assert np.all(part_image_swing(model, data) == 0.0)  # gain 0: nothing reaches the image
    with torch.no_grad():
        model.gain_raw.fill_(0.02)
    s1 = part_image_swing(model, data)
    with torch.no_grad():
        model.gain_raw.fill_(0.04)
    s2 = part_image_swing(model, data)
    assert np.all(s1 > 0)
    np.testing.assert_allclose(s2, 2 * s1, rtol=0.02)  # small angles: pixels ~ linear in theta


# -- freezing ----------------------------------------------------------------------------------


def test_frozen_parts_have_zero_theta_and_their_parameters_never_move(data, tmp_path):
    cfg = _cfg(K=4, iterations=14, warmup=2)
    model = build_model("ours", data, cfg["models"])
    snap = {}

    def hook(it, m, opt):
        if it == 6:
            with torch.no_grad():  # make part 0 tiny in the image, the others large
                m.gain_raw.fill_(0.05)
                m.gain_raw[0] = 1e-6
            out = freeze_invisible(m, data, 1e-3, optimizer=opt)  # part 0 swings ~1e-5 px
            snap.update(
                {
                    n: getattr(m, n).detach().clone()
                    for n in ("omega_raw", "zeta_raw", "gain_raw", "axis_raw", "pivot")
                }
            )
            return out
        return None

    res = train_model(
        model, data, cfg["train"], conditions=[0], seed=0, progress=False, on_iteration=hook
    )
    m = res.model
    assert res.stats["frozen_parts"] == int(m.frozen.sum()) >= 1 and bool(m.frozen[0])
    fz = m.frozen
    for n, before in snap.items():
        after = getattr(m, n).detach()
        assert torch.equal(after[fz], before[fz]), n  # exactly no update
    assert not torch.equal(m.gain_raw.detach()[~fz], snap["gain_raw"][~fz])  # others trained
    theta = m.part_theta(torch.tensor(data.wind[0]))
    assert torch.all(theta[fz] == 0) and torch.all(theta[~fz].abs().amax(1) > 0)
    # the mask travels in the checkpoint
    from physgs.models import save_checkpoint

    save_checkpoint(
        tmp_path / "o.pt",
        m,
        name="ours",
        config="single",
        seed=0,
        models_cfg=cfg["models"],
        train_cfg=cfg["train"],
        stats=res.stats,
    )
    assert torch.equal(load_checkpoint(tmp_path / "o.pt").frozen, fz)


def test_frozen_parts_count_as_untrusted_in_recovery(data):
    model = build_model("ours", data, _cfg(K=4)["models"])
    with torch.no_grad():
        model.gain_raw.fill_(0.05)
        model.omega_raw.copy_(torch.tensor([-2.0, -0.5, 0.5, 2.0]))
    model.freeze_parts(np.array([True, False, False, False]))
    w = np.asarray(data.wind[0], dtype=np.float64)
    from physgs.models.oscillator import integrate

    om = model.omega.detach().double()
    bones = integrate(
        om,
        torch.full((4,), 0.1, dtype=torch.float64),
        torch.ones(4, dtype=torch.float64),
        w,
        float(w.mean()),
        1 / data.fps,
        2,
    ).numpy()
    truth = SimpleNamespace(omega=om.numpy(), zeta=np.full(4, 0.1), theta=bones.T[None])
    rec = recover_model(model, data, truth)
    assert rec.n_frozen == 1 and not rec.match.trusted[0] and rec.match.corr[0] == 0.0
    assert rec.match.n_trusted == 3


def test_freeze_schedule_is_checked():
    cfg = _cfg(iterations=100, warmup=20)
    m, t = cfg["models"], cfg["train"]
    m["ours"].update(freeze_below_px=1.0, freeze_at=0.5)
    assert freeze_schedule(m, t) == 50
    m["ours"]["freeze_at"] = 0.1
    with pytest.raises(ValueError, match="freeze_at"):
        freeze_schedule(m, t)
    m["ours"]["freeze_below_px"] = 0.0
    assert freeze_schedule(m, t) is None


def test_run_training_freezes_and_reports(data, tmp_path):
    cfg = _cfg(K=4, iterations=12, warmup=2)
    cfg["models"]["ours"].update(freeze_below_px=1e6, freeze_at=0.5)  # everything is "invisible"
    res = train_and_save(
        data,
        job_spec(cfg, "ours", "single"),
        progress=False,
        checkpoint_path=tmp_path / "o.pt",
        loss_path=tmp_path / "o.csv",
    )
    assert res.stats["frozen_parts"] == 4 and res.stats["frozen_at"] == 6
    assert len(res.stats["part_swing_px"]) == 4
    assert load_checkpoint(tmp_path / "o.pt").checkpoint_info["stats"]["frozen_parts"] == 4


# -- K from the data ---------------------------------------------------------------------------


def test_split_and_choices():
    tr, held = heldout_split(20, 5)
    assert held.tolist() == [4, 9, 14, 19] and len(tr) == 16 and not set(tr) & set(held)
    with pytest.raises(ValueError, match="every"):
        heldout_split(20, 1)
    assert choose_heldout([8, 16, 32, 64], [20.0, 21.0, 21.08, 20.5], 0.1) == 16  # tie -> smaller
    assert choose_heldout([8, 16, 32, 64], [20.0, 21.0, 21.5, 20.5], 0.1) == 32
    assert bic(0.01, 1000, 4) == pytest.approx(
        1000 * math.log(0.01) + PARAMS_PER_PART * 4 * math.log(1000)
    )
    assert choose_bic([8, 16, 32], [5.0, 3.0, 3.0]) == 16


def test_select_k_then_train_auto(data, tmp_path):
    cfg = _cfg(iterations=14, warmup=4)
    cfg["models"]["kselect"] = {
        "candidates": [4, 1],
        "method": "heldout",
        "every": 5,
        "iterations": 14,
        "warmup": 4,
        "tie_db": 0.0,
        "conditions": "train",
    }
    cfg["models"]["ours"].update(freeze_below_px=0.0, freeze_at=0.5)
    job = job_spec(cfg, "ours", "single")
    sel = select_k(data, job, cfg["models"]["kselect"])
    assert sel.candidates == [1, 4] and len(sel.heldout_psnr) == 2
    assert np.all(np.isfinite(sel.heldout_psnr)) and np.all(np.isfinite(sel.bic))
    assert sel.k_heldout == [1, 4][int(np.argmax(sel.heldout_psnr))]
    assert sel.chosen_k == sel.k_heldout and sel.k_bic in (1, 4)
    save_selection(tmp_path / "k.json", sel)
    back = load_selection(tmp_path / "k.json")
    assert back == sel
    train_and_save(
        data,
        auto_job(job, back, "train"),
        progress=False,
        checkpoint_path=tmp_path / "a.pt",
        loss_path=tmp_path / "a.csv",
    )
    model = load_checkpoint(tmp_path / "a.pt")
    assert model.K == sel.chosen_k and model.checkpoint_info["config"] == "auto"
    bad = copy.deepcopy(cfg)
    bad["models"]["kselect"]["candidates"] = [4, 500]
    with pytest.raises(ValueError, match="K = 500 exceeds the 120 Gaussians"):
        select_k(data, job, bad["models"]["kselect"])
    with pytest.raises(ValueError, match="no K was given"):
        build_model("ours", data, cfg["models"], config="auto")


def test_tab_kselect_rows_and_undefined_entries():
    from physgs.report.build import Plan, needs
    from physgs.report.kselect import tab_kselect

    common = dict(view_psnr=22.0, k_heldout=16, k_bic=64)
    rows = {
        ("sparse", "ours", "single"): dict(
            K=32, time_psnr=25.0, median_rel_err=0.05, trusted=10, frozen=3, train_s=600.0, **common
        ),
        ("sparse", "ours", "auto"): dict(
            K=16,
            time_psnr=25.5,
            median_rel_err=float("nan"),
            trusted=0,
            frozen=16,
            train_s=500.0,
            select_s=250.0,
            **common,
        ),
    }
    t = tab_kselect({0: rows}, ["sparse"], {"sparse": 22}, "heldout")
    assert t.df["K"].tolist() == [32, 16] and t.df["median_rel_err_pct"].iloc[0] == 5.0
    assert "10/32" in t.tex and "0/16" in t.tex and "--" in t.tex  # NaN median shown as --
    assert ("kselect", "sparse", 3) in needs("tab_kselect", Plan(["sparse"], {}, [3]))
    # a second seed that chose another K: both choices shown, the rest averaged
    rows1 = {k: dict(v) for k, v in rows.items()}
    rows1[("sparse", "ours", "auto")].update(K=64, time_psnr=26.5)
    t2 = tab_kselect({0: rows, 1: rows1}, ["sparse"], {"sparse": 22}, "heldout")
    assert t2.df["seed"].tolist() == [0, 0, 1, 1] and "16/64" in t2.tex
    assert "26.00 $\\pm$ 0.71" in t2.tex
