"""What the claims of the catalogue ([`physgs.report.catalogue`][physgs.report.catalogue]) are
measured on: the [`Run`][physgs.report.claim_cells.Run] a family is asked of, the trees' roles
and the reading of one cell of one seed's rows.

A family's *scope* (``ClaimSpec.over``) takes the run, reads only its own table (``Run.own``)
and returns one cell per claim: a dict with ``suffix`` (the id after the family, "" for none),
the fields its sentence and reader use and, where the id is not the asked prior's, ``prefix``.
Its *reader* (``ClaimSpec.read``) takes one seed's rows and a cell and returns a float, NaN
where the rows are not there ("undecided: not measured").

A role-scoped family asks the trees whose preset declares the role (``presets.<tree>.role`` in
config/trees.yaml: ``frequencies`` separated or tiled, and ``paper``, the paper's tree it stands
for), never a tree by name. A table without a ``method`` (``model``) column is ours' alone.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import pandas as pd

from physgs.models.registry import PAPER_MODEL, models_of, spec_of

#: The configuration the recovery claims read (the paper's joint K = 32).
CONFIG = "joint32"
#: The pseudo-table of the priors' damping summaries (one row per seed, model and tree).
RECOVERY = "recovery"
#: The role of a tree whose bones' frequencies the untrained null cannot fake (the null loses).
SEPARATED = "separated"
#: The role of a tree whose bones' frequencies tile the axis (the null is expected to match).
TILED = "tiled"
#: The kinds of learned field, by whether its registry entry reads the wind: id -> its words.
FIELD_KINDS = {"blind": "wind-blind", "wind": "wind-conditioned"}

Cell = dict[str, Any]


@dataclass(frozen=True)
class Run:
    """What a claim family is asked of.

    Attributes:
        tables: table name -> its CSV (one row per seed; ``RECOVERY`` the damping summaries).
        trees: the run's trees.
        model: the prior the claim is asked of (``ours``, or another prior of the registry).
        others: the priors other than ours that the run's tables hold.
        table: the family's table (``ClaimSpec.table``): the one its scope reads.
        roles: tree -> its preset's ``role`` (``frequencies``, ``paper``).
    """

    tables: Mapping[str, pd.DataFrame]
    trees: Sequence[str]
    model: str = PAPER_MODEL
    others: tuple[str, ...] = ()
    table: str = ""
    roles: Mapping[str, Mapping[str, str]] = field(default_factory=dict)

    @property
    def own(self) -> pd.DataFrame | None:
        """The family's table, None where the run did not make it."""
        return self.tables.get(self.table)

    def role(self, tree: str, key: str) -> str | None:
        """A tree's declared role.

        Args:
            tree: the tree.
            key: ``frequencies`` or ``paper``.

        Returns:
            The preset's value; None where it declares none.
        """
        return (self.roles.get(tree) or {}).get(key)


#: A scope: the run -> the family's cells (its docstring: what the claims page says it ranges
#: over).
Scope = Callable[[Run], list[Cell]]
#: A reader: one seed's rows of the family's table and a cell -> the claim's value.
Reader = Callable[[pd.DataFrame, Cell], float]


def roles_of(presets: Mapping[str, Mapping], trees: Sequence[str]) -> dict[str, dict[str, str]]:
    """Each tree's role as its preset declares it (config ``presets.<tree>.role``).

    Args:
        presets: tree -> its preset.
        trees: the trees.

    Returns:
        tree -> ``{frequencies, paper}`` (only what the preset declares; {} for none).
    """
    return {t: dict((presets.get(t) or {}).get("role") or {}) for t in trees}


def fields_of_kind(kind: str) -> tuple[str, ...]:
    """The learned fields of one kind, from the registry (never from their names).

    Args:
        kind: a key of ``FIELD_KINDS``.

    Returns:
        The model ids of role "field" that read the wind (``"wind"``) or not (``"blind"``).
    """
    return tuple(m for m in models_of("field") if spec_of(m).wind == (kind == "wind"))


def value(df: pd.DataFrame, mask: pd.Series, col: str) -> float:
    """The single cell of ``col`` where ``mask`` holds.

    Args:
        df: one seed's rows of a table.
        mask: the row to read, ``[len(df)]`` booleans.
        col: the column.

    Returns:
        The cell; NaN where no row holds or ``col`` is not a column.
    """
    v = df.loc[mask, col] if col in df.columns else ()
    return float(v.iloc[0]) if len(v) else float("nan")


def rows_of(df: pd.DataFrame, who: str, col: str = "method") -> pd.Series:
    """The rows of one method (or model); a table without the column holds ours' only.

    Args:
        df: one seed's rows of a table.
        who: the method's (or model's) id.
        col: the column naming it.

    Returns:
        ``[len(df)]`` booleans.
    """
    if col in df.columns:
        return df[col].astype(str) == who
    return pd.Series(who == PAPER_MODEL, index=df.index)
