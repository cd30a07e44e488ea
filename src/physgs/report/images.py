"""The outputs that score rendered images: the tables tab_psnr, tab_fit, tab_transfer and
tab_margin (built here) and the figures fig_temporal, fig_teaser and fig_results (drawn by
``physgs.report.figures``), each declared here. Each reads the evaluations of the models of its
roles, trained in the base configuration."""

from __future__ import annotations

from functools import partial
from importlib import resources
from typing import Mapping, Sequence

import numpy as np
import pandas as pd
import yaml

from physgs.evaluate.metrics import ceiling_fraction
from physgs.evaluate.splits import load_eval
from physgs.evaluate.trajectories import load_trajectories
from physgs.experiments.recipe import heldout_split
from physgs.models.registry import BASE_CONFIG, BLIND_CONFIG, MODEL_NAMES, PAPER_MODEL
from physgs.models.registry import blind_priors
from physgs.models.registry import label, models_of, spec_of
from physgs.report import latex, paper
from physgs.report import seeds as seedstats
from physgs.report.claim_cells import roles_of
from physgs.report.output import Columns, Output
from physgs.report.tables import Table, condition_label, seed_rows, seeds_of, tree_index
from physgs.report.tables import tree_label

#: the roles of the methods compared on images, and of the references shown beside them
METHODS, REFERENCES = ("control", "field", "prior"), ("reference",)
#: tab_margin: the wind-conditioned field every prior's margin is taken against
MARGIN_BASELINE = "mlp_wind"
#: a .tex cell that a method does not define (a forcing-free prior beyond the window): never 0
NOT_DEFINED = "n/d"
#: tab_psnr's difference rows: ``<prior>-static`` and ``<prior>-best_field`` (the best learned
#: field, per seed and column)
PSNR_MINUS, BEST_FIELD = "-", "best_field"
#: a family heading over the learned fields' columns of tab_transfer
FAMILY_HEADS = {"mlp": "Deformation MLP", "d3dgs": "Deformable-3DGS"}
SPLITS = ("view", "time")
#: the tables' captions, in parts (text, kept apart from the code: ``image_tables.yaml``)
TEXT = yaml.safe_load(resources.files("physgs.report").joinpath("image_tables.yaml").read_text())


def _grid(kinds, models, config, plan, seeds) -> list[tuple]:
    return [(k, t, m, config, s) for s in seeds for k in kinds for t in plan.trees for m in models]


def _evals(kinds: Sequence[str], *roles: str, extra: Sequence[str] = ()):
    """needs(plan, seeds): ``kinds`` of the ``extra`` models and every model of ``roles`` (read
    when planned: the registry may grow) on every tree, per seed."""
    return lambda plan, seeds: _grid(kinds, (*extra, *models_of(*roles)), BASE_CONFIG, plan, seeds)


def _conditions(cfg: dict) -> dict:
    return {"conditions": [float(c) for c in cfg["testbed"]["conditions"]]}


def _per_seed(settings, configs: Mapping[str, str], read) -> dict:
    """{seed: {(tree, model): read(tree, model, config, seed)}}, ``configs``: model -> config."""
    jobs = [(t, m, c) for t in settings["trees"] for m, c in configs.items()]
    return {s: {(t, m): read(t, m, c, s) for t, m, c in jobs} for s in settings["seeds"]}


def _summaries(path, settings, models) -> dict:
    """{seed: {(tree, model): summary}} of the models trained in the base configuration."""
    summary = lambda *job: load_eval(path("eval", *job)).summary()
    return _per_seed(settings, dict.fromkeys(models, BASE_CONFIG), summary)


def fit_row(eval_path, loss_path, n_train: int, holdout_every: int) -> dict:
    """One tab_fit row from a model's evaluation and loss log.

    Args:
        eval_path (str | Path): the model's evaluation ``.npz``.
        loss_path (str | Path | None): its loss log CSV (its last ``seconds``), or None.
        n_train: training-window length, frames.
        holdout_every: the held-out stride (0: no held-out frames, ``heldout`` NaN).

    Returns:
        ``fit`` and ``heldout`` (dB: PSNR at the training camera and wind over the trained and
        the held-out frames < n_train), ``view``, ``time`` (dB), ``train_s`` (s) and
        ``iterations`` (NaN without a loss log).
    """
    ev = load_eval(eval_path)
    cam = np.asarray(ev.camera_psnr[0, :n_train], dtype=np.float64)  # [n_train] dB
    if holdout_every:
        trained, held = heldout_split(n_train, holdout_every)
    else:
        trained, held = np.arange(n_train), np.arange(0)
    s = ev.summary()
    none = pd.DataFrame({"iteration": [np.nan], "seconds": [np.nan]})  # no loss log
    log = none if loss_path is None else pd.read_csv(loss_path, usecols=["iteration", "seconds"])
    return {
        "fit": float(cam[trained].mean()),
        "heldout": float(cam[held].mean()) if held.size else float("nan"),
        "view": s["view"],
        "time": s["time"],
        "train_s": float(log["seconds"].iloc[-1]),
        "iterations": float(log["iteration"].iloc[-1]) + 1,
    }


