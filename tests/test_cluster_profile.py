"""The SLURM cluster profile without a cluster: the sbatch arguments the executor plugin sends
(a stand-in `sbatch` on PATH records them), and requests no node can meet refused before any
submission (a stand-in `sinfo` describes the partitions). The real SLURM run: test_slurm.py."""

from __future__ import annotations

import base64
import os
import re
import shutil
import stat
import subprocess
import sys
import time

import pytest
import yaml

from physgs.cluster import Partition, Request, parse_sinfo, parse_time_limit, problems
from workflow_helpers import ROOT, workflow_copy

pytest.importorskip("snakemake_executor_plugin_slurm", reason='needs pip install -e ".[cluster]"')

SBATCH = """#!/bin/sh
# stand-in sbatch: record the arguments, refuse the job (nothing runs)
printf '%s\\n' "$*" >> "$SBATCH_LOG"
exit 1
"""
SINFO = """#!/bin/sh
printf 'cpu*|2|21000|infinite\\ngpu|8|64000|2-00:00:00\\n'
"""
# The plugin (2.8) refuses to import where sinfo exists but neither sacct nor squeue does, and
# hangs when sacct is missing while it guesses an account: a stand-in sacct that fails, as
# SLURM 22.05's does for that query (the plugin then goes on without an account).
SACCT = """#!/bin/sh
echo "sacct: stand-in, no accounting" >&2
exit 1
"""
PARTITIONS = parse_sinfo("cpu*|2|21000|infinite\ngpu|8|64000|2-00:00:00\n")


def test_sinfo_is_parsed():
    assert PARTITIONS["cpu"] == Partition("cpu", True, 2, 21000, float("inf"))
    assert PARTITIONS["gpu"].max_minutes == 2 * 1440 and not PARTITIONS["gpu"].default
    assert parse_time_limit("1:30:00") == 90 and parse_time_limit("45") == 45
    assert parse_time_limit("10:30") == pytest.approx(10.5)


def test_requests_beyond_every_node_are_named():
    reqs = [
        Request("train", 8, 4000, 60, None),
        Request("evaluate", 1, 99999, 30, None),
        Request("figure", 1, 1000, 5000, "gpu"),
        Request("table", 1, 1000, 5, "bigmem"),
        Request("recovery", 1, 2000, 10, None),
    ]
    lines = problems(reqs, PARTITIONS)
    assert any(line.startswith("rule train: threads=8") for line in lines), lines
    assert any(line.startswith("rule evaluate: mem_mb=99999") for line in lines), lines
    assert any(line.startswith("rule figure: runtime=5000") for line in lines), lines
    assert any("slurm_partition=bigmem does not exist" in line for line in lines), lines
    assert not any("recovery" in line for line in lines) and len(lines) == 4


def test_the_profile_names_no_account_or_partition():
    """A placeholder account stops the first run ('CHANGE_ME appears to be invalid')."""
    spec = yaml.safe_load((ROOT / "workflow/profiles/cluster/config.yaml").read_text())
    assert "slurm_account" not in spec.get("default-resources", {})
    assert "slurm_partition" not in spec.get("default-resources", {})
    assert all(int(n) == 1 for n in spec.get("set-threads", {}).values())


