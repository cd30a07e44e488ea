"""The catalogue of claims: every claim family of the ledger as one entry of data.

An entry ([`ClaimSpec`][physgs.report.catalogue.ClaimSpec]) holds its scope (the run -> its
cells, and for ``of="priors"`` every prior of the registry other than ours that the run's tables
hold), its table and reader (one seed's value), its threshold (a name of
[`physgs.report.thresholds`][physgs.report.thresholds]) and side, its unit and sentence, the
paper's figure, the README's words for a headline, and its origin (the paper's or this
project's). [`physgs.report.claims.measure`][] loops over it; the tables the ledger reads, the
headline families and the claims page ([`markdown`][physgs.report.catalogue.markdown]) derive
from it. Entries are Python, not YAML: a scope and a reader are functions over the tables (a
scope's docstring is what the claims page says the family ranges over).
"""

from __future__ import annotations

import string
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np
import pandas as pd

from physgs.models.registry import BLIND_CONFIG, BLIND_PRIORS, MODELS, PRIOR_VARIANTS
from physgs.models.registry import PAPER_MODEL, label, models_of, spec_of
from physgs.report import paper, thresholds
from physgs.report.claim_cells import CONFIG, FIELD_KINDS, RECOVERY, SEPARATED, TILED, Cell
from physgs.report.claim_cells import Reader, Run, Scope, fields_of_kind, rows_of, value
from physgs.report.recovery import OMA
from physgs.testbed.variant import DAMPING

#: The origins of a claim: stated by the source paper, or this project's own.
ORIGINS = ("paper", "project")
#: The models the paper itself compared: a claim about any other model is this project's.
PAPER_MODELS = (*models_of("control", "field"), PAPER_MODEL)
#: The kinds of a claim: a premise of the comparison (``PREMISES``) or a finding.
KINDS = ("premise", "finding")
#: The side of an equivalence claim (flat, equal, matching): inside (-threshold, +threshold),
#: two one-sided tests on the 95% interval (stricter than TOST's customary 90%).
WITHIN = "within"
SIDES = (">", "<", WITHIN)
#: The family the summary's line on the other priors counts (``physgs.report.summary``).
AHEAD = "ahead_of_fields"
#: Names a sentence may use: every threshold, and the ledger's recovery configuration.
WORDS = {k: v for k, v in vars(thresholds).items() if k.isupper()} | {"CONFIG": CONFIG}
#: A paper's value in a claim's unit: (low, high), equal ends for a single figure; NaN: none.
NO_VALUE = (float("nan"), float("nan"))


@dataclass(frozen=True)
class Figure:
    """A figure the paper states ([`physgs.report.paper`][physgs.report.paper]), for one cell.

    Attributes:
        what: what the figure is and where the paper gives it (the claims page prints it).
        value: the cell -> ``(low, high)`` in the claim's unit; ``NO_VALUE`` where none.
        words: as the ledger prints it: a ``str.format`` template of the cell's fields and
            ``v`` (``value``'s low end), or a function of the cell.
    """

    what: str
    value: Callable[[Cell], tuple[float, float]]
    words: str | Callable[[Cell], str] = "{v:+.2f} dB"

    def text(self, cell: Cell) -> str:
        """The figure of ``cell`` as the ledger prints it.

        Args:
            cell: the claim's cell.

        Returns:
            The words; "--" where the paper gives no number.
        """
        if callable(self.words):
            return self.words(cell)
        v = self.value(cell)[0]
        return self.words.format(v=v, **cell) if np.isfinite(v) else "--"


@dataclass(frozen=True, kw_only=True)
class ClaimSpec:
    """One claim family of the ledger.

    Attributes:
        family: the claim id's family (ids are ``[<prior>/]<family>[/<cell>]``).
        of: ``"ours"`` (asked once) or ``"priors"`` (asked of every other prior the run's
            tables hold, ids prefixed by the prior's).
        over: its scope (``claim_cells.Scope``).
        table: the table it reads (``claim_cells.RECOVERY``: the priors' damping summaries).
        read: its reader (``claim_cells.Reader``).
        threshold: a name of ``physgs.report.thresholds``, ``-`` in front to negate it.
        side: ``">"`` or ``"<"``: the side the claim holds on; ``WITHIN``: an equivalence band.
        unit: the value's unit (``"ratio"``: its interval is taken on the log scale).
        text: the claim's sentence (``str.format`` fields: the cell's, ``name``, ``WORDS``).
        source: where it is measured (same fields, and ``table``).
        paper: the paper's figure: words (same fields), or a ``Figure``.
        origin: ``"paper"`` or ``"project"`` (``ORIGINS``).
        headline: the words the README tells the family with; "" when it is not a headline.
        needs_variance: False for a claim about the fixed testbed (a verdict from one value).
        optional: listed only when its table is given; otherwise a missing table lists its
            claims "undecided: not measured".
        one_sided: why a one-sided test is the claim's own; required for every side but
            ``WITHIN``.
        requires: a family whose claim on the same cell must hold for this one to hold.
    """

    family: str
    of: str = "ours"
    over: Scope
    table: str
    read: Reader
    threshold: str
    side: str
    unit: str
    text: str
    source: str
    paper: str | Figure = "--"
    origin: str = "paper"
    headline: str = ""
    needs_variance: bool = True
    optional: bool = False
    one_sided: str = ""
    requires: str = ""

    def __post_init__(self):
        """Refuse what the ledger cannot decide, naming the family."""
        if self.side not in SIDES or self.origin not in ORIGINS:
            raise ValueError(f"claim {self.family!r}: side in {SIDES}, origin in {ORIGINS}")
        if (self.side == WITHIN) == bool(self.one_sided):
            raise ValueError(
                f"claim {self.family!r}: a one-sided claim says why (one_sided), "
                "an equivalence claim (side WITHIN) has no such reason"
            )
        if self.side == WITHIN and (self.unit == "ratio" or self.threshold.startswith("-")):
            raise ValueError(f"claim {self.family!r}: a band is (-t, +t) on a linear scale")
        if self.of not in ("ours", "priors"):
            raise ValueError(f"claim {self.family!r}: of must be 'ours' or 'priors'")
        if self.threshold.lstrip("-") not in WORDS:
            raise ValueError(f"claim {self.family!r}: no threshold {self.threshold!r}")
        if not (callable(self.over) and callable(self.read)):
            raise ValueError(f"claim {self.family!r}: its scope and reader are functions")

    @property
    def value(self) -> float:
        """The threshold's value."""
        v = float(WORDS[self.threshold.lstrip("-")])
        return -v if self.threshold.startswith("-") else v

    def value_of_paper(self, cell: Cell) -> tuple[float, float]:
        """The paper's figure for the claim of ``cell``, in the claim's unit.

        Args:
            cell: the claim's cell.

        Returns:
            ``(low, high)``; NaN ends where the paper gives no number.
        """
        return self.paper.value(cell) if isinstance(self.paper, Figure) else NO_VALUE

    def claim_of(self, cell: Cell) -> dict[str, Any]:
        """The fields of the ledger's claim of ``cell`` (``physgs.report.claims.Claim``).

        Args:
            cell: the claim's cell (its fields; ``model``, the prior asked, and ``name``, its
                label; ``prefix`` and ``suffix`` of the id).

        Returns:
            The claim's fields by name: the id (``[<prior>/]<family>[/<suffix>]``), the
                sentences and the paper's figure filled in, the threshold's value, the origin
                (``origin_of``) and the companion's id on the same cell (``requires``).
        """
        fill = lambda template: template.format(**WORDS, **cell)
        prefix = cell.get("prefix", "" if cell["model"] == PAPER_MODEL else f"{cell['model']}/")
        suffix = f"/{cell['suffix']}" if cell.get("suffix") else ""
        cid = prefix + self.family + suffix
        paper = self.paper.text(cell) if isinstance(self.paper, Figure) else fill(self.paper)
        return dict(
            id=cid, text=fill(self.text), paper=paper, source=fill(self.source),
            threshold=self.value, side=self.side, unit=self.unit,
            needs_variance=self.needs_variance, origin=origin_of(cid),
            paper_value=self.value_of_paper(cell),
            requires=prefix + self.requires + suffix if self.requires else "",
        )  # fmt: skip


