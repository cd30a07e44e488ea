"""The report's tables and figures, each declared once (``Output``): its needs, its settings
and its builder. ``OUTPUTS`` lists them in build order; a model joins every output that reads
the models of its role (``physgs.models.registry.models_of``) through its registry entry
(``physgs.models.registry.MODELS``), and a new output is one ``Output`` added here."""

from physgs.report.outputs.base import NEED_FIELDS, Output, Plan, key, reader
from physgs.report.outputs.oma import FIG_STABILISATION
from physgs.report.outputs.recovery import (
    FIG_DAMPING,
    TAB_DAMPING,
    TAB_KSELECT,
    TAB_NULL,
    TAB_RECOVERY,
)
from physgs.report.outputs.studies import FIG_PARTS, TAB_PARTS, TAB_PARTS_K
from physgs.report.outputs.testbed import TAB_TESTBED
from physgs.report.outputs.trade import (
    FIG_FIT_CURVE,
    FIG_FIT_VS_EXTRAPOLATION,
    FIG_SPEED_ACCURACY,
)
from physgs.report.outputs.tracks import FIG_TRACKS, TAB_TRACKS
from physgs.report.outputs.views import (
    FIG_RESULTS,
    FIG_TEASER,
    FIG_TEMPORAL,
    TAB_FIT,
    TAB_MARGIN,
    TAB_PSNR,
    TAB_TRANSFER,
)

#: name -> Output, tables then figures, in the order the report lists them
OUTPUTS: dict[str, Output] = {
    o.name: o
    for o in (
        TAB_TESTBED,
        TAB_PSNR,
        TAB_NULL,
        TAB_RECOVERY,
        TAB_TRANSFER,
        TAB_MARGIN,
        TAB_KSELECT,
        TAB_FIT,
        TAB_DAMPING,
        TAB_PARTS,
        TAB_PARTS_K,
        TAB_TRACKS,
        FIG_TEMPORAL,
        FIG_TEASER,
        FIG_RESULTS,
        FIG_DAMPING,
        FIG_PARTS,
        FIG_TRACKS,
        FIG_STABILISATION,
        FIG_SPEED_ACCURACY,
        FIG_FIT_CURVE,
        FIG_FIT_VS_EXTRAPOLATION,
    )
}


__all__ = ["NEED_FIELDS", "OUTPUTS", "Output", "Plan", "key", "reader"]
