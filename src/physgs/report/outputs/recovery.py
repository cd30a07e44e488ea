"""The outputs that score recovered physics against the ground truth: tab_null (frequencies
against the untrained null), tab_damping (the damping benchmark), fig_damping and tab_kselect
(ours with K chosen from the data)."""

from __future__ import annotations

import pandas as pd

from physgs.evaluate.splits import load_eval
from physgs.experiments.kselect import BASE_MODEL, load_selection, selected_models
from physgs.models.registry import BLIND_CONFIG, blind_priors, config_label, models_of
from physgs.oma.settings import parts as oma_k
from physgs.recovery.record import load_null, load_recovery
from physgs.report import kselect, tables
from physgs.report.damping import TRACKS_NOTE, tab_damping
from physgs.report.outputs.base import Output
from physgs.testbed.variant import DAMPING, FAITHFUL, damping_id
from physgs.tracks.settings import parts as tracks_k

#: tab_kselect's rows: ours at the fixed K of the base configuration, and at the chosen K
KSELECT_ROWS = tuple(c for c, _ in kselect.ROWS)


def label_with_k(cfg: dict, config: str, K: int) -> str:
    """The LaTeX label of configuration ``config`` for a method that sets its own K (the 2D-track
    control, the output-only analysis).

    Args:
        cfg: the resolved config.
        config: a configuration name.
        K: the method's number of parts in that configuration.

    Returns:
        The label ([`config_label`][physgs.models.registry.config_label]).
    """
    return config_label(config, {**cfg["models"]["configs"][config], "K": K})


def _method_settings(cfg: dict, configs) -> dict:
    """The methods of tab_null / tab_damping besides the 2D-track control, in ``configs`` (the
    table's configurations): priors {model: {config: label}}, every prior of the registry (ours
    first) in each of them; oma {config: {K, label}}; blind {model: {config: label}}, the
    forcing-free priors (``registry.blind_priors``) in ``BLIND_CONFIG``."""
    mc = cfg["models"]["configs"]
    return {
        "priors": {m: {c: config_label(c, mc[c]) for c in configs} for m in models_of("prior")},
        "oma": {
            c: {"K": (k := oma_k(cfg, c)), "label": label_with_k(cfg, c, k)}
            for c in cfg["oma"]["configs"]
            if c in configs
        },
        "blind": {
            m: {BLIND_CONFIG: config_label(BLIND_CONFIG, mc[BLIND_CONFIG])}
            for m in blind_priors(configs)
        },
    }


def _method_needs(plan, configs, testbeds, s) -> list[tuple]:
    """The recoveries of tab_null / tab_damping's methods besides the 2D-track control on
    ``testbeds`` in ``configs`` (seed ``s``): every prior's, the output-only analysis' and the
    run's forcing-free priors' (``plan.blind``, in ``BLIND_CONFIG``)."""
    blind = [m for m in plan.blind if BLIND_CONFIG in configs]
    return (
        [
            ("prior_recovery", tb, m, c, s)
            for tb in testbeds
            for m in models_of("prior")
            for c in configs
        ]
        + [("oma_recovery", tb, c, s) for tb in testbeds for c in plan.oma if c in configs]
        + [("prior_recovery", tb, m, BLIND_CONFIG, s) for tb in testbeds for m in blind]
    )


def _methods(settings: dict, records, tracks_note: str, prior_note: str = "") -> dict:
    """tab_null / tab_damping's ``MethodRows`` in row order: every prior (ours first), the
    2D-track control, the output-only analysis, the forcing-free priors. records(kind, *fields,
    configs): the table's per-seed records of need ``kind`` in ``configs`` ({config: K})."""

    def prior(m, labels):
        K = {c: settings["configs"][c]["K"] for c in labels}
        return tables.prior_rows(m, labels, records("prior_recovery", m, configs=K), prior_note)

    tracks, oma = settings.get("tracks", {}), settings.get("oma", {})
    return {
        **{m: prior(m, labels) for m, labels in settings["priors"].items()},
        tables.TRACKS: tables.tracks_rows(
            {c: v["label"] for c, v in tracks.items()},
            records("tracks_recovery", configs={c: v["K"] for c, v in tracks.items()}),
            tracks_note,
        ),
        tables.OMA: tables.oma_rows(
            {c: v["label"] for c, v in oma.items()},
            records("oma_recovery", configs={c: v["K"] for c, v in oma.items()}),
        ),
        **{m: prior(m, labels) for m, labels in settings["blind"].items()},
    }


