"""The claims ledger: each quantitative claim of the source paper, measured, with a verdict
computed by code (never written by hand).

A claim is a measured quantity (one value per training seed: a table without a ``seed`` column
gives one), a threshold and a side. It **holds** when the 95% interval of the mean over seeds
lies entirely on the claimed side of the threshold, **fails** when it lies entirely on the other
side, and is **undecided** when it straddles it. A claim of flatness, equality or match (side
``WITHIN``) is an equivalence test, two one-sided tests: it **holds** inside the band
(-threshold, +threshold), **fails** wholly outside it, and is **undecided** across either edge.
A comparison between trained models needs seed variance: with one seed it is "undecided: one
seed" (with the side its point estimate falls on); a claim about the fixed testbed needs none.

Which claims there are, what each reads and its threshold: the catalogue
([`physgs.report.catalogue`][physgs.report.catalogue]); this module measures them and decides.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.models.registry import PAPER_MODEL, label, models_of
from physgs.report.catalogue import CATALOGUE, KINDS, WITHIN, kind_of, origin_of, undermines
from physgs.report.claim_cells import RECOVERY, Run
from physgs.report.prose import say
from physgs.report.seeds import MAX_SEEDS, finite, interval, log_interval, seeds_to_decide

#: The unit of a ratio: its interval is taken on the log scale (``estimate``).
RATIO = "ratio"


@dataclass(frozen=True)
class Claim:
    """One claim: id, the claim in one line, the paper's figure, where it is measured, the
    threshold and side ('>', '<', or ``WITHIN``: inside (-threshold, +threshold)), the unit,
    whether a verdict needs seed variance, its origin (the paper's or this project's), the
    paper's figure in the claim's unit and the companion that must hold too."""

    id: str
    text: str
    paper: str
    source: str
    threshold: float
    side: str
    unit: str
    needs_variance: bool = True
    origin: str = "paper"
    paper_value: tuple[float, float] = (float("nan"), float("nan"))
    requires: str = ""

    @property
    def log_scale(self) -> bool:
        """Whether its interval is taken on the log scale: a ratio's (unit ``RATIO``)."""
        return self.unit == RATIO

    @property
    def threshold_text(self) -> str:
        """The threshold and side as the ledger prints them: ``> 0``, ``within ±0.5``."""
        if self.side == WITHIN:
            return f"within ±{self.threshold:g}"
        return f"{self.side} {self.threshold:g}"


def estimate(claim: Claim, values: Sequence[float]) -> tuple[float, float, float, float]:
    """(estimate, sd, low, high) of a claim over seeds: Student's t on the mean
    ([`interval`][physgs.report.seeds.interval]); for a ratio, on the mean of the per-seed
    log-ratios, exponentiated ([`log_interval`][physgs.report.seeds.log_interval]).

    Args:
        claim: the claim (its unit).
        values: its per-seed values.

    Returns:
        ``(estimate, sd, low, high)``.
    """
    return log_interval(values) if claim.log_scale else interval(values)


def verdict(claim: Claim, values: Sequence[float]) -> str:
    """'holds', 'fails', 'undecided' or 'undecided: one seed' (see the module docstring).

    Args:
        claim: the claim (threshold, side, whether it needs seed variance).
        values: its per-seed values (NaN: not measured for that seed).

    Returns:
        The verdict, as [`decide`][physgs.report.claims.decide]'s.
    """
    m, _, lo, hi = estimate(claim, values)
    return decide(claim, m, lo, hi, len(finite(values)))


def on_claim(claim: Claim, x: float) -> bool:
    """Whether a value lies on the claimed side of the threshold (inside the band for WITHIN).

    Args:
        claim: the claim (threshold, side).
        x: a value in the claim's unit.

    Returns:
        True on the claim's side; False against it (and for NaN).
    """
    t = claim.threshold
    if claim.side == WITHIN:
        return bool(-t < x < t)
    return bool(x > t if claim.side == ">" else x < t)


def decide(claim: Claim, m: float, lo: float, hi: float, n: int) -> str:
    """The verdict of an estimate and its 95% interval (e.g. a committed record's ``measured``,
    ``ci_low``, ``ci_high`` and ``seeds``).

    Args:
        claim: the claim (threshold, side, whether it needs seed variance).
        m: the estimate.
        lo: the interval's low end.
        hi: its high end.
        n: the seeds measured.

    Returns:
        The verdict; ``'undecided: not measured'`` without a finite estimate, and the one-seed
            verdict says on which side the point estimate lies.
    """
    on = partial(on_claim, claim)
    if not np.isfinite(m):
        return "undecided: not measured"
    if not claim.needs_variance:
        return "holds" if on(m) else "fails"
    if n < 2:
        return f"undecided: one seed (point estimate {'on' if on(m) else 'against'} the claim)"
    if on(lo) and on(hi):
        return "holds"
    if claim.side == WITHIN:  # outside the band: wholly beyond one edge
        return "fails" if hi <= -claim.threshold or lo >= claim.threshold else "undecided"
    return "fails" if not on(lo) and not on(hi) else "undecided"


