"""The studies' trade figures (the `studies` target, never `report`): fig_speed_accuracy (the
speed-accuracy sweep beside the untrained null's chance level), fig_fit_curve (each model's fit
against its training budget) and fig_fit_vs_extrapolation (along each field's fit curve, its gain
beyond the window against its in-window fit), each drawn from its study's CSV (the rules
``speed_accuracy`` and ``fit_curve`` write ``results/tables/<study>.csv``)."""

from __future__ import annotations

from typing import Sequence

import pandas as pd

from physgs.experiments.fit_curve import fit_vs_extrapolation
from physgs.experiments.sweep import null_level
from physgs.models.registry import BASE_CONFIG, REFERENCE_NAMES, label
from physgs.recovery.record import load_null
from physgs.report.output import Output
from physgs.report.thresholds import FIT_BAR

#: the studies' CSVs (need ``("table", <study>)``), written by the rules of the same name
SPEED_ACCURACY, FIT_CURVE = "speed_accuracy", "fit_curve"


def _studies(name: str, study: str, draw, needs=lambda plan, seeds: [], **kw) -> Output:
    """A figure of the studies' seeds that the `studies` target builds (Snakefile), drawn by
    ``draw(df, out, path, settings)`` from its study's CSV ``df`` (need ``("table", study)``, then
    ``needs``)."""

    def build(path, settings, inputs, out):
        draw(pd.read_csv(path("table", study)), out, path, settings)

    every = lambda plan, seeds: [("table", study), *needs(plan, seeds)]
    return Output(name, "figure", every, build, seeds="studies", in_report=lambda p: False, **kw)


def _nulls(plan, seeds):
    """Per study seed, the untrained null of the sweep tree at the base configuration's K (the
    recovery panel's chance level)."""
    return [("null", plan.sweep_tree, int(plan.configs[BASE_CONFIG]["K"]), int(s)) for s in seeds]


def _speed_accuracy(df, out, path, settings):
    from physgs.report import figures  # matplotlib: not for the workflow's planning imports

    nulls = [load_null(path("null", settings["tree"], settings["K"], s)) for s in settings["seeds"]]
    figures.fig_speed_accuracy(df, out, null=null_level(nulls))


def _fit_curve(df, out, path, settings):
    from physgs.report import figures  # matplotlib: not for the workflow's planning imports

    figures.fig_fit_curve(df, out)


def draw_fit_vs_extrapolation(df: pd.DataFrame, outputs: Sequence[str]) -> None:
    """fig_fit_vs_extrapolation: one panel per tree, one line per model through its budgets.

    Args:
        df: [`fit_vs_extrapolation`][physgs.experiments.fit_curve.fit_vs_extrapolation]'s rows.
        outputs: the paths to write.
    """
    from physgs.report.figures import COLORS, _axes, _finish  # matplotlib: not for planning

    xy = ["of_ceiling", "beyond_gain"]
    trees = list(dict.fromkeys(df["tree"]))
    fig, axes = _axes(1, len(trees), 3.9, width=4.6 * len(trees))
    for ax, tree in zip(axes[0], trees):
        t = df[(df["tree"] == tree) & ~df["model"].isin(REFERENCE_NAMES)]
        for m, g in t.groupby("model", sort=False):
            field = m.partition("@")[0]
            lab, color = label(field) + (" (window time)" if "@" in m else ""), COLORS.get(field)
            ax.plot(g["of_ceiling"], g["beyond_gain"], ".", color=color, alpha=0.3, ms=4)
            mean = g.groupby("iterations")[xy].mean()
            ax.plot(mean["of_ceiling"], mean["beyond_gain"], "-o", color=color, ms=3.5, label=lab)
            prof = g[g["is_profile"]][xy].mean()
            ax.plot(prof["of_ceiling"], prof["beyond_gain"], "*", color=color, ms=10)
        ax.axhline(0.0, color="0.55", ls="--", lw=1.0)
        ax.axvline(FIT_BAR, color="k", ls=":", lw=1.0)
        ax.set(
            title=f"{tree} ({t['seed'].nunique()} seed(s))",
            xlabel="in-window fraction of the ceiling's gain",
            ylabel="gain over static beyond the window (dB)",
        )
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    title = (
        "Does fitting the window more make a field extrapolate worse? (line: the budgets, star: "
        "the profile's; dotted: the fit bar; dashed: static)"
    )
    _finish(fig, outputs, title, title_pt=9)


def _fit_vs_extrapolation(df, out, path, settings):
    draw_fit_vs_extrapolation(fit_vs_extrapolation(df), out)


def _speed_accuracy_settings(cfg: dict) -> dict:
    """The sweep's tree and the base configuration's K (its null's)."""
    K = int(cfg["models"]["configs"][BASE_CONFIG]["K"])
    return {"tree": cfg["speed_accuracy"]["tree"], "K": K}


FIG_SPEED_ACCURACY = _studies(
    "fig_speed_accuracy", SPEED_ACCURACY, _speed_accuracy, _nulls, settings=_speed_accuracy_settings
)
# the fit curve's CSV holds the studies' seeds' points
FIG_FIT_CURVE = _studies("fig_fit_curve", FIT_CURVE, _fit_curve)
FIG_FIT_VS_EXTRAPOLATION = _studies("fig_fit_vs_extrapolation", FIT_CURVE, _fit_vs_extrapolation)