# ---- why a family is one-sided (``ClaimSpec.one_sided``), and what most families share ----------
DIRECTION = "a direction: which is ahead, not by how much"
ABSOLUTE = (
    "two-sided by construction: the reader takes |offset|, so one bound on it is a band on both "
    "sides (the mean of |x| is at least |mean x|: stricter than a band on the signed offset)"
)
KIND_DIRECTION = (
    "a direction, as the paper's claim it splits: which kind of field is below static (and so "
    "which contradicts the paper's sign), not by how much"
)
NON_INFERIOR = (
    "non-inferiority: the claim is that the other does not lose, and its winning supports it too"
)
GROWS = "a direction: the margin grows, not by how much"
TRACKS_PROPOSAL = "not run (the paper's closing proposal)"
#: A difference whose sign is the claim (dB).
_AHEAD_DB = dict(threshold="EVEN", unit="dB", one_sided=DIRECTION)
#: A study or control of this project's that only some runs make.
_STUDY = dict(origin="project", optional=True)
#: A claim about ours asked again of every other prior.
_PRIOR = dict(of="priors", origin="project")


# ---- scopes and readers several families share ---------------------------------------------------
def _trees(run: Run, role: str = "", **fields) -> list[Cell]:
    """each tree"""  # the claims page's words; ``role``: only trees of it, ``fields``: added
    return [
        {"suffix": t, "tree": t, "paper": run.role(t, "paper"), **fields}
        for t in run.trees
        if not role or run.role(t, "frequencies") == role
    ]


def _recovered_trees(run: Run) -> list[Cell]:
    """each tree with the asked prior's recovery records (joint K = 32)"""
    rec = run.own
    have = set() if rec is None else set(rec.loc[rec["model"] == run.model, "tree"])
    return [c for c in _trees(run, config=CONFIG) if c["tree"] in have]


def _winds(run: Run) -> list[Cell]:
    """each split (training timestamps, beyond the window) x tree x unseen wind of tab_transfer"""
    tr = run.own
    if tr is None:
        return []
    return [
        {"suffix": f"{t}/wind_{sp}/{c:.2f}", "tree": t, "condition": c, "cond": f"{c:.2f}",
         "split": sp, "where": "beyond the window" if sp == "beyond" else "at training timestamps"}
        for (sp, t, c), _ in tr.groupby(["split", "tree", "condition"], sort=False)
    ]  # fmt: skip


def _winds_beyond(run: Run) -> list[Cell]:
    """each tree x unseen wind of tab_transfer, beyond the window"""
    # "beyond": a key of tab_transfer (images.TRANSFER_COLUMNS)
    return [
        {**c, "suffix": f"{c['tree']}/{c['cond']}"} for c in _winds(run) if c["split"] == "beyond"
    ]


def _best(d: pd.DataFrame, c: Cell, models: Sequence[str], split: str = "time") -> float:
    """The best of ``models``: tab_transfer's in the cell's split, tree and wind (a cell with a
    ``condition``), else tab_psnr's ``<tree>_<split>`` cells."""
    if "condition" not in c:
        return max(value(d, d["model"].astype(str) == m, f"{c['tree']}_{split}") for m in models)
    row = (d["split"] == c["split"]) & (d["tree"] == c["tree"])
    return max(value(d, row & np.isclose(d["condition"], c["condition"]), m) for m in models)


def _over_static(d: pd.DataFrame, c: Cell, models: Sequence[str]) -> float:
    return _best(d, c, models) - _best(d, c, ["static"])


def _ahead_of_fields(d: pd.DataFrame, c: Cell) -> float:
    sp = c.get("split", "view")
    return _best(d, c, [c["model"]], sp) - _best(d, c, models_of("field"), sp)


def _margin_trees(run: Run) -> list[Cell]:
    """each tree, tab_margin's first and last wind"""
    mg = run.own
    cols = [c for c in mg.columns if c.startswith("margin_")] if mg is not None else []
    first, last = (cols[0], cols[-1]) if cols else ("first", "last")
    return _trees(run, first=first, last=last)


def _margin_growth(d: pd.DataFrame, c: Cell) -> float:
    mine = (d["tree"] == c["tree"]) & rows_of(d, c["model"], "model")
    return value(d, mine, c["last"]) - value(d, mine, c["first"])


