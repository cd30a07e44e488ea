"""Two runs compared: each seeded table cell by cell, and the claims ledger verdict by verdict.
Did a change move a number beyond seed noise, or a verdict?

A change that only reorders floating-point work (a fused kernel, another summation order) still
moves a training's trajectory, and with it every number downstream; the question a reader asks
is whether it moved them further than a different seed would. For each numeric cell of the
new run this module sets its change beside the old run's spread over seeds of the same row
(the same key but the seed): within it, the rerun says nothing the seeds did not.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from physgs.report.outputs import OUTPUTS, PROVENANCE_COLUMNS


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


#: Columns that time a job (seconds, or a ratio of seconds): what the machine did, not what the
#: method found; a rerun on a busier core moves them. Never compared. Every table's declared
#: timing columns (``physgs.report.outputs``: ``Columns.timing``).
TIMING_COLUMNS = tuple(
    dict.fromkeys(c for o in OUTPUTS.values() if o.columns for c in o.columns.timing)
)


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


def table_keys(name: str, table: pd.DataFrame) -> list[str]:
    """The key columns of the seeded table ``name``: its declared keys (a report table's
    ``Columns.keys``), else [`seeded_keys`][physgs.report.rerun.seeded_keys].

    Args:
        name: the table's name (``tab_transfer``; the CSV's stem).
        table: the table.

    Returns:
        The key columns, seed first.
    """
    o = OUTPUTS.get(name)
    return list(o.columns.keys) if o is not None and o.columns else seeded_keys(table)


def timing_columns(name: str) -> tuple[str, ...]:
    """The columns of table ``name`` that time its jobs: its declared ones (a report table's
    ``Columns.timing``), else every table's (``TIMING_COLUMNS``).

    Args:
        name: the table's name (the CSV's stem).

    Returns:
        The timing column names.
    """
    o = OUTPUTS.get(name)
    return tuple(o.columns.timing) if o is not None and o.columns else TIMING_COLUMNS


def compare_table_csv(old_csv, new_csv, keys: list[str] | None = None) -> RerunComparison:
    """Compare two runs' CSVs of one seeded table, keyed by ``keys`` or else by
    [`table_keys`][physgs.report.rerun.table_keys] of its name.

    Args:
        old_csv (str | Path): the earlier run's table.
        new_csv (str | Path): the rerun's table.
        keys: the key columns; None for the table's own.

    Returns:
        The [`RerunComparison`][physgs.report.rerun.RerunComparison].
    """
    text = {"config_hash": str}  # a hash of digits stays text
    a, b = pd.read_csv(old_csv, dtype=text), pd.read_csv(new_csv, dtype=text)
    name = Path(old_csv).stem
    keys = table_keys(name, a) if keys is None else keys
    return compare_seeded(a, b, keys, timing=timing_columns(name))


def compare_seeded(
    old: pd.DataFrame,
    new: pd.DataFrame,
    keys: list[str],
    seed: str = "seed",
    timing: tuple[str, ...] = TIMING_COLUMNS,
) -> RerunComparison:
    """Compare a table's rerun with its earlier run, cell by cell against the seed spread.

    Args:
        old: the earlier run's table (one row per key).
        new: the rerun's table, same columns.
        keys: the columns that identify a row, ``seed`` among them.
        seed: the seed column.
        timing: the columns that time jobs, never compared (the table's declared ones).

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
        and c not in timing
        and c not in PROVENANCE_COLUMNS
        and c in new.columns
        and pd.api.types.is_numeric_dtype(old[c])
        and not pd.api.types.is_bool_dtype(old[c])  # a flag of the row, not a measurement
    ]
    group = [k for k in keys if k != seed]
    # each old row beside its row's spread over the old run's seeds (max - min)
    spread = old.groupby(group, dropna=False)[numeric].transform(lambda s: s.max() - s.min())
    old = old.join(spread.add_suffix("_spread"))
    merged = old.merge(new, on=keys, how="outer", suffixes=("_old", "_new"), indicator=True)
    both = merged[merged["_merge"] == "both"]
    only_old = [tuple(r) for r in merged.loc[merged["_merge"] == "left_only", keys].values]
    only_new = [tuple(r) for r in merged.loc[merged["_merge"] == "right_only", keys].values]
    a, b, sp = (
        both[[f"{c}_{s}" for c in numeric]].to_numpy(float) for s in ("old", "new", "spread")
    )
    same = (a == b) | (np.isnan(a) & np.isnan(b))
    moved = ~same & ~(np.abs(b - a) <= sp)  # NaN in one run only: beyond
    rows = both[keys].astype(object).to_numpy()  # plain Python values, as a reader prints them
    beyond = [
        CellChange(dict(zip(keys, rows[i])), numeric[j], *map(float, (a[i, j], b[i, j], sp[i, j])))
        for i, j in zip(*np.nonzero(moved))  # row by row, as the table reads
    ]
    cells, identical = a.size, int(same.sum())
    within = cells - identical - len(beyond)
    beyond.sort(key=spreads_moved, reverse=True)
    return RerunComparison(len(both), only_old, only_new, cells, identical, within, beyond)


