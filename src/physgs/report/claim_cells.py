"""Where each claim of the catalogue ([`physgs.report.catalogue`][physgs.report.catalogue]) is
measured: what a claim family ranges over (its *scope*: the cells of the ledger it makes, from
the run's trees, the priors of the registry and what the tables hold) and how one seed's value
is read from one seed's rows of its table (its *reader*).

A scope takes the [`Run`][physgs.report.claim_cells.Run] (and reads only the family's own table,
``Run.own``: moving a family to another table is its entry's ``table``) and returns its cells: one dict per
claim, with ``suffix`` (the claim id after the family, "" for none), the fields its sentence
and its reader use (``tree``, ``config``, ``method``, ...) and, where the id is not the asked
prior's, ``prefix``. A reader takes one seed's rows and a cell and returns a float, NaN where
the rows are not there (a model the run's table does not hold: "undecided: not measured").

Which trees a role-scoped family asks (the tree whose bones' frequencies the untrained null
cannot fake, the trees where it is expected to match) is declared in each tree's preset
(``presets.<tree>.role`` in config/trees.yaml: ``frequencies`` separated or tiled, and
``paper``, the paper's tree it stands for and whose figures it is read against), never by a
tree's name: a tree without a role gets the claims of every tree and none of a role's.

A table without a ``method`` (``model``) column is ours' alone (a table made before another
prior joined it). Cells read by id or by display label alike where a table holds labels
(``tab_psnr``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.models.registry import BLIND_CONFIG, BLIND_PRIORS, label, models_of, spec_of
from physgs.report import paper
from physgs.report.tables import OMA
from physgs.testbed.variant import DAMPING

#: The configuration the recovery claims read (the paper's joint K = 32; the base configuration
#: where a config has none: ``physgs.report.build.claims_needs``).
CONFIG = "joint32"
#: The pseudo-table of the priors' damping summaries (one row per seed, model and tree:
#: median_zeta, zeta_true, loglog_exponent), read from their recovery records.
RECOVERY = "recovery"

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
        roles: tree -> its preset's ``role`` (``frequencies``, ``paper``); a tree not in it has
            none.
    """

    tables: Mapping[str, pd.DataFrame]
    trees: Sequence[str]
    model: str = "ours"
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


#: The role of a tree whose bones' frequencies the untrained null cannot fake (the null loses).
SEPARATED = "separated"
#: The role of a tree whose bones' frequencies tile the axis (the null is expected to match).
TILED = "tiled"


def roles_of(presets: Mapping[str, Mapping], trees: Sequence[str]) -> dict[str, dict[str, str]]:
    """Each tree's role as its preset declares it (config ``presets.<tree>.role``).

    Args:
        presets: tree -> its preset.
        trees: the trees.

    Returns:
        tree -> ``{frequencies, paper}`` (only what the preset declares; {} for none).
    """
    return {t: dict((presets.get(t) or {}).get("role") or {}) for t in trees}


def fields() -> tuple[str, ...]:
    """The learned deformation fields.

    Returns:
        The model ids of registry role "field".
    """
    return models_of("field")


#: The kinds of learned field, by whether the field's registry entry reads the wind
#: (``ModelSpec.wind``): kind id -> its words. The paper's headline lumps both kinds; the
#: project's split families (``physgs.report.catalogue``) ask it of each.
FIELD_KINDS = {"blind": "wind-blind", "wind": "wind-conditioned"}


def fields_of_kind(kind: str) -> tuple[str, ...]:
    """The learned fields of one kind, from the registry (never from their names).

    Args:
        kind: a key of ``FIELD_KINDS``.

    Returns:
        The model ids of role "field" whose spec reads the wind (``"wind"``) or does not
            (``"blind"``), in registry order.
    """
    return tuple(m for m in fields() if spec_of(m).wind == (kind == "wind"))


# ---- helpers --------------------------------------------------------------------------------
def value(df: pd.DataFrame, mask: pd.Series, col: str) -> float:
    """The single cell of ``col`` where ``mask`` holds.

    Args:
        df: one seed's rows of a table.
        mask: the row to read, ``[len(df)]`` booleans.
        col: the column.

    Returns:
        The cell; NaN where no row holds or ``col`` is not a column.
    """
    if col not in df.columns:
        return float("nan")
    v = df.loc[mask, col]
    return float(v.iloc[0]) if len(v) else float("nan")


