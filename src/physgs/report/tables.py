"""Result tables (the protocol, section 4; the paper's tab:psnr, tab:null, tab:transfer, tab:margin).

Each builder returns a ``Table``: a flat pandas DataFrame (what goes to the .csv, full
precision) and the booktabs LaTeX shown in the paper (rounded; best per column or row in bold
where the paper bolds; laid out as a frame of cells and rendered by ``physgs.report.latex``).
``write_table`` writes both atomically. Undefined entries (NaN, e.g. a median over zero trusted
parts) are written as an empty CSV cell and ``--`` in LaTeX.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.atomic import atomic_path, write_text
from physgs.evaluate.metrics import ceiling_fraction
from physgs.models.registry import MODEL_NAMES as MODELS
from physgs.models.registry import RECOVERY_METHODS, label, recovery_label, spec_of
from physgs.report import latex, paper
from physgs.report import seeds as seedstats

#: the method ids of the 2D-track control and the output-only analysis (``RECOVERY_METHODS``)
TRACKS, OMA = "tracks", "oma"
#: a .tex cell that a method does not define (a forcing-free prior beyond the window): never 0
NOT_DEFINED = "n/d"


@dataclass(frozen=True)
class Table:
    """A built table: its name, its numbers and its booktabs LaTeX."""

    name: str
    df: pd.DataFrame  # flat, numeric columns at full precision
    tex: str


@dataclass(frozen=True)
class MethodRows:
    """One recovery method's rows in tab_null, tab_recovery or tab_damping (``method_rows``;
    ``registry.RECOVERY_METHODS``).

    label: its LaTeX name ("" for ours, the paper's prior: its rows are labelled by their
    configuration alone); configs: its configurations (name -> LaTeX label, with its own K), in
    row order; per_seed: ``per_seed[seed][key]``, the table's record of each key (tab_null, tab_recovery:
    ``(tree, config)`` -> (``RecoveryRecord``, the ``NullResult`` of its K); tab_damping:
    ``(tree, variant, config)`` -> ``RecoveryRecord``); note: its sentence of the caption."""

    label: str
    configs: Mapping[str, str]
    per_seed: Mapping[int, Mapping[tuple, object]]
    note: str = ""

    def row_label(self, config: str) -> str:
        """The LaTeX label of its row in a configuration.

        Args:
            config: the configuration's name (a key of ``configs``).

        Returns:
            '<label>, <config label>' (ours': the configuration's label alone).
        """
        return f"{self.label}, {self.configs[config]}" if self.label else self.configs[config]


def tree_label(tree: str, bones: int) -> str:
    """A tree's row label, ``Sparse (22 bones)``.

    Args:
        tree (str): the tree's name.
        bones (int): its animated bones.

    Returns:
        str: the label.
    """
    return f"{tree.capitalize()} ({bones} bones)"


def condition_label(mult: float, tex: bool = True) -> str:
    """Mean-speed multiplier -> '$v_0$' / '$0.84v_0$' (tex) or 'v0' / '0.84v0'.

    Args:
        mult: the multiplier of the training mean speed v0.
        tex: LaTeX (tables) or plain text.

    Returns:
        The label.
    """
    if np.isclose(mult, 1.0):
        return "$v_0$" if tex else "v0"
    return f"${mult:.2f}v_0$" if tex else f"{mult:.2f}v0"


def _check(keys: Sequence, have: Mapping, what: str) -> None:
    missing = [k for k in keys if k not in have]
    if missing:
        raise KeyError(f"{what}: no results for {missing}; run the rules that produce them first")


# --------------------------------------------------------------------------------------------
# Every builder takes its results per training seed ({seed: {key: value}}): the CSV holds one row
# per seed (a ``seed`` column first), the .tex the mean +- sd over seeds, differences paired per
# seed with their 95% interval (physgs.report.seeds). "Best" is bold only when its paired
# difference to the runner-up is decided.


def _seeds(per_seed: Mapping[int, Mapping], what: str, keys: Sequence = ()) -> list[int]:
    """The training seeds of ``per_seed``, sorted, each checked to hold every one of ``keys``."""
    if not per_seed:
        raise ValueError(f"{what}: no seeds given")
    bad = [s for s in per_seed if not isinstance(s, (int, np.integer))]
    if bad:
        raise TypeError(
            f"{what}: results must be keyed by training seed first ({{seed: {{...}}}}), "
            f"got key {bad[0]!r}"
        )
    seeds = sorted(int(s) for s in per_seed)
    for s in seeds:
        _check(keys, per_seed[s], f"{what} (seed {s})")
    return seeds


def _best_cols(V: np.ndarray, rows: np.ndarray, higher: bool = True) -> np.ndarray:
    """[R] bool: among ``rows`` [R] bool, the row whose mean is best when decided (V [S, R])."""
    out = np.zeros(V.shape[1], bool)
    idx = np.flatnonzero(rows)
    b = seedstats.decided_best(V[:, idx], higher=higher)
    if b is not None:
        out[idx[b]] = True
    return out


def _tree_index(rows: pd.DataFrame, labels: Sequence[str], name: str) -> pd.MultiIndex:
    """Row labels grouped by tree: (the tree's label, each row's ``labels``)."""
    trees = [tree_label(t, b) for t, b in zip(rows["tree"], rows["bones"])]
    return pd.MultiIndex.from_arrays([trees, list(labels)], names=["Tree", name])


#: tab_psnr's difference rows: ``<prior>-static`` and ``<prior>-best_field`` (column ``model``)
PSNR_MINUS = "-"
#: the id of "the best learned field, per seed" in tab_psnr's difference rows
BEST_FIELD = "best_field"


def tab_psnr(
    per_seed: Mapping[int, Mapping[tuple[str, str], Mapping[str, float]]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    models: Sequence[str] = MODELS,
    digits: int = 2,
    references: Sequence[str] = (),
) -> Table:
    """PSNR (dB) on the view and time splits, one row per model, two columns per tree.

    The CSV's ``model`` column holds ids (a difference row: ``<prior>-static``,
    ``<prior>-best_field``); the labels are the .tex's.

    Below the models: references (the true-motion ceiling; never bold) and two paired
    differences, ours - static and ours - the best learned field (per seed, the learned field with
    the highest PSNR in that column), for every prior among ``models`` (role "prior" in the
    registry: ours, then the chained prior). The best method per column is bold when its paired
    difference to the runner-up is decided.

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
    seeds = _seeds(per_seed, "tab_psnr", [(t, m) for t in trees for m in (*models, *references)])
    learned = [m for m in models if spec_of(m).role == "field"]
    priors = [m for m in models if spec_of(m).role == "prior"]
    cols = [f"{t}_{sp}" for t in trees for sp in ("view", "time")]
    rows = []
    for s in seeds:
        S = per_seed[s]
        val = {
            m: {f"{t}_{sp}": S[(t, m)][sp] for t in trees for sp in ("view", "time")}
            for m in (*models, *references)
        }
        for m in (*models, *references):
            rows.append(
                {"seed": s, "model": m, **val[m], "reference": m in references, "difference": False}
            )
        subtracted = {"static": val["static"]} if "static" in models else {}
        if learned:  # the best learned field, per seed and column
            subtracted[BEST_FIELD] = {c: max(val[m][c] for m in learned) for c in cols}
        for p in priors:
            for other, v in subtracted.items():
                rows.append(
                    {
                        "seed": s,
                        "model": f"{p}{PSNR_MINUS}{other}",
                        **{c: val[p][c] - v[c] for c in cols},
                        "reference": False,
                        "difference": True,
                    }
                )
    df = pd.DataFrame(rows)
    first = latex.rows(df)
    ref, diff = first["reference"].to_numpy(bool), first["difference"].to_numpy(bool)
    names = [
        " $-$ ".join(
            "best learned field" if x == BEST_FIELD else label(x) for x in m.split(PSNR_MINUS)
        )
        if d
        else (rf"\emph{{{label(m)}}}" if r else label(m))
        for m, r, d in zip(first["model"], ref, diff)
    ]
    cells = pd.DataFrame(
        {
            (tree_label(t, bones[t]), sp): np.where(
                diff,
                latex.cells(df, f"{t}_{sp}", fmt, cell=seedstats.difference),
                latex.cells(df, f"{t}_{sp}", fmt),
            )
            for t in trees
            for sp in ("view", "time")
        },
        index=names,
    )
    bold = np.stack([_best_cols(latex.by_seed(df, c), ~ref & ~diff) for c in cols], axis=1)
    if not references:
        df = df.drop(columns="reference")
    cap = (
        r"PSNR (dB). \emph{view}: held-out azimuths at the training wind inside the training "
        r"window. \emph{time}: frames beyond the training window at the training wind and camera. "
        r"Best method per column in bold."
        + (
            r" In italics, a reference (not a method, never bold): the canonical Gaussians moved "
            r"by the ground-truth motion, appearance trained by the same recipe."
            if references
            else ""
        )
        + r" Last rows: paired differences (dB); the best learned field is taken per seed."
        + latex.seed_note(len(seeds))
    )
    return Table("tab_psnr", df, latex.render(cells, cap, "tab:psnr", bold))


