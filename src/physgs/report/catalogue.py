"""The catalogue of claims: every claim family of the ledger as one entry of data.

An entry ([`ClaimSpec`][physgs.report.catalogue.ClaimSpec]) says what the family ranges over
(its scope: trees, cells of a table, and, for ``of="priors"``, every prior of the registry other
than ours that the run's tables hold), the table and how one seed's value is read from it (its
reader), its threshold (a name of [`physgs.report.thresholds`][physgs.report.thresholds]) and
side, its unit, its sentence, the paper's figure, whether it carries the story (a headline, with
the words the README uses), and its origin: the paper's claim, or this project's own.
[`physgs.report.claims.measure`][] loops over it; the tables the ledger reads, the README's
headline families and the list of claims on the claims page
([`markdown`][physgs.report.catalogue.markdown]) are derived from it.

Adding a claim family is one entry here, with its scope and reader beside it (the shared ones
come first; a scope's docstring is what the claims page says the family ranges over).

Entries are Python, not YAML: a family's scope and reader are functions over the tables, and a
frozen dataclass keeps them typed and importable where a YAML file would need a small language
of its own for the cell arithmetic.
"""

from __future__ import annotations

import string
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import pandas as pd

from physgs.models.registry import (
    BLIND_CONFIG,
    BLIND_PRIORS,
    MODELS,
    PRIOR_VARIANTS,
    label,
    models_of,
    spec_of,
)
from physgs.report import paper, thresholds
from physgs.report.claim_cells import (
    CONFIG,
    FIELD_KINDS,
    RECOVERY,
    SEPARATED,
    TILED,
    Cell,
    Reader,
    Run,
    Scope,
    fields,
    fields_of_kind,
    rows_of,
    value,
)
from physgs.report.recovery import OMA
from physgs.testbed.variant import DAMPING

#: The origins of a claim: stated by the source paper, or this project's own.
ORIGINS = ("paper", "project")
#: The models the paper itself compared: a claim about any other model is this project's.
PAPER_MODELS = (*models_of("control", "field"), "ours")

#: The kinds of a claim: a premise of the comparison (the testbed is the paper's, the models fit
#: their window) or a finding the comparison makes. Every family is a finding but ``PREMISES``'.
KINDS = ("premise", "finding")
#: The side of an equivalence claim (flat, equal, matching): the value lies inside the band
#: (-threshold, +threshold). Two one-sided tests on the 95% interval, each at 2.5% (stricter
#: than the customary 90% interval of TOST at 5%: one interval serves every verdict).
WITHIN = "within"
#: The sides a claim may take.
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
        value: the cell -> ``(low, high)`` in the claim's unit (equal ends for one figure);
            ``NO_VALUE`` where the paper gives none.
        words: the figure as the ledger prints it: a ``str.format`` template of the cell's
            fields and ``v`` (``value``'s low end; "--" where it is NaN), or a function of the
            cell.
    """

    what: str
    value: Callable[[Cell], tuple[float, float]]
    words: str | Callable[[Cell], str]

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
        of: ``"ours"`` (asked once) or ``"priors"`` (asked of every prior of the registry other
            than ours that the run's tables hold, ids prefixed by the prior's).
        over: its scope (the run -> the family's cells; ``claim_cells.Scope``).
        table: the table it reads (``claim_cells.RECOVERY``: the priors' damping summaries).
        read: its reader (one seed's rows and a cell -> the value; ``claim_cells.Reader``).
        threshold: a name of ``physgs.report.thresholds``, ``-`` in front to negate it.
        side: ``">"`` or ``"<"``: the side of the threshold the claim holds on; ``WITHIN``: an
            equivalence claim (flat, equal, matching), inside (-threshold, +threshold).
        unit: the value's unit (``"ratio"``: its interval is taken on the log scale).
        text: the claim's sentence (``str.format`` fields: the cell's, ``name`` of the prior,
            ``WORDS``).
        source: where it is measured (same fields, and ``table``).
        paper: the paper's figure: words (same fields), or a
            [`Figure`][physgs.report.catalogue.Figure] (its value in the claim's unit too).
        origin: ``"paper"`` or ``"project"`` (``ORIGINS``).
        headline: the words the README tells the family with; "" when it is not a headline.
        needs_variance: False for a claim about the fixed testbed (a verdict from one value).
        optional: listed only when its table is given (a study or control the run may not
            make); otherwise a missing table lists its claims "undecided: not measured".
        one_sided: why a one-sided test (``">"``, ``"<"``) is the claim's own test; required
            for every side but ``WITHIN``: a claim of flatness, equality or match is tested
            inside a band, never one-sided without a stated reason.
        requires: a family whose claim on the same cell must hold for this one to hold (a
            coverage holds only where its intervals also beat the null's interval score); ""
            for none.
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
        """Refuse an unknown side, origin or threshold name, a scope or reader that is not a
        function, a one-sided claim without its reason, and an equivalence band on a ratio,
        naming the family."""
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

    def claim_id(self, cell: Cell, family: str = "") -> str:
        """The id of the claim of ``cell``.

        Args:
            cell: the claim's cell (``model``: the prior asked; ``prefix``, ``suffix``).
            family: another family's id on the same cell (``requires``); "": this one's.

        Returns:
            ``[<prior>/]<family>[/<suffix>]``.
        """
        prefix = cell.get("prefix", "" if cell["model"] == "ours" else f"{cell['model']}/")
        fam = family or self.family
        return prefix + fam + (f"/{cell['suffix']}" if cell.get("suffix") else "")

    def words(self, template: str, cell: Cell) -> str:
        """A sentence of the claim of ``cell``.

        Args:
            template: ``text`` or ``source``.
            cell: the claim's cell (its fields and ``name``, the prior's label).

        Returns:
            ``template`` with the cell's fields and ``WORDS`` filled in.
        """
        return template.format(**WORDS, **cell)

    def value_of_paper(self, cell: Cell) -> tuple[float, float]:
        """The paper's figure for the claim of ``cell``, as a number in the claim's unit.

        Args:
            cell: the claim's cell.

        Returns:
            ``(low, high)``; NaN ends where the paper gives no number.
        """
        return self.paper.value(cell) if isinstance(self.paper, Figure) else NO_VALUE

    def figure(self, cell: Cell) -> str:
        """The paper's figure for the claim of ``cell``.

        Args:
            cell: the claim's cell.

        Returns:
            ``paper``, filled in or computed.
        """
        if isinstance(self.paper, Figure):
            return self.paper.text(cell)
        return self.words(self.paper, cell)


# ---- why a family is one-sided (``ClaimSpec.one_sided``) -----------------------------------------
#: a sign: the claim says which is ahead, not by how much (its size: ``paper_in_interval``)
DIRECTION = "a direction: which is ahead, not by how much"
#: the reader takes |value - truth|: a band around the truth on both sides by construction
ABSOLUTE = (
    "two-sided by construction: the reader takes |offset|, so one bound on it is a band on both "
    "sides (the mean of |x| is at least |mean x|: stricter than a band on the signed offset)"
)
#: a coverage floor: more coverage is never against it; its width is judged apart (the
#: interval score against the null's, ``*_interval_score``)
COVER = "a floor: coverage of at least the bar; width is judged by its interval-score companion"
#: the paper's headline split by kind of field: one-sided as its parent, a direction (the
#: question is which kind of field contradicts the paper's sign, not by how much)
KIND_DIRECTION = (
    "a direction, as the paper's claim it splits: which kind of field is below static (and so "
    "which contradicts the paper's sign), not by how much"
)
#: not worse by more than a margin: the better side supports the claim too
NON_INFERIOR = (
    "non-inferiority: the claim is that the other does not lose, and its winning supports it too"
)
#: a margin's growth: its sign
GROWS = "a direction: the margin grows, not by how much"
#: an interval's width bar
INFORMATIVE = (
    "a bar: an interval at most this wide says something; narrower never hurts "
    "(its misses are the interval score's)"
)

#: The paper's figure of a family the paper does not state.
PROJECT_ONLY = "not in the paper (this project's)"
TRACKS_PROPOSAL = "not run (the paper's closing proposal)"


# ---- scopes and readers several families share ---------------------------------------------------
def _trees(run: Run) -> list[Cell]:
    """each tree"""
    return [{"suffix": t, "tree": t, "paper": run.role(t, "paper")} for t in run.trees]


def _with_role(run: Run, role: str) -> list[Cell]:
    """The trees whose preset declares their frequencies ``role``."""
    return [c for c in _trees(run) if run.role(c["tree"], "frequencies") == role]


def _recovered_trees(run: Run) -> list[Cell]:
    """each tree with the asked prior's recovery records (joint K = 32)"""
    rec = run.own
    if rec is None:
        return []
    have = set(rec.loc[rec["model"] == run.model, "tree"])
    return [{**c, "config": CONFIG} for c in _trees(run) if c["tree"] in have]


