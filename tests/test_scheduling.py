"""physgs.scheduling: Snakemake's scheduling loop keeps one pending re-evaluation timer."""

from __future__ import annotations

import re
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
import yaml
from snakemake.settings.types import MaxJobsPerTimespan

from physgs.scheduling import single_reevaluation_timer

ROOT = Path(__file__).resolve().parents[1]
#: the profiles that run the jobs on this machine (the cluster's runs them elsewhere)
LOCAL_PROFILES = ("default", "quick")


def fake_scheduler_cls():
    """A class with Snakemake 9.27's method: each call arms a timer that releases _open_jobs."""

    class Loop:
        def __init__(self):
            self._open_jobs = threading.Semaphore(0)

        def _schedule_reevalutation(self, delay):
            threading.Timer(delay, lambda: self._open_jobs.release()).start()

    return Loop


def releases(sem: threading.Semaphore, expected: int) -> int:
    """Wait (up to 5 s each, for a loaded machine) for the expected releases, then count them
    and any others that arrive within 0.3 s more."""
    n = 0
    while n < expected and sem.acquire(timeout=5.0):
        n += 1
    time.sleep(0.3)
    while sem.acquire(blocking=False):
        n += 1
    return n


def test_unpatched_loop_arms_one_timer_per_call():
    """The upstream behaviour the patch removes: n calls, n wake-ups (the chains' seed)."""
    loop = fake_scheduler_cls()()
    for _ in range(20):
        loop._schedule_reevalutation(0.05)
    assert releases(loop._open_jobs, 20) == 20


def test_many_requests_one_wakeup():
    cls = fake_scheduler_cls()
    single_reevaluation_timer(cls)
    loop = cls()
    for _ in range(20):
        loop._schedule_reevalutation(0.05)
    assert releases(loop._open_jobs, 1) == 1
    # after it fired, the next request arms a new one (a pass always leaves a wake-up pending)
    loop._schedule_reevalutation(0.05)
    assert releases(loop._open_jobs, 1) == 1


def test_earlier_request_replaces_later_one():
    cls = fake_scheduler_cls()
    single_reevaluation_timer(cls)
    loop = cls()
    loop._schedule_reevalutation(30.0)  # e.g. a queue-input wait
    t0 = time.monotonic()
    loop._schedule_reevalutation(0.05)  # the rate limiter's timespan
    assert loop._open_jobs.acquire(timeout=5.0)
    assert time.monotonic() - t0 < 5.0  # not the 30-s one
    assert releases(loop._open_jobs, 0) == 0
    # the 30-s timer was cancelled (its thread ended), not left pending
    assert not [t for t in threading.enumerate() if getattr(t, "interval", None) == 30.0]


def test_instances_keep_their_own_timer():
    cls = fake_scheduler_cls()
    single_reevaluation_timer(cls)
    a, b = cls(), cls()
    a._schedule_reevalutation(0.05)
    b._schedule_reevalutation(0.05)
    assert (releases(a._open_jobs, 1), releases(b._open_jobs, 1)) == (1, 1)


def test_installing_twice_keeps_one_wrapper():
    cls = fake_scheduler_cls()
    single_reevaluation_timer(cls)
    method = cls._schedule_reevalutation
    single_reevaluation_timer(cls)
    assert cls._schedule_reevalutation is method


def test_a_loop_without_the_method_stops_with_a_message():
    with pytest.raises(RuntimeError, match="has no _schedule_reevalutation"):
        single_reevaluation_timer(type("OtherLoop", (), {}))


def test_a_method_that_no_longer_arms_the_timer_stops_with_a_message():
    class OtherLoop:
        def _schedule_reevalutation(self, delay):
            self._wake_at = delay  # another mechanism: replacing it would change what it does

    with pytest.raises(RuntimeError, match="no longer arms a timer"):
        single_reevaluation_timer(OtherLoop)


SNAKEFILE = """
import threading
{install}
rule all:
    input: expand("out/{{i}}.txt", i=range(40))
rule one:
    output: "out/{{i}}.txt"
    shell: "sleep 0.05 && touch {{output}}"
onsuccess:
    print("THREADS", threading.active_count())
"""


def run_threads(tmp_path, install: bool, *args: str) -> int:
    d = tmp_path / ("patched" if install else "upstream") / str(len(args))
    d.mkdir(parents=True)
    code = "import physgs.scheduling\nphysgs.scheduling.install()" if install else ""
    (d / "Snakefile").write_text(SNAKEFILE.format(install=code))
    out = subprocess.run(
        [sys.executable, "-m", "snakemake", "--cores", "2", "--workflow-profile", "none", *args],
        cwd=d,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    return int(re.search(r"THREADS (\d+)", out.stdout + out.stderr).group(1))


def test_snakemake_run_ends_with_one_timer_not_one_per_job(tmp_path):
    """Snakemake's own loop, 40 jobs: upstream leaves a timer chain per finished job alive at
    the end of the run; with the patch the loop holds at most one."""
    upstream = run_threads(tmp_path, install=False)
    patched = run_threads(tmp_path, install=True)
    assert upstream >= 20, upstream
    assert patched <= 4, patched


def profile_limit(profile: str) -> str:
    spec = yaml.safe_load((ROOT / "workflow/profiles" / profile / "config.yaml").read_text())
    return spec["max-jobs-per-timespan"]


@pytest.mark.parametrize("profile", LOCAL_PROFILES)
def test_local_profiles_keep_the_job_rate_timer_from_firing(profile):
    """Snakemake's job-rate limiter is always on; each local profile sets a cap no run reaches
    over a timespan longer than a run, so it never holds a job back and the loop's re-evaluation
    timer never fires (read by Snakemake's own parser)."""
    limit = MaxJobsPerTimespan.parse_choice(profile_limit(profile))
    assert limit.max_jobs >= 10_000  # `all`: 715 jobs at the default profile, 1,153 at the paper's
    assert limit.timespan >= 86_400  # s; `all` at the default profile: 4 h 11 min on 2 cores


def test_profiles_setting_with_the_patch_ends_at_once_with_one_timer(tmp_path):
    """The profiles' day-long timespan with the workflow's loop: the run ends (its one pending
    timer is a daemon thread; upstream's would hold the exit for a day) with at most one timer."""
    threads = run_threads(tmp_path, True, "--max-jobs-per-timespan", profile_limit("quick"))
    assert threads <= 4, threads