# --------------------------------------------------------------------------------------------
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
    static pose. heldout_ceiling_frac is the same on ``heldout`` (the held-out window frames,
    against the static pose's and the ceiling's on those frames): a field that memorises its
    trained frames shows as a held-out fraction well below its trained one. The reference row
    is listed for scale. A split a model does not define (NaN at every seed: a forcing-free
    prior beyond the window) is an empty CSV cell and ``NOT_DEFINED`` in the .tex, never a
    number.

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
    seeds = _seeds(per_seed, "tab_fit", [(t, m) for t in trees for m in (*models, reference)])
    recs = []
    for s in seeds:
        rows = per_seed[s]
        for t in trees:
            ceil, stat = rows[(t, reference)]["fit"], rows[(t, static)]["fit"]
            hceil, hstat = rows[(t, reference)]["heldout"], rows[(t, static)]["heldout"]
            for m in (*models, reference):
                r = rows[(t, m)]
                recs.append(
                    {
                        "seed": s,
                        "tree": t,
                        "bones": bones[t],
                        "model": m,
                        "reference": m == reference,
                        "fit_psnr_db": r["fit"],
                        "heldout_psnr_db": r["heldout"],
                        "ceiling_frac": float(ceiling_fraction(r["fit"], stat, ceil)),
                        "heldout_ceiling_frac": float(ceiling_fraction(r["heldout"], hstat, hceil)),
                        "view_psnr_db": r["view"],
                        "time_psnr_db": r["time"],
                        "train_s": r["train_s"],
                        "iterations": r["iterations"],
                    }
                )
    df = pd.DataFrame(recs)
    first = latex.rows(df)
    fmt = f".{int(digits)}f"
    view, time = (
        [NOT_DEFINED if c == "--" else c for c in latex.cells(df, col, fmt)]
        for col in ("view_psnr_db", "time_psnr_db")
    )
    cells = pd.DataFrame(
        {
            "Fit": latex.cells(df, "fit_psnr_db", fmt),
            "Held-out frames": latex.cells(df, "heldout_psnr_db", fmt),
            "Of ceiling": latex.cells(df, "ceiling_frac", ".0f", r"\%", scale=100),
            "Held-out of ceiling": latex.cells(df, "heldout_ceiling_frac", ".0f", r"\%", scale=100),
            "View": view,
            "Time": time,
            "Train (s)": latex.cells(df, "train_s", ".0f"),
            "Iter.": latex.cells(df, "iterations", ".0f"),
        },
        index=_tree_index(
            first,
            [rf"\emph{{{label(m)}}}" if m == reference else label(m) for m in first["model"]],
            "Model",
        ),
    )
    cap = (
        r"Fit to the training window, PSNR (dB) at the training camera and wind. \emph{Fit}: "
        r"the training-window frames each model was trained on; \emph{Held-out frames}: every "
        + f"{holdout_every}th"
        + r" training-window frame, never trained on; \emph{Of ceiling}: "
        r"(model $-$ static) / "
        r"(true motion $-$ static) on the fit; \emph{Held-out of ceiling}: the same on the "
        r"held-out frames (below the fit's: the model memorises its trained frames). "
        r"\emph{View}, \emph{Time}: the evaluation splits. "
        r"\emph{Iter.}: training iterations used (the stopping rule's, capped at train.iterations). "
        r"In italics the reference: the canonical Gaussians moved by the ground-truth motion."
        + (
            f" {NOT_DEFINED}: not defined (a learned forcing has no wind to read beyond the "
            "window or under another wind)."
            if NOT_DEFINED in (*view, *time)
            else ""
        )
        + latex.seed_note(len(seeds), decides=False)
    )
    return Table("tab_fit", df, latex.render(cells, cap, "tab:fit"))


