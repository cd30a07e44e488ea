"""Snakemake script of rule `fit_tracks`: ours' oscillators fitted to the tracks of each
configuration's conditions, every configuration of one tree and seed (observed.npz and the tracks
only)."""

from physgs.jobs import job
from physgs.testbed.dataset import load_observed
from physgs.tracks.run import fit_job
from physgs.tracks.store import load_fit, load_tracks, save_fit

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    observed = load_observed(sm.input.observed)
    conditions = sorted({c for j in sm.params.jobs for c in j["conditions"]})
    by_condition = {c: load_tracks(sm.input[f"c{c}"])[0] for c in conditions}  # read once
    for path, j in zip(sm.output.fits, sm.params.jobs, strict=True):
        tracks = [by_condition[c] for c in j["conditions"]]
        fit, osc = fit_job(tracks, observed, j)
        save_fit(path, fit, osc, j["K_key"], j["min_tracks"])
        load_fit(path)  # the file reads back before the job counts as done
        print(
            f"{path}: K={j['K']} ({j['K_key']}), conditions {j['conditions']}: tracks per part "
            f"{fit.n_tracks.tolist()}, {int(fit.estimated.sum())} parts estimated; rms "
            f"{fit.rms_px:.3f} px; {fit.seconds:.1f} s ({fit.loop_seconds:.1f} s in the Adam loop)",
            file=log,
        )
