"""Snakemake script of rule `speed_accuracy_point`: train and score ours at one sweep point."""

from physgs.atomic import write_json
from physgs.experiments.sweep import run_point
from physgs.jobs import job

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    rec = run_point(sm.params.point, sm.input.observed, sm.input.truth, progress=True)
    write_json(sm.output.record, rec)
    print(rec, file=log)
