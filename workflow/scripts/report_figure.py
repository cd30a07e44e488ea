"""Snakemake script of rule `figure`: one figure as .pdf and .png from the result files."""

from physgs.jobs import job
from physgs.report.build import make_figure

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    make_figure(
        sm.wildcards.name,
        dict(sm.input.items()),
        sm.params.settings,
        [sm.output.pdf, sm.output.png],
    )
    print(f"wrote {sm.output.pdf} and {sm.output.png}", file=log)
