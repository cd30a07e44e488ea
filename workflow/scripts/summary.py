"""Snakemake script of rule `summary`: results/summary.md from the finished run's own files."""

from physgs.atomic import write_text
from physgs.jobs import job
from physgs.report.summary import run_summary

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    text = run_summary(
        sm.params.stamp.to_dict(), sm.input.claims, sm.input.tab_fit, sm.params.benchmarks
    )
    write_text(sm.output[0], text)
    print(text, file=log)
