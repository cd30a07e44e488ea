"""Snakemake: build one tree's testbed (observed.npz + truth.npz); progress goes to the log."""
import contextlib

from physgs.testbed.dataset import build_dataset, save_dataset

sm = snakemake  # noqa: F821 (injected by Snakemake)
with open(sm.log[0], "w") as log, contextlib.redirect_stderr(log):
    observed, truth = build_dataset(sm.params.testbed, sm.params.preset, seed=sm.params.seed,
                                    tree=sm.wildcards.tree, progress=True)
    save_dataset(observed, truth, sm.output.observed, sm.output.truth)
    print(f"{sm.wildcards.tree}: {truth['omega'].size} bones, {len(truth['rest_vertices'])} "
          f"vertices, lead-in {observed['lead_in_frames']} frames", file=log)
