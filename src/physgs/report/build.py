"""Collect per-job result files into the tables and figures (what the report rules call).

The library never knows where the workflow keeps its files. Each output declares what it
needs as *need tuples* (``needs``): ``("eval" | "traj" | "panels" | "loss", tree, model, config,
seed)``, ``("recovery", tree, config, seed)``, ``("null", tree, K, seed)``, ``("kselect", tree,
seed)``, ``("stats", tree)`` and ``("table", name)``; seed is a training seed. The workflow
maps each tuple to a path (``workflow/rules/common.smk``) and hands the builders a mapping
``key(need) -> path``; the builders read only those paths. ``settings_for`` gives the narrow
settings an output reads, so editing one table's format rebuilds that table only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.evaluate.splits import load_eval
from physgs.evaluate.trajectories import load_trajectories
from physgs.experiments.kselect import load_selection
from physgs.experiments.recipe import heldout_split
from physgs.intermediate import read_json
from physgs.models.registry import BASE_CONFIG, MODEL_NAMES, REFERENCE_NAMES, config_label
from physgs.recovery.record import load_null, load_recovery
from physgs.report import kselect
from physgs.testbed.stats import load_stats

if TYPE_CHECKING:
    from physgs.report.tables import Table

TABLES = (
    "tab_testbed",
    "tab_psnr",
    "tab_null",
    "tab_transfer",
    "tab_margin",
    "tab_kselect",
    "tab_fit",
    "tab_damping",
    "tab_parts",
    "tab_parts_k",
    "tab_tracks",
)
FIGURES = ("fig_temporal", "fig_teaser", "fig_results", "fig_damping", "fig_parts", "fig_tracks")
#: The fields of each need tuple after its kind (what a workflow path template is formatted with).
NEED_FIELDS = {
    "eval": ("tree", "model", "config", "seed"),
    "traj": ("tree", "model", "config", "seed"),
    "panels": ("tree", "model", "config", "seed"),
    "loss": ("tree", "model", "config", "seed"),
    "recovery": ("tree", "config", "seed"),  # ours'
    "prior_recovery": ("tree", "model", "config", "seed"),  # any oscillator prior's
    "parts": ("tree", "seed"),  # the priors' segmentations (physgs.evaluate.parts)
    "kmatch": ("tree", "K", "seed"),  # the chained prior at a smaller K (experiments.kmatch)
    "null": ("tree", "K", "seed"),
    "kselect": ("tree", "seed"),
    "stats": ("tree",),
    "table": ("name",),
    # the 2D-track control (physgs.tracks): its recovery record (ours' format), its evaluation
    # record, its fit, one condition's tracks, and the observed dataset (fig_tracks' frame)
    "tracks_recovery": ("tree", "config", "seed"),
    "tracks_eval": ("tree", "config", "seed"),
    "tracks_fields": ("tree", "config", "seed"),  # the learned fields at the tracked points
    "tracks_fit": ("tree", "config", "seed"),
    "tracks": ("tree", "condition", "seed"),
    "observed": ("tree", "seed"),
}
#: Figures that show one training seed (qualitative: images, trajectories, a damping scatter);
#: they show the first seed listed.
ONE_SEED_FIGURES = ("fig_teaser", "fig_results", "fig_damping", "fig_parts", "fig_tracks")
#: Outputs of the parts study (``parts_needs``), built only when it trains a variant.
PARTS_OUTPUTS = ("tab_parts", "fig_parts", "tab_parts_k")
#: Outputs of the 2D-track control (``tracks_needs``).
TRACKS_OUTPUTS = ("tab_tracks", "fig_tracks")
#: Tables the claims ledger reads (their CSVs), and the configuration whose damping it reads.
CLAIMS_TABLES = ("tab_psnr", "tab_transfer", "tab_margin", "tab_null", "tab_testbed", "tab_fit")
CLAIMS_CONFIG = "joint32"
#: Models (trained in the base configuration) whose evaluation an output reads.
NEEDS_MODELS = {
    "tab_psnr": (*MODEL_NAMES, *REFERENCE_NAMES),
    "tab_transfer": MODEL_NAMES,
    "tab_margin": ("mlp_wind", "ours"),
    "fig_temporal": (*MODEL_NAMES, *REFERENCE_NAMES),
    "fig_teaser": MODEL_NAMES,
    "fig_results": MODEL_NAMES,
    "tab_fit": (*MODEL_NAMES, *REFERENCE_NAMES),
}
KSELECT_ROWS = tuple(c for c, _ in kselect.ROWS)
#: The prior every variant of the parts study is set beside, and the rows its fit fraction needs.
BASELINE_PRIOR = "ours"
FIT_FRAME = ("static", REFERENCE_NAMES[0])  # fixed K (single), chosen K (auto)


def key(need: tuple) -> str:
    """The name of a need in the inputs mapping: its parts joined by '/'."""
    return "/".join(str(p) for p in need)


def damping_needs(
    trees: Sequence[str],
    configs: Sequence[str],
    seeds: Sequence[int],
    tracks_configs: Sequence[str] = (),
) -> list[tuple]:
    """What tab_damping reads: ours' recovery on each benchmark tree's faithful and damping
    testbeds (``physgs.testbed.variant.damping_id``), per configuration and seed, and the 2D-track
    control's in ``tracks_configs``."""
    from physgs.testbed.variant import damping_id

    return [
        ("recovery", tb, c, int(s))
        for t in trees
        for tb in (t, damping_id(t))
        for c in configs
        for s in seeds
    ] + [
        ("tracks_recovery", tb, c, int(s))
        for t in trees
        for tb in (t, damping_id(t))
        for c in tracks_configs
        for s in seeds
    ]