def fit_settings(cfg: dict) -> dict:
    """What ``fit_row`` reads: the training window's length and its held-out stride.

    Args:
        cfg: the resolved config.

    Returns:
        ``n_train`` and ``holdout_every``.
    """
    n_train, every = cfg["testbed"]["n_train"], cfg["train"]["holdout_every"]
    return {"n_train": int(n_train), "holdout_every": int(every)}


# ---- the tables' builders ------------------------------------------------------------------
def _table(name, df, cells, *parts, n_seeds: int, bold=None, decides=True, **fills) -> Table:
    """The table ``name``: its CSV frame ``df`` and the .tex of ``cells`` under the caption joined
    from ``TEXT``'s ``name`` and ``parts`` (an empty one left out), each ``<key>`` of ``fills``
    filled in, and the seeds' sentence."""
    text = "".join(TEXT[p] for p in (name, *parts) if p)
    for key, value in fills.items():
        text = text.replace(f"<{key}>", value)
    cap = text + latex.seed_note(n_seeds, decides=decides)
    return Table(name, df, latex.render(cells, cap, name.replace("tab_", "tab:"), bold))


def _emph(model: str, reference: bool) -> str:
    """A row's model label, in italics for a reference."""
    return rf"\emph{{{label(model)}}}" if reference else label(model)