def _rows_of(df: pd.DataFrame, who: str, col: str = "method") -> pd.Series:
    """Rows of method (or model) ``who``; a table without the column holds ours' only."""
    if col in df.columns:
        return df[col].astype(str) == who
    return pd.Series(who == "ours", index=df.index)


def _psnr(d: pd.DataFrame, tree: str, model: str, split: str) -> float:
    """tab_psnr's ``<tree>_<split>`` cell of ``model`` (its id or its label)."""
    m = d["model"].astype(str)
    return value(d, m == model, f"{tree}_{split}")  # ids (the labels are the .tex's)


def _recovery(d: pd.DataFrame, c: Cell, col: str) -> float:
    return value(d, (d["model"] == c["model"]) & (d["tree"] == c["tree"]), col)


# ---- scopes: what a family ranges over --------------------------------------------------------
def _trees(run: Run) -> list[Cell]:
    """each tree"""
    return [{"suffix": t, "tree": t, "paper": run.role(t, "paper")} for t in run.trees]


def _with_role(run: Run, role: str) -> list[Cell]:
    return [c for c in _trees(run) if run.role(c["tree"], "frequencies") == role]


def _separated(run: Run) -> list[Cell]:
    """each tree whose preset declares its frequencies separated (the null cannot fake them)"""
    return _with_role(run, SEPARATED)


def _tiled(run: Run) -> list[Cell]:
    """each tree whose preset declares its frequencies tiled (the null expected to match)"""
    return _with_role(run, TILED)


def _gap_trees(run: Run) -> list[Cell]:
    """each tree standing for a paper's tree whose nearest-bone gap the paper states"""
    return [c for c in _trees(run) if c["paper"] in paper.NEAREST_BONE_GAP_PCT]


def _recovered_trees(run: Run) -> list[Cell]:
    """each tree with the asked prior's recovery records (joint K = 32)"""
    rec = run.own
    if rec is None:
        return []
    have = set(rec.loc[rec["model"] == run.model, "tree"])
    return [{**c, "config": CONFIG} for c in _trees(run) if c["tree"] in have]


def _fit_models(run: Run) -> list[Cell]:
    """each tree x each learned field, ours and every other prior the tables hold"""
    return [
        {"suffix": f"{t}/{m}", "tree": t, "fit_model": m, "fit_label": label(m)}
        for t in run.trees
        for m in (*fields(), "ours", *run.others)
    ]


def _kind_cells(cells: list[Cell]) -> list[Cell]:
    """``cells`` x each kind of learned field the registry holds, the kind in the suffix after
    the tree."""
    out = []
    for c in cells:
        for k, words in FIELD_KINDS.items():
            ms = fields_of_kind(k)
            if not ms:  # a registry without fields of this kind asks nothing of it
                continue
            rest = c["suffix"].split("/", 1)[1:]  # what follows the tree (a wind), if anything
            out.append(
                {
                    **c,
                    "suffix": "/".join([c["tree"], k, *rest]),
                    "kind": k,
                    "kind_words": words,
                    "kind_fields": ", ".join(label(m) for m in ms),
                }
            )
    return out


def _kind_trees(run: Run) -> list[Cell]:
    """each tree x each kind of learned field (wind-blind, wind-conditioned: whether its
    registry entry reads the wind)"""
    return _kind_cells(_trees(run))


def _kind_winds_beyond(run: Run) -> list[Cell]:
    """each tree x each kind of learned field (wind-blind, wind-conditioned: whether its
    registry entry reads the wind) x unseen wind of tab_transfer, beyond the window"""
    return _kind_cells(_winds_beyond(run))


def _splits(run: Run) -> list[Cell]:
    """each tree x held-out views and beyond the window"""
    words = {"view": "held-out views", "time": "beyond the window"}
    return [
        {"suffix": f"{t}/{sp}", "tree": t, "split": sp, "where": w}
        for t in run.trees
        for sp, w in words.items()
    ]


def _winds_beyond(run: Run) -> list[Cell]:
    """each tree x unseen wind of tab_transfer, beyond the window"""
    tr = run.own
    if tr is None:
        return []
    beyond = tr[tr["split"] == "beyond"] if "split" in tr.columns else tr
    return [
        {"suffix": f"{t}/{c:.2f}", "tree": t, "condition": c, "cond": f"{c:.2f}", "split": "beyond"}
        for (t, c), _ in beyond.groupby(["tree", "condition"], sort=False)
    ]