def tracks_needs(
    name: str,
    trees: Sequence[str],
    configs: Sequence[str],
    seeds: Sequence[int],
    fields: Sequence[tuple[str, str]] = (),
) -> list[tuple]:
    """What tab_tracks or fig_tracks reads. configs: the configurations the control is fitted in
    (``tracks.configs``); fields: the (tree, configuration) pairs whose learned fields are scored
    at the tracked points (``physgs.tracks.settings.fields_scored``). tab_tracks: its evaluation
    record, ours' loss log (training seconds) and, for those pairs, the fields' scores, per tree,
    configuration and seed;
    fig_tracks: per tree, the observed frames, the training video's tracks and (with a
    configuration) the first configuration's fit, of the first seed."""
    if not seeds:
        raise ValueError("tracks_needs: no training seeds given")
    if name == "tab_tracks":
        return [
            (kind, t, *m, c, int(s))
            for s in seeds
            for t in trees
            for c in configs
            for kind, m in (("tracks_eval", ()), ("loss", ("ours",)))  # ours' training seconds
        ] + [("tracks_fields", t, c, int(s)) for s in seeds for t, c in fields]
    if name == "fig_tracks":
        s0 = int(seeds[0])
        out = []
        for t in trees:
            out += [("observed", t, s0), ("tracks", t, 0, s0)]
            out += [("tracks_fit", t, configs[0], s0)] if configs else []
        return out
    raise ValueError(f"tracks_needs: {name!r} is not one of {TRACKS_OUTPUTS}")


def parts_needs(
    name: str,
    trees: Sequence[str],
    damping_trees: Sequence[str],
    models: Sequence[str],
    configs: Mapping[str, dict],
    seeds: Sequence[int],
) -> list[tuple]:
    """What tab_parts or fig_parts reads. models: the parts study's variants (ours is added
    first); configs: its configurations (name -> {K, ...}); damping_trees: the trees (of
    ``trees``) also built as damping testbeds, where each prior's damping is scored. tab_parts:
    every prior's evaluation, loss log and recovery on each tree (and damping testbed), the
    null of each K, the static pose's and the ceiling's fit, and the segmentation record;
    fig_parts: the segmentation records of the first seed."""
    from physgs.testbed.variant import damping_id

    priors = [BASELINE_PRIOR, *models]
    if name == "fig_parts":
        return [("parts", t, int(seeds[0])) for t in trees]
    if name != "tab_parts":
        raise ValueError(
            f"parts_needs: {name!r} is not tab_parts or fig_parts (tab_parts_k: kmatch_needs)"
        )
    out = []
    for s in (int(x) for x in seeds):
        for t in trees:
            out += [(k, t, m, BASE_CONFIG, s) for m in FIT_FRAME for k in ("eval", "loss")]
            for c in configs:
                for m in priors:
                    out += [(k, t, m, c, s) for k in ("eval", "loss", "prior_recovery")]
                    if t in damping_trees:
                        out.append(("prior_recovery", damping_id(t), m, c, s))
            out += list(dict.fromkeys(("null", t, int(configs[c]["K"]), s) for c in configs))
            out.append(("parts", t, s))
    return out


