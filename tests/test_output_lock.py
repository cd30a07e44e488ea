"""The project's own lock on each job's outputs (physgs.jobs): a job whose output another run is
making waits for it, even when Snakemake's own locks were deleted under the running job by a
third run finishing (Snakemake 9.27.1 ``_delete_locks``, docs/reliability.md), and then takes
that run's outputs or makes them; it never fails on them, so Snakemake's failed-job clean-up
never deletes what the other run made (issue 58)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from types import SimpleNamespace

import pytest

from physgs.jobs import job, job_key, output_locks
from workflow_helpers import ROOT

HOLD = """
import sys, time
from pathlib import Path
from physgs.jobs import output_locks
out, locks, key, seconds = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
with output_locks([out], locks, key=key):
    print("held", flush=True)
    time.sleep(seconds)
    Path(out).write_text("made by the holder")
"""


def _hold(out, locks, key="k", seconds=60.0):
    """A separate process that takes the lock on ``out``, then after ``seconds`` writes it and
    ends (recording that it made it under ``key``); returned once it holds the lock."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    proc = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(out), str(locks), key, str(seconds)],
        stdout=subprocess.PIPE,
        env=env,
        text=True,
    )
    assert proc.stdout.readline().strip() == "held"
    return proc


@pytest.fixture
def holder(tmp_path):
    """A separate process holding the lock on tmp_path/out.npz; yields (output, lock dir, proc)."""
    out, locks = tmp_path / "out.npz", tmp_path / "locks"
    proc = _hold(out, locks)
    yield out, locks, proc
    proc.kill()
    proc.wait()


def test_a_second_job_waits_naming_output_and_holder_then_makes_what_a_killed_holder_did_not(
    holder, capsys
):
    out, locks, proc = holder
    killed = threading.Event()

    def kill():  # SIGKILL: the kernel drops the flock
        killed.set()
        proc.kill()

    threading.Timer(1.0, kill).start()
    with output_locks([out], locks, key="k") as made_by:
        assert killed.is_set(), "the body ran while another process held the output"
        # the kernel drops the flock while the killed holder exits, a moment before its status
        # can be read (poll() may still say None): its status follows
        assert proc.wait(timeout=10) == -signal.SIGKILL
        assert made_by is None  # the holder made nothing: this job makes it
    err = capsys.readouterr().err
    assert f"another job is making {os.path.relpath(out)} now (pid {proc.pid}" in err, err
    assert "waiting for it to end" in err and "Two runs, one output" in err, err


def test_the_waiting_job_takes_what_the_holder_made_for_the_same_job_only(tmp_path):
    out, locks = tmp_path / "out.npz", tmp_path / "locks"
    proc = _hold(out, locks, key="k", seconds=0.5)
    with output_locks([out], locks, key="k") as made_by:  # waits, then takes it
        assert made_by is not None and made_by.startswith(f"pid {proc.pid} ")
    assert proc.wait() == 0 and out.read_text() == "made by the holder"
    with output_locks([out], locks, key="other params") as made_by:
        assert made_by is None  # made for another job: this one makes its own
        out.write_text("made by the second job")
    out.unlink()  # Snakemake deletes a job's outputs before it starts: these were not made now
    with output_locks([out], locks, key="other params") as made_by:
        assert made_by is None


def test_another_output_is_not_blocked_and_a_killed_holder_frees_it(holder, tmp_path):
    out, locks, proc = holder
    with output_locks([tmp_path / "other.npz"], locks):
        pass
    proc.send_signal(signal.SIGKILL)  # the kernel drops a flock with its process
    proc.wait()
    with output_locks([out], locks) as made_by:
        assert made_by is None


def test_the_job_prologue_takes_the_holders_outputs_and_ends_with_status_0(tmp_path, monkeypatch):
    out, locks, log = tmp_path / "out.npz", tmp_path / "locks", tmp_path / "job.log"
    monkeypatch.setattr("physgs.jobs.LOCK_DIR", locks)
    sm = SimpleNamespace(output=[str(out)], log=[str(log)], threads=1, rule="r", params=[])
    proc = _hold(out, locks, key=job_key(sm), seconds=0.5)
    with pytest.raises(SystemExit) as e:
        with job(sm):
            pytest.fail("the job body ran although the holder made its output")
    assert e.value.code == 0 and proc.wait() == 0
    assert out.read_text() == "made by the holder"
    assert f"made for this same job by pid {proc.pid} " in log.read_text()


