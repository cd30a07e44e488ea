"""Collect per-job result files into the tables and figures (what the report rules call).

The library never knows where the workflow keeps its files. Each output (``physgs.report.outputs``)
declares what it needs as *need tuples* (``needs``): ``("eval" | "traj" | "panels" | "loss", tree,
model, config, seed)``, ``("recovery", tree, method, config, seed)``, ``("null", tree, K, seed)``,
``("kselect", tree, seed)``, ``("stats", tree)``, ``("table", name)`` and the rest of
``NEED_FIELDS``; seed is a training seed. The workflow maps each tuple to a path
(``workflow/rules/common.smk``) and hands the builders a mapping ``key(need) -> path`` (the
claims ledger: ``need -> path``, the tuples as they are); the builders read only those paths. ``settings_for`` gives the narrow settings an output reads, so
editing one table's format rebuilds that table only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Mapping, Sequence

import pandas as pd

from physgs.atomic import atomic_path, write_text
from physgs.config import study_seeds
from physgs.models.registry import BASE_CONFIG, models_of
from physgs.recovery.record import load_recovery
from physgs.report import catalogue, claims, tables
from physgs.report.claim_cells import CONFIG as CLAIMS_CONFIG
from physgs.report.outputs import NEED_FIELDS, OUTPUTS, Plan, key, reader
from physgs.report.images import fit_row

if TYPE_CHECKING:
    from physgs.report.tables import Table

__all__ = ["NEED_FIELDS", "Plan", "fit_row", "key"]

TABLES = tuple(n for n, o in OUTPUTS.items() if o.kind == "table")
FIGURES = tuple(n for n, o in OUTPUTS.items() if o.kind == "figure")


def _output(name: str):
    if name not in OUTPUTS:
        raise ValueError(f"unknown output '{name}'; choose one of {TABLES + FIGURES}")
    return OUTPUTS[name]


def in_report(name: str, plan: Plan) -> bool:
    """Whether the ``report`` target builds output ``name`` in this plan (the rest: ``all``
    builds tab_kselect, ``studies`` tab_parts_k; a study or control not run builds nothing).

    Args:
        name: an output's name.
        plan: the run's plan.

    Returns:
        True when ``report`` builds it.

    Raises:
        ValueError: for an unknown output.
    """
    return _output(name).in_report(plan)


def claims_needs(plan: Plan, every: bool = False) -> list[tuple]:
    """What the claims ledger reads: the tables of the catalogue
    ([`physgs.report.catalogue.tables`][]) that the run builds, and every prior's recovery
    (damping) of every seed in the joint K=32 configuration (the paper's), or the base
    configuration when the config has none.

    Args:
        plan: the run's plan (trees, configurations, seeds; whether it builds the optional
            tables: ``in_report``).
        every: every table of the catalogue, built or not (``tools/ledger.py`` reads what
            exists).

    Returns:
        Need tuples (module docstring).
    """
    c = CLAIMS_CONFIG if CLAIMS_CONFIG in plan.configs else BASE_CONFIG
    required = catalogue.required_tables()
    tabs = [n for n in catalogue.tables() if every or n in required or _output(n).in_report(plan)]
    recovery = [
        ("recovery", t, m, c, int(s))
        for m in models_of("prior")
        for t in plan.trees
        for s in plan.seeds
    ]
    return [("table", n) for n in tabs] + (recovery if catalogue.reads_recovery() else [])


def read_table(name: str, path) -> pd.DataFrame:
    """A report table's CSV, read through its declared columns (``Output.columns``): refused
    when it breaks the declaration (a CSV of another version, a column renamed).

    Args:
        name: the table's name.
        path (str | Path): its CSV.

    Returns:
        The table.

    Raises:
        ValueError: for a name that is not a table, or a CSV that breaks its columns.
    """
    o = _output(name)
    if o.kind != "table":
        raise ValueError(f"unknown table '{name}'; choose one of {TABLES}")
    df = pd.read_csv(path, dtype={"config_hash": str})  # a hash of digits stays text
    o.columns.check(name, list(df.columns))
    return df


def claims_frame(
    inputs: Mapping[tuple, str],
    trees: Sequence[str],
    roles: Mapping[str, Mapping[str, str]] | None = None,
) -> pd.DataFrame:
    """The claims ledger ([`physgs.report.claims`][physgs.report.claims]) from the files in
    ``inputs``.

    The rule gives every table; a table left out of ``inputs`` leaves its claims "undecided: not
    measured" (a partial run's ledger, ``tools/ledger.py``).

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
        _, tree, model, _, _ = need  # ("recovery", tree, model, config, seed)
        d = load_recovery(inputs[need]).damping
        damping.setdefault(model, {}).setdefault(tree, []).append(
            {
                "median_zeta": d.median_zeta,
                "zeta_true": d.zeta_true,
                "loglog_exponent": d.loglog_exponent,
            }
        )
    ours = damping.pop("ours", {})  # the paper's claims; the other priors' are asked again
    return claims.ledger(claims.measure(tabs, ours, trees, damping, roles))


