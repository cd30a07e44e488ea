"""Snakemake script of rule `speed_accuracy`: the sweep's CSV (fig_speed_accuracy: rule figure)."""

from physgs.atomic import atomic_path
from physgs.experiments.sweep import collect
from physgs.intermediate import read_json
from physgs.jobs import job

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    df = collect([read_json(p, rule="speed_accuracy_point") for p in sm.input.points])
    with atomic_path(sm.output.csv) as tmp:
        df.to_csv(tmp, index=False, float_format="%.6g")
    print(df.to_string(), file=log)
