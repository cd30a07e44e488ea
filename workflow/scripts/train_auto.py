"""Snakemake script of rule `train_auto`: train ours with the K chosen by rule `kselect`."""

from physgs.experiments import train_and_save
from physgs.experiments.kselect import auto_job, load_selection
from physgs.jobs import job
from physgs.testbed.dataset import load_observed

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    spec = auto_job(sm.params.job, load_selection(sm.input.selection), sm.params.conditions)
    res = train_and_save(
        load_observed(sm.input.observed),
        spec,
        checkpoint_path=sm.output.ckpt,
        loss_path=sm.output.loss,
        resources=sm.resources,
    )
    print(f"done: K {spec['K']}, {res.stats}", file=log)
