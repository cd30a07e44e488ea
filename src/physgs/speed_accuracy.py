"""The speed-accuracy trade, measured: sweep one knob at a time away from the profile's settings.

Knobs: image resolution (pixels), training iterations, RK4 substeps per frame, K (parts) and the
number of Gaussians (= mesh vertices). Each sweep point trains ``ours`` (configuration
``single``) on one tree and records wall time (seconds), PSNR (dB) on the time split (the 50 tail
frames at the training camera and wind) and the frequency-recovery error (median relative error
over trusted parts). Points whose knob changes the testbed (resolution, vertices) rebuild the
tree's dataset at that setting in a scratch folder; the rest reuse the pipeline's dataset.
"""
from __future__ import annotations

import copy
import tempfile
import time
from pathlib import Path
from typing import Sequence

import numpy as np
import pandas as pd
import torch

from physgs.evaluate.adapter import model_render_fn
from physgs.evaluate.metrics import psnr

KNOBS = ("resolution", "iterations", "substeps", "K", "vertices")
TESTBED_KNOBS = ("resolution", "vertices")
BASE = "base"


def knob_value(cfg: dict, tree: str, knob: str) -> int:
    """The resolved config's current value of ``knob`` for ``tree``."""
    return {
        "resolution": lambda: cfg["testbed"]["resolution"],
        "vertices": lambda: cfg["testbed"]["vertices"][tree],
        "iterations": lambda: cfg["train"]["iterations"],
        "substeps": lambda: cfg["models"]["ours"]["substeps"],
        "K": lambda: cfg["models"]["configs"]["single"]["K"],
    }[knob]()


def with_knob(cfg: dict, tree: str, knob: str, value: int) -> dict:
    """A copy of the resolved config with one knob set; the static warm-up keeps its fraction."""
    if knob not in KNOBS:
        raise ValueError(f"unknown speed-accuracy knob '{knob}'; choose one of {KNOBS}")
    out = copy.deepcopy(cfg)
    value = int(value)
    if knob == "resolution":
        out["testbed"]["resolution"] = value
    elif knob == "vertices":
        out["testbed"]["vertices"][tree] = value
    elif knob == "iterations":
        frac = cfg["train"]["warmup"] / cfg["train"]["iterations"]
        out["train"]["iterations"] = value
        out["train"]["warmup"] = max(1, int(round(frac * value)))
    elif knob == "substeps":
        out["models"]["ours"]["substeps"] = value
    else:
        out["models"]["configs"]["single"]["K"] = value
    return out


def sweep_points(cfg: dict) -> list[str]:
    """Point names '<knob>-<value>' of the sweep, plus 'base' (every knob at the profile's value).

    A listed value equal to the profile's own is the base point, so it is run once.
    """
    sa = cfg["speed_accuracy"]
    tree = sa["tree"]
    names = [BASE]
    for knob in KNOBS:
        for v in sa["knobs"].get(knob, []):
            if int(v) != int(knob_value(cfg, tree, knob)):
                names.append(f"{knob}-{int(v)}")
    return names


def parse_point(name: str) -> tuple[str | None, int | None]:
    if name == BASE:
        return None, None
    knob, _, value = name.rpartition("-")
    if knob not in KNOBS or not value.isdigit():
        raise ValueError(f"bad sweep point '{name}': expected '{BASE}' or '<knob>-<int>' with knob "
                         f"in {KNOBS}")
    return knob, int(value)


def time_split_psnr(model, observed, backend: str = "auto") -> float:
    """Mean PSNR (dB) over the tail frames at the training camera and wind."""
    render = model_render_fn(model, observed, backend=backend)
    j0 = int(observed.n_train)
    scores = [psnr(render(j, 0, observed.train_camera)[0], observed.frames[0, j])
              for j in range(j0, j0 + int(observed.n_tail))]
    return float(np.mean(scores))


