"""Snakemake script of rule `evaluate`: score one checkpoint on every split."""
import contextlib

import numba
import torch

from physgs.evaluate.run import evaluate_checkpoint
from physgs.models.registry import load_checkpoint
from physgs.testbed.dataset import load_observed, load_truth

sm = snakemake  # noqa: F821 (injected by Snakemake)
torch.set_num_threads(sm.threads)
numba.set_num_threads(min(sm.threads, numba.config.NUMBA_NUM_THREADS))
with open(sm.log[0], "w") as log, contextlib.redirect_stderr(log):
    summary = evaluate_checkpoint(
        load_checkpoint(sm.input.ckpt), load_observed(sm.input.observed), load_truth(sm.input.truth),
        eval_path=sm.output.scores, traj_path=sm.output.traj, panels_path=sm.output.panels,
        backend=sm.params.backend, progress=lambda msg: print(msg, file=log, flush=True))
    print({k: round(v, 3) for k, v in summary.items()}, file=log)