def _winds(run: Run) -> list[Cell]:
    """each split (training timestamps, beyond the window) x tree x unseen wind of tab_transfer"""
    tr = run.own
    if tr is None:
        return []
    where = {"beyond": "beyond the window"}
    return [
        {
            "suffix": f"{t}/wind_{sp}/{c:.2f}",
            "tree": t,
            "condition": c,
            "cond": f"{c:.2f}",
            "split": sp,
            "where": where.get(sp, "at training timestamps"),
        }
        for (sp, t, c), _ in tr.groupby(["split", "tree", "condition"], sort=False)
    ]


def _margin_trees(run: Run) -> list[Cell]:
    """each tree, tab_margin's first and last wind"""
    mg = run.own
    cols = [c for c in mg.columns if c.startswith("margin_")] if mg is not None else []
    first, last = (cols[0], cols[-1]) if cols else ("first", "last")
    return [{**c, "first": first, "last": last} for c in _trees(run)]


def _recovery_trees(run: Run) -> list[Cell]:
    """each tree, in the ledger's recovery configuration (joint K = 32)"""
    return [{**c, "config": CONFIG, "method": run.model} for c in _trees(run)]


def _null_trees_separated(run: Run) -> list[Cell]:
    """each tree of separated frequencies, in the ledger's recovery configuration (joint K =
    32)"""
    return [{**c, "config": CONFIG, "method": run.model} for c in _separated(run)]


def _null_trees_tiled(run: Run) -> list[Cell]:
    """each tree of tiled frequencies, in the ledger's recovery configuration (joint K = 32)"""
    return [{**c, "config": CONFIG, "method": run.model} for c in _tiled(run)]


def _parts(run: Run) -> tuple[pd.DataFrame | None, set, str]:
    df = run.own
    if df is None or df.empty:
        return None, set(), ""
    return df, set(df["model"]), str(df["config"].iloc[0])


def _parts_damping_trees(run: Run) -> list[Cell]:
    """each tree with a damping testbed in tab_parts (its first configuration), when it holds
    the topology parts"""
    df, models, c0 = _parts(run)
    if df is None or "ours_topo" not in models:
        return []
    return [
        {**c, "config": c0}
        for c in _trees(run)
        if np.isfinite(df.loc[df["tree"] == c["tree"], "zeta_rel_err_pct"]).any()
    ]


def _parts_coupling(run: Run) -> list[Cell]:
    """each tree of separated frequencies in tab_parts (its first configuration), when it holds
    both topology priors (no id suffix for a single such tree: the family's id as before)"""
    df, models, c0 = _parts(run)
    if df is None or not {"ours_topo", "ours_chain"} <= models:
        return []
    cells = _separated(run)
    one = len(cells) == 1
    return [{**c, "suffix": "" if one else c["tree"], "config": c0} for c in cells]


def _tracks_separated(run: Run) -> list[Cell]:
    """each tree of separated frequencies, the 2D-track control's recovery in joint K = 32
    (else its first configuration)"""
    null = run.own
    if null is None or "method" not in null.columns:
        return []
    cfgs = list(dict.fromkeys(null.loc[null["method"] == "tracks", "config"]))
    if not cfgs:
        return []
    c = CONFIG if CONFIG in cfgs else cfgs[0]
    return [{**x, "config": c, "method": "tracks"} for x in _separated(run)]


def _tracks_trees(run: Run) -> list[Cell]:
    """each tree in tab_tracks, its base configuration (else its first)"""
    tr = run.own
    if tr is None:
        return []
    tc = list(dict.fromkeys(tr["config"]))
    if not tc:
        return []
    c = "single" if "single" in tc else tc[0]
    return [{**x, "config": c} for x in _trees(run) if (tr["tree"] == x["tree"]).any()]


def _blind_trees(run: Run) -> list[Cell]:
    """each forcing-free prior in tab_recovery x each tree, against the prior whose measured wind it
    replaces (ids ``<prior>/...`` for a prior other than ours)"""
    null = run.own
    if null is None or "method" not in null.columns:
        return []
    have, out = set(null["method"]), []
    for blind in (m for m in BLIND_PRIORS if m in have):
        wind = spec_of(blind).blind_of
        who, prefix = ("ours", "") if wind == "ours" else (f"the {label(wind)}", f"{wind}/")
        out += [
            {
                **c,
                "prefix": prefix,
                "blind": blind,
                "wind": wind,
                "who": who,
                "config": BLIND_CONFIG,
            }
            for c in _trees(run)
            if (null["tree"] == c["tree"]).any()
        ]
    return out