def run_point(cfg: dict, name: str, observed_path, truth_path, *, progress: bool = False) -> dict:
    """Train and score one sweep point; returns a flat record (seconds, dB, fractions).

    cfg: resolved config (reads ``speed_accuracy.tree``); observed_path/truth_path: the tree's
    pipeline dataset, reused unless the knob changes the testbed.
    """
    from physgs.models.registry import build_model
    from physgs.recovery.run import recover_model
    from physgs.testbed.dataset import build_dataset, load_observed, load_truth, save_dataset
    from physgs.train.loop import train_model

    tree = cfg["speed_accuracy"]["tree"]
    knob, value = parse_point(name)
    pcfg = cfg if knob is None else with_knob(cfg, tree, knob, value)
    rec = {"point": name, "knob": knob or BASE, "tree": tree,
           **{k: int(knob_value(pcfg, tree, k)) for k in KNOBS}}
    with tempfile.TemporaryDirectory(prefix="physgs-sweep-") as tmp:
        t0 = time.perf_counter()
        if knob in TESTBED_KNOBS:
            obs, tru = build_dataset(pcfg["testbed"], pcfg["presets"][tree], seed=int(pcfg["seed"]),
                                     tree=tree, progress=progress)
            observed_path, truth_path = Path(tmp) / "observed.npz", Path(tmp) / "truth.npz"
            save_dataset(obs, tru, observed_path, truth_path)
        rec["testbed_s"] = time.perf_counter() - t0 if knob in TESTBED_KNOBS else 0.0
        observed, truth = load_observed(observed_path), load_truth(truth_path)
        seed = int(pcfg["seed"])
        t0 = time.perf_counter()
        model = build_model("ours", observed, pcfg["models"], config="single", seed=seed)
        res = train_model(model, observed, pcfg["train"], conditions=[0], seed=seed,
                          name=f"ours_single[{name}]", progress=progress)
        rec["train_s"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        with torch.no_grad():
            rec["psnr_time"] = time_split_psnr(res.model, observed, pcfg["train"]["backend"])
        r = recover_model(res.model, observed, truth)
        rec["eval_s"] = time.perf_counter() - t0
    rec["rel_err"] = float(r.match.median_rel_err)
    rec["trusted"] = int(r.match.n_trusted)
    rec["parts"] = int(r.match.n_parts)
    rec["wall_s"] = rec["testbed_s"] + rec["train_s"] + rec["eval_s"]
    return rec


def collect(records: Sequence[dict]) -> pd.DataFrame:
    """One row per (knob, value), the base point repeated under every knob it anchors."""
    base = [r for r in records if r["point"] == BASE]
    if len(base) != 1:
        raise ValueError("speed-accuracy records need exactly one 'base' point")
    rows = []
    for knob in KNOBS:
        for r in [*base, *[r for r in records if r["knob"] == knob]]:
            rows.append({**r, "knob": knob, "value": r[knob], "is_base": r["point"] == BASE})
    df = pd.DataFrame(rows).sort_values(["knob", "value"], kind="stable").reset_index(drop=True)
    cols = ["knob", "value", "is_base", "wall_s", "train_s", "testbed_s", "eval_s", "psnr_time",
            "rel_err", "trusted", "parts", "tree", *KNOBS]
    return df[cols]


def fig_speed_accuracy(df: pd.DataFrame, outputs: Sequence[str | Path]) -> None:
    """Two panels against wall time (s): PSNR on the time split (dB) and recovery error (%).

    One line per knob through its values (labelled), the base point starred.
    """
    import matplotlib.pyplot as plt

    from physgs.report.figures import save_figure

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    colors = dict(zip(KNOBS, ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple"]))
    for knob, g in df.groupby("knob", sort=False):
        g = g.sort_values("value")
        for ax, col, scale in ((axes[0], "psnr_time", 1.0), (axes[1], "rel_err", 100.0)):
            ax.plot(g["wall_s"], g[col] * scale, "-o", ms=3.5, color=colors[knob], label=knob)
            for _, r in g.iterrows():
                ax.annotate(str(int(r["value"])), (r["wall_s"], r[col] * scale), fontsize=6,
                            xytext=(3, 3), textcoords="offset points", color=colors[knob])
    base = df[df["is_base"]].iloc[0]
    for ax, col, scale in ((axes[0], "psnr_time", 1.0), (axes[1], "rel_err", 100.0)):
        ax.plot([base["wall_s"]], [base[col] * scale], "k*", ms=11, label="profile setting")
        ax.set_xscale("log")
        ax.set_xlabel("wall time per point (s, log)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("PSNR, time split (dB)")
    axes[1].set_ylabel("median rel. error of omega, trusted parts (%)")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"Speed-accuracy trade, ours on the {df['tree'].iloc[0]} tree (one knob at a time)")
    fig.tight_layout()
    save_figure(fig, outputs)
