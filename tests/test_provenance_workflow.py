"""Provenance on real runs of the quick DAG: a results folder copied without Snakemake's metadata is
not passed off as made with the new settings, and the record takes one run of one config (its
overrides in its stamp) and refuses tables of two."""

from __future__ import annotations

import json
import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from workflow_helpers import ROOT, snakemake, workflow_copy

pytestmark = pytest.mark.slow
QUICK = ["--config", "profile=quick", 'trees=["sparse"]']  # as the quick_dag fixture ran
TESTBED = "results/figures/testbed_sparse.png"  # the testbed's jobs alone: seconds
REMAKE = "remake them (and what is made from them) with: "


def _run(wd: Path, *args: str) -> subprocess.CompletedProcess:
    """``args`` (a command line) in ``wd``, its status and output as they are."""
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    return subprocess.run(args, cwd=wd, env=env, capture_output=True, text=True, timeout=900)


def test_a_copied_folder_made_with_other_settings_is_refused_naming_the_key(quick_dag, tmp_path):
    """The copied folder holds no metadata, so Snakemake takes its files as up to date: the
    plan's check refuses them, naming the file and the key, and the command it gives remakes
    them with the new settings. The folder copied is the quick DAG's (made with QUICK)."""
    wd = workflow_copy(tmp_path / "copy")
    # what travels: results/, no .snakemake/
    shutil.copytree(quick_dag / "results", wd / "results", symlinks=True)
    # the same settings agree
    same = snakemake(wd, "--cores", "2", TESTBED, *QUICK)
    assert "provenance: the 4 files this plan reads as made agree" in same.stderr
    cmd = [sys.executable, "-m", "snakemake", "--cores", "2", TESTBED, *QUICK]
    other = _run(wd, *cmd, 'testbed={"resolution": 16}')
    out = other.stdout + other.stderr
    assert other.returncode != 0, out[-3000:]
    assert "results/testbed/sparse/observed.npz (rule `testbed_dataset`)" in out
    assert "`params.settings.testbed.resolution` 32 when it was made, 16 in this plan" in out
    remake = next(ln for ln in out.splitlines() if ln.startswith(REMAKE))[len(REMAKE) :]
    assert "--forcerun results/testbed/sparse/observed.npz" in remake
    words = shlex.split(remake)
    assert words[0] == "snakemake"
    _ = snakemake(wd, *words[1:])
    frames = np.load(wd / "results" / "testbed" / "sparse" / "observed.npz")["frames"]
    assert frames.shape[2:4] == (16, 16)


def _readme(wd: Path) -> Path:
    path = wd / "README.md"
    path.write_text("# x\n\n<!-- record:begin -->\nold\n<!-- record:end -->\n")
    return path


def _record(wd: Path, *overrides: str, at: Path | None = None) -> subprocess.CompletedProcess:
    """tools/record.py on ``wd``'s run, into ``record`` (a README of its own), run in ``wd`` or,
    given ``at``, in that other folder naming the run's folder by its path."""
    return _run(
        at or wd,
        sys.executable,
        str(ROOT / "tools" / "record.py"),
        str(wd / "results") if at else "results",
        "--out",
        "record",
        "--readme",
        str(_readme(at or wd)),
        "--wall-s",
        "60",
        "--commit",
        "abc1234",
        *overrides,
    )


@pytest.fixture
def run(quick_dag, tmp_path) -> Path:
    """A copy of the finished quick DAG, its metadata and times kept."""
    return Path(shutil.copytree(quick_dag, tmp_path / "run", symlinks=True))


def test_a_run_made_with_overrides_is_recorded_with_them(run):
    """The quick DAG was made with `--config profile=quick trees=[sparse]`: recorded with them,
    they are in its stamp and the README's block; a `--configfile` counts the same."""
    rec = _record(run, *QUICK)
    assert rec.returncode == 0, (rec.stdout + rec.stderr)[-3000:]
    stamp = json.loads((run / "record" / "stamp.json").read_text())
    assert stamp["overrides"] == QUICK
    assert stamp["profile"] == "quick"
    assert (
        "made with `--config profile=quick 'trees=[\"sparse\"]'`" in (run / "README.md").read_text()
    )
    # recorded from another folder naming the run's: the run's checkout's config and plan
    away = run.parent / "away"
    away.mkdir()
    far = _record(run, *QUICK, at=away)
    assert far.returncode == 0, (far.stdout + far.stderr)[-3000:]
    assert json.loads((away / "record" / "stamp.json").read_text()) == stamp
    assert (away / "README.md").read_text() == (run / "README.md").read_text()
    # without them the run is another config's: refused, saying to give them
    bare = _record(run)
    assert bare.returncode != 0 and "giving the run's own overrides" in bare.stderr
    # a --configfile is resolved as the Snakefile resolves it: the hash a table carries
    (run / "digits.yaml").write_text("report:\n  tab_testbed:\n    digits: 4\n")
    snakemake(
        run, "--cores", "2", "results/tables/tab_testbed.csv", "--configfile", "digits.yaml", *QUICK
    )
    made = pd.read_csv(run / "results/tables/tab_testbed.csv", dtype={"config_hash": str})
    tool = _tool()
    cwd = Path.cwd()
    try:
        os.chdir(run)
        here = tool._config_hash(QUICK[1:], ["digits.yaml"])
        assert here != tool._config_hash(QUICK[1:], [])
    finally:
        os.chdir(cwd)
    assert set(made["config_hash"]) == {here}


def _tool():
    import importlib.util

    spec = importlib.util.spec_from_file_location("record_tool", ROOT / "tools" / "record.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_a_record_of_tables_of_two_configs_is_refused_naming_each_and_the_key(run):
    """One table rebuilt alone under an edited config: the record names the tables of the old
    config and the key the edit changed, and writes nothing."""
    (run / "edit.yaml").write_text("models:\n  mlp:\n    width: 96\n")
    edit = ["--configfile", "edit.yaml", *QUICK]
    snakemake(run, "--cores", "2", "results/tables/tab_fit.tex", *edit)
    fit = pd.read_csv(run / "results/tables/tab_fit.csv", dtype={"config_hash": str})
    psnr = pd.read_csv(run / "results/tables/tab_psnr.csv", dtype={"config_hash": str})
    assert set(fit["config_hash"]) != set(psnr["config_hash"])  # the repro: two configs
    rec = _record(run, *edit)
    err = rec.stderr
    assert rec.returncode != 0, (rec.stdout + err)[-3000:]
    assert "tables/tab_psnr.csv: config_hash" in err
    assert "tables/tab_fit.csv: config_hash" not in err
    # what was made from the retrained fields names the key that changed
    assert "`params.job.settings.mlp.width` 128 then, 96 now" in err, err
    assert not (run / "record" / "stamp.json").exists()