def _psnr(d: pd.DataFrame, c: Cell, models: Sequence[str], split: str = "time") -> float:
    """tab_psnr: the best of ``models``' ``<tree>_<split>`` cells (by model id)."""
    return max(value(d, d["model"].astype(str) == m, f"{c['tree']}_{split}") for m in models)


def _ahead_of_fields(d: pd.DataFrame, c: Cell) -> float:
    """tab_psnr, the cell's split: the prior - max over learned fields"""
    sp = c.get("split", "view")
    return _psnr(d, c, [c["model"]], sp) - _psnr(d, c, fields(), sp)


def _winds_beyond(run: Run) -> list[Cell]:
    """each tree x unseen wind of tab_transfer, beyond the window"""
    tr = run.own
    if tr is None:
        return []
    beyond = tr[tr["split"] == "beyond"] if "split" in tr.columns else tr
    return [
        {"suffix": f"{t}/{c:.2f}", "tree": t, "condition": c, "cond": f"{c:.2f}", "split": "beyond"}
        for (t, c), _ in beyond.groupby(["tree", "condition"], sort=False)
    ]


def _transfer(d: pd.DataFrame, c: Cell, models: Sequence[str]) -> float:
    """tab_transfer: the best of ``models`` in the cell's split, tree and wind."""
    row = (
        (d["split"] == c["split"])
        & (d["tree"] == c["tree"])
        & np.isclose(d["condition"], c["condition"])
    )
    return max(value(d, row, m) for m in models)


def _wind_ahead(d: pd.DataFrame, c: Cell) -> float:
    """tab_transfer: the prior - max over learned fields"""
    return _transfer(d, c, [c["model"]]) - _transfer(d, c, fields())


def _margin_trees(run: Run) -> list[Cell]:
    """each tree, tab_margin's first and last wind"""
    mg = run.own
    cols = [c for c in mg.columns if c.startswith("margin_")] if mg is not None else []
    first, last = (cols[0], cols[-1]) if cols else ("first", "last")
    return [{**c, "first": first, "last": last} for c in _trees(run)]


def _margin_growth(d: pd.DataFrame, c: Cell) -> float:
    """tab_margin: the prior's last wind's margin - its first's"""
    mine = (d["tree"] == c["tree"]) & rows_of(d, c["model"], "model")
    return value(d, mine, c["last"]) - value(d, mine, c["first"])


def _null_trees_separated(run: Run) -> list[Cell]:
    """each tree of separated frequencies, in the ledger's recovery configuration (joint K =
    32)"""
    return [{**c, "config": CONFIG, "method": run.model} for c in _with_role(run, SEPARATED)]