def kmatch_needs(
    trees: Sequence[str], k_candidates: Sequence[int], seeds: Sequence[int]
) -> list[tuple]:
    """What tab_parts_k reads, at the studies' seeds: ours' and the chained prior's evaluation
    in the base configuration (their held-out training-window frames) and the chained prior's
    kmatch points at each smaller K."""
    out = []
    for s in (int(x) for x in seeds):
        for t in trees:
            out += [("eval", t, m, BASE_CONFIG, s) for m in (BASELINE_PRIOR, "ours_chain")]
            out += [("kmatch", t, int(k), s) for k in k_candidates]
    return out


def claims_needs(
    trees: Sequence[str],
    configs: Mapping[str, dict],
    seeds: Sequence[int],
    parts: bool = False,
    tracks: bool = False,
) -> list[tuple]:
    """What the claims ledger reads: the tables' CSVs and ours' recovery (damping) of every seed
    in the joint K=32 configuration (the paper's), or the base configuration when the config
    has none; with ``parts``, tab_parts too (the parts study's hypotheses); with ``tracks``,
    tab_tracks (the 2D-track control's; its recovery rows are in tab_null)."""
    c = CLAIMS_CONFIG if CLAIMS_CONFIG in configs else BASE_CONFIG
    extra = [("table", "tab_parts")] if parts else []
    extra += [("table", "tab_tracks")] if tracks else []
    return (
        [("table", n) for n in CLAIMS_TABLES]
        + extra
        + [("recovery", t, c, int(s)) for t in trees for s in seeds]
    )


def claims_frame(inputs: Mapping[str, str], trees: Sequence[str]) -> pd.DataFrame:
    """The claims ledger (``physgs.report.claims``) from the files in ``inputs`` (need key ->
    path, ``claims_needs``). The rule gives every table; a table left out of ``inputs`` leaves
    its claims "undecided: not measured" (a partial run's ledger, ``tools/ledger.py``)."""
    from physgs.report import claims

    names = (*CLAIMS_TABLES, "tab_parts", "tab_tracks")
    tabs = {n: pd.read_csv(inputs[key(("table", n))]) for n in names if key(("table", n)) in inputs}
    damping: dict[str, list] = {}
    for k, p in sorted(inputs.items()):  # recovery/<tree>/<config>/<seed>: one entry per seed
        if k.startswith("recovery/"):
            d = load_recovery(p).damping
            damping.setdefault(k.split("/")[1], []).append(
                {
                    "median_zeta": d.median_zeta,
                    "zeta_true": d.zeta_true,
                    "loglog_exponent": d.loglog_exponent,
                }
            )
    return claims.ledger(claims.measure(tabs, damping, trees))


def make_claims(inputs: Mapping[str, str], trees: Sequence[str], md_path, csv_path, stamp=None):
    """Build the claims ledger from the files in ``inputs`` (``claims_frame``) and write
    results/claims.md and .csv; returns the ledger."""
    from physgs.atomic import atomic_path, write_text
    from physgs.report import claims

    df = claims_frame(inputs, trees)
    sd = stamp.to_dict() if stamp is not None else None
    write_text(md_path, claims.ledger_markdown(df, sd))
    with atomic_path(csv_path) as tmp:
        (df.assign(**sd) if sd else df).to_csv(tmp, index=False, float_format="%.6g")
    return df


