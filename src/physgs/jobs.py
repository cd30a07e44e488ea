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
itself. The kernel drops the lock when the holder exits, even on SIGKILL.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import logging
import os
import sys
import time
import traceback
from pathlib import Path

from physgs.allocator import retain_freed_memory
from physgs.atomic import atomic_path
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


@contextlib.contextmanager
def output_locks(outputs, lock_dir: Path | str | None = None, key: str = ""):
    """Hold an exclusive lock on each of ``outputs`` for the body, waiting for another holder.

    A job never stops on a held lock: Snakemake would clean the stopped job up by deleting every
    one of its output paths that exists, the holder's work included. It waits (saying so on
    stderr, naming the output and the holder) until the holder ends, then either takes the
    holder's outputs (the value yielded) or makes them. The lock files record the holder's pid,
    host and start time while it works, and what it made once its body ended without an error.

    Args:
        outputs (Iterable[str | Path]): the output paths to lock (made absolute; duplicates locked
            once; locked in sorted order, so two jobs never wait on each other).
        lock_dir: where the lock files live (one per output, named by a hash of its path);
            default ``LOCK_DIR``.
        key: what makes two jobs the same job (see [`job_key`][physgs.jobs.job_key]); a holder
            that made the outputs under another key made other outputs.

    Yields:
        (str | None): who made the outputs (``"pid 123 on host at 14:02:11"``) when every
            output exists and the last holder of each lock recorded that it made it under
            ``key``: the body must take them as made and write nothing. Otherwise None: the body
            makes the outputs, and if it ends without an error each lock records so.
    """
    lock_dir = Path(LOCK_DIR if lock_dir is None else lock_dir)
    lock_dir.mkdir(parents=True, exist_ok=True)
    paths = sorted({os.path.abspath(str(o)) for o in outputs})
    held = []
    try:
        for out in paths:
            name = hashlib.sha256(out.encode()).hexdigest()[:24] + ".lock"
            fd = os.open(lock_dir / name, os.O_RDWR | os.O_CREAT, 0o666)
            held.append(fd)  # closed in the finally, held or not
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = _read(fd) or "unknown"
                print(
                    f"another job is making {os.path.relpath(out)} now ({holder}): waiting for it "
                    "to end, then taking its output if it made it for this same job, or making "
                    "it (docs/reliability.md, Two runs, one output)",
                    file=sys.stderr,
                    flush=True,
                )
                fcntl.flock(fd, fcntl.LOCK_EX)
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
        for fd in held:
            _record(fd, _stamp("since"))
        yield None
        for fd in held:  # the body ended without an error: what a waiting job may take
            _record(fd, f"{MADE}{key or '-'} by {_stamp('at')}")
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


def _keep_log(log, path: str) -> None:
    """Put this job's log back at ``path`` if the path no longer names it.

    Snakemake deletes a job's log file before the job starts (``Job.remove_existing_output``),
    so a second job of the same rule started while this one runs unlinks the log this one writes.
    """
    log.flush()
    try:
        if os.path.samestat(os.fstat(log.fileno()), os.stat(path)):
            return
    except FileNotFoundError:
        pass
    log.seek(0)
    text = log.read()
    with atomic_path(path) as tmp:
        tmp.write_text(text)


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
    to the console) before re-raising it. When the body ends well, each output gets its
    provenance record ([`physgs.provenance.write_provenance`][]: the rule, its params, the
    commit, the settings of each input); an output's old record is removed before the body
    runs. The log is put back if another job of the rule
    started meanwhile (Snakemake deletes a job's log before it starts). A job that Snakemake runs
    ([`run_by_snakemake`][physgs.jobs.run_by_snakemake]) and whose body ended without an error
    ends its process when the block ends ([`end_process`][physgs.jobs.end_process]): nothing
    after the ``with`` block runs, so a workflow script does all its work inside it
    (`tests/test_job_exit.py` checks every script).

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
    with output_locks(list(sm.output), key=job_key(sm)) as made_by:
        if made_by is not None:
            with open(sm.log[0], "a") as log:
                print(f"outputs made for this same job by {made_by}; taken as made", file=log)
            print(f"{sm.rule}: outputs made by {made_by}; taken as made", file=sys.stderr)
        else:
            previous = take_provenance(sm.output)  # no record outlives what it describes
            with (
                open(sm.log[0], "w+") as log,
                contextlib.redirect_stderr(log),
                contextlib.redirect_stdout(log),
            ):
                try:
                    yield log
                    made = [o for o in sm.output if os.path.exists(o)]  # Snakemake names the rest
                    write_provenance(made, sm.rule, sm.params, sm.input, previous=previous)
                except BaseException:
                    traceback.print_exc(file=log)
                    print(f"job failed; see {sm.log[0]}", file=sys.__stderr__)
                    raise
                finally:
                    _keep_log(log, sm.log[0])
    if made_by is not None:
        raise SystemExit(0)  # after the locks are released: nothing left to do
    if run_by_snakemake(sm):
        end_process()
