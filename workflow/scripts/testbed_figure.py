"""Snakemake script of rule `testbed_figure`: the testbed figure of one tree."""

from physgs.jobs import job
from physgs.testbed.dataset import load_observed, load_truth
from physgs.testbed.figure import testbed_figure
from physgs.testbed.stats import load_stats

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    out = testbed_figure(
        load_observed(sm.input.observed),
        load_truth(sm.input.truth),
        sm.wildcards.tree,
        sm.output.figure,
        stats=load_stats(sm.input.stats),
    )
    print(f"wrote {out}", file=log)