def needs(
    name: str,
    trees: Sequence[str],
    configs: Mapping[str, dict],
    seeds: Sequence[int],
    tracks: Mapping[str, int] | None = None,
) -> list[tuple]:
    """Every result an output reads, as need tuples (see the module docstring).

    configs: the config's ``models.configs`` (name -> {conditions, K}); the null control is
    keyed by K, so configurations sharing a K share one null. seeds: the training seeds; the
    figures of ``ONE_SEED_FIGURES`` read the first only. tracks: the 2D-track control's
    configurations (name -> its K, ``physgs.tracks.settings.parts``), whose recovery and null
    tab_null also reads.
    """
    if name not in (*TABLES, *FIGURES):
        raise ValueError(f"unknown output '{name}'; choose one of {TABLES + FIGURES}")
    if name == "tab_damping":
        raise ValueError("tab_damping reads the damping benchmark's testbeds: use damping_needs")
    if name in PARTS_OUTPUTS:
        raise ValueError(f"{name} reads the parts study's priors: use parts_needs")
    if name in TRACKS_OUTPUTS:
        raise ValueError(f"{name} reads the 2D-track control: use tracks_needs")
    if not seeds:
        raise ValueError("needs: no training seeds given")
    seeds = [int(seeds[0])] if name in ONE_SEED_FIGURES else [int(s) for s in seeds]
    out = []
    for s in seeds:
        out += [("eval", t, m, BASE_CONFIG, s) for t in trees for m in NEEDS_MODELS.get(name, ())]
        if name == "fig_teaser":
            out += [("traj", t, m, BASE_CONFIG, s) for t in trees for m in MODEL_NAMES]
        if name == "fig_results":
            out += [("panels", t, m, BASE_CONFIG, s) for t in trees for m in MODEL_NAMES]
        if name == "tab_fit":
            out += [("loss", t, m, BASE_CONFIG, s) for t in trees for m in NEEDS_MODELS[name]]
        if name in ("tab_null", "fig_damping"):
            out += [("recovery", t, c, s) for t in trees for c in configs]
        if name == "tab_null":
            tk = dict(tracks or {})
            out += [("tracks_recovery", t, c, s) for t in trees for c in tk]
            out += list(
                dict.fromkeys(
                    [("null", t, int(configs[c]["K"]), s) for t in trees for c in configs]
                    + [("null", t, int(k), s) for t in trees for k in tk.values()]
                )
            )
        if name == "tab_kselect":
            for t in trees:
                out.append(("kselect", t, s))
                out += [
                    x
                    for c in KSELECT_ROWS
                    for x in (("eval", t, "ours", c, s), ("recovery", t, c, s))
                ]
    if name == "tab_testbed":
        out += [("stats", t) for t in trees]
    return out