def _configs(cfg: dict, names=None) -> dict:
    """configs {name: {K, conditions}} of the table's configurations ``names`` (all: None)."""
    mc = cfg["models"]["configs"]
    return {
        "configs": {
            c: {"K": int(v["K"]), "conditions": v["conditions"]}
            for c, v in mc.items()
            if names is None or c in names
        }
    }


# ---- tab_null ------------------------------------------------------------------------------
def _null_needs(plan, seeds):
    out = []
    for s in seeds:
        out += _method_needs(plan, plan.configs, plan.trees, s)
        out += [("tracks_recovery", t, c, s) for t in plan.trees for c in plan.tracks]
        out += list(
            dict.fromkeys(
                [
                    ("null", t, int(plan.configs[c]["K"]), s)
                    for t in plan.trees
                    for c in plan.configs
                ]
                + [("null", t, int(k), s) for t in plan.trees for k in plan.tracks.values()]
                + [("null", t, int(k), s) for t in plan.trees for k in plan.oma.values()]
            )
        )
    return out


def _tracks_settings(cfg: dict, configs) -> dict:
    """tracks {config: {K, label}}: the 2D-track control's configurations among ``configs``, in
    that order, each with its own K."""
    return {
        "tracks": {
            c: {"K": (k := tracks_k(cfg, c)[0]), "label": label_with_k(cfg, c, k)}
            for c in configs
            if c in cfg["tracks"]["configs"]
        }
    }


def _null_settings(cfg: dict) -> dict:
    return {
        **_configs(cfg),
        **_tracks_settings(cfg, cfg["tracks"]["configs"]),
        **_method_settings(cfg, cfg["models"]["configs"]),
    }


def _tab_null(path, settings, inputs, out):
    trees, seeds = settings["trees"], settings["seeds"]

    def paired(kind, *fields, configs):
        """{seed: {(tree, config): (record of need ``kind``, the null of its K)}}; configs:
        {config: K}."""
        return {
            s: {
                (t, c): (
                    load_recovery(path(kind, t, *fields, c, s)),
                    load_null(path("null", t, int(k), s)),
                )
                for t in trees
                for c, k in configs.items()
            }
            for s in seeds
        }

    methods = _methods(settings, paired, tables.NULL_TRACKS_NOTE, tables.NULL_PRIOR_NOTE)
    return tables.tab_null(methods, trees, settings["bones"], digits=settings["digits"])


TAB_NULL = Output("tab_null", "table", _null_needs, _tab_null, settings=_null_settings)


# ---- tab_damping ---------------------------------------------------------------------------
def _testbeds(tree: str) -> dict:
    """{variant: testbed id} of a damping-benchmark tree: its faithful and damping testbeds."""
    return {FAITHFUL: tree, DAMPING: damping_id(tree)}


def _damping_needs(plan, seeds):
    testbeds = [tb for t in plan.damping_trees for tb in _testbeds(t).values()]
    tracks = [c for c in plan.damping_configs if c in plan.tracks]
    return [
        x
        for s in seeds
        for x in _method_needs(plan, plan.damping_configs, testbeds, int(s))
        + [("tracks_recovery", tb, c, int(s)) for tb in testbeds for c in tracks]
    ]


def _damping_settings(cfg: dict) -> dict:
    configs = cfg["damping_benchmark"]["configs"]
    return {
        **_configs(cfg, configs),
        **_tracks_settings(cfg, configs),
        **_method_settings(cfg, configs),
    }


def _tab_damping(path, settings, inputs, out):
    trees, seeds = settings["trees"], settings["seeds"]

    def records(kind, *fields, configs):
        """{seed: {(tree, variant, config): record}} of need ``kind`` on each tree's testbeds."""
        return {
            s: {
                (t, v, c): load_recovery(path(kind, tb, *fields, c, s))
                for t in trees
                for v, tb in _testbeds(t).items()
                for c in configs
            }
            for s in seeds
        }

    methods = _methods(settings, records, TRACKS_NOTE)
    return tab_damping(methods, trees, settings["bones"], digits=settings["digits"])


