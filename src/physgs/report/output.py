"""What every report output declares, and what the run plans (the shared vocabulary).

An output (a table or a figure) is one ``Output``: the result files it reads as *need tuples*
(``needs``: the models of the registry roles it shows, ``physgs.models.registry.models_of``), the
settings it reads from the resolved config (``settings``) and how it builds itself (``build``).
A need tuple is ``(kind, *fields)`` with the fields of ``NEED_FIELDS[kind]``; the workflow maps
each to a path (``workflow/rules/common.smk``) and hands the builder a mapping ``key(need) ->
path``. The builder reads only those paths, through ``reader``.
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
    "eval": ("tree", "model", "config", "seed"),
    "traj": ("tree", "model", "config", "seed"),
    "panels": ("tree", "model", "config", "seed"),
    "loss": ("tree", "model", "config", "seed"),
    # any recovery method's record (``registry.RECOVERY_METHODS``: the priors, ours too, the
    # forcing-free priors, the 2D-track control, the output-only analysis)
    "recovery": ("tree", "method", "config", "seed"),
    "parts": ("tree", "seed"),  # the priors' segmentations (physgs.evaluate.parts)
    "kmatch": ("tree", "K", "seed"),  # the chained prior at a smaller K (experiments.kmatch)
    "null": ("tree", "K", "seed"),
    "kselect": ("tree", "seed"),  # ours' K selection
    "prior_kselect": ("tree", "model", "seed"),  # another prior's (models.kselect.priors)
    "stats": ("tree",),
    "instance_stats": ("tree", "seed"),  # a tree instance's (testbed_seeds: testbed seed = seed)
    "table": ("name",),
    # the 2D-track control (physgs.tracks): its evaluation record, its fit, one condition's
    # tracks, and the observed dataset (fig_tracks' frame)
    "tracks_eval": ("tree", "config", "seed"),
    "tracks_fields": ("tree", "config", "seed"),  # the learned fields at the tracked points
    "tracks_fit": ("tree", "config", "seed"),
    "tracks": ("tree", "condition", "seed"),
    "observed": ("tree", "seed"),
    # the output-only analysis: one identification, and the truth its figure draws beside it
    "oma_modes": ("tree", "config", "seed"),
    "truth": ("tree", "seed"),
}


def key(need: tuple) -> str:
    """The name of a need among a rule's inputs (Snakemake names them by strings): its parts
    joined by '/'; never split again (a reader keeps the tuple).

    Args:
        need: a need tuple (kind, then its parts).

    Returns:
        The key.
    """
    return "/".join(str(p) for p in need)


def reader(inputs: Mapping[str, str]) -> Callable[..., str]:
    """``path(*need)``: the file of a need in ``inputs`` (KeyError naming it when absent).

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
    """What a run builds, as the report outputs' needs read it (``from_config`` of the resolved
    config; tests construct it directly). configs: ``models.configs`` (name -> {conditions, K});
    recovery: the recovery methods scored (``registry.recovery_plan``: id -> {configuration:
    K}, in ``RECOVERY_METHODS`` order; None: the wind-driven priors, ``models_of("prior")``, in
    every configuration); damping_trees/damping_configs: the damping benchmark's;
    tracks_fields: the (tree, configuration) pairs whose learned fields are scored at the
    tracked points; parts_models/parts_configs: the parts study's variants and configurations
    ({} without a study); study_seeds/k_candidates: the K match's; kselect_priors: the priors
    besides ours whose K is chosen from the data (``models.kselect.priors``); sweep_tree: the
    speed-accuracy sweep's tree (``speed_accuracy.tree``); testbed_seeds: whether each training
    seed has its own tree instance (``testbed_seeds``)."""

    trees: Sequence[str]
    configs: Mapping[str, dict]
    seeds: Sequence[int]
    recovery: Mapping[str, Mapping[str, int]] | None = None
    damping_trees: Sequence[str] = ()
    damping_configs: Sequence[str] = ()
    tracks_fields: Sequence[tuple[str, str]] = ()
    parts_models: Sequence[str] = ()
    parts_configs: Mapping[str, dict] = field(default_factory=dict)
    study_seeds: Sequence[int] = ()
    k_candidates: Sequence[int] = ()
    kselect_priors: Sequence[str] = ()
    sweep_tree: str = ""
    testbed_seeds: bool = False

    def __post_init__(self):
        """Default the recovery methods to the wind-driven priors in every configuration."""
        if self.recovery is None:
            K = {c: int(v["K"]) for c, v in self.configs.items()}
            priors = {m: dict(K) for m in models_of("prior")}
            object.__setattr__(self, "recovery", priors)

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
            parts_configs={c: configs[c] for c in cfg["parts_study"]["configs"]}
            if parts_models
            else {},
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
    """A table's CSV contract: which columns identify a row, which describe it, which hold its
    measurements and which time its jobs. A name may hold ``{placeholder}``s
    (``PLACEHOLDERS``): ``{tree}_view`` is one column per tree. Ids only, never labels: the
    labels live in the registry and appear in the .tex, Markdown and figures alone.

    keys: the columns that identify a row (seed first in a seeded table), present in every CSV;
    values: its measurements (what a rerun compares against the seed spread); timing: job
    seconds or ratios of them (what the machine did: never compared); about: columns that
    describe the row without identifying it (bones, K, a flag)."""

    keys: tuple[str, ...]
    values: tuple[str, ...]
    timing: tuple[str, ...] = ()
    about: tuple[str, ...] = ()

    def _pattern(self, names: Sequence[str]) -> re.Pattern:
        parts = [
            re.sub(r"\\\{(\w+)\\\}", lambda m: f"(?:{PLACEHOLDERS[m.group(1)]})", re.escape(n))
            for n in names
        ]
        return re.compile("|".join(f"(?:{p})" for p in parts) or "(?!)")

    def of(self, columns: Sequence[str], part: str) -> list[str]:
        """The columns of a CSV that are of one part of the contract.

        Args:
            columns: a CSV's columns.
            part: "keys", "values", "timing" or "about".

        Returns:
            Those of ``columns`` that the part's names match, in the CSV's order.
        """
        pat = self._pattern(getattr(self, part))
        return [c for c in columns if pat.fullmatch(c)]

    def check(self, name: str, columns: Sequence[str]) -> None:
        """Refuse a CSV that breaks the contract: a key missing, or a column not declared.

        Args:
            name: the table's name (for the message).
            columns: its CSV's columns.

        Raises:
            ValueError: naming the missing keys or the undeclared columns.
        """
        missing = [k for k in self.keys if k not in columns]
        every = self._pattern((*self.keys, *self.values, *self.timing, *self.about))
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
    """One table or figure of the report.

    name: its file name (results/tables/<name>.* or results/figures/<name>.*); kind: "table" or
    "figure"; seeds: which training seeds it reads (``SEEDS``); trees: the config key of its
    trees ("trees", or
    "damping_benchmark" for the damping benchmark's); needs(plan, seeds): its need tuples for
    those seeds; settings(cfg): the settings it reads beyond the common ones (trees, bones,
    seeds, digits); build(path, settings, inputs, out): writes a figure to ``out`` (its paths)
    or returns a ``Table`` (``out`` unused); in_report(plan): whether the ``report`` target
    builds it (else another target does: ``all``, ``studies``); columns: a table's CSV
    contract (``Columns``; required of a table)."""

    name: str
    kind: str
    needs: Callable[[Plan, Sequence[int]], list[tuple]]
    build: Callable[..., Any]
    settings: Callable[[dict], dict] = lambda cfg: {}
    seeds: str = "all"
    trees: str = "trees"
    in_report: Callable[[Plan], bool] = lambda plan: True
    columns: Columns | None = None

    def __post_init__(self):
        """Refuse an unknown kind or seed scope, or a table without its columns, naming the
        output."""
        if self.kind not in ("table", "figure"):
            raise ValueError(f"output {self.name!r}: kind must be table or figure")
        if (self.kind == "table") != (self.columns is not None):
            raise ValueError(f"output {self.name!r}: a table declares its columns, a figure none")
        if self.seeds not in SEEDS:
            raise ValueError(f"output {self.name!r}: seeds must be one of {SEEDS}")
