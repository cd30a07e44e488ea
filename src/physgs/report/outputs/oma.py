"""The output-only analysis' figure (docs/blind.md): fig_stabilisation, each tree's
stabilisation diagram of the first seed's identification in the analysis' first configuration,
the bones' true frequencies beside it (drawn, never used to select a mode)."""

from __future__ import annotations

from physgs.report.outputs.base import Output
from physgs.report.tables import OMA


def _analysed(plan) -> bool:
    return bool(plan.recovery.get(OMA))


def _fig_stabilisation_needs(plan, seeds):
    """Per tree, the first seed's identification in the first configuration and the truth of
    that seed's instance."""
    s0, config = int(seeds[0]), next(iter(plan.recovery[OMA]))
    return [need for t in plan.trees for need in (("oma_modes", t, config, s0), ("truth", t, s0))]


def _fig_stabilisation(path, settings, inputs, out):
    from physgs.oma.run import load_identification
    from physgs.report.stabilisation import fig_stabilisation
    from physgs.testbed.dataset import load_truth

    trees, s0, config = settings["trees"], settings["seeds"][0], settings["configs"][0]
    idents = {t: load_identification(path("oma_modes", t, config, s0)) for t in trees}
    omega = {t: load_truth(path("truth", t, s0)).omega for t in trees}
    title = f"Output-only modal analysis of the training window ({config}, seed {s0})"
    fig_stabilisation(idents, omega, trees, out, title=title)


FIG_STABILISATION = Output(
    "fig_stabilisation",
    "figure",
    _fig_stabilisation_needs,
    _fig_stabilisation,
    settings=lambda cfg: {"configs": list(cfg["oma"]["configs"])},
    seeds="first",
    in_report=_analysed,
)
