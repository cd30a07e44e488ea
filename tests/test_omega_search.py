"""The search over omega before the descent (physgs.models.omega_search): the projection against
scipy's exact LTI solution, the bank phase of the prior and its hand-over to the oscillators, the
training hook, the config's checks and the rerun scoping of its settings."""

import copy

import numpy as np
import pytest
import torch

import physgs.config
from physgs.config_checks import omega_search_is_runnable
from physgs.models import build_model
from physgs.models.omega_search import (
    GRID_INSET,
    OmegaSearch,
    log_grid,
    SearchHook,
    project_to_oscillators,
    search_iteration,
    unit_responses,
)
from physgs.models.oscillator_params import condition_vbar
from physgs.models.families import searches_omega
from physgs.models.registry import model_settings
from oracles import gusty_wind, model_context, quick_config, quick_models_cfg, wind_lsim

DT = 1 / 24


def test_projection_recovers_an_oscillator_simulated_by_scipy():
    # theta from scipy's exact first-order-hold solution; the grid's responses from physgs's RK4
    wind = gusty_wind(900, seed=3)
    vbar = float(wind.mean())
    true = [(2.6, 0.06, 0.02), (7.0, 0.2, -0.05)]  # (omega rad/s, zeta, gain)
    theta = np.stack([wind_lsim(o, z, g, wind, vbar, DT) for o, z, g in true])  # [2, T]
    om, ze = np.meshgrid(log_grid(1.0, 15.0, 120), np.linspace(0.02, 0.4, 20), indexing="ij")
    om, ze = om.ravel(), ze.ravel()
    r = unit_responses(om, ze, wind, vbar, DT, 4)
    s = slice(240, 900)  # a window after a lead-in, as the prior fits
    omega, zeta, gain, explained = project_to_oscillators(theta[:, s], r[:, s], om, ze)
    step = (15.0 / 1.0) ** (1 / 119)  # ratio between grid neighbours
    for k, (o, z, g) in enumerate(true):
        assert abs(np.log(omega[k] / o)) <= np.log(step)  # the nearest grid omega or next to it
        assert abs(zeta[k] - z) <= 0.03
        assert gain[k] == pytest.approx(g, rel=0.1)
        assert explained[k] > 0.98


def test_projection_refuses_mismatched_samples_and_scores_a_zero_angle():
    r = np.ones((3, 5))
    with pytest.raises(ValueError, match="share S"):
        project_to_oscillators(np.zeros((2, 4)), r, np.ones(3), np.ones(3))
    _, _, gain, explained = project_to_oscillators(np.zeros((1, 5)), r, np.ones(3), np.ones(3))
    assert gain[0] == 0.0 and explained[0] == 0.0


def _search_prior(K=3, search=None):
    ctx, wind = model_context(60, seed=1, lead_in=96)
    cfg = quick_models_cfg()
    cfg["omega_search"] = {**cfg["omega_search"], "models": ["ours_chain"]}
    if search:
        cfg["omega_search"].update(search)
    return build_model("ours_chain", ctx, cfg, K=K), wind


