"""Per-job result files into the tables, figures and claims ledger (what the report rules call).

Each output (``physgs.report.outputs``) declares what it reads as need tuples (``needs``, fields
``NEED_FIELDS``); the workflow maps each to a path (``workflow/rules/common.smk``) and hands the
builders ``key(need) -> path`` (the claims ledger: ``need -> path``). ``settings_for`` gives the
narrow settings an output reads, so editing one table's format rebuilds that table only.
"""

from __future__ import annotations

from itertools import product
from typing import Mapping, Sequence

import pandas as pd

from physgs.atomic import atomic_path, write_text
from physgs.config import study_seeds
from physgs.models.registry import BASE_CONFIG, models_of
from physgs.provenance import read_stamped
from physgs.recovery.record import load_recovery
from physgs.report import catalogue, claims, tables
from physgs.report.claim_cells import CONFIG as CLAIMS_CONFIG
from physgs.report.outputs import NEED_FIELDS, OUTPUTS, Plan, key, reader
from physgs.report.images import fit_row

__all__ = ["NEED_FIELDS", "Plan", "fit_row", "key"]

TABLES = tuple(n for n, o in OUTPUTS.items() if o.kind == "table")
FIGURES = tuple(n for n, o in OUTPUTS.items() if o.kind == "figure")


def _output(name: str, kind: str | None = None):
    """The output ``name`` (of ``kind`` when given), or ValueError naming the choices."""
    o = OUTPUTS.get(name)
    if o is None:
        raise ValueError(f"unknown output '{name}'; choose one of {TABLES + FIGURES}")
    if kind is not None and o.kind != kind:
        names = TABLES if kind == "table" else FIGURES
        raise ValueError(f"unknown {kind} '{name}'; choose one of {names}")
    return o


def in_report(name: str, plan: Plan) -> bool:
    """Whether the ``report`` target builds output ``name`` (ValueError for an unknown one).

    Args:
        name: an output's name.
        plan: the run's plan.

    Returns:
        True when ``report`` builds it (``all`` builds tab_kselect, ``studies`` tab_parts_k).
    """
    return _output(name).in_report(plan)


def claims_needs(plan: Plan, every: bool = False) -> list[tuple]:
    """What the claims ledger reads: the catalogue's tables that the run builds, and every
    prior's recovery of every seed in the joint K=32 configuration (else the base one).

    Args:
        plan: the run's plan.
        every: every table of the catalogue, built or not (``tools/ledger.py``).

    Returns:
        Need tuples.
    """
    c = CLAIMS_CONFIG if CLAIMS_CONFIG in plan.configs else BASE_CONFIG
    required = catalogue.required_tables()
    tabs = [n for n in catalogue.tables() if every or n in required or _output(n).in_report(plan)]
    prior = models_of("prior") if catalogue.reads_recovery() else ()
    rec = [("recovery", t, m, c, int(s)) for m, t, s in product(prior, plan.trees, plan.seeds)]
    return [("table", n) for n in tabs] + rec


def read_table(name: str, path) -> pd.DataFrame:
    """A report table's CSV; ValueError for a CSV that breaks its declared ``Output.columns``.

    Args:
        name: the table's name.
        path (str | Path): its CSV.

    Returns:
        The table.
    """
    o = _output(name, "table")
    df = read_stamped(path)
    o.columns.check(name, list(df.columns))
    return df


def claims_frame(
    inputs: Mapping[tuple, str], trees: Sequence[str], roles: Mapping | None = None
) -> pd.DataFrame:
    """The claims ledger ([`physgs.report.claims`][physgs.report.claims]) from the files in
    ``inputs``; a table left out leaves its claims "undecided: not measured" (a partial run).

    Args:
        inputs: need tuple -> path ([`claims_needs`][physgs.report.build.claims_needs]).
        trees: the trees.
        roles: tree -> its preset's role (``claim_cells.roles_of``); None: no tree has one.

    Returns:
        The ledger, one row per claim.
    """
    tabs = {
        n: read_table(n, inputs[("table", n)]) for n in catalogue.tables() if ("table", n) in inputs
    }
    damping: dict[str, dict[str, list]] = {}  # model -> tree -> one summary per seed
    for need in sorted(n for n in inputs if n[0] == "recovery"):
        _, tree, model, _, _ = need
        d = load_recovery(inputs[need]).damping
        damping.setdefault(model, {}).setdefault(tree, []).append(
            {k: getattr(d, k) for k in ("median_zeta", "zeta_true", "loglog_exponent")}
        )
    ours = damping.pop("ours", {})  # the paper's claims; the other priors' are asked again
    return claims.ledger(claims.measure(tabs, ours, trees, damping, roles))


