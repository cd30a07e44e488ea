"""Snakemake script of rule `fit_curve_point`: one model trained and scored at one budget."""

from physgs.atomic import write_json
from physgs.experiments.fit_curve import run_point
from physgs.jobs import job
from physgs.testbed.dataset import load_observed

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    rec = run_point(
        sm.params.job, load_observed(sm.input.observed), progress=True, series=sm.params.series
    )
    write_json(sm.output.record, rec)
    print(rec, file=log)
