"""The prologue every workflow script shares: thread counts from the rule, output to the job's
log, and any traceback into that log before the job fails."""

from __future__ import annotations

import contextlib
import os
import sys
import traceback

from physgs.allocator import retain_freed_memory


@contextlib.contextmanager
def job(sm):
    """Run a Snakemake script's body: ``with job(snakemake) as log: ...``.

    Keeps freed memory in the process (:func:`physgs.allocator.retain_freed_memory`), sets
    torch's and numba's thread counts to the rule's ``threads`` (those imported now, and
    through OMP_NUM_THREADS / NUMBA_NUM_THREADS those imported later), sends stdout and stderr
    (progress bars included) to ``sm.log[0]``, and writes the traceback of a failure there too
    (not only to the console) before re-raising it.
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