def spreads_moved(ch: CellChange) -> float:
    """How many of its row's seed spreads a cell moved.

    Args:
        ch: the cell's change.

    Returns:
        abs(new - old) / spread; inf for a zero or undefined spread, or a NaN in one run.
    """
    r = abs(ch.new - ch.old) / ch.spread if ch.spread > 0 else float("inf")
    return r if r == r else float("inf")


@dataclass(frozen=True)
class VerdictChange:
    """A claim of the ledger whose verdict differs between two runs.

    Attributes:
        id: the claim's id.
        claim: the claim in words.
        old: its verdict in the old run (holds, fails or undecided).
        new: its verdict in the new run.
        old_value: the old run's measurement with its interval, in words.
        new_value: the new run's, in words.
        threshold: the claim's threshold, in words.
        overlap: whether the two runs' 95% intervals overlap (``yes`` / ``no``; ``--`` where
            either run has no interval): a verdict that moved with overlapping intervals moved
            within the seeds' noise.
    """

    id: str
    claim: str
    old: str
    new: str
    old_value: str
    new_value: str
    threshold: str
    overlap: str


@dataclass(frozen=True)
class ClaimsComparison:
    """Two runs' claims ledgers, verdict by verdict (see
    [`compare_claims`][physgs.report.rerun.compare_claims]).

    Attributes:
        same: claims in both ledgers with the same verdict.
        changed: the claims whose verdict changed, in the new ledger's order.
        only_old: ids found only in the old ledger.
        only_new: ids found only in the new ledger.
    """

    same: int
    changed: list[VerdictChange]
    only_old: list[str]
    only_new: list[str]


def verdict_kind(verdict: str) -> str:
    """A verdict without its reason.

    Args:
        verdict: a ledger verdict (``undecided: one seed``).

    Returns:
        Its kind (``undecided``).
    """
    return str(verdict).split(":")[0].strip()


def _value(r: pd.Series) -> str:
    """A claim's measurement and 95% interval in words (``--`` where not measured)."""
    unit = r.get("unit")
    unit = "" if pd.isna(unit) else f" {unit}"
    if pd.isna(r["measured"]):
        return "--"
    if pd.isna(r.get("ci_low")) or pd.isna(r.get("ci_high")):
        return f"{r['measured']:+.3g}{unit}"
    return f"{r['measured']:+.3g} [{r['ci_low']:+.3g}, {r['ci_high']:+.3g}]{unit}"


def _overlap(a: pd.Series, b: pd.Series) -> str:
    """Whether two claims' 95% intervals [ci_low, ci_high] overlap: yes, no, or -- without both."""
    ends = [pd.to_numeric(r.get(k), errors="coerce") for r in (a, b) for k in ("ci_low", "ci_high")]
    if any(pd.isna(e) for e in ends):
        return "--"
    return "yes" if max(ends[0], ends[2]) <= min(ends[1], ends[3]) else "no"


def compare_claims(old: pd.DataFrame, new: pd.DataFrame) -> ClaimsComparison:
    """Compare two runs' claims ledgers (``claims.csv``) verdict by verdict.

    A verdict is compared by its kind (holds, fails, undecided), not by the reason an undecided
    one gives.

    Args:
        old: the earlier run's ledger (columns id, verdict, measured, ci_low, ci_high, unit,
            threshold; claim optional).
        new: the new run's ledger, same columns.

    Returns:
        The [`ClaimsComparison`][physgs.report.rerun.ClaimsComparison].

    Raises:
        ValueError: a ledger without an ``id`` or ``verdict`` column, or with an id repeated.
    """
    for name, df in (("old", old), ("new", new)):
        missing = [c for c in ("id", "verdict", "measured") if c not in df.columns]
        if missing:
            raise ValueError(f"compare_claims: the {name} ledger lacks column(s) {missing}")
        if df["id"].duplicated().any():
            raise ValueError(f"compare_claims: the {name} ledger repeats claim ids")
    before = {str(r["id"]): r for _, r in old.iterrows()}
    same = 0
    changed: list[VerdictChange] = []
    for _, r in new.iterrows():
        o = before.get(str(r["id"]))
        if o is None:
            continue
        a, b = verdict_kind(o["verdict"]), verdict_kind(r["verdict"])
        if a == b:
            same += 1
            continue
        unit = "" if pd.isna(r.get("unit")) else f" {r.get('unit')}"
        threshold = r.get("threshold")
        changed.append(
            VerdictChange(
                id=str(r["id"]),
                claim=str(r.get("claim", r["id"])),
                old=a,
                new=b,
                old_value=_value(o),
                new_value=_value(r),
                threshold="--" if pd.isna(threshold) else f"{threshold}{unit}",
                overlap=_overlap(o, r),
            )
        )
    ids_new = set(new["id"].astype(str))
    only_old = [i for i in old["id"].astype(str) if i not in ids_new]
    only_new = [i for i in new["id"].astype(str) if i not in before]
    return ClaimsComparison(same, changed, only_old, only_new)
