"""Snakemake script of rule `null_control`: untrained draws through ours' solver and matcher."""

from physgs.jobs import job
from physgs.recovery.record import save_null
from physgs.recovery.run import null_control
from physgs.testbed.dataset import load_observed, load_truth
from physgs.testbed.stats import load_stats

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    res = null_control(
        load_observed(sm.input.observed),
        load_truth(sm.input.truth),
        sm.params.null,
        load_stats(sm.input.stats)["visible"],
    )
    save_null(sm.output.record, res)
    print(
        f"null K={res.n_parts}: median trusted {res.median_n_trusted}, median rel err "
        f"{res.median_median_rel_err:.4f}, nearest-bone gap {res.nearest_bone_gap:.4f}",
        file=log,
    )
