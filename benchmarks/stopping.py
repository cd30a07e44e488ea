"""The stopping rule's data: held-out-window curves, the rule chosen on them, what scoring costs.

    PYTHONPATH=src nice -n 10 env OMP_NUM_THREADS=1 python benchmarks/stopping.py curves \
        --tree sparse --out curves/sparse.csv [--models static,mlp,...] [--every 50]
    python benchmarks/stopping.py choose curves/sparse.csv curves/medium.csv curves/dense.csv \
        [--every 100 --tol 0.005 --patience 3]   # one setting, per model and tree
    PYTHONPATH=src python benchmarks/stopping.py overhead results/testbed/sparse [--models ...]
    python benchmarks/stopping.py fits docs/record/claims.csv docs/studies/curves/*.csv \
        --fit docs/record/tables/tab_fit.csv [--markdown docs/studies/fit_shortfalls.md]

``curves``: held-out-window fit curves: each model's loss on the frames its training window holds
out (every ``train.holdout_every``-th, of the trained wind) every ``--every`` iterations of one
full-budget training (the profile's). What the stopping rule's N, tolerance and patience are
chosen on (docs/models.md); never the views, the tail or another wind. Writes one CSV row per
(model, iteration): the held-out loss (the training loss, L1 + D-SSIM), its PSNR (dB), the
training loss (mean of the last ``--every`` iterations), the wall time. ``--rule`` instead trains
each model as the pipeline does (``recipe.fit``, the config's ``train.stopping``, overridable
with ``--stop-every/--tol/--patience/--anneal``) and writes one row per model: the iterations
used, why it stopped, the held-out loss and PSNR at its end, its wall time and the time its
held-out scores took: the real cost of the chosen setting.

``plateau``: each curve's plateau by the rule's criterion (P scores without a ``tol`` relative
improvement of the held-out loss), its PSNR there, at 3000 iterations and at the end, the slope
over the last quarter (where it is heading), and with the static pose's and the ceiling's curves
the end's fraction of the ceiling's held-out gain; ``--markdown``/``--figure`` write them.

``fits``: each ``fits_window`` row of a ledger that does not hold (the fit bar's shortfalls),
beside the curve of its model on its tree at the budget it trained (``--fit``: the run's
tab_fit), else the longest measured: its last held-out score, its best and where it was heading.

``choose``: where the stopping rule would stop each model, from its held-out-window curve
(``curves``), for a grid of N (every), tol and P (patience), and what it would cost: the
held-out loss at the trigger against the loss at the cap (a bound: the final anneal after the
trigger only lowers the rates further) and the iterations and training time kept.

``overhead``: what scoring the held-out window frames costs against a training iteration, per
model: the mean wall time of a training iteration (``--iterations`` after the warm-up, the
profile's settings otherwise) and of one score of the held-out window frames
(``physgs.train.holdout.HoldoutEval``, ``--repeats`` times), side by side in one process, and
the share of a 3000-iteration training that scores every N iterations would add. Timings on a
shared machine compare only within one run.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import itertools
import os
import time
from pathlib import Path

import numpy as np
import pandas as pd
import torch

from physgs.config import load
from physgs.experiments.recipe import (
    Job,
    earliest_stop,
    fit,
    heldout_split,
    job_spec,
    window_scorer,
    with_budget,
)
from physgs.models.registry import (
    BLIND_PRIORS,
    build_model,
    is_prior,
    is_reference,
    training_jobs,
)
from physgs.testbed.dataset import load_observed, load_truth
from physgs.train.holdout import HoldoutEval
from physgs.train.loop import train_model
from physgs.train.seeding import seed_everything
from physgs.train.stopping import plateau_iteration

RULE_OFF = {"enabled": False, "every": 0, "patience": 1, "tol": 0.0, "anneal": 1}
FIELDS = (
    "model",
    "tree",
    "seed",
    "iteration",
    "holdout_loss",
    "holdout_psnr",
    "train_loss",
    "seconds",
)


def models_that_train(cfg: dict) -> list[str]:
    """Every model kind trained in `single`: the methods, the forcing-free priors, the parts
    study's variants and the ceiling."""
    ms = [m for m, c in training_jobs(cfg["models"]["configs"]) if c == "single"]
    ms += [m for m in BLIND_PRIORS] + [m for m in cfg["parts_study"]["models"] if m not in ms]
    return [*ms, "truth_motion"]


