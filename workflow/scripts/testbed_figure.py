"""Snakemake script of rule `testbed_figure`: the testbed figure of one tree."""
from physgs.jobs import job
from physgs.testbed.dataset import load_observed, load_truth
from physgs.testbed.figure import testbed_figure

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    out = testbed_figure(load_observed(sm.input.observed), load_truth(sm.input.truth),
                         sm.wildcards.tree, sm.output.figure)
    print(f"wrote {out}", file=log)