def make_claims(
    inputs: Mapping[tuple, str], trees: Sequence[str], md_path, csv_path, stamp=None, roles=None
) -> pd.DataFrame:
    """Write results/claims.md and .csv ([`claims_frame`][physgs.report.build.claims_frame]).

    Args:
        inputs: need tuple -> path.
        trees: the trees.
        md_path (str | Path): the Markdown ledger to write.
        csv_path (str | Path): the CSV ledger to write.
        stamp (Stamp | None): written into every CSV row and the Markdown.
        roles (Mapping | None): tree -> its preset's role (``claim_cells.roles_of``); None: none.

    Returns:
        The ledger (without the stamp's columns).
    """
    df = claims_frame(inputs, trees, roles)
    sd = stamp.to_dict() if stamp is not None else None
    with atomic_path(csv_path) as tmp:
        (df.assign(**sd) if sd else df).to_csv(tmp, index=False, float_format="%.6g")
    stored = read_stamped(csv_path)  # the page prints the CSV's digits
    write_text(md_path, claims.ledger_markdown(stored, sd))
    return df


def _seeds_of(output, seeds: Sequence[int], study: Sequence[int]) -> list[int]:
    """The training seeds ``output`` reads (``Output.seeds``)."""
    picked = {"all": seeds, "first": seeds[:1], "studies": study, "none": []}[output.seeds]
    return [int(s) for s in picked]


def needs(name: str, plan: Plan) -> list[tuple]:
    """Every result output ``name`` reads in run ``plan`` (ValueError: no seeds to read).

    Args:
        name: an output's name.
        plan: the run's plan.

    Returns:
        The need tuples, for the seeds of ``Output.seeds``.
    """
    o = _output(name)
    if o.seeds in ("all", "first") and not plan.seeds:
        raise ValueError("needs: no training seeds given")
    return o.needs(plan, _seeds_of(o, plan.seeds, plan.study_seeds))


def settings_for(name: str, cfg: dict) -> dict:
    """The settings output ``name`` reads from the resolved config, and nothing more.

    Args:
        name: an output's name.
        cfg: the resolved config.

    Returns:
        The rule's params: its trees, their bones, its seeds, a table's digits, its own settings.
    """
    o = _output(name)
    trees = list(cfg[o.trees]["trees"] if o.trees == "damping_benchmark" else cfg["trees"])
    out = {"trees": trees, "bones": {t: int(cfg["presets"][t]["bones"]) for t in trees}}
    if o.seeds != "none":
        study = study_seeds(cfg) if o.seeds == "studies" else ()
        out["seeds"] = _seeds_of(o, cfg["seeds"], study)
    if o.kind == "table":
        out["digits"] = int(cfg["report"][name]["digits"])
    return {**out, **o.settings(cfg)}


def make_table(
    name: str, inputs: Mapping[str, str], settings: dict, tex_path, csv_path, stamp=None
) -> tables.Table:
    """Build table ``name`` from the files in ``inputs`` and write its .tex and .csv.

    Args:
        name: a table's name.
        inputs: need key -> path.
        settings: [`settings_for`][physgs.report.build.settings_for] of the table.
        tex_path (str | Path): the .tex to write.
        csv_path (str | Path): the .csv to write.
        stamp (Stamp | None): a [`Stamp`][physgs.provenance.Stamp] written into every CSV row.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    o = _output(name, "table")
    settings = {**settings, "seeds": [int(x) for x in settings.get("seeds", ())]}
    settings.setdefault("digits", 2)
    table = o.build(reader(inputs), settings, inputs, None)
    o.columns.check(name, list(table.df.columns))  # the CSV keeps its declared contract
    tables.write_table(table, tex_path, csv_path, stamp=stamp)
    return table


def make_figure(
    name: str, inputs: Mapping[str, str], settings: dict, outputs: Sequence[str]
) -> None:
    """Build figure ``name`` from the files in ``inputs``, written to every path in ``outputs``.

    Args:
        name: a figure's name.
        inputs: need key -> path.
        settings: [`settings_for`][physgs.report.build.settings_for] of the figure.
        outputs: the paths to write.
    """
    settings = {**settings, "seeds": [int(x) for x in settings.get("seeds", ())]}
    _output(name, "figure").build(reader(inputs), settings, inputs, outputs)
