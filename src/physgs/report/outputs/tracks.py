"""The 2D-track control's outputs (docs/tracks.md): tab_tracks (the fit's scores beside ours'
and the learned fields' at the tracked points) and fig_tracks (the tracks and their parts)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from physgs.intermediate import read_json
from physgs.report.outputs.base import Columns, Output, key
from physgs.report.outputs.recovery import label_with_k
from physgs.report.tracks import TRACKER_COLUMNS, fig_tracks, tab_tracks
from physgs.tracks.settings import parts as tracks_k
from physgs.tracks.store import load_fit, load_tracks


def _controlled(plan) -> bool:
    return bool(plan.tracks)


# ---- tab_tracks ----------------------------------------------------------------------------
def _tab_tracks_needs(plan, seeds):
    """Its evaluation record, ours' loss log (training seconds) and, for ``plan.tracks_fields``,
    the fields' scores, per tree, configuration and seed."""
    return [
        (kind, t, *m, c, int(s))
        for s in seeds
        for t in plan.trees
        for c in plan.tracks
        for kind, m in (("tracks_eval", ()), ("loss", ("ours",)))  # ours' training seconds
    ] + [("tracks_fields", t, c, int(s)) for s in seeds for t, c in plan.tracks_fields]


def _tab_tracks_settings(cfg: dict) -> dict:
    return {
        "configs": {
            c: {
                "label": label_with_k(cfg, c, tracks_k(cfg, c)[0]),
                "conditions": cfg["models"]["configs"][c]["conditions"],
            }
            for c in cfg["tracks"]["configs"]
        },
        "conditions": [float(c) for c in cfg["testbed"]["conditions"]],
    }


def _tab_tracks(path, settings, inputs, out):
    scores = {}
    for s in settings["seeds"]:
        scores[s] = {}
        for t in settings["trees"]:
            for c in settings["configs"]:
                scores[s][(t, c)] = read_json(path("tracks_eval", t, c, s), rule="tracks_evaluate")
                if key(("tracks_fields", t, c, s)) in inputs:  # {case: {field: errors}}
                    fields = read_json(path("tracks_fields", t, c, s), rule="tracks_fields")
                    for case, f in fields.items():
                        scores[s][(t, c)][case]["fields"] = f
                loss = pd.read_csv(path("loss", t, "ours", c, s))
                scores[s][(t, c)]["ours_train_s"] = float(loss["seconds"].iloc[-1])
    return tab_tracks(
        scores,
        settings["trees"],
        settings["bones"],
        settings["configs"],
        settings["conditions"],
        digits=settings["digits"],
    )


#: tab_tracks' CSV: the tracker, the fit and the displacement errors per case (``tail``, each
#: unseen wind) of the control, ours, the best field, the static pose and each field scored
TRACKS_COLUMNS = Columns(
    keys=("seed", "tree", "config"),
    values=(
        *TRACKER_COLUMNS,
        "parts_estimated",
        "n_fitted",
        "fit_rms_px",
        *(
            f"{case}{who}_px"
            for case in ("tail", "wind_{wind}")
            for who in ("", "_ours", "_best_field", "_static", "_field_{model}")
        ),
    ),
    timing=("fit_s", "ours_train_s"),
    about=("bones", "conditions", "K"),
)

TAB_TRACKS = Output(
    "tab_tracks",
    "table",
    _tab_tracks_needs,
    _tab_tracks,
    settings=_tab_tracks_settings,
    in_report=_controlled,
    columns=TRACKS_COLUMNS,
)


# ---- fig_tracks ----------------------------------------------------------------------------
def _fig_tracks_needs(plan, seeds):
    """Per tree, the observed frames, the training video's tracks and (with a configuration)
    the first configuration's fit, of the first seed."""
    s0, configs = int(seeds[0]), list(plan.tracks)
    out = []
    for t in plan.trees:
        out += [("observed", t, s0), ("tracks", t, 0, s0)]
        out += [("tracks_fit", t, configs[0], s0)] if configs else []
    return out


def _fig_tracks(path, settings, inputs, out):
    trees, s0, configs = settings["trees"], settings["seeds"][0], list(settings["configs"])
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
    fig_tracks(frames, tracks, labels, trees, out, title=f"2D tracks ({what}seed {s0})")


FIG_TRACKS = Output(
    "fig_tracks",
    "figure",
    _fig_tracks_needs,
    _fig_tracks,
    settings=lambda cfg: {"configs": list(cfg["tracks"]["configs"])},
    seeds="first",  # drawn without a fit's parts when the control fits nothing
)