def _oma_separated(run: Run) -> list[Cell]:
    """each tree of separated frequencies, when tab_recovery holds the output-only analysis"""
    null = run.own
    if null is None or "method" not in null.columns or OMA not in set(null["method"]):
        return []
    return [{**c, "config": BLIND_CONFIG, "method": OMA} for c in _separated(run)]


def _oma_damping_trees(run: Run) -> list[Cell]:
    """each tree of tab_damping, when it holds the output-only analysis"""
    dmp = run.own
    if dmp is None or "method" not in dmp.columns or OMA not in set(dmp["method"]):
        return []
    return [{**c, "config": BLIND_CONFIG} for c in _trees(run) if (dmp["tree"] == c["tree"]).any()]


def _oma_interval_trees(run: Run) -> list[Cell]:
    """each tree of tab_damping, when it holds the output-only analysis' interval coverage"""
    dmp = run.own
    if dmp is None or "omega_interval_cover" not in dmp.columns:
        return []
    return _oma_damping_trees(run)


# ---- readers: one seed's value ---------------------------------------------------------------
def _best_field_minus_static(d: pd.DataFrame, c: Cell) -> float:
    """tab_psnr, time column: max over learned fields of (model - static)"""
    best = max(_psnr(d, c["tree"], m, "time") for m in fields())
    return best - _psnr(d, c["tree"], "static", "time")


def _kind_minus_static(d: pd.DataFrame, c: Cell) -> float:
    """tab_psnr, time column: max over the kind's learned fields of (model - static)"""
    best = max(_psnr(d, c["tree"], m, "time") for m in fields_of_kind(c["kind"]))
    return best - _psnr(d, c["tree"], "static", "time")


def _above_static(d: pd.DataFrame, c: Cell) -> float:
    """tab_psnr, time column: the prior - static"""
    return _psnr(d, c["tree"], c["model"], "time") - _psnr(d, c["tree"], "static", "time")


def _ahead_of_fields(d: pd.DataFrame, c: Cell) -> float:
    """tab_psnr, the cell's split: the prior - max over learned fields"""
    t, sp = c["tree"], c.get("split", "view")
    return _psnr(d, t, c["model"], sp) - max(_psnr(d, t, m, sp) for m in fields())


def _wind_row(d: pd.DataFrame, c: Cell):
    return (
        (d["split"] == c["split"])
        & (d["tree"] == c["tree"])
        & np.isclose(d["condition"], c["condition"])
    )


def _wind_ahead(d: pd.DataFrame, c: Cell) -> float:
    """tab_transfer: the prior - max over learned fields"""
    row = _wind_row(d, c)
    return value(d, row, c["model"]) - max(value(d, row, m) for m in fields())


def _wind_fields_minus_static(d: pd.DataFrame, c: Cell) -> float:
    """tab_transfer: max over learned fields - static"""
    row = _wind_row(d, c)
    return max(value(d, row, m) for m in fields()) - value(d, row, "static")


def _wind_kind_minus_static(d: pd.DataFrame, c: Cell) -> float:
    """tab_transfer: max over the kind's learned fields - static"""
    row = _wind_row(d, c)
    return max(value(d, row, m) for m in fields_of_kind(c["kind"])) - value(d, row, "static")


def _margin_growth(d: pd.DataFrame, c: Cell) -> float:
    """tab_margin: the prior's last wind's margin - its first's"""
    mine = (d["tree"] == c["tree"]) & _rows_of(d, c["model"], "model")
    return value(d, mine, c["last"]) - value(d, mine, c["first"])


def _null_row(d: pd.DataFrame, c: Cell):
    who = c.get("method", c["model"])
    return _rows_of(d, who) & (d["tree"] == c["tree"]) & (d["config"] == c["config"])


def _null_over_trained(d: pd.DataFrame, c: Cell) -> float:
    """tab_null / tab_recovery: null / trained median omega error of the cell's method"""
    row = _null_row(d, c)
    return value(d, row, "null_median_rel_err_pct") / value(d, row, "trained_median_rel_err_pct")


