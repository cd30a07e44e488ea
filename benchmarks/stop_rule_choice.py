"""Where the stopping rule would stop each model, from its held-out-window curve
(benchmarks/window_curves.py), for a grid of N (every), tol and P (patience), and what it
would cost: the held-out loss at the trigger against the loss at the cap (a bound: the
final anneal after the trigger only lowers the rates further) and the iterations and training
time kept.

    python benchmarks/stop_rule_choice.py curves/sparse.csv curves/medium.csv curves/dense.csv \
        [--every 100 --tol 0.005 --patience 3]   # one setting, per model and tree

A rule-on training (window_curves.py --rule) measures the real cost of the chosen setting.
"""

from __future__ import annotations

import argparse
import itertools

import numpy as np
import pandas as pd

from physgs.models.registry import is_prior
from physgs.train.stopping import plateau_iteration

CAP, ANNEAL, FREEZE = 3000, 300, 1500  # the default profile: train.iterations, the anneal,
# models.ours.freeze_at x iterations (the priors' recipe changes the model there)


def stops(df: pd.DataFrame, every: int, tol: float, patience: int, anneal: int = ANNEAL, start=0.0):
    """One row per (tree, model): trigger, iterations used, loss at the trigger / at the cap."""
    out = []
    for (t, m), g in df.groupby(["tree", "model"]):
        g = g.sort_values("iteration")
        g = g[g["iteration"] % every == 0]
        its, loss = g["iteration"].to_numpy(), g["holdout_loss"].to_numpy()
        earliest = max(FREEZE if is_prior(m) else 0, int(start * CAP))
        trig = plateau_iteration(its[its < CAP], loss[its < CAP], patience, tol, earliest)
        if trig is not None and trig + anneal >= CAP:
            trig = None
        used = CAP if trig is None else trig + anneal
        at = loss[its == (trig if trig is not None else CAP)][0]
        cap = loss[its == CAP][0]
        psnr = g["holdout_psnr"].to_numpy()
        out.append(
            {
                "tree": t,
                "model": m,
                "trigger": -1 if trig is None else trig,
                "used": used,
                "loss_at_trigger": at,
                "loss_cap": cap,
                "lost_pct": 100 * (at / cap - 1),
                "psnr_lost_db": psnr[its == CAP][0]
                - psnr[its == (trig if trig is not None else CAP)][0],
                "wall_cap_s": g["seconds"].iloc[-1],
            }
        )
    return pd.DataFrame(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("curves", nargs="+")
    ap.add_argument("--every", type=int)
    ap.add_argument("--tol", type=float)
    ap.add_argument("--patience", type=int)
    ap.add_argument("--start", type=float, default=0.0)
    a = ap.parse_args()
    df = pd.concat([pd.read_csv(p).assign(src=i) for i, p in enumerate(a.curves)])
    # a model recorded by two processes on one tree: the first file's record
    df = df[df["src"] == df.groupby(["tree", "model"])["src"].transform("min")]
    if a.every:
        r = stops(df, a.every, a.tol, a.patience, start=a.start)
        print(r.to_string(index=False, float_format=lambda x: f"{x:.4g}"))
        kept = (r["used"] / CAP * r["wall_cap_s"]).sum() / r["wall_cap_s"].sum()
        print(f"iterations kept {r['used'].sum() / (CAP * len(r)):.3f}, time kept {kept:.3f}")
        return
    rows = []
    for every, tol, p in itertools.product(
        (100, 200, 300), (0.0, 0.0025, 0.005, 0.01, 0.02), (1, 2, 3, 4, 5)
    ):
        r = stops(df, every, tol, p, start=a.start)
        rows.append(
            {
                "every": every,
                "tol": tol,
                "patience": p,
                "window": every * p,
                "stopped": int((r["trigger"] >= 0).sum()),
                "it_kept": r["used"].sum() / (CAP * len(r)),
                "time_kept": (r["used"] / CAP * r["wall_cap_s"]).sum() / r["wall_cap_s"].sum(),
                "lost_max_pct": r["lost_pct"].max(),
                "lost_mean_pct": r["lost_pct"].mean(),
                "psnr_lost_max_db": r["psnr_lost_db"].max(),
            }
        )
    g = pd.DataFrame(rows)
    print(f"{len(df.groupby(['tree', 'model']))} curves")
    print(g.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
    np.seterr(all="ignore")


if __name__ == "__main__":
    main()