def settings_for(name: str, cfg: dict) -> dict:
    """The settings output ``name`` reads from the resolved config (and nothing more)."""
    trees = list(cfg["damping_benchmark"]["trees"] if name == "tab_damping" else cfg["trees"])
    out = {"trees": trees, "bones": {t: int(cfg["presets"][t]["bones"]) for t in trees}}
    if name == "tab_damping":
        out["configs"] = {
            c: config_label(c, cfg["models"]["configs"][c])
            for c in cfg["damping_benchmark"]["configs"]
        }
        out["tracks_configs"] = {
            c: _tracks_label(cfg, c)
            for c in cfg["damping_benchmark"]["configs"]
            if c in cfg["tracks"]["configs"]
        }
    if name not in ("tab_testbed", *ONE_SEED_FIGURES):
        out["seeds"] = [int(x) for x in cfg["seeds"]]
    elif name in ONE_SEED_FIGURES:
        out["seeds"] = [int(cfg["seeds"][0])]
    if name in TABLES:
        out["digits"] = int(cfg["report"][name]["digits"])
    if name in ("tab_null", "fig_damping"):
        out["configs"] = {
            c: {"K": int(v["K"]), "conditions": v["conditions"]}
            for c, v in cfg["models"]["configs"].items()
        }
    if name == "tab_null":
        from physgs.tracks.settings import parts as tracks_k

        out["tracks"] = {
            c: {"K": tracks_k(cfg, c)[0], "label": _tracks_label(cfg, c)}
            for c in cfg["tracks"]["configs"]
        }
    if name == "tab_tracks":
        out["configs"] = {
            c: {
                "label": _tracks_label(cfg, c),
                "conditions": cfg["models"]["configs"][c]["conditions"],
            }
            for c in cfg["tracks"]["configs"]
        }
        out["conditions"] = [float(c) for c in cfg["testbed"]["conditions"]]
    if name == "fig_tracks":
        out["configs"] = list(cfg["tracks"]["configs"])
    if name in ("tab_transfer", "tab_margin", "fig_teaser", "fig_results"):
        out["conditions"] = [float(c) for c in cfg["testbed"]["conditions"]]
    if name in ("fig_temporal", "tab_fit"):
        out["n_train"] = int(cfg["testbed"]["n_train"])
    if name == "tab_fit":
        out["holdout_every"] = int(cfg["train"]["holdout_every"])
    if name == "fig_damping":
        out["zeta"] = float(cfg["testbed"]["zeta"])
    if name == "tab_kselect":
        out["method"] = cfg["models"]["kselect"]["method"]
    if name in PARTS_OUTPUTS:
        out["models"] = [BASELINE_PRIOR, *cfg["parts_study"]["models"]]
    if name == "tab_parts_k":
        from physgs.config import study_seeds

        out["seeds"] = [int(x) for x in study_seeds(cfg)]
        out["K"] = int(cfg["models"]["configs"][BASE_CONFIG]["K"])
        out["k_candidates"] = [int(k) for k in cfg["parts_study"]["k_candidates"]]
        out["tie_db"] = float(cfg["models"]["kselect"]["tie_db"])
        out["n_train"] = int(cfg["testbed"]["n_train"])
        out["holdout_every"] = int(cfg["train"]["holdout_every"])
    if name == "tab_parts":
        out["configs"] = {
            c: config_label(c, cfg["models"]["configs"][c]) for c in cfg["parts_study"]["configs"]
        }
        out["K"] = {c: int(cfg["models"]["configs"][c]["K"]) for c in cfg["parts_study"]["configs"]}
        out["damping_trees"] = [t for t in cfg["damping_benchmark"]["trees"] if t in cfg["trees"]]
        out["n_train"] = int(cfg["testbed"]["n_train"])
        out["holdout_every"] = int(cfg["train"]["holdout_every"])
    return out


def _tracks_label(cfg: dict, config: str) -> str:
    """The LaTeX label of the 2D-track control's configuration ``config`` with its own K."""
    from physgs.tracks.settings import parts as tracks_k

    spec = {**cfg["models"]["configs"][config], "K": tracks_k(cfg, config)[0]}
    return config_label(config, spec)


def _reader(inputs: Mapping[str, str]):
    def path(*need) -> str:
        k = key(need)
        if k not in inputs:
            raise KeyError(
                f"no input file for {k!r}; the rule must declare report needs "
                f"(physgs.report.build.needs)"
            )
        return inputs[k]

    return path


def _summaries(path, trees, models, seeds):
    """{seed: {(tree, model): summary}} of the models trained ``single``."""
    return {
        s: {
            (t, m): load_eval(path("eval", t, m, BASE_CONFIG, s)).summary()
            for t in trees
            for m in models
        }
        for s in seeds
    }


def fit_row(eval_path, loss_path, n_train: int, holdout_every: int) -> dict:
    """One tab_fit row from a model's evaluation and loss log: fit and held-out-frame PSNR (dB,
    training camera and wind, frames < n_train), view and time PSNR (dB), training seconds
    (NaN without a loss log)."""
    ev = load_eval(eval_path)
    cam = np.asarray(ev.camera_psnr[0, :n_train], dtype=np.float64)  # [n_train] dB
    if holdout_every:
        trained, held = heldout_split(n_train, holdout_every)
    else:
        trained, held = np.arange(n_train), np.arange(0)
    s = ev.summary()
    secs = pd.read_csv(loss_path)["seconds"] if loss_path is not None else pd.Series([np.nan])
    return {
        "fit": float(cam[trained].mean()),
        "heldout": float(cam[held].mean()) if held.size else float("nan"),
        "view": s["view"],
        "time": s["time"],
        "train_s": float(secs.iloc[-1]),
    }