def _trained_minus_null(d: pd.DataFrame, c: Cell) -> float:
    """tab_null / tab_recovery: trained - null median omega error of the cell's method (points)"""
    row = _null_row(d, c)
    return value(d, row, "trained_median_rel_err_pct") - value(d, row, "null_median_rel_err_pct")


def _gap_off(d: pd.DataFrame, c: Cell) -> float:
    """tab_testbed: |nearest-bone gap - the paper's tree's| / the paper's"""
    g = paper.NEAREST_BONE_GAP_PCT[c["paper"]]
    return abs(value(d, d["tree"] == c["tree"], "nearest_bone_gap_pct") - g) / g


def _damping_off(d: pd.DataFrame, c: Cell) -> float:
    """the prior's recovery: |median zeta_hat - zeta| / zeta"""
    z = _recovery(d, c, "zeta_true")
    return abs(_recovery(d, c, "median_zeta") - z) / z


def _decay_exponent(d: pd.DataFrame, c: Cell) -> float:
    """the prior's recovery: the exponent p of gamma ~ omega^p"""
    return _recovery(d, c, "loglog_exponent")


def _fit_fraction(d: pd.DataFrame, c: Cell) -> float:
    """tab_fit: (fit - static) / (ceiling - static) on the trained frames"""
    return value(d, (d["tree"] == c["tree"]) & (d["model"] == c["fit_model"]), "ceiling_frac")


def _parts_value(d: pd.DataFrame, c: Cell, model: str, col: str) -> float:
    row = (d["tree"] == c["tree"]) & (d["model"] == model) & (d["config"] == c["config"])
    return value(d, row, col)


def _topology_damping_gain(d: pd.DataFrame, c: Cell) -> float:
    """tab_parts: median zeta error, topology - k-means parts (points)"""
    col = "zeta_rel_err_pct"
    return _parts_value(d, c, "ours_topo", col) - _parts_value(d, c, "ours", col)


def _coupling_gain(d: pd.DataFrame, c: Cell) -> float:
    """tab_parts: ceiling fraction, chained - independent topology parts"""
    col = "ceiling_frac"
    return _parts_value(d, c, "ours_chain", col) - _parts_value(d, c, "ours_topo", col)


def _tracks_minus_ours(d: pd.DataFrame, c: Cell) -> float:
    """tab_recovery: 2D tracks - ours median omega error (points); NaN at another K than ours'"""
    tracks, ours = _null_row(d, c), _null_row(d, {**c, "method": "ours"})
    if value(d, tracks, "K") != value(d, ours, "K"):
        return float("nan")  # another K: not the same question
    col = "trained_median_rel_err_pct"
    return value(d, tracks, col) - value(d, ours, col)


def _tracks_tail(d: pd.DataFrame, c: Cell) -> float:
    """tab_tracks: tail displacement error, 2D tracks - ours (px)"""
    row = (d["tree"] == c["tree"]) & (d["config"] == c["config"])
    return value(d, row, "tail_px") - value(d, row, "tail_ours_px")


def _blind_minus_wind(d: pd.DataFrame, c: Cell) -> float:
    """tab_recovery: forcing-free prior - its wind-reading prior, median omega error (points)"""
    col = "trained_median_rel_err_pct"
    blind, wind = (
        _null_row(d, {**c, "method": c["blind"]}),
        _null_row(d, {**c, "method": c["wind"]}),
    )
    return value(d, blind, col) - value(d, wind, col)


def _oma_zeta_gain(d: pd.DataFrame, c: Cell) -> float:
    """tab_damping (damping testbed): output-only - null median zeta error (points)"""
    return value(d, _oma_damping_row(d, c), "trained_minus_null_pp")


def _oma_damping_row(d: pd.DataFrame, c: Cell) -> pd.Series:
    return (
        (d["testbed"] == DAMPING)
        & (d["tree"] == c["tree"])
        & (d["config"] == c["config"])
        & (d["method"] == OMA)
    )


def _oma_omega_cover(d: pd.DataFrame, c: Cell) -> float:
    """tab_damping (damping testbed): the output-only analysis' omega interval coverage"""
    return value(d, _oma_damping_row(d, c), "omega_interval_cover")


def _oma_zeta_cover(d: pd.DataFrame, c: Cell) -> float:
    """tab_damping (damping testbed): the output-only analysis' zeta interval coverage"""
    return value(d, _oma_damping_row(d, c), "zeta_interval_cover")


