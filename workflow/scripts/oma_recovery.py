"""Snakemake script of rule `oma_recovery`: the modes mapped to K parts, through ours' matcher
against the truth (evaluation)."""

from physgs.jobs import job
from physgs.oma.run import load_identification, part_modes, recover_oma, save_oma_recovery
from physgs.testbed.dataset import load_observed, load_truth
from physgs.testbed.stats import load_stats

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    p = sm.params.job
    pm = part_modes(load_identification(sm.input.modes), p["K"], p["seed"], p["kmeans_n_init"])
    rec, block = recover_oma(
        pm,
        load_observed(sm.input.observed),
        load_truth(sm.input.truth),
        p["solver"],
        load_stats(sm.input.stats)["visible"],
        damping=sm.params.damping,
    )
    save_oma_recovery(sm.output.record, rec, block)
    m = rec.match
    print(
        f"K={p['K']}: {block['n_modes']} modes, {block['n_no_estimate']} parts without one;"
        f" trusted {m.n_trusted}/{m.n_parts}, median rel err {m.median_rel_err:.4f}",
        file=log,
    )