def make_table(
    name: str, inputs: Mapping[str, str], settings: dict, tex_path, csv_path, stamp=None
) -> Table:
    """Build table ``name`` from the files in ``inputs`` (need key -> path) and write its .tex
    and .csv. settings: ``settings_for(name, cfg)``; stamp: a ``physgs.provenance.Stamp``
    written into every CSV row (profile, config hash, package version)."""
    from physgs.report import tables

    path = _reader(inputs)
    trees, bones, d = settings["trees"], settings["bones"], settings.get("digits", 2)
    seeds = [int(x) for x in settings.get("seeds", ())]
    if name == "tab_testbed":
        table = tables.tab_testbed(
            {t: load_stats(path("stats", t)) for t in trees}, trees, digits=d
        )
    elif name == "tab_psnr":
        table = tables.tab_psnr(
            _summaries(path, trees, (*MODEL_NAMES, *REFERENCE_NAMES), seeds),
            trees,
            bones,
            digits=d,
            references=REFERENCE_NAMES,
        )
    elif name == "tab_fit":
        rows = {
            s: {
                (t, m): fit_row(
                    path("eval", t, m, BASE_CONFIG, s),
                    path("loss", t, m, BASE_CONFIG, s),
                    int(settings["n_train"]),
                    int(settings["holdout_every"]),
                )
                for t in trees
                for m in NEEDS_MODELS[name]
            }
            for s in seeds
        }
        table = tables.tab_fit(
            rows,
            trees,
            bones,
            MODEL_NAMES,
            REFERENCE_NAMES[0],
            digits=d,
            holdout_every=int(settings["holdout_every"]),
        )
    elif name == "tab_transfer":
        table = tables.tab_transfer(
            _summaries(path, trees, MODEL_NAMES, seeds),
            trees,
            bones,
            settings["conditions"],
            digits=d,
        )
    elif name == "tab_margin":
        table = tables.tab_margin(
            _summaries(path, trees, ("mlp_wind", "ours"), seeds),
            trees,
            bones,
            settings["conditions"],
            digits=d,
        )
    elif name == "tab_null":
        configs = settings["configs"]
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
        labels = {c: config_label(c, v) for c, v in configs.items()}
        tk = settings.get("tracks", {})
        tracks = {
            s: {
                (t, c): (
                    load_recovery(path("tracks_recovery", t, c, s)),
                    load_null(path("null", t, int(tk[c]["K"]), s)),
                )
                for t in trees
                for c in tk
            }
            for s in seeds
        }
        table = tables.tab_null(
            rec,
            null,
            trees,
            bones,
            labels,
            digits=d,
            tracks=tracks,
            tracks_configs={c: v["label"] for c, v in tk.items()},
        )
    elif name == "tab_damping":
        from physgs.report.damping import tab_damping
        from physgs.testbed.variant import DAMPING, FAITHFUL, damping_id

        ids = {FAITHFUL: lambda t: t, DAMPING: damping_id}
        rows = {
            s: {
                (t, v, c): load_recovery(path("recovery", ids[v](t), c, s))
                for t in trees
                for v in ids
                for c in settings["configs"]
            }
            for s in seeds
        }
        tc = settings.get("tracks_configs", {})
        tracks = {
            s: {
                (t, v, c): load_recovery(path("tracks_recovery", ids[v](t), c, s))
                for t in trees
                for v in ids
                for c in tc
            }
            for s in seeds
        }
        table = tab_damping(
            rows,
            trees,
            bones,
            settings["configs"],
            digits=d,
            tracks=tracks,
            tracks_configs=tc,
        )
    elif name == "tab_parts":
        table = _tab_parts(path, settings, trees, bones, seeds, d)
    elif name == "tab_tracks":
        from physgs.report.tracks import tab_tracks

        scores = {}
        for s in seeds:
            scores[s] = {}
            for t in trees:
                for c in settings["configs"]:
                    scores[s][(t, c)] = read_json(
                        path("tracks_eval", t, c, s), rule="tracks_evaluate"
                    )
                    if key(("tracks_fields", t, c, s)) in inputs:  # {case: {field: errors}}
                        fields = read_json(path("tracks_fields", t, c, s), rule="tracks_fields")
                        for case, f in fields.items():
                            scores[s][(t, c)][case]["fields"] = f
                    loss = pd.read_csv(path("loss", t, "ours", c, s))
                    scores[s][(t, c)]["ours_train_s"] = float(loss["seconds"].iloc[-1])
        table = tab_tracks(
            scores, trees, bones, settings["configs"], settings["conditions"], digits=d
        )
    elif name == "tab_parts_k":
        table = _tab_parts_k(path, settings, trees, bones, seeds, d)
    elif name == "tab_kselect":
        rows = {}
        for s in seeds:
            rows[s] = {}
            for t in trees:
                sel = load_selection(path("kselect", t, s))
                for c in KSELECT_ROWS:
                    ev = load_eval(path("eval", t, "ours", c, s)).summary()
                    rec = load_recovery(path("recovery", t, c, s))
                    rows[s][(t, c)] = {
                        "K": rec.match.n_parts,
                        "time_psnr": ev["time"],
                        "median_rel_err": rec.match.median_rel_err,
                        "trusted": rec.match.n_trusted,
                        "frozen": rec.n_frozen,
                        "k_heldout": sel.k_heldout,
                        "k_bic": sel.k_bic,
                    }
        table = kselect.tab_kselect(rows, trees, bones, settings["method"], digits=d)
    else:
        raise ValueError(f"unknown table '{name}'; choose one of {TABLES}")
    tables.write_table(table, tex_path, csv_path, stamp=stamp)
    return table