def _fake_slurm(tmp_path):
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for name, text in (("sbatch", SBATCH), ("sinfo", SINFO), ("sacct", SACCT)):
        p = bin_dir / name
        p.write_text(text)
        p.chmod(p.stat().st_mode | stat.S_IEXEC)
    wd = workflow_copy(tmp_path / "wf")
    # the train job's only input, present: train is the first (and only) job submitted
    (wd / "results/testbed/sparse").mkdir(parents=True)
    (wd / "results/testbed/sparse/observed.npz").touch()
    log = tmp_path / "sbatch_calls.txt"
    env = dict(os.environ, SBATCH_LOG=str(log), PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    return wd, env, log


def _run(wd, env, *args):
    cmd = [sys.executable, "-m", "snakemake", "--workflow-profile", "workflow/profiles/cluster"]
    cmd += ["--retries", "0", "--slurm-init-seconds-before-status-checks", "1"]
    cmd += [
        "--seconds-between-status-checks",
        "1",
        "--config",
        "profile=quick",
        'trees=["sparse"]',
        *args,
    ]
    cmd += ["--", "results/models/sparse/seed0/static_single.pt"]
    return subprocess.run(cmd, cwd=wd, env=env, capture_output=True, text=True, timeout=300)


@pytest.mark.slow
def test_train_on_a_gpu_partition_sends_gres_and_partition(tmp_path):
    wd, env, log = _fake_slurm(tmp_path)
    proc = _run(wd, env, "--set-resources", "train:slurm_partition=gpu", "train:gres=gpu:1")
    assert proc.returncode != 0  # the stand-in refuses every job
    calls = log.read_text().splitlines()
    assert len(calls) == 1, proc.stdout[-3000:] + proc.stderr[-3000:]
    args = calls[0].split(" --wrap=")[0].split()
    assert "--gres=gpu:1" in args and args[args.index("-p") + 1] == "gpu", args
    assert args[args.index("--mem") + 1] == "4000" and "--cpus-per-task=1" in args, args
    assert "-A" not in args  # the account is the cluster's default
    # the job on the node sees its GPU request (physgs.device.resolve_device reads it there)
    wrap = calls[0].split(" --wrap=", 1)[1]
    sent = [base64.b64decode(t).decode() for t in re.findall(r"base64//([A-Za-z0-9+/=]+)", wrap)]
    assert any(re.fullmatch(r"(train:)?gres=.?gpu:1.?", t) for t in sent), sent


@pytest.mark.slow
def test_a_request_no_node_meets_is_refused_before_submission(tmp_path):
    wd, env, log = _fake_slurm(tmp_path)
    proc = _run(wd, env, "--cores", "16", "--set-threads", "train=8")
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and not log.exists(), out[-3000:]  # nothing submitted
    assert "rule train: threads=8 but partition cpu's nodes have at most 2 CPUs" in out, out[-3000:]


def _slurm_jobs(dry_run_log: str) -> list[tuple[str | None, list[str]]]:
    """(group or None, member rules) of each SLURM job a cluster-profile dry run plans."""
    jobs = []
    for block in re.split(
        r"\n(?=\[[^\]\n]+\](?: Group job \w+|\n(?:local)?rule \w+))", dry_run_log
    ):
        group = re.match(r"\[[^\]\n]+\] Group job (\w+)", block)
        rules = re.findall(r"^\s*(?:local)?rule (\w+):", block, re.M)
        if group or rules:
            jobs.append((group.group(1) if group else None, rules))
    return jobs


@pytest.mark.slow
def test_no_group_job_serialises_the_tail_of_the_run(tmp_path):
    """The tables and the ledger read every job: grouped with the per-model jobs they joined all
    of "post" into one SLURM job of ~60 members that ran one after another after the last
    training. The cheap jobs still travel in groups of a few chains."""
    wd, env, _ = _fake_slurm(tmp_path)
    cmd = [
        sys.executable,
        "-m",
        "snakemake",
        "-n",
        "--workflow-profile",
        "workflow/profiles/cluster",
    ]
    cmd += ["--config", "profile=quick", 'trees=["sparse"]', "--", "all"]
    proc = subprocess.run(cmd, cwd=wd, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    jobs = _slurm_jobs(proc.stdout)
    post = [rules for group, rules in jobs if group == "post"]
    grouped = {r for group, rules in jobs if group for r in rules}
    assert len(post) >= 2 and max(map(len, post)) <= 20, [len(p) for p in post]
    assert not grouped & {"table", "figure", "claims", "summary", "testbed_stats"}, grouped
    assert any(group == "fit" and "evaluate" in rules for group, rules in jobs)


def test_the_suites_snakemake_calls_wait_on_no_slurm_controller():
    """The suite without its `slurm` tests points SLURM at a configuration with no controller
    (conftest.py), so a `snakemake` call does not wait for a controller that is down, as it did
    for 1 s each where SLURM's packages were installed."""
    import conftest
    from conftest import NO_CONTROLLER

    assert sys.modules["conftest"] is conftest and conftest.MACHINE_SLURM_CONF != str(NO_CONTROLLER)
    assert os.environ.get("SLURM_CONF") == str(NO_CONTROLLER) and NO_CONTROLLER.is_file()
    if shutil.which("scontrol"):  # the packages are installed: the probe the plugin runs
        t0 = time.perf_counter()
        subprocess.run(["scontrol", "show", "config"], capture_output=True, timeout=30)
        assert time.perf_counter() - t0 < 0.5
