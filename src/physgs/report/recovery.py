"""tab_null (ours' frequencies against the untrained null) and tab_recovery (every recovery
method's, each against the null of its K), rows from ``registry.RECOVERY_METHODS``; tab_damping
(``physgs.report.damping``) shares their method rows (``MethodRows``)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial, reduce
from itertools import product
from operator import getitem
from typing import Mapping, Sequence

import pandas as pd

from physgs.models.registry import RECOVERY_METHODS, config_label, recovery_label, recovery_plan
from physgs.recovery.record import load_null, load_recovery
from physgs.report import latex
from physgs.report import seeds as seedstats
from physgs.report.output import Columns, Output
from physgs.report.table_captions import caption
from physgs.report.tables import Table, check_keys, seed_rows, seeds_of, tree_label

#: the method ids of the 2D-track control and the output-only analysis (``RECOVERY_METHODS``)
TRACKS, OMA = "tracks", "oma"
#: a method's name in the recovery tables' errors, where it is not its id
WHO = {TRACKS: "tracks control"}


@dataclass(frozen=True)
class MethodRows:
    """One recovery method's rows in tab_null, tab_recovery or tab_damping (``method_rows``).

    label: its LaTeX name ("" for ours: its rows are labelled by their configuration alone);
    configs: its configurations (name -> LaTeX label, with its own K), in row order; per_seed:
    ``per_seed[seed][key]`` (tab_null, tab_recovery: ``(tree, config)`` -> (``RecoveryRecord``,
    the ``NullResult`` of its K); tab_damping: ``(tree, variant, config)`` ->
    ``RecoveryRecord``); note: its sentence of the caption."""

    label: str
    configs: Mapping[str, str]
    per_seed: Mapping[int, Mapping[tuple, object]]
    note: str = ""


#: tab_null's and tab_recovery's CSV values (before ``INTERVAL_COLUMNS``) -> each from a
#: method's record and the null of its K
NULL_VALUES = {
    "trained_parts_trusted": lambda rec, nl: float(rec.match.n_trusted),
    "trained_median_rel_err_pct": lambda rec, nl: 100 * rec.match.median_rel_err,
    "trained_loglog_r2": lambda rec, nl: rec.match.loglog_r2,
    "null_parts_trusted": lambda rec, nl: nl.median_n_trusted,
    "null_median_rel_err_pct": lambda rec, nl: 100 * nl.median_median_rel_err,
    "null_loglog_r2": lambda rec, nl: nl.median_loglog_r2,
    "trained_minus_null_pp": (
        lambda rec, nl: 100 * rec.match.median_rel_err - 100 * nl.median_median_rel_err
    ),
    "nearest_bone_gap_pct": lambda rec, nl: 100 * nl.nearest_bone_gap,
    "trained_parts_trusted_visible": lambda rec, nl: float(rec.n_trusted_visible),
    "trained_median_rel_err_visible_pct": lambda rec, nl: 100 * rec.median_rel_err_visible,
    "null_parts_trusted_visible": lambda rec, nl: nl.median_n_trusted_visible,
    "null_median_rel_err_visible_pct": lambda rec, nl: 100 * nl.median_median_rel_err_visible,
}


def recovery_table(
    name: str, methods: Mapping[str, MethodRows], trees: Sequence, bones: Mapping, digits: int = 2
) -> Table:
    """Frequency recovery of each method against the untrained null, per tree and config.

    Columns, trained and null (null: medians over draws): parts trusted, median relative error
    (%), log-log R^2; trained - null (pp, paired per seed); the median nearest-bone gap (%).

    Args:
        name: tab_null (the paper's methods) or tab_recovery (every method, ours first); its
            label ``tab:<name without tab_>``, its caption's lead ``table_captions.TEXT[name]``.
        methods: method id -> its ``MethodRows``, in row order (one without configurations has
            no rows): ``per_seed[seed][(tree, config)]`` = (``RecoveryRecord``, ``NullResult``
            of that seed and the method's K).
        trees: the trees.
        bones: tree -> its bone count.
        digits: decimals shown in the .tex.

    Returns:
        The table: one CSV row per seed, tree, method and configuration.
    """

    def one(s, pair, t, c, method):
        rec, nl = pair
        m = rec.match
        if nl.n_parts != m.n_parts:
            raise ValueError(
                f"{name}: null for {t}/{c} (seed {s}) has K={nl.n_parts} but the "
                f"model has K={m.n_parts}; re-run the null with the model's K"
            )
        about = {"tree": t, "bones": bones[t], "config": c, "method": method, "K": m.n_parts}
        return about | {k: f(rec, nl) for k, f in NULL_VALUES.items()} | interval_cells(rec)

    def columns(df):
        col, fmt, out = partial(latex.cells, df), f".{int(digits)}f", {}
        for who, pre in (("Trained", "trained"), ("Untrained null", "null")):
            trusted = col(f"{pre}_parts_trusted", ".3g", cell=latex.mean)
            out[(who, "Parts")] = [f"{n}/{k}" for n, k in zip(trusted, latex.rows(df)["K"])]
            out[(who, r"Med.\ rel.\ err.")] = col(f"{pre}_median_rel_err_pct", fmt, r"\%")
            out[(who, r"log-log $R^2$")] = col(f"{pre}_loglog_r2", ".3f")
        out[("", r"Trained $-$ null")] = col(
            "trained_minus_null_pp", fmt, cell=seedstats.difference
        )
        out[("", "Gap")] = col("nearest_bone_gap_pct", fmt, r"\%", cell=latex.mean)
        for who, pre in (("Trained", "trained"), ("Null", "null")):
            out[("Visible bones", who)] = col(f"{pre}_median_rel_err_visible_pct", fmt, r"\%")
        return out

    lead = caption(name, "frequency_recovery")
    return _method_table(name, methods, trees, bones, one, columns, lead)


def _method_table(name, methods, trees, bones, one, columns, lead, testbeds=()) -> Table:
    """A recovery table of ``methods`` (those with configurations; each checked, KeyError, to
    hold its keys at every seed of the first) per tree (and testbed variant): CSV rows
    ``one(seed, per_seed[seed][(tree, *variant, config)], tree, *variant, config, method)``,
    .tex ``columns(df)``, the caption ``lead``, the methods' notes and the seed note."""
    methods = {m: mr for m, mr in methods.items() if mr.configs}
    rows = [  # method, config, its row's label (ours': the configuration's label alone)
        (m, c, f"{mr.label}, {mr.configs[c]}" if mr.label else mr.configs[c])
        for m, mr in methods.items()
        for c in mr.configs
    ]
    inner = [(v,) for v in testbeds] or [()]
    keys = [(t, *v, c, m) for t in trees for v in inner for m, c, _ in rows]
    seeds = seeds_of(next(iter(methods.values())).per_seed if methods else {}, name)
    for s, (m, mr) in product(seeds, methods.items()):
        mine = [k[:-1] for k in keys if k[-1] == m]
        check_keys(mine, mr.per_seed.get(s, {}), f"{name} ({WHO.get(m, m)}, seed {s})")
    df = seed_rows(seeds, keys, lambda s, *k: one(s, methods[k[-1]].per_seed[s][k[:-1]], *k))
    labels = [(tree_label(t, bones[t]), *v, lab) for t in trees for v in inner for *_, lab in rows]
    names = ["Tree", "Testbed", "Config"] if testbeds else ["Tree", "Config"]
    cells = pd.DataFrame(columns(df), index=pd.MultiIndex.from_tuples(labels, names=names))
    cap = lead + "".join(mr.note for mr in methods.values()) + latex.seed_note(len(seeds))
    return Table(name, df, latex.render(cells, cap, "tab:" + name.removeprefix("tab_")))


def method_rows(
    method: str, configs: Mapping[str, str], per_seed: Mapping[int, Mapping], damping: bool = False
) -> MethodRows:
    """A recovery method's rows, its label and caption sentence from ``RECOVERY_METHODS``.

    Args:
        method: a recovery method's id.
        configs: name -> LaTeX label (with its own K), as ``MethodRows.configs``.
        per_seed: its records, as ``MethodRows.per_seed``.
        damping: tab_damping's caption sentence (``damping_note``) in place of ``note``.

    Returns:
        The rows; the caption sentence ' <label>: <note>' ('' without a note).
    """
    rm, name = RECOVERY_METHODS[method], recovery_label(method)
    note = rm.damping_note if damping and rm.damping_note is not None else rm.note
    return MethodRows(name, configs, per_seed, f" {name}: {note}" if note else "")


#: tab_null / tab_damping's CSV columns of a method's own intervals (the output-only analysis';
#: NaN for a method without) -> where its record's ``intervals`` holds each: the median relative
#: sd (sigma / value) over its trusted parts, the coverage of their 95% intervals, the parts
#: covered, the parts its sigma rule keeps (alone, and with ours'), the mean relative interval
#: scores of its intervals and of the null's draw range (``physgs.oma.intervals.relative_scores``;
#: NaN in a record made before them)
INTERVALS = {
    "omega_rel_sd": ("median_rel_std", "omega"),
    "zeta_rel_sd": ("median_rel_std", "zeta"),
    "omega_interval_cover": ("coverage", "omega", "fraction"),
    "zeta_interval_cover": ("coverage", "zeta", "fraction"),
    "interval_parts": ("coverage", "omega", "n"),
    "sigma_parts_trusted": ("n_sigma_trusted",),
    "sigma_and_corr_parts_trusted": ("n_both_trusted",),
    "omega_interval_score": ("interval_score", "omega", "score"),
    "omega_null_interval_score": ("interval_score", "omega", "null_score"),
    "zeta_interval_score": ("interval_score", "zeta", "score"),
    "zeta_null_interval_score": ("interval_score", "zeta", "null_score"),
}
INTERVAL_COLUMNS = tuple(INTERVALS)


def interval_cells(rec) -> dict:
    """A record's ``INTERVAL_COLUMNS`` cells.

    Args:
        rec (RecoveryRecord): the record.

    Returns:
        Column -> value (NaN when the record has no ``intervals``).
    """
    iv, nan = rec.intervals, float("nan")
    if not iv:
        return dict.fromkeys(INTERVAL_COLUMNS, nan)
    scores = {  # NaN where the record has none (made before them)
        q: {"score": nan, "null_score": nan} | iv.get("interval_score", {}).get(q, {})
        for q in ("omega", "zeta")
    }
    iv = {**iv, "interval_score": scores}
    return {c: float(reduce(getitem, at, iv)) for c, at in INTERVALS.items()}


# ---- the declarations ----------------------------------------------------------------------
def _label_with_k(cfg: dict, config: str, K: int) -> str:
    """The LaTeX label of ``config`` for a method with K parts of its own there."""
    return config_label(config, {**cfg["models"]["configs"][config], "K": K})


def _methods_settings(cfg: dict, methods: Sequence[str], configs: Sequence[str]) -> dict:
    """``{"methods": {id: {config: {"K", "label"}}}}``: each of ``methods`` the run scores, in
    its configurations among ``configs``, with its own K."""
    plan, label = recovery_plan(cfg), partial(_label_with_k, cfg)
    mine = {m: {c: k for c, k in plan[m].items() if c in configs} for m in methods if m in plan}
    return {
        "methods": {
            m: {c: {"K": k, "label": label(c, k)} for c, k in ck.items()} for m, ck in mine.items()
        }
    }


def _methods_needs(plan, methods, configs, testbeds, s: int) -> list[tuple]:
    """``("recovery", testbed, method, config, s)`` of each method in its configurations
    (``plan.recovery``) among ``configs``."""
    return [
        ("recovery", tb, m, c, s)
        for tb in testbeds
        for m in methods
        for c in plan.recovery.get(m, {})
        if c in configs
    ]


def _table_methods(settings: dict, read, testbeds=None, damping=False) -> dict[str, MethodRows]:
    """Method id -> its ``MethodRows`` in ``RECOVERY_METHODS``' order (ours first), from the
    ``_methods_settings``: each record ``read(method, K, testbed, config, seed)`` at key (tree,
    *variant, config), ``testbeds(tree)``: {(variant,): testbed id} (None: the tree alone)."""
    out, methods, trees = {}, settings["methods"], settings["trees"]
    beds = testbeds or (lambda t: {(): t})
    for m in (m for m in RECOVERY_METHODS if m in methods):
        labels, ks = ({c: v[f] for c, v in methods[m].items()} for f in ("label", "K"))
        at = [
            ((t, *v, c), tb, c, k)
            for t in trees
            for v, tb in beds(t).items()
            for c, k in ks.items()
        ]
        per_seed = {
            s: {key: read(m, k, tb, c, s) for key, tb, c, k in at} for s in settings["seeds"]
        }
        out[m] = method_rows(m, labels, per_seed, damping=damping)
    return out


def _paper(plan_or_methods) -> list[str]:
    """The paper's recovery methods among these (tab_null's rows)."""
    return [m for m in plan_or_methods if RECOVERY_METHODS[m].paper]


#: tab_null's and tab_recovery's CSV: one row per seed, tree, configuration and method id
NULL_COLUMNS = Columns(
    keys=("seed", "tree", "config", "method"),
    values=(*NULL_VALUES, *INTERVAL_COLUMNS),
    about=("bones", "K"),
)


def _frequency_output(name: str, methods, in_report=lambda plan: True) -> Output:
    """A frequency-recovery table of the methods ``methods(ids)``, each beside its K's null."""

    def needs(plan, seeds):
        mine = methods(plan.recovery)
        out = []
        for s in seeds:
            out += _methods_needs(plan, mine, plan.configs, plan.trees, s)
            nulls = {int(k) for m in mine for k in plan.recovery[m].values()}
            out += [("null", t, k, s) for t in plan.trees for k in sorted(nulls)]
        return out

    def settings(cfg):
        return _methods_settings(cfg, methods(recovery_plan(cfg)), cfg["models"]["configs"])

    def table(path, settings, inputs, out):
        def read(m, K, t, c, s):  # its record and the null of its K
            rec = load_recovery(path("recovery", t, m, c, s))
            return rec, load_null(path("null", t, int(K), s))

        rows, trees = _table_methods(settings, read), settings["trees"]
        return recovery_table(name, rows, trees, settings["bones"], digits=settings["digits"])

    return Output(
        name, "table", needs, table, settings=settings, in_report=in_report, columns=NULL_COLUMNS
    )


TAB_NULL = _frequency_output("tab_null", _paper)
TAB_RECOVERY = _frequency_output(
    "tab_recovery", list, in_report=lambda plan: len(plan.recovery) > len(_paper(plan.recovery))
)
