"""Snakemake script of rule `evaluate`: score one checkpoint on every split."""

from physgs.evaluate.run import evaluate_checkpoint
from physgs.jobs import job
from physgs.models.registry import load_checkpoint
from physgs.testbed.dataset import load_observed, load_truth
from physgs.device import resolve_device

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    summary = evaluate_checkpoint(
        load_checkpoint(sm.input.ckpt),
        load_observed(sm.input.observed),
        load_truth(sm.input.truth),
        eval_path=sm.output.scores,
        traj_path=sm.output.traj,
        panels_path=sm.output.panels,
        backend=sm.params.backend,
        device=resolve_device(sm.params.device, sm.resources),
        progress=lambda msg: print(msg, file=log, flush=True),
    )
    print({k: round(v, 3) for k, v in summary.items()}, file=log)
