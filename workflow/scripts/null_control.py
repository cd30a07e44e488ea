"""Snakemake script of rule `null_control`: 8 untrained draws through ours' solver and matcher."""
from physgs.recovery.record import save_null
from physgs.recovery.run import null_for_config
from physgs.testbed.dataset import load_observed, load_truth

sm = snakemake  # noqa: F821 (injected by Snakemake)
with open(sm.log[0], "w") as log:
    res = null_for_config(load_observed(sm.input.observed), load_truth(sm.input.truth),
                          sm.params.cfg, sm.wildcards.config)
    save_null(sm.output.record, res)
    print(f"null: median trusted {res.median_n_trusted}, median rel err "
          f"{res.median_median_rel_err:.4f}, nearest-bone gap {res.nearest_bone_gap:.4f}", file=log)
