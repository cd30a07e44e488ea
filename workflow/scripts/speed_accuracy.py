"""Snakemake script of rule `speed_accuracy`: the sweep's CSV and fig_speed_accuracy."""

from physgs.atomic import atomic_path
from physgs.experiments.sweep import collect, null_level
from physgs.intermediate import read_json
from physgs.jobs import job
from physgs.recovery.record import load_null
from physgs.report.figures import fig_speed_accuracy

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    df = collect([read_json(p, rule="speed_accuracy_point") for p in sm.input.points])
    null = null_level([load_null(p) for p in sm.input.nulls])
    with atomic_path(sm.output.csv) as tmp:
        df.to_csv(tmp, index=False, float_format="%.6g")
    fig_speed_accuracy(df, [sm.output.pdf, sm.output.png], null=null)
    print(df.to_string(), f"untrained null: {null}", sep="\n", file=log)
