"""Snakemake's scheduling loop with one pending re-evaluation timer instead of a chain per event,
and a stop that stops the running jobs.

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

A SIGINT to Snakemake's own process used to leave its running jobs to their end, marked
incomplete; [`stop_jobs_on_cancel`][physgs.scheduling.stop_jobs_on_cancel] stops them first, and
[`wake_on_sigint`][physgs.scheduling.wake_on_sigint] and
[`sigint_always_raises`][physgs.scheduling.sigint_always_raises] make sure the SIGINT reaches the
loop (a waiting main thread is woken; asyncio does not swallow it).

The Snakefile installs both when the workflow loads (Snakemake imports the Snakefile in the
process that runs the loop). A Snakemake whose method is missing, or no longer arms a timer that
releases ``_open_jobs`` (what the replacement does), stops the workflow with a message rather
than running either loop silently.
"""

from __future__ import annotations

import inspect
import os
import signal
import sys
import threading
import time

from snakemake.executors.local import Executor as LocalExecutor
from snakemake.scheduling.job_scheduler import JobScheduler

#: marks a class whose method is already replaced (a Snakefile can be loaded more than once)
_MARK = "_physgs_single_timer"
_STOP_MARK = "_physgs_stops_jobs"
_WAKE_MARK = "_physgs_wakes_on_sigint"
#: seconds a job has to end after SIGTERM before it is killed (its handler raises at once; what
#: can delay it is a long call into compiled code, which no signal interrupts)
STOP_GRACE_S = 4.0


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


def stop_child_processes(grace_s: float = STOP_GRACE_S) -> list[int]:
    """Stop every process this one started, and theirs: SIGTERM, then SIGKILL after ``grace_s``.

    Children are not reaped here: a job's thread waits on its own child (``Popen.wait``), and a
    child reaped by another would read as a success to it.

    Args:
        grace_s: seconds the processes have to end after SIGTERM.

    Returns:
        The pids signalled (empty when there were none).
    """
    import psutil  # a dependency of Snakemake's; imported only when a run is stopped

    procs = psutil.Process().children(recursive=True)
    if not procs:
        return []
    print(
        f"stopping {len(procs)} job process(es): SIGTERM, SIGKILL after {grace_s:g} s "
        "(docs/reliability.md, Interrupted runs)",
        file=sys.stderr,
        flush=True,
    )

    def alive() -> list:
        left = []
        for p in procs:
            try:
                if p.is_running() and p.status() != psutil.STATUS_ZOMBIE:
                    left.append(p)
            except psutil.NoSuchProcess:
                pass
        return left

    def send(sig: int, to: list) -> None:
        for p in to:
            try:
                p.send_signal(sig)  # psutil checks that the pid was not reused
            except psutil.NoSuchProcess:
                pass

    send(signal.SIGTERM, procs)
    end = time.monotonic() + grace_s
    while alive() and time.monotonic() < end:
        time.sleep(0.05)
    send(signal.SIGKILL, alive())
    return [p.pid for p in procs]


def stop_jobs_on_cancel(executor_cls: type) -> None:
    """Make ``executor_cls.cancel`` stop the running jobs before it waits for them.

    Snakemake 9.27.1 turns a SIGINT to its own process into ``KeyboardInterrupt`` in the
    scheduling loop, prints "Terminating processes on user request" and calls the executor's
    ``cancel``. The local executor's is ``self.pool.shutdown()``: it waits for the running jobs'
    threads, and each waits for its job's process, which got no signal (only a SIGINT to the
    whole process group, a terminal's Ctrl-C, reaches it). So a training ran to its end, and since
    the loop had stopped, Snakemake never recorded it as finished: its outputs stayed marked
    incomplete and the next run (``rerun-incomplete``) trained it again. The replacement stops
    the job processes first ([`stop_child_processes`][physgs.scheduling.stop_child_processes]);
    a job ends within the grace, recorded as incomplete, as it is.

    Args:
        executor_cls: Snakemake's local ``Executor`` (a class whose ``cancel`` waits for its jobs).
    """
    if getattr(executor_cls, _STOP_MARK, False):
        return
    wait_for_jobs = executor_cls.cancel

    def cancel(self) -> None:
        stop_child_processes()
        wait_for_jobs(self)

    executor_cls.cancel = cancel
    setattr(executor_cls, _STOP_MARK, True)


