"""Snakemake script of rule `fig_stabilisation`: one tree's stabilisation diagram beside the
bones' true natural frequencies (the only OMA rule that reads the truth for drawing)."""

from physgs.jobs import job
from physgs.oma.figure import stabilisation_figure
from physgs.oma.run import load_identification
from physgs.testbed.dataset import load_truth

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm):
    stabilisation_figure(
        sm.output.figure,
        load_identification(sm.input.modes),
        load_truth(sm.input.truth).omega,
        title=sm.wildcards.tree,
    )
