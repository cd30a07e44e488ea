"""What a finished pipeline run cost: job-seconds per stage and seed, and what one more seed adds.

    python benchmarks/pipeline_cost.py [--benchmarks results/benchmarks] [--wall-s SECONDS]

Reads every Snakemake benchmark file of the run (physgs.experiments.cost) and prints job wall
seconds by stage, per training seed and shared (testbeds), the damping benchmark's share, and,
given the run's measured wall time (``--wall-s``, e.g. from ``/usr/bin/time``), the wall time one
more seed would add on the same machine and core count.
"""

from __future__ import annotations

import argparse

from physgs.experiments.cost import extra_seed_wall_s, read_costs, resources_by_stage, summarise


def _min(s: float) -> str:
    return f"{s / 60:7.1f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--benchmarks", default="results/benchmarks")
    ap.add_argument("--wall-s", type=float, default=None, help="the run's measured wall seconds")
    args = ap.parse_args()
    jobs = read_costs(args.benchmarks)
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
    if args.wall_s:
        extra = extra_seed_wall_s(summary, run_wall_s=args.wall_s)
        print(
            f"run wall time {_min(args.wall_s).strip()} min = {args.wall_s / summary['total_s']:.2f} x "
            f"job time; one more seed adds ~{_min(extra).strip()} min of wall time"
        )


if __name__ == "__main__":
    main()
