"""The speed-accuracy sweep's bookkeeping: one knob at a time, the base point run once."""

import copy

import numpy as np
import pytest

import physgs.config
from physgs.experiments import job_spec
from physgs.experiments import sweep as sa


@pytest.fixture
def cfg():
    return physgs.config.load("config/trees.yaml", "default")


def _flat(cfg, tree):
    return {k: sa.knob_value(cfg, tree, k) for k in sa.KNOBS}


@pytest.mark.parametrize("knob", sa.KNOBS)
def test_with_knob_changes_that_knob_alone(cfg, knob):
    tree = cfg["speed_accuracy"]["tree"]
    before = copy.deepcopy(cfg)
    new = sa.with_knob(cfg, tree, knob, 7)
    assert cfg == before  # the input is not mutated
    want = dict(_flat(cfg, tree), **{knob: 7})
    assert _flat(new, tree) == want
    if knob == "iterations":  # the static warm-up keeps its fraction of training
        frac = cfg["train"]["warmup"] / cfg["train"]["iterations"]
        assert new["train"]["warmup"] == max(1, round(frac * 7))


def test_sweep_points_run_the_profile_setting_once(cfg):
    tree = cfg["speed_accuracy"]["tree"]
    cfg["speed_accuracy"]["knobs"] = {
        "K": [8, sa.knob_value(cfg, tree, "K"), 64],
        "iterations": [sa.knob_value(cfg, tree, "iterations")],
    }
    assert sa.sweep_points(cfg) == ["base", "K-8", "K-64"]
    assert sa.parse_point("K-64") == ("K", 64)
    with pytest.raises(ValueError, match="bad sweep point"):
        sa.parse_point("colour-3")


def test_collect_repeats_the_base_under_every_knob():
    base = {
        "point": "base",
        "knob": "base",
        "wall_s": 10.0,
        "psnr_time": 25.0,
        "rel_err": 0.03,
        "train_s": 9.0,
        "testbed_s": 0.0,
        "eval_s": 1.0,
        "trusted": 5,
        "parts": 8,
        "frozen": 1,
        "tree": "sparse",
        "resolution": 128,
        "iterations": 100,
        "substeps": 2,
        "K": 8,
        "vertices": 2000,
        "seed": 0,
    }
    k4 = dict(base, point="K-4", knob="K", K=4, wall_s=6.0)
    df = sa.collect([k4, base])
    assert len(df) == len(sa.KNOBS) + 1
    k = df[df["knob"] == "K"]
    assert list(k["value"]) == [4, 8] and list(k["is_base"]) == [False, True]
    with pytest.raises(ValueError, match="exactly one 'base'"):
        sa.collect([k4])
    # two seeds: one row per seed and point, each seed anchored by its own base
    two = sa.collect(
        [dict(r, seed=s, psnr_time=r["psnr_time"] + s) for r in (k4, base) for s in (0, 1)]
    )
    assert len(two) == 2 * (len(sa.KNOBS) + 1)
    kb = two[(two["knob"] == "K") & two["is_base"]]
    assert sorted(kb["seed"]) == [0, 1] and sorted(kb["psnr_time"]) == [25.0, 26.0]
    with pytest.raises(ValueError, match="seed 1 need exactly one 'base'"):
        sa.collect([dict(base, seed=0), dict(k4, seed=1)])
    with pytest.raises(ValueError, match="names no seed"):
        sa.collect([{k: v for k, v in base.items() if k != "seed"}])


def test_null_level_is_the_central_95_percent_of_every_draw():
    from physgs.recovery.null import NullResult

    draws = [np.linspace(0.01, 0.05, 8), np.linspace(0.02, 0.06, 8)]
    nulls = [
        NullResult(np.full(8, 4), d, np.ones(8), np.ones((8, 32)), 32, 0.01, s)
        for s, d in enumerate(draws)
    ]
    lv = sa.null_level(nulls)
    pooled = np.concatenate(draws)
    assert lv["median"] == pytest.approx(np.median(pooled))
    assert (lv["low"], lv["high"]) == pytest.approx(tuple(np.percentile(pooled, [2.5, 97.5])))
    assert lv["draws"] == 16 and lv["K"] == 32


def test_fig_speed_accuracy_with_seeds_and_the_null_band(tmp_path):
    from physgs.report.figures import fig_speed_accuracy

    base = {
        "point": "base",
        "knob": "base",
        "wall_s": 10.0,
        "psnr_time": 25.0,
        "rel_err": 0.03,
        "train_s": 9.0,
        "testbed_s": 0.0,
        "eval_s": 1.0,
        "trusted": 5,
        "parts": 8,
        "frozen": 1,
        "tree": "sparse",
        "resolution": 128,
        "iterations": 100,
        "substeps": 2,
        "K": 8,
        "vertices": 2000,
    }
    recs = [
        dict(r, seed=s, rel_err=r["rel_err"] + 0.01 * s)
        for s in (0, 1)
        for r in (base, dict(base, point="K-4", knob="K", K=4, wall_s=6.0))
    ]
    outs = [tmp_path / "s.pdf", tmp_path / "s.png"]
    fig_speed_accuracy(
        sa.collect(recs),
        outs,
        null={"median": 0.03, "low": 0.02, "high": 0.04, "draws": 16, "K": 8},
    )
    assert all(o.stat().st_size > 1000 for o in outs)


def test_every_point_trains_the_tables_recipe(cfg):
    """The base point's job is the train rule's ours_single job (freezing settings included);
    a knob point differs from it in that knob alone."""
    tables_job = job_spec(cfg, "ours", "single")
    assert cfg["models"]["ours"]["freeze_below_px"] > 0  # the default profile freezes
    base = sa.point_settings(cfg, "base")
    assert base["job"] == tables_job and "testbed" not in base
    k8 = sa.point_settings(cfg, "K-8")["job"]
    assert k8["K"] == 8 and {**k8, "K": tables_job["K"]} == tables_job
    sub = sa.point_settings(cfg, "substeps-4")["job"]
    assert sub["settings"]["ours"]["substeps"] == 4
    assert sub["settings"]["ours"]["freeze_below_px"] == cfg["models"]["ours"]["freeze_below_px"]
    res = sa.point_settings(cfg, "resolution-64")
    assert res["testbed"]["testbed"]["resolution"] == 64 and res["job"] == tables_job
    # a training seed reaches the job; the rebuilt testbed keeps the testbed seed unless asked
    s3 = sa.point_settings(cfg, "resolution-64", seed=3)
    assert s3["job"] == job_spec(cfg, "ours", "single", seed=3)
    assert s3["testbed"]["seed"] == cfg["seed"]
    assert (
        sa.point_settings(cfg, "resolution-64", seed=3, testbed_seeds=True)["testbed"]["seed"] == 3
    )
