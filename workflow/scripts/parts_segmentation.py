"""Snakemake script of rule `parts_segmentation`: each trained prior's parts and their purity
against the ground-truth bones (an evaluation check; reads truth.npz)."""

from physgs.evaluate.parts import gaussian_bone, save_segmentations, segmentation_record
from physgs.jobs import job
from physgs.models.checkpoint import load_checkpoint
from physgs.testbed.dataset import load_truth

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    models = {m: load_checkpoint(sm.input[m]) for m in sm.params.models}
    rec = segmentation_record(models, gaussian_bone(load_truth(sm.input.truth)))
    save_segmentations(sm.output.record, rec)
    for m in models:
        print(f"{m}: purity {float(rec[f'{m}/overall']):.3f} over {models[m].K} parts", file=log)
