"""What the committed recipe searches found: one row per tree and model, from their trials files.

    python tools/search_summary.py docs/studies/search/*.trials.csv \
        --markdown docs/studies/search_summary.md [--check]

Each row (`physgs.experiments.search.summary`): trials scored and complete, those cut short
(trained again on resuming), the config's own recipe's held-out window PSNR (trial 0) and the
best complete trial's, the gain, and which recipe the config keeps by `search.adopt_above_db`
(read from config/trees.yaml). `--check` writes nothing and exits 1 when the page is out of date.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

import physgs.config
from physgs.experiments.search import summary
from physgs.models.registry import label

#: the page's column headers
HEADERS = {
    "trials": "trials scored",
    "cut": "cut, trained again",
    "own_psnr": "own (dB)",
    "best_psnr": "best (dB)",
    "best_trial": "best trial",
    "gain_db": "gain (dB)",
    "recipe": "recipe kept",
}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trials", nargs="+", help="searches' trials CSVs")
    ap.add_argument("--markdown", required=True, help="the page to write")
    ap.add_argument("--config", default="config/trees.yaml")
    ap.add_argument("--check", action="store_true", help="exit 1 if the page is out of date")
    args = ap.parse_args(argv)
    cfg = physgs.config.load(args.config)
    trials = pd.concat([pd.read_csv(p) for p in sorted(args.trials)], ignore_index=True)
    found = summary(trials, float(cfg["search"]["adopt_above_db"]))
    order = {t: i for i, t in enumerate(cfg["trees"])}  # the config's order of the trees
    found = found.sort_values("tree", key=lambda t: t.map(order), kind="stable")
    found["model"] = found["model"].map(label)
    found = found.rename(columns=HEADERS)
    text = found.to_markdown(index=False, floatfmt=".2f") + "\n"
    out = Path(args.markdown)
    if args.check:
        stale = not out.exists() or out.read_text() != text
        if stale:
            print(f"{out} is out of date: rerun without --check", file=sys.stderr)
        return int(stale)
    out.write_text(text)
    print(f"{out}: {len(found)} searches")
    return 0


if __name__ == "__main__":
    sys.exit(main())
