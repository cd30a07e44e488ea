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

from physgs.experiments.recipe import canonical, fit, job_spec, with_budget
from physgs.models.registry import BASE_CONFIG
from physgs.recovery.run import recover_model
from physgs.testbed.dataset import build_dataset, load_observed, load_truth, save_dataset
from physgs.testbed.variant import effective_settings

KNOBS = ("resolution", "iterations", "substeps", "K", "vertices")
TESTBED_KNOBS = ("resolution", "vertices")
BASE = "base"


def knob_value(cfg: dict, tree: str, knob: str) -> int:
    """The resolved config's current value of ``knob`` for ``tree``.

    Args:
        cfg: the resolved config.
        tree: the sweep's tree.
        knob: one of ``KNOBS``.

    Returns:
        The value.
    """
    return {
        "resolution": lambda: cfg["testbed"]["resolution"],
        "vertices": lambda: cfg["testbed"]["vertices"][tree],
        "iterations": lambda: cfg["train"]["iterations"],
        "substeps": lambda: cfg["models"]["ours"]["substeps"],
        "K": lambda: cfg["models"]["configs"][BASE_CONFIG]["K"],
    }[knob]()


def with_knob(cfg: dict, tree: str, knob: str, value: int) -> dict:
    """A copy of the resolved config with one knob set; the static warm-up keeps its fraction.

    Args:
        cfg: the resolved config (not modified).
        tree: the sweep's tree.
        knob: one of ``KNOBS``.
        value: the knob's value.

    Returns:
        The new config.

    Raises:
        ValueError: for an unknown knob.
    """
    if knob not in KNOBS:
        raise ValueError(f"unknown speed-accuracy knob '{knob}'; choose one of {KNOBS}")
    out = copy.deepcopy(cfg)
    value = int(value)
    if knob == "resolution":
        out["testbed"]["resolution"] = value
    elif knob == "vertices":
        out["testbed"]["vertices"][tree] = value
    elif knob == "iterations":
        out["train"] = with_budget(cfg["train"], value)
    elif knob == "substeps":
        out["models"]["ours"]["substeps"] = value
    else:
        out["models"]["configs"][BASE_CONFIG]["K"] = value
    return out


