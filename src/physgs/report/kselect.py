"""tab_kselect: ours with fixed K (`single`) beside ours with K chosen from the data (`auto`).

Built by ``physgs.report.build.make_table('tab_kselect', ...)`` from each tree's K selection
and the evaluation and recovery of ``ours_single`` and ``ours_auto``.
"""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.report import seeds as seedstats
from physgs.report.tables import Table, _by_seed, _first, _seeds, _tree_blocks, _wrap

ROWS = (("single", "fixed $K$"), ("auto", "chosen $K$"))


def tab_kselect(
    per_seed: Mapping[int, Mapping[tuple[str, str], dict]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    method: str,
    digits: int = 2,
) -> Table:
    """The K selection per tree and configuration.

    One LaTeX row per tree and configuration: K as chosen by each seed (slash-separated when the
    seeds disagree), the rest mean +- sd over seeds.

    Args:
        per_seed: ``per_seed[seed][(tree, config)]``: K, time_psnr (dB), median_rel_err
            (fraction), trusted, frozen, k_heldout, k_bic.
        trees: the trees.
        bones: tree -> its bone count.
        method: the selection method used (``models.kselect.method``).
        digits: decimals shown in the .tex.

    Returns:
        The [`Table`][physgs.report.tables.Table].
    """
    seeds = _seeds(per_seed, "tab_kselect")
    recs = []
    for s in seeds:
        for t in trees:
            for c, _ in ROWS:
                r = per_seed[s][(t, c)]
                recs.append(
                    {
                        "seed": s,
                        "tree": t,
                        "bones": bones[t],
                        "config": c,
                        "K": int(r["K"]),
                        "time_psnr_db": r["time_psnr"],
                        "median_rel_err_pct": 100 * r["median_rel_err"],
                        "parts_trusted": int(r["trusted"]),
                        "parts_frozen": int(r["frozen"]),
                        "k_heldout": r["k_heldout"],
                        "k_bic": r["k_bic"],
                    }
                )
    df = pd.DataFrame(recs)
    first = _first(df)
    first["_i"] = np.arange(len(first))
    V = {
        c: _by_seed(df, c, len(seeds))
        for c in ("K", "time_psnr_db", "median_rel_err_pct", "parts_trusted", "parts_frozen")
    }
    fmt = f".{digits}f"

    def cells(r):
        i = r._i
        ks = "/".join(str(k) for k in dict.fromkeys(V["K"][:, i].astype(int)))
        err = seedstats.pm(V["median_rel_err_pct"][:, i], fmt)
        return [
            dict(ROWS)[r.config],
            ks,
            seedstats.pm(V["time_psnr_db"][:, i], fmt),
            err if err == "--" else err + r"\%",
            f"{seedstats.pm(V['parts_trusted'][:, i], '.3g')}/{ks}",
            seedstats.pm(V["parts_frozen"][:, i], ".3g"),
        ]

    lines = [
        "  \\begin{tabular}{llccccc}",
        "    \\toprule",
        r"    Tree & Model & $K$ & PSNR time & Med.\ rel.\ err. & Trusted & Frozen \\",
        "    \\midrule",
    ]
    lines += _tree_blocks(first, trees, cells)
    lines += ["    \\bottomrule", "  \\end{tabular}", ""]
    cap = (
        rf"Ours with fixed $K$ against $K$ chosen from the data (method: {method}; the "
        r"CSV also lists the choice by held-out frames and by BIC). PSNR (dB) on the time split; "
        r"median relative frequency error over trusted parts; Frozen: parts whose swing stayed "
        r"under a pixel."
        + (
            rf" Mean $\pm$ sd over {len(seeds)} training seeds; $K$ as each "
            r"seed chose it."
            if len(seeds) > 1
            else " One training seed."
        )
    )
    return Table("tab_kselect", df, _wrap("\n".join(lines), cap, "tab:kselect"))
