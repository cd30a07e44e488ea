"""Two runs compared: each seeded table cell by cell, each numeric cell's change beside the old
run's spread over seeds of its row (within it, the rerun says nothing the seeds did not), and the
claims ledger verdict by verdict.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np
import pandas as pd

from physgs.provenance import read_stamped
from physgs.report.claims import Claim, on_claim
from physgs.report.outputs import OUTPUTS, PROVENANCE_COLUMNS


@dataclass(frozen=True)
class CellChange:
    """One numeric cell (``key``: its row's key values, seed included; ``column``) that moved
    from ``old`` to ``new`` by more than ``spread`` (the old run's max - min over its seeds)."""

    key: dict
    column: str
    old: float
    new: float
    spread: float


@dataclass(frozen=True)
class RerunComparison:
    """A rerun against the old run ([`compare_seeded`][physgs.report.rerun.compare_seeded]): the
    rows matched by key, the keys in one run only, the numeric cells compared, those identical
    (NaN = NaN), those moved within their row's seed spread, and those moved beyond it (largest
    move relative to the spread first)."""

    rows: int
    only_old: list
    only_new: list
    cells: int
    identical: int
    within: int
    beyond: list[CellChange]


#: Columns that time a job: what the machine did, not what the method found; never compared.
#: Every table's declared timing columns (``Columns.timing``).
TIMING_COLUMNS = tuple(
    dict.fromkeys(c for o in OUTPUTS.values() if o.columns for c in o.columns.timing)
)


def seeded_keys(table: pd.DataFrame, seed: str = "seed") -> list[str]:
    """The columns that identify a row of a seeded table: the seed and every non-numeric column
    but the run's provenance.

    Args:
        table: a seeded table.
        seed: the seed column.

    Returns:
        The key columns, seed first.

    Raises:
        ValueError: no seed column, or keys that repeat.
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
    """Table ``name``'s ``Columns.keys``, else [`seeded_keys`][physgs.report.rerun.seeded_keys].

    Args:
        name: the table's name (the CSV's stem).
        table: the table.

    Returns:
        The key columns, seed first.
    """
    o = OUTPUTS.get(name)
    return list(o.columns.keys) if o is not None and o.columns else seeded_keys(table)


def timing_columns(name: str) -> tuple[str, ...]:
    """The columns of table ``name`` that time its jobs: its declared ones, else ``TIMING_COLUMNS``.

    Args:
        name: the table's name (the CSV's stem).

    Returns:
        The timing column names.
    """
    o = OUTPUTS.get(name)
    return tuple(o.columns.timing) if o is not None and o.columns else TIMING_COLUMNS


def compare_table_csv(old_csv, new_csv, keys: list[str] | None = None) -> RerunComparison:
    """Compare two runs' CSVs of one seeded table ([`table_keys`][physgs.report.rerun.table_keys]).

    Args:
        old_csv (str | Path): the earlier run's table.
        new_csv (str | Path): the rerun's table.
        keys: the key columns; None for the table's own.

    Returns:
        The [`RerunComparison`][physgs.report.rerun.RerunComparison].
    """
    a, b = read_stamped(old_csv), read_stamped(new_csv)
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
        timing: the columns that time jobs, never compared.

    Returns:
        The [`RerunComparison`][physgs.report.rerun.RerunComparison]; a cell NaN in one run
            only counts as beyond the spread.

    Raises:
        ValueError: ``seed`` not among ``keys``, a key column missing, or a key repeated.
    """
    if seed not in keys:
        raise ValueError(f"compare_seeded: the seed column {seed!r} must be one of the keys")
    for name, df in (("old", old), ("new", new)):
        missing = [k for k in keys if k not in df.columns]
        if missing:
            raise ValueError(f"compare_seeded: the {name} table lacks key column(s) {missing}")
        if df.duplicated(keys).any():
            raise ValueError(f"compare_seeded: the {name} table repeats keys {keys}")
    skip = {*keys, *timing, *PROVENANCE_COLUMNS}  # nor a flag (bool) of the row: not a number
    numbers = old.select_dtypes("number", exclude="timedelta")
    numeric = [c for c in numbers if c not in skip and c in new.columns]
    group = [k for k in keys if k != seed]
    spread = old.groupby(group, dropna=False)[numeric].transform(lambda s: s.max() - s.min())
    old = old.join(spread.add_suffix("_spread"))
    merged = old.merge(new, on=keys, how="outer", suffixes=("_old", "_new"), indicator=True)
    both = merged[merged["_merge"] == "both"]
    only_old, only_new = (
        [tuple(r) for r in merged.loc[merged["_merge"] == side, keys].values]
        for side in ("left_only", "right_only")
    )
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
    beyond.sort(key=spreads_moved, reverse=True)
    within = cells - identical - len(beyond)
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
    """A claim whose verdict kind differs between two runs: each run's verdict and measurement
    with its interval in words, the threshold, and whether the runs' 95% intervals overlap
    (``yes``, ``no``, ``--`` where either run has none), and where the new run's first seed
    alone lies (``alone``: ``FIRST_SAME`` or ``FIRST_CROSSED`` and its value; ``--``)."""

    id: str
    claim: str
    old: str
    new: str
    old_value: str
    new_value: str
    threshold: str
    overlap: str
    alone: str = "--"


