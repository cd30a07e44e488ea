"""Learning-rate schedule shared by every model."""

from __future__ import annotations

#: Parameter groups whose rate decays exponentially (as 3DGS's position and Deformable-3DGS's
#: deformation rates); the others stay constant.
DECAYING = ("means", "deform", "physics", "pivot")


def lr_factor(group: str, it: int, iterations: int, warmup: int, final_ratio: float) -> float:
    """Multiplier of a group's base rate at iteration ``it`` (0-based).

    Canonical means decay over the whole run; deformation groups (deform, physics, pivot) from
    the end of the static warm-up, so they get the same schedule whatever the warm-up length.

    Args:
        group: the parameter group (``train.lr`` key); groups outside ``DECAYING`` keep 1.
        it: the iteration, 0-based.
        iterations: training iterations.
        warmup: static warm-up iterations.
        final_ratio: the factor reached at the last iteration.

    Returns:
        final_ratio ** progress, progress in [0, 1] over the group's span.
    """
    if group not in DECAYING:
        return 1.0
    start = 0 if group == "means" else warmup
    span = max(iterations - start, 1)
    progress = min(max((it - start) / span, 0.0), 1.0)
    return final_ratio**progress