def _best_cols(V: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """[R] bool: among ``rows`` [R] bool, the row whose mean is highest when decided (V [S, R])."""
    idx = np.flatnonzero(rows)
    b = seedstats.decided_best(V[:, idx], higher=True)
    return np.arange(V.shape[1]) == (-1 if b is None else idx[b])


def tab_psnr(
    per_seed: Mapping[int, Mapping[tuple[str, str], Mapping[str, float]]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    models: Sequence[str] = MODEL_NAMES,
    digits: int = 2,
    references: Sequence[str] = (),
) -> Table:
    """PSNR (dB) on the view and time splits, one row per model, two columns per tree.

    Below the models: the references (the true-motion ceiling; never bold), then for every prior
    among ``models`` (registry role "prior") two paired differences: the prior - static and the
    prior - the best learned field (per seed, the field with the highest PSNR in that column).
    The best method per column is bold when its paired difference to the runner-up is decided.
    The CSV's ``model`` holds ids (a difference: ``<prior>-static``, ``<prior>-best_field``).

    Args:
        per_seed: ``per_seed[seed][(tree, model)]``: ``EvalResult.summary()`` of the model trained
            ``single`` with that training seed.
        trees: the trees, in column order.
        bones: tree -> its bone count (in the header).
        models: the methods, in row order.
        digits: decimals shown in the .tex.
        references: the reference rows.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    fmt = f".{int(digits)}f"
    seeds = seeds_of(per_seed, "tab_psnr", [(t, m) for t in trees for m in (*models, *references)])
    learned = [m for m in models if spec_of(m).role == "field"]
    priors = [m for m in models if spec_of(m).role == "prior"]
    others = ["static"] * ("static" in models) + [BEST_FIELD] * bool(learned)
    cols = {f"{t}_{sp}": (t, sp) for t in trees for sp in SPLITS}

    def psnr(s, m):  # column -> dB of model m (the best learned field's: the max, per column)
        of = learned if m == BEST_FIELD else [m]
        return {c: max(per_seed[s][(t, x)][sp] for x in of) for c, (t, sp) in cols.items()}

    def row(s, m, other=None):  # a model's dB, or a prior's difference to ``other``'s
        a, b = psnr(s, m), psnr(s, other) if other else None
        name = f"{m}{PSNR_MINUS}{other}" if other else m
        dB = {c: a[c] - b[c] for c in cols} if other else a
        return {"model": name, **dB, "reference": m in references, "difference": bool(other)}

    keys = [(m,) for m in (*models, *references)] + [(p, o) for p in priors for o in others]
    df = seed_rows(seeds, keys, row)
    first = latex.rows(df)
    ref, diff = first["reference"].to_numpy(bool), first["difference"].to_numpy(bool)

    # a reference in italics; a difference "<a> $-$ <b>"
    term = lambda x: label(x) if x != BEST_FIELD else "best learned field"
    name = lambda m, r, d: " $-$ ".join(map(term, m.split(PSNR_MINUS))) if d else _emph(m, r)
    pm = partial(latex.cells, df, fmt=fmt)
    minus = partial(pm, cell=seedstats.difference)  # a difference's cell marks its interval
    names = [name(*x) for x in zip(first["model"], ref, diff)]
    heads = {c: (tree_label(t, bones[t]), sp) for c, (t, sp) in cols.items()}
    cells = pd.DataFrame({heads[c]: np.where(diff, minus(c), pm(c)) for c in cols}, index=names)
    bold = np.stack([_best_cols(latex.by_seed(df, c), ~ref & ~diff) for c in cols], axis=1)
    if not references:
        df = df.drop(columns="reference")
    notes = ("tab_psnr_references" if references else "", "tab_psnr_differences")
    return _table("tab_psnr", df, cells, *notes, n_seeds=len(seeds), bold=bold)


def tab_fit(
    per_seed: Mapping[int, Mapping[tuple[str, str], Mapping[str, float]]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    models: Sequence[str],
    reference: str,
    digits: int = 2,
    static: str = "static",
    holdout_every: int = 10,
) -> Table:
    """How much of the achievable fit each model reaches, per tree and model.

    ceiling_frac is (model - static) / (reference - static) on ``fit``, per seed against that
    seed's static pose and ceiling: 1 reaches the true-motion ceiling, 0 is no better than the
    static pose; heldout_ceiling_frac the same on ``heldout`` (a field that memorises its trained
    frames shows a held-out fraction well below its trained one). The reference row is listed
    for scale. A split a model does not define (NaN at every seed: a forcing-free prior beyond
    the window) is an empty CSV cell and ``NOT_DEFINED`` in the .tex, never a number.

    Args:
        per_seed: ``per_seed[seed][(tree, model)]``: fit (dB: mean PSNR over the trained
            training-window frames at the training camera and wind), heldout (dB: the same over
            the held-out training-window frames), view, time (dB: the evaluation splits), train_s
            (seconds of training), iterations (training iterations used: the stopping rule's).
        trees: the trees.
        bones: tree -> its bone count.
        models: the models, in row order.
        reference: the ceiling's id.
        digits: decimals shown in the .tex.
        static: the static model's id.
        holdout_every: train.holdout_every (the caption says which frames were held out).

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    keys = [(t, m) for t in trees for m in (*models, reference)]
    seeds = seeds_of(per_seed, "tab_fit", keys)

    def one(s, t, m):
        r, ceil, stat = (per_seed[s][(t, x)] for x in (m, reference, static))
        frac = {k: float(ceiling_fraction(r[k], stat[k], ceil[k])) for k in ("fit", "heldout")}
        fit = {f"{k}_psnr_db": r[k] for k in ("fit", "heldout")}
        fit |= {"ceiling_frac": frac["fit"], "heldout_ceiling_frac": frac["heldout"]}
        rest = {f"{k}_psnr_db": r[k] for k in SPLITS} | {k: r[k] for k in ("train_s", "iterations")}
        return {"tree": t, "bones": bones[t], "model": m, "reference": m == reference} | fit | rest

    df = seed_rows(seeds, keys, one)
    first = latex.rows(df)
    fmt = f".{int(digits)}f"
    cells = pd.DataFrame(
        {
            "Fit": latex.cells(df, "fit_psnr_db", fmt),
            "Held-out frames": latex.cells(df, "heldout_psnr_db", fmt),
            "Of ceiling": latex.cells(df, "ceiling_frac", ".0f", r"\%", scale=100),
            "Held-out of ceiling": latex.cells(df, "heldout_ceiling_frac", ".0f", r"\%", scale=100),
            "View": latex.cells(df, "view_psnr_db", fmt),
            "Time": latex.cells(df, "time_psnr_db", fmt),
            "Train (s)": latex.cells(df, "train_s", ".0f"),
            "Iter.": latex.cells(df, "iterations", ".0f"),
        },
        index=tree_index(first, [_emph(m, m == reference) for m in first["model"]], "Model"),
    )
    cells[["View", "Time"]] = cells[["View", "Time"]].replace("--", NOT_DEFINED)
    nd = "tab_fit_not_defined" if cells[["View", "Time"]].eq(NOT_DEFINED).any(axis=None) else ""
    fills = {"every": f"{holdout_every}", "nd": NOT_DEFINED}
    return _table("tab_fit", df, cells, nd, n_seeds=len(seeds), decides=False, **fills)


def tab_transfer(
    per_seed: Mapping[int, Mapping[tuple[str, str], Mapping[str, float]]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    conditions: Sequence[float],
    models: Sequence[str] = MODEL_NAMES,
    digits: int = 2,
) -> Table:
    """Zero-shot transfer PSNR (dB) on the unseen conditions (index >= 1), all models ``single``.

    Rows: split (training timestamps / beyond the window) x tree x unseen condition; columns:
    models. The best per row is bold when its paired difference to the runner-up is decided.

    Args:
        per_seed: ``per_seed[seed][(tree, model)]``: ``EvalResult.summary()``.
        trees: the trees.
        bones: tree -> its bone count.
        conditions: the mean-speed multipliers, the training one first.
        models: the methods, in column order.
        digits: decimals shown in the .tex.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    seeds = seeds_of(per_seed, "tab_transfer", [(t, m) for t in trees for m in models])
    stems = {"train": "train_c", "beyond": "beyond_c"}  # split -> its summary keys' stem

    def row(s, sp, t, c):
        psnr = {m: per_seed[s][(t, m)][f"{stems[sp]}{c}"] for m in models}
        return dict(split=sp, tree=t, bones=bones[t], condition=float(conditions[c])) | psnr

    keys = [(sp, t, c) for sp in stems for t in trees for c in range(1, len(conditions))]
    df = seed_rows(seeds, keys, row)
    first = latex.rows(df)
    V = np.stack([latex.by_seed(df, m) for m in models], axis=-1)  # [S, R, M]
    best = [seedstats.decided_best(V[:, i, :]) for i in range(len(first))]
    wind = [
        f"{tree_label(r.tree, r.bones)}, {condition_label(r.condition)}" for r in first.itertuples()
    ]
    split = first["split"].map(TEXT["tab_transfer_splits"])
    index = pd.MultiIndex.from_arrays([split, wind], names=["Split", "Tree / unseen wind"])

    # a field family's heading over the family's columns, and each model's short name
    family = lambda spec: FAMILY_HEADS.get(spec.family, "") if spec.role == "field" else ""
    heads = {m: (family(spec_of(m)), spec_of(m).short) for m in models}
    fmt = f".{int(digits)}f"
    cells = pd.DataFrame({heads[m]: latex.cells(df, m, fmt) for m in models}, index=index)
    bold = np.arange(len(models)) == np.array([-1 if b is None else b for b in best])[:, None]
    return _table("tab_transfer", df, cells, n_seeds=len(seeds), bold=bold)


def tab_margin(
    per_seed: Mapping[int, Mapping[tuple[str, str], Mapping[str, float]]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    conditions: Sequence[float],
    priors: Sequence[str] = (PAPER_MODEL,),
    baseline: str = "mlp_wind",
    digits: int = 2,
) -> Table:
    """Each prior minus Deformation MLP + wind, PSNR (dB) at training timestamps, per tree and
    condition (the training one included), paired per seed.

    Positive: the prior ahead. A margin is bold when its 95% interval excludes 0, marked undecided
    when not. One block of rows per prior of ``priors`` (column ``model``: its id), in that order.

    Args:
        per_seed: ``per_seed[seed][(tree, model)]``: ``EvalResult.summary()``.
        trees: the trees.
        bones: tree -> its bone count.
        conditions: the mean-speed multipliers, the training one first.
        priors: the priors, in block order.
        baseline: the model subtracted.
        digits: decimals shown in the .tex.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    seeds = seeds_of(per_seed, "tab_margin", [(t, m) for t in trees for m in (*priors, baseline)])
    col = {mult: f"margin_{condition_label(mult, tex=False)}" for mult in conditions}

    def row(s, p, t):  # the prior's PSNR minus the baseline's, per condition
        a, b = per_seed[s][(t, p)], per_seed[s][(t, baseline)]
        margins = {col[x]: a[f"train_c{c}"] - b[f"train_c{c}"] for c, x in enumerate(conditions)}
        return {"model": p, "tree": t, "bones": bones[t], **margins}

    df = seed_rows(seeds, [(p, t) for p in priors for t in trees], row)
    first = latex.rows(df)
    fmt = f".{int(digits)}f"
    minus = [rf"{label(p)} $-$ (Deformation MLP $+$\,wind)" for p in first["model"]]
    at = [tree_label(t, b) for t, b in zip(first["tree"], first["bones"])]
    margin = lambda x: latex.cells(df, col[x], fmt, cell=seedstats.difference)
    index = pd.MultiIndex.from_arrays([minus, at])
    cells = pd.DataFrame({condition_label(x): margin(x) for x in conditions}, index=index)
    others = ", ".join(label(p) for p in priors if p != PAPER_MODEL)
    more = "tab_margin_others" if others else ""
    return _table("tab_margin", df, cells, more, n_seeds=len(seeds), others=others)


# ---- the tables' declarations --------------------------------------------------------------
#: the needs of the methods' evaluations, and of the methods' and references'
EVAL_METHODS, EVAL_SHOWN = _evals(("eval",), *METHODS), _evals(("eval",), *METHODS, *REFERENCES)


def _tab_psnr(path, settings, inputs, out):
    per_seed = _summaries(path, settings, models_of(*METHODS, *REFERENCES))
    at = settings["trees"], settings["bones"], models_of(*METHODS), settings["digits"]
    return tab_psnr(per_seed, *at, models_of(*REFERENCES))


def _fit_needs(plan, seeds):
    """tab_fit's: every method's and reference's evaluation and loss log, and the forcing-free
    priors' (``plan.blind``, trained in ``BLIND_CONFIG``)."""
    kinds = ("eval", "loss")
    blind = _grid(kinds, plan.blind, BLIND_CONFIG, plan, seeds)
    return _evals(kinds, *METHODS, *REFERENCES)(plan, seeds) + blind


def _fit_settings(cfg):
    """``fit_settings``' and the forcing-free priors trained (``blind``)."""
    return {**fit_settings(cfg), "blind": list(blind_priors(cfg["models"]["configs"]))}


def _tab_fit(path, settings, inputs, out):
    n, every = int(settings["n_train"]), int(settings["holdout_every"])
    blind = settings.get("blind", [])  # in BLIND_CONFIG, the others in BASE_CONFIG
    config = dict.fromkeys(models_of(*METHODS, *REFERENCES), BASE_CONFIG)
    config |= dict.fromkeys(blind, BLIND_CONFIG)
    fit = lambda *job: fit_row(path("eval", *job), path("loss", *job), n, every)
    rows = _per_seed(settings, config, fit)
    models, reference = (*models_of(*METHODS), *blind), models_of(*REFERENCES)[0]
    at = settings["trees"], settings["bones"], models, reference, settings["digits"]
    return tab_fit(rows, *at, holdout_every=every)


def _tab_transfer(path, settings, inputs, out):
    per_seed = _summaries(path, settings, models_of(*METHODS))
    at = settings["trees"], settings["bones"], settings["conditions"], models_of(*METHODS)
    return tab_transfer(per_seed, *at, settings["digits"])


def _tab_margin(path, settings, inputs, out):
    per_seed = _summaries(path, settings, (MARGIN_BASELINE, *models_of("prior")))
    at = settings["trees"], settings["bones"], settings["conditions"], models_of("prior")
    return tab_margin(per_seed, *at, MARGIN_BASELINE, settings["digits"])


# one row per model id (a difference row: ``<prior>-static``, ``<prior>-best_field``)
PSNR_COLUMNS = Columns(
    ("seed", "model"), ("{tree}_view", "{tree}_time"), about=("reference", "difference")
)
TAB_PSNR = Output("tab_psnr", "table", EVAL_SHOWN, _tab_psnr, columns=PSNR_COLUMNS)
FIT_VALUES = ("fit_psnr_db", "heldout_psnr_db", "ceiling_frac", "heldout_ceiling_frac")
FIT_COLUMNS = Columns(
    ("seed", "tree", "model"),
    (*FIT_VALUES, "view_psnr_db", "time_psnr_db", "iterations"),
    timing=("train_s",),
    about=("bones", "reference"),
)
TAB_FIT = Output("tab_fit", "table", _fit_needs, _tab_fit, _fit_settings, columns=FIT_COLUMNS)
# one column per model id; the wind (``condition``) is a numeric key
TRANSFER_COLUMNS = Columns(("seed", "split", "tree", "condition"), ("{model}",), about=("bones",))
TAB_TRANSFER = Output(
    "tab_transfer", "table", EVAL_METHODS, _tab_transfer, _conditions, columns=TRANSFER_COLUMNS
)
MARGIN_COLUMNS = Columns(("seed", "model", "tree"), ("margin_{wind}",), about=("bones",))
MARGIN_NEEDS = _evals(("eval",), "prior", extra=(MARGIN_BASELINE,))
TAB_MARGIN = Output(
    "tab_margin", "table", MARGIN_NEEDS, _tab_margin, _conditions, columns=MARGIN_COLUMNS
)


# ---- figures -------------------------------------------------------------------------------
def teaser_tree(trees: Sequence[str], roles: dict | None = None) -> str:
    """The tree the teaser shows: the one whose preset stands for the paper's teaser tree
    (``paper.TEASER_TREE``, its clearest case) if built, else the last.

    Args:
        trees: the trees built.
        roles: tree -> its preset's role (``claim_cells.roles_of``); None: none declared.

    Returns:
        The tree's name.
    """
    stand_in = [t for t in trees if ((roles or {}).get(t) or {}).get("paper") == paper.TEASER_TREE]
    return stand_in[0] if stand_in else trees[-1]


def _fig_temporal(path, settings, inputs, out):
    from physgs.report import figures  # matplotlib: not for the workflow's planning imports

    shown = dict.fromkeys(models_of(*METHODS, *REFERENCES), BASE_CONFIG)
    runs = _per_seed(settings, shown, lambda *job: load_eval(path("eval", *job)).temporal_psnr)
    curves = {k: np.stack([run[k] for run in runs.values()]) for k in next(iter(runs.values()))}
    figures.fig_temporal(curves, settings["trees"], int(settings["n_train"]), out)


def _fig_teaser(path, settings, inputs, out):
    from physgs.report import figures

    t, s0 = teaser_tree(settings["trees"], settings.get("roles")), settings["seeds"][0]
    evals = {m: load_eval(path("eval", t, m, BASE_CONFIG, s0)) for m in models_of(*METHODS)}
    summary = {m: e.summary() for m, e in evals.items()}
    base = figures.best_baseline(summary, key="time", exclude=models_of("control", "prior"))
    shown = (*models_of("prior"), base)  # every prior beside the best learned field
    traj = {m: load_trajectories(path("traj", t, m, BASE_CONFIG, s0)) for m in shown}
    cen = {m: evals[m].centroid_err for m in shown}
    title = f"{t} tree, training seed {s0}"
    figures.fig_teaser(traj, cen, settings["conditions"], out, title=title)


def _fig_results(path, settings, inputs, out):
    from physgs.report import figures

    s0, models = settings["seeds"][0], models_of(*METHODS)
    rows, images = [], {}
    for t in settings["trees"]:
        panels = {m: np.load(path("panels", t, m, BASE_CONFIG, s0)) for m in models}
        for split in ("time", "view", "wind"):
            row = f"{t}: unseen {split}"
            rows.append(row)
            images[(row, "gt")] = (panels[PAPER_MODEL][f"{split}_gt"], None)
            for m in models:
                images[(row, m)] = (panels[m][f"{split}_pred"], float(panels[m][f"{split}_psnr"]))
    figures.fig_results(rows, ["gt", *models], images, out)


def _teaser_settings(cfg: dict) -> dict:
    """The conditions, and the trees' roles: the teaser shows the tree standing for the paper's."""
    return {**_conditions(cfg), "roles": roles_of(cfg["presets"], cfg["trees"])}


def _n_train(cfg: dict) -> dict:
    """The training window's length."""
    return {"n_train": int(cfg["testbed"]["n_train"])}


FIG_TEMPORAL = Output("fig_temporal", "figure", EVAL_SHOWN, _fig_temporal, _n_train)
TEASER_NEEDS, RESULTS_NEEDS = (_evals(("eval", k), *METHODS) for k in ("traj", "panels"))
FIG_TEASER = Output("fig_teaser", "figure", TEASER_NEEDS, _fig_teaser, _teaser_settings, "first")
FIG_RESULTS = Output("fig_results", "figure", RESULTS_NEEDS, _fig_results, _conditions, "first")