#: The first seed alone on the old mean's side of the threshold: the other instances moved it.
FIRST_SAME = "same side"
#: The first seed alone crossed the threshold too: that tree moved (settings, training noise).
FIRST_CROSSED = "crossed"


def _alone(first: tuple[Claim, float] | None, old: pd.Series) -> str:
    """Whether the new run's first-seed value lies on the old mean's side of the threshold."""
    m = pd.to_numeric(old["measured"], errors="coerce")
    if first is None or not (np.isfinite(first[1]) and np.isfinite(m)):
        return "--"
    claim, v = first
    same = on_claim(claim, v) == on_claim(claim, float(m))
    return f"{FIRST_SAME if same else FIRST_CROSSED}, {v:+.3g}"


@dataclass(frozen=True)
class ClaimsComparison:
    """Two runs' ledgers ([`compare_claims`][physgs.report.rerun.compare_claims]): the claims in
    both with the same verdict, those changed (the new ledger's order), the ids in one only."""

    same: int
    changed: list[VerdictChange]
    only_old: list[str]
    only_new: list[str]


def verdict_kind(verdict: str) -> str:
    """A verdict without its reason (``undecided: one seed`` -> ``undecided``).

    Args:
        verdict: a ledger verdict.

    Returns:
        Its kind.
    """
    return str(verdict).split(":")[0].strip()


def _value(r: pd.Series) -> str:
    """A claim's measurement and 95% interval in words (``--`` where not measured)."""
    unit = "" if pd.isna(r.get("unit")) else f" {r.get('unit')}"
    if pd.isna(r["measured"]):
        return "--"
    if pd.isna(r.get("ci_low")) or pd.isna(r.get("ci_high")):
        return f"{r['measured']:+.3g}{unit}"
    return f"{r['measured']:+.3g} [{r['ci_low']:+.3g}, {r['ci_high']:+.3g}]{unit}"


def _overlap(a: pd.Series, b: pd.Series) -> str:
    """Whether two claims' 95% intervals overlap: yes, no, or -- without both."""
    ends = [pd.to_numeric(r.get(k), errors="coerce") for r in (a, b) for k in ("ci_low", "ci_high")]
    if any(pd.isna(e) for e in ends):
        return "--"
    return "yes" if max(ends[0], ends[2]) <= min(ends[1], ends[3]) else "no"


def compare_claims(
    old: pd.DataFrame, new: pd.DataFrame, first: Mapping[str, tuple[Claim, float]] | None = None
) -> ClaimsComparison:
    """Compare two runs' ledgers (``claims.csv``) verdict by verdict, by kind (not reason).

    Args:
        old: the earlier run's ledger (id, verdict, measured, ci_low, ci_high, unit, threshold).
        new: the new run's ledger, same columns.
        first: claim id -> (claim, the new run's value on its first seed alone)
            ([`first_seed`][physgs.report.claims.first_seed]); None: not set beside.

    Returns:
        The [`ClaimsComparison`][physgs.report.rerun.ClaimsComparison].

    Raises:
        ValueError: a ledger without ``id``, ``verdict`` or ``measured``, or repeating an id.
    """
    for name, df in (("old", old), ("new", new)):
        missing = [c for c in ("id", "verdict", "measured") if c not in df.columns]
        if missing:
            raise ValueError(f"compare_claims: the {name} ledger lacks column(s) {missing}")
        if df["id"].duplicated().any():
            raise ValueError(f"compare_claims: the {name} ledger repeats claim ids")
    before = {str(r["id"]): r for _, r in old.iterrows()}
    both = [(before[str(r["id"])], r) for _, r in new.iterrows() if str(r["id"]) in before]
    changed = []
    for o, r in both:
        a, b = verdict_kind(o["verdict"]), verdict_kind(r["verdict"])
        if a == b:
            continue
        unit = "" if pd.isna(r.get("unit")) else f" {r.get('unit')}"
        threshold = "--" if pd.isna(r.get("threshold")) else f"{r.get('threshold')}{unit}"
        claim = str(r.get("claim", r["id"]))
        alone = _alone((first or {}).get(str(r["id"])), o)
        values = (_value(o), _value(r), threshold, _overlap(o, r), alone)
        changed.append(VerdictChange(str(r["id"]), claim, a, b, *values))
    ids_new = set(new["id"].astype(str))
    only_old = [i for i in old["id"].astype(str) if i not in ids_new]
    only_new = [i for i in new["id"].astype(str) if i not in before]
    return ClaimsComparison(len(both) - len(changed), changed, only_old, only_new)
