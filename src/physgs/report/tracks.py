"""tab_tracks and fig_tracks: the 2D-track control ([`physgs.tracks`][], docs/tracks.md): its
tracker, its fit and its predicted tracks' motion errors beside ours', the best learned field's
and a motionless prediction's at the same points; the tracks drawn over frame 0."""

from __future__ import annotations

from functools import partial
from itertools import product
from typing import Mapping, Sequence

import numpy as np
import pandas as pd

from physgs.intermediate import read_json
from physgs.models.registry import PAPER_MODEL
from physgs.report import latex
from physgs.report.output import Columns, Output, key
from physgs.report.recovery import _label_with_k
from physgs.report.table_captions import caption
from physgs.report.tables import Table, condition_label, seed_rows, seeds_of, tree_label
from physgs.tracks.settings import parts as tracks_k
from physgs.tracks.store import load_fit, load_tracks

#: tab_tracks' tracker columns -> their entry in the evaluation record's ``tracker``
TRACKER = {
    "n_tracks": "n_tracks",
    "n_seed0": "n_seed0",
    "share_kept": "share_kept",
    "track_median_px": "median_px",
    "track_p90_px": "p90_px",
    "disp_median_px": "disp_median_px",
    "disp_p90_px": "disp_p90_px",
}
#: its fit columns -> their entry in the record's ``fit``
FIT = {"K": "K", "parts_estimated": "n_estimated", "n_fitted": "n_fitted", "fit_s": "seconds"}
#: each motion prediction's column suffix and .tex heading
WHO = {"": "Tracks", "_ours": "Ours", "_best_field": "Field", "_static": "Still"}
#: the motion columns: per case (``tail``, each unseen wind), each prediction's and each field's
MOTION = [f"{c}{who}_px" for c in ("tail", "wind_{wind}") for who in (*WHO, "_field_{model}")]


def _stems(conditions: Sequence[float]) -> list[str]:
    """The motion cases' column stems: 'tail', then 'wind_<mult>v0' per unseen wind."""
    return ["tail", *("wind_" + condition_label(float(c), tex=False) for c in conditions[1:])]


def _row(scores: Mapping, conditions: Sequence[float]) -> dict[str, float]:
    """One tab_tracks row (px, s) from ``evaluate_job``'s scores (+ ``ours_train_s``). Per
    motion case (KeyError if missing): ``<case>_px`` (the control), ``<case>_ours_px``,
    ``<case>_field_<id>_px``, ``<case>_best_field_px`` (NaN when unscored), ``<case>_static_px``.
    """
    tr, fit = scores["tracker"], scores["fit"]
    out = {c: float(tr[k]) for c, k in TRACKER.items()} | {c: float(fit[k]) for c, k in FIT.items()}
    out["ours_train_s"] = float(scores.get("ours_train_s", float("nan")))
    out["fit_rms_px"] = float(fit["rms_px"])
    cases = ["tail", *(f"wind{c}" for c in range(1, len(conditions)))]
    for case, stem in zip(cases, _stems(conditions)):
        if case not in scores:
            raise KeyError(f"tab_tracks: the evaluation record has no {case!r} motion scores")
        sc = scores[case]
        ours = sc.get("ours")
        out[f"{stem}_px"] = float(sc["tracks"]["motion_median_px"])
        out[f"{stem}_ours_px"] = float(ours["motion_median_px"]) if ours else float("nan")
        fields = {m: float(e["motion_median_px"]) for m, e in sc.get("fields", {}).items()}
        out |= {f"{stem}_field_{m}_px": v for m, v in fields.items()}
        finite = [v for v in fields.values() if np.isfinite(v)]
        out[f"{stem}_best_field_px"] = min(finite) if finite else float("nan")
        out[f"{stem}_static_px"] = float(sc["tracks"]["static_median_px"])
    return out


