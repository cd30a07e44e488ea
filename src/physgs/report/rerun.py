"""Two runs of one seeded table, cell by cell: did a change move a number beyond seed noise?

A change that only reorders floating-point work (a fused kernel, another summation order) still
moves a training's trajectory, and with it every number downstream; the question a reader asks
is whether it moved them further than a different seed would. For each numeric cell of the
new run this module sets its change beside the old run's spread over seeds of the same row
(the same key but the seed): within it, the rerun says nothing the seeds did not.
"""

from __future__ import annotations

from dataclasses import dataclass

import pandas as pd


@dataclass(frozen=True)
class CellChange:
    """One numeric cell that moved by more than the old run's seed spread of its row.

    Attributes:
        key: the row's key values (seed included), by column.
        column: the cell's column.
        old: its value in the old run.
        new: its value in the new run.
        spread: max - min of the column over the old run's seeds of the same row.
    """

    key: dict
    column: str
    old: float
    new: float
    spread: float


@dataclass(frozen=True)
class RerunComparison:
    """Summary of a rerun against the old run (see [`compare_seeded`][physgs.report.rerun.compare_seeded]).

    Attributes:
        rows: rows matched by key in both runs.
        only_old: keys found only in the old run.
        only_new: keys found only in the new run.
        cells: numeric cells compared (both values finite, or both NaN).
        identical: cells equal in both runs (NaN = NaN).
        within: cells that changed by no more than their row's seed spread.
        beyond: the cells that changed by more, largest change relative to spread first.
    """

    rows: int
    only_old: list
    only_new: list
    cells: int
    identical: int
    within: int
    beyond: list[CellChange]


#: Columns that describe the run, not a row: never keys.
PROVENANCE_COLUMNS = ("profile", "config_hash", "physgs_version")


def seeded_keys(table: pd.DataFrame, seed: str = "seed") -> list[str]:
    """The columns that identify a row of a seeded table: the seed and every non-numeric column
    (tree, method, configuration, ...) but the run's provenance.

    Args:
        table: a seeded table.
        seed: the seed column.

    Returns:
        The key columns, seed first.

    Raises:
        ValueError: no seed column, or keys that repeat (name them with ``keys`` instead).
    """
    if seed not in table.columns:
        raise ValueError(f"seeded_keys: the table has no {seed!r} column")
    keys = [seed] + [
        c
        for c in table.columns
        if c != seed and c not in PROVENANCE_COLUMNS and not pd.api.types.is_numeric_dtype(table[c])
    ]
    if table.duplicated(keys).any():
        raise ValueError(
            f"seeded_keys: {keys} repeat in the table; name the key columns explicitly"
        )
    return keys


def compare_seeded(
    old: pd.DataFrame, new: pd.DataFrame, keys: list[str], seed: str = "seed"
) -> RerunComparison:
    """Compare a table's rerun with its earlier run, cell by cell against the seed spread.

    Args:
        old: the earlier run's table (one row per key).
        new: the rerun's table, same columns.
        keys: the columns that identify a row, ``seed`` among them.
        seed: the seed column.

    Returns:
        The [`RerunComparison`][physgs.report.rerun.RerunComparison]. A cell whose value is NaN
            in one run only counts as beyond the spread (spread NaN).

    Raises:
        ValueError: ``seed`` not among ``keys``, a key column missing, or a key repeated in
            either table.
    """
    if seed not in keys:
        raise ValueError(f"compare_seeded: the seed column {seed!r} must be one of the keys")
    for name, df in (("old", old), ("new", new)):
        missing = [k for k in keys if k not in df.columns]
        if missing:
            raise ValueError(f"compare_seeded: the {name} table lacks key column(s) {missing}")
        if df.duplicated(keys).any():
            raise ValueError(f"compare_seeded: the {name} table repeats keys {keys}")
    numeric = [
        c
        for c in old.columns
        if c not in keys
        and c in new.columns
        and pd.api.types.is_numeric_dtype(old[c])
        and not pd.api.types.is_bool_dtype(old[c])  # a flag of the row, not a measurement
    ]
    group = [k for k in keys if k != seed]
    spread = old.groupby(group, dropna=False)[numeric].agg(lambda s: s.max() - s.min())
    merged = old.merge(new, on=keys, how="outer", suffixes=("_old", "_new"), indicator=True)
    both = merged[merged["_merge"] == "both"]
    only_old = [tuple(r) for r in merged.loc[merged["_merge"] == "left_only", keys].values]
    only_new = [tuple(r) for r in merged.loc[merged["_merge"] == "right_only", keys].values]
    cells = identical = within = 0
    beyond: list[CellChange] = []
    for _, row in both.iterrows():
        sp_row = spread.loc[tuple(row[g] for g in group) if len(group) > 1 else row[group[0]]]
        for c in numeric:
            a, b = float(row[f"{c}_old"]), float(row[f"{c}_new"])
            cells += 1
            if a == b or (pd.isna(a) and pd.isna(b)):
                identical += 1
                continue
            sp = float(sp_row[c])
            if abs(b - a) <= sp:
                within += 1
            else:
                beyond.append(CellChange({k: row[k] for k in keys}, c, a, b, sp))
    beyond.sort(key=_excess, reverse=True)
    return RerunComparison(len(both), only_old, only_new, cells, identical, within, beyond)


def _excess(ch: CellChange) -> float:
    """How many seed spreads a cell moved (inf for a zero or undefined spread, or a NaN)."""
    r = abs(ch.new - ch.old) / ch.spread if ch.spread > 0 else float("inf")
    return r if r == r else float("inf")
