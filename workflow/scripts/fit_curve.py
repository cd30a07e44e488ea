"""Snakemake script of rule `fit_curve`: the fit curve's CSV over its trees."""

from physgs.atomic import atomic_path
from physgs.experiments.fit_curve import curve_table
from physgs.intermediate import read_json
from physgs.jobs import job
from physgs.report.build import fit_row

sm = snakemake  # noqa: F821 (injected by Snakemake)
p, inp = sm.params, sm.input
with job(sm) as log:
    points = {
        t: [read_json(f, rule="fit_curve_point") for f in inp[f"points_{t}"]] for t in p.trees
    }
    own = {
        t: {
            s: {
                m: fit_row(
                    inp[f"eval_{t}_{m}_{s}"], inp[f"loss_{t}_{m}_{s}"], p.n_train, p.holdout_every
                )
                for m in p.models
            }
            for s in p.seeds
        }
        for t in p.trees
    }
    df = curve_table(points, own, p.iterations)
    with atomic_path(sm.output.csv) as tmp:
        df.to_csv(tmp, index=False, float_format="%.6g")
    print(df.to_string(), file=log)
