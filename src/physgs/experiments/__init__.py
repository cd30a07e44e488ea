"""Experiments: the one recipe that builds, trains and scores a model, and the studies built on
it (K selection, the speed-accuracy sweep, the fit curve, the recipe search). Training, K
selection, the sweep and every trial of the search call ``recipe.fit``, so every study measures the
model the tables report."""

from physgs.experiments.recipe import Job, fit, job_spec, train_and_save

__all__ = ["Job", "fit", "job_spec", "train_and_save"]
