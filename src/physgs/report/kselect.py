"""tab_kselect: ours with fixed K (`single`) beside ours with K chosen from the data (`auto`).

Built by ``physgs.report.build.make_table('tab_kselect', ...)`` from each tree's K selection
and the evaluation and recovery of ``ours_single`` and ``ours_auto``.
"""
from __future__ import annotations

from typing import Mapping, Sequence

import pandas as pd

from physgs.report.tables import Table, _fmt, _pct, _tree_blocks, _wrap

ROWS = (("single", "fixed $K$"), ("auto", "chosen $K$"))


def tab_kselect(rows: Mapping[tuple[str, str], dict], trees: Sequence[str],
                bones: Mapping[str, int], method: str, digits: int = 2) -> Table:
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
    lines += _tree_blocks(df, trees, lambda r: [
        dict(ROWS)[r.config], str(r.K), _fmt(r.time_psnr_db, f".{digits}f"),
        _pct(r.median_rel_err_pct, False, digits), f"{r.parts_trusted}/{r.K}",
        str(r.parts_frozen)])
    lines += ["    \\bottomrule", "  \\end{tabular}", ""]
    cap = (rf"Ours with fixed $K$ against $K$ chosen from the data (method: {method}; the "
           r"CSV also lists the choice by held-out frames and by BIC). PSNR (dB) on the time split; "
           r"median relative frequency error over trusted parts; Frozen: parts whose swing stayed "
           r"under a pixel.")
    return Table("tab_kselect", df, _wrap("\n".join(lines), cap, "tab:kselect"))
