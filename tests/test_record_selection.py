"""What the record takes of a run's folder (physgs.report.record.run_files, tools/record.py):
exactly the tables, figures and benchmarked jobs of `all`'s plan, whatever else the folder holds
(a `snakemake studies` run made in it, an earlier run's files)."""

import importlib.util
from pathlib import Path

import pytest

import physgs.config
from physgs.experiments.cost import dry_run, plan_jobs, plan_outputs, read_costs, summarise
from physgs.provenance import config_hash
from physgs.report import record

ROOT = Path(__file__).resolve().parents[1]
HEADER = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"

# `all`'s plan as Snakemake prints it (snakemake -n --forceall all): the printout's format
ALL_DRY = """
Job stats:
job                count
---------------  -------
testbed_dataset        1
testbed_figure         1
train                  1
evaluate               1
table                  2
figure                 1
summary                1
all                    1
total                  9

[Fri Nov 27 21:51:12 2026]
rule testbed_dataset:
    output: results/testbed/sparse/observed.npz, results/testbed/sparse/truth.npz
    log: logs/testbed/sparse.log
    jobid: 1
    benchmark: results/benchmarks/testbed/sparse.tsv

localrule testbed_figure:
    input: results/testbed/sparse/observed.npz
    output: results/figures/testbed_sparse.png
    log: logs/testbed/figure_sparse.log

rule train:
    output: results/models/sparse/seed0/ours_single.pt, results/models/sparse/seed0/ours_single.loss.csv
    benchmark: results/benchmarks/train/sparse/seed0/ours_single.tsv

rule evaluate:
    output: results/eval/sparse/seed0/ours_single.npz
    benchmark: results/benchmarks/evaluate/sparse/seed0/ours_single.tsv

rule table:
    output: results/tables/tab_fit.tex, results/tables/tab_fit.csv

rule table:
    output: results/tables/tab_psnr.tex, results/tables/tab_psnr.csv

rule figure:
    output: results/figures/fig_results.pdf, results/figures/fig_results.png

rule summary:
    input: results/tables/tab_fit.csv
    output: results/summary.md

localrule all:
    input: results/summary.md
    jobid: 0
"""
#: job seconds of all's benchmarked jobs, and of the studies' that a later run left in the folder
ALL_JOBS = {
    "testbed/sparse.tsv": 50.0,
    "train/sparse/seed0/ours_single.tsv": 100.0,
    "evaluate/sparse/seed0/ours_single.tsv": 20.0,
}
STUDIES_JOBS = {
    "speed_accuracy/seed0/K-8.tsv": 30.0,
    "fit_curve/sparse/seed0/mlp_it500.tsv": 40.0,
    "kmatch/sparse/seed0_chain_K8.tsv": 10.0,
}
ALL_FILES = ("tables/tab_fit.csv", "tables/tab_psnr.csv", "figures/fig_results.png")
STUDIES_FILES = (
    "tables/fit_curve.csv",
    "tables/speed_accuracy.csv",
    "tables/tab_parts_k.csv",
    "figures/fig_speed_accuracy.png",
)


def _touch(path: Path, text: str = "x\n") -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def _bench(root: Path, rel: str, s: float) -> None:
    _touch(root / "benchmarks" / rel, HEADER + f"{s}\t0:00:00\t1\t1\t1\t1\t0\t0\t50\t1.0\n")


def _below_results(paths):
    """The plan's paths relative to the run's folder, as tools/record.py hands them over."""
    return [str(Path(p).relative_to("results")) for p in paths if p.startswith("results/")]


def _plan(dry: str) -> tuple[list[str], list[str]]:
    return _below_results(plan_outputs(dry)), _below_results(b for _, b in plan_jobs(dry) if b)


@pytest.fixture
def run(tmp_path):
    """A finished `all` run's folder with a `studies` run made in it afterwards."""
    r = tmp_path / "results"
    for rel in (*ALL_FILES, "figures/testbed_sparse.png", *STUDIES_FILES):
        _touch(r / rel)
    for rel, s in {**ALL_JOBS, **STUDIES_JOBS}.items():
        _bench(r, rel, s)
    return r


def test_the_record_takes_alls_tables_figures_and_jobs_and_leaves_the_studies_out(run):
    sel = record.run_files(run, *_plan(ALL_DRY))
    assert [p.relative_to(run).as_posix() for p in sel.tables] == [
        "tables/tab_fit.csv",
        "tables/tab_psnr.csv",
    ]
    assert [p.relative_to(run).as_posix() for p in sel.figures] == [
        "figures/fig_results.png",
        "figures/testbed_sparse.png",
    ]
    # the stamp's job count and job-minutes by stage are all's alone (170 job-s, not 250)
    assert sorted(j.path for j in sel.jobs) == sorted(ALL_JOBS)
    by_stage = summarise(list(sel.jobs))["by_stage"]
    assert {k: sum(v.values()) for k, v in by_stage.items()} == pytest.approx(
        {"testbed": 50.0, "train": 100.0, "evaluate": 20.0}
    )
    assert set(sel.left_out) == {*STUDIES_FILES, *(f"benchmarks/{p}" for p in STUDIES_JOBS)}
    assert sel.left_out_line() == (
        "left out (not made by all): figures/fig_speed_accuracy.png, tables/fit_curve.csv, "
        "tables/speed_accuracy.csv, tables/tab_parts_k.csv; 3 benchmark files (fit_curve 1, "
        "kmatch 1, speed_accuracy 1)"
    )


