"""Snakemake script of rule `train_auto`: train ours with the K chosen by rule `kselect`."""
import contextlib

import numba
import torch

from physgs.models.kselect import auto_config, load_selection
from physgs.testbed.dataset import load_observed
from physgs.train import run_training

sm = snakemake  # noqa: F821 (injected by Snakemake)
torch.set_num_threads(sm.threads)
numba.set_num_threads(min(sm.threads, numba.config.NUMBA_NUM_THREADS))
with open(sm.log[0], "w") as log, contextlib.redirect_stderr(log):
    cfg = auto_config(sm.params.cfg, load_selection(sm.input.selection))
    res = run_training(load_observed(sm.input.observed), cfg, model="ours", config="auto",
                       checkpoint_path=sm.output.ckpt, loss_path=sm.output.loss)
    print(f"done: K {cfg['models']['configs']['auto']['K']}, {res.stats}", file=log)
