"""Snakemake wiring of the training rule (dry runs only)."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from physgs.models.fields import native_bf16

ROOT = Path(__file__).resolve().parents[1]


def _dry_run(*targets, profile="quick"):
    # the default profile's bf16 fields stop the plan on a CPU without native bf16 (tested in
    # test_field_precision); there the plan is checked with the float32 overlay it names
    overlay = [] if profile == "quick" or native_bf16() else ["--configfile", "config/float32.yaml"]
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "snakemake",
            "-n",
            "--forceall",  # the whole plan, whatever results/ the checkout already holds
            "--cores",
            "2",
            *overlay,
            "--config",
            f"profile={profile}",
            "--",
            *targets,
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.fixture(scope="module")
def plan():
    """One dry run of every training job and the true-motion ceiling (each dry run costs
    seconds of DAG building, so both tests read this one)."""
    r = _dry_run(
        "train_all",
        *[
            f"results/models/{t}/seed0/truth_motion_single.pt"
            for t in ("sparse", "medium", "dense")
        ],
    )
    assert r.returncode == 0, r.stderr[-2000:] + r.stdout[-2000:]
    return r.stdout


def _blocks(out, rule):
    return re.findall(rf"rule {rule}:\n((?:    .*\n)+)", out)


def test_only_the_reference_rule_reads_the_truth(plan):
    """The true-motion ceiling is trained by its own rule, the only one that reads truth.npz."""
    ref = _blocks(plan, "train_reference")
    assert len(ref) == 3
    for b in ref:
        inputs = re.search(r"input: (.*)", b).group(1)
        assert "truth.npz" in inputs and "truth_motion_single.pt" in b
    text = (ROOT / "workflow" / "rules" / "train.smk").read_text()
    rules = re.split(r"\nrule ", text)
    readers = [
        b.split(":", 1)[0]
        for b in rules[1:]
        if re.search(r"TRUTH|truth_input", b.split("output:", 1)[0])
    ]
    assert readers == ["train_reference"], readers


def test_train_jobs_read_only_the_observed_dataset(plan):
    blocks = _blocks(plan, "train")
    # 3 trees x (5 baselines single + each prior, ours and the chained, single/joint32/joint96)
    assert len(blocks) == 33
    for b in blocks:
        inputs = re.search(r"input: (.*)", b).group(1)
        assert re.fullmatch(r"results/testbed/\w+/observed\.npz", inputs.strip()), inputs
        assert "truth" not in inputs and "truth_motion" not in b
        assert "mem_mb=" in b and "runtime=" in b and "benchmark:" in b and "log:" in b
    # threads are declared (a 1-thread job prints no threads line in the plan)
    assert re.search(
        r"rule train:(?:\n    .*)*\n    threads: \d",
        (ROOT / "workflow" / "rules" / "train.smk").read_text(),
    )


def test_tab_damping_plans_ours_on_both_testbeds_of_each_tree():
    """tab_damping (default profile: the quick one builds no damping testbed) trains the priors
    alone (ours and the chained prior), in the benchmark's configurations, per seed, on each tree
    and its <tree>_damping copy, whose dataset is built by the same testbed rule with the damping
    variant; the forcing-free priors in their one configuration there too; and ours in the 2D-track
    control's other configurations on the faithful trees (the control scores every configuration
    of a tree and seed in one job)."""
    from physgs import config as pconfig
    from physgs.models.registry import BLIND_CONFIG, BLIND_PRIORS, models_of

    cfg = pconfig.load(ROOT / "config" / "trees.yaml", "default")
    db = cfg["damping_benchmark"]
    r = _dry_run("results/tables/tab_damping.tex", profile="default")
    assert r.returncode == 0, r.stderr[-2000:] + r.stdout[-2000:]
    ids = (*models_of("prior"), *BLIND_PRIORS)
    priors = "|".join(sorted(ids, key=len, reverse=True))
    trained = set(re.findall(rf"results/models/(\w+)/seed(\d+)/({priors})_(\w+)\.pt", r.stdout))
    want = {
        (tb, str(s), m, c)
        for t in db["trees"]
        for tb in (t, f"{t}_damping")
        for s in cfg["seeds"]
        for m in models_of("prior")
        for c in db["configs"]
    }
    want |= {
        (t, str(s), "ours", c)
        for t in db["trees"]
        for s in cfg["seeds"]
        for c in cfg["tracks"]["configs"]
    }
    want |= {  # the forcing-free priors' rows, in their one configuration
        (tb, str(s), m, BLIND_CONFIG)
        for t in db["trees"]
        for tb in (t, f"{t}_damping")
        for s in cfg["seeds"]
        for m in BLIND_PRIORS
    }
    assert trained == want
    # with testbed_seeds each seed builds its own damping instance (testbed_dataset_seeded)
    rule = "testbed_dataset_seeded" if cfg["testbed_seeds"] else "testbed_dataset"
    built = [b for b in _blocks(r.stdout, rule) if "_damping/" in b and "observed.npz" in b]
    per_tree = len(cfg["seeds"]) if cfg["testbed_seeds"] else 1
    assert len(built) == len(db["trees"]) * per_tree
