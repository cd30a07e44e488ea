"""Seed every global random source from a job's seed, before its model is built.

A model's initial weights come partly from global state: ``torch.nn.Linear`` draws its weights from
torch's default generator, whose starting seed differs per process. Calling
[`seed_everything`][physgs.train.seeding.seed_everything] with the job's seed before building the
model makes the same job give bitwise-equal weights (and checkpoints) in any process.

This pins only what reads global state. Library code should still take explicit seeds or
generators (``np.random.default_rng(seed)``, scikit-learn's ``random_state``): k-means and the
training loop's frame draws do, so they do not depend on what ran before them in the process.
"""

from __future__ import annotations

import random

import numpy as np
import torch


def seed_everything(seed: int) -> None:
    """Seed torch's default generator (CPU and every CUDA device), numpy's legacy global
    generator (``np.random.seed``) and Python's ``random`` from ``seed``.

    numpy's legacy seed must fit in 32 bits, so it gets ``seed mod 2**32``; torch and ``random``
    get ``seed``.

    Args:
        seed: a non-negative integer (the job's seed).

    Raises:
        ValueError: for anything else (a bool or negative number included).
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed_everything: seed must be a non-negative integer, got {seed!r}")
    seed = int(seed)
    random.seed(seed)
    np.random.seed(seed % 2**32)
    torch.manual_seed(seed)  # also seeds every CUDA device's generator