def sweep_points(cfg: dict) -> list[str]:
    """Point names '<knob>-<value>' of the sweep, plus 'base' (every knob at the profile's value).

    A listed value equal to the profile's own is the base point, so it is run once.

    Args:
        cfg: the resolved config.

    Returns:
        ``'base'`` then the other points, knobs in ``KNOBS`` order.
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
    """The knob and value a sweep point's name stands for.

    Args:
        name: ``'base'`` or ``'<knob>-<int>'`` with the knob one of ``KNOBS``.

    Returns:
        (knob, value), or (None, None) for the base point.

    Raises:
        ValueError: the name is neither.
    """
    if name == BASE:
        return None, None
    knob, _, value = name.rpartition("-")
    if knob not in KNOBS or not value.isdigit():
        raise ValueError(
            f"bad sweep point '{name}': expected '{BASE}' or '<knob>-<int>' with knob in {KNOBS}"
        )
    return knob, int(value)


def point_settings(
    cfg: dict, name: str, seed: int | None = None, testbed_seeds: bool = False
) -> dict:
    """What sweep point ``name`` reads, as a sorted plain dict (the workflow's params).

    Its knob values, ours' training job at those values
    ([`job_spec`][physgs.experiments.recipe.job_spec], the tables' recipe) and, for a knob that
    changes the testbed, the testbed settings to rebuild it with.

    Args:
        cfg: the resolved config.
        name: the point's name (``'base'`` or ``'<knob>-<value>'``).
        seed: the training seed (default ``cfg['seed']``).
        testbed_seeds: build a changed testbed with ``seed`` instead of ``cfg['seed']``: each
            seed then has its own tree instance.

    Returns:
        ``point``, ``knob``, ``tree``, ``values``, ``job`` and, for a testbed knob, ``testbed``.
    """
    tree = cfg["speed_accuracy"]["tree"]
    knob, value = parse_point(name)
    pcfg = cfg if knob is None else with_knob(cfg, tree, knob, value)
    out = {
        "point": name,
        "knob": knob or BASE,
        "tree": tree,
        "values": {k: int(knob_value(pcfg, tree, k)) for k in KNOBS},
        "job": job_spec(pcfg, "ours", BASE_CONFIG, seed=seed),
    }
    if knob in TESTBED_KNOBS:
        tb_seed = int(seed) if testbed_seeds and seed is not None else int(pcfg["seed"])
        out["testbed"] = {
            "testbed": effective_settings(pcfg["testbed"]),
            "preset": pcfg["presets"][tree],
            "seed": tb_seed,
        }
    return canonical(out)


def run_point(point: dict, observed_path, truth_path, *, progress: bool = False) -> dict:
    """Train and score one sweep point; returns a flat record (seconds, dB, fractions).

    Ours is trained by [`fit`][physgs.experiments.recipe.fit], freezing included, so each point is
    the model the tables report at those settings.

    Args:
        point: [`point_settings`][physgs.experiments.sweep.point_settings].
        observed_path (str | Path): the tree's pipeline dataset, reused unless the knob changes
            the testbed (then rebuilt in a temporary folder).
        truth_path (str | Path): its truth file.
        progress: show progress bars.

    Returns:
        The point's name, knob, tree, seed and knob values, with ``testbed_s``, ``train_s``,
            ``eval_s``, ``wall_s`` (s), ``psnr_time`` (dB, the tail at the training camera),
            ``rel_err`` (median relative frequency error, fraction), ``trusted``, ``parts`` and
            ``frozen`` counts.
    """
    from physgs.evaluate.run import training_camera_scores  # torch: only when training

    name, tree = point["point"], point["tree"]
    rec = {
        "point": name,
        "knob": point["knob"],
        "tree": tree,
        "seed": int(point["job"]["seed"]),
        **point["values"],
    }
    with tempfile.TemporaryDirectory(prefix="physgs-sweep-") as tmp:
        t0 = time.perf_counter()
        if "testbed" in point:
            tb = point["testbed"]
            obs, tru = build_dataset(
                tb["testbed"], tb["preset"], seed=int(tb["seed"]), tree=tree, progress=progress
            )
            observed_path, truth_path = Path(tmp) / "observed.npz", Path(tmp) / "truth.npz"
            save_dataset(obs, tru, observed_path, truth_path)
        rec["testbed_s"] = time.perf_counter() - t0 if "testbed" in point else 0.0
        observed, truth = load_observed(observed_path), load_truth(truth_path)
        t0 = time.perf_counter()
        res = fit(observed, point["job"], progress=progress, name=f"ours_single[{name}]")
        rec["train_s"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        tail = np.arange(observed.n_train, observed.n_train + observed.n_tail)
        _, p_time = training_camera_scores(
            res.model, observed, tail, backend=point["job"]["train"]["backend"]
        )
        rec["psnr_time"] = float(np.mean(p_time))
        r = recover_model(res.model, observed, truth)
        rec["eval_s"] = time.perf_counter() - t0
    rec["rel_err"] = float(r.match.median_rel_err)
    rec["trusted"] = int(r.match.n_trusted)
    rec["parts"] = int(r.match.n_parts)
    rec["frozen"] = int(res.stats.get("frozen_parts", 0))
    rec["wall_s"] = rec["testbed_s"] + rec["train_s"] + rec["eval_s"]
    return rec


def collect(records: Sequence[dict]) -> pd.DataFrame:
    """One row per (seed, knob, value), the base point of each seed repeated under every knob it
    anchors.

    Args:
        records: [`run_point`][physgs.experiments.sweep.run_point] records of one seed or several
            (each names its ``seed``).

    Returns:
        Rows sorted by knob, value and seed: seed, knob, value, is_base, the timings, scores,
            counts, tree and every knob's value.

    Raises:
        ValueError: for a record without a seed, or a seed without exactly one base point.
    """
    by_seed: dict[int, list[dict]] = {}
    for r in records:
        if "seed" not in r:
            raise ValueError(f"sweep record {r.get('point')!r} names no seed; re-run its point")
        by_seed.setdefault(int(r["seed"]), []).append(r)
    rows = []
    for seed in sorted(by_seed):
        recs = by_seed[seed]
        base = [r for r in recs if r["point"] == BASE]
        if len(base) != 1:
            raise ValueError(
                f"speed-accuracy records of seed {seed} need exactly one 'base' "
                f"point, got {len(base)}"
            )
        for knob in KNOBS:
            for r in [*base, *[r for r in recs if r["knob"] == knob]]:
                rows.append(
                    {
                        **r,
                        "seed": seed,
                        "knob": knob,
                        "value": r[knob],
                        "is_base": r["point"] == BASE,
                    }
                )
    df = pd.DataFrame(rows).sort_values(["knob", "value", "seed"], kind="stable")
    cols = [
        "seed",
        "knob",
        "value",
        "is_base",
        "wall_s",
        "train_s",
        "testbed_s",
        "eval_s",
        "psnr_time",
        "rel_err",
        "trusted",
        "parts",
        "frozen",
        "tree",
        *KNOBS,
    ]
    return df[cols].reset_index(drop=True)


def null_level(nulls: Sequence) -> dict:
    """The untrained null's chance level for the recovery panel, from ``NullResult`` s (one per
    seed): the median over every draw of each draw's median relative error, and the central 95%
    of those draws (fractions). A sweep point inside the band is indistinguishable from chance.

    Args:
        nulls (Sequence[NullResult]): one [`NullResult`][physgs.recovery.null.NullResult] per
            seed, at one K.

    Returns:
        ``median``, ``low`` and ``high`` (fractions), ``draws`` and ``K`` (no ``K`` when no draw
            is finite: the values are then NaN).
    """
    v = np.concatenate([np.asarray(n.median_rel_err, float) for n in nulls])
    v = v[np.isfinite(v)]
    if not v.size:
        return {"median": np.nan, "low": np.nan, "high": np.nan, "draws": 0}
    lo, med, hi = np.percentile(v, [2.5, 50, 97.5])
    return {
        "median": float(med),
        "low": float(lo),
        "high": float(hi),
        "draws": int(v.size),
        "K": int(nulls[0].n_parts),
    }