SNAKEFILE = """
rule slow:
    output:
        "x.txt",
    log:
        "slow.log",
    script:
        "slow.py"


rule fast:
    output:
        "y.txt",
    shell:
        "echo y > {output}"
"""

# the job of rule slow; the test says when it writes ("go") and when it ends ("release")
SCRIPT = """
import os
import time
from pathlib import Path


def wait_for(path):
    t0 = time.monotonic()
    while not os.path.exists(path):
        assert time.monotonic() - t0 < 90, f"{path} never came"
        time.sleep(0.05)


sm = snakemake  # noqa: F821
if os.path.exists("held"):  # the holder runs: this is the second job
    Path("second_started").touch()
    wait_for(sm.output[0])  # its start-up (imports: 2-3 s in the real jobs) outlasts the write
from physgs.jobs import job  # noqa: E402

with job(sm) as log:
    Path("held.tmp").write_text(str(os.getpid()))
    os.replace("held.tmp", "held")
    print(f"made by {os.getpid()}", file=log)
    wait_for("go")
    Path("x.tmp").write_text(f"made by {os.getpid()}")
    os.replace("x.tmp", sm.output[0])  # atomic, as every output of the project
    wait_for("release")  # still holding the lock, as a job writing its next output or its log
"""


def _until(cond, what):
    t0 = time.monotonic()
    while not cond():
        assert time.monotonic() - t0 < 120, what
        time.sleep(0.1)


def test_a_second_run_on_the_same_output_leaves_the_holders_output_whole(tmp_path):
    """Run A's job takes the lock; run B makes y.txt and, finishing, deletes Snakemake's lock
    folder; run C then plans x.txt again and starts its job (the upstream defect), and A writes
    x.txt while C's job starts up. C's job used to stop on the lock, and Snakemake's clean-up of
    the failed job then deleted A's x.txt ("Removing output files of failed job"): now C's job
    waits for A, takes A's x.txt as made, and both runs end with status 0, x.txt and A's log
    whole."""
    (tmp_path / "Snakefile").write_text(SNAKEFILE)
    (tmp_path / "slow.py").write_text(SCRIPT)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    sm = [sys.executable, "-m", "snakemake", "--cores", "1", "--latency-wait", "1"]
    kw = dict(cwd=tmp_path, env=env, stderr=subprocess.STDOUT)
    with open(tmp_path / "a.out", "w") as a_out, open(tmp_path / "c.out", "w") as c_out:
        a = subprocess.Popen([*sm, "x.txt"], stdout=a_out, **kw)
        c = None
        try:
            _until(lambda: (tmp_path / "held").exists(), "run A's job never took the lock")
            a_pid = int((tmp_path / "held").read_text())
            b = subprocess.run(
                [*sm, "y.txt"], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120
            )
            assert b.returncode == 0, b.stdout + b.stderr
            assert not (tmp_path / ".snakemake" / "locks").exists()  # A's Snakemake lock is gone
            c = subprocess.Popen([*sm, "x.txt"], stdout=c_out, **kw)
            _until(lambda: (tmp_path / "second_started").exists(), "run C's job never started")
            (tmp_path / "go").touch()  # A writes x.txt while C's job starts up
            _until(
                lambda: c.poll() is not None or "waiting" in (tmp_path / "c.out").read_text(),
                "run C's job neither ended nor waited",
            )
            (tmp_path / "release").touch()
            codes = a.wait(timeout=120), c.wait(timeout=120)
        finally:
            for p in (a, c):
                if p is not None and p.poll() is None:
                    p.kill()
                    p.wait()
    out = {k: (tmp_path / f"{k}.out").read_text() for k in "ac"}
    assert "Removing output files" not in out["c"], out["c"]
    assert (tmp_path / "x.txt").read_text() == f"made by {a_pid}", out
    assert codes == (0, 0), out
    assert "another job is making x.txt now" in out["c"] and "taken as made" in out["c"]
    log = (tmp_path / "slow.log").read_text()  # C's Snakemake deleted A's log as C's job began
    assert log.startswith(f"made by {a_pid}\n") and "taken as made" in log, log
