"""Snakemake script of rule `speed_accuracy`: the sweep's CSV and fig_speed_accuracy."""
import json

from physgs.atomic import atomic_path
from physgs.experiments.sweep import collect
from physgs.jobs import job
from physgs.report.figures import fig_speed_accuracy

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    records = [json.load(open(p)) for p in sm.input]
    df = collect(records)
    with atomic_path(sm.output.csv) as tmp:
        df.to_csv(tmp, index=False, float_format="%.6g")
    fig_speed_accuracy(df, [sm.output.pdf, sm.output.png])
    print(df.to_string(), file=log)
