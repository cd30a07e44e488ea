"""Config loading: schema validation and profile resolution."""
from pathlib import Path

import pytest
import yaml

from physgs import config as pconfig

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "trees.yaml"


def _base() -> dict:
    return yaml.safe_load(CONFIG.read_text())


def test_shipped_config_validates_for_every_profile():
    base = _base()
    for name in base["profiles"]:
        cfg = pconfig.resolve(base, name)
        pconfig.validate(cfg)
        assert cfg["profile"] == name
        assert "profiles" not in cfg


def test_profile_overrides_only_what_it_names():
    base = _base()
    quick = pconfig.resolve(base, "quick")
    default = pconfig.resolve(base, "default")
    assert quick["testbed"]["resolution"] < default["testbed"]["resolution"]
    # untouched leaves survive the merge
    assert quick["testbed"]["fps"] == default["testbed"]["fps"] == base["testbed"]["fps"]


def test_schema_violation_names_the_key():
    base = _base()
    base["testbed"]["zeta"] = -0.1
    with pytest.raises(pconfig.ConfigError, match="testbed/zeta"):
        pconfig.validate(base)


def test_unknown_profile_is_refused_with_the_choices():
    with pytest.raises(pconfig.ConfigError, match="quick"):
        pconfig.resolve(_base(), "fastest")


def test_load_rejects_a_bad_file(tmp_path):
    base = _base()
    base["trees"] = ["sparse", "oak"]
    bad = tmp_path / "trees.yaml"
    bad.write_text(yaml.safe_dump(base))
    with pytest.raises(pconfig.ConfigError, match="trees/1"):
        pconfig.load(bad)
