"""Snakemake script of rule `tracks_evaluate`: the tracks control of each configuration of one
tree and seed scored against the truth (tracker error, recovery through ours' matcher, motion
beyond the window and under unseen wind beside ours' Gaussians at the same points). An
evaluation: reads truth.npz."""

from physgs.atomic import write_json
from physgs.jobs import job
from physgs.models.checkpoint import load_checkpoint
from physgs.testbed.dataset import load_observed, load_truth
from physgs.testbed.stats import load_stats
from physgs.tracks.recover import save_tracks_recovery
from physgs.tracks.run import evaluate_job
from physgs.tracks.store import load_fit, load_tracks

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    tracks0 = load_tracks(sm.input.tracks)[0]
    observed, truth = load_observed(sm.input.observed), load_truth(sm.input.truth)
    visible = load_stats(sm.input.stats)["visible"]
    outs = zip(
        sm.params.configs, sm.params.damping, sm.output.scores, sm.output.records, strict=True
    )
    for c, damping, scores_path, record_path in outs:
        fit, osc, meta = load_fit(sm.input[f"fit_{c}"])
        kw = dict(bone_visible=visible, damping=damping, min_tracks=meta["min_tracks"])
        ours = load_checkpoint(sm.input[f"ours_{c}"])
        rec, scores = evaluate_job(fit, osc, tracks0, observed, truth, ours=ours, **kw)
        save_tracks_recovery(record_path, rec)
        write_json(scores_path, scores)
        print(c, rec.to_dict(), scores, sep="\n", file=log)
