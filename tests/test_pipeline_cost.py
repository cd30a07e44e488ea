"""physgs.experiments.cost: job-seconds from Snakemake benchmark files, by stage and seed."""

import subprocess
import time

import pytest

from physgs.experiments.cost import (
    by_job,
    earlier_segments,
    extra_seed_wall_s,
    left_cost,
    plan_cost,
    plan_jobs,
    read_costs,
    segment_seconds,
    summarise,
)

HEADER = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"


def _write(root, rel, s):
    f = root / rel
    f.parent.mkdir(parents=True, exist_ok=True)
    f.write_text(HEADER + f"{s}\t0:00:00\t1\t1\t1\t1\t0\t0\t50\t1.0\n")


@pytest.fixture
def bench(tmp_path):
    _write(tmp_path, "testbed/sparse.tsv", 50.0)
    _write(tmp_path, "testbed/stats_sparse.tsv", 5.0)
    _write(tmp_path, "testbed/sparse_damping.tsv", 40.0)
    _write(tmp_path, "train/sparse/seed0/ours_single.tsv", 100.0)
    _write(tmp_path, "train/sparse/seed1/ours_single.tsv", 120.0)
    _write(tmp_path, "train/sparse_damping/seed0/ours_single.tsv", 80.0)
    _write(tmp_path, "evaluate/sparse/seed0/ours_single.tsv", 20.0)
    _write(tmp_path, "speed_accuracy/seed1/K-8.tsv", 30.0)
    _write(tmp_path, "testbed/sparse_seed1.tsv", 60.0)
    _write(tmp_path, "testbed/stats_sparse_damping_seed1.tsv", 4.0)
    return tmp_path


def test_stage_seed_and_damping_come_from_the_path(bench):
    jobs = {j.path: j for j in read_costs(bench)}
    assert jobs["train/sparse/seed1/ours_single.tsv"].seed == 1
    assert jobs["testbed/sparse.tsv"].seed is None
    assert jobs["testbed/sparse_seed1.tsv"].seed == 1  # a seeded testbed is that seed's
    assert jobs["train/sparse_damping/seed0/ours_single.tsv"].damping
    assert jobs["testbed/sparse_damping.tsv"].damping and not jobs["testbed/sparse.tsv"].damping
    assert jobs["testbed/stats_sparse_damping_seed1.tsv"].damping
    assert jobs["testbed/stats_sparse_damping_seed1.tsv"].seed == 1


def test_sums_by_seed_shared_and_damping(bench):
    s = summarise(read_costs(bench))
    assert s["shared_s"] == pytest.approx(50 + 5 + 40)
    assert s["per_seed"] == pytest.approx({0: 100 + 80 + 20, 1: 120 + 30 + 60 + 4})
    assert s["damping_s"] == pytest.approx(40 + 80 + 4)
    assert s["damping_per_seed"] == pytest.approx({0: 80, 1: 4})
    assert s["by_stage"]["train"] == pytest.approx({0: 180, 1: 120})
    assert s["total_s"] == pytest.approx(95 + 200 + 214)


def test_each_job_costs_its_seconds_over_every_tree_and_seed(bench):
    got = by_job(read_costs(bench))
    assert got[("train", "ours_single")] == (3, pytest.approx(100 + 120 + 80))  # 2 seeds, damping
    assert got[("testbed", "sparse")] == (2, pytest.approx(50 + 60))  # the seeded one with it
    assert got[("testbed", "stats_sparse_damping")] == (1, pytest.approx(4.0))
    assert list(got)[0] == ("train", "ours_single")  # costliest first
    assert sum(n for n, _ in got.values()) == 10
    _write(bench, "kselect/sparse/seed0.tsv", 7.0)  # a file named by its seed alone
    assert by_job(read_costs(bench))[("kselect", "-")] == (1, pytest.approx(7.0))


def test_one_more_seed_scales_by_the_runs_own_packing(bench):
    s = summarise(read_costs(bench))
    # mean seed 207 job-s; the run took 305.4 s of wall for 509 job-s (0.6 wall per job-second)
    assert extra_seed_wall_s(s, run_wall_s=305.4) == pytest.approx(207 * 305.4 / 509)
    with pytest.raises(ValueError, match="run_wall_s"):
        extra_seed_wall_s(s, run_wall_s=0)


