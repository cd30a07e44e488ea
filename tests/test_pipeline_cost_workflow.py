"""What a cut run has left, on a real one: a copy of the finished quick DAG with one model's
training and evaluation undone (their outputs and benchmark files gone, as a session's end leaves
jobs in flight) plans those two jobs again, and each is priced by the run's own finished jobs."""

from __future__ import annotations

import os
import shutil
import statistics
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from physgs.experiments.cost import dry_run, left_cost, plan_jobs, read_costs
from workflow_helpers import ROOT

pytestmark = pytest.mark.slow
QUICK = ["profile=quick", 'trees=["sparse"]']  # as the quick_dag fixture ran
TARGET = "results/eval/sparse/seed0/ours_single.npz"


def _median_s(folder: Path) -> float:
    """The median wall seconds of the benchmark files in ``folder``, read here from the files."""
    return statistics.median(pd.read_csv(f, sep="\t")["s"].iloc[-1] for f in folder.glob("*.tsv"))


def test_a_cut_run_lists_and_prices_what_it_has_left(quick_dag, tmp_path):
    run = Path(shutil.copytree(quick_dag, tmp_path / "run", symlinks=True))
    bench = run / "results" / "benchmarks"
    for f in ("models/sparse/seed0/ours_single.pt", TARGET.removeprefix("results/")):
        (run / "results" / f).unlink()
    for stage in ("train", "evaluate"):
        (bench / stage / "sparse/seed0/ours_single.tsv").unlink()
    # one seed: no twin at another seed, so each is priced by its stage on its tree
    train_s, eval_s = (_median_s(bench / s / "sparse/seed0") for s in ("train", "evaluate"))
    planned = plan_jobs(dry_run([TARGET], QUICK, run, forceall=False))
    cost = left_cost([(r, b and str(run / b)) for r, b in planned], read_costs(bench), bench)
    assert cost["by_rule"] == {
        "train": (1, pytest.approx(train_s)),
        "evaluate": (1, pytest.approx(eval_s)),
    }
    assert cost["by_match"] == {"kind": 0, "tree": 2, "stage": 0} and not cost["unpriced"]
    tool = [sys.executable, str(ROOT / "tools" / "pipeline_cost.py"), "--left"]
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    r = subprocess.run(
        [*tool, "--target", TARGET, "--config", *QUICK],
        cwd=run, capture_output=True, text=True, env=env,
    )  # fmt: skip
    assert r.returncode == 0, (r.stdout + r.stderr)[-3000:]
    words = {ln.split()[0]: ln.split()[1:3] for ln in r.stdout.splitlines() if " jobs " in ln}
    assert words["train"] == words["evaluate"] == ["1", "jobs"] and words["left"] == ["2", "jobs"]
    assert "wall time left: at least" in r.stdout and "an estimate" in r.stdout