TAB_DAMPING = Output(
    "tab_damping",
    "table",
    _damping_needs,
    _tab_damping,
    settings=_damping_settings,
    trees="damping_benchmark",
    in_report=lambda plan: bool(plan.damping_trees),
)


# ---- fig_damping ---------------------------------------------------------------------------
def _fig_damping(path, settings, inputs, out):
    from physgs.report import figures

    trees, configs, s0 = settings["trees"], list(settings["configs"]), settings["seeds"][0]
    damping = {
        m: {
            (t, c): load_recovery(path("prior_recovery", t, m, c, s0)).damping
            for t in trees
            for c in configs
        }
        for m in models_of("prior")
    }
    figures.fig_damping(damping, trees, configs, float(settings["zeta"]), out)


FIG_DAMPING = Output(
    "fig_damping",
    "figure",
    lambda plan, seeds: [
        ("prior_recovery", t, m, c, s)
        for s in seeds
        for t in plan.trees
        for m in models_of("prior")
        for c in plan.configs
    ],
    _fig_damping,
    settings=lambda cfg: {**_configs(cfg), "zeta": float(cfg["testbed"]["zeta"])},
    seeds="first",
)


# ---- tab_kselect ---------------------------------------------------------------------------
def _kselect_models(plan) -> list[str]:
    """The priors whose K is chosen: ours, then the plan's others (``models.kselect.priors``)."""
    return [BASE_MODEL, *plan.kselect_priors]


def _selection_need(t: str, m: str, s: int) -> tuple:
    """The need of prior ``m``'s K selection on tree ``t`` (ours' has its own kind)."""
    return ("kselect", t, s) if m == BASE_MODEL else ("prior_kselect", t, m, s)


def _kselect_needs(plan, seeds):
    """Per seed, tree and prior: its K selection, and the evaluation, recovery and loss log
    (training seconds) of its fixed-K and chosen-K models."""
    out = []
    for s in seeds:
        for t in plan.trees:
            for m in _kselect_models(plan):
                out.append(_selection_need(t, m, s))
                for c in KSELECT_ROWS:
                    rec = ("prior_recovery", t, m, c, s)
                    out += [("eval", t, m, c, s), rec, ("loss", t, m, c, s)]
    return out


def _tab_kselect(path, settings, inputs, out):
    rows = {}
    for s in settings["seeds"]:
        rows[s] = {}
        for t in settings["trees"]:
            for m in settings["models"]:
                sel = load_selection(path(*_selection_need(t, m, s)))
                for c in KSELECT_ROWS:
                    ev = load_eval(path("eval", t, m, c, s)).summary()
                    rec = load_recovery(path("prior_recovery", t, m, c, s))
                    loss = pd.read_csv(path("loss", t, m, c, s))
                    rows[s][(t, m, c)] = {
                        "K": rec.match.n_parts,
                        "view_psnr": ev["view"],
                        "time_psnr": ev["time"],
                        "median_rel_err": rec.match.median_rel_err,
                        "trusted": rec.match.n_trusted,
                        "frozen": rec.n_frozen,
                        "k_heldout": sel.k_heldout,
                        "k_bic": sel.k_bic,
                        "train_s": float(loss["seconds"].iloc[-1]),
                        "select_s": float(sum(sel.wall_s)),
                    }
    return kselect.tab_kselect(
        rows,
        settings["trees"],
        settings["bones"],
        settings["method"],
        models=settings["models"],
        digits=settings["digits"],
    )


TAB_KSELECT = Output(
    "tab_kselect",
    "table",
    _kselect_needs,
    _tab_kselect,
    settings=lambda cfg: {
        "method": cfg["models"]["kselect"]["method"],
        "models": list(selected_models(cfg["models"]["kselect"])),
    },
    in_report=lambda plan: False,  # `all` builds it (Snakefile): K selection costs trainings
)
