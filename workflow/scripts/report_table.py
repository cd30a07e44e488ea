"""Snakemake script of rule `table`: one table's .tex and .csv from the result files."""

from physgs.jobs import job
from physgs.report.build import make_table

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    t = make_table(
        sm.wildcards.name,
        dict(sm.input.items()),
        sm.params.settings,
        sm.output.tex,
        sm.output.csv,
        stamp=sm.params.stamp,
    )
    print(t.df.to_string(), file=log)
