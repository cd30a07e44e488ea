"""Snakemake script of rule `train`: fit one model on one tree's observed dataset."""

from physgs.experiments import train_and_save
from physgs.jobs import job
from physgs.testbed.dataset import load_observed

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    res = train_and_save(
        load_observed(sm.input.observed),
        sm.params.job,
        checkpoint_path=sm.output.ckpt,
        loss_path=sm.output.loss,
        resources=sm.resources,
    )
    print(f"done: {res.stats}", file=log)