def _null_trees_separated(run: Run) -> list[Cell]:
    """each tree of separated frequencies, in the ledger's recovery configuration (joint K = 32)"""
    return _trees(run, SEPARATED, config=CONFIG, method=run.model)


def _at(d: pd.DataFrame, c: Cell) -> pd.Series:
    """The rows of the cell's tree and configuration."""
    return (d["tree"] == c["tree"]) & (d["config"] == c["config"])


def _null_row(d: pd.DataFrame, c: Cell, who: str = "") -> pd.Series:
    """tab_null / tab_recovery: method ``who``'s row (default: the cell's) in its tree, config."""
    who = who or c.get("method", c["model"])
    return rows_of(d, who) & _at(d, c)


def _err(d: pd.DataFrame, c: Cell, of: str = "trained", who: str = "") -> float:
    """tab_null / tab_recovery: the ``of`` (trained, null) median omega error (%) of ``who``."""
    return value(d, _null_row(d, c, who), f"{of}_median_rel_err_pct")


def _null_over_trained(d: pd.DataFrame, c: Cell) -> float:
    return _err(d, c, "null") / _err(d, c)


def _trained_minus_null(d: pd.DataFrame, c: Cell) -> float:
    return _err(d, c) - _err(d, c, "null")


def _of(d: pd.DataFrame, c: Cell, col: str, model: str = "") -> float:
    """``col`` of ``model`` (default: the cell's; the recovery summaries') in the cell's tree."""
    return value(d, (d["model"] == (model or c["model"])) & (d["tree"] == c["tree"]), col)


def _damping_off(d: pd.DataFrame, c: Cell) -> float:
    """|median zeta_hat - zeta| / zeta"""
    z = _of(d, c, "zeta_true")
    return abs(_of(d, c, "median_zeta") - z) / z


# ---- the paper's figures (``ClaimSpec.paper``) ---------------------------------------------------
def _from_paper(table: dict, c: Cell, f: Callable) -> tuple[float, float]:
    """``f`` of the cell's paper tree's entry of ``table`` as one figure; none without one."""
    v = table.get(c.get("paper"))
    return (float(f(v)),) * 2 if v else NO_VALUE


def _paper_over_static(c: Cell, models: Sequence[str]) -> tuple[float, float]:
    """tab:psnr: the best of ``models`` - static beyond the window (dB)."""
    return _from_paper(paper.PSNR, c, lambda pp: max(pp[m][1] - pp["static"][1] for m in models))


def _zeta_off(c: Cell) -> tuple[float, float]:
    """The paper's median zeta_hat range as |zeta_hat - 0.08| / 0.08 (its truth)."""
    z = paper.ZETA.get(c.get("paper"))
    if not z:
        return NO_VALUE
    ends = sorted(abs(float(x) - paper.ZETA_TRUE) / paper.ZETA_TRUE for x in z.split("-"))
    return (ends[0], ends[-1])


NULL_RATIO = Figure(
    "null / trained median omega error, tab:null",
    lambda c: _from_paper(paper.NULL, c, lambda v: v[1] / v[0]),  # (trained, null) %
    "null / trained = {v:.2f}",
)


# ---- the paper's: beyond the window and on held-out views (tab:psnr), unseen wind (tab:transfer)
_MOTION = (
    ClaimSpec(
        family="ours_above_static_beyond", over=_trees, table="tab_psnr", **_AHEAD_DB, side=">",
        read=lambda d, c: _over_static(d, c, [c["model"]]),
        text="{tree}: ours is above the static pose beyond the window",
        source="tab_psnr, time column: ours - static",
        paper=Figure("ours - static beyond the window, tab:psnr",
                     lambda c: _paper_over_static(c, [PAPER_MODEL])),
        headline="ours above the static pose beyond the training window",
    ),
    ClaimSpec(
        family="baselines_below_static_beyond", over=_trees, table="tab_psnr", **_AHEAD_DB,
        side="<", read=lambda d, c: _over_static(d, c, models_of("field")),
        text="{tree}: every learned baseline is below the static pose beyond the window",
        source="tab_psnr, time column: max over learned fields of (model - static)",
        paper=Figure("best learned field - static beyond the window, tab:psnr",
                     lambda c: _paper_over_static(c, models_of("field")),
                     "best baseline - static = {v:+.2f} dB"),
        headline="every learned field below static beyond the window",
    ),
    ClaimSpec(
        family="ours_behind_on_views", over=_trees, table="tab_psnr", read=_ahead_of_fields,
        **_AHEAD_DB, side="<",
        text="{tree}: ours is behind the best learned field on held-out views",
        source="tab_psnr, view column: ours - max over learned fields",
        paper=Figure("ours - best learned field on held-out views, tab:psnr", lambda c: _from_paper(
            paper.PSNR, c, lambda pp: pp["ours"][0] - max(pp[m][0] for m in models_of("field"))
        )),
    ),
    ClaimSpec(
        family="transfer_ours_ahead", over=_winds_beyond, table="tab_transfer",
        read=_ahead_of_fields, **_AHEAD_DB, side=">",
        text="{tree}, {cond} v0, beyond the window: ours ahead of the best baseline",
        source="tab_transfer (beyond): ours - max learned",
        paper="ahead in every cell, by 0.38-4.68 dB",
        headline="ours ahead of the best learned field under unseen wind",
    ),
    ClaimSpec(
        family="transfer_baselines_below_static", over=_winds_beyond, table="tab_transfer",
        read=lambda d, c: _over_static(d, c, models_of("field")), **_AHEAD_DB, side="<",
        text="{tree}, {cond} v0, beyond the window: every learned baseline below static",
        source="tab_transfer (beyond): max learned - static",
        paper="below static in all 24 cells, by 0.10-2.79 dB",
    ),
)  # fmt: skip