# --------------------------------------------------------------------------------------------
def tab_null(
    methods: Mapping[str, MethodRows],
    trees: Sequence[str],
    bones: Mapping[str, int],
    digits: int = 2,
) -> Table:
    """The paper's tab:null: ours' frequency recovery beside the untrained null of the same K,
    per tree and configuration (``recovery_table``'s columns).

    Args:
        methods: method id -> its [`MethodRows`][physgs.report.tables.MethodRows]: the paper's
            (``RecoveryMethod.paper``: ours), as in ``recovery_table``.
        trees: the trees.
        bones: tree -> its bone count.
        digits: decimals shown in the .tex.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    lead = "Frequency recovery against an untrained null."
    return recovery_table("tab_null", lead, methods, trees, bones, digits)


def tab_recovery(
    methods: Mapping[str, MethodRows],
    trees: Sequence[str],
    bones: Mapping[str, int],
    digits: int = 2,
) -> Table:
    """Every recovery method's frequency recovery (``registry.RECOVERY_METHODS``), each beside
    the untrained null of its own K; ours' rows (tab_null's) first, as the reference the others'
    claims compare with.

    Args:
        methods: method id -> its [`MethodRows`][physgs.report.tables.MethodRows], as in
            ``recovery_table``.
        trees: the trees.
        bones: tree -> its bone count.
        digits: decimals shown in the .tex.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    lead = (
        r"Frequency recovery of every method against the untrained null of its $K$; rows "
        r"labelled by their configuration alone are ours (Table~\ref{tab:null})."
    )
    return recovery_table("tab_recovery", lead, methods, trees, bones, digits)


