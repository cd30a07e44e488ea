"""The outputs that score recovered physics against the ground truth: tab_null (frequencies
against the untrained null), tab_damping (the damping benchmark), fig_damping and tab_kselect
(ours with K chosen from the data)."""

from __future__ import annotations

from physgs.experiments.kselect import BASE_MODEL, selected_models
from physgs.models.registry import BLIND_CONFIG, config_label, models_of
from physgs.recovery.record import load_null, load_recovery
from physgs.report import kselect
from physgs.report.outputs.base import Output

#: tab_kselect's rows: ours at the fixed K of the base configuration, and at the chosen K
KSELECT_ROWS = tuple(c for c, _ in kselect.ROWS)


def tracks_label(cfg: dict, config: str) -> str:
    """The LaTeX label of the 2D-track control's configuration ``config`` with its own K."""
    from physgs.tracks.settings import parts as tracks_k

    spec = {**cfg["models"]["configs"][config], "K": tracks_k(cfg, config)[0]}
    return config_label(config, spec)


def other_priors() -> tuple[str, ...]:
    """The priors besides ours (the paper's, read through the ``recovery`` need kind): each read
    through ``prior_recovery`` and set beside ours' rows."""
    return tuple(m for m in models_of("prior") if m != "ours")


def oma_label(cfg: dict, config: str) -> str:
    """The LaTeX label of the output-only analysis' configuration ``config`` with its own K."""
    from physgs.oma.settings import parts as oma_k

    return config_label(config, {**cfg["models"]["configs"][config], "K": oma_k(cfg, config)})


def _further_settings(cfg: dict, configs) -> dict:
    """The forcing-free methods' settings of tab_null / tab_damping in ``configs`` (the table's
    configurations): oma {config: {K, label}}; blind {model: {config: label}} in
    ``BLIND_CONFIG`` (``registry.BLIND_PRIORS``, none when the run lacks that configuration)."""
    from physgs.models.registry import BLIND_PRIORS
    from physgs.oma.settings import parts as oma_k

    mc = cfg["models"]["configs"]
    blind = {m: {BLIND_CONFIG: config_label(BLIND_CONFIG, mc[BLIND_CONFIG])} for m in BLIND_PRIORS}
    return {
        "oma": {
            c: {"K": oma_k(cfg, c), "label": oma_label(cfg, c)}
            for c in cfg["oma"]["configs"]
            if c in configs
        },
        "blind": blind if BLIND_CONFIG in configs else {},
    }


def _further_needs(plan, configs, testbeds, s) -> list[tuple]:
    """The forcing-free methods' recoveries on ``testbeds`` in ``configs`` (seed ``s``)."""
    blind = [m for m in plan.blind if BLIND_CONFIG in configs]
    return [("oma_recovery", tb, c, s) for tb in testbeds for c in plan.oma if c in configs] + [
        ("prior_recovery", tb, m, BLIND_CONFIG, s) for tb in testbeds for m in blind
    ]


def _configs(cfg: dict) -> dict:
    return {
        "configs": {
            c: {"K": int(v["K"]), "conditions": v["conditions"]}
            for c, v in cfg["models"]["configs"].items()
        }
    }


# ---- tab_null ------------------------------------------------------------------------------
def _null_needs(plan, seeds):
    out = []
    for s in seeds:
        out += [("recovery", t, c, s) for t in plan.trees for c in plan.configs]
        out += [
            ("prior_recovery", t, m, c, s)
            for t in plan.trees
            for m in other_priors()
            for c in plan.configs
        ]
        out += [("tracks_recovery", t, c, s) for t in plan.trees for c in plan.tracks]
        out += _further_needs(plan, plan.configs, plan.trees, s)
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


def _null_settings(cfg: dict) -> dict:
    from physgs.tracks.settings import parts as tracks_k

    return {
        **_configs(cfg),
        "tracks": {
            c: {"K": tracks_k(cfg, c)[0], "label": tracks_label(cfg, c)}
            for c in cfg["tracks"]["configs"]
        },
        **_further_settings(cfg, cfg["models"]["configs"]),
    }


def _tab_null(path, settings, inputs, out):
    from physgs.report import tables

    trees, seeds, configs = settings["trees"], settings["seeds"], settings["configs"]
    rec = {
        s: {(t, c): load_recovery(path("recovery", t, c, s)) for t in trees for c in configs}
        for s in seeds
    }
    null = {
        s: {
            (t, c): load_null(path("null", t, int(configs[c]["K"]), s))
            for t in trees
            for c in configs
        }
        for s in seeds
    }

    def paired(kind, *fields, parts):
        """{seed: {(tree, config): (record of need ``kind``, the null of its K)}}; parts:
        {config: K}."""
        return {
            s: {
                (t, c): (
                    load_recovery(path(kind, t, *fields, c, s)),
                    load_null(path("null", t, int(k), s)),
                )
                for t in trees
                for c, k in parts.items()
            }
            for s in seeds
        }

    tk, oma = settings.get("tracks", {}), settings.get("oma", {})
    tracks = paired("tracks_recovery", parts={c: v["K"] for c, v in tk.items()})
    methods = {
        tables.OMA: tables.oma_rows(
            {c: v["label"] for c, v in oma.items()},
            paired("oma_recovery", parts={c: v["K"] for c, v in oma.items()}),
        )
    }
    methods.update(
        {
            m: tables.blind_rows(
                m, mc, paired("prior_recovery", m, parts={c: configs[c]["K"] for c in mc})
            )
            for m, mc in settings.get("blind", {}).items()
        }
    )
    return tables.tab_null(
        rec,
        null,
        trees,
        settings["bones"],
        {c: config_label(c, v) for c, v in configs.items()},
        digits=settings["digits"],
        tracks=tracks,
        tracks_configs={c: v["label"] for c, v in tk.items()},
        priors={
            m: {
                s: {
                    (t, c): load_recovery(path("prior_recovery", t, m, c, s))
                    for t in trees
                    for c in configs
                }
                for s in seeds
            }
            for m in other_priors()
        },
        methods={m: mr for m, mr in methods.items() if mr.configs},
    )


