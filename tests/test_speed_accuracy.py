"""The speed-accuracy sweep's bookkeeping: one knob at a time, the base point run once."""
import copy

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
    cfg["speed_accuracy"]["knobs"] = {"K": [8, sa.knob_value(cfg, tree, "K"), 64],
                                      "iterations": [sa.knob_value(cfg, tree, "iterations")]}
    assert sa.sweep_points(cfg) == ["base", "K-8", "K-64"]
    assert sa.parse_point("K-64") == ("K", 64)
    with pytest.raises(ValueError, match="bad sweep point"):
        sa.parse_point("colour-3")


def test_collect_repeats_the_base_under_every_knob():
    base = {"point": "base", "knob": "base", "wall_s": 10.0, "psnr_time": 25.0, "rel_err": 0.03,
            "train_s": 9.0, "testbed_s": 0.0, "eval_s": 1.0, "trusted": 5, "parts": 8, "frozen": 1,
            "tree": "sparse", "resolution": 128, "iterations": 100, "substeps": 2, "K": 8,
            "vertices": 2000}
    k4 = dict(base, point="K-4", knob="K", K=4, wall_s=6.0)
    df = sa.collect([k4, base])
    assert len(df) == len(sa.KNOBS) + 1
    k = df[df["knob"] == "K"]
    assert list(k["value"]) == [4, 8] and list(k["is_base"]) == [False, True]
    with pytest.raises(ValueError, match="exactly one 'base'"):
        sa.collect([k4])


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
