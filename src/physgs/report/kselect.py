"""tab_kselect: ours with fixed K = 32 (`single`) beside ours with K chosen from the data (`auto`).

Inputs per tree: the K selection JSON (``KSELECT``), the evaluation and recovery files of
``ours_single`` and ``ours_auto`` (templates of physgs.report.build).
"""
from __future__ import annotations

from typing import Mapping, Sequence

import pandas as pd

from physgs.evaluate.splits import load_eval
from physgs.models.kselect import load_selection
from physgs.recovery.record import load_recovery
from physgs.report.build import EVAL, RECOVERY
from physgs.report.tables import Table, _fmt, _pct, _wrap, tree_label, write_table

KSELECT = "results/kselect/{tree}.json"
ROWS = (("single", "fixed $K{=}32$"), ("auto", "chosen $K$"))


def inputs(trees: Sequence[str]) -> list[str]:
    """Every file tab_kselect reads (what its rule declares)."""
    files = [KSELECT.format(tree=t) for t in trees]
    for t in trees:
        for c, _ in ROWS:
            files += [EVAL.format(tree=t, model="ours", config=c),
                      RECOVERY.format(tree=t, config=c)]
    return files


def tab_kselect(rows: Mapping[tuple[str, str], dict], trees: Sequence[str],
                bones: Mapping[str, int], method: str) -> Table:
    """rows[(tree, config)]: K, time_psnr (dB), median_rel_err (fraction), trusted, frozen,
    k_heldout, k_bic. One LaTeX row per tree and configuration."""
    recs = []
    for t in trees:
        for c, _ in ROWS:
            r = rows[(t, c)]
            recs.append({"tree": t, "bones": bones[t], "config": c, "K": int(r["K"]),
                         "time_psnr_db": r["time_psnr"],
                         "median_rel_err_pct": 100 * r["median_rel_err"],
                         "parts_trusted": int(r["trusted"]), "parts_frozen": int(r["frozen"]),
                         "k_heldout": r["k_heldout"], "k_bic": r["k_bic"]})
    df = pd.DataFrame(recs)
    lines = ["  \\begin{tabular}{llccccc}", "    \\toprule",
             r"    Tree & Model & $K$ & PSNR time & Med.\ rel.\ err. & Trusted & Frozen \\",
             "    \\midrule"]
    for i, t in enumerate(trees):
        sub = df[df.tree == t]
        for j, (_, r) in enumerate(sub.iterrows()):
            head = rf"\multirow{{2}}{{*}}{{{tree_label(t, r.bones)}}}" if j == 0 else ""
            label = dict(ROWS)[r.config]
            lines.append("    " + " & ".join([
                head, label, str(r.K), _fmt(r.time_psnr_db, ".2f"),
                _pct(r.median_rel_err_pct, False), f"{r.parts_trusted}/{r.K}",
                str(r.parts_frozen)]) + r" \\")
        if i < len(trees) - 1:
            lines.append("    \\midrule")
    lines += ["    \\bottomrule", "  \\end{tabular}", ""]
    cap = (rf"Ours with fixed $K=32$ against $K$ chosen from the data (method: {method}; the "
           r"CSV also lists the choice by held-out frames and by BIC). PSNR (dB) on the time split; "
           r"median relative frequency error over trusted parts; Frozen: parts whose swing stayed "
           r"under a pixel.")
    return Table("tab_kselect", df, _wrap("\n".join(lines), cap, "tab:kselect"))


def make_tab_kselect(cfg: dict, tex_path, csv_path) -> Table:
    """Read every tree's files (see ``inputs``) and write tab_kselect's .tex and .csv."""
    trees = cfg["trees"]
    rows = {}
    for t in trees:
        sel = load_selection(KSELECT.format(tree=t))
        for c, _ in ROWS:
            ev = load_eval(EVAL.format(tree=t, model="ours", config=c)).summary()
            rec = load_recovery(RECOVERY.format(tree=t, config=c))
            rows[(t, c)] = {"K": rec.match.n_parts, "time_psnr": ev["time"],
                            "median_rel_err": rec.match.median_rel_err,
                            "trusted": rec.match.n_trusted, "frozen": rec.n_frozen,
                            "k_heldout": sel.k_heldout, "k_bic": sel.k_bic}
    bones = {t: int(cfg["presets"][t]["bones"]) for t in trees}
    table = tab_kselect(rows, trees, bones, cfg["models"]["kselect"]["method"])
    write_table(table, tex_path, csv_path)
    return table
