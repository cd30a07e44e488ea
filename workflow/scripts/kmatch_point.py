"""Snakemake script of rule `kmatch_point`: the chained prior at a smaller K, scored on the
held-out training-window frames (physgs.experiments.kmatch)."""

from physgs.atomic import write_json
from physgs.experiments.kmatch import kmatch_point
from physgs.jobs import job
from physgs.testbed.dataset import load_observed

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    point = kmatch_point(load_observed(sm.input.observed), sm.params.job, progress=True)
    write_json(sm.output.point, point)
    print(point, file=log)
