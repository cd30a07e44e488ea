"""The catalogue of claims: every claim family of the ledger as one entry of data.

An entry ([`ClaimSpec`][physgs.report.catalogue.ClaimSpec]) says what the family ranges over
(its scope: trees, cells of a table, and, for ``of="priors"``, every prior of the registry other
than ours that the run's tables hold), the table and the cells it reads, its threshold (a name
of [`physgs.report.thresholds`][physgs.report.thresholds]) and side, its unit, its sentence, the
paper's figure, whether it carries the story (a headline, with the words the README uses), and
its origin: the paper's claim, or this project's own. [`physgs.report.claims.measure`][] loops
over it; the tables the ledger reads, the README's headline families and the list of claims on
the claims page ([`markdown`][physgs.report.catalogue.markdown]) are derived from it.

Adding a claim family is one entry here (and, when no reader or scope fits, one function in
[`physgs.report.claim_cells`][physgs.report.claim_cells]).

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

from physgs.models.registry import MODELS, PRIOR_VARIANTS, label, models_of
from physgs.report import claim_cells as cc
from physgs.report import paper, thresholds
from physgs.report.claim_cells import CONFIG, READERS, RECOVERY, SCOPES, Cell

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


@dataclass(frozen=True)
class ClaimSpec:
    """One claim family of the ledger.

    Attributes:
        family: the claim id's family (ids are ``[<prior>/]<family>[/<cell>]``).
        of: ``"ours"`` (asked once) or ``"priors"`` (asked of every prior of the registry other
            than ours that the run's tables hold, ids prefixed by the prior's).
        over: its scope, a name of ``claim_cells.SCOPES`` (the run -> the family's cells).
        table: the table it reads (``claim_cells.RECOVERY``: the priors' damping summaries).
        read: its reader, a name of ``claim_cells.READERS`` (one seed's rows and a cell -> the
            value).
        threshold: a name of ``physgs.report.thresholds``, ``-`` in front to negate it.
        side: ``">"`` or ``"<"``: the side of the threshold the claim holds on; ``WITHIN``: an
            equivalence claim (flat, equal, matching), inside (-threshold, +threshold).
        unit: the value's unit (``"ratio"``: its interval is taken on the log scale).
        text: the claim's sentence (``str.format`` fields: the cell's, ``name`` of the prior,
            ``WORDS``).
        source: where it is measured (same fields, and ``table``).
        paper: the paper's figure, or a function of the cell giving it.
        origin: ``"paper"`` or ``"project"`` (``ORIGINS``).
        headline: the words the README tells the family with; "" when it is not a headline.
        needs_variance: False for a claim about the fixed testbed (a verdict from one value).
        optional: listed only when its table is given (a study or control the run may not
            make); otherwise a missing table lists its claims "undecided: not measured".
        one_sided: why a one-sided test (``">"``, ``"<"``) is the claim's own test; required
            for every side but ``WITHIN``: a claim of flatness, equality or match is tested
            inside a band, never one-sided without a stated reason.
        paper_value: the paper's figure in the claim's unit, ``(low, high)`` (equal ends for
            one figure); None where the paper gives no number.
        requires: a family whose claim on the same cell must hold for this one to hold (a
            coverage holds only where its intervals also beat the null's interval score); ""
            for none.
    """

    family: str
    of: str
    over: str
    table: str
    read: str
    threshold: str
    side: str
    unit: str
    text: str
    source: str
    paper: str | Callable[[Cell], str] = "--"
    origin: str = "paper"
    headline: str = ""
    needs_variance: bool = True
    optional: bool = False
    one_sided: str = ""
    paper_value: Callable[[Cell], tuple[float, float]] | None = None
    requires: str = ""

    def __post_init__(self):
        """Refuse an unknown side, origin, scope, reader or threshold name, a one-sided claim
        without its reason, and an equivalence band on a ratio, naming the family."""
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
        if self.over not in SCOPES or self.read not in READERS:
            raise ValueError(
                f"claim {self.family!r}: no scope {self.over!r} or reader {self.read!r}"
            )

    @property
    def value(self) -> float:
        """The threshold's value."""
        v = float(WORDS[self.threshold.lstrip("-")])
        return -v if self.threshold.startswith("-") else v

    def cells(self, run: cc.Run) -> list[Cell]:
        """The family's cells in ``run`` (its scope).

        Args:
            run: what the family is asked of.

        Returns:
            One cell per claim.
        """
        return SCOPES[self.over](run)

    def measure(self, rows: pd.DataFrame, cell: Cell) -> float:
        """One seed's value of the claim of ``cell`` (its reader).

        Args:
            rows: one seed's rows of the family's table.
            cell: the claim's cell.

        Returns:
            The value, in ``unit``; NaN where the rows are not there.
        """
        return float(READERS[self.read](rows, cell))

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
        return self.paper_value(cell) if self.paper_value else NO_VALUE

    def figure(self, cell: Cell) -> str:
        """The paper's figure for the claim of ``cell``.

        Args:
            cell: the claim's cell.

        Returns:
            ``paper``, filled in or computed.
        """
        return self.paper(cell) if callable(self.paper) else self.words(self.paper, cell)


# ---- the paper's figures ---------------------------------------------------------------------
#: A paper's value in a claim's unit: (low, high), equal ends for a single figure; NaN: none.
NO_VALUE = (float("nan"), float("nan"))


def _paper_tree(c: Cell) -> str | None:
    """The paper's tree the cell's tree stands for (its preset's ``role.paper``)."""
    return c.get("paper")


def _pp(c: Cell):
    return paper.PSNR.get(_paper_tree(c))


def _point(x: float) -> tuple[float, float]:
    return (float(x), float(x))


def _value_best_field_minus_static(c: Cell) -> tuple[float, float]:
    pp = _pp(c)
    return _point(max(pp[m][1] - pp["static"][1] for m in cc.fields())) if pp else NO_VALUE


def _value_kind_minus_static(c: Cell) -> tuple[float, float]:
    pp = _pp(c)
    ms = cc.fields_of_kind(c["kind"])
    return _point(max(pp[m][1] - pp["static"][1] for m in ms)) if pp else NO_VALUE


def _value_ours_minus_static(c: Cell) -> tuple[float, float]:
    pp = _pp(c)
    return _point(pp["ours"][1] - pp["static"][1]) if pp else NO_VALUE


def _value_ours_behind(c: Cell) -> tuple[float, float]:
    pp = _pp(c)
    return _point(pp["ours"][0] - max(pp[m][0] for m in cc.fields())) if pp else NO_VALUE


def _value_null_ratio(c: Cell) -> tuple[float, float]:
    tr, nl = paper.NULL.get(_paper_tree(c), (np.nan, np.nan))
    return _point(nl / tr)


def _value_null_difference(c: Cell) -> tuple[float, float]:
    tr, nl = paper.NULL.get(_paper_tree(c), (np.nan, np.nan))
    return _point(tr - nl)


def _value_margin(c: Cell) -> tuple[float, float]:
    p = paper.MARGIN.get(_paper_tree(c))
    return _point(p[-1] - p[0]) if p else NO_VALUE


def _value_zeta_off(c: Cell) -> tuple[float, float]:
    """The paper's median zeta_hat range as |zeta_hat - 0.08| / 0.08 (its truth)."""
    z = paper.ZETA.get(_paper_tree(c))
    if not z:
        return NO_VALUE
    ends = sorted(abs(float(x) - paper.ZETA_TRUE) / paper.ZETA_TRUE for x in z.split("-"))
    return (ends[0], ends[-1])


def _paper_best_field_minus_static(c: Cell) -> str:
    """best learned field - static beyond the window, tab:psnr"""
    v = _value_best_field_minus_static(c)[0]
    return f"best baseline - static = {v:+.2f} dB" if np.isfinite(v) else "--"


def _paper_kind_minus_static(c: Cell) -> str:
    """the kind's best learned field - static beyond the window, tab:psnr"""
    v = _value_kind_minus_static(c)[0]
    return f"best {c['kind_words']} baseline - static = {v:+.2f} dB" if np.isfinite(v) else "--"


def _paper_ours_minus_static(c: Cell) -> str:
    """ours - static beyond the window, tab:psnr"""
    v = _value_ours_minus_static(c)[0]
    return f"{v:+.2f} dB" if np.isfinite(v) else "--"


def _paper_ours_behind(c: Cell) -> str:
    """ours - best learned field on held-out views, tab:psnr"""
    v = _value_ours_behind(c)[0]
    return f"{v:+.2f} dB" if np.isfinite(v) else "--"


def _paper_null_ratio(c: Cell) -> str:
    """null / trained median omega error, tab:null"""
    v = _value_null_ratio(c)[0]
    return f"null / trained = {v:.2f}" if np.isfinite(v) else "--"


def _paper_null_difference(c: Cell) -> str:
    """trained - null median omega error, tab:null"""
    v = _value_null_difference(c)[0]
    return f"trained - null = {v:+.2f} points" if np.isfinite(v) else "--"


def _paper_gap(c: Cell) -> str:
    """the median nearest-bone gap, section 4"""
    return f"{paper.NEAREST_BONE_GAP_PCT[c['paper']]:.2f}%"


def _paper_zeta(c: Cell) -> str:
    """the median fitted zeta, section 4"""
    z = paper.ZETA.get(_paper_tree(c))
    return f"median zeta_hat {z} vs {paper.ZETA_TRUE:g}" if z else "--"


def _paper_margin(c: Cell) -> str:
    """the margin's growth from the training wind to the farthest, tab:margin"""
    v = _value_margin(c)[0]
    return f"{v:+.2f} dB" if np.isfinite(v) else "--"


TRACKS_PROPOSAL = "not run (the paper's closing proposal)"

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

# ---- the catalogue ---------------------------------------------------------------------------
#: Every claim family, in the ledger's order.
CATALOGUE: tuple[ClaimSpec, ...] = (
    # the paper's: beyond the window and on held-out views (tab:psnr)
    ClaimSpec(
        "ours_above_static_beyond", "ours", "trees", "tab_psnr", "above_static",
        "EVEN", ">", "dB",
        "{tree}: ours is above the static pose beyond the window",
        "tab_psnr, time column: ours - static",
        _paper_ours_minus_static,
        headline="ours above the static pose beyond the training window",
        one_sided=DIRECTION,
        paper_value=_value_ours_minus_static,
    ),
    ClaimSpec(
        "baselines_below_static_beyond", "ours", "trees", "tab_psnr",
        "best_field_minus_static", "EVEN", "<", "dB",
        "{tree}: every learned baseline is below the static pose beyond the window",
        "tab_psnr, time column: max over learned fields of (model - static)",
        _paper_best_field_minus_static,
        headline="every learned field below static beyond the window",
        one_sided=DIRECTION,
        paper_value=_value_best_field_minus_static,
    ),
    ClaimSpec(
        "ours_behind_on_views", "ours", "trees", "tab_psnr", "ahead_of_fields",
        "EVEN", "<", "dB",
        "{tree}: ours is behind the best learned field on held-out views",
        "tab_psnr, view column: ours - max over learned fields",
        _paper_ours_behind,
        one_sided=DIRECTION,
        paper_value=_value_ours_behind,
    ),
    # the paper's: unseen wind (tab:transfer, tab:margin)
    ClaimSpec(
        "transfer_ours_ahead", "ours", "winds_beyond", "tab_transfer", "wind_ahead",
        "EVEN", ">", "dB",
        "{tree}, {cond} v0, beyond the window: ours ahead of the best baseline",
        "tab_transfer (beyond): ours - max learned",
        "ahead in every cell, by 0.38-4.68 dB",
        headline="ours ahead of the best learned field under unseen wind",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        "transfer_baselines_below_static", "ours", "winds_beyond", "tab_transfer",
        "wind_fields_minus_static", "EVEN", "<", "dB",
        "{tree}, {cond} v0, beyond the window: every learned baseline below static",
        "tab_transfer (beyond): max learned - static",
        "below static in all 24 cells, by 0.10-2.79 dB",
        one_sided=DIRECTION,
    ),
    # this project's: the two headlines above split by kind of field (wind-blind,
    # wind-conditioned: the registry's ``ModelSpec.wind``), so the ledger says which kind
    # contradicts the paper
    ClaimSpec(
        "kind_below_static_beyond", "ours", "kind_trees", "tab_psnr", "kind_minus_static",
        "EVEN", "<", "dB",
        "{tree}: every {kind_words} learned field ({kind_fields}) is below the static pose "
        "beyond the window",
        "tab_psnr, time column: max over the {kind_words} fields of (model - static)",
        _paper_kind_minus_static,
        origin="project",
        one_sided=KIND_DIRECTION,
        paper_value=_value_kind_minus_static,
    ),
    ClaimSpec(
        "transfer_kind_below_static", "ours", "kind_winds_beyond", "tab_transfer",
        "wind_kind_minus_static", "EVEN", "<", "dB",
        "{tree}, {cond} v0, beyond the window: every {kind_words} learned field "
        "({kind_fields}) below static",
        "tab_transfer (beyond): max {kind_words} learned - static",
        "every baseline below static in all 24 cells",
        origin="project",
        one_sided=KIND_DIRECTION,
    ),
    ClaimSpec(
        "margin_grows", "ours", "margin_trees", "tab_margin", "margin_growth",
        "EVEN", ">", "dB",
        "{tree}: the margin against MLP + wind grows as the wind departs from training",
        "tab_margin: {last} - {first}",
        _paper_margin,
        one_sided="a direction: the margin grows, not by how much",
        paper_value=_value_margin,
    ),
    # the paper's: recovery against the untrained null (tab:null, section 4)
    ClaimSpec(
        "null_factor", "ours", "null_trees_separated", "tab_null", "null_over_trained",
        "NULL_FACTOR", ">", "ratio",
        "{tree}: ... by the paper's factor of {NULL_FACTOR:g}",
        "{table}, {config}: null / trained",
        _paper_null_ratio,
        headline="ours beats the untrained null by the paper's factor on frequency",
        one_sided="a lower bound: the paper's factor or more (a larger one supports it)",
        paper_value=_value_null_ratio,
    ),
    ClaimSpec(
        "null_loses", "ours", "null_trees_separated", "tab_null", "null_over_trained",
        "RATIO_EVEN", ">", "ratio",
        "{tree}: joint training beats the untrained null",
        "{table}, {config}: null / trained median rel. error",
        _paper_null_ratio,
        one_sided=DIRECTION,
        paper_value=_value_null_ratio,
    ),
    ClaimSpec(
        "null_matches", "ours", "null_trees_tiled", "tab_null", "trained_minus_null",
        "-NULL_MATCH_PP", ">", "points",
        "{tree}: the untrained null matches the trained model (it is not beaten by "
        "{NULL_MATCH_PP} points or more)",
        "{table}, {config}: trained - null median rel. error (points)",
        _paper_null_difference,
        headline="the untrained null matches ours on frequency",
        one_sided="non-inferiority of the null: the paper's point is that training adds nothing over it on these trees, which a null ahead of the trained model supports too",
        paper_value=_value_null_difference,
    ),
    ClaimSpec(
        "nearest_bone_gap", "ours", "gap_trees", "tab_testbed", "gap_off",
        "GAP_RTOL", "<", "fraction",
        "{tree}: the median nearest-bone gap is the paper's (within {GAP_RTOL:.0%} of it)",
        "tab_testbed: |gap - paper| / paper",
        _paper_gap,
        needs_variance=False,
        one_sided=ABSOLUTE,
    ),
    ClaimSpec(
        "damping_not_recovered", "ours", "recovered_trees", RECOVERY, "damping_off",
        "DAMPING_OFF", ">", "fraction",
        "{tree}: damping is not recovered (median zeta_hat off the truth by more than "
        "{DAMPING_OFF:.0%})",
        "recovery ({config}): |median zeta_hat - zeta| / zeta",
        _paper_zeta,
        headline="damping is not recovered",
        one_sided="|offset| above the bar on either side: off the truth, whichever way",
        paper_value=_value_zeta_off,
    ),
    ClaimSpec(
        "decay_rate_flat", "ours", "recovered_trees", RECOVERY, "decay_exponent",
        "RATE_EXPONENT", WITHIN, "exponent",
        "{tree}: the fitted decay rate gamma = zeta*omega is nearly frequency-independent "
        "(gamma ~ omega^p, |p| < {RATE_EXPONENT})",
        "recovery ({config}): exponent p",
        "nearly frequency-independent",
    ),
    # the premise of every comparison: the fields fit their window (a model the paper did not
    # train makes its row this project's: ``origin_of``)
    ClaimSpec(
        "fits_window", "ours", "fit_models", "tab_fit", "fit_fraction",
        "FIT_BAR", ">", "fraction",
        "{tree}: {fit_label} fits its training window (reaches {FIT_BAR:.0%} of the "
        "true-motion ceiling's in-window gain over static)",
        "tab_fit: (fit - static) / (ceiling - static) on the trained frames",
        "the fields 'fit the training window well'",
        one_sided="a bar: the premise is that a field fits at least this well",
    ),
    # this project's: the paper's claims about ours asked again of every other prior
    ClaimSpec(
        "above_static_beyond", "priors", "trees", "tab_psnr", "above_static",
        "EVEN", ">", "dB",
        "{tree}: the {name} is above the static pose beyond the window",
        "tab_psnr, time column: prior - static",
        origin="project",
        headline="the {name} above the static pose beyond the window",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        AHEAD, "priors", "splits", "tab_psnr", "ahead_of_fields",
        "EVEN", ">", "dB",
        "{tree}: the {name} is ahead of the best learned field on {where}",
        "tab_psnr, {split} column: prior - max over learned fields",
        origin="project",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        AHEAD, "priors", "winds", "tab_transfer", "wind_ahead",
        "EVEN", ">", "dB",
        "{tree}, {cond} v0, {where}: the {name} is ahead of the best learned field",
        "tab_transfer ({split}): prior - max learned",
        origin="project",
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        "margin_grows", "priors", "margin_trees", "tab_margin", "margin_growth",
        "EVEN", ">", "dB",
        "{tree}: the {name}'s margin against MLP + wind grows as the wind departs",
        "tab_margin ({model}): {last} - {first}",
        origin="project",
        one_sided="a direction: the margin grows, not by how much",
    ),
    ClaimSpec(
        "beats_null", "priors", "recovery_trees", "tab_recovery", "trained_minus_null",
        "-NULL_MATCH_PP", "<", "points",
        "{tree}: the {name} beats the untrained null on frequency recovery (by "
        "{NULL_MATCH_PP} points or more)",
        "{table}, {config}: trained - null median rel. error (points)",
        origin="project",
        one_sided="superiority by a margin: ahead of the null by the margin or more",
    ),
    ClaimSpec(
        "damping_recovered", "priors", "recovered_trees", RECOVERY, "damping_off",
        "DAMPING_OFF", "<", "fraction",
        "{tree}: the {name} recovers damping (median zeta_hat within {DAMPING_OFF:.0%} of the "
        "truth)",
        "recovery ({config}): |median zeta_hat - zeta| / zeta",
        origin="project",
        one_sided=ABSOLUTE,
    ),
    ClaimSpec(
        "decay_rate_flat", "priors", "recovered_trees", RECOVERY, "decay_exponent",
        "RATE_EXPONENT", WITHIN, "exponent",
        "{tree}: the {name}'s fitted decay rate gamma = zeta*omega is nearly "
        "frequency-independent (gamma ~ omega^p, |p| < {RATE_EXPONENT})",
        "recovery ({config}): exponent p",
        origin="project",
    ),
    # this project's: without the anemometer, and the output-only analysis (docs/blind.md)
    ClaimSpec(
        "anemometer_needed", "ours", "blind_trees", "tab_recovery", "blind_minus_wind",
        "EVEN", ">", "pp",
        "{tree}: without the measured wind (a learned forcing) {who} recovers omega worse",
        "{table}, {config}: {blind} - {wind} median rel. error (points)",
        "the paper's closing limit: 'real footage needs an anemometer'",
        origin="project",
        headline="without the anemometer (a learned forcing), ours' frequency error grows "
        "(points)",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        "oma_beats_null", "ours", "oma_separated", "tab_recovery", "null_over_trained",
        "RATIO_EVEN", ">", "ratio",
        "{tree}: output-only modal analysis of the video recovers omega better than the "
        "untrained null",
        "{table}, {config}: null / output-only median rel. error",
        "not run",
        origin="project",
        headline="output-only modal analysis of the video beats the untrained null",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        "oma_recovers_zeta", "ours", "oma_damping_trees", "tab_damping", "oma_zeta_gain",
        "EVEN", "<", "pp",
        "{tree} (damping testbed): output-only modal analysis recovers zeta better than the "
        "untrained null",
        "tab_damping, {config}: output-only - null median zeta error (points)",
        "no method here recovers zeta (the paper)",
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        "oma_frequency_interval_covers", "ours", "oma_interval_trees", "tab_damping",
        "oma_omega_cover", "INTERVAL_COVER", ">", "fraction",
        "{tree} (damping testbed): the output-only analysis' 95% intervals for omega hold the "
        "matched bone's true omega on at least {INTERVAL_COVER:.0%} of its trusted parts",
        "{table}, {config}: output-only omega_interval_cover",
        "not in the paper (this project's)",
        origin="project",
        optional=True,
        one_sided=COVER,
        requires="oma_frequency_interval_score",
    ),
    ClaimSpec(
        "oma_damping_interval_covers", "ours", "oma_interval_trees", "tab_damping",
        "oma_zeta_cover", "INTERVAL_COVER", ">", "fraction",
        "{tree} (damping testbed): the output-only analysis' 95% intervals for zeta hold the "
        "matched bone's true zeta on at least {INTERVAL_COVER:.0%} of its trusted parts",
        "{table}, {config}: output-only zeta_interval_cover",
        "not in the paper (this project's)",
        origin="project",
        optional=True,
        one_sided=COVER,
        requires="oma_damping_interval_score",
    ),
    ClaimSpec(
        "oma_frequency_interval_score", "ours", "oma_interval_trees", "tab_damping",
        "oma_omega_score", "RATIO_EVEN", ">", "ratio",
        "{tree} (damping testbed): the output-only analysis' 95% intervals for omega score "
        "better than the untrained null's draw range (interval score, Gneiting and Raftery "
        "2007: width plus 2/alpha times the miss, per part, relative to the truth)",
        "{table}, {config}: omega_null_interval_score / omega_interval_score",
        "not in the paper (this project's)",
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        "oma_frequency_interval_informative", "ours", "oma_interval_trees", "tab_damping",
        "oma_omega_halfwidth", "INFORMATIVE_HALFWIDTH", "<", "fraction",
        "{tree} (damping testbed): the output-only analysis' 95% intervals for omega are "
        "informative (median half-width below {INFORMATIVE_HALFWIDTH:.0%} of the value: the "
        "interval excludes zero)",
        "{table}, {config}: 1.96 x output-only omega_rel_sd",
        "not in the paper (this project's)",
        origin="project",
        optional=True,
        one_sided="a bar: an interval at most this wide says something; narrower never hurts "
        "(its misses are the interval score's)",
    ),
    ClaimSpec(
        "oma_damping_interval_score", "ours", "oma_interval_trees", "tab_damping",
        "oma_zeta_score", "RATIO_EVEN", ">", "ratio",
        "{tree} (damping testbed): the output-only analysis' 95% intervals for zeta score "
        "better than the untrained null's draw range (interval score, Gneiting and Raftery "
        "2007: width plus 2/alpha times the miss, per part, relative to the truth)",
        "{table}, {config}: zeta_null_interval_score / zeta_interval_score",
        "not in the paper (this project's)",
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        "oma_damping_interval_informative", "ours", "oma_interval_trees", "tab_damping",
        "oma_zeta_halfwidth", "INFORMATIVE_HALFWIDTH", "<", "fraction",
        "{tree} (damping testbed): the output-only analysis' 95% intervals for zeta are "
        "informative (median half-width below {INFORMATIVE_HALFWIDTH:.0%} of the value: the "
        "interval excludes zero)",
        "{table}, {config}: 1.96 x output-only zeta_rel_sd",
        "not in the paper (this project's)",
        origin="project",
        optional=True,
        one_sided="a bar: an interval at most this wide says something; narrower never hurts "
        "(its misses are the interval score's)",
    ),
    # this project's: the paper's two hypotheses about its prior (section 6), tested
    ClaimSpec(
        "topology_parts_reduce_damping_error", "ours", "parts_damping_trees", "tab_parts",
        "topology_damping_gain", "EVEN", "<", "pp",
        "{tree}: topology-aware parts reduce the damping error (damping testbed)",
        "tab_parts ({config}): median rel. err. of zeta, topology - k-means parts",
        "hypothesis (k-means parts 'plausibly feed the damping bias')",
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        "coupling_lifts_sparse_fit", "ours", "parts_coupling", "tab_parts", "coupling_gain",
        "EVEN", ">", "fraction",
        "{tree}: parent-child coupling lifts the in-window fit",
        "tab_parts ({config}): fraction of the ceiling's gain, chained - independent topology "
        "parts",
        "hypothesis (independent parts 'represent no coupling')",
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
    # this project's: the 2D-track control (docs/tracks.md)
    ClaimSpec(
        "tracks_beats_null", "ours", "tracks_separated", "tab_recovery", "null_over_trained",
        "RATIO_EVEN", ">", "ratio",
        "{tree}: oscillators fitted to 2D tracks recover omega better than the untrained null",
        "{table}, 2D tracks {config}: null / tracks median rel. error",
        TRACKS_PROPOSAL,
        origin="project",
        optional=True,
        one_sided=DIRECTION,
    ),
    ClaimSpec(
        "tracks_match_ours", "ours", "tracks_separated", "tab_recovery", "tracks_minus_ours",
        "NULL_MATCH_PP", "<", "points",
        "{tree}: oscillators fitted to 2D tracks match ours' omega recovery (ours does not "
        "beat them by {NULL_MATCH_PP} points or more)",
        "{table}, {config}: 2D tracks - ours median rel. error (points)",
        TRACKS_PROPOSAL,
        origin="project",
        optional=True,
        one_sided=NON_INFERIOR,
    ),
    ClaimSpec(
        "tracks_extrapolate_as_ours", "ours", "tracks_trees", "tab_tracks", "tracks_tail",
        "EVEN", "<", "px",
        "{tree}: beyond the window, oscillators fitted to 2D tracks predict the tracked points "
        "at least as well as ours' Gaussians",
        "tab_tracks, {config}: tail displacement error, 2D tracks - ours (px)",
        TRACKS_PROPOSAL,
        origin="project",
        optional=True,
        one_sided=NON_INFERIOR,
    ),
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
    fam = parts[1] if parts[0] in _MODEL_IDS and len(parts) > 1 else parts[0]
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
        over = ("ours" if s.of == "ours" else "every other prior") + ", " + _doc(SCOPES[s.over])
        thr = s.threshold.lstrip("-")
        sign = "-" if s.threshold.startswith("-") else ""
        figure = _doc(s.paper) if callable(s.paper) else _template(s.paper)
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