# ---- this project's: the two headlines above split by kind of field (``ModelSpec.wind``), so
# the ledger says which kind contradicts the paper; the paper's margin under unseen wind --------
def _kind_cells(cells: list[Cell]) -> list[Cell]:
    """``cells`` x each kind of learned field the registry holds, the kind after the tree."""
    return [
        {**c, "suffix": "/".join([c["tree"], k, *c["suffix"].split("/", 1)[1:]]), "kind": k,
         "kind_words": words, "kind_fields": ", ".join(label(m) for m in fields_of_kind(k))}
        for c in cells
        for k, words in FIELD_KINDS.items()
        if fields_of_kind(k)  # a registry without fields of this kind asks nothing of it
    ]  # fmt: skip


def _kind_trees(run: Run) -> list[Cell]:
    """each tree x each kind of learned field (wind-blind, wind-conditioned: whether its
    registry entry reads the wind)"""
    return _kind_cells(_trees(run))


def _kind_winds_beyond(run: Run) -> list[Cell]:
    """each tree x each kind of learned field (wind-blind, wind-conditioned: whether its
    registry entry reads the wind) x unseen wind of tab_transfer, beyond the window"""
    return _kind_cells(_winds_beyond(run))


_KINDS = (
    ClaimSpec(
        family="kind_below_static_beyond", over=_kind_trees, table="tab_psnr",
        read=lambda d, c: _over_static(d, c, fields_of_kind(c["kind"])),
        threshold="EVEN", side="<", unit="dB", origin="project", one_sided=KIND_DIRECTION,
        text="{tree}: every {kind_words} learned field ({kind_fields}) is below the static pose "
        "beyond the window",
        source="tab_psnr, time column: max over the {kind_words} fields of (model - static)",
        paper=Figure("the kind's best learned field - static beyond the window, tab:psnr",
                     lambda c: _paper_over_static(c, fields_of_kind(c["kind"])),
                     "best {kind_words} baseline - static = {v:+.2f} dB"),
    ),
    ClaimSpec(
        family="transfer_kind_below_static", over=_kind_winds_beyond, table="tab_transfer",
        read=lambda d, c: _over_static(d, c, fields_of_kind(c["kind"])),
        threshold="EVEN", side="<", unit="dB", origin="project", one_sided=KIND_DIRECTION,
        text="{tree}, {cond} v0, beyond the window: every {kind_words} learned field "
        "({kind_fields}) below static",
        source="tab_transfer (beyond): max {kind_words} learned - static",
        paper="every baseline below static in all 24 cells",
    ),
    ClaimSpec(
        family="margin_grows", over=_margin_trees, table="tab_margin", read=_margin_growth,
        threshold="EVEN", side=">", unit="dB", one_sided=GROWS,
        text="{tree}: the margin against MLP + wind grows as the wind departs from training",
        source="tab_margin: {last} - {first}",
        paper=Figure("the margin's growth from the training wind to the farthest, tab:margin",
                     lambda c: _from_paper(paper.MARGIN, c, lambda p: p[-1] - p[0])),
    ),
)  # fmt: skip


# ---- the paper's: recovery against the untrained null (tab:null, section 4) ----------------------
def _null_trees_tiled(run: Run) -> list[Cell]:
    """each tree of tiled frequencies, in the ledger's recovery configuration (joint K = 32)"""
    return _trees(run, TILED, config=CONFIG, method=run.model)


def _gap_trees(run: Run) -> list[Cell]:
    """each tree standing for a paper's tree whose nearest-bone gap the paper states"""
    return [c for c in _trees(run) if c["paper"] in paper.NEAREST_BONE_GAP_PCT]


def _gap_off(d: pd.DataFrame, c: Cell) -> float:
    """tab_testbed: |nearest-bone gap - the paper's tree's| / the paper's"""
    g = paper.NEAREST_BONE_GAP_PCT[c["paper"]]
    return abs(value(d, d["tree"] == c["tree"], "nearest_bone_gap_pct") - g) / g


def _zeta_words(c: Cell) -> str:
    z = paper.ZETA.get(c.get("paper"))
    return f"median zeta_hat {z} vs {paper.ZETA_TRUE:g}" if z else "--"


def _fit_models(run: Run) -> list[Cell]:
    """each tree x each learned field, ours and every other prior the tables hold"""
    return [
        {"suffix": f"{t}/{m}", "tree": t, "fit_model": m, "fit_label": label(m)}
        for t in run.trees
        for m in (*models_of("field"), PAPER_MODEL, *run.others)
    ]


_RECOVERY = (
    ClaimSpec(
        family="null_factor", over=_null_trees_separated, table="tab_null",
        read=_null_over_trained, threshold="NULL_FACTOR", side=">", unit="ratio",
        text="{tree}: ... by the paper's factor of {NULL_FACTOR:g}",
        source="{table}, {config}: null / trained", paper=NULL_RATIO,
        headline="ours beats the untrained null by the paper's factor on frequency",
        one_sided="a lower bound: the paper's factor or more (a larger one supports it)",
    ),
    ClaimSpec(
        family="null_loses", over=_null_trees_separated, table="tab_null",
        read=_null_over_trained, threshold="RATIO_EVEN", side=">", unit="ratio",
        text="{tree}: joint training beats the untrained null",
        source="{table}, {config}: null / trained median rel. error", paper=NULL_RATIO,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="null_matches", over=_null_trees_tiled, table="tab_null",
        read=_trained_minus_null, threshold="-NULL_MATCH_PP", side=">", unit="points",
        text="{tree}: the untrained null matches the trained model (it is not beaten by "
        "{NULL_MATCH_PP} points or more)",
        source="{table}, {config}: trained - null median rel. error (points)",
        paper=Figure("trained - null median omega error, tab:null",
                     lambda c: _from_paper(paper.NULL, c, lambda v: v[0] - v[1]),
                     "trained - null = {v:+.2f} points"),
        headline="the untrained null matches ours on frequency",
        one_sided="non-inferiority of the null: the paper's point is that training adds nothing "
        "over it on these trees, which a null ahead of the trained model supports too",
    ),
    ClaimSpec(
        family="nearest_bone_gap", over=_gap_trees, table="tab_testbed", read=_gap_off,
        threshold="GAP_RTOL", side="<", unit="fraction", one_sided=ABSOLUTE,
        text="{tree}: the median nearest-bone gap is the paper's (within {GAP_RTOL:.0%} of it)",
        source="tab_testbed: |gap - paper| / paper",
        paper=Figure("the median nearest-bone gap, section 4",
                     lambda c: NO_VALUE,  # a figure of the testbed, not in the claim's unit
                     lambda c: f"{paper.NEAREST_BONE_GAP_PCT[c['paper']]:.2f}%"),
        needs_variance=False,
    ),
    ClaimSpec(
        family="damping_not_recovered", over=_recovered_trees, table=RECOVERY,
        read=_damping_off, threshold="DAMPING_OFF", side=">", unit="fraction",
        text="{tree}: damping is not recovered (median zeta_hat off the truth by more than "
        "{DAMPING_OFF:.0%})",
        source="recovery ({config}): |median zeta_hat - zeta| / zeta",
        paper=Figure("the median fitted zeta, section 4", _zeta_off, _zeta_words),
        headline="damping is not recovered",
        one_sided="|offset| above the bar on either side: off the truth, whichever way",
    ),
    ClaimSpec(
        family="decay_rate_flat", over=_recovered_trees, table=RECOVERY,
        read=lambda d, c: _of(d, c, "loglog_exponent"),
        threshold="RATE_EXPONENT", side=WITHIN, unit="exponent",
        text="{tree}: the fitted decay rate gamma = zeta*omega is nearly frequency-independent "
        "(gamma ~ omega^p, |p| < {RATE_EXPONENT})",
        source="recovery ({config}): exponent p", paper="nearly frequency-independent",
    ),
    # the premise of every comparison (a model the paper did not train: the project's row)
    ClaimSpec(
        family="fits_window", over=_fit_models, table="tab_fit",
        read=lambda d, c: _of(d, c, "ceiling_frac", c["fit_model"]),
        threshold="FIT_BAR", side=">", unit="fraction",
        text="{tree}: {fit_label} fits its training window (reaches {FIT_BAR:.0%} of the "
        "true-motion ceiling's in-window gain over static)",
        source="tab_fit: (fit - static) / (ceiling - static) on the trained frames",
        paper="the fields 'fit the training window well'",
        one_sided="a bar: the premise is that a field fits at least this well",
    ),
)  # fmt: skip


