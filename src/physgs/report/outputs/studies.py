"""The parts study's outputs: tab_parts (every prior's fit, recovery and damping,
with parts cut by k-means or along the tree), fig_parts (their segmentations) and tab_parts_k
(the smallest K at which the chained prior matches ours)."""

from __future__ import annotations

from physgs.evaluate.parts import load_segmentations
from physgs.intermediate import read_json
from physgs.models.registry import BASE_CONFIG, REFERENCE_NAMES, config_label
from physgs.recovery.record import load_null, load_recovery
from physgs.report import parts
from physgs.report.outputs.base import Columns, Output
from physgs.report.outputs.views import fit_row, fit_settings
from physgs.report.parts import fig_parts
from physgs.testbed.variant import damping_id

#: The prior every variant of the parts study is set beside, and the rows its fit fraction needs.
BASELINE_PRIOR = "ours"
FIT_FRAME = ("static", REFERENCE_NAMES[0])


def _studied(plan) -> bool:
    return bool(plan.parts_models)


# ---- tab_parts -----------------------------------------------------------------------------
def _parts_needs(plan, seeds):
    """Every prior's evaluation, loss log and recovery on each tree (and damping testbed), the
    null of each K, the static pose's and the ceiling's fit, and the segmentation record."""
    priors = [BASELINE_PRIOR, *plan.parts_models]
    configs = plan.parts_configs
    damping_trees = [t for t in plan.damping_trees if t in plan.trees]
    out = []
    for s in (int(x) for x in seeds):
        for t in plan.trees:
            out += [(k, t, m, BASE_CONFIG, s) for m in FIT_FRAME for k in ("eval", "loss")]
            for c in configs:
                for m in priors:
                    out += [(k, t, m, c, s) for k in ("eval", "loss", "recovery")]
                    if t in damping_trees:
                        out.append(("recovery", damping_id(t), m, c, s))
            out += list(dict.fromkeys(("null", t, int(configs[c]["K"]), s) for c in configs))
            out.append(("parts", t, s))
    return out


def _parts_settings(cfg: dict) -> dict:
    study = cfg["parts_study"]
    return {
        "models": [BASELINE_PRIOR, *study["models"]],
        "configs": {c: config_label(c, cfg["models"]["configs"][c]) for c in study["configs"]},
        "K": {c: int(cfg["models"]["configs"][c]["K"]) for c in study["configs"]},
        "damping_trees": [t for t in cfg["damping_benchmark"]["trees"] if t in cfg["trees"]],
        **fit_settings(cfg),
    }


def _tab_parts(path, settings, inputs, out):
    trees, models, configs = settings["trees"], settings["models"], settings["configs"]
    n, every = int(settings["n_train"]), int(settings["holdout_every"])
    rows: dict[int, dict] = {}
    for s in settings["seeds"]:
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
                        load_recovery(path("recovery", damping_id(t), m, c, s))
                        if t in settings["damping_trees"]
                        else None
                    )
                    rows[s][(t, m, c)] = parts.row(
                        fit_row(path("eval", t, m, c, s), path("loss", t, m, c, s), n, every),
                        frame["static"]["fit"],
                        frame[FIT_FRAME[1]]["fit"],
                        load_recovery(path("recovery", t, m, c, s)),
                        null,
                        damp,
                        purity=float(seg[f"{m}/overall"]) if c == BASE_CONFIG else float("nan"),
                    )
    return parts.tab_parts(
        rows, trees, settings["bones"], models, configs, digits=settings["digits"]
    )


PARTS_COLUMNS = Columns(
    keys=("seed", "tree", "model", "config"),
    values=tuple(c for c in parts.COLUMNS if c != "train_s"),  # the table's own column list
    timing=("train_s",),
    about=("bones",),
)

TAB_PARTS = Output(
    "tab_parts",
    "table",
    _parts_needs,
    _tab_parts,
    settings=_parts_settings,
    in_report=_studied,
    columns=PARTS_COLUMNS,
)


# ---- fig_parts -----------------------------------------------------------------------------
def _fig_parts(path, settings, inputs, out):
    trees, s0 = settings["trees"], settings["seeds"][0]
    recs = {t: load_segmentations(path("parts", t, s0)) for t in trees}
    fig_parts(recs, trees, out, title=f"parts of each prior (single), training seed {s0}")


FIG_PARTS = Output(
    "fig_parts",
    "figure",
    lambda plan, seeds: [("parts", t, int(seeds[0])) for t in plan.trees],
    _fig_parts,
    settings=lambda cfg: {"models": [BASELINE_PRIOR, *cfg["parts_study"]["models"]]},
    seeds="first",
    in_report=_studied,
)


# ---- tab_parts_k ---------------------------------------------------------------------------
def _kmatch_needs(plan, seeds):
    """Ours' and the chained prior's evaluation in the base configuration (their held-out
    training-window frames) and the chained prior's kmatch points at each smaller K."""
    out = []
    for s in (int(x) for x in seeds):
        for t in plan.trees:
            out += [("eval", t, m, BASE_CONFIG, s) for m in (BASELINE_PRIOR, "ours_chain")]
            out += [("kmatch", t, int(k), s) for k in plan.k_candidates]
    return out


def _kmatch_settings(cfg: dict) -> dict:
    return {
        "models": [BASELINE_PRIOR, *cfg["parts_study"]["models"]],
        "K": int(cfg["models"]["configs"][BASE_CONFIG]["K"]),
        "k_candidates": [int(k) for k in cfg["parts_study"]["k_candidates"]],
        "tie_db": float(cfg["models"]["kselect"]["tie_db"]),
        **fit_settings(cfg),
    }


def _tab_parts_k(path, settings, inputs, out):
    n, every, K = int(settings["n_train"]), int(settings["holdout_every"]), int(settings["K"])

    def held(m, t, s):
        return fit_row(path("eval", t, m, BASE_CONFIG, s), None, n, every)["heldout"]

    rows: dict[int, dict] = {}
    for s in settings["seeds"]:
        rows[s] = {}
        for t in settings["trees"]:
            chain = {K: held("ours_chain", t, s)}
            for k in settings["k_candidates"]:
                point = read_json(
                    path("kmatch", t, int(k), s), ("heldout_psnr",), rule="kmatch_point"
                )
                chain[int(k)] = float(point["heldout_psnr"])
            rows[s][t] = {"ours": held(BASELINE_PRIOR, t, s), "chain": chain}
    return parts.tab_parts_k(
        rows,
        settings["trees"],
        settings["bones"],
        K,
        float(settings["tie_db"]),
        digits=settings["digits"],
    )


#: tab_parts_k's CSV: the chained prior at several K (a numeric key)
PARTS_K_COLUMNS = Columns(
    keys=("seed", "tree", "model", "K"), values=("heldout_psnr_db", "matched_k"), about=("bones",)
)

TAB_PARTS_K = Output(
    "tab_parts_k",
    "table",
    _kmatch_needs,
    _tab_parts_k,
    settings=_kmatch_settings,
    seeds="studies",
    in_report=lambda plan: False,  # a study: the `studies` target (Snakefile)
    columns=PARTS_K_COLUMNS,
)