def _null_row(d: pd.DataFrame, c: Cell, who: str = "") -> pd.Series:
    """tab_null / tab_recovery: the row of method ``who`` (default: the cell's) in the cell's
    tree and configuration."""
    who = who or c.get("method", c["model"])
    return rows_of(d, who) & (d["tree"] == c["tree"]) & (d["config"] == c["config"])


def _null_over_trained(d: pd.DataFrame, c: Cell) -> float:
    """tab_null / tab_recovery: null / trained median omega error of the cell's method"""
    row = _null_row(d, c)
    return value(d, row, "null_median_rel_err_pct") / value(d, row, "trained_median_rel_err_pct")


def _trained_minus_null(d: pd.DataFrame, c: Cell) -> float:
    """tab_null / tab_recovery: trained - null median omega error of the cell's method (points)"""
    row = _null_row(d, c)
    return value(d, row, "trained_median_rel_err_pct") - value(d, row, "null_median_rel_err_pct")


def _damping_off(d: pd.DataFrame, c: Cell) -> float:
    """the prior's recovery: |median zeta_hat - zeta| / zeta"""
    row = (d["model"] == c["model"]) & (d["tree"] == c["tree"])
    z = value(d, row, "zeta_true")
    return abs(value(d, row, "median_zeta") - z) / z


def _decay_exponent(d: pd.DataFrame, c: Cell) -> float:
    """the prior's recovery: the exponent p of gamma ~ omega^p"""
    return value(d, (d["model"] == c["model"]) & (d["tree"] == c["tree"]), "loglog_exponent")


# ---- the paper's figures (``ClaimSpec.paper``) ---------------------------------------------------
def _point(x: float) -> tuple[float, float]:
    """A single figure as ``(low, high)``."""
    return (float(x), float(x))


def _tab_psnr(c: Cell, f: Callable[[dict], float]) -> tuple[float, float]:
    """``f`` of the cell's paper tree's tab:psnr ((view, time) dB per model); none without."""
    pp = paper.PSNR.get(c.get("paper"))
    return _point(f(pp)) if pp else NO_VALUE


def _tab_null(c: Cell, f: Callable[[float, float], float]) -> tuple[float, float]:
    """``f`` of the cell's paper tree's tab:null (trained, null median omega error, %)."""
    return _point(f(*paper.NULL.get(c.get("paper"), (np.nan, np.nan))))


def _zeta_off(c: Cell) -> tuple[float, float]:
    """The paper's median zeta_hat range as |zeta_hat - 0.08| / 0.08 (its truth)."""
    z = paper.ZETA.get(c.get("paper"))
    if not z:
        return NO_VALUE
    ends = sorted(abs(float(x) - paper.ZETA_TRUE) / paper.ZETA_TRUE for x in z.split("-"))
    return (ends[0], ends[-1])


def _margin(c: Cell) -> tuple[float, float]:
    """tab:margin's last wind - its first (dB)."""
    p = paper.MARGIN.get(c.get("paper"))
    return _point(p[-1] - p[0]) if p else NO_VALUE


NULL_RATIO = Figure(
    "null / trained median omega error, tab:null",
    lambda c: _tab_null(c, lambda tr, nl: nl / tr),
    "null / trained = {v:.2f}",
)


# ---- the paper's: beyond the window and on held-out views (tab:psnr), unseen wind (tab:transfer)
_MOTION = (
    ClaimSpec(
        family="ours_above_static_beyond", over=_trees, table="tab_psnr",
        read=lambda d, c: _psnr(d, c, [c["model"]]) - _psnr(d, c, ["static"]),
        threshold="EVEN", side=">", unit="dB",
        text="{tree}: ours is above the static pose beyond the window",
        source="tab_psnr, time column: ours - static",
        paper=Figure(
            "ours - static beyond the window, tab:psnr",
            lambda c: _tab_psnr(c, lambda pp: pp["ours"][1] - pp["static"][1]),
            "{v:+.2f} dB",
        ),
        headline="ours above the static pose beyond the training window",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="baselines_below_static_beyond", over=_trees, table="tab_psnr",
        read=lambda d, c: _psnr(d, c, fields()) - _psnr(d, c, ["static"]),
        threshold="EVEN", side="<", unit="dB",
        text="{tree}: every learned baseline is below the static pose beyond the window",
        source="tab_psnr, time column: max over learned fields of (model - static)",
        paper=Figure(
            "best learned field - static beyond the window, tab:psnr",
            lambda c: _tab_psnr(c, lambda pp: max(pp[m][1] - pp["static"][1] for m in fields())),
            "best baseline - static = {v:+.2f} dB",
        ),
        headline="every learned field below static beyond the window",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="ours_behind_on_views", over=_trees, table="tab_psnr", read=_ahead_of_fields,
        threshold="EVEN", side="<", unit="dB",
        text="{tree}: ours is behind the best learned field on held-out views",
        source="tab_psnr, view column: ours - max over learned fields",
        paper=Figure(
            "ours - best learned field on held-out views, tab:psnr",
            lambda c: _tab_psnr(c, lambda pp: pp["ours"][0] - max(pp[m][0] for m in fields())),
            "{v:+.2f} dB",
        ),
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="transfer_ours_ahead", over=_winds_beyond, table="tab_transfer", read=_wind_ahead,
        threshold="EVEN", side=">", unit="dB",
        text="{tree}, {cond} v0, beyond the window: ours ahead of the best baseline",
        source="tab_transfer (beyond): ours - max learned",
        paper="ahead in every cell, by 0.38-4.68 dB",
        headline="ours ahead of the best learned field under unseen wind",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="transfer_baselines_below_static", over=_winds_beyond, table="tab_transfer",
        read=lambda d, c: _transfer(d, c, fields()) - _transfer(d, c, ["static"]),
        threshold="EVEN", side="<", unit="dB",
        text="{tree}, {cond} v0, beyond the window: every learned baseline below static",
        source="tab_transfer (beyond): max learned - static",
        paper="below static in all 24 cells, by 0.10-2.79 dB",
        one_sided=DIRECTION,
    ),
)  # fmt: skip


