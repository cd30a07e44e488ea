"""Snakemake script of rule `claims`: the claims ledger (results/claims.md and .csv)."""

from physgs.jobs import job
from physgs.report.build import key, make_claims

sm = snakemake  # noqa: F821 (injected by Snakemake)
with job(sm) as log:
    df = make_claims(
        {need: sm.input[key(need)] for need in sm.params.needs},
        sm.params.trees,
        sm.output.md,
        sm.output.csv,
        stamp=sm.params.stamp,
        roles=sm.params.roles,
    )
    print(df.to_string(), file=log)
