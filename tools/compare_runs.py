"""Compare a seeded table's rerun with an earlier run: each changed cell against the seed spread.

    python tools/compare_runs.py OLD.csv NEW.csv [--keys seed,tree,config,method] [--show 15]
    python tools/compare_runs.py OLD_TABLES_DIR NEW_TABLES_DIR      # every seeded CSV in both
    python tools/compare_runs.py OLD_RECORD/claims.csv NEW_RECORD/claims.csv   # verdict by verdict

Prints how many numeric cells are identical, changed within the old run's spread over seeds of
their row, or beyond it (those listed, largest first). The keys default to the seed and the
table's non-numeric columns (`physgs.report.rerun.table_keys`: a table named in `TABLE_KEYS`
takes its keys from there). Two ledgers (`claims.csv`) are compared verdict by verdict
(`physgs.report.rerun.compare_claims`). Job timings are never compared.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

from physgs.report.rerun import compare_claims, compare_table_csv


def report(old: Path, new: Path, keys: str, show: int) -> None:
    r = compare_table_csv(old, new, None if keys == "auto" else keys.split(","))
    print(
        f"{new.name}: {r.rows} rows matched ({len(r.only_old)} only in old, {len(r.only_new)} "
        f"only in new); {r.cells} numeric cells: {r.identical} identical, {r.within} changed "
        f"within the seed spread of their row, {len(r.beyond)} beyond it"
    )
    for ch in r.beyond[:show]:
        key = " ".join(f"{k}={v}" for k, v in ch.key.items())
        print(f"  {key} {ch.column}: {ch.old:g} -> {ch.new:g} (seed spread {ch.spread:g})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old", type=Path, help="a table's CSV, or a folder of them")
    ap.add_argument("new", type=Path, help="the rerun's CSV, or its folder")
    ap.add_argument("--keys", default="auto", help="comma-separated key columns, or auto")
    ap.add_argument("--show", type=int, default=15, help="beyond-spread cells to list")
    args = ap.parse_args()
    columns = [] if args.old.is_dir() else list(pd.read_csv(args.old, nrows=0).columns)
    if not args.old.is_dir() and "seed" not in columns:
        if "verdict" not in columns:
            ap.error(f"{args.old}: neither a seeded table nor a claims ledger")
        c = compare_claims(pd.read_csv(args.old), pd.read_csv(args.new))
        print(
            f"ledger: {c.same} verdicts the same, {len(c.changed)} changed; "
            f"{len(c.only_new)} claims only in new, {len(c.only_old)} only in old"
        )
        for v in c.changed:
            print(
                f"  {v.id}: {v.old} {v.old_value} -> {v.new} {v.new_value} (threshold {v.threshold})"
            )
        return
    if not args.old.is_dir():
        report(args.old, args.new, args.keys, args.show)
        return
    for old in sorted(args.old.glob("*.csv")):
        new = args.new / old.name
        if not new.exists():
            print(f"{old.name}: not in {args.new}")
        elif "seed" not in pd.read_csv(old, nrows=0).columns:
            print(f"{old.name}: no seed column (compare it with cmp)")
        else:
            try:
                report(old, new, args.keys, args.show)
            except ValueError as e:  # keys that do not identify rows: name them for this table
                print(f"{old.name}: {e}")


if __name__ == "__main__":
    main()