TAB_NULL = Output("tab_null", "table", ("prior",), _null_needs, _tab_null, settings=_null_settings)


# ---- tab_damping ---------------------------------------------------------------------------
def _testbeds(tree: str) -> dict:
    """{variant: testbed id} of a damping-benchmark tree: its faithful and damping testbeds."""
    from physgs.testbed.variant import DAMPING, FAITHFUL, damping_id

    return {FAITHFUL: tree, DAMPING: damping_id(tree)}


def _damping_needs(plan, seeds):
    tracks = [c for c in plan.damping_configs if c in plan.tracks]
    return (
        [
            ("recovery", tb, c, int(s))
            for t in plan.damping_trees
            for tb in _testbeds(t).values()
            for c in plan.damping_configs
            for s in seeds
        ]
        + [
            ("prior_recovery", tb, m, c, int(s))
            for t in plan.damping_trees
            for tb in _testbeds(t).values()
            for m in other_priors()
            for c in plan.damping_configs
            for s in seeds
        ]
        + [
            ("tracks_recovery", tb, c, int(s))
            for t in plan.damping_trees
            for tb in _testbeds(t).values()
            for c in tracks
            for s in seeds
        ]
        + [
            x
            for s in seeds
            for x in _further_needs(
                plan,
                plan.damping_configs,
                [tb for t in plan.damping_trees for tb in _testbeds(t).values()],
                int(s),
            )
        ]
    )


def _damping_settings(cfg: dict) -> dict:
    configs = cfg["damping_benchmark"]["configs"]
    return {
        "configs": {c: config_label(c, cfg["models"]["configs"][c]) for c in configs},
        "tracks_configs": {
            c: tracks_label(cfg, c) for c in configs if c in cfg["tracks"]["configs"]
        },
        **_further_settings(cfg, configs),
    }


def _tab_damping(path, settings, inputs, out):
    from physgs.report import tables
    from physgs.report.damping import tab_damping

    trees, seeds, configs = settings["trees"], settings["seeds"], settings["configs"]

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

    tc = settings.get("tracks_configs", {})
    oma = {c: v["label"] for c, v in settings.get("oma", {}).items()}
    methods = {tables.OMA: tables.oma_rows(oma, records("oma_recovery", configs=oma))}
    methods.update(
        {
            m: tables.blind_rows(m, mc, records("prior_recovery", m, configs=mc))
            for m, mc in settings.get("blind", {}).items()
        }
    )
    return tab_damping(
        records("recovery", configs=configs),
        trees,
        settings["bones"],
        configs,
        digits=settings["digits"],
        tracks=records("tracks_recovery", configs=tc),
        tracks_configs=tc,
        priors={m: records("prior_recovery", m, configs=configs) for m in other_priors()},
        methods={m: mr for m, mr in methods.items() if mr.configs},
    )


TAB_DAMPING = Output(
    "tab_damping",
    "table",
    ("prior",),
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
        (t, c): load_recovery(path("recovery", t, c, s0)).damping for t in trees for c in configs
    }
    priors = {
        m: {
            (t, c): load_recovery(path("prior_recovery", t, m, c, s0)).damping
            for t in trees
            for c in configs
        }
        for m in other_priors()
    }
    figures.fig_damping(damping, trees, configs, float(settings["zeta"]), out, priors=priors)


FIG_DAMPING = Output(
    "fig_damping",
    "figure",
    ("prior",),
    lambda plan, seeds: (
        [("recovery", t, c, s) for s in seeds for t in plan.trees for c in plan.configs]
        + [
            ("prior_recovery", t, m, c, s)
            for s in seeds
            for t in plan.trees
            for m in other_priors()
            for c in plan.configs
        ]
    ),
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
                    rec = (
                        ("recovery", t, c, s) if m == BASE_MODEL else ("prior_recovery", t, m, c, s)
                    )
                    out += [("eval", t, m, c, s), rec, ("loss", t, m, c, s)]
    return out


def _tab_kselect(path, settings, inputs, out):
    import pandas as pd

    from physgs.evaluate.splits import load_eval
    from physgs.experiments.kselect import load_selection

    rows = {}
    for s in settings["seeds"]:
        rows[s] = {}
        for t in settings["trees"]:
            for m in settings["models"]:
                sel = load_selection(path(*_selection_need(t, m, s)))
                for c in KSELECT_ROWS:
                    ev = load_eval(path("eval", t, m, c, s)).summary()
                    rec = load_recovery(
                        path("recovery", t, c, s)
                        if m == BASE_MODEL
                        else path("prior_recovery", t, m, c, s)
                    )
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
    ("prior",),
    _kselect_needs,
    _tab_kselect,
    settings=lambda cfg: {
        "method": cfg["models"]["kselect"]["method"],
        "models": list(selected_models(cfg["models"]["kselect"])),
    },
    in_report=lambda plan: False,  # `all` builds it (Snakefile): K selection costs trainings
)
