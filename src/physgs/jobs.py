"""The prologue every workflow script shares: a lock on the job's outputs, thread counts from
the rule, output to the job's log, and any traceback into that log before the job fails.

The lock is the project's own, beside Snakemake's: Snakemake 9.27.1 deletes its whole lock
folder when any run ends (``_delete_locks``: ``shutil.rmtree(.snakemake/locks)``), so a run
started after a run on other targets finished can plan a job that a third run is still doing
(docs/reliability.md, Two runs, one output). Each job takes an exclusive ``flock`` on one lock
file per output (under LOCK_DIR, named by the output's absolute path). A job whose output is
locked WAITS for the holder instead of stopping: a job that fails there is cleaned up by
Snakemake (``Job.cleanup``: "Removing output files of failed job"), which deletes every one of
its output paths that exists, and the holder may have written them meanwhile. When the holder
ends, the waiting job takes the outputs as made if the holder recorded (in each lock file, as
its last act) that it made every one of them for the same job, and they all exist; otherwise
(the holder failed or was killed, or made them for other inputs or params) it makes them
itself. The kernel drops the lock when the holder exits, even on SIGKILL. A holder that stops
making progress (its log silent for ``PHYSGS_HOLDER_SILENT_S``, or its process gone while its
lock is held) ends the wait with an error, and the holder's log, hard-linked beside its lock,
survives Snakemake's deleting the log path as the waiting job starts.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import hashlib
import logging
import os
import re
import signal
import sys
import threading
import time
import traceback
from pathlib import Path

from physgs.allocator import retain_freed_memory
from physgs.atomic import FULL_BELOW, atomic_path, disk_full_error, free_bytes
from physgs.provenance import take_provenance, write_provenance

#: where the output locks live, relative to the workflow's working directory (not Snakemake's
#: own ``.snakemake/locks``, which a finishing run deletes whole)
LOCK_DIR = Path(".snakemake") / "physgs-locks"
#: how a lock file starts once its holder made the output (then the job key and who made it)
MADE = "made "


def _stamp(when: str) -> str:
    return f"pid {os.getpid()} on {os.uname().nodename} {when} {time.strftime('%H:%M:%S')}"


def _record(fd: int, text: str) -> None:
    os.ftruncate(fd, 0)
    os.pwrite(fd, text.encode(), 0)


def _read(fd: int) -> str:
    return os.pread(fd, 1000, 0).decode(errors="replace").strip()


#: seconds a waited-on holder's log may stay silent before the wait ends (a stopped holder);
#: the environment variable ``PHYSGS_HOLDER_SILENT_S`` sets it for a run's jobs
HOLDER_SILENT_S = 600.0
SILENT_ENV = "PHYSGS_HOLDER_SILENT_S"
#: seconds between two looks at a waited-on lock and its holder
POLL_S = 0.5
_SINCE = re.compile(r"^pid (\d+) on (\S+) since \S+(?: log (.+))?$")


class HolderStalled(RuntimeError):
    """The job this one waits for has stopped making progress (or its process is gone while its
    lock is still held); the message names it, its log and what to do."""


def holder_silent_s() -> float:
    """The silence after which a waited-on holder counts as stopped: ``PHYSGS_HOLDER_SILENT_S``
    when set, else ``HOLDER_SILENT_S``.

    Returns:
        Seconds (positive, finite).

    Raises:
        ValueError: the variable is set to something else than a positive number of seconds.
    """
    raw = os.environ.get(SILENT_ENV)
    if raw is None:
        return HOLDER_SILENT_S
    try:
        value = float(raw)
    except ValueError:
        value = float("nan")
    if not (0 < value < float("inf")):
        raise ValueError(f"{SILENT_ENV}={raw!r}: expected a positive number of seconds")
    return value


#: seconds a holder's process may be gone while its lock is still held before the wait ends
GONE_GRACE_S = 3.0


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # alive, another user's
        return True
    try:
        with open(f"/proc/{pid}/stat") as f:  # a zombie has ended
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return True


def _wait_for_holder(fd: int, log_link: Path, out: str, silent_s: float) -> None:
    """Block until ``fd``'s lock is free; raise if its holder stopped making progress.

    The holder is taken for stopped when its process is gone on this host (yet the lock is held:
    a child it left holds it) or its log (``log_link``, a hard link, so Snakemake's deleting the
    log path does not hide it) has not changed for ``silent_s`` seconds. A holder that names no
    log (an ``output_locks`` user without a job) is waited for as long as it lives.
    """
    host = os.uname().nodename
    gone_since = None
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except BlockingIOError:
            pass
        record = _read(fd)
        m = _SINCE.match(record)
        if m is not None:
            pid, on, log = int(m.group(1)), m.group(2), m.group(3)
            why = None
            if on == host and not _pid_alive(pid):
                # a process that is ending releases its lock a moment after it is gone (seen on a
                # loaded machine): only a lock still held GONE_GRACE_S later is a child's
                gone_since = gone_since or time.monotonic()
                if time.monotonic() - gone_since > GONE_GRACE_S:
                    why = f"its process (pid {pid}) is gone, yet its lock is still held"
            elif log is not None:
                gone_since = None
                quiet = None  # not linked yet (a moment after the lock is taken), or no link
                for path in (log_link, log):
                    with contextlib.suppress(FileNotFoundError):
                        quiet = time.time() - os.stat(path).st_mtime
                        break
                if quiet is not None and quiet > silent_s:
                    why = (
                        f"its log {os.path.relpath(log)} has not changed for {quiet:.0f} s "
                        f"(limit {silent_s:g} s, {SILENT_ENV})"
                    )
            if why is not None:
                raise HolderStalled(
                    f"the job making {os.path.relpath(out)} ({record}) looks stopped: {why}. "
                    f"Stop it (kill {pid} on {on}) and rerun, or, if it is only slow, rerun with "
                    f"{SILENT_ENV} set above {silent_s:g} (docs/reliability.md, Two runs, one "
                    "output)"
                )
        time.sleep(POLL_S)


def _link(src: str, dst: Path) -> None:
    """Make ``dst`` a hard link to ``src``, replacing what ``dst`` was; best effort.

    Where no hard link can be made (the log on another file system than the locks), a waiting
    job watches the log's path instead, which Snakemake deletes as that job starts: it then waits
    for the holder's end however silent its log.
    """
    with contextlib.suppress(FileNotFoundError):
        os.unlink(dst)
    with contextlib.suppress(OSError):
        os.link(src, dst)


@contextlib.contextmanager
def output_locks(
    outputs,
    lock_dir: Path | str | None = None,
    key: str = "",
    *,
    log: str | None = None,
    silent_s: float | None = None,
    notes: list | None = None,
):
    """Hold an exclusive lock on each of ``outputs`` for the body, waiting for another holder.

    A job never stops on a held lock while its holder works: Snakemake would clean the stopped
    job up by deleting every one of its output paths that exists, the holder's work included. It
    waits (saying so on stderr, naming the output and the holder) until the holder ends, then
    either takes the holder's outputs (the value yielded) or makes them. The lock files record
    the holder's pid, host, start time and log while it works, and what it made once its body
    ended without an error.

    With ``log``, the holder's log is also hard-linked beside its lock (``<lock>.log``), so it
    outlives Snakemake's deleting the log path when a second job of the rule starts. A waiting
    job then puts the holder's log back at its path, writes its own messages to
    ``<log>.waiting`` (its own file, removed when the wait ends, kept if it fails: the lines also
    go to ``notes``), and ends
    the wait with [`HolderStalled`][physgs.jobs.HolderStalled] when the holder's log stays
    silent for ``silent_s`` or its process is gone. A job that takes over from a holder that
    made nothing keeps that holder's log, renamed ``<log>.pid<its pid>``.

    Args:
        outputs (Iterable[str | Path]): the output paths to lock (made absolute; duplicates locked
            once; locked in sorted order, so two jobs never wait on each other).
        lock_dir: where the lock files live (one per output, named by a hash of its path);
            default ``LOCK_DIR``.
        key: what makes two jobs the same job (see [`job_key`][physgs.jobs.job_key]); a holder
            that made the outputs under another key made other outputs.
        log: this job's log path (None: no log is linked, kept or watched).
        silent_s: seconds a holder's log may stay silent before the wait ends; default
            [`holder_silent_s`][physgs.jobs.holder_silent_s].
        notes (list[str] | None): what the wait said is appended here, for the body's log.

    Yields:
        (str | None): who made the outputs (``"pid 123 on host at 14:02:11"``) when every
            output exists and the last holder of each lock recorded that it made it under
            ``key``: the body must take them as made and write nothing. Otherwise None: the body
            makes the outputs, and if it ends without an error each lock records so.

    Raises:
        HolderStalled: a waited-on holder stopped making progress (nothing was made or written).
    """
    lock_dir = Path(LOCK_DIR if lock_dir is None else lock_dir)
    lock_dir.mkdir(parents=True, exist_ok=True)
    silent_s = holder_silent_s() if silent_s is None else silent_s
    notes = [] if notes is None else notes
    paths = sorted({os.path.abspath(str(o)) for o in outputs})
    held, links = [], []
    waiting = f"{log}.waiting" if log else None
    holders = {}  # pid -> its log, of each holder waited for

    def say(text: str) -> None:
        notes.append(text)
        print(text, file=sys.stderr, flush=True)
        if waiting:
            with open(waiting, "a") as f:
                print(f"{time.strftime('%H:%M:%S')} {text}", file=f)

    try:
        for out in paths:
            lock = lock_dir / (hashlib.sha256(out.encode()).hexdigest()[:24] + ".lock")
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
            held.append(fd)  # closed in the finally, held or not
            links.append(lock.with_suffix(".log"))
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = _read(fd) or "unknown"
                m = _SINCE.match(holder)
                if m is not None and m.group(3):
                    holders[m.group(1)] = m.group(3)
                    if not os.path.exists(m.group(3)):  # Snakemake deleted it as this job began
                        with contextlib.suppress(OSError):
                            os.link(links[-1], m.group(3))
                say(
                    f"another job is making {os.path.relpath(out)} now ({holder}): waiting for it "
                    "to end, then taking its output if it made it for this same job, or making "
                    "it (docs/reliability.md, Two runs, one output)"
                )
                _wait_for_holder(fd, links[-1], out, silent_s)
        if waiting:  # the wait is over: what it said is in ``notes``, for the job's log
            with contextlib.suppress(FileNotFoundError):
                os.unlink(waiting)
            waiting = None
        records = [_read(fd) for fd in held]
        made = [r.split(" ", 2) for r in records if r.startswith(MADE)]
        if (
            key
            and len(made) == len(held)
            and all(m[1] == key for m in made)
            and all(os.path.exists(p) for p in paths)
        ):
            yield made[0][2].removeprefix("by ")
            return
        if log:
            for pid, their in holders.items():  # made nothing: its log is kept, not overwritten
                if their == os.path.abspath(log) and os.path.exists(log):
                    os.replace(log, f"{log}.pid{pid}")
                    say(f"the log of pid {pid}, which made nothing, is kept as {log}.pid{pid}")
            open(log, "w").close()
        for fd, link in zip(held, links):
            _record(fd, _stamp("since") + (f" log {os.path.abspath(log)}" if log else ""))
            if log:
                _link(log, link)
        yield None
        for fd in held:  # the body ended without an error: what a waiting job may take
            _record(fd, f"{MADE}{key or '-'} by {_stamp('at')}")
        if log:
            for link in links:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(link)
    finally:
        for fd in held:
            os.close(fd)  # closing drops the flock


def job_key(sm) -> str:
    """What makes two Snakemake jobs the same job, for a waiting job to take another's outputs.

    The rule, the outputs, the inputs with their modification times and the params: what
    Snakemake itself compares to decide that an output is up to date (its code trigger aside:
    two runs of one job at once run one version of the workflow).

    Args:
        sm (snakemake.script.Snakemake): the script's ``snakemake`` object.

    Returns:
        24 hex digits of a SHA-256 over those, each in a fixed order.
    """

    def mtime(path):
        try:
            return os.stat(path).st_mtime_ns
        except OSError:
            return None

    params = getattr(sm, "params", [])
    names = sorted(params.keys()) if hasattr(params, "keys") else []
    parts = (
        getattr(sm, "rule", ""),
        sorted(os.path.abspath(str(o)) for o in sm.output),
        [(os.path.abspath(str(i)), mtime(i)) for i in getattr(sm, "input", [])],
        names,
        list(params),
    )
    return hashlib.sha256(repr(parts).encode()).hexdigest()[:24]


def _report_failure(log, path: str, error: BaseException) -> BaseException:
    """Write the traceback of ``error`` to the log, or to the console if the log cannot take it;
    return the error to raise.

    A log on a full disk cannot hold the traceback: then the console gets it, rather than a
    "see" pointing at an empty log. A write to the log that failed for want of space raised an
    ``OSError`` naming no file; the error returned names the log
    ([`physgs.atomic.disk_full_error`][]).
    """
    try:
        traceback.print_exception(error, file=log)
        log.flush()
        print(f"job failed; see {path}", file=sys.__stderr__)
    except OSError as e:
        print(
            f"job failed, and its log {path} could not be written ({e}); its traceback:",
            file=sys.__stderr__,
        )
        traceback.print_exception(error, file=sys.__stderr__)
    if (
        isinstance(error, OSError)
        and error.errno == errno.ENOSPC
        and error.filename is None
        and free_bytes(path) < FULL_BELOW
    ):
        return disk_full_error(path, error)
    return error


def _keep_log(log, path: str) -> None:
    """Put this job's log back at ``path`` if the path no longer names it.

    Snakemake deletes a job's log file before the job starts (``Job.remove_existing_output``),
    so a second job of the same rule started while this one runs unlinks the log this one writes.
    A log that cannot be written for want of space raises an ``OSError`` naming ENOSPC and it.
    """
    try:
        log.flush()
    except OSError as e:
        full = disk_full_error(path, e)
        if full is None:
            raise
        raise full from e
    try:
        if os.path.samestat(os.fstat(log.fileno()), os.stat(path)):
            return
    except FileNotFoundError:
        pass
    log.seek(0)
    text = log.read()
    with atomic_path(path) as tmp:
        tmp.write_text(text)


@contextlib.contextmanager
def stop_on_signals():
    """For the body, turn SIGTERM and SIGINT into ``KeyboardInterrupt`` in this process, once.

    Python's default for SIGTERM ends the process at once: no ``finally`` runs, so a temporary
    file of [`physgs.atomic.atomic_path`][] stays beside its output and the log gets no line. Raised
    as an exception, the job's clean-up runs and its log says why it stopped. A second signal
    while it cleans up (Ctrl-C sends SIGINT to the whole process group, then Snakemake sends
    SIGTERM to its jobs: [`physgs.scheduling.stop_child_processes`][]) is ignored, so the clean-up
    is not cut short. A process that does not end soon is killed by whoever stopped it. The
    previous handlers are back after the body. Does nothing outside the main thread (where Python
    runs signal handlers).

    Yields:
        (None): nothing; the body runs with the handlers installed.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, frame):
        for sig in (signal.SIGTERM, signal.SIGINT):
            signal.signal(sig, signal.SIG_IGN)
        raise KeyboardInterrupt(f"stopped by {signal.Signals(signum).name}")

    previous = {sig: signal.signal(sig, stop) for sig in (signal.SIGTERM, signal.SIGINT)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def set_threads(threads: int) -> None:
    """Set the thread count of torch, numba and OpenMP to ``threads``, whatever is imported yet.

    Torch and numba are set where the process has imported them; a job that never does (the
    tracker) does not pay their start-up, and a later import reads the count from the
    environment (OpenMP and numba read it when they load). Once numba is imported its
    ``NUMBA_NUM_THREADS`` is left alone: numba rereads it at every compile, and a value changed
    after its threads started fails the first compile of a kernel not in the cache ("Cannot set
    NUMBA_NUM_THREADS to a different value once the threads have been launched": every job on a
    cold cache). Its pool keeps the size it started with; parallel regions use ``threads`` of it.

    Args:
        threads: threads for this process (at least 1).
    """
    os.environ["OMP_NUM_THREADS"] = str(threads)
    if "torch" in sys.modules:
        sys.modules["torch"].set_num_threads(threads)
    if "numba" in sys.modules:
        numba = sys.modules["numba"]
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    else:
        os.environ["NUMBA_NUM_THREADS"] = str(threads)


def run_by_snakemake(sm) -> bool:
    """Whether ``sm`` is the ``snakemake`` object Snakemake gives a script it runs (not a stand-in
    a test or a notebook builds).

    Args:
        sm (object): the script's ``snakemake`` object.

    Returns:
        True for Snakemake's own class.
    """
    return type(sm).__module__.split(".")[0] == "snakemake"


def end_process() -> None:
    """End this process now, status 0, without Python's finalisation.

    A job's outputs and log are written and closed by then. What finalisation would still do is
    tear down the modules the job imported: 0.3-0.45 CPU-s for torch, numba and scipy
    (`python benchmarks/job_startup.py`, "exit"), paid by each of a run's jobs for memory the
    kernel frees anyway. The atexit handlers those modules register (torch's, numba's,
    llvmlite's, matplotlib's, multiprocessing's, weakref finalisers) only free memory or end
    threads; this does what the rest would for the job's output: logging's handlers flushed and
    closed, stdout and stderr flushed.
    """
    logging.shutdown()
    for stream in (sys.stdout, sys.stderr, sys.__stdout__, sys.__stderr__):
        if stream is not None:
            stream.flush()
    os._exit(0)


@contextlib.contextmanager
def job(sm):
    """Run a Snakemake script's body: ``with job(snakemake) as log: ...``.

    Locks the job's outputs ([`output_locks`][physgs.jobs.output_locks]: a job whose output another
    run is making waits for it, then takes that run's outputs if it made them for this same job,
    [`job_key`][physgs.jobs.job_key], or makes them), keeps freed memory in the process
    ([`physgs.allocator.retain_freed_memory`][]), sets the thread counts to the rule's
    ``threads`` ([`set_threads`][physgs.jobs.set_threads]), sends stdout and stderr (progress
    bars included) to ``sm.log[0]``, and writes the traceback of a failure there too (not only
    to the console; only to the console when the log cannot be written) before re-raising it.
    When the body ends well, each output gets its provenance record
    ([`physgs.provenance.write_provenance`][]: the rule, its params, the commit, the settings of
    each input); an output's old record is removed before the body runs.
    A waiting job's own lines go to ``<log>.waiting`` until the wait ends, then to the log
    (`output_locks`' ``log`` and ``notes``). The log is put back if another job of the rule
    started meanwhile (Snakemake deletes a job's log before it starts). A job that Snakemake runs
    ([`run_by_snakemake`][physgs.jobs.run_by_snakemake]) and whose body ended without an error
    ends its process when the block ends ([`end_process`][physgs.jobs.end_process]): nothing
    after the ``with`` block runs, so a workflow script does all its work inside it
    (`tests/test_job_exit.py` checks every script). SIGTERM and SIGINT raise in the body
    ([`stop_on_signals`][physgs.jobs.stop_on_signals]), so a stopped job cleans up and its log
    says why it ended.

    Args:
        sm (snakemake.script.Snakemake): the script's ``snakemake`` object (reads ``threads``,
            ``rule``, ``input``, ``output``, ``params`` and ``log[0]``).

    Yields:
        (TextIO): The open log file (``sm.log[0]``), where stdout and stderr go for the body.

    Raises:
        SystemExit: status 0, before the body, when another run made the outputs for this same
            job while this one waited: the job is done (a line in the log says who made them).
            Any exception of the body is re-raised after its traceback is written to the log.
    """
    set_threads(max(1, int(getattr(sm, "threads", 1))))
    retain_freed_memory()  # no page faults of fresh memory every training iteration
    notes = []  # what a wait for another job's outputs said, for this job's log
    with (
        stop_on_signals(),
        output_locks(list(sm.output), key=job_key(sm), log=sm.log[0], notes=notes) as made_by,
    ):
        if made_by is not None:
            with open(sm.log[0], "a") as log:  # the maker's log: this job's lines after its own
                for line in notes:
                    print(f"[pid {os.getpid()}, a second job] {line}", file=log)
                print(f"outputs made for this same job by {made_by}; taken as made", file=log)
            print(f"{sm.rule}: outputs made by {made_by}; taken as made", file=sys.stderr)
        else:
            previous = take_provenance(sm.output)  # no record outlives what it describes
            log = open(sm.log[0], "w+")
            for line in notes:
                print(line, file=log, flush=True)
            failed = False
            try:
                with contextlib.redirect_stderr(log), contextlib.redirect_stdout(log):
                    try:
                        yield log
                        made = [o for o in sm.output if os.path.exists(o)]  # Snakemake: the rest
                        write_provenance(made, sm.rule, sm.params, sm.input, previous=previous)
                    except BaseException as e:
                        failed = True
                        err = _report_failure(log, sm.log[0], e)
                        if err is e:
                            raise
                        raise err from e
                    finally:
                        try:
                            _keep_log(log, sm.log[0])
                        except OSError:
                            if not failed:  # else the failure's own error says it all
                                raise
            finally:
                with contextlib.suppress(OSError):  # a full disk: reported above
                    log.close()
    if made_by is not None:
        raise SystemExit(0)  # after the locks are released: nothing left to do
    if run_by_snakemake(sm):
        end_process()