def tab_tracks(
    per_seed: Mapping[int, Mapping[tuple[str, str], Mapping]],
    trees: Sequence[str],
    bones: Mapping[str, int],
    configs: Mapping[str, Mapping],
    conditions: Sequence[float],
    digits: int = 2,
) -> Table:
    """The 2D-track control per tree and configuration.

    Args:
        per_seed: ``per_seed[seed][(tree, config)]``: an evaluation record
            ([`evaluate_job`][physgs.tracks.run.evaluate_job]'s scores).
        trees: the trees.
        bones: tree -> its bone count.
        configs: name -> {"label": LaTeX, "conditions": 'train' | 'all'}, in row order.
        conditions: the testbed's multipliers.
        digits: decimals shown in the .tex.

    Returns:
        The table: one CSV row per seed, tree and configuration; the .tex mean +- sd over seeds.
    """
    keys = [(t, c) for t in trees for c in configs]
    seeds = seeds_of(per_seed, "tab_tracks", keys)

    about = lambda t, c: dict(tree=t, bones=bones[t], config=c, conditions=configs[c]["conditions"])
    df = seed_rows(seeds, keys, lambda s, t, c: about(t, c) | _row(per_seed[s][(t, c)], conditions))
    col = lambda c, fmt=f".{int(digits)}f", **kw: pd.Series(latex.cells(df, c, fmt, **kw))
    mean = partial(col, fmt=".0f", cell=latex.mean)  # counts and shares: no sd
    kept = mean("n_tracks") + " (" + mean("share_kept", scale=100) + r"\%)"
    columns = {  # a 'median / 90th percentile' pair in one cell
        ("Tracker", "Tracks (kept)"): kept,
        ("Tracker", "Error (px)"): col("track_median_px") + " / " + col("track_p90_px"),
        ("Tracker", r"Displ.\ (px)"): col("disp_median_px") + " / " + col("disp_p90_px"),
        ("Fit", "Parts"): mean("parts_estimated") + "/" + mean("K"),
        ("Fit", "s"): col("fit_s", ".0f"),
        ("Fit", "ours (s)"): col("ours_train_s", ".0f"),
    }
    winds = [f"wind {condition_label(float(c))}" for c in conditions[1:]]
    for head, stem in zip(["beyond the window", *winds], _stems(conditions)):
        for suffix, who in WHO.items():
            columns[(f"{head} (px)", who)] = col(f"{stem}{suffix}_px")
    rows = [(tree_label(t, bones[t]), configs[c]["label"]) for t, c in keys]
    index = pd.MultiIndex.from_tuples(rows, names=["Tree", "Config"])
    cells = pd.DataFrame(columns).set_axis(index)
    joint = ", ".join(c.replace("_", r"\_") for c in configs if configs[c]["conditions"] != "train")
    cap = caption("tab_tracks", *(["tab_tracks_joint"] if joint else []), joint=joint)
    cap += latex.seed_note(len(seeds), decides=False)
    return Table("tab_tracks", df, latex.render(cells, cap, "tab:tracks"))


