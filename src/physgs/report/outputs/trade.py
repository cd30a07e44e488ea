"""The studies of the trade's figures (the `studies` target): fig_speed_accuracy (the
speed-accuracy sweep beside the untrained null's chance level) and fig_fit_curve (each model's
fit against its training budget), each drawn from its study's CSV (rules ``speed_accuracy`` and
``fit_curve`` collect the points into ``results/tables/<study>.csv``)."""

from __future__ import annotations

import pandas as pd

from physgs.experiments.sweep import null_level
from physgs.models.registry import BASE_CONFIG
from physgs.recovery.record import load_null
from physgs.report.outputs.base import Output

#: the studies' CSVs (need ``("table", <study>)``), written by the rules of the same name
SPEED_ACCURACY, FIT_CURVE = "speed_accuracy", "fit_curve"


def _studies_only(plan) -> bool:
    return False  # the `studies` target builds them (Snakefile), never `report`


# ---- fig_speed_accuracy --------------------------------------------------------------------
def _speed_accuracy_needs(plan, seeds):
    """The sweep's CSV and the untrained null of the sweep tree at the base configuration's K,
    per study seed (the chance level the recovery panel draws)."""
    K = int(plan.configs[BASE_CONFIG]["K"])
    return [("table", SPEED_ACCURACY)] + [("null", plan.sweep_tree, K, int(s)) for s in seeds]


def _fig_speed_accuracy(path, settings, inputs, out):
    df = pd.read_csv(path("table", SPEED_ACCURACY))
    K = settings["K"]
    null = null_level([load_null(path("null", settings["tree"], K, s)) for s in settings["seeds"]])
    from physgs.report import figures  # matplotlib: not for the workflow's planning imports

    figures.fig_speed_accuracy(df, out, null=null)


def _fig_fit_curve(path, settings, inputs, out):
    from physgs.report import figures  # matplotlib: not for the workflow's planning imports

    figures.fig_fit_curve(pd.read_csv(path("table", FIT_CURVE)), out)


FIG_SPEED_ACCURACY = Output(
    "fig_speed_accuracy",
    "figure",
    _speed_accuracy_needs,
    _fig_speed_accuracy,
    settings=lambda cfg: {
        "tree": cfg["speed_accuracy"]["tree"],
        "K": int(cfg["models"]["configs"][BASE_CONFIG]["K"]),
    },
    seeds="studies",
    in_report=_studies_only,
)


# ---- fig_fit_curve -------------------------------------------------------------------------
FIG_FIT_CURVE = Output(
    "fig_fit_curve",
    "figure",
    lambda plan, seeds: [("table", FIT_CURVE)],
    _fig_fit_curve,
    seeds="studies",  # its CSV holds the studies' seeds' points
    in_report=_studies_only,
)
