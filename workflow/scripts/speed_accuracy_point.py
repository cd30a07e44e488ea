"""Snakemake script of rule `speed_accuracy_point`: train and score ours at one sweep point."""
import contextlib

import numba
import torch

from physgs.atomic import write_json
from physgs.speed_accuracy import run_point

sm = snakemake  # noqa: F821 (injected by Snakemake)
torch.set_num_threads(sm.threads)
numba.set_num_threads(min(sm.threads, numba.config.NUMBA_NUM_THREADS))
with open(sm.log[0], "w") as log, contextlib.redirect_stderr(log):
    rec = run_point(sm.params.cfg, sm.wildcards.point, sm.input.observed, sm.input.truth,
                    progress=True)
    write_json(sm.output.record, rec)
    print(rec, file=log)
