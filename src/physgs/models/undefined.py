"""Where a model makes no prediction: the exception every model raises and every evaluation reads.

Torch-free: the evaluation's splits (imported while a run is planned) catch it.
"""

from __future__ import annotations


class NotDefined(Exception):
    """A model makes no prediction for this frame or condition (a prior with a learned forcing
    beyond its window or under another wind): the evaluation records NaN, "not defined", never
    a score."""