def recovery_table(
    name: str,
    lead: str,
    methods: Mapping[str, MethodRows],
    trees: Sequence[str],
    bones: Mapping[str, int],
    digits: int = 2,
) -> Table:
    """Frequency recovery of each method against the untrained null, per tree and config.

    Each tree's rows: every method's in turn, each in its configurations; column ``method`` the
    id. Columns: parts trusted, median relative error (%), log-log R^2 for trained and null
    (null entries are medians over draws), trained - null (percentage points, paired per seed:
    negative means the trained model beats chance), and the median nearest-bone gap (%).

    Args:
        name: the table's name (its LaTeX label: ``tab:<name without tab_>``).
        lead: the caption's first sentence.
        methods: method id -> its [`MethodRows`][physgs.report.tables.MethodRows], in row order
            (``RECOVERY_METHODS``'; a method with no configurations has no rows):
            ``per_seed[seed][(tree, config)]`` = (its ``RecoveryRecord``, the ``NullResult``
            drawn with that seed and the method's K).
        trees: the trees.
        bones: tree -> its bone count.
        digits: decimals shown in the .tex.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    methods = {m: mr for m, mr in methods.items() if mr.configs}
    keys = [(t, c, m) for t in trees for m, mr in methods.items() for c in mr.configs]
    seeds = _method_seeds(methods, name, keys)
    rows = []
    for s in seeds:
        for t, c, method in keys:
            rec, nl = methods[method].per_seed[s][(t, c)]
            m = rec.match
            if nl.n_parts != m.n_parts:
                raise ValueError(
                    f"{name}: null for {t}/{c} (seed {s}) has K={nl.n_parts} but the "
                    f"model has K={m.n_parts}; re-run the null with the model's K"
                )
            tr, nu = 100 * m.median_rel_err, 100 * nl.median_median_rel_err
            rows.append(
                {
                    "seed": s,
                    "tree": t,
                    "bones": bones[t],
                    "config": c,
                    "method": method,
                    "K": m.n_parts,
                    "trained_parts_trusted": float(m.n_trusted),
                    "trained_median_rel_err_pct": tr,
                    "trained_loglog_r2": m.loglog_r2,
                    "null_parts_trusted": nl.median_n_trusted,
                    "null_median_rel_err_pct": nu,
                    "null_loglog_r2": nl.median_loglog_r2,
                    "trained_minus_null_pp": tr - nu,
                    "nearest_bone_gap_pct": 100 * nl.nearest_bone_gap,
                    "trained_parts_trusted_visible": float(rec.n_trusted_visible),
                    "trained_median_rel_err_visible_pct": 100 * rec.median_rel_err_visible,
                    "null_parts_trusted_visible": nl.median_n_trusted_visible,
                    "null_median_rel_err_visible_pct": 100 * nl.median_median_rel_err_visible,
                    **interval_cells(rec),
                }
            )
    df = pd.DataFrame(rows)  # each seed's block: each tree's rows together, in ``keys`` order
    first = latex.rows(df)
    fmt = f".{int(digits)}f"
    columns = {}
    for who, pre in (("Trained", "trained"), ("Untrained null", "null")):
        trusted = latex.cells(df, f"{pre}_parts_trusted", ".3g", cell=latex.mean)
        columns[(who, "Parts")] = [f"{n}/{k}" for n, k in zip(trusted, first["K"])]
        columns[(who, r"Med.\ rel.\ err.")] = latex.cells(
            df, f"{pre}_median_rel_err_pct", fmt, r"\%"
        )
        columns[(who, r"log-log $R^2$")] = latex.cells(df, f"{pre}_loglog_r2", ".3f")
    columns[("", r"Trained $-$ null")] = latex.cells(
        df, "trained_minus_null_pp", fmt, cell=seedstats.difference
    )
    columns[("", "Gap")] = latex.cells(df, "nearest_bone_gap_pct", fmt, r"\%", cell=latex.mean)
    for who, pre in (("Trained", "trained"), ("Null", "null")):
        columns[("Visible bones", who)] = latex.cells(
            df, f"{pre}_median_rel_err_visible_pct", fmt, r"\%"
        )
    labels = [methods[m].row_label(c) for m, c in zip(first["method"], first["config"])]
    cells = pd.DataFrame(columns, index=_tree_index(first, labels, "Config"))
    cap = (
        lead + r" Parts: parts trusted ($|\mathrm{corr}|\geq0.7$) "
        r"of $K$ (mean over seeds). Median relative error over trusted parts; $R^2$ of "
        r"$\log\hat\omega_p$ against $\log\omega_p$. Null entries are medians over 8 draws "
        r"of each seed, with the trained model's $K$; Trained $-$ null: percentage points, "
        r"paired per seed (negative: the trained model beats chance); Gap: median nearest-bone "
        r"gap. Visible bones: the median errors restricted to parts matched to bones whose own "
        r"motion moves at least a pixel in the training camera (the CSV also gives the part "
        r"counts)." + "".join(mr.note for mr in methods.values()) + latex.seed_note(len(seeds))
    )
    return Table(name, df, latex.render(cells, cap, "tab:" + name.removeprefix("tab_")))


def _method_seeds(methods: Mapping[str, MethodRows], what: str, keys: Sequence[tuple]) -> list[int]:
    """The training seeds of a recovery table (its first method's), each method checked to hold
    its ``keys`` (``(..., method)``) at every seed."""
    seeds = _seeds(next(iter(methods.values())).per_seed if methods else {}, what)
    for s in seeds:
        for m, mr in methods.items():
            have = mr.per_seed.get(s, {})
            _check([k[:-1] for k in keys if k[-1] == m], have, f"{what} ({_who(m)}, seed {s})")
    return seeds


def _who(method: str) -> str:
    """A method's name in the recovery tables' errors."""
    return "tracks control" if method == TRACKS else method


def method_rows(
    method: str, configs: Mapping[str, str], per_seed: Mapping[int, Mapping], damping: bool = False
) -> MethodRows:
    """A recovery method's rows (``registry.RECOVERY_METHODS``) for tab_null, tab_recovery or
    tab_damping: its label and caption sentence from its entry.

    Args:
        method: a recovery method's id.
        configs: name -> LaTeX label (with its own K), as in
            [`MethodRows`][physgs.report.tables.MethodRows].
        per_seed: its records, as in ``MethodRows``.
        damping: tab_damping's caption sentence (``RecoveryMethod.damping_note``) in place of
            the frequency tables'.

    Returns:
        The rows; the caption sentence '<label>: <note>' (none without a note).
    """
    rm, name = RECOVERY_METHODS[method], recovery_label(method)
    note = rm.damping_note if damping and rm.damping_note is not None else rm.note
    return MethodRows(name, configs, per_seed, f" {name}: {note}" if note else "")


#: tab_null / tab_damping's CSV columns of a method's own intervals (the output-only analysis';
#: NaN for a method without them): the coverage of its trusted parts' 95% intervals for omega
#: and zeta, the parts they cover, the median relative standard deviations (sigma / value) over
#: those parts, and the parts its sigma rule keeps (alone, and with ours'); last, the mean
#: relative interval scores of its intervals and of the untrained null's draw range on the same
#: parts (``physgs.oma.intervals.relative_scores``; NaN in a record made before them)
INTERVAL_COLUMNS = (
    "omega_rel_sd",
    "zeta_rel_sd",
    "omega_interval_cover",
    "zeta_interval_cover",
    "interval_parts",
    "sigma_parts_trusted",
    "sigma_and_corr_parts_trusted",
    "omega_interval_score",
    "omega_null_interval_score",
    "zeta_interval_score",
    "zeta_null_interval_score",
)


def interval_cells(rec) -> dict:
    """A record's ``INTERVAL_COLUMNS`` cells (NaN when
    the record has no ``intervals``).

    Args:
        rec (RecoveryRecord): the record.

    Returns:
        Column -> value.
    """
    iv = rec.intervals
    if not iv:
        return dict.fromkeys(INTERVAL_COLUMNS, float("nan"))
    cov = iv["coverage"]
    score = iv.get("interval_score", {})  # absent in a record made before the scores

    def sc(q: str, key: str) -> float:
        return float(score.get(q, {}).get(key, float("nan")))

    return {
        "omega_rel_sd": float(iv["median_rel_std"]["omega"]),
        "zeta_rel_sd": float(iv["median_rel_std"]["zeta"]),
        "omega_interval_cover": float(cov["omega"]["fraction"]),
        "zeta_interval_cover": float(cov["zeta"]["fraction"]),
        "interval_parts": float(cov["omega"]["n"]),
        "sigma_parts_trusted": float(iv["n_sigma_trusted"]),
        "sigma_and_corr_parts_trusted": float(iv["n_both_trusted"]),
        "omega_interval_score": sc("omega", "score"),
        "omega_null_interval_score": sc("omega", "null_score"),
        "zeta_interval_score": sc("zeta", "score"),
        "zeta_null_interval_score": sc("zeta", "null_score"),
    }


# --------------------------------------------------------------------------------------------
def tab_transfer(
    per_seed: Mapping[int, Mapping[tuple[str, str], Mapping[str, float]]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    conditions: Sequence[float],
    models: Sequence[str] = MODELS,
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
    seeds = _seeds(per_seed, "tab_transfer", [(t, m) for t in trees for m in models])
    rows = []
    for s in seeds:
        S = per_seed[s]
        for split, key in (("train", "train_c"), ("beyond", "beyond_c")):
            for t in trees:
                for c in range(1, len(conditions)):
                    r = {
                        "seed": s,
                        "split": split,
                        "tree": t,
                        "bones": bones[t],
                        "condition": float(conditions[c]),
                    }
                    for m in models:
                        r[m] = S[(t, m)][f"{key}{c}"]
                    rows.append(r)
    df = pd.DataFrame(rows)
    first = latex.rows(df)
    V = np.stack([latex.by_seed(df, m) for m in models], axis=-1)  # [S, R, M]
    best = [seedstats.decided_best(V[:, i, :]) for i in range(len(first))]
    splits = {
        "train": r"\shortstack[l]{Training\\timestamps}",
        "beyond": r"\shortstack[l]{Beyond the\\training window}",
    }
    index = pd.MultiIndex.from_arrays(
        [
            [splits[x] for x in first["split"]],
            [
                f"{tree_label(r.tree, r.bones)}, {condition_label(r.condition)}"
                for r in first.itertuples()
            ],
        ],
        names=["Split", "Tree / unseen wind"],
    )
    fmt = f".{int(digits)}f"
    cells = pd.DataFrame({_family_head(m): latex.cells(df, m, fmt) for m in models}, index=index)
    cap = (
        r"Zero-shot transfer to unseen wind, PSNR (dB); every model is fit to $v_0$ only. "
        r"Top: training timestamps; bottom: frames beyond the training window. Best per row in "
        r"bold." + latex.seed_note(len(seeds))
    )
    bold = np.arange(len(models)) == np.array([-1 if b is None else b for b in best])[:, None]
    return Table("tab_transfer", df, latex.render(cells, cap, "tab:transfer", bold))


#: a family heading over the learned fields' columns of tab_transfer
FAMILY_HEADS = {"mlp": "Deformation MLP", "d3dgs": "Deformable-3DGS"}


def _family_head(model: str) -> tuple[str, str]:
    """A model's tab_transfer heading: (its field family's, spanning the family's adjacent
    columns; "" for the rest), its short name."""
    spec = spec_of(model)
    return FAMILY_HEADS.get(spec.family, "") if spec.role == "field" else "", spec.short


# --------------------------------------------------------------------------------------------
def tab_margin(
    per_seed: Mapping[int, Mapping[tuple[str, str], Mapping[str, float]]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    conditions: Sequence[float],
    priors: Sequence[str] = ("ours",),
    baseline: str = "mlp_wind",
    digits: int = 2,
) -> Table:
    """Each prior minus Deformation MLP + wind, PSNR (dB) at training timestamps, per tree and
    condition (including the training condition), paired per seed.

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
    seeds = _seeds(per_seed, "tab_margin", [(t, m) for t in trees for m in (*priors, baseline)])
    rows = []
    for s in seeds:
        S = per_seed[s]
        for p in priors:
            for t in trees:
                r = {"seed": s, "model": p, "tree": t, "bones": bones[t]}
                for c, mult in enumerate(conditions):
                    r[f"margin_{condition_label(mult, tex=False)}"] = (
                        S[(t, p)][f"train_c{c}"] - S[(t, baseline)][f"train_c{c}"]
                    )
                rows.append(r)
    df = pd.DataFrame(rows)
    first = latex.rows(df)
    fmt = f".{int(digits)}f"
    index = pd.MultiIndex.from_arrays(
        [
            [rf"{label(p)} $-$ (Deformation MLP $+$\,wind)" for p in first["model"]],
            [tree_label(t, b) for t, b in zip(first["tree"], first["bones"])],
        ]
    )
    cells = pd.DataFrame(
        {
            condition_label(mult): latex.cells(
                df, f"margin_{condition_label(mult, tex=False)}", fmt, cell=seedstats.difference
            )
            for mult in conditions
        },
        index=index,
    )
    others = [label(p) for p in priors if p != "ours"]
    cap = (
        r"Margin against the wind-conditioned baseline: ours minus Deformation MLP\,$+$\,wind, "
        r"PSNR (dB) at training timestamps, on the training condition and the two unseen ones. "
        r"Positive means ours is ahead."
        + (f" Below, the same for: {', '.join(others)}." if others else "")
        + latex.seed_note(len(seeds))
    )
    return Table("tab_margin", df, latex.render(cells, cap, "tab:margin"))