# ---- this project's: the two headlines above split by kind of field (wind-blind,
# wind-conditioned: the registry's ``ModelSpec.wind``), so the ledger says which kind contradicts
# the paper --------------------------------------------------------------------------------------
def _kind_cells(cells: list[Cell]) -> list[Cell]:
    """``cells`` x each kind of learned field the registry holds, the kind in the suffix after
    the tree."""
    out = []
    for c in cells:
        for k, words in FIELD_KINDS.items():
            ms = fields_of_kind(k)
            if not ms:  # a registry without fields of this kind asks nothing of it
                continue
            rest = c["suffix"].split("/", 1)[1:]  # what follows the tree (a wind), if anything
            out.append(
                {
                    **c,
                    "suffix": "/".join([c["tree"], k, *rest]),
                    "kind": k,
                    "kind_words": words,
                    "kind_fields": ", ".join(label(m) for m in ms),
                }
            )
    return out


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
        read=lambda d, c: _psnr(d, c, fields_of_kind(c["kind"])) - _psnr(d, c, ["static"]),
        threshold="EVEN", side="<", unit="dB",
        text="{tree}: every {kind_words} learned field ({kind_fields}) is below the static pose "
        "beyond the window",
        source="tab_psnr, time column: max over the {kind_words} fields of (model - static)",
        paper=Figure(
            "the kind's best learned field - static beyond the window, tab:psnr",
            lambda c: _tab_psnr(
                c, lambda pp: max(pp[m][1] - pp["static"][1] for m in fields_of_kind(c["kind"]))
            ),
            "best {kind_words} baseline - static = {v:+.2f} dB",
        ),
        origin="project",
        one_sided=KIND_DIRECTION,
    ),
    ClaimSpec(
        family="transfer_kind_below_static", over=_kind_winds_beyond, table="tab_transfer",
        read=lambda d, c: _transfer(d, c, fields_of_kind(c["kind"])) - _transfer(d, c, ["static"]),
        threshold="EVEN", side="<", unit="dB",
        text="{tree}, {cond} v0, beyond the window: every {kind_words} learned field "
        "({kind_fields}) below static",
        source="tab_transfer (beyond): max {kind_words} learned - static",
        paper="every baseline below static in all 24 cells",
        origin="project",
        one_sided=KIND_DIRECTION,
    ),
    # the paper's: the margin under unseen wind (tab:margin)
    ClaimSpec(
        family="margin_grows", over=_margin_trees, table="tab_margin", read=_margin_growth,
        threshold="EVEN", side=">", unit="dB",
        text="{tree}: the margin against MLP + wind grows as the wind departs from training",
        source="tab_margin: {last} - {first}",
        paper=Figure(
            "the margin's growth from the training wind to the farthest, tab:margin",
            _margin,
            "{v:+.2f} dB",
        ),
        one_sided=GROWS,
    ),
)  # fmt: skip


# ---- the paper's: recovery against the untrained null (tab:null, section 4) ----------------------
def _null_trees_tiled(run: Run) -> list[Cell]:
    """each tree of tiled frequencies, in the ledger's recovery configuration (joint K = 32)"""
    return [{**c, "config": CONFIG, "method": run.model} for c in _with_role(run, TILED)]


def _gap_trees(run: Run) -> list[Cell]:
    """each tree standing for a paper's tree whose nearest-bone gap the paper states"""
    return [c for c in _trees(run) if c["paper"] in paper.NEAREST_BONE_GAP_PCT]


def _gap_off(d: pd.DataFrame, c: Cell) -> float:
    """tab_testbed: |nearest-bone gap - the paper's tree's| / the paper's"""
    g = paper.NEAREST_BONE_GAP_PCT[c["paper"]]
    return abs(value(d, d["tree"] == c["tree"], "nearest_bone_gap_pct") - g) / g


def _zeta_words(c: Cell) -> str:
    """The paper's median zeta_hat range beside the truth; "--" where it gives none."""
    z = paper.ZETA.get(c.get("paper"))
    return f"median zeta_hat {z} vs {paper.ZETA_TRUE:g}" if z else "--"


def _fit_models(run: Run) -> list[Cell]:
    """each tree x each learned field, ours and every other prior the tables hold"""
    return [
        {"suffix": f"{t}/{m}", "tree": t, "fit_model": m, "fit_label": label(m)}
        for t in run.trees
        for m in (*fields(), "ours", *run.others)
    ]


