"""Snakemake script of rule `recovery`: match ours' parts to bones and summarise damping."""

from physgs.jobs import job
from physgs.models.checkpoint import load_checkpoint
from physgs.recovery.record import save_recovery
from physgs.recovery.run import recover_model
from physgs.testbed.dataset import load_observed, load_truth
from physgs.testbed.stats import load_stats

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    rec = recover_model(
        load_checkpoint(sm.input.ckpt),
        load_observed(sm.input.observed),
        load_truth(sm.input.truth),
        load_stats(sm.input.stats)["visible"],
        damping=sm.params.damping,
    )
    save_recovery(sm.output.record, rec)
    print(
        f"trusted {rec.match.n_trusted}/{rec.match.n_parts}, median rel err "
        f"{rec.match.median_rel_err:.4f}, log-log R2 {rec.match.loglog_r2:.3f}, "
        f"median zeta {rec.damping.median_zeta:.3f}; on visible bones {rec.n_trusted_visible} "
        f"trusted, median rel err {rec.median_rel_err_visible:.4f}",
        file=log,
    )
