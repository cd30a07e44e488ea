"""Does fitting the window more make a model extrapolate worse? fig_fit_vs_extrapolation's
numbers, from the fit curve's CSV (`snakemake --cores 2 studies` writes
results/tables/fit_curve.csv), as a Markdown table (physgs.experiments.fit_curve.trade_summary).

    python tools/fit_trade.py results/tables/fit_curve.csv --markdown docs/studies/fit_trade.md \
        --figure results/figures/fig_fit_vs_extrapolation.png docs/img/fit_vs_extrapolation.png
"""

import argparse
from pathlib import Path

import pandas as pd

from physgs.experiments.fit_curve import fit_vs_extrapolation, trade_summary
from physgs.provenance import read_provenance
from physgs.report.record import web_sized

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("csv", type=Path, help="the fit curve's CSV")
ap.add_argument("--markdown", type=Path, help="write the table there too")
ap.add_argument("--figure", nargs=2, type=Path, metavar=("PNG", "TO"), help="copy, web-sized")
a = ap.parse_args()
if not a.csv.is_file():
    raise SystemExit(f"{a.csv}: missing; run `snakemake --cores 2 studies` first")
made = read_provenance(a.csv)  # the Snakemake job's sidecar: what made the CSV
if made is None:
    raise SystemExit(f"{a.csv}: no provenance record beside it; remake it with the workflow")
origin = (
    f"Made from `{a.csv.name}` (commit {made['commit']}, settings {made['settings_hash']}, "
    f"seeds {made['settings']['params']['seeds']}) by `python tools/fit_trade.py`.\n\n"
)
table = origin + trade_summary(fit_vs_extrapolation(pd.read_csv(a.csv))).to_markdown(
    index=False, floatfmt="+.2f"
)
print(table)
if a.markdown:
    a.markdown.write_text(table + "\n")
if a.figure:
    web_sized(*a.figure)
