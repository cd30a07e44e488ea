"""A waited-on holder of an output (physgs.jobs.output_locks) that stops making progress ends the
wait with a message, and the holder's log survives the second job: put back at its path while the
holder works, kept beside it when the second job takes over."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

import pytest

from physgs.jobs import HolderStalled, holder_silent_s, output_locks
from workflow_helpers import ROOT

# holds the lock on argv[1] with its log at argv[3], logging a line every 0.2 s; with "fork",
# it leaves the lock to a child and exits (the lock held, its recorded pid gone)
HOLD = """
import os, sys, time
from physgs.jobs import output_locks
out, locks, log, mode = sys.argv[1:5]
with output_locks([out], locks, key="k", log=log):
    with open(log, "a") as f:
        print("holder working", flush=True)
        if mode == "fork" and os.fork() != 0:
            os._exit(0)  # the child inherited the lock's descriptor
        while True:
            print("step", file=f, flush=True)
            time.sleep(0.2)
"""


def _hold(tmp_path, mode="loop"):
    out, locks, log = tmp_path / "out.npz", tmp_path / "locks", tmp_path / "job.log"
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    proc = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(out), str(locks), str(log), mode],
        stdout=subprocess.PIPE,
        env=env,
        text=True,
        start_new_session=True,  # the forked child goes with the group at the end
    )
    assert proc.stdout.readline().strip() == "holder working"
    return out, locks, log, proc


@pytest.fixture
def holder(tmp_path):
    out, locks, log, proc = _hold(tmp_path)
    yield out, locks, log, proc
    with_group = os.getpgid(proc.pid) if proc.poll() is None else None
    if with_group is not None:
        os.killpg(with_group, signal.SIGKILL)
    proc.wait()


def test_a_stopped_holder_ends_the_wait_naming_it_and_its_log_survives(holder):
    out, locks, log, proc = holder
    time.sleep(0.5)
    log.unlink()  # what Snakemake does to the log path as the second job of the rule starts
    proc.send_signal(signal.SIGSTOP)  # alive, silent
    t0 = time.monotonic()
    with pytest.raises(HolderStalled) as e:
        with output_locks([out], locks, key="k", log=str(log), silent_s=2.0):
            pytest.fail("the body ran while the holder held the lock")
    took = time.monotonic() - t0
    msg = str(e.value)
    assert f"pid {proc.pid} " in msg and f"kill {proc.pid}" in msg, msg
    assert "has not changed for" in msg and "PHYSGS_HOLDER_SILENT_S" in msg, msg
    assert 2.0 <= took < 10, took
    assert log.read_text().startswith("step\n"), "the holder's log is not back at its path"
    waiting = log.with_name("job.log.waiting").read_text()  # the second job's own account
    assert "another job is making" in waiting and str(proc.pid) in waiting, waiting
    proc.send_signal(signal.SIGCONT)
    time.sleep(0.5)
    assert log.read_text().count("step") > 2  # still the holder's live log


def test_a_working_holder_is_waited_for(holder):
    out, locks, log, proc = holder
    done = []

    def stop_holder():  # after twice the silence limit: the wait outlasts the limit
        time.sleep(4)
        done.append(True)
        proc.kill()

    threading.Thread(target=stop_holder).start()
    with output_locks([out], locks, key="k", log=str(log), silent_s=2.0) as made_by:
        assert done, "the wait ended while the holder still logged"
        assert made_by is None


def test_a_holder_whose_process_is_gone_while_its_lock_is_held_ends_the_wait(tmp_path):
    out, locks, log, proc = _hold(tmp_path, mode="fork")
    try:
        assert proc.wait(timeout=30) == 0  # the recorded pid is gone; a child holds the lock
        with pytest.raises(HolderStalled) as e:
            with output_locks([out], locks, key="k", log=str(log), silent_s=600):
                pytest.fail("the body ran while the lock was held")
        assert f"its process (pid {proc.pid}) is gone" in str(e.value), str(e.value)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)


def test_taking_over_from_a_killed_holder_keeps_its_log(holder):
    out, locks, log, proc = holder
    time.sleep(0.5)
    log.unlink()  # Snakemake, as the second job starts
    threading.Timer(1.0, proc.kill).start()
    notes = []
    with output_locks([out], locks, key="k", log=str(log), notes=notes) as made_by:
        assert made_by is None  # the holder made nothing: this job makes it
        kept = log.with_name(f"job.log.pid{proc.pid}")
        assert kept.read_text().startswith("step\n"), "the holder's log was not kept"
        assert log.read_text() == ""  # this job's log, fresh
        assert not log.with_name("job.log.waiting").exists()  # its lines are in notes
    assert any("another job is making" in n for n in notes), notes
    assert any(str(kept) in n for n in notes), notes


def test_the_silence_limit_is_read_from_the_environment(monkeypatch):
    monkeypatch.setenv("PHYSGS_HOLDER_SILENT_S", "30")
    assert holder_silent_s() == 30.0
    for bad in ("0", "-5", "nan", "inf", "ten"):
        monkeypatch.setenv("PHYSGS_HOLDER_SILENT_S", bad)
        with pytest.raises(ValueError, match="PHYSGS_HOLDER_SILENT_S"):
            holder_silent_s()
