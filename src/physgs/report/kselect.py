"""tab_kselect: each prior with fixed K (`single`) beside the same prior with K chosen from the
data (`auto`): ours, and every prior under ``models.kselect.priors`` (the chained prior)."""

from __future__ import annotations

from functools import partial
from itertools import product
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.evaluate.splits import load_eval
from physgs.experiments.kselect import BASE_MODEL, load_selection, selected_models
from physgs.models.registry import PAPER_MODEL, spec_of
from physgs.recovery.record import load_recovery
from physgs.report import latex
from physgs.report.output import Columns, Output
from physgs.report.table_captions import caption
from physgs.report.tables import Table, seed_rows, seeds_of, tree_index

#: the rows of each prior: configuration -> its label (fixed K, then K chosen from the data)
ROWS = {"single": "fixed $K$", "auto": "chosen $K$"}

#: tab_kselect's CSV values -> each from a row of its ``per_seed`` (its timings follow them)
VALUES = {
    "view_psnr_db": lambda r: r["view_psnr"],
    "time_psnr_db": lambda r: r["time_psnr"],
    "median_rel_err_pct": lambda r: 100 * r["median_rel_err"],
    "parts_trusted": lambda r: int(r["trusted"]),
    "parts_frozen": lambda r: int(r["frozen"]),
    "k_heldout": lambda r: r["k_heldout"],
    "k_bic": lambda r: r["k_bic"],
}


def tab_kselect(
    per_seed: Mapping[int, Mapping[tuple[str, str, str], dict]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    method: str,
    models: Sequence[str] = (PAPER_MODEL,),
    digits: int = 2,
) -> Table:
    """One LaTeX row per tree, prior and configuration (fixed, then chosen K).

    Args:
        per_seed: ``per_seed[seed][(tree, model, config)]`` with config ``single`` or
            ``auto``: K, view_psnr and time_psnr (dB), median_rel_err (fraction), trusted,
            frozen, k_heldout, k_bic (of the model's selection), train_s (seconds of the
            model's training), and for ``auto`` select_s (seconds of the selection's runs).
        trees: the tree names, in row order.
        bones: tree -> bone count (its label).
        method: the criterion that chose K (``models.kselect.method``).
        models: the priors, in row order (ours first).
        digits: decimals of the PSNR and error cells.

    Returns:
        The table: K as each seed chose it (slash-separated when the seeds disagree), the
            rest mean +- sd over seeds; the CSV also holds each seed's cost against the fixed
            K, ``cost_x`` = (train_s + select_s) / train_s of the fixed-K row.
    """
    keys = [(t, m, c) for t in trees for m in models for c in ROWS]
    seeds = seeds_of(per_seed, "tab_kselect", keys)

    def one(s, t, m, c):
        r = per_seed[s][(t, m, c)]
        select_s = float(r["select_s"]) if c == "auto" else np.nan
        fixed_s = float(per_seed[s][(t, m, "single")]["train_s"])
        about = {"tree": t, "bones": bones[t], "model": m, "config": c, "K": int(r["K"])}
        cost = (float(r["train_s"]) + select_s) / fixed_s if c == "auto" else np.nan
        timing = {"train_s": float(r["train_s"]), "select_s": select_s, "cost_x": cost}
        return about | {k: f(r) for k, f in VALUES.items()} | timing

    df = seed_rows(seeds, keys, one)
    first = latex.rows(df)
    col, fmt = partial(latex.cells, df), f".{digits}f"
    # K as each seed chose it; the rest mean +- sd
    ks = ["/".join(str(k) for k in dict.fromkeys(v.astype(int))) for v in latex.by_seed(df, "K").T]
    trusted = col("parts_trusted", ".3g")
    labels = [f"{spec_of(m).short}, {ROWS[c]}" for m, c in zip(first["model"], first["config"])]
    cells = pd.DataFrame(
        {
            "$K$": ks,
            "PSNR views": col("view_psnr_db", fmt),
            "PSNR time": col("time_psnr_db", fmt),
            r"Med.\ rel.\ err.": col("median_rel_err_pct", fmt, r"\%"),
            "Trusted": [f"{n}/{k}" for n, k in zip(trusted, ks)],
            "Frozen": col("parts_frozen", ".3g"),
            "Train (s)": col("train_s", ".0f"),
            "Select (s)": col("select_s", ".0f"),
            "Cost": col("cost_x", ".2g", r"$\times$"),
        },
        index=tree_index(first, labels, "Model"),
    )
    cap = caption("tab_kselect", method=method) + latex.seed_note(len(seeds), decides=False)
    cap += r" $K$: as each seed chose it."
    return Table("tab_kselect", df, latex.render(cells, cap, "tab:kselect"))


# ---- the declaration -----------------------------------------------------------------------
def _selection_need(t: str, m: str, s: int) -> tuple:
    """The need of prior ``m``'s K selection on tree ``t`` (ours' has its own kind)."""
    return ("kselect", t, s) if m == BASE_MODEL else ("prior_kselect", t, m, s)


def _kselect_needs(plan, seeds):
    """Per seed, tree and prior: its K selection, and the evaluation, recovery and loss log
    of its fixed-K and chosen-K models."""
    out = []
    for s, t, m in product(seeds, plan.trees, [BASE_MODEL, *plan.kselect_priors]):
        out.append(_selection_need(t, m, s))
        out += [(k, t, m, c, s) for c in ROWS for k in ("eval", "recovery", "loss")]
    return out


def _tab_kselect(path, settings, inputs, out):
    rows = {s: {} for s in settings["seeds"]}
    for s, t, m in product(rows, settings["trees"], settings["models"]):
        sel = load_selection(path(*_selection_need(t, m, s)))
        for c in ROWS:
            ev = load_eval(path("eval", t, m, c, s)).summary()
            rec = load_recovery(path("recovery", t, m, c, s))
            loss = pd.read_csv(path("loss", t, m, c, s))
            rows[s][(t, m, c)] = {
                "K": rec.match.n_parts,
                "view_psnr": ev["view"],
                "time_psnr": ev["time"],
                "median_rel_err": rec.match.median_rel_err,
                "trusted": rec.match.n_trusted,
                "frozen": rec.n_frozen,
                "k_heldout": sel.k_heldout,
                "k_bic": sel.k_bic,
                "train_s": float(loss["seconds"].iloc[-1]),
                "select_s": float(sum(sel.wall_s)),
            }
    trees, bones, method = settings["trees"], settings["bones"], settings["method"]
    models, digits = settings["models"], settings["digits"]
    return tab_kselect(rows, trees, bones, method, models=models, digits=digits)


TAB_KSELECT = Output(
    "tab_kselect",
    "table",
    _kselect_needs,
    _tab_kselect,
    settings=lambda cfg: {
        "method": cfg["models"]["kselect"]["method"],
        "models": list(selected_models(cfg["models"]["kselect"])),
    },
    in_report=lambda plan: False,  # `all` builds it (Snakefile): K selection costs trainings
    columns=Columns(
        keys=("seed", "tree", "model", "config"),
        values=tuple(VALUES),
        timing=("train_s", "select_s", "cost_x"),
        about=("bones", "K"),
    ),
)
