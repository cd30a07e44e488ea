"""config/README.md: every key of the config, generated from the schema's annotations and held
in sync with it (physgs.config_reference, tools/config_reference.py)."""

import copy
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from physgs.config import read_yaml, schema
from physgs.config_reference import reference, rows, type_words

ROOT = Path(__file__).resolve().parents[1]


def test_the_committed_reference_is_the_schemas():
    r = subprocess.run(
        [sys.executable, "tools/config_reference.py", "--check"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr


def test_every_key_of_the_config_file_has_a_row():
    paths = {r.path for r in rows(schema())}
    cfg = yaml.safe_load((ROOT / "config" / "trees.yaml").read_text())

    def keys(node, prefix):
        for k, v in node.items():
            yield f"{prefix}{k}"
            if isinstance(v, dict) and k not in (
                "profiles",
                "presets",
                "configs",
                "time_top_hz",
                "priors",
                "recipes",  # tree -> model -> a partial of train/models: checked by config_checks
            ):
                yield from keys(v, f"{prefix}{k}.")

    assert not set(keys(cfg, "")) - paths


def test_a_key_without_a_description_is_named():
    s = copy.deepcopy(schema())
    del s["properties"]["train"]["properties"]["warmup"]["description"]
    with pytest.raises(ValueError, match="train.warmup"):
        list(rows(s))


def test_type_words():
    defs = {"$defs": {"r": {"type": "number", "minimum": 0}}}
    assert type_words({"type": "integer", "minimum": 1, "maximum": 8}, defs) == "integer ≥ 1, ≤ 8"
    assert type_words({"type": "number", "exclusiveMinimum": 0}, defs) == "number > 0"
    assert type_words({"enum": ["a", "b"]}, defs) == "one of: a, b"
    assert type_words({"$ref": "#/$defs/r"}, defs) == "number ≥ 0"
    pair = {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}
    assert type_words(pair, defs) == "list of 2 of number"


def test_profile_values_land_in_their_columns():
    cfg = read_yaml(ROOT / "config" / "trees.yaml")
    text = reference(schema(), cfg)
    row = next(ln for ln in text.splitlines() if ln.startswith("| `train.iterations` |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    quick = cfg["profiles"]["quick"]["train"]["iterations"]
    paper = cfg["profiles"]["paper"]["train"]["iterations"]
    assert cells[2:5] == [f"`{cfg['train']['iterations']}`", f"`{quick}`", f"`{paper}`"]
    assert "**Reruns:** every training" in text
