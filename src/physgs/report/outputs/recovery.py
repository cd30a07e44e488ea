"""The outputs that score recovered physics against the ground truth: tab_null (the paper's:
ours' frequencies against the untrained null), tab_recovery (every recovery method's, each
against the null of its K), tab_damping (the damping benchmark), fig_damping and tab_kselect
(ours with K chosen from the data). The recovery tables' rows come from the one list of
recovery methods (``registry.RECOVERY_METHODS``): one need kind (``recovery``) serves them all."""

from __future__ import annotations

import pandas as pd

from physgs.evaluate.splits import load_eval
from physgs.experiments.kselect import BASE_MODEL, load_selection, selected_models
from physgs.models.registry import RECOVERY_METHODS, config_label, models_of, recovery_plan
from physgs.recovery.record import load_null, load_recovery
from physgs.report import kselect, tables
from physgs.report.damping import COLUMNS as DAMPING_VALUES
from physgs.report.damping import tab_damping
from physgs.report.outputs.base import Columns, Output
from physgs.testbed.variant import DAMPING, FAITHFUL, damping_id

#: tab_kselect's rows: ours at the fixed K of the base configuration, and at the chosen K
KSELECT_ROWS = tuple(c for c, _ in kselect.ROWS)


def label_with_k(cfg: dict, config: str, K: int) -> str:
    """The LaTeX label of configuration ``config`` for a method with K parts there (a method
    with a K of its own: the 2D-track control, the output-only analysis).

    Args:
        cfg: the resolved config.
        config: a configuration name.
        K: the method's number of parts in that configuration.

    Returns:
        The label ([`config_label`][physgs.models.registry.config_label]).
    """
    return config_label(config, {**cfg["models"]["configs"][config], "K": K})


def _methods_settings(cfg: dict, methods, configs) -> dict:
    """methods {id: {config: {K, label}}}: each recovery method of ``methods`` the run scores
    (``registry.recovery_plan``), in the table's configurations ``configs``, each with its K."""
    plan = recovery_plan(cfg)
    return {
        "methods": {
            m: {
                c: {"K": k, "label": label_with_k(cfg, c, k)}
                for c, k in plan[m].items()
                if c in configs
            }
            for m in methods
            if m in plan
        }
    }


def _methods_needs(plan, methods, configs, testbeds, s) -> list[tuple]:
    """The records of the recovery ``methods`` on ``testbeds`` in the table's ``configs``
    (seed ``s``)."""
    return [
        ("recovery", tb, m, c, s)
        for tb in testbeds
        for m in methods
        for c in plan.recovery.get(m, {})
        if c in configs
    ]


def _method_rows(settings: dict, records, damping: bool = False) -> dict:
    """The table's ``MethodRows`` in row order (``RECOVERY_METHODS``', ours first: the settings
    arrive with their keys sorted). records(method, configs): the table's per-seed records of a
    method in ``configs`` ({config: K})."""
    methods = settings["methods"]
    return {
        m: tables.method_rows(
            m,
            {c: v["label"] for c, v in methods[m].items()},
            records(m, {c: v["K"] for c, v in methods[m].items()}),
            damping=damping,
        )
        for m in RECOVERY_METHODS
        if m in methods
    }


def _paper(plan_or_methods) -> list[str]:
    """The paper's recovery methods (``RecoveryMethod.paper``: tab_null's rows) among these."""
    return [m for m in plan_or_methods if RECOVERY_METHODS[m].paper]


# ---- tab_null and tab_recovery: frequencies against the null of each method's K -------------
#: tab_null's and tab_recovery's CSV: one row per seed, tree, configuration and method id
NULL_COLUMNS = Columns(
    keys=("seed", "tree", "config", "method"),
    values=(
        "trained_parts_trusted",
        "trained_median_rel_err_pct",
        "trained_loglog_r2",
        "null_parts_trusted",
        "null_median_rel_err_pct",
        "null_loglog_r2",
        "trained_minus_null_pp",
        "nearest_bone_gap_pct",
        "trained_parts_trusted_visible",
        "trained_median_rel_err_visible_pct",
        "null_parts_trusted_visible",
        "null_median_rel_err_visible_pct",
        *tables.INTERVAL_COLUMNS,  # a method's own intervals (the output-only analysis')
    ),
    about=("bones", "K"),
)


