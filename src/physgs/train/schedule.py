"""Learning-rate schedule shared by every model."""

from __future__ import annotations

#: Parameter groups whose rate decays exponentially (as 3DGS's position and Deformable-3DGS's
#: deformation rates); the others stay constant.
DECAYING = ("means", "deform", "physics", "pivot")


def lr_factor(
    group: str,
    it: int,
    iterations: int,
    warmup: int,
    final_ratio: float,
    anneal_from: int | None = None,
    end: int | None = None,
) -> float:
    """Multiplier of a group's base rate at iteration ``it`` (0-based).

    Canonical means decay over the whole run; deformation groups (deform, physics, pivot) from
    the end of the static warm-up, so they get the same schedule whatever the warm-up length.
    The decay's progress runs linearly over the budget ``iterations`` until ``anneal_from``, then
    linearly from there to 1 at ``end``: the stopping rule's final anneal
    ([`physgs.train.stopping`][]), so a training stopped at ``end`` ends at ``final_ratio`` as a
    full one does. With ``anneal_from = iterations - A`` and ``end = iterations`` the anneal is
    the budget's own tail: the schedule without a stop, unchanged.

    Args:
        group: the parameter group (``train.lr`` key); groups outside ``DECAYING`` keep 1.
        it: the iteration, 0-based.
        iterations: training iterations (the budget, the cap).
        warmup: static warm-up iterations.
        final_ratio: the factor reached at the last iteration.
        anneal_from: the iteration the final anneal starts at (None: no early anneal).
        end: the iteration the anneal ends at (the training's length; required with
            ``anneal_from``, > ``anneal_from``).

    Returns:
        final_ratio ** progress, progress in [0, 1] over the group's span.

    Raises:
        ValueError: ``anneal_from`` without an ``end`` after it.
    """
    if group not in DECAYING:
        return 1.0
    start = 0 if group == "means" else warmup
    span = max(iterations - start, 1)
    if anneal_from is None or it < anneal_from:
        progress = (it - start) / span
    else:
        if end is None or end <= anneal_from:
            raise ValueError(f"the anneal from {anneal_from} needs an end after it, got {end}")
        p0 = min(max((anneal_from - start) / span, 0.0), 1.0)
        progress = p0 + (1.0 - p0) * (it - anneal_from) / (end - anneal_from)
    progress = min(max(progress, 0.0), 1.0)
    return final_ratio**progress
