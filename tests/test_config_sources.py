"""Cross-key refusals name the command-line flag behind them, and the K bound is the Gaussians the
tree's mesh has, not its target vertex count (issue 58)."""

from __future__ import annotations

import pytest
import yaml

from physgs import config as pconfig
from physgs.testbed.dataset import gaussian_count, tree_geometry
from physgs.testbed.weberpenn import generate
from workflow_helpers import ROOT


def _raw() -> dict:
    return yaml.safe_load((ROOT / "config" / "trees.yaml").read_text())


def _refusal(**kw) -> str:
    with pytest.raises(pconfig.ConfigError) as e:
        pconfig.load_workflow_config(_raw(), "quick", **kw)
    return str(e.value)


def test_a_cross_key_refusal_names_the_config_flag_that_set_the_other_key():
    # quick's omega search ends its bank phase at half of its iterations: 20 leaves no room
    msg = _refusal(command_line={"train": {"iterations": 20}})
    assert "models/omega_search/until" in msg and "train/iterations = 20 from --config" in msg
    assert msg.splitlines()[-1] == "Fix --config or config/trees.yaml.", msg
    msg = _refusal(command_line={"models": {"configs": {"single": {"K": 1}}}})
    assert (
        "parts_study/k_candidates/0" in msg and "models/configs/single/K = 1 from --config" in msg
    )


def test_a_cross_key_refusal_names_the_set_flag_that_set_the_other_key():
    cfg = pconfig.resolve(_raw(), "quick")
    with pytest.raises(pconfig.ConfigError) as e:
        pconfig.apply_overrides(cfg, ["train.iterations=20"])
    msg = str(e.value)
    assert "train/iterations = 20 from --set train.iterations=20" in msg, msg
    assert msg.splitlines()[-1].startswith("Fix --set train.iterations=20 or "), msg


@pytest.mark.parametrize("profile", ["quick", "default"])
def test_the_gaussian_count_is_the_meshs_vertex_count(profile):
    """The oracle: the mesh the testbed builds (its vertex count is the Gaussians)."""
    cfg = pconfig.resolve(_raw(), profile)
    for tree in cfg["trees"]:
        preset, seed = cfg["presets"][tree], int(cfg["seed"])
        _, mesh = tree_geometry(cfg["testbed"], preset, seed=seed, tree=tree)
        skel = generate(preset, seed=seed, name=tree)
        assert gaussian_count(cfg["testbed"], preset, skel, tree) == len(mesh.vertices)


def test_k_above_the_gaussians_the_tree_has_is_refused_at_load():
    """quick's sparse tree targets 400 vertices; its mesh has 385 (the Gaussians)."""
    one = {"trees": ["sparse"]}
    msg = _refusal(command_line={**one, "models": {"configs": {"single": {"K": 395}}}})
    assert "models/configs/single/K" in msg and "K = 395 parts exceeds the 385 Gaussians" in msg
    assert "testbed/vertices/sparse = 400" in msg, msg
    ok = pconfig.load_workflow_config(
        _raw(), "quick", command_line={**one, "models": {"configs": {"single": {"K": 385}}}}
    )
    assert ok["models"]["configs"]["single"]["K"] == 385
