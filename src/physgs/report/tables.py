"""What every table shares: the ``Table`` a builder returns, its row labels, the check of its
per-seed results (``{seed: {key: value}}``), and ``write_table``.

A table's .csv holds one row per seed and key at full precision (NaN an empty cell); its .tex
the mean +- sd over seeds (``physgs.report.latex``, ``physgs.report.seeds``; NaN ``--``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.atomic import atomic_path, write_text


@dataclass(frozen=True)
class Table:
    """A built table: its name, its numbers and its booktabs LaTeX."""

    name: str
    df: pd.DataFrame  # flat, numeric columns at full precision
    tex: str


def tree_label(tree: str, bones: int) -> str:
    """A tree's row label, ``Sparse (22 bones)``.

    Args:
        tree: the tree's name.
        bones: its animated bones.

    Returns:
        The label.
    """
    return f"{tree.capitalize()} ({bones} bones)"


def condition_label(mult: float, tex: bool = True) -> str:
    """A wind's label: '$v_0$' / '$0.84v_0$' (tex) or 'v0' / '0.84v0'.

    Args:
        mult: the multiplier of the training mean speed v0.
        tex: LaTeX (tables) or plain text.

    Returns:
        The label.
    """
    if np.isclose(mult, 1.0):
        return "$v_0$" if tex else "v0"
    return f"${mult:.2f}v_0$" if tex else f"{mult:.2f}v0"


def check_keys(keys: Sequence, have: Mapping, what: str) -> None:
    """Refuse results that lack a key a table reads (KeyError naming them).

    Args:
        keys: the keys the table reads.
        have: the results, by key.
        what: the table (and seed) for the message.
    """
    missing = [k for k in keys if k not in have]
    if missing:
        raise KeyError(f"{what}: no results for {missing}; run the rules that produce them first")


def seeds_of(per_seed: Mapping[int, Mapping], what: str, keys: Sequence = ()) -> list[int]:
    """The training seeds of a builder's results, each checked to hold every one of ``keys``.

    Args:
        per_seed: ``{seed: {key: result}}`` (ValueError when empty, TypeError when not by seed).
        what: the table, for the messages.
        keys: the keys every seed must hold (``check_keys``).

    Returns:
        The seeds, sorted.
    """
    if not per_seed:
        raise ValueError(f"{what}: no seeds given")
    bad = [s for s in per_seed if not isinstance(s, (int, np.integer))]
    if bad:
        raise TypeError(
            f"{what}: results must be keyed by training seed first ({{seed: {{...}}}}), "
            f"got key {bad[0]!r}"
        )
    seeds = sorted(int(s) for s in per_seed)
    for s in seeds:
        check_keys(keys, per_seed[s], f"{what} (seed {s})")
    return seeds


def seed_rows(
    seeds: Sequence[int], keys: Sequence[tuple], row: Callable[..., dict]
) -> pd.DataFrame:
    """A table's CSV frame, seed by seed (the layout ``latex.by_seed`` reads).

    Args:
        seeds: the training seeds.
        keys: the table's row keys (tuples), in row order.
        row: ``row(seed, *key)`` -> that row's columns after ``seed``, in CSV order.

    Returns:
        [S * len(keys)] rows: ``seed``, then the row's columns.
    """
    return pd.DataFrame([{"seed": s, **row(s, *k)} for s in seeds for k in keys])


def tree_index(rows: pd.DataFrame, labels: Sequence[str], name: str) -> pd.MultiIndex:
    """A table's row labels grouped by tree (``latex.render`` spans each tree's rows).

    Args:
        rows: [R] the table's rows (``latex.rows``), with ``tree`` and ``bones``.
        labels: [R] each row's label within its tree.
        name: the inner level's name.

    Returns:
        [R] (the tree's label, the row's label).
    """
    trees = [tree_label(t, b) for t, b in zip(rows["tree"], rows["bones"])]
    return pd.MultiIndex.from_arrays([trees, list(labels)], names=["Tree", name])


def write_table(table: Table, tex_path: str | Path, csv_path: str | Path, stamp=None) -> None:
    """Write the table's .tex and .csv, each atomically.

    Args:
        table: the table.
        tex_path: the .tex to write.
        csv_path: the .csv to write.
        stamp (Stamp | None): a [`Stamp`][physgs.provenance.Stamp]; its fields become the CSV's
            last columns and a comment line of the .tex.
    """
    df, tex = table.df, table.tex
    if stamp is not None:
        df = df.assign(**stamp.to_dict())
        tex = "% " + ", ".join(f"{k}={v}" for k, v in stamp.to_dict().items()) + "\n" + tex
    write_text(tex_path, tex)
    with atomic_path(csv_path) as tmp:
        df.to_csv(tmp, index=False, float_format="%.6g")
