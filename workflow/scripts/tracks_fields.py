"""Snakemake script of rule `tracks_fields`: the learned fields' Gaussians at the 2D-track
control's tracked points, scored as the control (beyond the window, under each other wind). An
evaluation: reads truth.npz."""

from physgs.atomic import write_json
from physgs.jobs import job
from physgs.models.checkpoint import load_checkpoint
from physgs.testbed.dataset import load_observed, load_truth
from physgs.tracks.run import models_at_tracks
from physgs.tracks.store import load_fit, load_tracks

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    fields = {k.removeprefix("field_"): p for k, p in sm.input.items() if k.startswith("field_")}
    scores = models_at_tracks(
        {m: load_checkpoint(p) for m, p in fields.items()},
        load_fit(sm.input.fit)[0],
        load_tracks(sm.input.tracks)[0],
        load_observed(sm.input.observed),
        load_truth(sm.input.truth),
    )
    write_json(sm.output.scores, scores)
    print(scores, file=log)