def _score_ratio(d: pd.DataFrame, c: Cell, q: str) -> float:
    row = _oma_damping_row(d, c)
    return value(d, row, f"{q}_null_interval_score") / value(d, row, f"{q}_interval_score")


def _oma_omega_score(d: pd.DataFrame, c: Cell) -> float:
    """tab_damping (damping testbed): the null's draw range over the output-only analysis'
    omega intervals, mean relative interval score (null / output-only)"""
    return _score_ratio(d, c, "omega")


def _oma_zeta_score(d: pd.DataFrame, c: Cell) -> float:
    """tab_damping (damping testbed): the null's draw range over the output-only analysis'
    zeta intervals, mean relative interval score (null / output-only)"""
    return _score_ratio(d, c, "zeta")


def _halfwidth(d: pd.DataFrame, c: Cell, q: str) -> float:
    from physgs.oma.intervals import Z95  # here: scipy, which planning never loads

    return Z95 * value(d, _oma_damping_row(d, c), f"{q}_rel_sd")


def _oma_omega_halfwidth(d: pd.DataFrame, c: Cell) -> float:
    """tab_damping (damping testbed): the output-only analysis' median relative half-width of
    its omega intervals, 1.96 sigma / omega"""
    return _halfwidth(d, c, "omega")


def _oma_zeta_halfwidth(d: pd.DataFrame, c: Cell) -> float:
    """tab_damping (damping testbed): the output-only analysis' median relative half-width of
    its zeta intervals, 1.96 sigma / zeta"""
    return _halfwidth(d, c, "zeta")


#: A reader: one seed's rows and a cell -> the claim's value.
Reader = Callable[[pd.DataFrame, Cell], float]
#: A scope: the run -> the family's cells.
Scope = Callable[[Run], list[Cell]]

#: The scopes a catalogue entry names (``ClaimSpec.over``); each one's docstring says what it
#: ranges over (the claims page prints it).
SCOPES: dict[str, Scope] = {
    "trees": _trees,
    "separated": _separated,
    "tiled": _tiled,
    "gap_trees": _gap_trees,
    "recovered_trees": _recovered_trees,
    "fit_models": _fit_models,
    "splits": _splits,
    "winds_beyond": _winds_beyond,
    "kind_trees": _kind_trees,
    "kind_winds_beyond": _kind_winds_beyond,
    "winds": _winds,
    "margin_trees": _margin_trees,
    "recovery_trees": _recovery_trees,
    "null_trees_separated": _null_trees_separated,
    "null_trees_tiled": _null_trees_tiled,
    "parts_damping_trees": _parts_damping_trees,
    "parts_coupling": _parts_coupling,
    "tracks_separated": _tracks_separated,
    "tracks_trees": _tracks_trees,
    "blind_trees": _blind_trees,
    "oma_separated": _oma_separated,
    "oma_damping_trees": _oma_damping_trees,
    "oma_interval_trees": _oma_interval_trees,
}
#: The readers a catalogue entry names (``ClaimSpec.read``); each one's docstring says what it
#: reads.
READERS: dict[str, Reader] = {
    "best_field_minus_static": _best_field_minus_static,
    "above_static": _above_static,
    "ahead_of_fields": _ahead_of_fields,
    "wind_ahead": _wind_ahead,
    "wind_fields_minus_static": _wind_fields_minus_static,
    "kind_minus_static": _kind_minus_static,
    "wind_kind_minus_static": _wind_kind_minus_static,
    "margin_growth": _margin_growth,
    "null_over_trained": _null_over_trained,
    "trained_minus_null": _trained_minus_null,
    "gap_off": _gap_off,
    "damping_off": _damping_off,
    "decay_exponent": _decay_exponent,
    "fit_fraction": _fit_fraction,
    "topology_damping_gain": _topology_damping_gain,
    "coupling_gain": _coupling_gain,
    "tracks_minus_ours": _tracks_minus_ours,
    "tracks_tail": _tracks_tail,
    "blind_minus_wind": _blind_minus_wind,
    "oma_zeta_gain": _oma_zeta_gain,
    "oma_omega_cover": _oma_omega_cover,
    "oma_zeta_cover": _oma_zeta_cover,
    "oma_omega_score": _oma_omega_score,
    "oma_zeta_score": _oma_zeta_score,
    "oma_omega_halfwidth": _oma_omega_halfwidth,
    "oma_zeta_halfwidth": _oma_zeta_halfwidth,
}