def _frequency_output(name: str, methods, build, in_report=lambda plan: True) -> Output:
    """A frequency-recovery table of the recovery methods ``methods(ids)`` (tab_null: the
    paper's; tab_recovery: every one), each row beside the untrained null of its K."""

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
        trees, seeds = settings["trees"], settings["seeds"]

        def paired(m, configs):
            """{seed: {(tree, config): (its record, the null of its K)}}; configs: {config: K}."""
            return {
                s: {
                    (t, c): (
                        load_recovery(path("recovery", t, m, c, s)),
                        load_null(path("null", t, int(k), s)),
                    )
                    for t in trees
                    for c, k in configs.items()
                }
                for s in seeds
            }

        rows = _method_rows(settings, paired)
        return build(rows, trees, settings["bones"], digits=settings["digits"])

    return Output(
        name, "table", needs, table, settings=settings, in_report=in_report, columns=NULL_COLUMNS
    )


TAB_NULL = _frequency_output("tab_null", _paper, tables.tab_null)
TAB_RECOVERY = _frequency_output(
    "tab_recovery",
    list,
    tables.tab_recovery,
    in_report=lambda plan: len(plan.recovery) > len(_paper(plan.recovery)),
)


# ---- tab_damping ---------------------------------------------------------------------------
def _testbeds(tree: str) -> dict:
    """{variant: testbed id} of a damping-benchmark tree: its faithful and damping testbeds."""
    return {FAITHFUL: tree, DAMPING: damping_id(tree)}


def _damping_needs(plan, seeds):
    testbeds = [tb for t in plan.damping_trees for tb in _testbeds(t).values()]
    return [
        x
        for s in seeds
        for x in _methods_needs(plan, plan.recovery, plan.damping_configs, testbeds, int(s))
    ]


def _damping_settings(cfg: dict) -> dict:
    configs = cfg["damping_benchmark"]["configs"]
    return _methods_settings(cfg, RECOVERY_METHODS, configs)


def _tab_damping(path, settings, inputs, out):
    trees, seeds = settings["trees"], settings["seeds"]

    def records(m, configs):
        """{seed: {(tree, variant, config): record}} of a method on each tree's testbeds."""
        return {
            s: {
                (t, v, c): load_recovery(path("recovery", tb, m, c, s))
                for t in trees
                for v, tb in _testbeds(t).items()
                for c in configs
            }
            for s in seeds
        }

    methods = _method_rows(settings, records, damping=True)
    return tab_damping(methods, trees, settings["bones"], digits=settings["digits"])


DAMPING_COLUMNS = Columns(
    keys=("seed", "tree", "testbed", "config", "method"),
    values=(*DAMPING_VALUES, *tables.INTERVAL_COLUMNS),
    about=("bones",),
)

TAB_DAMPING = Output(
    "tab_damping",
    "table",
    _damping_needs,
    _tab_damping,
    settings=_damping_settings,
    trees="damping_benchmark",
    in_report=lambda plan: bool(plan.damping_trees),
    columns=DAMPING_COLUMNS,
)


def _configs(cfg: dict) -> dict:
    """configs {name: {K, conditions}}: the run's configurations (``models.configs``)."""
    mc = cfg["models"]["configs"]
    return {
        "configs": {c: {"K": int(v["K"]), "conditions": v["conditions"]} for c, v in mc.items()}
    }


