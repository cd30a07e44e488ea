"""What Snakemake's own process costs while it runs a workflow's jobs, by its job-rate setting.

    python benchmarks/scheduler_overhead.py [--jobs 300] [--job-s 0.5] [--cores 2]
        [--timespans 100/1s,1000/10s] [--loops upstream,single]

Snakemake 9 (9.27.1 here) re-runs its scheduling loop on a timer whenever a job-rate limit is set,
and `--max-jobs-per-timespan` defaults to `100/1s`, so a limit is always set. Each pass schedules
the next timer, and every other wake-up (each finished job) starts a chain of its own that never
ends: after n finished jobs the loop runs about n times per `timespan`. In a full default-profile
run the Snakemake process held 391 timer threads after ~460 finished jobs and used 77% of a core
while the jobs ran. This script measures that cost away from the pipeline: a throwaway workflow of
`--jobs` independent jobs that each sleep `--job-s` seconds (no CPU of their own) runs once per
candidate setting, and the table gives Snakemake's CPU seconds (its process and its children:
the jobs' shells), its wall time and the jobs' ideal wall time (jobs x job_s / cores). The
limit's count is kept far above any rate the pipeline reaches, so the setting changes only how
often the loop wakes; the price of a longer timespan is that the process waits up to one
timespan for its last timers when the run ends.

Each setting runs with Snakemake's loop as released ('upstream') and with the loop the
workflow installs (:mod:`physgs.scheduling`, 'single': one pending re-evaluation timer, a
daemon thread, so no wait at exit either).
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import tempfile
import time
from pathlib import Path

SNAKEFILE = """
{install}
N = {jobs}
rule all:
    input: expand("out/{{i}}.txt", i=range(N))
rule one:
    output: "out/{{i}}.txt"
    shell: "sleep {job_s} && touch {{output}}"
"""


#: the Snakefile's first lines for each loop
LOOPS = {"upstream": "", "single": "import physgs.scheduling\nphysgs.scheduling.install()"}


def run_once(jobs: int, job_s: float, cores: int, timespan: str, loop: str) -> tuple[float, float]:
    """Run the throwaway workflow once; (CPU seconds of Snakemake and its children, wall s)."""
    with tempfile.TemporaryDirectory() as d:
        Path(d, "Snakefile").write_text(
            SNAKEFILE.format(install=LOOPS[loop], jobs=jobs, job_s=job_s)
        )
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.monotonic()
        subprocess.run(
            ["snakemake", "--cores", str(cores), "--quiet", "all",
             "--max-jobs-per-timespan", timespan],
            cwd=d, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        wall = time.monotonic() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=300)
    ap.add_argument("--job-s", type=float, default=0.5)
    ap.add_argument("--cores", type=int, default=2)
    ap.add_argument("--timespans", default="100/1s,1000/10s")
    ap.add_argument("--loops", default="upstream,single", help=f"among {', '.join(LOOPS)}")
    args = ap.parse_args()
    ideal = args.jobs * args.job_s / args.cores
    print(f"{args.jobs} jobs of {args.job_s} s on {args.cores} cores: ideal wall {ideal:.0f} s")
    print(f"{'loop':>9}{'max-jobs-per-timespan':>22}{'CPU s':>9}{'wall s':>9}{'wall - ideal':>14}")
    for loop in args.loops.split(","):
        for ts in args.timespans.split(","):
            cpu, wall = run_once(args.jobs, args.job_s, args.cores, ts, loop)
            print(f"{loop:>9}{ts:>22}{cpu:>9.1f}{wall:>9.1f}{wall - ideal:>14.1f}")


if __name__ == "__main__":
    main()
