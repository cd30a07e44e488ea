"""Parameter recovery against ground truth and null controls (the protocol, section 4).

Modules: ``matcher`` (part-to-bone matching by trajectory correlation), ``null`` (untrained
null control, nearest-bone gap), ``damping`` (zeta_hat, gamma_hat), ``damping_scores`` (zeta_hat
part by part against a per-bone truth, and its untrained null: the damping testbed variant),
``record`` (scoring one model, JSON storage).
"""

from physgs.recovery.damping import DampingResult, damping_summary
from physgs.recovery.matcher import (
    MatchResult,
    loglog_r2,
    match_parts,
    pearson_matrix,
    training_window,
)

__all__ = [
    "MatchResult",
    "match_parts",
    "pearson_matrix",
    "loglog_r2",
    "training_window",
    "DampingResult",
    "damping_summary",
]
