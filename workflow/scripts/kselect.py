"""Snakemake script of rule `kselect`: choose ours' K for one tree from its training frames."""

from physgs.experiments.kselect import save_selection, select_k
from physgs.jobs import job
from physgs.testbed.dataset import load_observed

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    s = sm.params.settings
    sel = select_k(load_observed(sm.input.observed), s["job"], s["kselect"], progress=True)
    save_selection(sm.output.selection, sel)
    print(f"chosen K {sel.chosen_k} (heldout {sel.k_heldout}, bic {sel.k_bic}); {sel}", file=log)
