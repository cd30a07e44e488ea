"""Compare a seeded table's rerun with an earlier run: each changed cell against the seed spread.

    python tools/compare_runs.py OLD.csv NEW.csv [--keys seed,tree,config,method] [--show 15]

Prints how many numeric cells are identical, changed within the old run's spread over seeds of
their row, or beyond it (those listed, largest first). `physgs.report.rerun.compare_seeded`.
"""

from __future__ import annotations

import argparse

import pandas as pd

from physgs.report.rerun import compare_seeded


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--keys", default="seed,tree,config,method")
    ap.add_argument("--show", type=int, default=15, help="beyond-spread cells to list")
    args = ap.parse_args()
    r = compare_seeded(pd.read_csv(args.old), pd.read_csv(args.new), args.keys.split(","))
    print(
        f"{r.rows} rows matched ({len(r.only_old)} only in old, {len(r.only_new)} only in new); "
        f"{r.cells} numeric cells: {r.identical} identical, {r.within} changed within the seed "
        f"spread of their row, {len(r.beyond)} beyond it"
    )
    for ch in r.beyond[: args.show]:
        key = " ".join(f"{k}={v}" for k, v in ch.key.items())
        print(f"  {key} {ch.column}: {ch.old:g} -> {ch.new:g} (seed spread {ch.spread:g})")


if __name__ == "__main__":
    main()
