"""The fit curve: how each model's fit to its training window grows with the training budget.

On each tree of ``speed_accuracy.fit_curve.trees`` (absent: every tree of the run), each listed model is trained ``single`` at each
listed budget (training iterations; the static warm-up keeps its fraction, as in the sweep) by
the tables' recipe, and scored at the training camera and wind: on the trained frames (fit), on
the every-``holdout_every``-th frames held out of training (interpolation), and on the tail (the
time split). The profile's own budget is not retrained: its point is the pipeline's own job,
read from that job's evaluation and loss log, so the curve passes through the tables' numbers.

Diagnostic series: each listed field whose time encoding is not Deformable-3DGS's window-
normalised time (``models.<family>.time_top_hz``) is also trained at the profile's budget with
that convention, as the series ``<model>@window``, so a reader sees both.
"""

from __future__ import annotations

import copy

import time
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.evaluate.metrics import ceiling_fraction as _fraction
from physgs.experiments.recipe import fit, heldout_split, job_spec, with_budget
from physgs.models.registry import BASE_CONFIG, FIELD_FAMILIES, MODELS
from physgs.models.timescale import WINDOW_TIME

#: suffix of a fit-curve series trained with the window-normalised time encoding
WINDOW_SERIES = "@" + WINDOW_TIME

COLUMNS = ("seed", "model", "iterations", "is_profile", "fit", "heldout", "time", "train_s", "tree")


def trees_of(cfg: dict) -> list[str]:
    """The fit curve's trees: ``speed_accuracy.fit_curve.trees``, or every tree of the run.

    Args:
        cfg: the resolved config.

    Returns:
        Tree names.
    """
    return list(cfg["speed_accuracy"]["fit_curve"].get("trees") or cfg["trees"])


def own_budget(cfg: dict, tree: str | None = None, model: str | None = None) -> int:
    """The budget the pipeline's own job trains: ``train.iterations``, or the tree's recipe's for
    that model (``recipes``).

    Args:
        cfg: the resolved config.
        tree: the tree; None: the shared budget.
        model: the model; None: the shared budget.

    Returns:
        Training iterations.
    """
    if tree is None or model is None:
        return int(cfg["train"]["iterations"])
    return int(job_spec(cfg, model, BASE_CONFIG, tree=tree)["train"]["iterations"])


def budgets(cfg: dict, tree: str | None = None, model: str | None = None) -> list[int]:
    """Every budget on a model's curve, ascending: the listed ones, the shared
    ``train.iterations`` and its own job's (a tree's recipe may set another).

    Args:
        cfg: the resolved config.
        tree: the tree (its recipe may set the model's own budget); None: the shared budget.
        model: the model; None: the shared budget.

    Returns:
        Training iterations, ascending, without repeats.
    """
    fc = cfg["speed_accuracy"]["fit_curve"]
    shared = int(cfg["train"]["iterations"])
    return sorted({*map(int, fc["iterations"]), shared, own_budget(cfg, tree, model)})


def extra_budgets(cfg: dict, tree: str | None = None, model: str | None = None) -> list[int]:
    """The budgets that need a training job of their own (all but the model's own job's).

    Args:
        cfg: the resolved config.
        tree: the tree; None: the shared budget.
        model: the model; None: the shared budget.

    Returns:
        Training iterations, ascending.
    """
    own = own_budget(cfg, tree, model)
    return [b for b in budgets(cfg, tree, model) if b != own]


def window_models(cfg: dict) -> list[str]:
    """The fit curve's fields whose chosen time encoding is not the window convention: each gets
    a ``<model>@window`` diagnostic point at the profile's budget.

    Args:
        cfg: the resolved config.

    Returns:
        Model ids, in the fit curve's order.
    """
    out = []
    for m in cfg["speed_accuracy"]["fit_curve"]["models"]:
        family = MODELS[m].family
        if family in FIELD_FAMILIES and cfg["models"][family]["time_top_hz"][m] != WINDOW_TIME:
            out.append(m)
    return out


def point_job(
    cfg: dict,
    model: str,
    iterations: int,
    seed: int | None = None,
    window_time: bool = False,
    tree: str | None = None,
) -> dict:
    """The training job ([`job_spec`][physgs.experiments.recipe.job_spec]) of ``model`` at a budget.

    Args:
        cfg: the resolved config.
        model: a model id.
        iterations: the training budget (the warm-up keeps its fraction).
        seed: the training seed (default ``cfg['seed']``).
        window_time: a field with the window-normalised time encoding instead of its chosen one
            (the diagnostic series).
        tree: the point's tree (its recipe, ``recipes``, applies); None: the fit curve's first.

    Returns:
        The job as a sorted dict.

    Raises:
        ValueError: for ``window_time`` on a model that is not a field.
    """
    tree = tree or trees_of(cfg)[0]
    pcfg = cfg
    if window_time:
        pcfg = copy.deepcopy(cfg)
        family = MODELS[model].family
        if family not in FIELD_FAMILIES:
            raise ValueError(f"{model!r} has no time encoding; the window series is for fields")
        pcfg["models"][family]["time_top_hz"] = {
            **pcfg["models"][family]["time_top_hz"],
            model: WINDOW_TIME,
        }
    job = job_spec(pcfg, model, BASE_CONFIG, seed=seed, tree=tree)
    # the budget alone changes, over the tree's recipe too; the warm-up keeps its fraction
    return {**job, "train": with_budget(job["train"], iterations)}


