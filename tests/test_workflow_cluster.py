"""Every job is self-contained: the quick DAG runs through a real executor plugin
(cluster-generic) that submits each job as a separate, detached process, as a cluster scheduler
would. Starting from the quick DAG's testbed (built by the session fixture), train -> recovery
plus the null control run through the plugin: every kind of job that reads a dataset and writes a
checkpoint or scores, within the suite's time budget (the full DAG runs locally in
test_workflow_e2e.py)."""

from __future__ import annotations

import shutil
import stat

import pytest

from physgs.recovery.record import load_null, load_recovery

from workflow_helpers import snakemake, workflow_copy

pytestmark = pytest.mark.slow

SUBMIT = """#!/usr/bin/env bash
# A local stand-in for sbatch/qsub: run the job script detached, print a job id.
setsid bash "$1" > "$1.out" 2>&1 < /dev/null &
echo $!
"""


def test_quick_dag_through_cluster_generic_executor(tmp_path, quick_dag):
    wd = workflow_copy(tmp_path / "wf")
    shutil.copytree(quick_dag / "results" / "testbed", wd / "results" / "testbed")
    submit = wd / "submit.sh"
    submit.write_text(SUBMIT)
    submit.chmod(submit.stat().st_mode | stat.S_IEXEC)
    proc = snakemake(
        wd,
        "--executor",
        "cluster-generic",
        "--cluster-generic-submit-cmd",
        str(submit),
        "--jobs",
        "2",
        "--latency-wait",
        "30",
        "--seconds-between-status-checks",
        "1",
        "--default-resources",
        "mem_mb=2000",
        "runtime=20",
        "--config",
        "profile=quick",
        'trees=["sparse"]',
        "--",
        "results/recovery/sparse/seed0/ours_single.json",
        "results/recovery/sparse/seed0/null_K32.json",
        timeout=900,
    )
    log = proc.stdout + proc.stderr
    # every job went through the plugin, each with its own external job id
    assert "cluster-generic" in log or "Submitted job" in log
    assert log.count("Submitted job") == 3, log[-3000:]  # train, recovery, null
    rec = load_recovery(wd / "results" / "recovery" / "sparse" / "seed0" / "ours_single.json")
    null = load_null(wd / "results" / "recovery" / "sparse" / "seed0" / "null_K32.json")
    assert rec.match.n_parts == 32 and 0 <= rec.match.n_trusted <= 32
    assert null.nearest_bone_gap > 0