# ---- fig_damping ---------------------------------------------------------------------------
def _fig_damping(path, settings, inputs, out):
    from physgs.report import figures

    trees, configs, s0 = settings["trees"], list(settings["configs"]), settings["seeds"][0]
    damping = {
        m: {
            (t, c): load_recovery(path("recovery", t, m, c, s0)).damping
            for t in trees
            for c in configs
        }
        for m in models_of("prior")
    }
    bound = settings.get("zeta_bound")  # settings made before the bound was drawn lack it
    figures.fig_damping(
        damping, trees, configs, float(settings["zeta"]), out, None if bound is None else bound
    )


FIG_DAMPING = Output(
    "fig_damping",
    "figure",
    lambda plan, seeds: [
        ("recovery", t, m, c, s)
        for s in seeds
        for t in plan.trees
        for m in models_of("prior")
        for c in plan.configs
    ],
    _fig_damping,
    settings=lambda cfg: {
        **_configs(cfg),
        "zeta": float(cfg["testbed"]["zeta"]),
        "zeta_bound": float(max(cfg["models"]["ours"]["zeta"])),
    },
    seeds="first",
)


# ---- tab_kselect ---------------------------------------------------------------------------
def _kselect_models(plan) -> list[str]:
    """The priors whose K is chosen: ours, then the plan's others (``models.kselect.priors``)."""
    return [BASE_MODEL, *plan.kselect_priors]


def _selection_need(t: str, m: str, s: int) -> tuple:
    """The need of prior ``m``'s K selection on tree ``t`` (ours' has its own kind)."""
    return ("kselect", t, s) if m == BASE_MODEL else ("prior_kselect", t, m, s)


def _kselect_needs(plan, seeds):
    """Per seed, tree and prior: its K selection, and the evaluation, recovery and loss log
    (training seconds) of its fixed-K and chosen-K models."""
    out = []
    for s in seeds:
        for t in plan.trees:
            for m in _kselect_models(plan):
                out.append(_selection_need(t, m, s))
                for c in KSELECT_ROWS:
                    rec = ("recovery", t, m, c, s)
                    out += [("eval", t, m, c, s), rec, ("loss", t, m, c, s)]
    return out


def _tab_kselect(path, settings, inputs, out):
    rows = {}
    for s in settings["seeds"]:
        rows[s] = {}
        for t in settings["trees"]:
            for m in settings["models"]:
                sel = load_selection(path(*_selection_need(t, m, s)))
                for c in KSELECT_ROWS:
                    ev = load_eval(path("eval", t, m, c, s)).summary()
                    rec = load_recovery(path("recovery", t, m, c, s))
                    loss = pd.read_csv(path("loss", t, m, c, s))
                    rows[s][(t, m, c)] = {
                        "K": rec.match.n_parts,
                        "view_psnr": ev["view"],
                        "time_psnr": ev["time"],
                        "median_rel_err": rec.match.median_rel_err,
                        "trusted": rec.match.n_trusted,
                        "frozen": rec.n_frozen,
                        "k_heldout": sel.k_heldout,
                        "k_bic": sel.k_bic,
                        "train_s": float(loss["seconds"].iloc[-1]),
                        "select_s": float(sum(sel.wall_s)),
                    }
    return kselect.tab_kselect(
        rows,
        settings["trees"],
        settings["bones"],
        settings["method"],
        models=settings["models"],
        digits=settings["digits"],
    )


KSELECT_COLUMNS = Columns(
    keys=("seed", "tree", "model", "config"),
    values=(
        "view_psnr_db",
        "time_psnr_db",
        "median_rel_err_pct",
        "parts_trusted",
        "parts_frozen",
        "k_heldout",
        "k_bic",
    ),
    timing=("train_s", "select_s", "cost_x"),
    about=("bones", "K"),
)

TAB_KSELECT = Output(
    "tab_kselect",
    "table",
    _kselect_needs,
    _tab_kselect,
    settings=lambda cfg: {
        "method": cfg["models"]["kselect"]["method"],
        "models": list(selected_models(cfg["models"]["kselect"])),
    },
    in_report=lambda plan: False,  # `all` builds it (Snakefile): K selection costs trainings
    columns=KSELECT_COLUMNS,
)