# ---- this project's: the paper's claims about ours asked again of every other prior -------------
def _splits(run: Run) -> list[Cell]:
    """each tree x held-out views and beyond the window"""
    words = {"view": "held-out views", "time": "beyond the window"}
    return [
        {"suffix": f"{t}/{sp}", "tree": t, "split": sp, "where": w}
        for t in run.trees
        for sp, w in words.items()
    ]


def _recovery_trees(run: Run) -> list[Cell]:
    """each tree, in the ledger's recovery configuration (joint K = 32)"""
    return _trees(run, config=CONFIG, method=run.model)


_PRIORS = (
    ClaimSpec(
        family="above_static_beyond", **_PRIOR, over=_trees, table="tab_psnr", **_AHEAD_DB,
        side=">", read=lambda d, c: _over_static(d, c, [c["model"]]),
        text="{tree}: the {name} is above the static pose beyond the window",
        source="tab_psnr, time column: prior - static",
        headline="the {name} above the static pose beyond the window",
    ),
    ClaimSpec(
        family=AHEAD, **_PRIOR, over=_splits, table="tab_psnr", read=_ahead_of_fields,
        **_AHEAD_DB, side=">",
        text="{tree}: the {name} is ahead of the best learned field on {where}",
        source="tab_psnr, {split} column: prior - max over learned fields",
    ),
    ClaimSpec(
        family=AHEAD, **_PRIOR, over=_winds, table="tab_transfer", read=_ahead_of_fields,
        **_AHEAD_DB, side=">",
        text="{tree}, {cond} v0, {where}: the {name} is ahead of the best learned field",
        source="tab_transfer ({split}): prior - max learned",
    ),
    ClaimSpec(
        family="margin_grows", **_PRIOR, over=_margin_trees, table="tab_margin",
        read=_margin_growth, threshold="EVEN", side=">", unit="dB", one_sided=GROWS,
        text="{tree}: the {name}'s margin against MLP + wind grows as the wind departs",
        source="tab_margin ({model}): {last} - {first}",
    ),
    ClaimSpec(
        family="beats_null", **_PRIOR, over=_recovery_trees, table="tab_recovery",
        read=_trained_minus_null, threshold="-NULL_MATCH_PP", side="<", unit="points",
        text="{tree}: the {name} beats the untrained null on frequency recovery (by "
        "{NULL_MATCH_PP} points or more)",
        source="{table}, {config}: trained - null median rel. error (points)",
        one_sided="superiority by a margin: ahead of the null by the margin or more",
    ),
    ClaimSpec(
        family="damping_recovered", **_PRIOR, over=_recovered_trees, table=RECOVERY,
        read=_damping_off, threshold="DAMPING_OFF", side="<", unit="fraction",
        text="{tree}: the {name} recovers damping (median zeta_hat within {DAMPING_OFF:.0%} of "
        "the truth)",
        source="recovery ({config}): |median zeta_hat - zeta| / zeta", one_sided=ABSOLUTE,
    ),
    ClaimSpec(
        family="decay_rate_flat", **_PRIOR, over=_recovered_trees, table=RECOVERY,
        read=lambda d, c: _of(d, c, "loglog_exponent"),
        threshold="RATE_EXPONENT", side=WITHIN, unit="exponent",
        text="{tree}: the {name}'s fitted decay rate gamma = zeta*omega is nearly "
        "frequency-independent (gamma ~ omega^p, |p| < {RATE_EXPONENT})",
        source="recovery ({config}): exponent p",
    ),
)  # fmt: skip


# ---- this project's: without the anemometer, and the output-only analysis (docs/blind.md) ------
def _has(df: pd.DataFrame | None, method: str | None = None) -> bool:
    """Whether ``df`` has a ``method`` column (holding ``method``, when given)."""
    ok = df is not None and "method" in df.columns
    return ok and (method is None or method in set(df["method"]))


