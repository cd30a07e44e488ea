"""What every report output declares, and what the run plans (the shared vocabulary).

An output (a table or a figure) is one ``Output``: the result files it reads as *need tuples*
(``needs``: the models of the registry roles it shows, ``physgs.models.registry.models_of``), the
settings it reads from the resolved config (``settings``) and how it builds itself (``build``).
A need tuple is ``(kind, *fields)`` with the fields of ``NEED_FIELDS[kind]``; the workflow maps
each to a path (``workflow/rules/common.smk``) and hands the builder a mapping ``key(need) ->
path``. The builder reads only those paths, through ``reader``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

from physgs.config import study_seeds
from physgs.experiments.kselect import selected_models
from physgs.models.registry import blind_priors
from physgs.oma.settings import parts as oma_k
from physgs.tracks.settings import fields_scored
from physgs.tracks.settings import parts as tracks_k

#: The fields of each need tuple after its kind (what a workflow path template is formatted with).
NEED_FIELDS = {
    "eval": ("tree", "model", "config", "seed"),
    "traj": ("tree", "model", "config", "seed"),
    "panels": ("tree", "model", "config", "seed"),
    "loss": ("tree", "model", "config", "seed"),
    "prior_recovery": ("tree", "model", "config", "seed"),  # any oscillator prior's, ours too
    "parts": ("tree", "seed"),  # the priors' segmentations (physgs.evaluate.parts)
    "kmatch": ("tree", "K", "seed"),  # the chained prior at a smaller K (experiments.kmatch)
    "null": ("tree", "K", "seed"),
    "kselect": ("tree", "seed"),  # ours' K selection
    "prior_kselect": ("tree", "model", "seed"),  # another prior's (models.kselect.priors)
    "stats": ("tree",),
    "table": ("name",),
    # the 2D-track control (physgs.tracks): its recovery record (ours' format), its evaluation
    # record, its fit, one condition's tracks, and the observed dataset (fig_tracks' frame)
    "tracks_recovery": ("tree", "config", "seed"),
    # the output-only modal analysis' recovery record (physgs.oma; ours' format)
    "oma_recovery": ("tree", "config", "seed"),
    "tracks_eval": ("tree", "config", "seed"),
    "tracks_fields": ("tree", "config", "seed"),  # the learned fields at the tracked points
    "tracks_fit": ("tree", "config", "seed"),
    "tracks": ("tree", "condition", "seed"),
    "observed": ("tree", "seed"),
}


def key(need: tuple) -> str:
    """The name of a need in the inputs mapping: its parts joined by '/'.

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
    tracks: the 2D-track control's configurations -> their K; damping_trees/damping_configs: the
    damping benchmark's; tracks_fields: the (tree, configuration) pairs whose learned fields are
    scored at the tracked points; parts_models/parts_configs: the parts study's variants and
    configurations ({} without a study); study_seeds/k_candidates: the K match's; oma: the
    output-only analysis' configurations -> their K (``oma.configs``); blind: the forcing-free
    priors trained (``registry.blind_priors``: in ``BLIND_CONFIG``, none without it);
    kselect_priors: the priors besides ours whose K is chosen from the data
    (``models.kselect.priors``)."""

    trees: Sequence[str]
    configs: Mapping[str, dict]
    seeds: Sequence[int]
    tracks: Mapping[str, int] = field(default_factory=dict)
    damping_trees: Sequence[str] = ()
    damping_configs: Sequence[str] = ()
    tracks_fields: Sequence[tuple[str, str]] = ()
    parts_models: Sequence[str] = ()
    parts_configs: Mapping[str, dict] = field(default_factory=dict)
    study_seeds: Sequence[int] = ()
    k_candidates: Sequence[int] = ()
    oma: Mapping[str, int] = field(default_factory=dict)
    blind: Sequence[str] = ()
    kselect_priors: Sequence[str] = ()

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
            tracks={c: tracks_k(cfg, c)[0] for c in tracks},
            damping_trees=list(cfg["damping_benchmark"]["trees"]),
            damping_configs=list(cfg["damping_benchmark"]["configs"]),
            tracks_fields=[(t, c) for t in trees for c in tracks if fields_scored(cfg, c, t)],
            parts_models=parts_models,
            parts_configs={c: configs[c] for c in cfg["parts_study"]["configs"]}
            if parts_models
            else {},
            study_seeds=[int(s) for s in study_seeds(cfg)],
            k_candidates=[int(k) for k in cfg["parts_study"]["k_candidates"]],
            oma={c: oma_k(cfg, c) for c in cfg["oma"]["configs"]},
            blind=list(blind_priors(configs)),
            kselect_priors=list(selected_models(cfg["models"]["kselect"])[1:]),
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
    builds it (else another target does: ``all``, ``studies``)."""

    name: str
    kind: str
    needs: Callable[[Plan, Sequence[int]], list[tuple]]
    build: Callable[..., Any]
    settings: Callable[[dict], dict] = lambda cfg: {}
    seeds: str = "all"
    trees: str = "trees"
    in_report: Callable[[Plan], bool] = lambda plan: True

    def __post_init__(self):
        """Refuse an unknown kind or seed scope, naming the output."""
        if self.kind not in ("table", "figure"):
            raise ValueError(f"output {self.name!r}: kind must be table or figure")
        if self.seeds not in SEEDS:
            raise ValueError(f"output {self.name!r}: seeds must be one of {SEEDS}")
