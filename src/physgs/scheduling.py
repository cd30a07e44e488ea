"""Snakemake's scheduling loop with one pending re-evaluation timer instead of a chain per event.

Snakemake 9 (9.27.1 here, the newest release) always sets a job-rate limit
(``--max-jobs-per-timespan`` defaults to ``100/1s``), and its scheduling loop ends every pass
by arming a ``threading.Timer`` that wakes the loop again one timespan later
(``JobScheduler._schedule_reevalutation``). A pass woken by a finished job arms one more, so
every finished job starts a chain that never ends: after n finished jobs the loop runs about n
times per timespan, each pass re-reading the ready jobs' params, resources and input sizes. In a
full default-profile run the Snakemake process held 391 timer threads and used 77 % of a core
near the end (``benchmarks/scheduler_overhead.py``), on a machine whose two cores the jobs need.

The loop needs only one pending wake-up: the rate limiter's (after a timespan, to admit jobs the
limit held back), while finished jobs wake it themselves. The local profiles set a limit no run
reaches over a day (``max-jobs-per-timespan: 100000/1d``), so that wake-up never fires either.
[`single_reevaluation_timer`][physgs.scheduling.single_reevaluation_timer] replaces the method on
the class so that a request is dropped when a timer that fires no later
is already pending; an earlier request replaces the pending one. The timer is a daemon thread,
so a finished run exits at once instead of waiting out the last timespan.

The Snakefile installs it when the workflow loads (Snakemake imports the Snakefile in the
process that runs the loop). A Snakemake whose method is missing, or no longer arms a timer that
releases ``_open_jobs`` (what the replacement does), stops the workflow with a message rather
than running either loop silently.
"""

from __future__ import annotations

import inspect
import threading
import time

from snakemake.scheduling.job_scheduler import JobScheduler

#: marks a class whose method is already replaced (a Snakefile can be loaded more than once)
_MARK = "_physgs_single_timer"


def single_reevaluation_timer(scheduler_cls: type) -> None:
    """Replace ``scheduler_cls._schedule_reevalutation`` (sic) by a one-timer version.

    Args:
        scheduler_cls: Snakemake's ``JobScheduler`` class (or a class with the same method:
            ``_schedule_reevalutation(self, delay: float)`` that arms a timer releasing
            ``self._open_jobs``).

    Raises:
        RuntimeError: the class has no ``_schedule_reevalutation``, or its body does not release
            ``_open_jobs`` from a timer (a Snakemake whose loop this was not written for).
    """
    if getattr(scheduler_cls, _MARK, False):
        return
    where = f"{scheduler_cls.__module__}.{scheduler_cls.__name__}"
    hint = (
        "physgs.scheduling was written for Snakemake 9.27's scheduling loop; check its timers "
        "before running this Snakemake (benchmarks/scheduler_overhead.py)"
    )
    method = getattr(scheduler_cls, "_schedule_reevalutation", None)
    if method is None:
        raise RuntimeError(f"{where} has no _schedule_reevalutation: {hint}")
    try:
        body = inspect.getsource(method)
    except (OSError, TypeError) as e:
        raise RuntimeError(f"{where}._schedule_reevalutation has no readable source: {hint}") from e
    if "Timer(" not in body or "_open_jobs.release()" not in body:
        raise RuntimeError(
            f"{where}._schedule_reevalutation no longer arms a timer that releases _open_jobs: "
            f"{hint}"
        )
    lock = threading.Lock()

    def _schedule_reevalutation(self, delay: float) -> None:
        due = time.monotonic() + delay
        with lock:
            pending = getattr(self, "_physgs_timer", None)
            if pending is not None and self._physgs_due <= due:
                return  # a wake-up at or before this one is already on its way
            if pending is not None:
                pending.cancel()

            def wake() -> None:
                with lock:  # cleared before the release, so the pass it starts can arm the next
                    if self._physgs_timer is timer:
                        self._physgs_timer = None
                self._open_jobs.release()

            timer = threading.Timer(delay, wake)
            timer.daemon = True  # a finished run does not wait for it
            self._physgs_timer, self._physgs_due = timer, due
            timer.start()

    scheduler_cls._schedule_reevalutation = _schedule_reevalutation
    setattr(scheduler_cls, _MARK, True)


def install() -> None:
    """Install [`single_reevaluation_timer`][physgs.scheduling.single_reevaluation_timer] on
    Snakemake's ``JobScheduler``."""
    single_reevaluation_timer(JobScheduler)