def _blind_trees(run: Run) -> list[Cell]:
    """each forcing-free prior in tab_recovery x each tree, against the prior whose measured wind it
    replaces (ids ``<prior>/...`` for a prior other than ours)"""
    null = run.own
    if not _has(null):
        return []
    have, out = set(null["method"]), []
    for blind in (m for m in BLIND_PRIORS if m in have):
        wind = spec_of(blind).blind_of
        who, prefix = ("ours", "") if wind == PAPER_MODEL else (f"the {label(wind)}", f"{wind}/")
        cells = _trees(run, prefix=prefix, blind=blind, wind=wind, who=who, config=BLIND_CONFIG)
        out += [c for c in cells if (null["tree"] == c["tree"]).any()]
    return out


def _oma_separated(run: Run) -> list[Cell]:
    """each tree of separated frequencies, when tab_recovery holds the output-only analysis"""
    return _trees(run, SEPARATED, config=BLIND_CONFIG, method=OMA) if _has(run.own, OMA) else []


def _oma_damping_trees(run: Run) -> list[Cell]:
    """each tree of tab_damping, when it holds the output-only analysis"""
    dmp = run.own
    if not _has(dmp, OMA):
        return []
    return [c for c in _trees(run, config=BLIND_CONFIG) if (dmp["tree"] == c["tree"]).any()]


def _oma_interval_trees(run: Run) -> list[Cell]:
    """each tree of tab_damping, when it holds the output-only analysis' interval coverage"""
    dmp = run.own
    ok = dmp is not None and "omega_interval_cover" in dmp.columns
    return _oma_damping_trees(run) if ok else []


def _oma(d: pd.DataFrame, c: Cell, col: str) -> float:
    """tab_damping (damping testbed): the output-only analysis' ``col`` in the cell's tree and
    configuration."""
    return value(d, _at(d, c) & (d["testbed"] == DAMPING) & (d["method"] == OMA), col)


def _halfwidth(d: pd.DataFrame, c: Cell, q: str) -> float:
    """The median relative half-width of the ``q`` intervals, 1.96 sigma / value."""
    from physgs.oma.intervals import Z95  # here: scipy, which planning never loads

    return Z95 * _oma(d, c, f"{q}_rel_sd")


def _oma_intervals(q: str, name: str) -> dict[str, ClaimSpec]:
    """The output-only analysis' 95% intervals for ``q`` (``omega``, ``zeta``; ``name`` in the
    ids): they cover, they score better than the null's, they are informative."""
    intervals = f"{{tree}} (damping testbed): the output-only analysis' 95% intervals for {q}"
    common = dict(
        over=_oma_interval_trees,
        table="tab_damping",
        paper="not in the paper (this project's)",
        **_STUDY,
    )
    return {
        "covers": ClaimSpec(
            family=f"oma_{name}_interval_covers", **common,
            read=lambda d, c: _oma(d, c, f"{q}_interval_cover"),
            threshold="INTERVAL_COVER", side=">", unit="fraction",
            text=f"{intervals} hold the matched bone's true {q} on at least "
            "{INTERVAL_COVER:.0%} of its trusted parts",
            source=f"{{table}}, {{config}}: output-only {q}_interval_cover",
            one_sided="a floor: coverage of at least the bar; width is judged by its "
            "interval-score companion",
            requires=f"oma_{name}_interval_score",
        ),
        "score": ClaimSpec(
            family=f"oma_{name}_interval_score", **common,
            read=lambda d, c: (
                _oma(d, c, f"{q}_null_interval_score") / _oma(d, c, f"{q}_interval_score")
            ),
            threshold="RATIO_EVEN", side=">", unit="ratio",
            text=f"{intervals} score better than the untrained null's draw range (interval "
            "score, Gneiting and Raftery 2007: width plus 2/alpha times the miss, per part, "
            "relative to the truth)",
            source=f"{{table}}, {{config}}: {q}_null_interval_score / {q}_interval_score",
            one_sided=DIRECTION,
        ),
        "informative": ClaimSpec(
            family=f"oma_{name}_interval_informative", **common,
            read=lambda d, c: _halfwidth(d, c, q),
            threshold="INFORMATIVE_HALFWIDTH", side="<", unit="fraction",
            text=f"{intervals} are informative (median half-width below "
            "{INFORMATIVE_HALFWIDTH:.0%} of the value: the interval excludes zero)",
            source=f"{{table}}, {{config}}: 1.96 x output-only {q}_rel_sd",
            one_sided="a bar: an interval at most this wide says something; narrower never "
            "hurts (its misses are the interval score's)",
        ),
    }  # fmt: skip


_OMEGA, _ZETA = _oma_intervals("omega", "frequency"), _oma_intervals("zeta", "damping")

_BLIND = (
    ClaimSpec(
        family="anemometer_needed", over=_blind_trees, table="tab_recovery",
        read=lambda d, c: _err(d, c, who=c["blind"]) - _err(d, c, who=c["wind"]),
        threshold="EVEN", side=">", unit="pp", **_STUDY, one_sided=DIRECTION,
        text="{tree}: without the measured wind (a learned forcing) {who} recovers omega worse",
        source="{table}, {config}: {blind} - {wind} median rel. error (points)",
        paper="the paper's closing limit: 'real footage needs an anemometer'",
        headline="without the anemometer (a learned forcing), ours' frequency error grows "
        "(points)",
    ),
    ClaimSpec(
        family="oma_beats_null", over=_oma_separated, table="tab_recovery",
        read=_null_over_trained, threshold="RATIO_EVEN", side=">", unit="ratio",
        text="{tree}: output-only modal analysis of the video recovers omega better than the "
        "untrained null",
        source="{table}, {config}: null / output-only median rel. error",
        paper="not run", **_STUDY, one_sided=DIRECTION,
        headline="output-only modal analysis of the video beats the untrained null",
    ),
    ClaimSpec(
        family="oma_recovers_zeta", over=_oma_damping_trees, table="tab_damping",
        read=lambda d, c: _oma(d, c, "trained_minus_null_pp"),
        threshold="EVEN", side="<", unit="pp", **_STUDY, one_sided=DIRECTION,
        text="{tree} (damping testbed): output-only modal analysis recovers zeta better than "
        "the untrained null",
        source="tab_damping, {config}: output-only - null median zeta error (points)",
        paper="no method here recovers zeta (the paper)",
    ),
    _OMEGA["covers"], _ZETA["covers"], _OMEGA["score"], _OMEGA["informative"], _ZETA["score"],
    _ZETA["informative"],
)  # fmt: skip


