"""The report's tables and figures, in build order: ``OUTPUTS``, the one list the workflow reads.

Each is an ``Output`` (``physgs.report.output``) declared beside its builder; a model joins the
outputs of its role (``physgs.models.registry.models_of``). Importing this plans, never draws.
"""

from physgs.report.damping import FIG_DAMPING, TAB_DAMPING
from physgs.report.images import (
    FIG_RESULTS,
    FIG_TEASER,
    FIG_TEMPORAL,
    TAB_FIT,
    TAB_MARGIN,
    TAB_PSNR,
    TAB_TRANSFER,
)
from physgs.report.kselect import TAB_KSELECT
from physgs.report.output import NEED_FIELDS, PROVENANCE_COLUMNS, Output, Plan, key, reader
from physgs.report.parts import FIG_PARTS, TAB_PARTS, TAB_PARTS_K
from physgs.report.recovery import TAB_NULL, TAB_RECOVERY
from physgs.report.stabilisation import FIG_STABILISATION
from physgs.report.testbed import TAB_TESTBED
from physgs.report.trade import FIG_FIT_CURVE, FIG_FIT_VS_EXTRAPOLATION, FIG_SPEED_ACCURACY
from physgs.report.tracks import FIG_TRACKS, TAB_TRACKS

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


__all__ = ["NEED_FIELDS", "OUTPUTS", "PROVENANCE_COLUMNS", "Output", "Plan", "key", "reader"]