def test_missing_or_foreign_files_are_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="no benchmark folder"):
        read_costs(tmp_path / "absent")
    (tmp_path / "x").mkdir()
    with pytest.raises(FileNotFoundError, match="no benchmark files"):
        read_costs(tmp_path / "x")
    (tmp_path / "x" / "bad.tsv").write_text("a\tb\n1\t2\n")
    with pytest.raises(ValueError, match="bad.tsv"):
        read_costs(tmp_path / "x")


def test_resources_by_stage_read_cpu_and_peak_memory(tmp_path):
    from physgs.experiments.cost import resources_by_stage

    rows = {"train/a/seed0/x.tsv": (10.0, 300.5, 9.0), "train/a/seed1/x.tsv": (30.0, 700.0, 25.0)}
    for rel, (s, rss, cpu) in rows.items():
        f = tmp_path / rel
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(HEADER + f"{s}\t0:00:10\t{rss}\t1\t1\t1\t0\t0\t90\t{cpu}\n")
    f = tmp_path / "evaluate/a/seed0/x.tsv"
    f.parent.mkdir(parents=True)
    f.write_text(HEADER + "5.0\t0:00:05\t-\t-\t-\t-\t-\t-\t-\t-\n")  # psutil measured nothing
    r = resources_by_stage(read_costs(tmp_path))
    assert r["train"] == {
        "jobs": 2,
        "wall_mean_s": 20.0,
        "wall_max_s": 30.0,
        "cpu_mean_s": 17.0,
        "cpu_max_s": 25.0,
        "rss_max_mb": 700.0,
    }
    assert r["evaluate"]["jobs"] == 1 and r["evaluate"]["wall_max_s"] == 5.0
    assert r["evaluate"]["rss_max_mb"] != r["evaluate"]["rss_max_mb"]  # NaN, not 0


DRY_RUN = """
Job stats:
job                count
---------------  -------
testbed_dataset        1
train                  2
recovery               1
table                  1
total                  5

[Thu Nov 26 05:30:42 2026]
rule testbed_dataset:
    output: results/testbed/sparse/observed.npz, results/testbed/sparse/truth.npz
    log: logs/testbed/sparse.log
    jobid: 1
    benchmark: results/benchmarks/testbed/sparse.tsv
    wildcards: tree=sparse

[Thu Nov 26 05:30:42 2026]
localrule train:
    input: results/testbed/sparse/observed.npz
    benchmark: results/benchmarks/train/sparse/seed0/ours_single.tsv
    wildcards: tree=sparse, seed=0, model=ours, config=single

rule recovery:
    output: results/recovery/sparse/seed0/ours_single.json

rule train:
    benchmark: results/benchmarks/train/dense/seed0/ours_single.tsv

localrule table:
    output: results/tables/tab_null.tex
"""


def test_a_plan_is_read_job_by_job_with_its_benchmark():
    assert plan_jobs(DRY_RUN) == [
        ("testbed_dataset", "results/benchmarks/testbed/sparse.tsv"),
        ("train", "results/benchmarks/train/sparse/seed0/ours_single.tsv"),
        ("recovery", None),
        ("train", "results/benchmarks/train/dense/seed0/ours_single.tsv"),
        ("table", None),
    ]


def test_a_printout_whose_jobs_do_not_add_up_to_its_stats_is_refused():
    with pytest.raises(ValueError, match="job-stats table"):
        plan_jobs(DRY_RUN.replace("train                  2", "train                  3"))
    with pytest.raises(ValueError, match="says nothing"):
        plan_jobs(DRY_RUN.split("[Thu", 1)[1])  # job blocks without a stats table
    assert plan_jobs("Building DAG of jobs...\nNothing to be done.\n") == []
    with pytest.raises(ValueError, match="job blocks read"):
        plan_jobs(DRY_RUN.replace("rule recovery:", "rule recovery (group x):"))


def test_a_plan_costs_the_measured_seconds_of_its_jobs(bench):
    planned = [
        (r, b.replace("results/benchmarks", str(bench)) if b else None)
        for r, b in plan_jobs(DRY_RUN)
    ]
    cost = plan_cost(planned, read_costs(bench), bench)
    assert cost["job_s"] == 50.0 + 100.0  # the testbed and the sparse training
    assert cost["by_rule"] == {"testbed_dataset": (1, 50.0), "train": (1, 100.0)}
    assert cost["unmeasured"] == {"train": 1}  # the dense training did not run
    assert cost["light"] == {"recovery": 1, "table": 1}