# ---- this project's: the paper's two hypotheses about its prior (section 6), tested --------------
def _parts(run: Run) -> tuple[pd.DataFrame | None, set, str]:
    """tab_parts, its models and its first configuration (None, empty where it is not there)."""
    df = run.own
    if df is None or df.empty:
        return None, set(), ""
    return df, set(df["model"]), str(df["config"].iloc[0])


def _parts_damping_trees(run: Run) -> list[Cell]:
    """each tree with a damping testbed in tab_parts (its first configuration), when it holds
    the topology parts"""
    df, models, c0 = _parts(run)
    if "ours_topo" not in models:
        return []
    zeta = df.loc[np.isfinite(df["zeta_rel_err_pct"]), "tree"]
    return [c for c in _trees(run, config=c0) if (zeta == c["tree"]).any()]


def _parts_coupling(run: Run) -> list[Cell]:
    """each tree of separated frequencies in tab_parts (its first configuration), when it holds
    both topology priors (no id suffix for a single such tree: the family's id as before)"""
    _, models, c0 = _parts(run)
    cells = _trees(run, SEPARATED, config=c0) if {"ours_topo", "ours_chain"} <= models else []
    return [{**c, "suffix": "" if len(cells) == 1 else c["tree"]} for c in cells]


def _parts_gain(d: pd.DataFrame, c: Cell, better: str, base: str, col: str) -> float:
    """tab_parts: ``col`` of parts ``better`` - of parts ``base`` in the cell's tree, config."""
    at = _at(d, c)
    return value(d, at & (d["model"] == better), col) - value(d, at & (d["model"] == base), col)


_PARTS = (
    ClaimSpec(
        family="topology_parts_reduce_damping_error", over=_parts_damping_trees,
        table="tab_parts", **_STUDY, one_sided=DIRECTION,
        read=lambda d, c: _parts_gain(d, c, "ours_topo", "ours", "zeta_rel_err_pct"),
        threshold="EVEN", side="<", unit="pp",
        text="{tree}: topology-aware parts reduce the damping error (damping testbed)",
        source="tab_parts ({config}): median rel. err. of zeta, topology - k-means parts",
        paper="hypothesis (k-means parts 'plausibly feed the damping bias')",
    ),
    ClaimSpec(
        family="coupling_lifts_sparse_fit", over=_parts_coupling, table="tab_parts",
        read=lambda d, c: _parts_gain(d, c, "ours_chain", "ours_topo", "ceiling_frac"),
        threshold="EVEN", side=">", unit="fraction", **_STUDY, one_sided=DIRECTION,
        text="{tree}: parent-child coupling lifts the in-window fit",
        source="tab_parts ({config}): fraction of the ceiling's gain, chained - independent "
        "topology parts",
        paper="hypothesis (independent parts 'represent no coupling')",
    ),
)  # fmt: skip


# ---- this project's: the 2D-track control (docs/tracks.md) ---------------------------------------
def _config_of(configs: pd.Series, preferred: str) -> str | None:
    """``preferred`` where ``configs`` hold it, else the first; None for none."""
    cs = list(dict.fromkeys(configs))
    return preferred if preferred in cs else next(iter(cs), None)


def _tracks_separated(run: Run) -> list[Cell]:
    """each tree of separated frequencies, the 2D-track control's recovery in joint K = 32
    (else its first configuration)"""
    null = run.own
    c = _config_of(null.loc[null["method"] == "tracks", "config"], CONFIG) if _has(null) else None
    return [] if c is None else _trees(run, SEPARATED, config=c, method="tracks")


def _tracks_minus_ours(d: pd.DataFrame, c: Cell) -> float:
    """tab_recovery: 2D tracks - ours median omega error (points); NaN at another K than ours'"""
    if value(d, _null_row(d, c), "K") != value(d, _null_row(d, c, PAPER_MODEL), "K"):
        return float("nan")  # another K: not the same question
    return _err(d, c) - _err(d, c, who=PAPER_MODEL)


def _tracks_trees(run: Run) -> list[Cell]:
    """each tree in tab_tracks, its base configuration (else its first)"""
    tr = run.own
    c = None if tr is None else _config_of(tr["config"], "single")
    if c is None:
        return []
    return [x for x in _trees(run, config=c) if (tr["tree"] == x["tree"]).any()]


_TRACKS = (
    ClaimSpec(
        family="tracks_beats_null", over=_tracks_separated, table="tab_recovery",
        read=_null_over_trained, threshold="RATIO_EVEN", side=">", unit="ratio",
        text="{tree}: oscillators fitted to 2D tracks recover omega better than the untrained "
        "null",
        source="{table}, 2D tracks {config}: null / tracks median rel. error",
        paper=TRACKS_PROPOSAL, **_STUDY, one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="tracks_match_ours", over=_tracks_separated, table="tab_recovery",
        read=_tracks_minus_ours, threshold="NULL_MATCH_PP", side="<", unit="points",
        text="{tree}: oscillators fitted to 2D tracks match ours' omega recovery (ours does not "
        "beat them by {NULL_MATCH_PP} points or more)",
        source="{table}, {config}: 2D tracks - ours median rel. error (points)",
        paper=TRACKS_PROPOSAL, **_STUDY, one_sided=NON_INFERIOR,
    ),
    ClaimSpec(
        family="tracks_extrapolate_as_ours", over=_tracks_trees, table="tab_tracks",
        read=lambda d, c: value(d, _at(d, c), "tail_px") - value(d, _at(d, c), "tail_ours_px"),
        threshold="EVEN", side="<", unit="px",
        text="{tree}: beyond the window, oscillators fitted to 2D tracks predict the tracked "
        "points at least as well as ours' Gaussians",
        source="tab_tracks, {config}: tail displacement error, 2D tracks - ours (px)",
        paper=TRACKS_PROPOSAL, **_STUDY, one_sided=NON_INFERIOR,
    ),
)  # fmt: skip

#: Every claim family, in the ledger's order.
CATALOGUE: tuple[ClaimSpec, ...] = (
    *_MOTION, *_KINDS, *_RECOVERY, *_PRIORS, *_BLIND, *_PARTS, *_TRACKS
)  # fmt: skip