# --------------------------------------------------------------------------------------------
def write_table(table: Table, tex_path: str | Path, csv_path: str | Path, stamp=None) -> None:
    """Write the table's .tex and .csv, each atomically (temp file then rename).

    Args:
        table: the table.
        tex_path: the .tex to write.
        csv_path: the .csv to write.
        stamp (Stamp | None): a [`Stamp`][physgs.provenance.Stamp]; its fields become the CSV's
            last columns (one value per row) and a comment line of the .tex.
    """
    df, tex = table.df, table.tex
    if stamp is not None:
        df = df.assign(**stamp.to_dict())
        tex = "% " + ", ".join(f"{k}={v}" for k, v in stamp.to_dict().items()) + "\n" + tex
    write_text(tex_path, tex)
    with atomic_path(csv_path) as tmp:
        df.to_csv(tmp, index=False, float_format="%.6g")


# --------------------------------------------------------------------------------------------
#: tab_testbed's statistics that vary from one tree instance to the next: each gets a
#: ``<col>_sd`` column, its spread over the instances (``testbed_seeds``)
INSTANCE_SPREAD = (
    "distinct_frequencies",
    "f_min_hz",
    "f_median_hz",
    "f_max_hz",
    "f_span",
    "clamped",
    "nearest_bone_gap_pct",
    "swing_deg_median",
    "visible_px_median",
    "visible_below_px_pct",
    "height_fill_pct",
    "coverage_pct",
)