def _tab_parts(path, settings, trees, bones, seeds, digits) -> Table:
    from physgs.evaluate.parts import load_segmentations
    from physgs.report import parts
    from physgs.testbed.variant import damping_id

    models, configs = settings["models"], settings["configs"]
    n, every = int(settings["n_train"]), int(settings["holdout_every"])
    rows: dict[int, dict] = {}
    for s in seeds:
        rows[s] = {}
        for t in trees:
            frame = {
                m: fit_row(
                    path("eval", t, m, BASE_CONFIG, s), path("loss", t, m, BASE_CONFIG, s), n, every
                )
                for m in FIT_FRAME
            }
            seg = load_segmentations(path("parts", t, s))
            for c in configs:
                null = load_null(path("null", t, int(settings["K"][c]), s))
                for m in models:
                    damp = (
                        load_recovery(path("prior_recovery", damping_id(t), m, c, s))
                        if t in settings["damping_trees"]
                        else None
                    )
                    rows[s][(t, m, c)] = parts.row(
                        fit_row(path("eval", t, m, c, s), path("loss", t, m, c, s), n, every),
                        frame["static"]["fit"],
                        frame[FIT_FRAME[1]]["fit"],
                        load_recovery(path("prior_recovery", t, m, c, s)),
                        null,
                        damp,
                        purity=float(seg[f"{m}/overall"]) if c == BASE_CONFIG else float("nan"),
                    )
    return parts.tab_parts(rows, trees, bones, models, configs, digits=digits)


def _tab_parts_k(path, settings, trees, bones, seeds, digits) -> Table:

    from physgs.report import parts

    n, every, K = int(settings["n_train"]), int(settings["holdout_every"]), int(settings["K"])

    def held(m, t, s):
        return fit_row(path("eval", t, m, BASE_CONFIG, s), None, n, every)["heldout"]

    rows: dict[int, dict] = {}
    for s in seeds:
        rows[s] = {}
        for t in trees:
            chain = {K: held("ours_chain", t, s)}
            for k in settings["k_candidates"]:
                point = read_json(
                    path("kmatch", t, int(k), s), ("heldout_psnr",), rule="kmatch_point"
                )
                chain[int(k)] = float(point["heldout_psnr"])
            rows[s][t] = {"ours": held(BASELINE_PRIOR, t, s), "chain": chain}
    return parts.tab_parts_k(rows, trees, bones, K, float(settings["tie_db"]), digits=digits)


