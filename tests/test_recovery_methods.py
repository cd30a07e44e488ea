"""The one list of recovery methods (registry.RECOVERY_METHODS): every method that recovers omega
and zeta is one entry, with its configurations and K from the config, and the rule its entry
names writes its record at the one path template."""

import re
import subprocess
import sys

import pytest

from physgs.models import registry
from physgs.models.registry import (
    BLIND_PRIORS,
    RECOVERY_METHODS,
    models_of,
    recovery_configs,
    recovery_label,
    recovery_plan,
)
from oracles import quick_config
from workflow_helpers import ROOT


def test_every_prior_and_every_method_beside_them_is_one_entry():
    assert set(models_of("prior")) | set(BLIND_PRIORS) | {"tracks", "oma"} == set(RECOVERY_METHODS)
    assert [m for m, rm in RECOVERY_METHODS.items() if rm.paper] == ["ours"]
    assert list(RECOVERY_METHODS)[0] == "ours"  # ours' rows first, the reference
    assert recovery_label("ours") == ""  # the paper's rows: their configuration alone
    assert recovery_label("ours_chain") == registry.label("ours_chain")
    assert recovery_label("tracks") == r"\emph{2D tracks}"


def test_each_method_runs_in_its_configurations_with_its_k():
    cfg = quick_config()
    configs = {c: int(v["K"]) for c, v in cfg["models"]["configs"].items()}
    assert recovery_configs("ours", cfg) == configs
    assert recovery_configs("ours_chain", cfg) == configs
    # quick: tracks/K and oma/K are the integer 2 (32 px frames hold few tracks and cells)
    assert recovery_configs("tracks", cfg) == {c: 2 for c in cfg["tracks"]["configs"]}
    assert recovery_configs("oma", cfg) == {c: 2 for c in cfg["oma"]["configs"]}
    for m in BLIND_PRIORS:
        assert recovery_configs(m, cfg) == {"single": configs["single"]}
    same = {**cfg, "tracks": {**cfg["tracks"], "K": "same"}}
    assert recovery_configs("tracks", same) == {c: configs[c] for c in cfg["tracks"]["configs"]}
    none = {**cfg, "oma": {**cfg["oma"], "configs": []}}
    assert "oma" not in recovery_plan(none) and "oma" in recovery_plan(cfg)
    with pytest.raises(ValueError, match="unknown recovery method"):
        recovery_configs("mlp", cfg)


def test_the_rule_each_entry_names_writes_its_record():
    """One dry run of one record per method: the planned job of each is its entry's rule, at the
    one record template."""
    targets = [f"results/recovery/sparse/seed0/{m}_single.json" for m in RECOVERY_METHODS]
    r = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "--forceall", "--nolock", "--cores", "1"]
        + ["--config", "profile=quick", 'trees=["sparse"]', "--", *targets],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr[-2000:] + r.stdout[-2000:]
    blocks = re.split(r"\n(?=(?:local)?rule \w+:)", r.stdout)
    for m, rm in RECOVERY_METHODS.items():
        made = [
            b for b in blocks if f"/{m}_single.json" in b.split("output:", 1)[-1].split("\n")[0]
        ]
        assert len(made) == 1, m
        assert re.match(rf"(?:local)?rule {rm.rule}:", made[0]), (m, made[0][:80])