def _per_seed(df: pd.DataFrame) -> list[pd.DataFrame]:
    return [g for _, g in df.groupby("seed")] if "seed" in df.columns else [df]


def _holds(tables: Mapping[str, pd.DataFrame], model: str) -> bool:
    """Whether a table of a family asked of the priors has a row or column of ``model``."""
    names = {s.table for s in CATALOGUE if s.of == "priors" and s.table in tables} - {RECOVERY}
    return any(
        model in df.columns
        or any(c in df.columns and (df[c].astype(str) == model).any() for c in ("model", "method"))
        for df in map(tables.get, names)
    )


def measure(
    tables: Mapping[str, pd.DataFrame],
    damping: Mapping[str, Sequence[Mapping[str, float]]],
    trees: Sequence[str],
    prior_damping: Mapping[str, Mapping[str, Sequence[Mapping[str, float]]]] | None = None,
    roles: Mapping[str, Mapping[str, str]] | None = None,
) -> list[tuple[Claim, list[float]]]:
    """Every claim of the catalogue with its per-seed values, from the tables' CSVs and the
    priors' damping summaries.

    A claim whose table is missing is listed with no values ("undecided: not measured"), except
    where its cells come from the table itself and in the optional families
    (``ClaimSpec.optional``). The families asked of the priors are asked of every prior of the
    registry other than ours that the run's tables hold.

    Args:
        tables: table name -> its CSV (``catalogue.tables()``).
        damping: tree -> ours' per-seed damping summaries (median_zeta, loglog_exponent,
            zeta_true), for the joint K=32 configuration.
        trees: the trees.
        prior_damping: model -> tree -> per-seed summaries, as ``damping``, of the other priors.
        roles: tree -> its preset's role (``claim_cells.roles_of``); None or a tree left out: no
            role, so none of the role-scoped claims and no paper figure for it.

    Returns:
        ``(claim, per-seed values)`` pairs, in the ledger's order (the catalogue's).
    """
    tabs = dict(tables)
    summaries = {PAPER_MODEL: damping, **(prior_damping or {})}
    rec = [
        {"seed": i, "model": m, "tree": t, **summary}  # seed: the summary's place in its list
        for m, by_tree in summaries.items()
        for t, per_seed in by_tree.items()
        for i, summary in enumerate(per_seed)
    ]
    if rec:
        tabs[RECOVERY] = pd.DataFrame(rec)
    others = tuple(m for m in models_of("prior") if m != PAPER_MODEL and _holds(tables, m))
    out: list[tuple[Claim, list[float]]] = []
    for spec in CATALOGUE:
        if spec.optional and spec.table not in tabs:
            continue
        seeds = _per_seed(tabs[spec.table]) if spec.table in tabs else []
        for model in (PAPER_MODEL,) if spec.of == "ours" else others:
            run = Run(tabs, trees, model, others, spec.table, dict(roles or {}))
            for cell in spec.over(run):
                cell = {"model": model, "name": label(model), "table": spec.table, **cell}
                claim = Claim(**spec.claim_of(cell))
                out.append((claim, [float(spec.read(d, cell)) for d in seeds]))
    return out


def first_seed(
    tables: Mapping[str, pd.DataFrame],
    trees: Sequence[str],
    roles: Mapping[str, Mapping[str, str]] | None = None,
) -> dict[str, tuple[Claim, float]]:
    """Each claim on the run's first seed alone: with ``testbed_seeds``, the instance built with
    the first testbed seed, the one tree of the paper's protocol (a rerun sets it beside a
    one-instance record: did the other instances move a verdict, or did that tree move too?).

    Claims over the priors' damping summaries (not in the tables) are left out.

    Args:
        tables: table name -> its CSV, every seed (``measure``'s).
        trees: the trees.
        roles: tree -> its preset's role, as ``measure``'s.

    Returns:
        claim id -> (the claim, its value on the first seed; NaN where not measured).
    """
    first = {
        n: df[df["seed"] == df["seed"].min()] if "seed" in df.columns else df
        for n, df in tables.items()
    }
    return {
        c.id: (c, float(v[0]) if len(v) else float("nan"))
        for c, v in measure(first, {}, trees, roles=roles)
    }


