"""Snakemake script of rule `fit_curve`: the fit curve's CSV (fig_fit_curve: rule figure)."""

from physgs.atomic import atomic_path
from physgs.experiments.fit_curve import ceiling_fraction, collect
from physgs.intermediate import read_json
from physgs.jobs import job
from physgs.report.build import fit_row

sm = snakemake  # noqa: F821 (injected by Snakemake)
p = sm.params
with job(sm) as log:
    points = [read_json(f, rule="fit_curve_point") for f in sm.input.points]
    own = {
        s: {
            m: fit_row(
                sm.input[f"eval_{m}_{s}"], sm.input[f"loss_{m}_{s}"], p.n_train, p.holdout_every
            )
            for m in p.models
        }
        for s in p.seeds
    }
    df = collect(points, own, p.iterations, p.tree)
    df["of_ceiling"] = ceiling_fraction(df)
    with atomic_path(sm.output.csv) as tmp:
        df.to_csv(tmp, index=False, float_format="%.6g")
    print(df.to_string(), file=log)