def fig_tracks(
    frames: Mapping[str, np.ndarray],
    tracks: Mapping[str, object],
    labels: Mapping[str, np.ndarray | None],
    trees: Sequence[str],
    outputs: Sequence[str],
    title: str = "",
) -> None:
    """One panel per tree: the training camera's frame 0 under the tracks' paths (each seed
    position a dot; pixel centres at integer + 0.5, so drawn at xy - 0.5 in imshow's frame).

    Args:
        frames: ``frames[tree]``: [H, W, 3] uint8, the training camera's frame 0.
        tracks: ``tracks[tree]``: [`Tracks`][physgs.tracks.track.Tracks] of that video.
        labels: ``labels[tree]``: [P] each track's part (-1 or None: grey, not fitted or in a part
            without an estimate).
        trees: the trees, one panel each.
        outputs: the paths to write (pdf, png).
        title: the figure's title.
    """
    import matplotlib.pyplot as plt

    from physgs.report.figures import PAGE_WIDTH_IN, _axes, _finish, _texts

    fig, axes = _axes(1, len(trees), PAGE_WIDTH_IN / len(trees) + 0.9)
    cmap = plt.get_cmap("tab20")
    for ax, t in zip(axes[0], trees):
        tr, lab = tracks[t], labels.get(t)
        ax.imshow(frames[t], interpolation="nearest")
        for p in range(tr.n_tracks):
            xy = tr.xy[p, tr.valid[p]] - 0.5
            part = -1 if lab is None else int(lab[p])
            colour = "0.6" if part < 0 else cmap(part % 20)
            ax.plot(xy[:, 0], xy[:, 1], "-", color=colour, lw=0.6 if part < 0 else 0.9)
            ax.plot(xy[:1, 0], xy[:1, 1], ".", color=colour, ms=2)
        s0 = tr.start == 0
        kept = float(tr.valid[s0, -1].mean()) if s0.any() else 0.0
        fitted = 0 if lab is None else int((np.asarray(lab) >= 0).sum())
        head = f"{t}: {tr.n_tracks} tracks\n{100 * kept:.0f}% of frame 0's kept, {fitted} in parts"
        # the frame's own pixels are the scale
        _texts(ax, head, "x (px)", "y (px)" if ax is axes[0, 0] else None)
    _finish(fig, outputs, title, dpi=150)


# ---- the declarations ----------------------------------------------------------------------
def _tab_tracks_needs(plan, seeds):
    """Per tree, configuration and seed: the evaluation record, ours' loss log (training
    seconds) and, for ``plan.tracks_fields``, the fields' scores."""
    each = (("tracks_eval", ()), ("loss", (PAPER_MODEL,)))  # the record, ours' loss log
    mine = product([int(s) for s in seeds], plan.trees, plan.tracks)
    out = [(k, t, *m, c, s) for s, t, c in mine for k, m in each]
    return out + [("tracks_fields", t, c, int(s)) for s in seeds for t, c in plan.tracks_fields]


def _tab_tracks_settings(cfg: dict) -> dict:
    conditions = {c: v["conditions"] for c, v in cfg["models"]["configs"].items()}
    label = {c: _label_with_k(cfg, c, tracks_k(cfg, c)[0]) for c in cfg["tracks"]["configs"]}
    configs = {c: {"label": lab, "conditions": conditions[c]} for c, lab in label.items()}
    return {"configs": configs, "conditions": [float(c) for c in cfg["testbed"]["conditions"]]}


def _tab_tracks(path, settings, inputs, out):
    def scores(s, t, c):
        sc = read_json(path("tracks_eval", t, c, s), rule="tracks_evaluate")
        if key(("tracks_fields", t, c, s)) in inputs:  # {case: {field: errors}}
            for case, f in read_json(path("tracks_fields", t, c, s), rule="tracks_fields").items():
                sc[case]["fields"] = f
        loss = pd.read_csv(path("loss", t, PAPER_MODEL, c, s))
        sc["ours_train_s"] = float(loss["seconds"].iloc[-1])
        return sc

    trees, configs, seeds = settings["trees"], settings["configs"], settings["seeds"]
    per_seed = {s: {(t, c): scores(s, t, c) for t in trees for c in configs} for s in seeds}
    conditions, digits = settings["conditions"], settings["digits"]
    return tab_tracks(per_seed, trees, settings["bones"], configs, conditions, digits=digits)


TAB_TRACKS = Output(
    "tab_tracks",
    "table",
    _tab_tracks_needs,
    _tab_tracks,
    settings=_tab_tracks_settings,
    in_report=lambda plan: bool(plan.tracks),
    # the tracker, the fit and the displacement errors of the control, ours, the best field, the
    # static pose and each field scored
    columns=Columns(
        keys=("seed", "tree", "config"),
        values=(*TRACKER, "parts_estimated", "n_fitted", "fit_rms_px", *MOTION),
        timing=("fit_s", "ours_train_s"),
        about=("bones", "conditions", "K"),
    ),
)


def _fig_tracks_needs(plan, seeds):
    """Per tree, the first seed's observed frames, training video's tracks and (with a
    configuration) the first configuration's fit."""
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
