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
from physgs.report.record import FIGURE_WIDTH_PX

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("csv", type=Path, help="the fit curve's CSV")
ap.add_argument("--markdown", type=Path, help="write the table there too")
ap.add_argument("--figure", nargs=2, type=Path, metavar=("PNG", "TO"), help="copy, web-sized")
a = ap.parse_args()
if not a.csv.is_file():
    raise SystemExit(f"{a.csv}: missing; run `snakemake --cores 2 studies` first")
table = trade_summary(fit_vs_extrapolation(pd.read_csv(a.csv))).to_markdown(
    index=False, floatfmt="+.2f"
)
print(table)
if a.markdown:
    a.markdown.write_text(table + "\n")
if a.figure:
    from PIL import Image

    with Image.open(a.figure[0]) as im:  # sized as the record sizes its figures
        h = round(im.height * FIGURE_WIDTH_PX / im.width)
        small = im.resize((FIGURE_WIDTH_PX, h), Image.LANCZOS) if im.width > FIGURE_WIDTH_PX else im
        small.save(a.figure[1], optimize=True)