def _raise_keyboard_interrupt(signum: int, frame) -> None:
    raise KeyboardInterrupt


def sigint_always_raises() -> None:
    """Make SIGINT raise ``KeyboardInterrupt`` in the main thread even inside an asyncio run.

    Snakemake runs coroutines in its main thread through one ``asyncio.Runner`` per thread
    (``Workflow.async_run``). While SIGINT's handler is Python's default, each ``Runner.run``
    swaps in its own, which cancels the running task instead of raising: a coroutine that ends
    without letting the cancellation out then returns normally, and the SIGINT is gone: the
    scheduling loop would go back to waiting for its jobs (shown on a bare runner in
    ``tests/test_interrupt.py``; not caught in Snakemake itself).
    A handler of our own that raises as the default does is one the runner leaves in place
    (it swaps only the default), so the interrupt reaches the loop's ``except
    KeyboardInterrupt`` and its ``cancel``. Only the main thread may set a handler; elsewhere,
    and where a handler other than the default is set, nothing changes.
    """
    if threading.current_thread() is not threading.main_thread():
        return
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _raise_keyboard_interrupt)


def _watch_sigint(wake) -> bool:
    """Call ``wake()`` from a daemon thread each time the process receives SIGINT, whichever of
    its threads the kernel ran the signal on (``signal.set_wakeup_fd``). False where it cannot:
    not the main thread, or another wakeup fd is already set (left in place)."""
    if threading.current_thread() is not threading.main_thread():
        return False
    r, w = os.pipe()
    os.set_blocking(w, False)  # set_wakeup_fd requires it: the C handler must never block
    old = signal.set_wakeup_fd(w, warn_on_full_buffer=False)
    if old != -1:
        signal.set_wakeup_fd(old)
        os.close(r), os.close(w)
        return False

    def watch() -> None:
        while data := os.read(r, 64):  # one byte per signal: its number
            if signal.SIGINT in data:
                wake()

    threading.Thread(target=watch, name="physgs-sigint-wake", daemon=True).start()
    return True


def wake_on_sigint(scheduler_cls: type) -> None:
    """Wake Snakemake's scheduling loop when SIGINT arrives, so that its main thread raises it.

    While jobs run and none is ready, the loop waits on ``_open_jobs`` with no timer pending
    (upstream's pass that finds nothing to run arms none either), until a job ends. Python runs
    signal handlers only in the main thread, and a wait there is cut short only when the kernel
    delivers the signal to that thread; delivered to a job's thread (which the kernel may pick),
    the handler waited for the running job: a ``kill -INT`` of a run left its training to its end
    (the suite's interrupt test, run beside other tests, hung there: its stack dump shows that
    wait). A thread that reads the signal's wakeup byte releases ``_open_jobs`` once, and the
    woken main thread runs the handler (``KeyboardInterrupt``, the loop's ``cancel``); an extra
    release costs one pass.

    Args:
        scheduler_cls: Snakemake's ``JobScheduler`` (a class whose ``schedule`` waits on
            ``self._open_jobs``, a semaphore).
    """
    if getattr(scheduler_cls, _WAKE_MARK, False):
        return
    schedule = scheduler_cls.schedule

    def schedule_awake(self):
        _watch_sigint(self._open_jobs.release)
        return schedule(self)

    scheduler_cls.schedule = schedule_awake
    setattr(scheduler_cls, _WAKE_MARK, True)


def install() -> None:
    """Install [`single_reevaluation_timer`][physgs.scheduling.single_reevaluation_timer] on
    Snakemake's ``JobScheduler``, [`stop_jobs_on_cancel`][physgs.scheduling.stop_jobs_on_cancel]
    on its local executor, [`wake_on_sigint`][physgs.scheduling.wake_on_sigint] on the scheduler
    and [`sigint_always_raises`][physgs.scheduling.sigint_always_raises]."""
    single_reevaluation_timer(JobScheduler)
    stop_jobs_on_cancel(LocalExecutor)
    wake_on_sigint(JobScheduler)
    sigint_always_raises()