def to_decide(claim: Claim, values: Sequence[float]) -> tuple[float, float]:
    """The seeds that would decide an undecided claim at its observed effect and sd, two
    estimates ([`seeds_to_decide`][physgs.report.seeds.seeds_to_decide]); on the log scale for a
    ratio.

    Args:
        claim: the claim.
        values: its per-seed values.

    Returns:
        ``(plug-in n, power n)``; NaN for a claim that is decided, or has fewer than two seeds.
    """
    if verdict(claim, values) != "undecided":
        return np.nan, np.nan
    v = finite(values)
    v, thr = (np.log(v), np.log(claim.threshold)) if claim.log_scale else (v, claim.threshold)
    m = float(v.mean())
    if claim.side == WITHIN:  # the interval straddles an edge: the nearer one decides it
        thr = min((-thr, thr), key=lambda e: abs(m - e))
    return seeds_to_decide(m - thr, float(v.std(ddof=1)))


def paper_in_interval(claim: Claim, low: float, high: float) -> str:
    """Whether the paper's figure (a range: whether it meets it) lies inside the measured 95%
    interval: the claim reproduced in size, beside its verdict.

    Args:
        claim: the claim (``paper_value``, in its unit).
        low: the interval's low end.
        high: its high end.

    Returns:
        ``"inside"`` or ``"outside"``; ``""`` where the paper gives no number or there is no
            interval.
    """
    p_lo, p_hi = claim.paper_value
    if not (np.isfinite(p_lo) and np.isfinite(low) and np.isfinite(high)):
        return ""
    return "inside" if p_lo <= high and p_hi >= low else "outside"


def _gated(claim: Claim, own: str, verdicts: Mapping[str, str]) -> str:
    """``own``, unless it holds and its companion (``Claim.requires``) does not: then "fails:
    ..." or "undecided: ...", naming the companion's verdict."""
    comp = verdicts.get(claim.requires, "undecided: not measured")
    kind = comp.split(":")[0]
    if not claim.requires or own != "holds" or kind == "holds":
        return own
    return f"{'fails' if kind == 'fails' else 'undecided'}: covers, but {claim.requires} {comp}"


def ledger(measured: Sequence[tuple[Claim, list[float]]]) -> pd.DataFrame:
    """One row per claim: the claim, the paper's figure, the measured mean (a ratio's geometric
    mean), sd (a ratio's: of its logs), 95% interval and seeds, the threshold, the verdict (one
    that holds only if its companion ``requires`` holds too), its source, origin and kind
    (``catalogue.kind_of``), for an undecided claim the seeds that would decide it
    (``to_decide``); last (added later: older readers keep their columns), the paper's figure as
    a number, whether it lies inside the interval, and the companion.

    Args:
        measured: [`measure`][physgs.report.claims.measure]'s pairs.

    Returns:
        The ledger, one row per claim.
    """
    own = [verdict(c, values) for c, values in measured]
    alone = {c.id: v for (c, _), v in zip(measured, own)}  # the companions' (``requires``)
    rows = []
    for (c, values), v in zip(measured, own):
        m, sd, lo, hi = estimate(c, values)
        n_t, n_power = to_decide(c, values)
        rows.append(dict(
            id=c.id, claim=c.text, paper=c.paper, measured=m, sd=sd, ci_low=lo, ci_high=hi,
            seeds=int(np.isfinite(values).sum()), unit=c.unit, threshold=c.threshold_text,
            verdict=_gated(c, v, alone), source=c.source, origin=c.origin, kind=kind_of(c.id),
            scale="log" if c.log_scale else "linear", seeds_to_decide_t_est=n_t,
            seeds_to_decide_power80_est=n_power, paper_low=c.paper_value[0],
            paper_high=c.paper_value[1], paper_in_interval=paper_in_interval(c, lo, hi),
            requires=c.requires,
        ))  # fmt: skip
    return pd.DataFrame(rows)


def column(claims: pd.DataFrame, name: str) -> pd.Series:
    """A catalogue-derived column of the ledger (``origin``, ``kind``): as written, or the
    catalogue's word for each id of a ledger written before the column.

    Args:
        claims: the ledger (``claims.csv``: ``id`` at least).
        name: ``"origin"`` or ``"kind"``.

    Returns:
        One value per row.
    """
    if name in claims.columns:
        return claims[name].astype(str)
    return claims["id"].astype(str).map({"origin": origin_of, "kind": kind_of}[name])


def number(x: float, unit: str) -> str:
    """A measured value as the ledger prints it: signed, but a ratio's (always positive).

    Args:
        x: the value.
        unit: its unit (``RATIO``: unsigned).

    Returns:
        Three significant digits.
    """
    return f"{x:.3g}" if unit == RATIO else f"{x:+.3g}"


