"""What Snakemake's own process costs while it runs a workflow's jobs, by loop and job-rate setting.

    python benchmarks/scheduler_overhead.py [--jobs 300] [--job-s 0.5] [--cores 2]
        [--cases upstream:100/1s,upstream:1000/10s,single:100/1s,single:100000/1d]
    python benchmarks/scheduler_overhead.py --watch -- snakemake --cores 2 all --config profile=quick

Snakemake 9 (9.27.1 here) re-runs its scheduling loop on a timer whenever a job-rate limit is set,
and `--max-jobs-per-timespan` defaults to `100/1s`, so a limit is always set (a profile cannot
unset it: a null value is skipped, any other is parsed as `count/timespan`). Each pass arms the
next timer (`JobScheduler._schedule_reevalutation`, a non-daemon `threading.Timer`), and every
other wake-up (each finished job) starts a chain of its own that never ends: after n finished
jobs the loop runs about n times per timespan and the process holds about n timer threads. A
longer timespan makes the passes rarer but leaves the threads, and the process then waits up to
one timespan for its last timers when the run ends. The workflow's loop (:mod:`physgs.scheduling`,
'single': one pending re-evaluation timer, a daemon thread) holds one thread and exits at once;
with a job cap above any run's job count and a long timespan (the profiles' `100000/1d`) the
limiter never holds a job back and its timer never fires, so the loop wakes only for jobs.

Without `--watch`: a throwaway workflow of `--jobs` independent jobs that each sleep `--job-s`
seconds (no CPU of their own) runs once per case (loop:setting; the upstream loop with a long
timespan would wait that long at exit, so it is not offered). With `--watch`: the command given
after `--` runs once (a workflow of your own, e.g. the pipeline from nothing). Either way the
Snakemake process is sampled every `--every` seconds (psutil): its own CPU seconds (not its
jobs'), its peak thread count and its busiest `--window` seconds as a share of a core, read from
the process at its exit before it is reaped; beside them the CPU seconds of the whole process
tree and the wall time (for the throwaway workflow also against the jobs' ideal wall time,
jobs x job_s / cores).
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import psutil

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
#: upstream with the default setting and a 10x longer timespan; the workflow's loop with the
#: default and with the profiles' setting
CASES = "upstream:100/1s,upstream:1000/10s,single:100/1s,single:100000/1d"


@dataclass(frozen=True)
class Usage:
    """What one Snakemake process used.

    Attributes:
        main_cpu_s: CPU seconds (user + system) of the Snakemake process itself.
        peak_threads: the most threads it held at one sample.
        peak_share: its busiest window's CPU seconds per wall second (1.0 = one core).
        tree_cpu_s: CPU seconds of the process and every child it waited for (its jobs).
        wall_s: wall seconds from start to exit.
    """

    main_cpu_s: float
    peak_threads: int
    peak_share: float
    tree_cpu_s: float
    wall_s: float


def _busiest(samples: list[tuple[float, float]], window: float) -> float:
    """Highest CPU seconds per wall second over `window` s among (time s, CPU s) samples."""
    best, j = 0.0, 0
    for t, cpu in samples:
        while j < len(samples) and samples[j][0] < t + window:
            j += 1
        if j == len(samples):
            break
        best = max(best, (samples[j][1] - cpu) / (samples[j][0] - t))
    if not best and len(samples) > 1:  # run shorter than a window: its mean
        (t0, c0), (t1, c1) = samples[0], samples[-1]
        best = (c1 - c0) / max(t1 - t0, 1e-9)
    return best


def watch(
    cmd: list[str],
    cwd: str | None = None,
    every: float = 0.2,
    window: float = 30.0,
    quiet: bool = False,
) -> Usage:
    """Run `cmd` and sample its process (Snakemake's main process) until it exits.

    Args:
        cmd: the command (its first process is the one measured).
        cwd: folder to run it in (None: this one).
        every: seconds between samples.
        window: seconds of the window whose CPU share is reported as the peak.
        quiet: discard the command's output.

    Returns:
        The process's usage; CPU seconds and threads read from the exited, not yet reaped
        process, so the last interval is counted too.
    """
    out = subprocess.DEVNULL if quiet else None
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, cwd=cwd, stdout=out, stderr=out)
    proc = psutil.Process(p.pid)
    samples: list[tuple[float, float]] = []
    peak = [0]
    done = threading.Event()

    def sample() -> None:
        try:
            c = proc.cpu_times()
            samples.append((time.monotonic() - t0, c.user + c.system))
            peak[0] = max(peak[0], proc.num_threads())
        except psutil.Error:
            pass

    def poll() -> None:
        while not done.wait(every):
            sample()

    poller = threading.Thread(target=poll, daemon=True)
    poller.start()
    os.waitid(os.P_PID, p.pid, os.WEXITED | os.WNOWAIT)  # exited, not reaped: still readable
    done.set()
    poller.join()
    sample()
    rc = p.wait()
    wall = time.monotonic() - t0
    if rc:
        raise SystemExit(f"{' '.join(cmd)} exited with {rc}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    tree = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return Usage(samples[-1][1], peak[0], _busiest(samples, window), tree, wall)


def run_case(jobs: int, job_s: float, cores: int, loop: str, timespan: str, window: float) -> Usage:
    """Run the throwaway workflow once with `loop` and `--max-jobs-per-timespan timespan`."""
    with tempfile.TemporaryDirectory() as d:
        Path(d, "Snakefile").write_text(
            SNAKEFILE.format(install=LOOPS[loop], jobs=jobs, job_s=job_s)
        )
        cmd = ["snakemake", "--cores", str(cores), "--quiet", "all", "--workflow-profile", "none",
               "--max-jobs-per-timespan", timespan]  # fmt: skip
        return watch(cmd, cwd=d, window=window, quiet=True)


HEAD = f"{'main CPU s':>11}{'peak threads':>14}{'peak core':>11}{'tree CPU s':>12}{'wall s':>9}"


def row(u: Usage) -> str:
    """One table row's measured columns."""
    return (f"{u.main_cpu_s:>11.1f}{u.peak_threads:>14d}{u.peak_share:>11.2f}"
            f"{u.tree_cpu_s:>12.1f}{u.wall_s:>9.1f}")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__.splitlines()[0], formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="\n".join(__doc__.splitlines()[1:5]),
    )  # fmt: skip
    ap.add_argument("--jobs", type=int, default=300)
    ap.add_argument("--job-s", type=float, default=0.5)
    ap.add_argument("--cores", type=int, default=2)
    ap.add_argument("--cases", default=CASES, help=f"loop:setting, loops among {', '.join(LOOPS)}")
    ap.add_argument("--window", type=float, default=30.0, help="s of the peak-share window")
    ap.add_argument("--watch", action="store_true", help="measure the command after `--` instead")
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    args, cmd = ap.parse_args(argv[:cut]), argv[cut + 1 :]
    if args.watch != bool(cmd):
        ap.error("--watch takes a command after `--`, and a command needs --watch")
    if args.watch:
        u = watch(cmd, window=args.window)
        print(f"{'command':<40}{HEAD}\n{' '.join(cmd)[:39]:<40}{row(u)}")
        return
    ideal = args.jobs * args.job_s / args.cores
    print(f"{args.jobs} jobs of {args.job_s} s on {args.cores} cores: ideal wall {ideal:.0f} s")
    print(f"{'loop':>9}{'max-jobs-per-timespan':>22}{HEAD}{'wall - ideal':>14}")
    for case in args.cases.split(","):
        loop, ts = case.split(":")
        if loop == "upstream" and not ts.endswith(("s", "m")):
            raise SystemExit(f"{case}: the upstream loop would wait up to {ts} at exit")
        u = run_case(args.jobs, args.job_s, args.cores, loop, ts, args.window)
        print(f"{loop:>9}{ts:>22}{row(u)}{u.wall_s - ideal:>14.1f}")


if __name__ == "__main__":
    main()
