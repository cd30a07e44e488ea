"""The ledger's headline claims repeated for a prior other than the paper's: the
chained prior, or any model of role "prior" the registry adds.

The paper's claims about ours ([`physgs.report.claims.measure`][]) decide its story; each is asked
again of the other prior, on the same tables and thresholds, with ids ``<model>/<claim>/...``:
above the static pose beyond the window; ahead of the best learned field on every split
(views, beyond the window, and each unseen wind at training timestamps and beyond); its margin
against MLP + wind growing with departure; beating the untrained null on recovery by
``NULL_MATCH_PP`` points or more (joint K=32, each tree); damping recovered within
``DAMPING_OFF``, and the decay rate's exponent. A value whose row a table lacks (a run made
before the prior joined it) is NaN: "undecided: not measured".
"""

from __future__ import annotations

from typing import Callable, Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.models.registry import label, models_of
from physgs.report.claims import (
    DAMPING_OFF,
    NULL_MATCH_PP,
    RATE_EXPONENT,
    Claim,
    _per_seed,
    damping_offsets,
)
from physgs.report.claims import _cell as _value

#: the claim family counted by the summary's line (physgs.report.summary.prior_line)
AHEAD = "ahead_of_fields"


def _psnr(d: pd.DataFrame, tree: str, model: str, split: str) -> float:
    return _value(d, d["model"] == label(model), f"{tree}_{split}")


def _col(d: pd.DataFrame, mask, model: str) -> float:
    return _value(d, mask, model) if model in d.columns else float("nan")


def prior_claims(
    model: str,
    tables: Mapping[str, pd.DataFrame],
    damping: Mapping[str, Sequence[Mapping[str, float]]],
    trees: Sequence[str],
    config: str = "joint32",
) -> list[tuple[Claim, list[float]]]:
    """The headline claims for ``model`` with their per-seed values.

    Args:
        model: a prior's id.
        tables: the tables' CSVs (tab_psnr, tab_transfer, tab_margin, tab_null; a table not given
            leaves its claims unmeasured).
        damping: tree -> per-seed {median_zeta, zeta_true, loglog_exponent} of ``model``'s
            recovery in ``config`` (trees without it are skipped).
        trees: the trees.
        config: the configuration of the recovery claims (the ledger's).

    Returns:
        ``(claim, per-seed values)`` pairs, ids prefixed by the model's.
    """
    name = label(model)
    out: list[tuple[Claim, list[float]]] = []

    def add(claim: Claim, table: str, fn: Callable[[pd.DataFrame], float]):
        vals = [fn(d) for d in _per_seed(tables[table])] if table in tables else []
        out.append((claim, vals))

    def ahead(cid, text, source, table, fn):
        add(Claim(f"{model}/{AHEAD}/{cid}", text, "--", source, 0.0, ">", "dB"), table, fn)

    for t in trees:
        add(
            Claim(
                f"{model}/above_static_beyond/{t}",
                f"{t}: the {name} is above the static pose beyond the window",
                "--",
                "tab_psnr, time column: prior - static",
                0.0,
                ">",
                "dB",
            ),
            "tab_psnr",
            lambda d, t=t: _psnr(d, t, model, "time") - _psnr(d, t, "static", "time"),
        )
        for split, where in (("view", "held-out views"), ("time", "beyond the window")):
            ahead(
                f"{t}/{split}",
                f"{t}: the {name} is ahead of the best learned field on {where}",
                f"tab_psnr, {split} column: prior - max over learned fields",
                "tab_psnr",
                lambda d, t=t, sp=split: (
                    _psnr(d, t, model, sp) - max(_psnr(d, t, m, sp) for m in models_of("field"))
                ),
            )

    tr = tables.get("tab_transfer")  # its per-wind rows exist only with the table
    if tr is not None:
        for (sp, t, c), _ in tr.groupby(["split", "tree", "condition"], sort=False):

            def cell(d, sp=sp, t=t, c=c):
                return (d["split"] == sp) & (d["tree"] == t) & np.isclose(d["condition"], c)

            where = "beyond the window" if sp == "beyond" else "at training timestamps"
            ahead(
                f"{t}/wind_{sp}/{c:.2f}",
                f"{t}, {c:.2f} v0, {where}: the {name} is ahead of the best learned field",
                f"tab_transfer ({sp}): prior - max learned",
                "tab_transfer",
                lambda d, cell=cell: (
                    _col(d, cell(d), model) - max(_col(d, cell(d), m) for m in models_of("field"))
                ),
            )

    mg = tables.get("tab_margin")
    cols = (
        [c for c in mg.columns if c.startswith("margin_")] if mg is not None else ["first", "last"]
    )
    for t in trees:

        def margin(d, t=t):
            mine = (d["tree"] == t) & (d.get("model", pd.Series(index=d.index)) == model)
            return _value(d, mine, cols[-1]) - _value(d, mine, cols[0])

        add(
            Claim(
                f"{model}/margin_grows/{t}",
                f"{t}: the {name}'s margin against MLP + wind grows as the wind departs",
                "--",
                f"tab_margin ({model}): {cols[-1]} - {cols[0]}",
                0.0,
                ">",
                "dB",
            ),
            "tab_margin",
            margin,
        )

    for t in trees:

        def beats(d, t=t):
            mine = (
                (d.get("method", pd.Series(index=d.index)) == model)
                & (d["tree"] == t)
                & (d["config"] == config)
            )
            return _value(d, mine, "trained_median_rel_err_pct") - _value(
                d, mine, "null_median_rel_err_pct"
            )

        add(
            Claim(
                f"{model}/beats_null/{t}",
                f"{t}: the {name} beats the untrained null on frequency recovery (by "
                f"{NULL_MATCH_PP} points or more)",
                "--",
                f"tab_null, {config}: trained - null median rel. error (points)",
                -NULL_MATCH_PP,
                "<",
                "points",
            ),
            "tab_null",
            beats,
        )

    for t in trees:
        dmp = damping.get(t)
        if dmp is None:
            continue
        out.append(
            (
                Claim(
                    f"{model}/damping_recovered/{t}",
                    f"{t}: the {name} recovers damping (median zeta_hat within "
                    f"{DAMPING_OFF:.0%} of the truth)",
                    "--",
                    f"recovery ({config}): |median zeta_hat - zeta| / zeta",
                    DAMPING_OFF,
                    "<",
                    "fraction",
                ),
                damping_offsets(dmp),
            )
        )
        out.append(
            (
                Claim(
                    f"{model}/decay_rate_flat/{t}",
                    f"{t}: the {name}'s fitted decay rate gamma = zeta*omega is nearly "
                    f"frequency-independent (gamma ~ omega^p, p < {RATE_EXPONENT})",
                    "--",
                    f"recovery ({config}): exponent p",
                    RATE_EXPONENT,
                    "<",
                    "exponent",
                ),
                [v["loglog_exponent"] for v in dmp],
            )
        )
    return out
