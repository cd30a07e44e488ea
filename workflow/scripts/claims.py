"""Snakemake script of rule `claims`: the claims ledger (results/claims.md and .csv)."""

from physgs.jobs import job
from physgs.report.build import make_claims

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    df = make_claims(
        dict(sm.input.items()),
        sm.params.trees,
        sm.output.md,
        sm.output.csv,
        stamp=sm.params.stamp,
        roles=sm.params.roles,
    )
    print(df.to_string(), file=log)
