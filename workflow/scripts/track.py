"""Snakemake script of rule `track`: point tracks of one condition's training-camera video over
the training window (observed.npz only)."""

from physgs.jobs import job
from physgs.testbed.dataset import load_observed
from physgs.tracks.store import save_tracks
from physgs.tracks.track import track_condition

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    c = int(sm.wildcards.condition)
    tr = track_condition(load_observed(sm.input.observed), c, sm.params.settings)
    save_tracks(sm.output.tracks, tr, c)
    s0 = tr.start == 0
    kept = float(tr.valid[s0, -1].mean()) if s0.any() else 0.0
    print(
        f"condition {c}: {tr.n_tracks} tracks, {int(s0.sum())} from frame 0 "
        f"({100 * kept:.0f}% kept to the window's end), mean length {tr.length().mean():.1f}",
        file=log,
    )
