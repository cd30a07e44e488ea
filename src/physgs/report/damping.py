"""tab_damping: each method's damping recovery (``damping_scores``/``damping_null`` of its
recovery records) on the faithful testbed and its damping variant, beside the untrained null;
fig_damping: each prior's recovered damping on the run's own trees (first seed)."""

from __future__ import annotations

from functools import partial
from itertools import product
from typing import Mapping, Sequence

from physgs.models.registry import PAPER_MODEL, RECOVERY_METHODS, models_of
from physgs.recovery.record import load_recovery
from physgs.report import latex
from physgs.report import recovery as R
from physgs.report import seeds as seedstats
from physgs.report.output import Columns, Output
from physgs.report.table_captions import caption
from physgs.report.tables import Table
from physgs.testbed.variant import DAMPING, FAITHFUL, VARIANTS, damping_id

#: tab_damping's CSV values (before ``INTERVAL_COLUMNS``) -> each from a record's damping
#: scores and their null
VALUES = {
    "trusted": lambda sc, nl: sc.n_trusted,
    "rel_err_pct": lambda sc, nl: 100 * sc.median_rel_err,
    "null_rel_err_pct": lambda sc, nl: 100 * nl.median_median_rel_err,
    "trained_minus_null_pp": lambda sc, nl: 100 * (sc.median_rel_err - nl.median_median_rel_err),
    "log_corr": lambda sc, nl: sc.log_corr,
    "null_log_corr": lambda sc, nl: nl.median_log_corr,
    "gamma_exponent": lambda sc, nl: sc.gamma_exponent,
    "null_gamma_exponent": lambda sc, nl: nl.median_gamma_exponent,
    "gamma_exponent_true": lambda sc, nl: sc.gamma_exponent_true,
}


def tab_damping(
    methods: Mapping[str, R.MethodRows], trees: Sequence, bones: Mapping, digits: int = 2
) -> Table:
    """Damping recovery per seed, tree, variant, method and configuration, beside the null.

    Args:
        methods: method id -> its ``MethodRows``, in row order (ours first; one without
            configurations has no rows): ``per_seed[seed][(tree, variant, config)]`` = its
            ``RecoveryRecord`` with damping scores and null; variant 'faithful' or 'damping'.
        trees: the trees.
        bones: tree -> its bone count.
        digits: decimals shown in the .tex.

    Returns:
        The table: one CSV row per seed and row; the .tex mean +- sd over seeds and the paired
            trained - null difference with its 95% interval.

    Raises:
        ValueError: when a record has no damping scores.
        KeyError: when a seed lacks a record.
    """

    def one(s, rec, t, v, c, method):
        sc, nl = rec.damping_scores, rec.damping_null
        if sc is None or nl is None:
            name = "" if method == PAPER_MODEL else f" ({R.WHO.get(method, method)})"
            raise ValueError(
                f"tab_damping: the recovery of {t}/{v}/{c}{name} (seed {s}) has no "
                "damping scores; re-run its recovery rule with damping params"
            )
        about = {"tree": t, "bones": bones[t], "testbed": v, "config": c, "method": method}
        return about | {k: f(sc, nl) for k, f in VALUES.items()} | R.interval_cells(rec)

    def columns(df):
        col, fmt = partial(latex.cells, df), f".{int(digits)}f"
        p, p_true = col("gamma_exponent", ".2f"), col("gamma_exponent_true", ".2f", cell=latex.mean)
        err, corr = r"Med.\ rel.\ err.\ of $\hat\zeta$", r"corr($\log\hat\zeta$, $\log\zeta$)"
        return {
            ("", "Trusted"): col("trusted", ".1f"),  # a mean count: one decimal
            (err, "Trained"): col("rel_err_pct", ".0f", r"\%"),
            (err, "Null"): col("null_rel_err_pct", ".0f", r"\%"),
            (err, r"Trained $-$ null"): col(
                "trained_minus_null_pp", ".0f", cell=seedstats.difference
            ),
            (corr, "Trained"): col("log_corr", fmt),
            (corr, "Null"): col("null_log_corr", fmt),
            (r"$\hat\gamma\propto\hat\omega^p$", "$p$ (truth)"): [
                a if b == "--" else f"{a} ({b})" for a, b in zip(p, p_true)
            ],
        }

    lead = caption("tab_damping")
    return R._method_table("tab_damping", methods, trees, bones, one, columns, lead, VARIANTS)


# ---- the declarations ----------------------------------------------------------------------
def _testbeds(tree: str) -> dict:
    """{(variant,): testbed id} of a damping-benchmark tree."""
    return {(FAITHFUL,): tree, (DAMPING,): damping_id(tree)}


def _damping_needs(plan, seeds):
    testbeds = [tb for t in plan.damping_trees for tb in _testbeds(t).values()]
    need = partial(R._methods_needs, plan, plan.recovery, plan.damping_configs, testbeds)
    return [x for s in seeds for x in need(int(s))]


def _tab_damping(path, settings, inputs, out):
    def read(m, K, tb, c, s):
        return load_recovery(path("recovery", tb, m, c, s))

    methods = R._table_methods(settings, read, _testbeds, damping=True)
    return tab_damping(methods, settings["trees"], settings["bones"], digits=settings["digits"])


TAB_DAMPING = Output(
    "tab_damping",
    "table",
    _damping_needs,
    _tab_damping,
    settings=lambda cfg: R._methods_settings(
        cfg, RECOVERY_METHODS, cfg["damping_benchmark"]["configs"]
    ),
    trees="damping_benchmark",
    in_report=lambda plan: bool(plan.damping_trees),
    columns=Columns(
        keys=("seed", "tree", "testbed", "config", "method"),
        values=(*VALUES, *R.INTERVAL_COLUMNS),
        about=("bones",),
    ),
)


def _fig_damping(path, settings, inputs, out):
    from physgs.report import figures  # matplotlib: not for the workflow's planning imports

    trees, configs, s0 = settings["trees"], settings["configs"], settings["seeds"][0]
    pairs = list(product(trees, configs))
    damping = {
        m: {(t, c): load_recovery(path("recovery", t, m, c, s0)).damping for t, c in pairs}
        for m in models_of("prior")
    }
    zeta, bound = float(settings["zeta"]), float(settings["zeta_bound"])
    figures.fig_damping(damping, trees, configs, zeta, out, bound)


FIG_DAMPING = Output(
    "fig_damping",
    "figure",
    lambda plan, seeds: [
        ("recovery", t, m, c, s)
        for s, t, m, c in product(seeds, plan.trees, models_of("prior"), plan.configs)
    ],
    _fig_damping,
    settings=lambda cfg: {
        # sorted, as the settings' mapping of configurations always reached the figure
        "configs": sorted(cfg["models"]["configs"]),
        "zeta": float(cfg["testbed"]["zeta"]),
        "zeta_bound": float(max(cfg["models"]["ours"]["zeta"])),
    },
    seeds="first",
)