def make_claims(
    inputs: Mapping[tuple, str],
    trees: Sequence[str],
    md_path,
    csv_path,
    stamp=None,
    roles: Mapping[str, Mapping[str, str]] | None = None,
):
    """Build the claims ledger from the files in ``inputs``
    ([`claims_frame`][physgs.report.build.claims_frame]) and write results/claims.md and .csv.

    Args:
        inputs: need tuple -> path.
        trees: the trees.
        md_path (str | Path): the Markdown ledger to write.
        csv_path (str | Path): the CSV ledger to write.
        stamp (Stamp | None): written into every CSV row and the Markdown.
        roles: tree -> its preset's role (``claim_cells.roles_of``); None: no tree has one.

    Returns:
        (pd.DataFrame): The ledger (without the stamp's columns).
    """
    df = claims_frame(inputs, trees, roles)
    sd = stamp.to_dict() if stamp is not None else None
    write_text(md_path, claims.ledger_markdown(df, sd))
    with atomic_path(csv_path) as tmp:
        (df.assign(**sd) if sd else df).to_csv(tmp, index=False, float_format="%.6g")
    return df


def _seeds_of(output, seeds: Sequence[int], study_seeds: Sequence[int]) -> list[int]:
    """The training seeds ``output`` reads (``Output.seeds``) of the run's ``seeds``."""
    return {
        "all": [int(s) for s in seeds],
        "first": [int(s) for s in seeds[:1]],
        "studies": [int(s) for s in study_seeds],
        "none": [],
    }[output.seeds]


def needs(name: str, plan: Plan) -> list[tuple]:
    """Every result output ``name`` reads in run ``plan``, as need tuples (module docstring).

    The outputs that show one training seed (a figure of images, trajectories or a scatter)
    read the first seed only; tab_parts_k reads the studies' seeds; tab_testbed none.

    Args:
        name: an output's name.
        plan: the run's plan.

    Returns:
        The need tuples.

    Raises:
        ValueError: for an unknown output, or a plan without seeds for an output that reads them.
    """
    o = _output(name)
    if o.seeds in ("all", "first") and not plan.seeds:
        raise ValueError("needs: no training seeds given")
    return o.needs(plan, _seeds_of(o, plan.seeds, plan.study_seeds))


def settings_for(name: str, cfg: dict) -> dict:
    """The settings output ``name`` reads from the resolved config (and nothing more).

    Its trees with their bones, its training seeds, a table's digits, and its own
    (``Output.settings``).

    Args:
        name: an output's name.
        cfg: the resolved config.

    Returns:
        The settings (the rule's params).

    Raises:
        ValueError: for an unknown output.
    """
    o = _output(name)
    trees = list(
        cfg["damping_benchmark"]["trees"] if o.trees == "damping_benchmark" else cfg["trees"]
    )
    out = {"trees": trees, "bones": {t: int(cfg["presets"][t]["bones"]) for t in trees}}
    if o.seeds != "none":
        study = study_seeds(cfg) if o.seeds == "studies" else ()
        out["seeds"] = _seeds_of(o, cfg["seeds"], study)
    if o.kind == "table":
        out["digits"] = int(cfg["report"][name]["digits"])
    return {**out, **o.settings(cfg)}


def make_table(
    name: str, inputs: Mapping[str, str], settings: dict, tex_path, csv_path, stamp=None
) -> Table:
    """Build table ``name`` from the files in ``inputs`` and write its .tex and .csv.

    Args:
        name: a table's name.
        inputs: need key -> path.
        settings: [`settings_for`][physgs.report.build.settings_for] of the table.
        tex_path (str | Path): the .tex to write.
        csv_path (str | Path): the .csv to write.
        stamp (Stamp | None): a [`Stamp`][physgs.provenance.Stamp] written into every CSV row
            (profile, config hash, package version).

    Returns:
        The [`Table`][physgs.report.tables.Table].

    Raises:
        ValueError: for a name that is not a table.
    """
    o = _output(name)
    if o.kind != "table":
        raise ValueError(f"unknown table '{name}'; choose one of {TABLES}")
    settings = {**settings, "seeds": [int(x) for x in settings.get("seeds", ())]}
    settings["digits"] = settings.get("digits", 2)
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

    Raises:
        ValueError: for a name that is not a figure.
    """
    o = _output(name)
    if o.kind != "figure":
        raise ValueError(f"unknown figure '{name}'; choose one of {FIGURES}")
    settings = {**settings, "seeds": [int(x) for x in settings.get("seeds", ())]}
    o.build(reader(inputs), settings, inputs, outputs)