def counted(claims: pd.DataFrame, origin: str) -> str:
    """The claims of one origin counted, findings apart from premises, each by verdict:
    ``52 claims: 34 findings (20 hold, 10 fail, 4 undecided), 18 premises (4 hold, 14 fail)``.

    Args:
        claims: the ledger (``id``, ``verdict``; ``origin``, ``kind`` where written).
        origin: ``"paper"`` or ``"project"``.

    Returns:
        The words.
    """
    verdicts = claims["verdict"].astype(str).str.split(":").str[0]
    mine = column(claims, "origin") == origin
    kinds = column(claims, "kind")
    parts = []
    for k in reversed(KINDS):  # findings first: they are what the comparison says
        v = verdicts[mine & (kinds == k)].value_counts()
        if not v.sum():
            continue
        by = ", ".join(
            f"{int(v[w])} {w[:-1] if w != 'undecided' else w}"
            for w in ("holds", "fails", "undecided")
            if v.get(w, 0)
        )
        parts.append(f"{int(v.sum())} {k}{'s' if v.sum() != 1 else ''} ({by})")
    n = int(mine.sum())
    return f"{n} claim{'s' if n != 1 else ''}: " + (", ".join(parts) or "none")


def failed_premises(claims: pd.DataFrame) -> list[str]:
    """Each premise family with a failed claim: where it fails and what that undermines.

    Args:
        claims: the ledger.

    Returns:
        One sentence per family, in the ledger's order; none when every premise holds.
    """
    verdicts = claims["verdict"].astype(str).str.split(":").str[0]
    failed = claims[(column(claims, "kind") == "premise") & (verdicts == "fails")]
    # the family is the id's first part: no premise family is asked of the priors
    by_family: dict[str, dict[str, list[str]]] = {}
    for cid in failed["id"].astype(str):
        fam, _, cell = cid.partition("/")
        where, _, what = (cell or "all").partition("/")  # tree, then the model where it has one
        by_family.setdefault(fam, {}).setdefault(where, []).extend([what] if what else [])
    return [
        f"the premise `{fam}` fails on "
        + ", ".join(f"{w} ({', '.join(m)})" if m else w for w, m in cells.items())
        + f": this undermines {undermines(fam)}."
        for fam, cells in by_family.items()
    ]


def ledger_markdown(df: pd.DataFrame, stamp: Mapping[str, str] | None = None) -> str:
    """The ledger as a Markdown page (results/claims.md).

    Args:
        df: the [`ledger`][physgs.report.claims.ledger].
        stamp: the run's stamp fields, printed under the title; None: none.

    Returns:
        The page's Markdown, ending in a newline.
    """
    lines = [
        "# Claims ledger",
        "",
        say("claims_intro"),
        "",
        *(["Made by: " + ", ".join(f"{k}={v}" for k, v in stamp.items()), ""] if stamp else []),
        say("claims_counts", paper=counted(df, "paper"), project=counted(df, "project")),
        "",
        *[f"- {s[0].upper() + s[1:]}" for s in failed_premises(df)],
        "",
        *say("claims_head").splitlines(),
    ]
    for (_, r), k in zip(df.iterrows(), column(df, "kind")):
        meas = "--" if not np.isfinite(r.measured) else f"{number(r.measured, r.unit)} {r.unit}"
        if np.isfinite(r.ci_low):
            meas += f" [{number(r.ci_low, r.unit)}, {number(r.ci_high, r.unit)}], {r.seeds} seeds"
        elif np.isfinite(r.measured):
            meas += f", {r.seeds} seed"
        size = r.get("paper_in_interval", "")
        size = f" ({size} the interval)" if isinstance(size, str) and size else ""
        lines.append(
            f"| {r.claim} | {r.origin} | {r.paper}{size} | {meas} | {r.threshold} "
            f"| **{r.verdict}** | {k} | {decide_cell(r)} | {r.source} |"
        )
    return "\n".join(lines) + "\n"


def decide_cell(row) -> str:
    """An undecided claim's seeds to decide, ``t 5 / power 8`` (``> MAX_SEEDS`` beyond the
    search); "" for a claim with no estimate (decided, or fewer than two seeds).

    Args:
        row (pd.Series): a ledger row (``verdict``, ``seeds_to_decide_t_est``,
            ``seeds_to_decide_power80_est``).

    Returns:
        The cell's text.
    """
    if str(row["verdict"]) != "undecided" or "seeds_to_decide_t_est" not in row.index:
        return ""
    n = lambda x: f"{int(x)}" if np.isfinite(x) else f"> {MAX_SEEDS}"
    return f"t {n(row['seeds_to_decide_t_est'])} / power {n(row['seeds_to_decide_power80_est'])}"