def test_bank_phase_is_linear_in_the_weights_and_hands_over_to_matching_oscillators():
    model, wind = _search_prior()
    w = torch.as_tensor(wind, dtype=torch.float64)
    assert model.search is not None and bool(model.bank_active)
    assert torch.count_nonzero(model.part_theta(w)) == 0  # starts at the canonical pose
    M = model.search.bank_size
    with torch.no_grad():  # each part rides one bank member: its angle is that response
        model.bank_weights.zero_()
        for p, m in enumerate((3, M // 2, M - 4)):
            model.bank_weights[p, m] = 0.05 * (p + 1)
    bank_theta = model.part_theta(w).clone()  # [K, L+F]
    # linear in the weights: doubling them doubles the angle
    with torch.no_grad():
        model.bank_weights.mul_(2.0)
    assert torch.allclose(model.part_theta(w), 2 * bank_theta)
    with torch.no_grad():
        model.bank_weights.mul_(0.5)
    lead, n = model.lead_in, model.ctx.n_train
    stats = model.end_bank_phase([(wind, slice(lead, lead + n))])
    assert not bool(model.bank_active)
    # the projection's grid spans the bounds: each part's omega lands next to its bank member's
    for p, m in enumerate((3, M // 2, M - 4)):
        assert abs(np.log(float(model.omega[p].detach()) / model.bank_omega[m])) < 0.05
    after = model.part_theta(w)  # the oscillators now: the same motion over the window
    err = (after - bank_theta)[:, lead : lead + n].norm(dim=1)
    assert (err <= 0.15 * bank_theta[:, lead : lead + n].norm(dim=1)).all()
    # the gain handed over is the least-squares one (project_to_oscillators): the least-squares
    # factor from the oscillators' motion onto the bank's is then exactly 1 (1 + 2e-7 measured in
    # float64), whatever the shape's residual; a gain off by the model's gain_scale (1.08 here)
    # puts it 8% off
    b, a = bank_theta[:, lead : lead + n].double(), after[:, lead : lead + n].detach().double()
    ls_factor = (a * b).sum(1) / (a * a).sum(1)  # [K]
    assert torch.allclose(ls_factor, torch.ones_like(ls_factor), rtol=0, atol=1e-4), ls_factor
    assert stats["omega_search_explained_median"] > 0.95
    with pytest.raises(RuntimeError, match="no bank phase"):
        model.end_bank_phase([(wind, slice(lead, lead + n))])


def test_projection_from_frame_0_fits_each_angle_relative_to_frame_0():
    # with a frame-0 canonical pose the images see theta(t) - theta(frame 0): the projection
    # must fit that, the grid point whose responses' differences a least-squares gain fits best
    # (oracle: numpy lstsq per grid point), not the absolute angle
    def projected(pose):
        model, wind = _search_prior(K=1)
        model.canonical_pose = pose
        M = model.search.bank_size
        with torch.no_grad():  # two bank members of unequal weight: no single oscillator fits
            model.bank_weights[0, 2] = 0.08
            model.bank_weights[0, M - 6] = 0.03
        lead, n = model.lead_in, model.ctx.n_train
        w = torch.as_tensor(wind, dtype=torch.float64)
        bank = model.part_theta(w)[0, lead : lead + n].detach().double().numpy()  # [S]
        model.end_bank_phase([(wind, slice(lead, lead + n))])
        return model, w, bank

    model, w, bank = projected("frame0")
    b, (n_om, n_ze) = model.bounds, model.search.grid
    om = np.exp(
        np.linspace(
            np.log(b.omega_lo * (1 + GRID_INSET)), np.log(b.omega_hi * (1 - GRID_INSET)), n_om
        )
    )
    dz = GRID_INSET * (b.zeta_hi - b.zeta_lo)
    om, ze = (
        a.ravel()
        for a in np.meshgrid(om, np.linspace(b.zeta_lo + dz, b.zeta_hi - dz, n_ze), indexing="ij")
    )
    lead, n = model.lead_in, model.ctx.n_train
    vbar = condition_vbar(model.vbar_ratio, w)
    r = unit_responses(om, ze, w, vbar, model.dt, model.substeps)[:, lead : lead + n]  # [G, S]
    rel, r_rel = bank - bank[0], r - r[:, :1]
    resid = [np.linalg.lstsq(g[:, None], rel, rcond=None)[1].sum() for g in r_rel]
    best = int(np.argmin(resid))
    assert float(model.omega[0].detach()) == pytest.approx(om[best], rel=1e-5)
    assert float(model.zeta[0].detach()) == pytest.approx(ze[best], rel=1e-5)
    after = model.part_theta(w)[0, lead : lead + n].detach().double().numpy()
    gain = (r_rel[best] @ rel) / (r_rel[best] @ r_rel[best])
    assert np.allclose(after - after[0], gain * r_rel[best], atol=1e-6 * np.abs(rel).max())
    rest, _, _ = projected("rest")  # fitting the absolute angle picks another oscillator
    assert abs(np.log(float(rest.omega[0].detach()) / om[best])) > 0.01


def test_gradients_reach_the_bank_weights_only_during_the_bank_phase():
    model, wind = _search_prior()
    w = torch.as_tensor(wind, dtype=torch.float64)
    model.part_theta(w).sum().backward()
    assert model.bank_weights.grad is not None and model.omega_raw.grad is None
    model.zero_grad(set_to_none=True)
    model.end_bank_phase([(wind, slice(96, 396))])
    with torch.no_grad():
        model.gain_raw.fill_(0.1)
    model.part_theta(w).sum().backward()
    assert model.bank_weights.grad is None and model.omega_raw.grad is not None


def test_search_hook_trains_through_the_hand_over(swaying, tmp_path):
    from physgs.experiments.recipe import fit
    from physgs.models import load_checkpoint, save_checkpoint

    cfg = quick_config()
    cfg["train"].update(iterations=24, warmup=4, backend="fast", holdout_every=0)
    cfg["models"]["configs"]["single"]["K"] = 3
    cfg["models"]["omega_search"]["until"] = 0.5
    from physgs.experiments import job_spec

    job = job_spec(cfg, "ours_chain", "single", 0)
    res = fit(swaying, job, progress=False)
    assert res.stats["omega_search_at"] == 12
    assert not bool(res.model.bank_active)
    assert len(res.stats["omega_search_hz_quartiles"]) == 3
    # the checkpoint reloads as oscillators, not as a bank
    path = tmp_path / "chain.pt"
    save_checkpoint(
        path,
        res.model,
        name="ours_chain",
        config="single",
        seed=0,
        stats=res.stats,
        models_cfg=job["settings"],
        train_cfg=job["train"],
    )
    back = load_checkpoint(path)
    w = torch.as_tensor(swaying.wind[0], dtype=torch.float64)
    assert not bool(back.bank_active)
    assert torch.equal(back.part_theta(w), res.model.part_theta(w))
    # the independent prior does not search: same job without the hook's statistics
    res_ours = fit(swaying, job_spec(cfg, "ours", "single", 0), progress=False)
    assert "omega_search_at" not in res_ours.stats


def test_search_iteration_must_fall_between_warmup_and_freezing():
    s = OmegaSearch(0.3, 8, 0.15, 0.02, (10, 4), 0.05)
    assert search_iteration(s, {"iterations": 3000, "warmup": 50}, 1500) == 900
    with pytest.raises(ValueError, match="models.omega_search.until"):
        search_iteration(s, {"iterations": 30, "warmup": 10}, None)
    with pytest.raises(ValueError, match="freezing"):
        search_iteration(s, {"iterations": 3000, "warmup": 50}, 600)


def test_config_check_names_the_key():
    cfg = physgs.config.load("config/trees.yaml", "default")
    assert list(omega_search_is_runnable(cfg)) == []
    bad = copy.deepcopy(cfg)
    bad["models"]["omega_search"]["until"] = 0.6  # after freeze_at 0.5
    bad["models"]["omega_search"]["models"] = ["ours_chain", "mlp"]
    keys = [k for k, _ in omega_search_is_runnable(bad)]
    assert ("models", "omega_search", "models", 1) in keys
    assert ("models", "omega_search", "until") in keys


def test_only_the_searching_models_read_its_settings():
    cfg = quick_models_cfg()
    assert searches_omega(cfg, "ours_chain") and not searches_omega(cfg, "ours")
    assert "omega_search" in model_settings(cfg, "ours_chain")
    assert "omega_search" not in model_settings(cfg, "ours")
    assert model_settings(cfg, "ours_chain")["omega_search"]["models"] == ["ours_chain"]
    cfg["omega_search"]["models"] = ["ours_chain"]
    assert "omega_search" not in model_settings(cfg, "ours_topo")


def test_training_calls_every_hook_in_order_and_merges_their_statistics(swaying):
    from physgs.train.loop import train_model

    cfg = quick_config()
    cfg["train"].update(iterations=6, warmup=2, backend="fast")
    calls = []

    def a(it, m, o):
        calls.append(("a", it))
        return {"x": 1} if it == 3 else None

    def b(it, m, o):
        calls.append(("b", it))
        return {"y": 2} if it == 4 else None

    model = build_model("static", swaying, cfg["models"])
    res = train_model(
        model, swaying, cfg["train"], conditions=[0], seed=0, progress=False, on_iteration=[a, b]
    )
    assert calls == [(h, it) for it in range(6) for h in ("a", "b")]
    assert res.stats["x"] == 1 and res.stats["y"] == 2


def test_search_hook_scales_the_physics_rate_and_drops_its_moments():
    model, wind = _search_prior()
    opt = torch.optim.Adam(
        [
            {"name": "physics", "params": [model.axis_raw, model.bank_weights], "lr": 0.05},
            {"name": "pivot", "params": [model.pivot], "lr": 0.01},
        ]
    )
    for g in opt.param_groups:
        g["base_lr"] = g["lr"]
    w = torch.as_tensor(wind, dtype=torch.float64)
    (model.part_theta(w).sum() + model.axis.sum() + model.pivot.sum()).backward()
    opt.step()
    hook = SearchHook(3, [(wind, slice(96, 396))])
    assert hook(2, model, opt) is None and bool(model.bank_active)
    stats = hook(3, model, opt)
    assert stats["omega_search_at"] == 3 and not bool(model.bank_active)
    phys, piv = opt.param_groups
    assert phys["base_lr"] == pytest.approx(0.05 * model.search.physics_lr_after)
    assert piv["base_lr"] == 0.01  # other groups untouched
    assert model.axis_raw not in opt.state and model.pivot in opt.state