_RECOVERY = (
    ClaimSpec(
        family="null_factor", over=_null_trees_separated, table="tab_null",
        read=_null_over_trained, threshold="NULL_FACTOR", side=">", unit="ratio",
        text="{tree}: ... by the paper's factor of {NULL_FACTOR:g}",
        source="{table}, {config}: null / trained",
        paper=NULL_RATIO,
        headline="ours beats the untrained null by the paper's factor on frequency",
        one_sided="a lower bound: the paper's factor or more (a larger one supports it)",
    ),
    ClaimSpec(
        family="null_loses", over=_null_trees_separated, table="tab_null",
        read=_null_over_trained, threshold="RATIO_EVEN", side=">", unit="ratio",
        text="{tree}: joint training beats the untrained null",
        source="{table}, {config}: null / trained median rel. error",
        paper=NULL_RATIO,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="null_matches", over=_null_trees_tiled, table="tab_null",
        read=_trained_minus_null, threshold="-NULL_MATCH_PP", side=">", unit="points",
        text="{tree}: the untrained null matches the trained model (it is not beaten by "
        "{NULL_MATCH_PP} points or more)",
        source="{table}, {config}: trained - null median rel. error (points)",
        paper=Figure(
            "trained - null median omega error, tab:null",
            lambda c: _tab_null(c, lambda tr, nl: tr - nl),
            "trained - null = {v:+.2f} points",
        ),
        headline="the untrained null matches ours on frequency",
        one_sided="non-inferiority of the null: the paper's point is that training adds nothing "
        "over it on these trees, which a null ahead of the trained model supports too",
    ),
    ClaimSpec(
        family="nearest_bone_gap", over=_gap_trees, table="tab_testbed", read=_gap_off,
        threshold="GAP_RTOL", side="<", unit="fraction",
        text="{tree}: the median nearest-bone gap is the paper's (within {GAP_RTOL:.0%} of it)",
        source="tab_testbed: |gap - paper| / paper",
        paper=Figure(
            "the median nearest-bone gap, section 4",
            lambda c: NO_VALUE,  # a figure of the testbed, not in the claim's unit
            lambda c: f"{paper.NEAREST_BONE_GAP_PCT[c['paper']]:.2f}%",
        ),
        needs_variance=False,
        one_sided=ABSOLUTE,
    ),
    ClaimSpec(
        family="damping_not_recovered", over=_recovered_trees, table=RECOVERY,
        read=_damping_off, threshold="DAMPING_OFF", side=">", unit="fraction",
        text="{tree}: damping is not recovered (median zeta_hat off the truth by more than "
        "{DAMPING_OFF:.0%})",
        source="recovery ({config}): |median zeta_hat - zeta| / zeta",
        paper=Figure(
            "the median fitted zeta, section 4",
            _zeta_off,
            _zeta_words,
        ),
        headline="damping is not recovered",
        one_sided="|offset| above the bar on either side: off the truth, whichever way",
    ),
    ClaimSpec(
        family="decay_rate_flat", over=_recovered_trees, table=RECOVERY,
        read=_decay_exponent, threshold="RATE_EXPONENT", side=WITHIN, unit="exponent",
        text="{tree}: the fitted decay rate gamma = zeta*omega is nearly frequency-independent "
        "(gamma ~ omega^p, |p| < {RATE_EXPONENT})",
        source="recovery ({config}): exponent p",
        paper="nearly frequency-independent",
    ),
    # the premise of every comparison: the fields fit their window (a model the paper did not
    # train makes its row this project's: ``origin_of``)
    ClaimSpec(
        family="fits_window", over=_fit_models, table="tab_fit",
        read=lambda d, c: value(
            d, (d["tree"] == c["tree"]) & (d["model"] == c["fit_model"]), "ceiling_frac"
        ),
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


def _winds(run: Run) -> list[Cell]:
    """each split (training timestamps, beyond the window) x tree x unseen wind of tab_transfer"""
    tr = run.own
    if tr is None:
        return []
    where = {"beyond": "beyond the window"}
    return [
        {
            "suffix": f"{t}/wind_{sp}/{c:.2f}",
            "tree": t,
            "condition": c,
            "cond": f"{c:.2f}",
            "split": sp,
            "where": where.get(sp, "at training timestamps"),
        }
        for (sp, t, c), _ in tr.groupby(["split", "tree", "condition"], sort=False)
    ]


def _recovery_trees(run: Run) -> list[Cell]:
    """each tree, in the ledger's recovery configuration (joint K = 32)"""
    return [{**c, "config": CONFIG, "method": run.model} for c in _trees(run)]


_PRIORS = (
    ClaimSpec(
        family="above_static_beyond", of="priors", over=_trees, table="tab_psnr",
        read=lambda d, c: _psnr(d, c, [c["model"]]) - _psnr(d, c, ["static"]),
        threshold="EVEN", side=">", unit="dB",
        text="{tree}: the {name} is above the static pose beyond the window",
        source="tab_psnr, time column: prior - static",
        origin="project",
        headline="the {name} above the static pose beyond the window",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family=AHEAD, of="priors", over=_splits, table="tab_psnr", read=_ahead_of_fields,
        threshold="EVEN", side=">", unit="dB",
        text="{tree}: the {name} is ahead of the best learned field on {where}",
        source="tab_psnr, {split} column: prior - max over learned fields",
        origin="project",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family=AHEAD, of="priors", over=_winds, table="tab_transfer", read=_wind_ahead,
        threshold="EVEN", side=">", unit="dB",
        text="{tree}, {cond} v0, {where}: the {name} is ahead of the best learned field",
        source="tab_transfer ({split}): prior - max learned",
        origin="project",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="margin_grows", of="priors", over=_margin_trees, table="tab_margin",
        read=_margin_growth, threshold="EVEN", side=">", unit="dB",
        text="{tree}: the {name}'s margin against MLP + wind grows as the wind departs",
        source="tab_margin ({model}): {last} - {first}",
        origin="project",
        one_sided=GROWS,
    ),
    ClaimSpec(
        family="beats_null", of="priors", over=_recovery_trees, table="tab_recovery",
        read=_trained_minus_null, threshold="-NULL_MATCH_PP", side="<", unit="points",
        text="{tree}: the {name} beats the untrained null on frequency recovery (by "
        "{NULL_MATCH_PP} points or more)",
        source="{table}, {config}: trained - null median rel. error (points)",
        origin="project",
        one_sided="superiority by a margin: ahead of the null by the margin or more",
    ),
    ClaimSpec(
        family="damping_recovered", of="priors", over=_recovered_trees, table=RECOVERY,
        read=_damping_off, threshold="DAMPING_OFF", side="<", unit="fraction",
        text="{tree}: the {name} recovers damping (median zeta_hat within {DAMPING_OFF:.0%} of "
        "the truth)",
        source="recovery ({config}): |median zeta_hat - zeta| / zeta",
        origin="project",
        one_sided=ABSOLUTE,
    ),
    ClaimSpec(
        family="decay_rate_flat", of="priors", over=_recovered_trees, table=RECOVERY,
        read=_decay_exponent, threshold="RATE_EXPONENT", side=WITHIN, unit="exponent",
        text="{tree}: the {name}'s fitted decay rate gamma = zeta*omega is nearly "
        "frequency-independent (gamma ~ omega^p, |p| < {RATE_EXPONENT})",
        source="recovery ({config}): exponent p",
        origin="project",
    ),
)  # fmt: skip


# ---- this project's: without the anemometer, and the output-only analysis (docs/blind.md) ------
def _blind_trees(run: Run) -> list[Cell]:
    """each forcing-free prior in tab_recovery x each tree, against the prior whose measured wind it
    replaces (ids ``<prior>/...`` for a prior other than ours)"""
    null = run.own
    if null is None or "method" not in null.columns:
        return []
    have, out = set(null["method"]), []
    for blind in (m for m in BLIND_PRIORS if m in have):
        wind = spec_of(blind).blind_of
        who, prefix = ("ours", "") if wind == "ours" else (f"the {label(wind)}", f"{wind}/")
        out += [
            {
                **c,
                "prefix": prefix,
                "blind": blind,
                "wind": wind,
                "who": who,
                "config": BLIND_CONFIG,
            }
            for c in _trees(run)
            if (null["tree"] == c["tree"]).any()
        ]
    return out


def _oma_separated(run: Run) -> list[Cell]:
    """each tree of separated frequencies, when tab_recovery holds the output-only analysis"""
    null = run.own
    if null is None or "method" not in null.columns or OMA not in set(null["method"]):
        return []
    return [{**c, "config": BLIND_CONFIG, "method": OMA} for c in _with_role(run, SEPARATED)]


def _oma_damping_trees(run: Run) -> list[Cell]:
    """each tree of tab_damping, when it holds the output-only analysis"""
    dmp = run.own
    if dmp is None or "method" not in dmp.columns or OMA not in set(dmp["method"]):
        return []
    return [{**c, "config": BLIND_CONFIG} for c in _trees(run) if (dmp["tree"] == c["tree"]).any()]


def _oma_interval_trees(run: Run) -> list[Cell]:
    """each tree of tab_damping, when it holds the output-only analysis' interval coverage"""
    dmp = run.own
    if dmp is None or "omega_interval_cover" not in dmp.columns:
        return []
    return _oma_damping_trees(run)


def _oma(d: pd.DataFrame, c: Cell, col: str) -> float:
    """tab_damping (damping testbed): the output-only analysis' ``col`` in the cell's tree and
    configuration."""
    row = (
        (d["testbed"] == DAMPING)
        & (d["tree"] == c["tree"])
        & (d["config"] == c["config"])
        & (d["method"] == OMA)
    )
    return value(d, row, col)


def _halfwidth(d: pd.DataFrame, c: Cell, q: str) -> float:
    """tab_damping: the output-only analysis' median relative half-width of its ``q``
    intervals, 1.96 sigma / value."""
    from physgs.oma.intervals import Z95  # here: scipy, which planning never loads

    return Z95 * _oma(d, c, f"{q}_rel_sd")


def _oma_intervals(q: str, name: str) -> dict[str, ClaimSpec]:
    """The three families of the output-only analysis' 95% intervals for ``q`` (``omega``,
    ``zeta``; ``name`` in the family ids: ``frequency``, ``damping``): they cover, they score
    better than the null's, they are informative."""
    intervals = f"{{tree}} (damping testbed): the output-only analysis' 95% intervals for {q}"
    common = dict(over=_oma_interval_trees, table="tab_damping", paper=PROJECT_ONLY,
                  origin="project", optional=True)  # fmt: skip
    return {
        "covers": ClaimSpec(
            family=f"oma_{name}_interval_covers", **common,
            read=lambda d, c: _oma(d, c, f"{q}_interval_cover"),
            threshold="INTERVAL_COVER", side=">", unit="fraction",
            text=f"{intervals} hold the matched bone's true {q} on at least "
            "{INTERVAL_COVER:.0%} of its trusted parts",
            source=f"{{table}}, {{config}}: output-only {q}_interval_cover",
            one_sided=COVER, requires=f"oma_{name}_interval_score",
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
            one_sided=INFORMATIVE,
        ),
    }  # fmt: skip


_OMEGA, _ZETA = _oma_intervals("omega", "frequency"), _oma_intervals("zeta", "damping")

_BLIND = (
    ClaimSpec(
        family="anemometer_needed", over=_blind_trees, table="tab_recovery",
        read=lambda d, c: (
            value(d, _null_row(d, c, c["blind"]), "trained_median_rel_err_pct")
            - value(d, _null_row(d, c, c["wind"]), "trained_median_rel_err_pct")
        ),
        threshold="EVEN", side=">", unit="pp",
        text="{tree}: without the measured wind (a learned forcing) {who} recovers omega worse",
        source="{table}, {config}: {blind} - {wind} median rel. error (points)",
        paper="the paper's closing limit: 'real footage needs an anemometer'",
        origin="project",
        headline="without the anemometer (a learned forcing), ours' frequency error grows "
        "(points)",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="oma_beats_null", over=_oma_separated, table="tab_recovery",
        read=_null_over_trained, threshold="RATIO_EVEN", side=">", unit="ratio",
        text="{tree}: output-only modal analysis of the video recovers omega better than the "
        "untrained null",
        source="{table}, {config}: null / output-only median rel. error",
        paper="not run",
        origin="project",
        headline="output-only modal analysis of the video beats the untrained null",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="oma_recovers_zeta", over=_oma_damping_trees, table="tab_damping",
        read=lambda d, c: _oma(d, c, "trained_minus_null_pp"),
        threshold="EVEN", side="<", unit="pp",
        text="{tree} (damping testbed): output-only modal analysis recovers zeta better than "
        "the untrained null",
        source="tab_damping, {config}: output-only - null median zeta error (points)",
        paper="no method here recovers zeta (the paper)",
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
    _OMEGA["covers"],
    _ZETA["covers"],
    _OMEGA["score"],
    _OMEGA["informative"],
    _ZETA["score"],
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
    if df is None or "ours_topo" not in models:
        return []
    return [
        {**c, "config": c0}
        for c in _trees(run)
        if np.isfinite(df.loc[df["tree"] == c["tree"], "zeta_rel_err_pct"]).any()
    ]


def _parts_coupling(run: Run) -> list[Cell]:
    """each tree of separated frequencies in tab_parts (its first configuration), when it holds
    both topology priors (no id suffix for a single such tree: the family's id as before)"""
    df, models, c0 = _parts(run)
    if df is None or not {"ours_topo", "ours_chain"} <= models:
        return []
    cells = _with_role(run, SEPARATED)
    one = len(cells) == 1
    return [{**c, "suffix": "" if one else c["tree"], "config": c0} for c in cells]


def _parts_gain(d: pd.DataFrame, c: Cell, better: str, base: str, col: str) -> float:
    """tab_parts: ``col`` of parts ``better`` - of parts ``base`` in the cell's tree and
    configuration."""
    row = (d["tree"] == c["tree"]) & (d["config"] == c["config"])
    return value(d, row & (d["model"] == better), col) - value(d, row & (d["model"] == base), col)


_PARTS = (
    ClaimSpec(
        family="topology_parts_reduce_damping_error", over=_parts_damping_trees,
        table="tab_parts",
        read=lambda d, c: _parts_gain(d, c, "ours_topo", "ours", "zeta_rel_err_pct"),
        threshold="EVEN", side="<", unit="pp",
        text="{tree}: topology-aware parts reduce the damping error (damping testbed)",
        source="tab_parts ({config}): median rel. err. of zeta, topology - k-means parts",
        paper="hypothesis (k-means parts 'plausibly feed the damping bias')",
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="coupling_lifts_sparse_fit", over=_parts_coupling, table="tab_parts",
        read=lambda d, c: _parts_gain(d, c, "ours_chain", "ours_topo", "ceiling_frac"),
        threshold="EVEN", side=">", unit="fraction",
        text="{tree}: parent-child coupling lifts the in-window fit",
        source="tab_parts ({config}): fraction of the ceiling's gain, chained - independent "
        "topology parts",
        paper="hypothesis (independent parts 'represent no coupling')",
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
)  # fmt: skip


# ---- this project's: the 2D-track control (docs/tracks.md) ---------------------------------------
def _tracks_separated(run: Run) -> list[Cell]:
    """each tree of separated frequencies, the 2D-track control's recovery in joint K = 32
    (else its first configuration)"""
    null = run.own
    if null is None or "method" not in null.columns:
        return []
    cfgs = list(dict.fromkeys(null.loc[null["method"] == "tracks", "config"]))
    if not cfgs:
        return []
    c = CONFIG if CONFIG in cfgs else cfgs[0]
    return [{**x, "config": c, "method": "tracks"} for x in _with_role(run, SEPARATED)]


def _tracks_minus_ours(d: pd.DataFrame, c: Cell) -> float:
    """tab_recovery: 2D tracks - ours median omega error (points); NaN at another K than ours'"""
    tracks, ours = _null_row(d, c), _null_row(d, c, "ours")
    if value(d, tracks, "K") != value(d, ours, "K"):
        return float("nan")  # another K: not the same question
    col = "trained_median_rel_err_pct"
    return value(d, tracks, col) - value(d, ours, col)


def _tracks_trees(run: Run) -> list[Cell]:
    """each tree in tab_tracks, its base configuration (else its first)"""
    tr = run.own
    if tr is None:
        return []
    tc = list(dict.fromkeys(tr["config"]))
    if not tc:
        return []
    c = "single" if "single" in tc else tc[0]
    return [{**x, "config": c} for x in _trees(run) if (tr["tree"] == x["tree"]).any()]


def _tracks_tail(d: pd.DataFrame, c: Cell) -> float:
    """tab_tracks: tail displacement error, 2D tracks - ours (px)"""
    row = (d["tree"] == c["tree"]) & (d["config"] == c["config"])
    return value(d, row, "tail_px") - value(d, row, "tail_ours_px")


_TRACKS = (
    ClaimSpec(
        family="tracks_beats_null", over=_tracks_separated, table="tab_recovery",
        read=_null_over_trained, threshold="RATIO_EVEN", side=">", unit="ratio",
        text="{tree}: oscillators fitted to 2D tracks recover omega better than the untrained "
        "null",
        source="{table}, 2D tracks {config}: null / tracks median rel. error",
        paper=TRACKS_PROPOSAL,
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        family="tracks_match_ours", over=_tracks_separated, table="tab_recovery",
        read=_tracks_minus_ours, threshold="NULL_MATCH_PP", side="<", unit="points",
        text="{tree}: oscillators fitted to 2D tracks match ours' omega recovery (ours does not "
        "beat them by {NULL_MATCH_PP} points or more)",
        source="{table}, {config}: 2D tracks - ours median rel. error (points)",
        paper=TRACKS_PROPOSAL,
        origin="project",
        optional=True,
        one_sided=NON_INFERIOR,
    ),
    ClaimSpec(
        family="tracks_extrapolate_as_ours", over=_tracks_trees, table="tab_tracks",
        read=_tracks_tail, threshold="EVEN", side="<", unit="px",
        text="{tree}: beyond the window, oscillators fitted to 2D tracks predict the tracked "
        "points at least as well as ours' Gaussians",
        source="tab_tracks, {config}: tail displacement error, 2D tracks - ours (px)",
        paper=TRACKS_PROPOSAL,
        origin="project",
        optional=True,
        one_sided=NON_INFERIOR,
    ),
)  # fmt: skip

#: Every claim family, in the ledger's order.
CATALOGUE: tuple[ClaimSpec, ...] = (
    *_MOTION,
    *_KINDS,
    *_RECOVERY,
    *_PRIORS,
    *_BLIND,
    *_PARTS,
    *_TRACKS,
)


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


# ---- derived from the catalogue ----------------------------------------------------------------
def tables(optional: bool = True) -> tuple[str, ...]:
    """The tables the ledger reads, in catalogue order.

    Args:
        optional: include the tables only some runs make (``ClaimSpec.optional``).

    Returns:
        Table names (the recovery summaries are not a table: ``reads_recovery``).
    """
    required = {s.table for s in CATALOGUE if not s.optional}
    every = dict.fromkeys(s.table for s in CATALOGUE if s.table != RECOVERY)
    return tuple(t for t in every if optional or t in required)


def required_tables() -> tuple[str, ...]:
    """The tables every run's ledger reads.

    Returns:
        Table names (a missing one leaves its claims "undecided: not measured").
    """
    return tables(optional=False)


def prior_tables() -> tuple[str, ...]:
    """The tables whose rows or columns say that a run holds a prior other than ours.

    Returns:
        The tables of the ``of="priors"`` families.
    """
    return tuple(
        dict.fromkeys(s.table for s in CATALOGUE if s.of == "priors" and s.table != RECOVERY)
    )


def reads_recovery() -> bool:
    """Whether any family reads the priors' recovery records.

    Returns:
        True when a family's table is ``RECOVERY``.
    """
    return any(s.table == RECOVERY for s in CATALOGUE)


def _name(model: str) -> str:
    """A prior's label as words inside a sentence (its first letter lower case)."""
    name = label(model)
    return name[0].lower() + name[1:]


def headline(priors: Sequence[str] | None = None) -> list[tuple[str, str, str]]:
    """The families that carry the story, in catalogue order: ``(id prefix, words, origin)``;
    a family asked of the priors gives one per prior other than ours.

    Args:
        priors: the priors other than ours (default: the registry's).

    Returns:
        One triple per headline family.
    """
    others = [m for m in models_of("prior") if m != "ours"] if priors is None else priors
    out = []
    for s in CATALOGUE:
        if not s.headline:
            continue
        if s.of == "ours":
            out.append((s.family, s.headline, s.origin))
        else:
            out += [(f"{m}/{s.family}", s.headline.format(name=_name(m)), s.origin) for m in others]
    return out


_MODEL_IDS = set(MODELS) | set(PRIOR_VARIANTS)
# a premise names a family of the catalogue (a renamed family must not turn it into a finding)
if not set(PREMISES) <= {s.family for s in CATALOGUE}:
    raise ValueError(f"PREMISES: no family {sorted(set(PREMISES) - {s.family for s in CATALOGUE})}")


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


def _family(claim_id: str) -> str:
    """The family of a claim id (``[<prior>/]<family>[/<cell>]``)."""
    parts = claim_id.split("/")
    return parts[1] if parts[0] in _MODEL_IDS and len(parts) > 1 else parts[0]


def kind_of(claim_id: str) -> str:
    """Whether a claim is a premise of the comparison or a finding (``KINDS``): its family's
    entry in ``PREMISES``.

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
    """A sentence template as the claims page shows it: thresholds filled in, the cell's fields
    as ``<field>``."""
    out = []
    for lit, field, spec, _ in string.Formatter().parse(text):
        out.append(lit)
        if field is None:
            continue
        if field in WORDS:
            out.append(format(WORDS[field], spec or ""))
        elif field == "name":
            out.append("<prior>")
        elif field == "table":
            out.append(table)
        else:
            out.append(f"<{field}>")
    return "".join(out)


def _doc(fn) -> str:
    """A function's docstring's first paragraph, on one line."""
    return " ".join((fn.__doc__ or fn.__name__).strip().split("\n\n")[0].split())


BEGIN, END = "<!-- catalogue:begin -->", "<!-- catalogue:end -->"


def markdown() -> str:
    """The claims page's list of claims (``docs/claims.md``, between ``BEGIN`` and ``END``),
    one row per family: generated, never typed (``tools/claims_reference.py``).

    Returns:
        The block, markers included.
    """
    head = [
        BEGIN,
        "",
        "<!-- no verdict -->",  # thresholds and the paper's figures: the record states verdicts
        "| family | asked of, over | claim | threshold | test | reads | the paper | origin |",
        "|---|---|---|---|---|---|---|---|",
    ]
    rows = []
    for s in CATALOGUE:
        fam = f"`{s.family}`" if s.of == "ours" else f"`<prior>/{s.family}`"
        if s.headline:
            fam += " (headline)"
        if s.family in PREMISES:
            fam += " (premise)"
        over = ("ours" if s.of == "ours" else "every other prior") + ", " + _doc(s.over)
        thr = s.threshold.lstrip("-")
        sign = "-" if s.threshold.startswith("-") else ""
        figure = s.paper.what if isinstance(s.paper, Figure) else _template(s.paper)
        figure = "this project" if figure == "--" else figure
        cells = [
            fam,
            over,
            _template(s.text),
            f"{s.side} {sign}`{thr}` = {s.value:g} {s.unit}"
            if s.side != WITHIN
            else f"within ±`{thr}` = {s.value:g} {s.unit}",
            "equivalence (inside the band)" if s.side == WITHIN else f"one-sided: {s.one_sided}",
            f"{_template(s.source, s.table)}{' (optional)' if s.optional else ''}",
            figure,
            s.origin,
        ]
        rows.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join([*head, *rows, "", END])