def _testbed_row(s: Mapping) -> dict:
    """One instance's statistics in tab_testbed's columns (percentages as percent)."""
    return {
        "distinct_frequencies": int(s["distinct_frequencies"]),
        "f_min_hz": s["f_min_hz"],
        "f_median_hz": s["f_median_hz"],
        "f_max_hz": s["f_max_hz"],
        "f_span": s["f_span"],
        "clamped": int(s["clamped"]),
        "nearest_bone_gap_pct": 100 * s["nearest_bone_gap"],
        "swing_deg_median": s["swing_deg_median"],
        "visible_px_median": s["visible_px_median"],
        "visible_below_px_pct": 100 * s["visible_below_px_fraction"],
        "height_fill_pct": 100 * s["height_fill"],
        "coverage_pct": 100 * s["coverage"],
        "order_share": s["order_share"],
        "order_share_random": s["order_share_random"],
    }


def tab_testbed(
    stats: Mapping[str, Mapping],
    trees: Sequence[str],
    digits: int = 2,
    instances: Mapping[str, Sequence[Mapping]] | None = None,
    paper_trees: Mapping[str, str | None] | None = None,
) -> Table:
    """The testbed's statistics per tree
    ([`testbed_stats`][physgs.testbed.stats.testbed_stats]), beside the paper's figures where it
    gives them ([`physgs.report.paper`][physgs.report.paper]).

    Columns: bones; distinct natural frequencies; f min / median / max (Hz) and span; bones
    clamped into the band; median nearest-bone gap (%); median per-bone swing (degrees); how
    visible each bone's own motion is in the training camera (median pixels, % under 1 px);
    the training frame's height filled by the swept tree and pixels covered (%). With tree
    instances (``testbed_seeds``: one per training seed), each is the mean over a tree's
    instances, ``<col>_sd`` its spread (sample sd; ``INSTANCE_SPREAD``) and ``instances`` their
    number; without, the one instance's (sd NaN, ``instances`` 1).

    Args:
        stats: tree -> its statistics (as [`load_stats`][physgs.testbed.stats.load_stats] reads
            them): the one instance's.
        trees: the trees, in row order.
        digits: decimals shown in the .tex.
        instances: tree -> each instance's statistics (``testbed_seeds``); None or a tree left
            out: the one instance of ``stats``.
        paper_trees: tree -> the paper's tree it stands for (its preset's ``role.paper``), whose
            figures go beside it; None or a tree left out: none.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    _check(list(trees), stats, "tab_testbed")
    rows = []
    for t in trees:
        per = [_testbed_row(x) for x in ((instances or {}).get(t) or [stats[t]])]
        inst = pd.DataFrame(per)
        mean = {c: float(inst[c].mean()) for c in inst.columns}
        sd = {
            f"{c}_sd": float(inst[c].std(ddof=1)) if len(inst) > 1 else np.nan
            for c in INSTANCE_SPREAD
        }
        pt = (paper_trees or {}).get(t)
        rows.append(
            {
                "tree": t,
                "bones": int(stats[t]["bones"]),
                "paper_bones": paper.BONES.get(pt),
                **mean,
                "paper_f_span": paper.FREQUENCY_SPAN,
                "paper_nearest_bone_gap_pct": paper.NEAREST_BONE_GAP_PCT.get(pt, np.nan),
                "instances": len(per),
                **sd,
            }
        )
    df = pd.DataFrame(rows)
    fmt = f".{int(digits)}f"
    paper_gap = [
        "--" if not np.isfinite(x) else format(x, fmt) for x in df["paper_nearest_bone_gap_pct"]
    ]
    spread = [  # over the tree's instances, where there are several
        f" $\\pm$ {sd:{fmt}}" if n > 1 else ""
        for sd, n in zip(df["nearest_bone_gap_pct_sd"], df["instances"])
    ]
    cells = pd.DataFrame(
        {
            "Bones": df["bones"].astype(str),
            "Distinct $f$": df["distinct_frequencies"].astype(str),
            "$f$ min / med / max (Hz)": [
                f"{r.f_min_hz:.3f} / {r.f_median_hz:.3f} / {r.f_max_hz:.3f}"
                for r in df.itertuples()
            ],
            "Span": [f"{x:.2f}$\\times$" for x in df["f_span"]],
            "Clamped": df["clamped"].astype(str),
            "Gap (paper)": [
                f"{g:{fmt}}{sd}\\% ({p}\\%)"
                for g, sd, p in zip(df["nearest_bone_gap_pct"], spread, paper_gap)
            ],
            r"Swing ($^\circ$)": [f"{x:{fmt}}" for x in df["swing_deg_median"]],
            "Visible (px)": [f"{x:{fmt}}" for x in df["visible_px_median"]],
            r"$<$1\,px": [f"{x:.0f}\\%" for x in df["visible_below_px_pct"]],
            "Height": [f"{x:.0f}\\%" for x in df["height_fill_pct"]],
        }
    ).set_axis(pd.Index(df["tree"].str.capitalize(), name="Tree"))
    cap = (
        r"The testbed. Distinct $f$: distinct natural frequencies; Span: max/min frequency "
        + f"(paper: $\\sim${paper.FREQUENCY_SPAN}$\\times$)"
        + r"; Gap: median nearest-bone gap, the "
        r"paper's in brackets; Swing: median RMS of each bone's own angle over the window; "
        r"Visible: median image displacement caused by a bone's own angle alone, acting on its "
        r"subtree, in training-camera pixels, and the share of bones under 1\,px (no method "
        r"can recover those); Height: training-image height spanned by the swept tree."
        + (
            f" Each value is the mean over a tree's {int(df['instances'].max())} instances "
            r"(one per training seed), the gap $\pm$ its sd over them (the CSV: every "
            r"statistic's)."
            if (df["instances"] > 1).any()
            else " One instance per tree (the paper's protocol)."
        )
    )
    return Table("tab_testbed", df, latex.render(cells, cap, "tab:testbed"))
