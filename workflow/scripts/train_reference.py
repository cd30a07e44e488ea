"""Snakemake script of rule `train_reference`: the true-motion ceiling's appearance, trained by
the same recipe as every model with the motion fixed to the ground truth."""

from physgs.experiments import train_and_save
from physgs.jobs import job
from physgs.testbed.dataset import load_observed, load_truth

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    res = train_and_save(
        load_observed(sm.input.observed),
        sm.params.job,
        truth=load_truth(sm.input.truth),
        checkpoint_path=sm.output.ckpt,
        loss_path=sm.output.loss,
        resources=sm.resources,
    )
    print(f"done: {res.stats}", file=log)
