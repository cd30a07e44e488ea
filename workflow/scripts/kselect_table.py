"""Snakemake script of rule `tab_kselect`: fixed K = 32 against K chosen from the data."""
from physgs.report.kselect import make_tab_kselect

sm = snakemake  # noqa: F821 (injected by Snakemake)
with open(sm.log[0], "w") as log:
    t = make_tab_kselect(sm.params.cfg, sm.output.tex, sm.output.csv)
    print(t.df.to_string(), file=log)
