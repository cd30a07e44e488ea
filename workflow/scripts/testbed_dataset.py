"""Snakemake script of rule `testbed_dataset`: one tree's observed.npz + truth.npz."""

from physgs.jobs import job
from physgs.testbed.dataset import build_dataset, save_dataset

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    s = sm.params.settings
    observed, truth = build_dataset(
        s["testbed"], s["preset"], seed=s["seed"], tree=s["tree"], progress=True
    )  # <tree>_damping: same tree
    save_dataset(observed, truth, sm.output.observed, sm.output.truth)
    print(
        f"{sm.wildcards.tree}: {truth['omega'].size} bones, {len(truth['rest_vertices'])} "
        f"vertices, lead-in {observed['lead_in_frames']} frames",
        file=log,
    )
