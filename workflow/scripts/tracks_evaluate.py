"""Snakemake script of rule `tracks_evaluate`: the tracks control scored against the truth
(tracker error, recovery through ours' matcher, motion beyond the window and under unseen wind
beside ours' Gaussians at the same points). An evaluation: reads truth.npz."""

from physgs.atomic import write_json
from physgs.jobs import job
from physgs.models.registry import load_checkpoint
from physgs.testbed.dataset import load_observed, load_truth
from physgs.testbed.stats import load_stats
from physgs.tracks.recover import save_tracks_recovery
from physgs.tracks.run import evaluate_job
from physgs.tracks.store import load_fit, load_tracks

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    fit, osc, meta = load_fit(sm.input.fit)
    rec, scores = evaluate_job(
        fit,
        osc,
        load_tracks(sm.input.tracks)[0],
        load_observed(sm.input.observed),
        load_truth(sm.input.truth),
        bone_visible=load_stats(sm.input.stats)["visible"],
        damping=sm.params.damping,
        min_tracks=meta["min_tracks"],
        ours=load_checkpoint(sm.input.ours),
    )
    save_tracks_recovery(sm.output.record, rec)
    write_json(sm.output.scores, scores)
    print(rec.to_dict(), scores, sep="\n", file=log)