def test_a_cut_run_prices_each_job_left_by_its_nearest_finished_jobs(bench):
    b = f"{bench}/"
    planned = [
        ("train", b + "train/sparse/seed2/ours_single.tsv"),  # itself at seeds 0, 1: 100, 120
        ("train", b + "train/sparse_damping/seed1/mlp_single.tsv"),  # its tree's trainings: 80
        ("evaluate", b + "evaluate/dense/seed0/ours_single.tsv"),  # its stage's one job: 20
        ("testbed_dataset_seeded", b + "testbed/sparse_seed2.tsv"),  # sparse, sparse_seed1: 50, 60
        ("oma_identify", b + "oma/sparse/seed0/modes.tsv"),  # no oma job finished
        ("table", None),
    ]
    cost = left_cost(planned, read_costs(bench), bench)
    assert cost["by_rule"] == {
        "train": (2, pytest.approx(110.0 + 80.0)),
        "evaluate": (1, pytest.approx(20.0)),
        "testbed_dataset_seeded": (1, pytest.approx(55.0)),
    }
    assert cost["job_s"] == pytest.approx(110.0 + 80.0 + 20.0 + 55.0)
    assert cost["by_match"] == {"kind": 2, "tree": 1, "stage": 1}
    assert cost["unpriced"] == {"oma_identify": 1} and cost["light"] == {"table": 1}
    assert cost["done_s"] == pytest.approx(509.0)  # every finished job, as summarise counts


def _timed(root, rel, s, end):
    """A benchmark file of a job of ``s`` seconds that ended at ``end`` (epoch seconds)."""
    import os

    _write(root, rel, s)
    os.utime(root / rel, (end, end))


def test_occupancy_places_each_job_in_time_and_counts_idle_cores(tmp_path):
    from physgs.experiments.cost import occupancy

    t = 1_000_000.0
    # core A: train 0-100 s, then evaluate 100-150; core B: train 0-60, then nothing until a
    # tracks job 200-260 (60-100 one core idle, 150-200 no job at all, 200-260 one idle)
    _timed(tmp_path, "train/sparse/seed0/a.tsv", 100.0, t + 100)
    _timed(tmp_path, "evaluate/sparse/seed0/a.tsv", 50.0, t + 150)
    _timed(tmp_path, "train/sparse/seed0/b.tsv", 60.0, t + 60)
    _timed(tmp_path, "tracks/sparse/seed0/c.tsv", 60.0, t + 260)
    occ = occupancy(read_costs(tmp_path), cores=2, bin_s=100.0)
    assert occ.busy == pytest.approx([1.6, 0.5, 1.0])  # (100 + 60) / 100, 50 / 100, 60 / 60
    assert occ.running[0] == pytest.approx({"train": 160.0})
    assert occ.running[1] == pytest.approx({"evaluate": 50.0})
    assert occ.idle_core_s == pytest.approx(40.0 + 50.0 + 60.0)  # 60-100, 100-150, 200-260
    assert occ.paused_s == pytest.approx(50.0)
    with pytest.raises(ValueError, match="cores >= 1"):
        occupancy(read_costs(tmp_path), cores=0)


def test_a_training_estimate_counts_the_plan_and_never_guesses_a_rate():
    from physgs.experiments.cost import training_estimate

    dry = "\n".join(
        [
            "job count",
            "---  ---",
            "train 3",
            "kselect 1",
            "total 4",
            "",
            "rule train:",
            "    benchmark: results/benchmarks/train/medium/seed0/ours_chain_joint32.tsv",
            "rule train:",
            "    benchmark: results/benchmarks/train/medium_damping/seed1/ours_chain_joint32.tsv",
            "rule train:",
            "    benchmark: results/benchmarks/train/dense/seed1/d3dgs_wind_single.tsv",
            "rule kselect:",
            "    benchmark: results/benchmarks/kselect/medium/seed0.tsv",
        ]
    )
    planned = plan_jobs(dry)
    rates = {("medium", "ours_chain", "joint32"): 0.3, ("medium", "static", "single"): 0.1}
    est = training_estimate(planned, rates, ["single", "joint32"], iterations=1000, warmup=100)
    # two rated trainings (the damping testbed costs as its tree): 100 x 0.1 + 900 x 0.3 each
    assert est["jobs"] == 2 and est["cpu_s"] == pytest.approx(2 * (10 + 270))
    assert est["per_seed"] == {0: 1, 1: 2}  # K selection is not a training
    assert est["unrated"] == {("dense", "d3dgs_wind", "single"): 1}  # counted apart, no guess


