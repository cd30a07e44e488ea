"""The project's own lock on each job's outputs (physgs.jobs): a job whose output another run is
making stops at once, naming it, even when Snakemake's own locks were deleted under the running
job by a third run finishing (Snakemake 9.27.1 ``_delete_locks``, docs/reliability.md)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from types import SimpleNamespace

import pytest

from physgs.jobs import OutputLockedError, job, output_locks
from workflow_helpers import ROOT

HOLD = """
import sys, time
from physgs.jobs import output_locks
with output_locks([sys.argv[1]], sys.argv[2]):
    print("held", flush=True)
    time.sleep(60)
"""


@pytest.fixture
def holder(tmp_path):
    """A separate process holding the lock on tmp_path/out.npz; yields (output, lock dir, proc)."""
    out, locks = tmp_path / "out.npz", tmp_path / "locks"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    proc = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(out), str(locks)],
        stdout=subprocess.PIPE,
        env=env,
        text=True,
    )
    assert proc.stdout.readline().strip() == "held"
    yield out, locks, proc
    proc.kill()
    proc.wait()


def test_a_locked_output_stops_the_second_job_naming_output_and_holder(holder):
    out, locks, proc = holder
    with pytest.raises(OutputLockedError) as e:
        with output_locks([out], locks):
            pytest.fail("the body ran while another process held the output")
    msg = str(e.value)
    assert "out.npz" in msg and f"pid {proc.pid}" in msg and "Two runs, one output" in msg, msg


def test_another_output_is_not_blocked_and_a_killed_holder_frees_it(holder, tmp_path):
    out, locks, proc = holder
    with output_locks([tmp_path / "other.npz"], locks):
        pass
    proc.send_signal(signal.SIGKILL)  # the kernel drops a flock with its process
    proc.wait()
    with output_locks([out], locks):
        pass


def test_the_job_prologue_takes_the_lock(holder, tmp_path, monkeypatch):
    out, locks, _ = holder
    monkeypatch.setattr("physgs.jobs.LOCK_DIR", locks)
    sm = SimpleNamespace(output=[str(out)], log=[str(tmp_path / "job.log")], threads=1)
    with pytest.raises(OutputLockedError, match="out.npz"):
        with job(sm):
            pytest.fail("the job body ran while another process held its output")


SNAKEFILE = """
from physgs.jobs import output_locks


rule slow:
    output:
        "x.txt",
    run:
        with output_locks(output):
            import os, time

            t0 = time.monotonic()  # hold the job until the test says so (at most a minute)
            while not os.path.exists("release") and time.monotonic() - t0 < 60:
                time.sleep(0.1)
            open(output[0], "w").write("x")


rule fast:
    output:
        "y.txt",
    shell:
        "echo y > {output}"
"""


def test_a_third_run_after_snakemakes_locks_were_deleted_is_stopped(tmp_path):
    """Run A makes x.txt (slowly); run B makes y.txt and, finishing, deletes Snakemake's lock
    folder; run C then plans x.txt again and starts its job (the upstream defect): the output
    lock stops C's job at once, and A's x.txt is made once."""
    (tmp_path / "Snakefile").write_text(SNAKEFILE)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    sm = [sys.executable, "-m", "snakemake", "--cores", "1"]
    run = dict(cwd=tmp_path, capture_output=True, text=True, env=env, timeout=120)
    a = subprocess.Popen(
        [*sm, "x.txt"], cwd=tmp_path, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    try:
        t0 = time.monotonic()
        while not (tmp_path / ".snakemake" / "physgs-locks").exists():  # A's job has started
            assert time.monotonic() - t0 < 60 and a.poll() is None
            time.sleep(0.2)
        b = subprocess.run([*sm, "y.txt"], **run)
        assert b.returncode == 0, b.stderr
        assert not (tmp_path / ".snakemake" / "locks").exists()  # the defect: A's locks are gone
        c = subprocess.run([*sm, "x.txt"], **run)
        assert "rule slow" in c.stdout + c.stderr  # Snakemake let C start the job...
        assert c.returncode != 0 and "another job is making x.txt" in c.stdout + c.stderr
        (tmp_path / "release").touch()
        assert a.wait(timeout=60) == 0  # ...and A finishes its x.txt undisturbed
        assert (tmp_path / "x.txt").read_text() == "x"
    finally:
        a.kill()
        a.wait()