@contextlib.contextmanager
def appending(path: str, fields: tuple[str, ...]):
    """A CSV writer appending to ``path`` (the header only when the file is new): one output
    file gathers the runs of several trees and models."""
    new = not os.path.exists(path)
    with open(path, "a", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        if new:
            w.writeheader()
        yield w, fh


RULE_FIELDS = (
    "model",
    "tree",
    "seed",
    "every",
    "patience",
    "tol",
    "anneal",
    "iterations",
    "stopped",
    "stop_trigger",
    "holdout_loss",
    "holdout_psnr",
    "wall_s",
    "holdout_s",
    "holdout_evals",
)


def run_rule(a, cfg: dict, obs, truth, models: list[str]) -> None:
    """Train each model with the stopping rule on and append its row to ``a.out``."""
    st = dict(cfg["train"]["stopping"], enabled=True)
    for k, v in (
        ("every", a.stop_every),
        ("tol", a.tol),
        ("patience", a.patience),
        ("anneal", a.anneal),
    ):
        if v is not None:
            st[k] = v
    cfg["train"]["stopping"] = st
    with appending(a.out, RULE_FIELDS) as (w, fh):
        for m in models:
            job = Job.from_dict(job_spec(cfg, m, "single", seed=a.seed))
            res = fit(obs, job, truth=truth if is_reference(m) else None, progress=False)
            loss, p = window_scorer(obs, job).evaluate(res.model)
            s = res.stats
            w.writerow(
                dict(
                    model=m,
                    tree=a.tree,
                    seed=a.seed,
                    every=st["every"],
                    patience=st["patience"],
                    tol=st["tol"],
                    anneal=st["anneal"],
                    iterations=s["iterations"],
                    stopped=s["stopped"],
                    stop_trigger=s["stop_trigger"],
                    holdout_loss=loss,
                    holdout_psnr=p,
                    wall_s=s["wall_s"],
                    holdout_s=s["holdout_s"],
                    holdout_evals=s["holdout_evals"],
                )
            )
            fh.flush()
            print(
                f"{a.tree} {m}: {s['iterations']} it ({s['stopped']}), {s['wall_s']:.0f} s "
                f"(scores {s['holdout_s']:.1f} s), holdout loss {loss:.4f}, {p:.2f} dB",
                flush=True,
            )


def curves(a: argparse.Namespace) -> None:
    """Write each model's held-out-window curve (or, with ``--rule``, its rule-on row)."""
    cfg = load("config/trees.yaml", a.profile)
    obs = load_observed(f"results/testbed/{a.tree}/observed.npz")
    truth = load_truth(f"results/testbed/{a.tree}/truth.npz")
    models = a.models.split(",") if a.models else models_that_train(cfg)
    if a.rule:
        run_rule(a, cfg, obs, truth, models)
        return
    with appending(a.out, FIELDS) as (w, fh):
        for m in models:
            job = Job.from_dict(job_spec(cfg, m, "single", seed=a.seed))
            # the full budget, scored by the hook below: the curve the rule is chosen on
            train = {**job.train, "stopping": {**RULE_OFF}}
            if a.budget:  # a per-model budget: the schedule and the recipe's fractions over it
                train = with_budget(train, a.budget)
            job = job.replace(train=train)
            ev = window_scorer(obs, job)
            t0 = time.perf_counter()
            rows = []

            warmup = int(job.train["warmup"])

            def record(it, mdl, opt, _ev=ev, _rows=rows, _m=m, _t0=t0, _w=warmup):
                if it % a.every == 0 and it > 0:
                    loss, p = _ev.evaluate(mdl, warm=it < _w)
                    _rows.append(
                        dict(
                            model=_m,
                            tree=a.tree,
                            seed=a.seed,
                            iteration=it,
                            holdout_loss=loss,
                            holdout_psnr=p,
                            seconds=time.perf_counter() - _t0,
                        )
                    )
                    # a long curve is read while it runs: each score as it comes (without the
                    # training loss, which the log gives at the end)
                    print(",".join(str(v) for v in _rows[-1].values()), flush=True)

            truth_m = truth if is_reference(m) else None
            res = fit(obs, job, truth=truth_m, progress=False, name=m, hooks=(record,))
            loss, p = ev.evaluate(res.model, warm=False)
            rows.append(
                dict(
                    model=m,
                    tree=a.tree,
                    seed=a.seed,
                    iteration=len(res.log),
                    holdout_loss=loss,
                    holdout_psnr=p,
                    seconds=time.perf_counter() - t0,
                )
            )
            tl = np.array([r["loss"] for r in res.log])
            for r in rows:
                i = r["iteration"]
                r["train_loss"] = float(tl[max(0, i - a.every) : i].mean())
                w.writerow(r)
            fh.flush()
            print(
                f"{a.tree} {m}: {len(res.log)} it, {res.stats['wall_s']:.0f} s, "
                f"holdout loss {loss:.4f}, {p:.2f} dB",
                flush=True,
            )


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


def plateaus(
    df: pd.DataFrame,
    patience: int,
    tol: float,
    refs: pd.DataFrame | None = None,
    within_db: float = 0.5,
):
    """Per (tree, model) curve: where the rule's criterion finds its plateau and where it heads.

    Args:
        df: curve rows (``FIELDS``), one or more curves.
        patience: P of the rule (scores without an improvement of ``tol``).
        tol: the relative improvement that counts.
        refs: the static pose's and the ceiling's curves (their last score is the held-out
            window's reference), or None.
        within_db: ``enough_at`` is the first scored iteration within this many dB of the
            curve's best (the budget that buys all but ``within_db`` of what the curve reaches).

    Returns:
        One row per curve: its budget, the plateau iteration (empty: none before the end), the
        held-out PSNR there, at 3000 and at the end (dB), the slope over the last quarter (dB per
        1000 iterations: where it is heading) and, with ``refs``, the end's fraction of the
        ceiling's held-out gain over static.
    """
    out = []
    for (tree, m), g in df.groupby(["tree", "model"], sort=False):
        g = g.sort_values("iteration")
        it, psnr = g["iteration"].to_numpy(), g["holdout_psnr"].to_numpy()
        trig = plateau_iteration(it, g["holdout_loss"], patience, tol)
        tail = it >= it[-1] * 0.75
        slope = np.polyfit(it[tail], psnr[tail], 1)[0] * 1000 if tail.sum() > 1 else np.nan
        row = {
            "tree": tree,
            "model": m,
            "budget": int(it[-1]),
            "plateau_at": trig,
            "psnr_plateau": psnr[it == trig][0] if trig is not None else np.nan,
            "psnr_3000": psnr[it == 3000][0] if (it == 3000).any() else np.nan,
            "psnr_end": psnr[-1],
            "best_at": int(it[np.argmax(psnr)]),
            "psnr_best": psnr.max(),
            "enough_at": int(it[np.argmax(psnr >= psnr.max() - within_db)]),
            "slope_db_per_1000": slope,
        }
        if refs is not None:
            r = refs[refs["tree"] == tree].sort_values("iteration").groupby("model").last()
            if {"static", "truth_motion"} <= set(r.index):
                st, ce = r.loc["static", "holdout_psnr"], r.loc["truth_motion", "holdout_psnr"]
                row["heldout_of_ceiling_end"] = (psnr[-1] - st) / (ce - st)
        out.append(row)
    return pd.DataFrame(out)


def own_budgets(curves_: pd.DataFrame, own: pd.DataFrame) -> pd.DataFrame:
    """Trainings whose schedule ends at their own budget B against the long curve at B.

    The long curve's checkpoint at B is a training still at a higher learning rate, before any
    milestone set as a fraction of the budget (ours' part freeze, the omega search's bank), so
    it can lie below what a training of budget B reaches; this measures by how much.

    Args:
        curves_: the long curves' rows (``FIELDS``), one per (tree, model).
        own: the shorter trainings' rows, with a ``budget`` column.

    Returns:
        One row per (tree, model, budget): ``own_end`` (the B-training's last held-out window
        PSNR, dB), ``long_at`` (the long curve's score at B), ``long_best`` (its best) and
        ``own_below_best`` = long_best - own_end.
    """
    out = []
    for (tree, m, b), g in own.groupby(["tree", "model", "budget"]):
        long_ = curves_[(curves_["tree"] == tree) & (curves_["model"] == m)]
        at = long_[long_["iteration"] <= b]["holdout_psnr"]
        end = g.sort_values("iteration")["holdout_psnr"].iloc[-1]
        best = long_["holdout_psnr"].max() if len(long_) else np.nan
        out.append(
            {
                "tree": tree,
                "model": m,
                "budget": int(b),
                "own_end": end,
                "long_at": at.iloc[-1] if len(at) else np.nan,
                "long_best": best,
                "own_below_best": best - end,
            }
        )
    return pd.DataFrame(out)


def shortfalls(df: pd.DataFrame, caps: list[int]) -> pd.DataFrame:
    """Per curve, how far below its best its held-out window score is when training stops at each
    cap: the cost in fit of a budget lower than the curve's own.

    Args:
        df: curve rows (``FIELDS``).
        caps: budgets, iterations; a cap past the curve's end reads its last score.

    Returns:
        One row per (tree, model): ``below_best_<cap>`` = best PSNR - PSNR at the last score at
        or before the cap, dB (NaN where the curve has no score by then).
    """
    out = []
    for (tree, m), g in df.groupby(["tree", "model"], sort=False):
        g = g.sort_values("iteration")
        best = g["holdout_psnr"].max()
        row = {"tree": tree, "model": m}
        for c in caps:
            by = g[g["iteration"] <= c]
            row[f"below_best_{c}"] = best - by["holdout_psnr"].iloc[-1] if len(by) else np.nan
        out.append(row)
    return pd.DataFrame(out)


#: |slope| over a curve's last quarter below this (dB per 1000 iterations) reads as flat: a
#: quarter of a 12,000-iteration curve then moves under 0.3 dB, the size of a seed's spread
FLAT_DB_PER_1000 = 0.1


def heading(slope: float) -> str:
    """Where a curve is heading, in words, from its last quarter's slope.

    Args:
        slope: dB per 1000 iterations (NaN: too few scores).

    Returns:
        ``rising``, ``flat`` or ``falling`` with the slope; ``--`` without one.
    """
    if not np.isfinite(slope):
        return "--"
    word = "flat" if abs(slope) < FLAT_DB_PER_1000 else ("rising" if slope > 0 else "falling")
    return f"{word} ({slope:+.2f} dB/1000)"


def curves_at(df: pd.DataFrame, trained: dict) -> pd.DataFrame:
    """One curve per (tree, model) of the learned models: the training at the budget the model
    trained in a run, where one was made; else the longest.

    Args:
        df: curve rows (``FIELDS``) with each training's ``budget``.
        trained: (tree, model) -> the iterations it trained in the run.

    Returns:
        The chosen curves' rows.
    """
    learned = df[~df["model"].isin(["static", "truth_motion"])]
    keep = []
    for (tree, m), g in learned.groupby(["tree", "model"], sort=False):
        b = trained.get((tree, m))
        keep.append(g[g["budget"] == (b if (g["budget"] == b).any() else g["budget"].max())])
    return pd.concat(keep, ignore_index=True) if keep else learned


def fit_shortfalls(claims: pd.DataFrame, p: pd.DataFrame) -> pd.DataFrame:
    """Each ``fits_window`` row of a ledger that does not hold, beside its curve's plateau.

    Args:
        claims: a ledger (``claims.csv``: id, verdict, measured, ci_low, ci_high).
        p: ``plateaus``' rows of the held-out window curves.

    Returns:
        One row per such (tree, model): the verdict and measured fraction of the ceiling's
        in-window gain with its interval, the curve's length, its last held-out score and its
        best (dB, and where), and where it was heading (``heading``); ``--`` without a curve.
    """
    fits = claims[claims["id"].astype(str).str.startswith("fits_window/")]
    out = []
    for _, c in fits[~fits["verdict"].astype(str).str.startswith("holds")].iterrows():
        _, tree, model = str(c["id"]).split("/")
        row = {
            "tree": tree,
            "model": model,
            "verdict": str(c["verdict"]).split(":")[0],
            "ceiling_frac": f"{c['measured']:.2f} [{c['ci_low']:.2f}, {c['ci_high']:.2f}]",
        }
        r = p[(p["tree"] == tree) & (p["model"] == model)]
        if r.empty:
            row.update(curve="no curve measured", last_psnr="--", best="--", heading="--")
        else:
            r = r.iloc[0]
            row.update(
                curve=f"{r['budget']} it",
                last_psnr=f"{r['psnr_end']:.2f}",
                best=f"{r['psnr_best']:.2f} at {r['best_at']}",
                heading=heading(r["slope_db_per_1000"]),
            )
        out.append(row)
    return pd.DataFrame(out, columns=["tree", "model", "verdict", "ceiling_frac", "curve",
                                      "last_psnr", "best", "heading"])  # fmt: skip


def read_curves(paths: list[str]) -> pd.DataFrame:
    """Curve CSVs as one frame, each training's rows with its ``budget`` (its last iteration).

    Args:
        paths: curve CSVs (``curves``' output).

    Returns:
        Their rows (``FIELDS`` and ``budget``).
    """
    return pd.concat(
        [pd.read_csv(p).assign(budget=lambda d: d["iteration"].max()) for p in paths],
        ignore_index=True,
    )


def plateau(a: argparse.Namespace) -> None:
    """Print (and with ``--markdown`` write) each curve's plateau; ``--figure`` draws them."""
    df = read_curves(a.curves)
    refs = df[df["model"].isin(["static", "truth_motion"])]
    learned = df[~df["model"].isin(["static", "truth_motion"])]
    # the longest training of each (tree, model) is its curve; shorter ones are own-budget runs
    longest = learned.groupby(["tree", "model"])["budget"].transform("max")
    curves_, shorter = learned[learned["budget"] == longest], learned[learned["budget"] < longest]
    if len(shorter):
        print("trainings at their own budget against the long curve's checkpoint there (dB):")
        own = own_budgets(curves_, shorter)
        print(own.to_string(index=False, float_format="{:.2f}".format))
        print()
        if a.own_markdown:
            Path(a.own_markdown).write_text(own.to_markdown(index=False, floatfmt=".2f") + "\n")
    r = plateaus(curves_, a.patience, a.tol, refs if len(refs) else None, a.within)
    print(r.to_string(index=False, float_format=lambda x: f"{x:.3g}"))
    if a.caps:
        caps = [int(c) for c in a.caps.split(",")]
        short = shortfalls(curves_, caps)
        print("\nheld-out window PSNR below the curve's best at each cap (dB):")
        print(short.to_string(index=False, float_format=lambda x: f"{x:.2f}"))
        if a.markdown:
            r = r.merge(short, on=["tree", "model"])
    if a.markdown:
        Path(a.markdown).write_text(r.to_markdown(index=False, floatfmt=".3g") + "\n")
    if a.figure:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        trees = list(dict.fromkeys(curves_["tree"]))
        # one colour per model across the panels
        color = {m: f"C{i}" for i, m in enumerate(sorted(set(curves_["model"])))}
        fig, axes = plt.subplots(1, len(trees), figsize=(4.8 * len(trees), 3.8), squeeze=False)
        for ax, t in zip(axes[0], trees):
            for m, g in curves_[curves_["tree"] == t].groupby("model", sort=False):
                ax.plot(g["iteration"], g["holdout_psnr"], label=m, lw=1.2, color=color[m])
                row = r[(r["tree"] == t) & (r["model"] == m)].iloc[0]
                if pd.notna(row["plateau_at"]):
                    ax.plot(row["plateau_at"], row["psnr_plateau"], "kx", ms=6)
            for m, ls in (("static", "--"), ("truth_motion", ":")):
                g = refs[(refs["tree"] == t) & (refs["model"] == m)]
                if len(g):
                    ax.axhline(
                        g.sort_values("iteration")["holdout_psnr"].iloc[-1],
                        color="0.4",
                        ls=ls,
                        lw=1,
                        label=f"{m} (end)",
                    )
            ax.axvline(3000, color="0.7", lw=0.8)
            ax.set(title=t, xlabel="iteration", ylabel="held-out window PSNR (dB)")
            ax.grid(alpha=0.3)
        axes[0][0].legend(fontsize=7)
        fig.suptitle(
            "Held-out window curves (x: the rule's plateau; grey: today's budget)", fontsize=9
        )
        fig.tight_layout()
        fig.savefig(a.figure, dpi=150)


def fits(a: argparse.Namespace) -> None:
    """Print (and with ``--markdown`` write) the fit bar's shortfalls beside their curves."""
    df = read_curves(a.curves)
    trained = {}
    if a.fit:  # the budget each model trained in the run: its own-schedule curve, where measured
        tf = pd.read_csv(a.fit)
        trained = tf.groupby(["tree", "model"])["iterations"].max().astype(int).to_dict()
    p = plateaus(curves_at(df, trained), a.patience, a.tol)
    r = fit_shortfalls(pd.read_csv(a.claims), p)
    print(r.to_string(index=False))
    if a.markdown:
        Path(a.markdown).write_text(r.to_markdown(index=False) + "\n")


def choose(a: argparse.Namespace) -> None:
    """Print where the rule stops each curve, for one setting or over the grid."""
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


def overhead(a: argparse.Namespace) -> None:
    """Print, per model, ms per iteration and per held-out score, and the share."""
    cfg = load("config/trees.yaml", "default")
    obs = load_observed(a.testbed / "observed.npz")
    truth = load_truth(a.testbed / "truth.npz")
    every = a.every
    print(
        f"{'model':>12} {'ms/iter':>8} {'ms/score':>9} {'frames':>6} {'share':>6} (every {every})"
    )
    for m in a.models.split(","):
        job = Job.from_dict(job_spec(cfg, m, "single"))
        w = 10
        tcfg = {**job.train, "iterations": w + a.iterations, "warmup": w}
        tcfg["stopping"] = {**tcfg["stopping"], "enabled": False, "every": 0}
        seed_everything(0)
        model = build_model(m, obs, job.settings, K=job.K, truth=truth if is_reference(m) else None)
        res = train_model(model, obs, tcfg, conditions=[0], seed=0, progress=False)
        secs = np.array([r["seconds"] for r in res.log])
        it_ms = 1e3 * float(np.diff(secs[w:]).mean())
        held = heldout_split(int(obs.n_train), int(job.train["holdout_every"]))[1]
        ev = HoldoutEval.build(obs, held, [0], job.train)
        t = []
        for _ in range(a.repeats):
            t0 = time.perf_counter()
            ev.evaluate(res.model)
            t.append(time.perf_counter() - t0)
        sc_ms = 1e3 * float(np.median(t))
        # the scores of an enabled rule: every N from the recipe's last change, while a trigger
        # (+ the anneal) could still end the run before the cap
        anneal, cap = int(job.train["stopping"]["anneal"]), 3000
        first = max(earliest_stop(job), 1)
        n_scores = len([i for i in range(first, cap - anneal) if i % every == 0])
        share = n_scores * sc_ms / (3000 * it_ms)
        print(f"{m:>12} {it_ms:8.1f} {sc_ms:9.0f} {len(ev.pairs):6d} {100 * share:5.1f}%")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("curves", help="held-out-window fit curves (--rule: rule-on trainings)")
    p.add_argument("--tree", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--models", default="")
    p.add_argument("--every", type=int, default=50)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--profile", default="default")
    p.add_argument("--rule", action="store_true", help="train with the stopping rule on")
    p.add_argument("--budget", type=int, default=None, help="train this many iterations")
    p.add_argument("--stop-every", type=int, default=None)
    p.add_argument("--tol", type=float, default=None)
    p.add_argument("--patience", type=int, default=None)
    p.add_argument("--anneal", type=int, default=None)
    p.set_defaults(run=curves, threads=1)
    p = sub.add_parser("choose", help="where the rule would stop each curve, over a grid")
    p.add_argument("curves", nargs="+")
    p.add_argument("--every", type=int)
    p.add_argument("--tol", type=float)
    p.add_argument("--patience", type=int)
    p.add_argument("--start", type=float, default=0.0)
    p.set_defaults(run=choose, threads=None)
    p = sub.add_parser("plateau", help="each curve's plateau by the rule's criterion, its heading")
    p.add_argument("curves", nargs="+")
    p.add_argument("--patience", type=int, default=2)
    p.add_argument("--tol", type=float, default=0.005)
    p.add_argument("--within", type=float, default=0.5, help="enough_at: dB below the best")
    p.add_argument("--own-markdown", default=None, help="write the own-budget table here")
    p.add_argument("--caps", default="", help="e.g. 4500,6000: the shortfall at each budget")
    p.add_argument("--markdown", default=None, help="write the table here")
    p.add_argument("--figure", default=None, help="draw the curves here (PNG)")
    p.set_defaults(run=plateau, threads=None)
    p = sub.add_parser("fits", help="each fits_window row that does not hold, with its curve")
    p.add_argument("claims", help="a ledger: docs/record/claims.csv")
    p.add_argument("curves", nargs="+")
    p.add_argument("--patience", type=int, default=2)
    p.add_argument("--tol", type=float, default=0.005)
    p.add_argument("--fit", default=None, help="the run's tab_fit.csv: each model's budget")
    p.add_argument("--markdown", default=None, help="write the table here")
    p.set_defaults(run=fits, threads=None)
    p = sub.add_parser("overhead", help="a held-out score's cost against a training iteration")
    p.add_argument("testbed", type=Path)
    p.add_argument("--models", default="static,ours,mlp,mlp_wind,d3dgs,d3dgs_wind")
    p.add_argument("--iterations", type=int, default=60)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--every", type=int, default=300, help="N: iterations between scores")
    p.set_defaults(run=overhead, threads=1)
    args = ap.parse_args()
    if args.threads:
        torch.set_num_threads(args.threads)
    args.run(args)


if __name__ == "__main__":
    main()