def test_a_training_estimate_prices_each_job_at_its_own_budget():
    """A profile's recipes give models their own budgets: each job is priced at its own, and a
    damping testbed's job is asked for by its full tree id (its recipe is its tree's)."""
    from physgs.experiments.cost import training_estimate

    dry = "\n".join(
        [
            "job count",
            "---  ---",
            "train 2",
            "total 2",
            "",
            "rule train:",
            "    benchmark: results/benchmarks/train/medium/seed0/mlp_single.tsv",
            "rule train:",
            "    benchmark: results/benchmarks/train/medium_damping/seed0/ours_single.tsv",
        ]
    )
    rates = {
        ("medium", "mlp", "single"): 0.2,
        ("medium", "ours", "single"): 0.5,
        ("medium", "static", "single"): 0.1,
    }
    asked = []

    def budget(tree, model):
        asked.append((tree, model))
        return {"mlp": (4000, 200), "ours": (1000, 100)}[model]

    est = training_estimate(plan_jobs(dry), rates, ["single"], 3000, 50, budget=budget)
    assert asked == [("medium", "mlp"), ("medium_damping", "ours")]
    mlp, ours = 200 * 0.1 + 3800 * 0.2, 100 * 0.1 + 900 * 0.5
    assert est["cpu_s"] == pytest.approx(mlp + ours)
    assert est["longest_s"] == pytest.approx(max(mlp, ours))
    # a job whose own budget has a warm-up needs the static rate, whatever the shared warm-up
    del rates[("medium", "static", "single")]
    est = training_estimate(plan_jobs(dry), rates, ["single"], 3000, 0, budget=budget)
    assert est["jobs"] == 0 and sum(est["unrated"].values()) == 2


# Snakemake 9's log in the form the record's run at 23fa2c6 wrote (two jobs finished, one cut)
_LOG9 = """Building DAG of jobs...
[Mon Nov  9 08:57:10 2026]
localrule testbed_dataset_seeded:
    jobid: 45
[Mon Nov  9 08:57:51 2026]
Finished jobid: 45 (Rule: testbed_dataset_seeded)
[Mon Nov  9 08:57:51 2026]
localrule testbed_dataset_seeded:
    jobid: 773
[Mon Nov  9 09:58:07 2026]
Finished jobid: 773 (Rule: testbed_dataset_seeded)
[Mon Nov  9 09:58:07 2026]
localrule train:
    jobid: 12
"""


def test_a_segment_ends_at_its_last_finished_job(tmp_path):
    log9 = tmp_path / "2026-11-09T085706.329317.snakemake.log"
    log9.write_text(_LOG9)
    # 08:57:06 to 09:58:07 on the same day, by hand: 1 h 1 min 1 s; the cut train job adds nothing
    assert segment_seconds(log9) == 3661.0
    log8 = tmp_path / "2026-11-10T100000.000001.snakemake.log"
    log8.write_text("[Tue Nov 10 10:00:30 2026]\nFinished job 3.\n[Tue Nov 10 10:05:00 2026]\n")
    assert segment_seconds(log8) == 30.0
    unlock = tmp_path / "2026-11-10T110000.5.snakemake.log"
    unlock.write_text("Unlocked working directory.\n")
    assert segment_seconds(unlock) is None
    assert earlier_segments(tmp_path) == [(log9.name, 3661.0), (log8.name, 30.0)]
    with pytest.raises(ValueError, match="not a Snakemake log"):
        segment_seconds(tmp_path / "run.log")
    with pytest.raises(FileNotFoundError, match="no such folder"):
        earlier_segments(tmp_path / ".snakemake" / "lgo")


def test_a_real_snakemake_log_gives_its_segment(tmp_path):
    # the installed Snakemake's own log format, not a copy of it
    (tmp_path / "Snakefile").write_text(
        'rule a:\n    output: "a.txt"\n    shell: "touch {output}"\n'
    )
    t0 = time.time()
    subprocess.run(
        ["snakemake", "--cores", "1", "a.txt"], cwd=tmp_path, check=True, capture_output=True
    )
    wall = time.time() - t0
    found = earlier_segments(tmp_path / ".snakemake" / "log")
    assert len(found) == 1 and 0 <= found[0][1] <= wall + 1  # whole seconds in the log
