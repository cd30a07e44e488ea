"""tab_kselect: each prior with fixed K (`single`) beside the same prior with K chosen from the
data (`auto`): ours, and every prior under ``models.kselect.priors`` (the chained prior).

Built by ``physgs.report.build.make_table('tab_kselect', ...)`` from each tree's K selections
and the evaluation, recovery and loss log of ``<prior>_single`` and ``<prior>_auto``.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.models.registry import spec_of
from physgs.report import latex
from physgs.report.tables import Table, _seeds, _tree_index

ROWS = (("single", "fixed $K$"), ("auto", "chosen $K$"))


def row_label(model: str, config: str) -> str:
    """A row's LaTeX label: the registry's short name and the row kind.

    Args:
        model: the prior's registry id.
        config: the row kind (``single``: fixed K, ``auto``: chosen K).

    Returns:
        'Ours, fixed $K$' / 'Chained, chosen $K$'.
    """
    return f"{spec_of(model).short}, {dict(ROWS)[config]}"


def cost_ratio(train_s: float, select_s: float, fixed_train_s: float) -> float:
    """What K from the data costs against the fixed K.

    Args:
        train_s: training of the chosen-K model, s.
        select_s: the selection's runs, s.
        fixed_train_s: training of the fixed-K model, s.

    Returns:
        (train_s + select_s) / fixed_train_s.
    """
    return (train_s + select_s) / fixed_train_s


def tab_kselect(
    per_seed: Mapping[int, Mapping[tuple[str, str, str], dict]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    method: str,
    models: Sequence[str] = ("ours",),
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
    keys = [(t, m, c) for t in trees for m in models for c, _ in ROWS]
    seeds = _seeds(per_seed, "tab_kselect", keys)
    recs = []
    for s in seeds:
        for t in trees:
            for m in models:
                fixed_s = float(per_seed[s][(t, m, "single")]["train_s"])
                for c, _ in ROWS:
                    r = per_seed[s][(t, m, c)]
                    select_s = float(r["select_s"]) if c == "auto" else np.nan
                    recs.append(
                        {
                            "seed": s,
                            "tree": t,
                            "bones": bones[t],
                            "model": m,
                            "config": c,
                            "K": int(r["K"]),
                            "view_psnr_db": r["view_psnr"],
                            "time_psnr_db": r["time_psnr"],
                            "median_rel_err_pct": 100 * r["median_rel_err"],
                            "parts_trusted": int(r["trusted"]),
                            "parts_frozen": int(r["frozen"]),
                            "k_heldout": r["k_heldout"],
                            "k_bic": r["k_bic"],
                            "train_s": float(r["train_s"]),
                            "select_s": select_s,
                            "cost_x": cost_ratio(float(r["train_s"]), select_s, fixed_s)
                            if c == "auto"
                            else np.nan,
                        }
                    )
    df = pd.DataFrame(recs)
    first = latex.rows(df)
    fmt = f".{digits}f"
    # K as each seed chose it; the rest mean +- sd
    ks = ["/".join(str(k) for k in dict.fromkeys(v.astype(int))) for v in latex.by_seed(df, "K").T]
    trusted = latex.cells(df, "parts_trusted", ".3g")
    labels = [row_label(m, c) for m, c in zip(first["model"], first["config"])]
    cells = pd.DataFrame(
        {
            "$K$": ks,
            "PSNR views": latex.cells(df, "view_psnr_db", fmt),
            "PSNR time": latex.cells(df, "time_psnr_db", fmt),
            r"Med.\ rel.\ err.": latex.cells(df, "median_rel_err_pct", fmt, r"\%"),
            "Trusted": [f"{n}/{k}" for n, k in zip(trusted, ks)],
            "Frozen": latex.cells(df, "parts_frozen", ".3g"),
            "Train (s)": latex.cells(df, "train_s", ".0f"),
            "Select (s)": latex.cells(df, "select_s", ".0f"),
            "Cost": latex.cells(df, "cost_x", ".2g", r"$\times$"),
        },
        index=_tree_index(first, labels, "Model"),
    )
    cap = (
        rf"Each prior with fixed $K$ against $K$ chosen from the data (method: {method}, on "
        r"held-out training-window frames; the CSV also lists the choice by held-out frames and "
        r"by BIC). PSNR (dB) on the held-out views and on the time split (beyond the window); "
        r"median relative frequency error over trusted parts; Frozen: parts whose swing stayed "
        r"under a pixel. Train: seconds of the model's training; Select: seconds of the "
        r"selection's short runs; Cost: (train + select) over the fixed-$K$ training."
        + latex.seed_note(len(seeds), decides=False)
        + r" $K$: as each seed chose it."
    )
    return Table("tab_kselect", df, latex.render(cells, cap, "tab:kselect"))
