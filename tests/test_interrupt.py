"""A stop means stop: SIGINT to Snakemake's own process ends the running jobs within seconds, and
the jobs that had finished are not run again (physgs.scheduling.stop_jobs_on_cancel,
physgs.jobs.stop_on_signals)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

from workflow_helpers import ROOT

SNAKEFILE = """
import physgs.scheduling

physgs.scheduling.install()


rule all:
    input:
        "done.txt",
        "long.txt",


rule done:
    output:
        "done.txt",
    shell:
        "echo done > {output}"


rule long:
    input:
        "done.txt",
    output:
        "long.txt",
    log:
        "long.log",
    script:
        "long.py"
"""

# a training stand-in: a minute of steps, each saying so in the log; the output written at the end
LONG = """
import os
import time
from pathlib import Path

from physgs.atomic import atomic_path
from physgs.jobs import job

with job(snakemake) as log:  # noqa: F821
    Path("long.pid").write_text(str(os.getpid()))
    with atomic_path(snakemake.output[0]) as tmp:  # noqa: F821
        tmp.write_text("partial")
        for step in range(600):
            print("step", step, file=log, flush=True)
            time.sleep(0.1)
        tmp.write_text("long")
"""


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    with open(f"/proc/{pid}/stat") as f:  # a zombie has ended
        return f.read().rsplit(")", 1)[1].split()[0] != "Z"


def test_sigint_to_snakemake_ends_the_running_job_in_seconds_and_keeps_finished_ones(tmp_path):
    (tmp_path / "Snakefile").write_text(SNAKEFILE)
    (tmp_path / "long.py").write_text(LONG)
    # a run that outlives the SIGINT is sent SIGABRT: faulthandler then writes every thread's
    # stack to run.out, so a failure says where Snakemake's main thread was waiting
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "PYTHONFAULTHANDLER": "1"}
    cmd = [sys.executable, "-m", "snakemake", "--cores", "1", "--rerun-incomplete"]
    with open(tmp_path / "run.out", "w") as out:
        # its own session: the SIGINT goes to Snakemake's process only, not to a process group
        # the jobs share (a terminal's Ctrl-C reaches them all, and always stopped the jobs)
        run = subprocess.Popen(
            [*cmd, "all"],
            cwd=tmp_path,
            env=env,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        try:
            t0 = time.monotonic()
            while (
                not (tmp_path / "long.log").exists()
                or "step 3" not in (tmp_path / "long.log").read_text()
            ):
                assert run.poll() is None, (tmp_path / "run.out").read_text()
                assert time.monotonic() - t0 < 120, "the long job never started"
                time.sleep(0.1)
            job_pid = int((tmp_path / "long.pid").read_text())
            run.send_signal(signal.SIGINT)
            t_int = time.monotonic()
            try:
                code = run.wait(timeout=30)
            except subprocess.TimeoutExpired:
                code = None
            took = time.monotonic() - t_int
        finally:
            if run.poll() is None:
                run.send_signal(signal.SIGABRT)
                try:
                    run.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    run.kill()
                    run.wait()
    log = (tmp_path / "run.out").read_text()
    assert code is not None and took < 10, f"Snakemake ran {took:.1f} s after SIGINT:\n{log}"
    assert code != 0, log
    assert not _alive(job_pid), "the job's process outlived the run"
    assert "stopped by SIGTERM" in (tmp_path / "long.log").read_text()
    assert not (tmp_path / "long.txt").exists()
    assert sorted(p.name for p in tmp_path.glob(".long*")) == []  # its temporary was removed
    assert (tmp_path / "done.txt").read_text() == "done\n"
    plan = subprocess.run(
        [*cmd, "-n", "all"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120
    )
    assert plan.returncode == 0, plan.stdout + plan.stderr
    jobs = [line.split()[-1] for line in plan.stdout.splitlines() if line.startswith("rule ")]
    assert sorted(jobs) == ["all:", "long:"], plan.stdout  # not `done`: it had finished


def _printed(tmp_path, source: str, arg: str) -> str:
    """What a Python script prints, run in a process of its own with ``arg``."""
    (tmp_path / "script.py").write_text(source)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    out = subprocess.run(
        [sys.executable, "script.py", arg],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


# a coroutine of the kind that lost the SIGINT: it lets no cancellation out and returns normally
SWALLOWED = """
import asyncio, os, signal, sys

from physgs.scheduling import sigint_always_raises

if sys.argv[1] == "ours":
    sigint_always_raises()


async def step():
    try:
        os.kill(os.getpid(), signal.SIGINT)
        await asyncio.sleep(1)
    except asyncio.CancelledError:  # e.g. a cancelled subtask's, taken for its own
        pass
    return "finished"


with asyncio.Runner() as runner:  # as Snakemake's Workflow.async_run keeps one per thread
    try:
        print(runner.run(step()))
    except KeyboardInterrupt:
        print("interrupted")
"""


def test_a_sigint_inside_asyncio_reaches_the_main_thread_as_keyboard_interrupt(tmp_path):
    """With Python's default handler, asyncio's runner turns a SIGINT into a cancellation that a
    coroutine can swallow (the run goes on as if none came); with ``sigint_always_raises`` it is a
    ``KeyboardInterrupt`` in the main thread, as Snakemake's loop expects."""
    assert _printed(tmp_path, SWALLOWED, "python") == "finished"  # the cancellation swallowed
    assert _printed(tmp_path, SWALLOWED, "ours") == "interrupted"


# the scheduling loop's wait, with SIGINT blocked in the main thread so that the kernel must run it
# on another thread (as it may for a run's SIGINT while a job's thread waits on its process)
ELSEWHERE = """
import os, signal, sys, threading, time

from physgs.scheduling import _watch_sigint

open_jobs = threading.Semaphore(0)  # Snakemake's JobScheduler._open_jobs
if sys.argv[1] == "wake":
    assert _watch_sigint(open_jobs.release)
job_thread = threading.Thread(target=time.sleep, args=(30,), daemon=True)
job_thread.start()  # SIGINT not blocked here
signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
t0 = time.monotonic()
threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT)).start()
try:
    open_jobs.acquire(timeout=3)
    print("none")
except KeyboardInterrupt:
    print(f"{time.monotonic() - t0:.2f}")
"""


def test_a_sigint_run_on_another_thread_wakes_the_waiting_loop(tmp_path):
    """A SIGINT the kernel runs on a thread other than the waiting main thread reaches the main
    thread's handler only when the wait ends: at its timeout without the watcher (the loop's wait
    has none: it waited for the running job), at once with it."""
    # without the watcher the handler ran only when the 3 s wait timed out
    assert float(_printed(tmp_path, ELSEWHERE, "plain")) > 2.7
    assert float(_printed(tmp_path, ELSEWHERE, "wake")) < 2.0