#: The families that are premises of the comparison, each with what its failure undermines (the
#: claims' ``kind``: ``kind_of``); every other family is a finding.
PREMISES: dict[str, str] = {
    "nearest_bone_gap": "the frequency-recovery claims set beside the paper's (how near an "
    "untrained null's omega lands to some bone's depends on how far apart the bones' "
    "frequencies lie)",
    "fits_window": "every comparison that model enters on that tree (beyond the window, on "
    "held-out views, under unseen wind): a model that does not fit its own training window says "
    "little about what lies beyond it",
}
if not set(PREMISES) <= {s.family for s in CATALOGUE}:  # a renamed family stays a premise
    raise ValueError(f"PREMISES: no family {sorted(set(PREMISES) - {s.family for s in CATALOGUE})}")


# ---- derived from the catalogue ----------------------------------------------------------------
def tables(optional: bool = True) -> tuple[str, ...]:
    """The tables the ledger reads, in catalogue order (the recovery summaries are not one).

    Args:
        optional: include the tables only some runs make (``ClaimSpec.optional``).

    Returns:
        Table names.
    """
    required = {s.table for s in CATALOGUE if not s.optional}
    every = dict.fromkeys(s.table for s in CATALOGUE if s.table != RECOVERY)
    return tuple(t for t in every if optional or t in required)


def required_tables() -> tuple[str, ...]:
    """The tables every run's ledger reads (a missing one: "undecided: not measured").

    Returns:
        Table names.
    """
    return tables(optional=False)


def reads_recovery() -> bool:
    """Whether any family reads the priors' recovery records.

    Returns:
        True when a family's table is ``RECOVERY``.
    """
    return any(s.table == RECOVERY for s in CATALOGUE)


def headline(priors: Sequence[str] | None = None) -> list[tuple[str, str, str]]:
    """The families that carry the story, in catalogue order: ``(id prefix, words, origin)``,
    one per prior other than ours for a family asked of the priors.

    Args:
        priors: the priors other than ours (default: the registry's).

    Returns:
        One triple per headline family.
    """
    others = [m for m in models_of("prior") if m != PAPER_MODEL] if priors is None else priors
    out = []
    for s in (s for s in CATALOGUE if s.headline):
        if s.of == "ours":
            out.append((s.family, s.headline, s.origin))
        else:  # the prior's label inside a sentence: its first letter lower case
            names = {m: label(m)[0].lower() + label(m)[1:] for m in others}
            out += [(f"{m}/{s.family}", s.headline.format(name=names[m]), s.origin) for m in others]
    return out


_MODEL_IDS = set(MODELS) | set(PRIOR_VARIANTS)


def _family(claim_id: str) -> str:
    parts = claim_id.split("/")
    return parts[1] if parts[0] in _MODEL_IDS and len(parts) > 1 else parts[0]


def origin_of(claim_id: str) -> str:
    """Whether a claim id is the paper's or this project's: its family's origin, and this
    project's wherever the id names a model the paper did not train.

    Args:
        claim_id: a ledger id (``[<prior>/]<family>[/<cell>]``).

    Returns:
        ``"paper"`` or ``"project"``.

    Raises:
        ValueError: for an id of no family of the catalogue.
    """
    parts = claim_id.split("/")
    if any(p in _MODEL_IDS and p not in PAPER_MODELS for p in parts):
        return "project"
    fam = _family(claim_id)
    for s in CATALOGUE:
        if s.family == fam and (s.of == "priors") == (parts[0] in _MODEL_IDS):
            return s.origin
    raise ValueError(f"claim {claim_id!r}: no family {fam!r} in the catalogue")


def kind_of(claim_id: str) -> str:
    """Whether a claim is a premise of the comparison or a finding (its family in ``PREMISES``).

    Args:
        claim_id: a ledger id (``[<prior>/]<family>[/<cell>]``).

    Returns:
        ``"premise"`` or ``"finding"``.
    """
    return "premise" if _family(claim_id) in PREMISES else "finding"


def undermines(claim_id: str) -> str:
    """What a premise's failure undermines.

    Args:
        claim_id: a ledger id.

    Returns:
        The words (``PREMISES``); "" for a finding.
    """
    return PREMISES.get(_family(claim_id), "")


def _template(text: str, table: str = "") -> str:
    """A sentence template as the claims page shows it: thresholds filled in, fields ``<f>``."""
    other = {"name": "<prior>", "table": table}
    fill = lambda f, spec: format(WORDS[f], spec) if f in WORDS else other.get(f, f"<{f}>")
    parts = string.Formatter().parse(text)
    return "".join(lit + ("" if f is None else fill(f, spec)) for lit, f, spec, _ in parts)


BEGIN, END = "<!-- catalogue:begin -->", "<!-- catalogue:end -->"


def markdown() -> str:
    """The claims page's list of claims (``docs/claims.md``, between ``BEGIN`` and ``END``),
    one row per family: generated, never typed (``tools/claims_reference.py``).

    Returns:
        The block, markers included.
    """
    rows = []
    for s in CATALOGUE:
        fam = f"`{s.family}`" if s.of == "ours" else f"`<prior>/{s.family}`"
        fam += " (headline)" * bool(s.headline) + " (premise)" * (s.family in PREMISES)
        doc = " ".join((s.over.__doc__ or s.over.__name__).strip().split("\n\n")[0].split())
        sign = "±" if s.side == WITHIN else "-" * s.threshold.startswith("-")
        figure = s.paper.what if isinstance(s.paper, Figure) else _template(s.paper)
        cells = [
            fam,
            ("ours" if s.of == "ours" else "every other prior") + ", " + doc,
            _template(s.text),
            f"{s.side} {sign}`{s.threshold.lstrip('-')}` = {s.value:g} {s.unit}",
            "equivalence (inside the band)" if s.side == WITHIN else f"one-sided: {s.one_sided}",
            _template(s.source, s.table) + " (optional)" * s.optional,
            "this project" if figure == "--" else figure,
            s.origin,
        ]
        rows.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    head = "| family | asked of, over | claim | threshold | test | reads | the paper | origin |"
    # thresholds and the paper's figures: the record states verdicts
    return "\n".join([BEGIN, "", "<!-- no verdict -->", head, "|---" * 8 + "|", *rows, "", END])