def run_point(job: Mapping, observed, *, progress: bool = False, series: str | None = None) -> dict:
    """Train ``job`` on ``observed`` and score it; a flat record (dB, seconds).

    Args:
        job: the training job's dict.
        observed (Observed): the dataset.
        progress: show a progress bar.
        series: the record's ``model`` (default the job's model id; ``<model>@window`` for the
            window-time diagnostic).

    Returns:
        ``model``, ``seed``, ``iterations``, ``fit`` / ``heldout`` (mean PSNR over the trained /
            held-out training-window frames, dB; heldout NaN without held-out frames), ``time``
            (over the tail frames, dB), all at the training camera and wind, and ``train_s`` (wall
            time of the training, s).
    """
    from physgs.evaluate.run import training_camera_scores  # torch: only when training

    t0 = time.perf_counter()
    res = fit(
        observed,
        dict(job),
        progress=progress,
        name=f"{job['model']}_{job['config']}[{job['train']['iterations']} it]",
    )
    train_s = time.perf_counter() - t0
    n = int(observed.n_train)
    every = int(job["train"].get("holdout_every", 0))
    trained, held = heldout_split(n, every) if every else (np.arange(n), np.arange(0))
    backend = job["train"]["backend"]
    _, p_fit = training_camera_scores(res.model, observed, trained, backend=backend)
    _, p_held = (
        training_camera_scores(res.model, observed, held, backend=backend)
        if held.size
        else (None, np.array([np.nan]))
    )
    tail = np.arange(n, n + int(observed.n_tail))
    _, p_time = training_camera_scores(res.model, observed, tail, backend=backend)
    return {
        "model": series if series is not None else job["model"],
        "seed": int(job["seed"]),
        "iterations": int(job["train"]["iterations"]),
        "fit": float(np.mean(p_fit)),
        "heldout": float(np.mean(p_held)),
        "time": float(np.mean(p_time)),
        "train_s": float(train_s),
    }


def collect(
    points: Sequence[dict],
    profile_rows: Mapping[int, Mapping[str, dict]],
    profile_iterations: int,
    tree: str,
) -> pd.DataFrame:
    """One row per (seed, model, budget), sorted.

    Args:
        points: [`run_point`][physgs.experiments.fit_curve.run_point] records (each names its
            seed).
        profile_rows: seed -> model -> the pipeline's own row at the profile's budget
            ([`fit_row`][physgs.report.build.fit_row]: fit, heldout, time, train_s), references
            included.
        profile_iterations: the profile's budget (a profile row's own ``iterations``, the
            job's, wins: a tree's recipe may set a model's budget).
        tree: the fit curve's tree (a column).

    Returns:
        The ``COLUMNS`` table, sorted by model, iterations and seed; ``is_profile`` marks the
            pipeline's rows.

    Raises:
        ValueError: when a point repeats a (seed, model) at the profile's budget.
    """
    keep = ("model", "iterations", "fit", "heldout", "time", "train_s")
    rows = [
        {"seed": int(p["seed"]), **{k: p[k] for k in keep}, "is_profile": False, "tree": tree}
        for p in points
    ]
    for seed, by_model in profile_rows.items():
        for m, r in by_model.items():
            used = r.get("iterations", np.nan)  # the job's own: a tree's recipe may set it
            rows.append(
                {
                    "seed": int(seed),
                    "model": m,
                    "iterations": int(profile_iterations if np.isnan(used) else used),
                    "fit": r["fit"],
                    "heldout": r["heldout"],
                    "time": r["time"],
                    "train_s": r["train_s"],
                    "is_profile": True,
                    "tree": tree,
                }
            )
    df = pd.DataFrame(rows, columns=list(COLUMNS))
    if df.duplicated(["seed", "model", "iterations"]).any():
        raise ValueError(
            f"fit curve: budget {profile_iterations} given twice for a model and "
            "seed; the profile's budget comes from the pipeline, not from a point"
        )
    return df.sort_values(["model", "iterations", "seed"], kind="stable").reset_index(drop=True)


