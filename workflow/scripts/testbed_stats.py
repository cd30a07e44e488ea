"""Snakemake script of rule `testbed_stats`: one tree's statistics (frequencies, gaps, swing,
visible motion per bone, framing, order leak) as JSON."""

from physgs.jobs import job
from physgs.testbed.dataset import load_observed, load_truth
from physgs.testbed.stats import save_stats, testbed_stats

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    stats = testbed_stats(load_observed(sm.input.observed), load_truth(sm.input.truth))
    save_stats(sm.output.stats, stats)
    print({k: v for k, v in stats.items() if not hasattr(v, "shape")}, file=log)
