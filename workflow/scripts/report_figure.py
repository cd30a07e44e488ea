"""Snakemake script of rule `figure`: one figure as .pdf and .png from the result files."""
from physgs.report.build import make_figure

sm = snakemake  # noqa: F821 (injected by Snakemake)
with open(sm.log[0], "w") as log:
    make_figure(sm.wildcards.name, sm.params.cfg, [sm.output.pdf, sm.output.png])
    print(f"wrote {sm.output.pdf} and {sm.output.png}", file=log)
