"""What a finished pipeline run cost: job-seconds per stage and seed, and what one more seed adds.

    python tools/pipeline_cost.py [--benchmarks results/benchmarks] [--wall-s SECONDS]
        [--target TARGET ...] [--left [--config WORDS ...]]

Reads every Snakemake benchmark file of the run (physgs.experiments.cost) and prints job wall
seconds by stage, per training seed and shared (testbeds), the damping benchmark's share, and,
given the run's measured wall time (``--wall-s``, e.g. from ``/usr/bin/time``), the wall time one
more seed would add on the same machine and core count. With ``--target``, what a run of those
targets from nothing would cost, from the same run's measured jobs (``snakemake -n --forceall``
lists the plan; each planned job's benchmark file gives its seconds), scaled to wall time by the
finished run's own ratio of wall time to job time (``--wall-s``): an estimate for a reader who
wants one table (``--target results/tables/tab_null.tex``), not a measurement.

With ``--left``, what a cut or running run of ``--target`` (default ``all``) has left: the jobs
``snakemake -n`` would run now (given the run's ``--config`` words), each priced at the median of
the run's own finished jobs of its kind (``physgs.experiments.cost.left_cost``), and the wall
time that is at this run's pace so far (its segments' wall time, from ``.snakemake/log``, per
finished job-second): an estimate, printed as one. Run it in the run's folder; it reads and
plans, and never locks the run.

The timeline (``--cores``, default 2; ``--bin-min``, default 10) says when the cores were busy:
the jobs running at once in each stretch of the run (from the benchmark files' times), the
stages that ran where fewer than ``--cores`` jobs did, and the core-minutes left unused while
jobs ran (``physgs.experiments.cost.occupancy``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from physgs.experiments.cost import (
    by_job,
    dry_run,
    earlier_segments,
    extra_seed_wall_s,
    left_cost,
    occupancy,
    plan_cost,
    plan_jobs,
    read_costs,
    resources_by_stage,
    summarise,
)


def _min(s: float) -> str:
    return f"{s / 60:7.1f}"


#: Jobs (a stage's job over every tree and seed) the split by job lists, costliest first.
JOBS_SHOWN = 12


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--benchmarks", default="results/benchmarks")
    ap.add_argument("--wall-s", type=float, default=None, help="the run's measured wall seconds")
    ap.add_argument("--target", nargs="+", default=None, help="Snakemake targets to cost")
    ap.add_argument("--left", action="store_true", help="what a cut or running run has left")
    ap.add_argument("--config", nargs="+", default=[], help="the run's --config words")
    ap.add_argument("--cores", type=int, default=2, help="the cores the run had")
    ap.add_argument("--bin-min", type=float, default=10.0, help="timeline bin, minutes")
    args = ap.parse_args()
    jobs = read_costs(args.benchmarks)
    if args.left:
        left(args.target or ["all"], args.config, jobs, args.benchmarks, args.cores)
        return
    if args.target:
        target_cost(args.target, jobs, args.benchmarks, args.wall_s, summarise(jobs)["total_s"])
        return
    summary = summarise(jobs)
    seeds = list(summary["per_seed"])
    cols = ["shared", *seeds]
    print("job minutes (sum of benchmarked job wall times)")
    print(
        f"{'stage':<16}"
        + "".join(f"{('seed ' + str(c)) if c != 'shared' else c:>10}" for c in cols)
    )
    for stage, row in sorted(summary["by_stage"].items()):
        print(f"{stage:<16}" + "".join(f"{_min(row.get(c, 0.0)):>10}" for c in cols))
    print(
        f"{'total':<16}{_min(summary['shared_s']):>10}"
        + "".join(f"{_min(summary['per_seed'][s]):>10}" for s in seeds)
    )
    print(
        f"\nall jobs: {_min(summary['total_s']).strip()} job-min; damping benchmark: "
        f"{_min(summary['damping_s']).strip()} job-min "
        f"({', '.join(f'seed {s}: {_min(v).strip()}' for s, v in summary['damping_per_seed'].items())})"
    )
    print("\nper job, by stage (to size a cluster's requests: docs/cluster.md)")
    print(
        f"{'stage':<16}{'jobs':>6}{'wall s mean/max':>20}{'CPU s mean/max':>20}{'peak RSS MB':>13}"
    )
    for stage, r in resources_by_stage(jobs).items():
        print(
            f"{stage:<16}{r['jobs']:>6}{r['wall_mean_s']:>11.0f} /{r['wall_max_s']:>6.0f}"
            f"{r['cpu_mean_s']:>12.0f} /{r['cpu_max_s']:>6.0f}{r['rss_max_mb']:>13.0f}"
        )
    print(
        "(CPU and peak RSS are Snakemake's samples, taken every 30 s after a job's first 15 s: "
        "lower bounds that miss up to a job's last 30 s; wall s is exact)"
    )
    print(
        f"\nthe {JOBS_SHOWN} costliest jobs over every tree and seed (what a cheaper recipe saves)"
    )
    for (stage, name), (n, s) in list(by_job(jobs).items())[:JOBS_SHOWN]:
        print(f"{stage:<12}{name:<28}{n:>5} jobs{_min(s)} job-min")
    timeline(jobs, args.cores, args.bin_min * 60)
    if args.wall_s:
        extra = extra_seed_wall_s(summary, run_wall_s=args.wall_s)
        print(
            f"run wall time {_min(args.wall_s).strip()} min = {args.wall_s / summary['total_s']:.2f} x "
            f"job time; one more seed adds ~{_min(extra).strip()} min of wall time"
        )


def timeline(jobs, cores: int, bin_s: float) -> None:
    """Print the jobs running at once per bin, and what ran where the cores were not full."""
    occ = occupancy(jobs, cores, bin_s)
    print(f"\ntimeline: jobs running at once per {bin_s / 60:g} min (of {cores} cores)")
    for k, (b, stages) in enumerate(zip(occ.busy, occ.running)):
        ran = ""
        if b < cores - 0.05:  # name what ran where a core sat idle
            top = sorted(stages.items(), key=lambda kv: -kv[1])[:4]
            ran = "  " + ", ".join(f"{st} {v / 60:.1f}" for st, v in top)
        print(f"{k * bin_s / 60:7.{0 if bin_s >= 60 else 1}f} min {b:5.2f}{ran}")
    print(
        f"idle while jobs ran: {occ.idle_core_s / 60:.1f} core-min; no benchmarked job running: "
        f"{occ.paused_s / 60:.1f} min (a pause between segments, or light jobs only)"
    )


def left(targets, config, jobs, benchmarks, cores: int) -> None:
    """Print what a cut or running run of ``targets`` has left, priced by its finished jobs."""
    cost = left_cost(plan_jobs(dry_run(targets, config, forceall=False)), jobs, benchmarks)
    print(f"{' '.join(targets)}: the jobs left, each at the median of the run's finished jobs")
    for rule, (n, s) in sorted(cost["by_rule"].items(), key=lambda kv: -kv[1][1]):
        print(f"{rule:<24}{n:>5} jobs{_min(s)} job-min")
    print(f"{'left':<24}{sum(cost['by_match'].values()):>5} jobs{_min(cost['job_s'])} job-min")
    print(f"{'finished':<24}{len(jobs):>5} jobs{_min(cost['done_s'])} job-min")
    print(f"priced by the same job at other seeds / its stage on its tree / its stage: "
          f"{' / '.join(str(n) for n in cost['by_match'].values())} jobs; jobs running now count whole")  # fmt: skip
    if cost["unpriced"]:
        print(f"left unpriced (no finished job of their stage): {cost['unpriced']}")
    light = ", ".join(f"{r} {n}" for r, n in sorted(cost["light"].items()))
    print(f"jobs without a benchmark (not counted): {light or 'none'}")
    logs = Path(".snakemake/log")  # a results folder copied without them: no pace to read
    segments = [s for _, s in earlier_segments(logs)] if logs.is_dir() else []
    floor = f"wall time left: at least {_min(cost['job_s'] / cores).strip()} min on {cores} cores"
    if not segments or not cost["done_s"]:
        print(f"{floor}; no segment in .snakemake/log to read this run's pace from")
        return
    pace = sum(segments) / cost["done_s"]
    print(
        f"{floor}; about {_min(cost['job_s'] * pace).strip()} min at this run's pace so far "
        f"({pace:.2f} s of wall per job-second over {len(segments)} segments, "
        f"{_min(sum(segments)).strip()} min): an estimate"
    )


def target_cost(targets, jobs, benchmarks, wall_s, run_job_s) -> None:
    """Print the cost of a run of ``targets`` from nothing, from the finished run's jobs."""
    cost = plan_cost(plan_jobs(dry_run(targets)), jobs, benchmarks)
    print(f"{' '.join(targets)}: job minutes by rule (measured in the finished run)")
    for rule, (n, s) in sorted(cost["by_rule"].items(), key=lambda kv: -kv[1][1]):
        print(f"{rule:<24}{n:>5} jobs{_min(s)} job-min")
    print(
        f"{'total':<24}{sum(n for n, _ in cost['by_rule'].values()):>5} jobs{_min(cost['job_s'])}"
    )
    light = ", ".join(f"{r} {n}" for r, n in sorted(cost["light"].items()))
    print(f"jobs without a benchmark (not counted): {light or 'none'}")
    if cost["unmeasured"]:
        print(f"planned jobs the run did not measure: {cost['unmeasured']}")
    if wall_s:
        est = cost["job_s"] * wall_s / run_job_s
        print(
            f"estimated wall time: {_min(est).strip()} min (the run's {wall_s / run_job_s:.2f}"
            " s of wall per job-second)"
        )


if __name__ == "__main__":
    main()
