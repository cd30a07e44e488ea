"""The prologue every workflow script shares: a lock on the job's outputs, thread counts from
the rule, output to the job's log, and any traceback into that log before the job fails.

The lock is the project's own, beside Snakemake's: Snakemake 9.27.1 deletes its whole lock
folder when any run ends (``_delete_locks``: ``shutil.rmtree(.snakemake/locks)``), so a run
started after a run on other targets finished can plan a job that a third run is still doing
(docs/reliability.md, Two runs, one output). Each job takes an exclusive ``flock`` on one lock
file per output (under LOCK_DIR, named by the output's absolute path); a job whose output is
locked stops at once, naming the output and the process that holds it, instead of doing the
same work a second time. The kernel drops the lock when the holder exits, even on SIGKILL.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import os
import sys
import time
import traceback
from pathlib import Path

from physgs.allocator import retain_freed_memory

#: where the output locks live, relative to the workflow's working directory (not Snakemake's
#: own ``.snakemake/locks``, which a finishing run deletes whole)
LOCK_DIR = Path(".snakemake") / "physgs-locks"


class OutputLockedError(RuntimeError):
    """Another process is making this output now; the message names the output and the holder."""


@contextlib.contextmanager
def output_locks(outputs, lock_dir: Path | str | None = None):
    """Hold an exclusive lock on each of ``outputs`` for the body.

    No waiting: another process that holds one is doing this work. The lock files record the
    holder's pid, host and start time, and stay (empty of meaning once released: a lock is the
    ``flock``, not the file).

    Args:
        outputs (Iterable[str | Path]): the output paths to lock (made absolute; duplicates locked
            once).
        lock_dir: where the lock files live (one per output, named by a hash of its path);
            default ``LOCK_DIR``.

    Yields:
        (None): the body runs while the locks are held; they are released on exit.

    Raises:
        OutputLockedError: at once if another process holds one of the locks.
    """
    lock_dir = Path(LOCK_DIR if lock_dir is None else lock_dir)
    lock_dir.mkdir(parents=True, exist_ok=True)
    held = []
    try:
        for out in sorted({os.path.abspath(str(o)) for o in outputs}):
            name = hashlib.sha256(out.encode()).hexdigest()[:24] + ".lock"
            fd = os.open(lock_dir / name, os.O_RDWR | os.O_CREAT, 0o666)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.pread(fd, 200, 0).decode(errors="replace").strip() or "unknown"
                os.close(fd)
                raise OutputLockedError(
                    f"another job is making {os.path.relpath(out)} now ({holder}): this job stops "
                    "instead of making it a second time at once. Let that run finish, then rerun "
                    "this command: Snakemake will find the file made (docs/reliability.md, Two "
                    "runs, one output)"
                ) from None
            os.ftruncate(fd, 0)
            stamp = f"pid {os.getpid()} on {os.uname().nodename} since {time.strftime('%H:%M:%S')}"
            os.pwrite(fd, stamp.encode(), 0)
            held.append(fd)
        yield
    finally:
        for fd in held:
            os.close(fd)  # closing drops the flock


@contextlib.contextmanager
def job(sm):
    """Run a Snakemake script's body: ``with job(snakemake) as log: ...``.

    Locks the job's outputs ([`output_locks`][physgs.jobs.output_locks]: a job whose output another
    run is making stops at once), keeps freed memory in the process
    ([`physgs.allocator.retain_freed_memory`][]), sets torch's and numba's thread counts to the
    rule's ``threads`` (those imported now, and through OMP_NUM_THREADS / NUMBA_NUM_THREADS those
    imported later), sends stdout and stderr (progress bars included) to ``sm.log[0]``, and writes
    the traceback of a failure there too (not only to the console) before re-raising it.

    Args:
        sm (snakemake.script.Snakemake): the script's ``snakemake`` object (reads ``threads``,
            ``output`` and ``log[0]``).

    Yields:
        (TextIO): The open log file (``sm.log[0]``), where stdout and stderr go for the body.

    Raises:
        OutputLockedError: when another run is making one of the outputs now. Any exception of
            the body is re-raised after its traceback is written to the log.
    """
    threads = max(1, int(getattr(sm, "threads", 1)))
    retain_freed_memory()  # no page faults of fresh memory every training iteration
    # torch and numba are set where the script has imported them; a job that never does (the
    # tracker) does not pay their start-up, and a later import reads the same count from the
    # environment (OpenMP and numba read it when they load)
    os.environ["OMP_NUM_THREADS"] = os.environ["NUMBA_NUM_THREADS"] = str(threads)
    if "torch" in sys.modules:
        sys.modules["torch"].set_num_threads(threads)
    if "numba" in sys.modules:
        numba = sys.modules["numba"]
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    with (
        output_locks(list(sm.output)),
        open(sm.log[0], "w") as log,
        contextlib.redirect_stderr(log),
        contextlib.redirect_stdout(log),
    ):
        try:
            yield log
        except BaseException:
            traceback.print_exc(file=log)
            log.flush()
            print(f"job failed; see {sm.log[0]}", file=sys.__stderr__)
            raise
