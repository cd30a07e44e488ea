"""Snakemake script of rule `oma_identify`: SSI-cov of the dense flow of the configuration's
videos (observed.npz's frames of the training window only; never the wind)."""

from physgs.jobs import job
from physgs.oma.run import OMASettings, identify_video, load_identification, save_identification
from physgs.testbed.dataset import load_observed

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    p = sm.params.settings
    s = OMASettings.from_config(p, {"omega_hz": p["omega_hz"]})
    obs = load_observed(sm.input.observed)
    videos = [obs.frames[c, : obs.n_train] for c in p["conditions"]]
    ident = identify_video(videos, obs.background, obs.fps, s)
    save_identification(sm.output.modes, ident, s)
    load_identification(sm.output.modes)  # the file reads back before the job counts as done
    m = ident.modes
    print(
        f"{ident.channels.n_cells} cells, {m.n_modes} modes (Hz) {m.freq_hz.round(3).tolist()},"
        f" zeta {m.zeta.round(3).tolist()}; {ident.seconds:.1f} s",
        file=log,
    )
