"""Snakemake script of rule `train`: fit one model on one tree's observed dataset."""
import contextlib
import traceback

import numba
import torch

from physgs.testbed.dataset import load_observed
from physgs.train import run_training

torch.set_num_threads(snakemake.threads)  # noqa: F821 (injected by Snakemake)
numba.set_num_threads(min(snakemake.threads, numba.config.NUMBA_NUM_THREADS))  # noqa: F821
with open(snakemake.log[0], "w") as log, contextlib.redirect_stderr(log):  # noqa: F821
    try:
        res = run_training(
            load_observed(snakemake.input.observed),  # noqa: F821
            snakemake.params.cfg,  # noqa: F821
            model=snakemake.wildcards.model,  # noqa: F821
            config=snakemake.wildcards.config,  # noqa: F821
            checkpoint_path=snakemake.output.ckpt,  # noqa: F821
            loss_path=snakemake.output.loss,  # noqa: F821
        )
    except Exception:
        traceback.print_exc(file=log)  # the cause in the job's log, not only on the console
        raise
    print(f"done: {res.stats}", file=log)