def _teaser_tree(trees: Sequence[str]) -> str:
    """The tree the teaser shows: medium if built (the paper's clearest case), else the last."""
    return "medium" if "medium" in trees else trees[-1]


def make_figure(
    name: str, inputs: Mapping[str, str], settings: dict, outputs: Sequence[str]
) -> None:
    """Build figure ``name`` from the files in ``inputs`` (need key -> path), written to every
    path in ``outputs``. settings: ``settings_for(name, cfg)``."""
    from physgs.report import figures  # matplotlib: not for the workflow's planning imports

    path = _reader(inputs)
    trees = settings["trees"]
    seeds = [int(x) for x in settings["seeds"]]
    s0 = seeds[0]  # what the one-seed figures show
    if name == "fig_temporal":
        curves = {
            (t, m): np.stack(
                [load_eval(path("eval", t, m, BASE_CONFIG, s)).temporal_psnr for s in seeds]
            )
            for t in trees
            for m in NEEDS_MODELS[name]
        }
        figures.fig_temporal(curves, trees, int(settings["n_train"]), outputs)
    elif name == "fig_teaser":
        t = _teaser_tree(trees)
        evals = {m: load_eval(path("eval", t, m, BASE_CONFIG, s0)) for m in MODEL_NAMES}
        base = figures.best_baseline({m: e.summary() for m, e in evals.items()}, key="time")
        shown = ("ours", base)
        traj = {m: load_trajectories(path("traj", t, m, BASE_CONFIG, s0)) for m in shown}
        cen = {m: evals[m].centroid_err for m in shown}
        figures.fig_teaser(
            traj, cen, settings["conditions"], outputs, title=f"{t} tree, training seed {s0}"
        )
    elif name == "fig_results":
        rows, images = [], {}
        for t in trees:
            panels = {m: np.load(path("panels", t, m, BASE_CONFIG, s0)) for m in MODEL_NAMES}
            for split in ("time", "view", "wind"):
                row = f"{t}: unseen {split}"
                rows.append(row)
                images[(row, "gt")] = (panels["ours"][f"{split}_gt"], None)
                for m in MODEL_NAMES:
                    images[(row, m)] = (
                        panels[m][f"{split}_pred"],
                        float(panels[m][f"{split}_psnr"]),
                    )
        figures.fig_results(rows, ["gt", *MODEL_NAMES], images, outputs)
    elif name == "fig_damping":
        configs = list(settings["configs"])
        damping = {
            (t, c): load_recovery(path("recovery", t, c, s0)).damping
            for t in trees
            for c in configs
        }
        figures.fig_damping(damping, trees, configs, float(settings["zeta"]), outputs)
    elif name == "fig_parts":
        from physgs.evaluate.parts import load_segmentations
        from physgs.report.parts import fig_parts

        recs = {t: load_segmentations(path("parts", t, s0)) for t in trees}
        fig_parts(recs, trees, outputs, title=f"parts of each prior (single), training seed {s0}")
    elif name == "fig_tracks":
        _fig_tracks(path, settings, trees, s0, outputs)
    else:
        raise ValueError(f"unknown figure '{name}'; choose one of {FIGURES}")


def _fig_tracks(path, settings, trees, s0, outputs) -> None:
    from physgs.report.tracks import fig_tracks
    from physgs.tracks.store import load_fit, load_tracks

    configs = list(settings["configs"])
    frames, tracks, labels = {}, {}, {}
    for t in trees:
        with np.load(path("observed", t, s0)) as z:
            frames[t] = z["frames"][0, 0]  # training condition, recorded frame 0 [H, W, 3]
        tracks[t], _ = load_tracks(path("tracks", t, 0, s0))
        labels[t] = None
        if configs:  # each track's part; -1 (grey) where not fitted or its part has no estimate
            fit = load_fit(path("tracks_fit", t, configs[0], s0))[0]
            lab = fit.labels[0]
            labels[t] = np.where((lab >= 0) & fit.estimated[np.maximum(lab, 0)], lab, -1)
    what = f"colour: part in the {configs[0]} fit; " if configs else ""
    fig_tracks(frames, tracks, labels, trees, outputs, title=f"2D tracks ({what}seed {s0})")
