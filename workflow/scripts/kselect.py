"""Snakemake script of rule `kselect`: choose ours' K for one tree from its training frames."""
import contextlib

import numba
import torch

from physgs.models.kselect import save_selection, select_k
from physgs.testbed.dataset import load_observed

sm = snakemake  # noqa: F821 (injected by Snakemake)
torch.set_num_threads(sm.threads)
numba.set_num_threads(min(sm.threads, numba.config.NUMBA_NUM_THREADS))
with open(sm.log[0], "w") as log, contextlib.redirect_stderr(log):
    sel = select_k(load_observed(sm.input.observed), sm.params.cfg, progress=True)
    save_selection(sm.output.selection, sel)
    print(f"chosen K {sel.chosen_k} (heldout {sel.k_heldout}, bic {sel.k_bic}); {sel}", file=log)