def test_a_folder_of_alls_files_alone_leaves_nothing_out(tmp_path):
    r = tmp_path / "results"
    for rel in (*ALL_FILES, "figures/testbed_sparse.png"):
        _touch(r / rel)
    for rel, s in ALL_JOBS.items():
        _bench(r, rel, s)
    sel = record.run_files(r, *_plan(ALL_DRY))
    assert sel.left_out == () and len(sel.jobs) == 3
    assert sel.left_out_line() == "left out (not made by all): nothing"


def test_what_all_makes_but_the_folder_lacks_is_named(run):
    outputs, benchmarks = _plan(ALL_DRY)
    (run / "tables" / "tab_psnr.csv").unlink()
    (run / "figures" / "testbed_sparse.png").unlink()
    with pytest.raises(FileNotFoundError, match="tab_psnr.csv, figures/testbed_sparse.png.*all"):
        record.run_files(run, outputs, benchmarks)
    _touch(run / "tables" / "tab_psnr.csv")
    _touch(run / "figures" / "testbed_sparse.png")
    (run / "benchmarks" / "evaluate" / "sparse" / "seed0" / "ours_single.tsv").unlink()
    with pytest.raises(FileNotFoundError, match="evaluate/sparse/seed0/ours_single.tsv"):
        record.run_files(run, outputs, benchmarks)


def _record_tool():
    spec = importlib.util.spec_from_file_location("record_tool", ROOT / "tools" / "record.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_alls_real_plan_leaves_the_studies_tables_figures_and_jobs_out(tmp_path, monkeypatch):
    """The workflow's own plans (quick profile), all's as tools/record.py reads it: a folder
    holding everything `all` and `studies` make gives the record all's files and jobs, and
    lists exactly the tables and figures studies alone makes; the studies' own jobs keep their
    benchmark files apart (results/studies/benchmarks/), so neither the record nor the summary
    of `all` counts them; a run of another config is refused."""
    tool = _record_tool()
    monkeypatch.chdir(ROOT)
    with pytest.raises(SystemExit, match="another run's"):
        tool._plan(["profile=quick"], [], "000000000000")
    quick = config_hash(physgs.config.load(ROOT / "config" / "trees.yaml", "quick"))
    a_out, a_bench = tool._plan(["profile=quick"], [], quick)
    s_dry = dry_run(["studies"], ["profile=quick"], cwd=ROOT)
    s_out = _below_results(plan_outputs(s_dry))
    s_bench = _below_results(b for _, b in plan_jobs(s_dry) if b)
    studies_jobs = set(s_bench) - set(a_bench)
    assert studies_jobs and all(p.startswith("studies/benchmarks/") for p in studies_jobs)
    assert all(p.startswith("benchmarks/") for p in a_bench)
    stages = {Path(p).parts[2] for p in studies_jobs}
    assert {"speed_accuracy", "fit_curve"} <= stages
    r = tmp_path / "results"
    for rel in {*a_out, *s_out}:
        if rel.startswith(("tables/", "figures/")):
            _touch(r / rel)
    for rel in {*a_bench, *s_bench}:  # each where its rule writes it
        _touch(r / rel, HEADER + "1.0\t0:00:00\t1\t1\t1\t1\t0\t0\t50\t1.0\n")
    sel = record.run_files(r, a_out, a_bench)
    assert len(sel.jobs) == len(set(a_bench)) > 0
    assert "tables/tab_fit.csv" in {p.relative_to(r).as_posix() for p in sel.tables}
    studies_only = {
        p
        for p in set(s_out) - set(a_out)
        if (p.startswith("tables/") and p.endswith(".csv"))
        or (p.startswith("figures/") and p.endswith(".png"))
    }
    assert set(sel.left_out) == studies_only
    assert {"tables/fit_curve.csv", "tables/speed_accuracy.csv"} <= studies_only
    assert not stages & {j.stage for j in sel.jobs}  # the studies' stages add no job-minutes
    # and what the summary of `all` reads: every benchmark file under results/benchmarks/
    assert {j.stage for j in read_costs(r / "benchmarks")} == {j.stage for j in sel.jobs}


def test_a_plan_snakemake_refuses_is_an_error_naming_the_command():
    with pytest.raises(RuntimeError, match="-n --forceall --nolock --config profile=quick -- nope"):
        dry_run(["nope"], ["profile=quick"], cwd=ROOT)
