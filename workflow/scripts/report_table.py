"""Snakemake script of rule `table`: one table's .tex and .csv from the result files."""
from physgs.report.build import make_table

sm = snakemake  # noqa: F821 (injected by Snakemake)
with open(sm.log[0], "w") as log:
    t = make_table(sm.wildcards.name, sm.params.cfg, sm.output.tex, sm.output.csv)
    print(t.df.to_string(), file=log)
