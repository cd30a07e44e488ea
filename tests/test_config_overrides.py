"""`--set KEY.PATH=VALUE` overrides (benchmarks/fit_recipe.py) go through the config's schema and
cross-key checks: a bad one is refused with the key named before any work starts."""

from __future__ import annotations

import sys

import pytest

import physgs.config
from workflow_helpers import ROOT


@pytest.fixture(scope="module")
def cfg():
    return physgs.config.load(ROOT / "config" / "trees.yaml", "quick")


def test_a_valid_override_is_applied(cfg):
    out = physgs.config.apply_overrides(cfg, ["train.lr.deform=1.0e-3", "train.iterations=70"])
    assert out["train"]["lr"]["deform"] == 1.0e-3 and out["train"]["iterations"] == 70
    assert out is not cfg


def test_a_string_for_a_number_is_refused_with_the_key(cfg):
    with pytest.raises(physgs.config.ConfigError, match=r"train/lr/deform.*not of type 'number'"):
        physgs.config.apply_overrides(cfg, ["train.lr.deform=1e6"])


def test_the_message_says_how_to_write_the_number(cfg):
    with pytest.raises(physgs.config.ConfigError, match=r"1\.0e\+6"):
        physgs.config.apply_overrides(cfg, ["train.lr.deform=1e6"])


def test_an_unknown_key_names_the_nearest(cfg):
    with pytest.raises(physgs.config.ConfigError, match="did you mean 'train/lr/deform'"):
        physgs.config.apply_overrides(cfg, ["train.lr.defrom=0.001"])


def test_a_malformed_assignment_is_refused(cfg):
    with pytest.raises(physgs.config.ConfigError, match="KEY.PATH=VALUE"):
        physgs.config.apply_overrides(cfg, ["train.iterations"])


def test_fit_recipe_refuses_before_reading_the_dataset(tmp_path, monkeypatch):
    """The dataset folder does not exist: a ConfigError (not FileNotFoundError, not a TypeError
    from inside training) proves the override was checked before any work."""
    monkeypatch.chdir(ROOT)
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    sys.modules.pop("fit_recipe", None)
    import fit_recipe

    with pytest.raises(physgs.config.ConfigError, match="train/lr/deform"):
        fit_recipe.main(
            [str(tmp_path / "absent"), "--models", "static", "--set", "train.lr.deform=1e6"]
        )