def ceiling_fraction(
    df: pd.DataFrame, static: str = "static", ceiling: str = "truth_motion"
) -> pd.Series:
    """(fit - static) / (ceiling - static) per row, against the same tree's and seed's
    profile-budget static and ceiling rows (the fraction of the achievable in-window gain); NaN without them.

    Args:
        df: [`collect`][physgs.experiments.fit_curve.collect]'s table.
        static: the static model's id.
        ceiling: the ceiling's id.

    Returns:
        The fractions, indexed like ``df``.
    """
    prof = df[df["is_profile"]].set_index(["tree", "seed", "model"])["fit"]
    out = pd.Series(np.nan, index=df.index)
    for (tree, seed), g in df.groupby(["tree", "seed"]):
        if (tree, seed, static) in prof.index and (tree, seed, ceiling) in prof.index:
            out[g.index] = _fraction(
                g["fit"], prof[(tree, seed, static)], prof[(tree, seed, ceiling)]
            )
    return out


def curve_table(
    points: Mapping[str, Sequence[dict]],
    profile_rows: Mapping[str, Mapping[int, Mapping[str, dict]]],
    profile_iterations: int,
) -> pd.DataFrame:
    """The fit curve's CSV over its trees: [`collect`][physgs.experiments.fit_curve.collect] per
    tree, with each row's fraction of its tree's and seed's ceiling (``of_ceiling``).

    Args:
        points: tree -> its [`run_point`][physgs.experiments.fit_curve.run_point] records.
        profile_rows: tree -> seed -> model -> the pipeline's own row at the profile's budget.
        profile_iterations: the profile's budget.

    Returns:
        The ``COLUMNS`` table and ``of_ceiling``, tree by tree in ``points``' order.
    """
    df = pd.concat(
        [collect(points[t], profile_rows[t], profile_iterations, t) for t in points],
        ignore_index=True,
    )
    df["of_ceiling"] = ceiling_fraction(df)
    return df


def fit_vs_extrapolation(df: pd.DataFrame, static: str = "static") -> pd.DataFrame:
    """Each fit-curve point's in-window fraction of the ceiling and its gain over the static pose
    beyond the window.

    Args:
        df: the fit curve's CSV ([`fit_curve.collect`][physgs.experiments.fit_curve.collect]
            with ``of_ceiling``): one row per tree, seed, model and budget.
        static: the static pose's id.

    Returns:
        The rows of every model but the static pose that have both numbers (the references
        too: the figure leaves them out), with ``beyond_gain``: time-split PSNR minus the same
        tree's and seed's static pose at the profile's budget (dB).
    """
    prof = df[df["is_profile"] & (df["model"] == static)].set_index(["tree", "seed"])["time"]
    out = df[df["model"] != static].join(prof.rename("static_time"), on=["tree", "seed"])
    out["beyond_gain"] = out.pop("time") - out.pop("static_time")
    return out.dropna(subset=["of_ceiling", "beyond_gain"])


def trade_summary(df: pd.DataFrame, references: Sequence[str] = ("truth_motion",)) -> pd.DataFrame:
    """Along each model's fit curve, its in-window fit and its gain beyond the window at each
    budget (means over seeds), and how both moved from its smallest budget to its largest: what
    fig_fit_vs_extrapolation draws, as numbers.

    Args:
        df: [`fit_vs_extrapolation`][physgs.experiments.fit_curve.fit_vs_extrapolation]'s rows.
        references: models left out (the ceiling is no opponent).

    Returns:
        One row per tree and model (the curve's order): ``budgets`` (iterations, the profile's
        starred), ``seeds``, ``of_ceiling`` and ``beyond_gain_db`` (per budget, ``a / b / c``),
        ``d_of_ceiling`` and ``d_beyond_db`` (largest budget minus smallest).
    """
    rows = []
    for (tree, model), g in df[~df["model"].isin(references)].groupby(
        ["tree", "model"], sort=False
    ):
        m = g.groupby("iterations").agg(
            of_ceiling=("of_ceiling", "mean"),
            beyond=("beyond_gain", "mean"),
            profile=("is_profile", "any"),
        )
        rows.append(
            {
                "tree": tree,
                "model": model,
                "budgets": " / ".join(f"{i}{'*' * p}" for i, p in zip(m.index, m["profile"])),
                "seeds": g["seed"].nunique(),
                "of_ceiling": " / ".join(f"{v:.2f}" for v in m["of_ceiling"]),
                "beyond_gain_db": " / ".join(f"{v:+.2f}" for v in m["beyond"]),
                "d_of_ceiling": m["of_ceiling"].iloc[-1] - m["of_ceiling"].iloc[0],
                "d_beyond_db": m["beyond"].iloc[-1] - m["beyond"].iloc[0],
            }
        )
    return pd.DataFrame(rows)
