"""What every report output declares, and what the run plans (the shared vocabulary).

An ``Output`` (a table or a figure) declares the files it reads as *need tuples*
``(kind, *NEED_FIELDS[kind])`` (``needs``), the settings it reads from the resolved config and
its builder. The workflow maps each need to a path (``workflow/rules/common.smk``) and hands the
builder ``key(need) -> path``, read through ``reader``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

from physgs.config import study_seeds
from physgs.experiments.kselect import selected_models
from physgs.models.registry import (
    BLIND_PRIORS,
    MODEL_NAMES,
    PRIOR_VARIANT_NAMES,
    REFERENCE_NAMES,
    models_of,
    recovery_plan,
)
from physgs.tracks.settings import fields_scored

#: The fields of each need tuple after its kind (what a workflow path template is formatted with).
NEED_FIELDS = {
    **dict.fromkeys(("eval", "traj", "panels", "loss"), ("tree", "model", "config", "seed")),
    "recovery": ("tree", "method", "config", "seed"),  # any of ``registry.RECOVERY_METHODS``
    # the priors' segmentations, ours' K selection, a tree instance's stats (``testbed_seeds``),
    # the observed dataset (fig_tracks' frame), the truth (beside the output-only analysis)
    **dict.fromkeys(("parts", "kselect", "instance_stats", "observed", "truth"), ("tree", "seed")),
    # the 2D-track control's record, learned fields at its points and fit; an OMA identification
    **dict.fromkeys(
        ("tracks_eval", "tracks_fields", "tracks_fit", "oma_modes"), ("tree", "config", "seed")
    ),
    **dict.fromkeys(("kmatch", "null"), ("tree", "K", "seed")),  # kmatch: the chained prior's
    "prior_kselect": ("tree", "model", "seed"),  # a prior's besides ours' (models.kselect.priors)
    "tracks": ("tree", "condition", "seed"),
    "stats": ("tree",),
    "table": ("name",),
}


def key(need: tuple) -> str:
    """A need's name among a rule's inputs: its parts joined by '/' (never split again).

    Args:
        need: a need tuple (kind, then its parts).

    Returns:
        The key.
    """
    return "/".join(str(p) for p in need)


def reader(inputs: Mapping[str, str]) -> Callable[..., str]:
    """``path(*need)``: the file of a need in ``inputs``.

    Args:
        inputs: need key -> path (the rule's inputs).

    Returns:
        The ``path`` function; it raises ``KeyError`` naming a need without a file.
    """

    def path(*need) -> str:
        k = key(need)
        if k not in inputs:
            raise KeyError(
                f"no input file for {k!r}; the rule must declare report needs "
                f"(physgs.report.build.needs)"
            )
        return inputs[k]

    return path


@dataclass(frozen=True)
class Plan:
    """What a run builds, as the outputs' needs read it (``from_config``; tests build it)."""

    trees: Sequence[str]
    configs: Mapping[str, dict]  # ``models.configs``: name -> {conditions, K}
    seeds: Sequence[int]
    # ``registry.recovery_plan``: method -> {configuration: K}; None: the priors in every one
    recovery: Mapping[str, Mapping[str, int]] | None = None
    damping_trees: Sequence[str] = ()
    damping_configs: Sequence[str] = ()
    tracks_fields: Sequence[tuple[str, str]] = ()  # (tree, config): fields scored at the tracks
    parts_models: Sequence[str] = ()
    parts_configs: Mapping[str, dict] = field(default_factory=dict)  # {} without a parts study
    study_seeds: Sequence[int] = ()
    k_candidates: Sequence[int] = ()
    kselect_priors: Sequence[str] = ()  # the priors besides ours whose K the data choose
    sweep_tree: str = ""  # the speed-accuracy sweep's
    testbed_seeds: bool = False  # whether each training seed has its own tree instance

    def __post_init__(self):
        """Default the recovery methods to the wind-driven priors in every configuration."""
        if self.recovery is None:
            K = {c: int(v["K"]) for c, v in self.configs.items()}
            object.__setattr__(self, "recovery", {m: dict(K) for m in models_of("prior")})

    @property
    def tracks(self) -> Mapping[str, int]:
        """The 2D-track control's configurations -> their K ({} when it is not run)."""
        return self.recovery.get("tracks", {})

    @property
    def blind(self) -> tuple[str, ...]:
        """The forcing-free priors the run trains (``registry.BLIND_PRIORS``)."""
        return tuple(m for m in BLIND_PRIORS if m in self.recovery)

    @classmethod
    def from_config(cls, cfg: dict) -> Plan:
        """The plan of a resolved config.

        Args:
            cfg (dict): the resolved config ([`physgs.config.load`][]).

        Returns:
            Plan: its trees, configurations, seeds and study settings.
        """
        trees, configs = list(cfg["trees"]), dict(cfg["models"]["configs"])
        parts_models = list(cfg["parts_study"]["models"])
        tracks = list(cfg["tracks"]["configs"])
        return cls(
            trees=trees,
            configs=configs,
            seeds=[int(s) for s in cfg["seeds"]],
            recovery=recovery_plan(cfg),
            damping_trees=list(cfg["damping_benchmark"]["trees"]),
            damping_configs=list(cfg["damping_benchmark"]["configs"]),
            tracks_fields=[(t, c) for t in trees for c in tracks if fields_scored(cfg, c, t)],
            parts_models=parts_models,
            parts_configs={c: configs[c] for c in cfg["parts_study"]["configs"] if parts_models},
            study_seeds=[int(s) for s in study_seeds(cfg)],
            k_candidates=[int(k) for k in cfg["parts_study"]["k_candidates"]],
            kselect_priors=list(selected_models(cfg["models"]["kselect"])[1:]),
            sweep_tree=str(cfg["speed_accuracy"]["tree"]),
            testbed_seeds=bool(cfg["testbed_seeds"]),
        )


#: the columns ``write_table`` adds to every CSV row (``physgs.provenance.Stamp``): the run's, not
#: the row's; never keys, never compared
PROVENANCE_COLUMNS = ("profile", "config_hash", "physgs_version")
#: what a ``{placeholder}`` in a declared column name stands for (a regular expression): a testbed
#: id, a model id of the registry, a wind (``v0``, ``0.84v0``: the mean-speed multiplier)
PLACEHOLDERS = {
    "tree": r"[A-Za-z0-9_]+",
    "model": "|".join(re.escape(m) for m in (*MODEL_NAMES, *PRIOR_VARIANT_NAMES, *REFERENCE_NAMES)),
    "wind": r"(?:\d+(?:\.\d+)?)?v0",
}


@dataclass(frozen=True)
class Columns:
    """A table's CSV contract, by column name (ids, never labels); a name may hold
    ``{placeholder}``s (``PLACEHOLDERS``): ``{tree}_view`` is one column per tree."""

    keys: tuple[str, ...]  # identify a row (seed first in a seeded table), in every CSV
    values: tuple[str, ...]  # its measurements (what a rerun compares)
    timing: tuple[str, ...] = ()  # job seconds or their ratios (never compared)
    about: tuple[str, ...] = ()  # describe a row without identifying it (bones, K, a flag)

    def check(self, name: str, columns: Sequence[str]) -> None:
        """Refuse a CSV that breaks the contract: ValueError naming missing keys, extra columns.

        Args:
            name: the table's name (for the message).
            columns: its CSV's columns.
        """
        declared = [
            re.sub(r"\\\{(\w+)\\\}", lambda m: f"(?:{PLACEHOLDERS[m.group(1)]})", re.escape(n))
            for n in (*self.keys, *self.values, *self.timing, *self.about)
        ]
        every = re.compile("|".join(f"(?:{p})" for p in declared) or "(?!)")
        missing = [k for k in self.keys if k not in columns]
        extra = [c for c in columns if c not in PROVENANCE_COLUMNS and not every.fullmatch(c)]
        if missing or extra:
            raise ValueError(
                f"{name}: its CSV breaks its declared columns (physgs.report.outputs): "
                f"missing keys {missing}, undeclared columns {extra}"
            )


#: which training seeds an output reads: all (mean +- sd), the first (a one-seed figure), the
#: studies' (``speed_accuracy/seeds``) or none (the testbed's)
SEEDS = ("all", "first", "studies", "none")


@dataclass(frozen=True)
class Output:
    """One table or figure of the report."""

    name: str  # its file name: results/tables/<name>.* or results/figures/<name>.*
    kind: str  # "table" or "figure"
    needs: Callable[[Plan, Sequence[int]], list[tuple]]  # (plan, training seeds) -> need tuples
    # (path, settings, inputs, out): writes a figure to the paths ``out``, or returns a ``Table``
    build: Callable[..., Any]
    settings: Callable[[dict], dict] = lambda cfg: {}  # beyond trees, bones, seeds and digits
    seeds: str = "all"  # which training seeds it reads (``SEEDS``)
    trees: str = "trees"  # the config key of its trees: "trees" or "damping_benchmark"
    in_report: Callable[[Plan], bool] = lambda plan: True  # else ``all`` or ``studies`` builds it
    columns: Columns | None = None  # a table's CSV contract (required of a table)

    def __post_init__(self):
        """Refuse an unknown kind or seed scope, or a table without its columns."""
        if self.kind not in ("table", "figure"):
            raise ValueError(f"output {self.name!r}: kind must be table or figure")
        if (self.kind == "table") != (self.columns is not None):
            raise ValueError(f"output {self.name!r}: a table declares its columns, a figure none")
        if self.seeds not in SEEDS:
            raise ValueError(f"output {self.name!r}: seeds must be one of {SEEDS}")
