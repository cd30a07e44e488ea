"""Cross-key checks of a resolved config: what one key's schema cannot say about another.

Each check takes the resolved config (after the profile merge, already schema-valid) and yields
``(key path, message)`` pairs, the message saying what is wrong and how to fix it; the key path is
the key to change. [`problems`][physgs.config_checks.problems] runs every check in ``CHECKS``;
[`physgs.config`][] turns the pairs into one ``ConfigError``. They run when the Snakefile loads, so
a bad config stops in seconds with nothing written, instead of in the first job that needs the
value. To add a check, write a function here and append it to ``CHECKS``.
"""

from __future__ import annotations

import functools
import json
import math
from typing import Callable, Iterator

from physgs.device import check_setting  # imports torch only when cuda is asked for
from physgs.mappings import deep_merge
from physgs.experiments.kselect import BASE_MODEL, selected_models, settings_for
from physgs.models.omega_search import search_problem
from physgs.models.families import searches_omega
from physgs.models.registry import (
    FIELD_FAMILIES,
    MODEL_NAMES,
    MODELS,
    PRIOR_VARIANT_NAMES,
    BLIND_PRIORS,
    is_prior,
    model_settings,
    spec_of,
    training_jobs,
)
from physgs.models.timescale import WINDOW_TIME
from physgs.oma.ssi import RecordError, SSISettings, check_record
from physgs.testbed import physics, wind  # the formulas the testbed itself uses
from physgs.testbed.dataset import gaussian_count
from physgs.testbed.weberpenn import PresetError, generate

Problem = tuple[tuple, str]
Check = Callable[[dict], Iterator[Problem]]


def trees_have_settings(cfg: dict) -> Iterator[Problem]:
    """Every tree in ``trees`` has a preset and a vertex count.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    vertices, presets = cfg["testbed"]["vertices"], cfg["presets"]
    for t in cfg["trees"]:
        if t not in vertices:
            yield (
                ("testbed", "vertices", t),
                f"tree '{t}' is listed in trees but has no target vertex count; add "
                f"testbed/vertices/{t} (e.g. {t}: 2000) or drop '{t}' from trees",
            )
        if t not in presets:
            yield (
                ("presets", t),
                f"tree '{t}' is listed in trees but has no Weber-Penn preset; add presets/{t} "
                f"or drop '{t}' from trees",
            )


def tree_names_distinct(cfg: dict) -> Iterator[Problem]:
    """A preset or vertex count for a tree no run lists, named like another tree's, is a typo.

    The presets are an open set (a new tree is a preset of its own, with its role), so the
    schema cannot refuse ``presets/mediun``; a name that no tree lists and that is close to
    another preset's is refused here, naming the nearest.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    import difflib

    listed = set(cfg["trees"]) | set(cfg["damping_benchmark"]["trees"])
    for section, names in (
        (("presets",), cfg["presets"]),
        (("testbed", "vertices"), cfg["testbed"]["vertices"]),
    ):
        for name in names:
            others = [n for n in names if n != name]
            near = difflib.get_close_matches(name, others, n=1, cutoff=0.75)
            if name not in listed and near:
                yield (
                    (*section, name),
                    f"'{name}' is listed by no tree and is close to '{near[0]}': did you mean "
                    f"'{near[0]}'? A new tree needs a name of its own",
                )


def conditions_have_unseen_wind(cfg: dict) -> Iterator[Problem]:
    """conditions[0] is the training wind (1.0) and at least one unseen condition follows.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    cond = cfg["testbed"]["conditions"]
    if not math.isclose(float(cond[0]), 1.0, rel_tol=0, abs_tol=1e-12):
        yield (
            ("testbed", "conditions", 0),
            f"the first condition is the training wind and must be 1.0, got {cond[0]}; put 1.0 "
            "first (the multipliers scale the training mean speed testbed/wind/v0)",
        )
    if len(cond) < 2:
        yield (
            ("testbed", "conditions"),
            f"{cond} has no unseen wind condition, which the transfer table (tab_transfer) and "
            "the joint configurations need; add at least one multiplier after 1.0, e.g. "
            "[1.0, 0.84, 0.71]",
        )


def band_ordered(cfg: dict) -> Iterator[Problem]:
    """testbed/band_hz and the wind band are (low, high).

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    lo, hi = cfg["testbed"]["band_hz"]
    if not lo < hi:
        yield (("testbed", "band_hz"), f"[{lo}, {hi}] Hz must be [low, high] with low < high")
    w = cfg["testbed"]["wind"]
    if not w["f_lo_hz"] < w["f_hi_hz"]:
        yield (
            ("testbed", "wind", "f_lo_hz"),
            f"{w['f_lo_hz']} Hz must be below testbed/wind/f_hi_hz = {w['f_hi_hz']} Hz",
        )


def lead_in_fits_wind_period(cfg: dict) -> Iterator[Problem]:
    """The record (lead-in + window + tail) is shorter than the periodic wind's period.

    The lead-in is [`physgs.testbed.physics.lead_in_frames`][] at the slowest a bone can decay
    (the band's lower edge: calibration clamps every bone into the band; the lowest zeta:
    testbed/zeta, or for the damping variant the low end of testbed/damping/zeta_range), so this
    bounds the longest lead-in any tree gets; [`physgs.testbed.dataset.simulate_tree`][] refuses
    the same record.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    tb = cfg["testbed"]
    lo, hi = tb["band_hz"]
    if not 0 < lo < hi:
        return  # band_ordered reports it
    fps, tau = int(tb["fps"]), float(tb["lead_in_tau"])
    period = wind.PERIOD_S * fps
    if abs(period - round(period)) > 1e-9:
        yield (
            ("testbed", "fps"),
            f"{fps} fps does not divide the {wind.PERIOD_S:g} s wind period into whole frames; "
            "use an integer number of frames per second that does",
        )
        return
    damping = _damping_built(cfg) and "damping" in tb
    # the damping variant's slowest decay is at the lowest zeta it can draw
    zeta = min(float(z) for z in tb["damping"]["zeta_range"]) if damping else float(tb["zeta"])
    if not zeta > 0:
        return  # damping_range_valid reports it
    raise_zeta = "testbed/damping/zeta_range[0]" if damping else "testbed/zeta"
    P = int(round(period))
    F = int(tb["n_train"]) + int(tb["n_tail"])
    omega_min = 2 * math.pi * float(lo)
    L = physics.lead_in_frames(omega_min, zeta, tau, fps)
    if L + F >= P:
        tau_max = 1.0 / (zeta * omega_min)
        room = max(P - F - 1, 0)
        yield (
            ("testbed", "lead_in_tau"),
            f"{tau:g} gives a lead-in of {L / fps:.1f} s ({tau:g} x tau_max, tau_max = "
            f"1/(zeta*2pi*band_hz[0]) = {tau_max:.2f} s), so the record ({L / fps:.1f} s + "
            f"{F / fps:.1f} s of n_train + n_tail) is not shorter than the {wind.PERIOD_S:g} s "
            f"wind period; lower testbed/lead_in_tau to at most "
            f"{room / (tau_max * fps):.3g}, or raise {raise_zeta} or testbed/band_hz[0], or "
            "lower n_train/n_tail",
        )


def _damping_built(cfg: dict) -> bool:
    """Whether any damping-variant testbed is built: every tree (testbed/variant: damping) or
    the damping benchmark's <tree>_damping copies (damping_benchmark/trees)."""
    return cfg["testbed"].get("variant", "faithful") == "damping" or bool(
        cfg.get("damping_benchmark", {}).get("trees")
    )


def damping_benchmark_is_runnable(cfg: dict) -> Iterator[Problem]:
    """The damping benchmark's trees are built faithfully too (tab_damping compares the two) and
    its configurations are ours' configurations.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    db = cfg.get("damping_benchmark") or {}
    if db.get("trees") and "damping" not in cfg["testbed"]:
        yield (
            ("damping_benchmark", "trees"),
            f"{db['trees']} are built as damping testbeds, which read testbed/damping "
            "(zeta_range, transient); add that block or set damping_benchmark/trees: []",
        )
    for t in db.get("trees", []):
        if t not in cfg["trees"]:
            yield (
                ("damping_benchmark", "trees"),
                f"'{t}' is not in trees {cfg['trees']}: tab_damping compares each damping "
                "testbed with the same tree's faithful one; add it to trees or drop it here",
            )
    for c in db.get("configs", []):
        if c not in cfg["models"]["configs"]:
            yield (
                ("damping_benchmark", "configs"),
                f"'{c}' is not one of models/configs {sorted(cfg['models']['configs'])}",
            )


def parts_study_is_runnable(cfg: dict) -> Iterator[Problem]:
    """The parts study's configurations are ours' configurations, and, where the damping
    benchmark builds testbeds, among its configurations too (tab_parts sets each variant's damping
    error beside ours' on the same configuration).

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    ps = cfg.get("parts_study") or {}
    if not ps.get("models"):
        return
    db = cfg.get("damping_benchmark") or {}
    for c in ps.get("configs", []):
        if c not in cfg["models"]["configs"]:
            yield (
                ("parts_study", "configs"),
                f"'{c}' is not one of models/configs {sorted(cfg['models']['configs'])}",
            )
        elif db.get("trees") and c not in db.get("configs", []):
            yield (
                ("parts_study", "configs"),
                f"'{c}' is not one of damping_benchmark/configs {db.get('configs')}: tab_parts "
                "compares each variant's damping error with ours' in the same configuration; "
                "add it there or drop it here",
            )
    single = cfg["models"]["configs"].get("single")
    for i, k in enumerate(ps.get("k_candidates", [])):
        if "ours_chain" not in ps["models"]:
            yield (
                ("parts_study", "k_candidates"),
                "the K candidates train ours_chain, which parts_study/models does not list; "
                "add it there or set k_candidates: []",
            )
            break
        if single is not None and int(k) >= int(single["K"]):
            yield (
                ("parts_study", "k_candidates", i),
                f"K = {k} is not below models/configs/single/K = {single['K']}, where the "
                "chained prior is the pipeline's own ours_chain job; list only smaller K",
            )


def tracks_is_runnable(cfg: dict) -> Iterator[Problem]:
    """The tracks control is fitted in configurations of ours (their conditions and K), and its
    shortest fitted track fits in the training window. (Whether K exceeds the tracks kept is only
    known once the video is tracked: the fit job refuses it, naming the key.)

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    tr = cfg.get("tracks") or {}
    for i, c in enumerate(tr.get("configs", [])):
        if c not in cfg["models"]["configs"]:
            yield (
                ("tracks", "configs", i),
                f"'{c}' is not one of models/configs {sorted(cfg['models']['configs'])}: the "
                "tracks control is fitted in ours' configurations (same conditions and K)",
            )
    n = int(cfg["testbed"]["n_train"])
    if "min_track_frames" in tr and int(tr["min_track_frames"]) > n:
        yield (
            ("tracks", "min_track_frames"),
            f"{tr['min_track_frames']} frames is longer than the training window (testbed/n_train "
            f"= {n}): no track could be fitted; lower it to at most {n}",
        )


def oma_is_runnable(cfg: dict) -> Iterator[Problem]:
    """The training window carries the SSI model the output-only analysis asks for: 4 x
    block_rows samples at least, and an order no higher than (block_rows - 1) x components (the
    channels SSI reads). Fewer channels than components are only known once the video is seen:
    the job then stops, naming the key ([`physgs.oma.ssi.check_record`][]).

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    o = cfg.get("oma") or {}
    if not o.get("configs"):
        return
    for i, c in enumerate(o["configs"]):
        if c not in cfg["models"]["configs"]:
            yield (
                ("oma", "configs", i),
                f"'{c}' is not one of models/configs {sorted(cfg['models']['configs'])}: the "
                "analysis runs in ours' configurations (their winds' videos and K)",
            )

    try:
        check_record(int(cfg["testbed"]["n_train"]), int(o["components"]), SSISettings(**o["ssi"]))
    except RecordError as e:
        yield tuple(e.key.split("/")), f"{e.msg} (testbed/n_train, oma/components)"


#: The calm must last at least this many periods of the slowest band frequency (band_hz[0]) to
#: show a free decay: over less, the slowest bones do not complete one oscillation.
MIN_CALM_PERIODS = 1.0


def damping_range_valid(cfg: dict) -> Iterator[Problem]:
    """testbed/damping/zeta_range is (low, high) with 0 < low < high <= 1 (checked whatever the
    variant: it is a typo either way; a constant zeta is the faithful variant's testbed/zeta).

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    tb = cfg["testbed"]
    if "damping" not in tb:
        return
    lo, hi = (float(z) for z in tb["damping"]["zeta_range"])
    if not (0 < lo <= 1 and 0 < hi <= 1):
        yield (
            ("testbed", "damping", "zeta_range"),
            f"[{lo:g}, {hi:g}] must lie in (0, 1] (damping ratios of under-damped bones); "
            "choose e.g. [0.03, 0.2]",
        )
    elif not lo < hi:
        yield (
            ("testbed", "damping", "zeta_range"),
            f"[{lo:g}, {hi:g}] must be [low, high] with low < high; swap them, or for one zeta "
            "on every bone use variant: faithful with testbed/zeta",
        )


def damping_transient_fits(cfg: dict) -> Iterator[Problem]:
    """For the damping variant: the gust and the calm (testbed/damping/transient, seconds from
    recorded frame 0) lie inside the training window [0, n_train / fps], and the calm lasts at
    least MIN_CALM_PERIODS periods of band_hz[0], so every bone's free decay is recorded.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    tb = cfg["testbed"]
    if not _damping_built(cfg) or "damping" not in tb:
        return  # damping_benchmark_is_runnable reports a missing block
    tr = tb["damping"]["transient"]
    start, calm, gust = float(tr["start_s"]), float(tr["calm_s"]), float(tr["gust_s"])
    window = int(tb["n_train"]) / int(tb["fps"])
    key = ("testbed", "damping", "transient")
    if start - gust < 0:
        yield (
            key + ("start_s",),
            f"{start:g} s puts the gust (gust_s = {gust:g} s before the calm) at "
            f"{start - gust:g} s, before recorded frame 0; raise start_s to at least "
            f"{gust:g} or shorten gust_s",
        )
    lo_hz = float(tb["band_hz"][0])
    shortest = MIN_CALM_PERIODS / lo_hz if lo_hz > 0 else 0.0
    if start - gust >= 0 and start + calm > window + 1e-9:
        fixes = []  # only the fixes that leave a valid transient
        if window - calm >= gust:
            fixes.append(f"lower start_s to at most {window - calm:g}")
        if window - start >= shortest:
            fixes.append(f"lower calm_s to at most {window - start:g}")
        n_min = math.ceil((start + calm) * int(tb["fps"]) - 1e-9)
        fixes.append(f"raise testbed/n_train to at least {n_min}")
        if tb.get("variant", "faithful") != "damping":  # built for the benchmark only
            trees = list(cfg["damping_benchmark"]["trees"])
            fixes.append(f"build no damping testbed (damping_benchmark/trees is {trees}: [])")
        yield (
            key + ("calm_s",),
            f"the calm [{start:g}, {start + calm:g}] s ends after the training window "
            f"(n_train / fps = {window:g} s), so the free decay is not all recorded; "
            + ", or ".join(fixes),
        )
    if calm < shortest:
        yield (
            key + ("calm_s",),
            f"{calm:g} s of calm is shorter than one period of the slowest band frequency "
            f"(1 / band_hz[0] = {shortest:.2f} s), too short to show the slow bones decay; "
            f"raise calm_s to at least {shortest:.2f}"
            + (
                f" (and testbed/n_train to fit it: the window is {window:g} s)"
                if shortest + gust > window
                else ""
            ),
        )


def field_time_scales_valid(cfg: dict) -> Iterator[Problem]:
    """Each learned field names its time encoding's top band: a positive frequency (Hz) no higher
    than half the frame rate (a band above Nyquist aliases between frames), or "window"
    (physgs.models.timescale), for exactly the model ids of its architecture.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    nyquist = 0.5 * float(cfg["testbed"]["fps"])
    for family in FIELD_FAMILIES:
        tops = cfg["models"][family]["time_top_hz"]
        ids = [m for m, spec in MODELS.items() if spec.family == family]
        for m in ids:
            if m not in tops:
                yield (
                    ("models", family, "time_top_hz", m),
                    f"the field {m!r} names no time scale; add models/{family}/time_top_hz/{m}: "
                    f"a top-band frequency in Hz, or {WINDOW_TIME!r} for Deformable-3DGS's "
                    "window-normalised time",
                )
        for m, v in tops.items():
            key = ("models", family, "time_top_hz", m)
            if m not in ids:
                yield (key, f"{m!r} is not a {family} field; the {family} fields are {ids}")
            elif v == WINDOW_TIME:
                continue
            elif isinstance(v, str) or isinstance(v, bool) or not v > 0:
                yield (
                    key,
                    f"{v!r} is not a time scale: give a positive top-band frequency in Hz "
                    f"or {WINDOW_TIME!r}",
                )
            elif v > nyquist:
                yield (
                    key,
                    f"a top time band at {v} Hz lies above half the frame rate "
                    f"(testbed/fps = {cfg['testbed']['fps']}: {nyquist:g} Hz), where it "
                    "aliases between frames; choose at most "
                    f"{nyquist:g} Hz",
                )


def study_seeds_in_seeds(cfg: dict) -> Iterator[Problem]:
    """The studies' seeds (speed_accuracy/seeds) are training seeds of the run.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    v = cfg["speed_accuracy"]["seeds"]
    if isinstance(v, list):
        extra = [s for s in v if int(s) not in {int(x) for x in cfg["seeds"]}]
        if extra:
            yield (
                ("speed_accuracy", "seeds"),
                f"{v} names seed(s) {extra} that are not in seeds {cfg['seeds']}: the studies "
                "reuse the tables' own jobs of their seeds; name seeds from seeds, or 'first' "
                "or 'all'",
            )


def _kselect_runs(cfg: dict, *own_keys: str) -> Iterator[tuple[str, tuple, dict]]:
    """(model, config path, settings) of every K selection's short runs: ours' (the section's
    own keys) and each prior's under models/kselect/priors (its keys over the section's); with
    ``own_keys``, a prior's only where its entry sets one of them (else a problem with them is
    ours', reported once under ours' key)."""
    ks = cfg["models"]["kselect"]
    for m in selected_models(ks):
        where = ("models", "kselect") if m == BASE_MODEL else ("models", "kselect", "priors", m)
        if m == BASE_MODEL or not own_keys or set(own_keys) & set(ks["priors"][m]):
            yield m, where, settings_for(ks, m)


def _recipes(cfg: dict) -> Iterator[tuple[tuple, str, str, dict]]:
    """(config path, tree, model, recipe) of every tree's recipe (``recipes``)."""
    for tree, models in (cfg.get("recipes") or {}).items():
        for model, recipe in (models or {}).items():
            yield ("recipes", tree, model), tree, model, recipe or {}


def _schedules(cfg: dict) -> Iterator[tuple[tuple, str, dict]]:
    """(config path, its name in messages, iterations/warmup node) of train, of every tree's
    recipe that changes it and of every K selection's short runs."""
    yield ("train",), "train", cfg["train"]
    for where, _, _, recipe in _recipes(cfg):
        if recipe.get("train"):
            yield (
                where + ("train",),
                "/".join(where + ("train",)),
                deep_merge(cfg["train"], recipe["train"]),
            )
    for _, where, node in _kselect_runs(cfg, "iterations", "warmup"):
        yield where, "/".join(where), node


def warmup_below_iterations(cfg: dict) -> Iterator[Problem]:
    """The static warm-up ends before training does (train and the K-selection runs).

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    for section, key, node in _schedules(cfg):
        it, warm = int(node["iterations"]), int(node["warmup"])
        if not 0 <= warm < it:
            yield (
                section + ("warmup",),
                f"{warm} must lie in [0, {key}/iterations = {it}); lower {key}/warmup or raise "
                f"{key}/iterations",
            )


def _unknown_paths(over: dict, base: dict, path: tuple = ()) -> Iterator[tuple[tuple, list]]:
    """(key path, the keys ``base`` holds there) of each key of ``over`` that ``base`` lacks (a
    nested dict is walked where both hold one)."""
    for k, v in over.items():
        if k not in base:
            yield path + (k,), sorted(base)
        elif isinstance(v, dict) and isinstance(base[k], dict):
            yield from _unknown_paths(v, base[k], path + (k,))


def recipes_are_known(cfg: dict) -> Iterator[Problem]:
    """A tree's recipe names a listed tree and a trained model, and sets only keys the shared
    settings hold: a misspelt key would otherwise be merged in and read by nothing.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    trained = {m for m, _ in training_jobs(cfg["models"]["configs"])} | set(BLIND_PRIORS)
    trained |= set(cfg["parts_study"]["models"])
    for where, tree, model, recipe in _recipes(cfg):
        if tree not in cfg["trees"]:
            yield where[:2], f"tree {tree!r} is not in trees {cfg['trees']}"
            continue
        if model not in trained:
            yield where, f"model {model!r} is not trained; trained models: {sorted(trained)}"
            continue
        try:
            settings = model_settings(cfg["models"], model)
        except KeyError:  # a setting the model reads is missing: its own check names it
            continue
        bases = {"train": cfg["train"], "settings": settings}
        for part, base in bases.items():
            for p, holds in _unknown_paths(recipe.get(part) or {}, base):
                yield (
                    where + (part, *p),
                    f"{'/'.join(p)} is not a setting of {model}'s {part} (there: {holds})",
                )


def search_is_runnable(cfg: dict) -> Iterator[Problem]:
    """The recipe search's trees are listed and its trials are scored before they end.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    search = cfg["search"]
    for t in search.get("trees", []):
        if t not in cfg["trees"]:
            yield ("search", "trees"), f"{t!r} is not in trees {cfg['trees']}"
    if search["every"] >= cfg["train"]["iterations"]:
        yield (
            ("search", "every"),
            f"{search['every']} must be below train/iterations ({cfg['train']['iterations']}): "
            "the pruner reads no score otherwise",
        )


def device_is_available(cfg: dict) -> Iterator[Problem]:
    """``train.device: cuda`` only where torch sees a GPU (torch is imported only then).

    A cluster run that trains on GPU nodes leaves the setting ``auto`` and asks for the GPU
    through the rule's resources (docs/cluster.md), so a login node without one plans it.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    try:
        check_setting(cfg["train"]["device"])
    except (ValueError, RuntimeError) as e:
        yield ("train", "device"), str(e)


def holdout_leaves_training_frames(cfg: dict) -> Iterator[Problem]:
    """Held-out training frames (train.holdout_every) leave most of the window to train on.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    every, n = int(cfg["train"]["holdout_every"]), int(cfg["testbed"]["n_train"])
    if every != 0 and not 2 <= every <= n:
        yield (
            ("train", "holdout_every"),
            f"{every} must be 0 (no held-out frames) or lie in [2, testbed/n_train = {n}]",
        )


def stopping_has_held_out_frames(cfg: dict) -> Iterator[Problem]:
    """The stopping rule (train.stopping) reads held-out window frames: enabled, it needs
    train.holdout_every > 0 and a scoring period.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    st = cfg["train"]["stopping"]
    if not st["enabled"]:
        return
    if int(cfg["train"]["holdout_every"]) == 0:
        yield (
            ("train", "stopping", "enabled"),
            "true needs held-out window frames to read: set train/holdout_every > 0, or "
            "enabled: false to train train/iterations",
        )
    if int(st["every"]) == 0:
        yield (
            ("train", "stopping", "every"),
            "0 never scores the held-out frames, so the enabled rule could never stop; set it "
            "> 0 or enabled: false",
        )


def _freeze_iteration(ours: dict, iterations: int) -> int:
    """The iteration at which freezing runs, round(freeze_at x iterations), as
    [`physgs.models.visibility.freeze_schedule`][] computes it (that module loads torch)."""
    return int(round(float(ours["freeze_at"]) * iterations))


def freeze_inside_deformation_phase(cfg: dict) -> Iterator[Problem]:
    """models/ours/freeze_at falls after the warm-up, for train and the K-selection runs alike.

    The freezing iteration is round(freeze_at * iterations), as in
    [`physgs.models.visibility.freeze_schedule`][]; freezing is off when freeze_below_px is 0.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    o = cfg["models"]["ours"]
    if float(o["freeze_below_px"]) == 0:
        return
    at = float(o["freeze_at"])
    for _, key, node in _schedules(cfg):
        it, warm = int(node["iterations"]), int(node["warmup"])
        if not 0 <= warm < it:
            continue  # warmup_below_iterations reports it
        frz = _freeze_iteration(o, it)
        if not warm < frz < it:
            yield (
                ("models", "ours", "freeze_at"),
                f"{at:g} freezes at iteration {frz} of {key}/iterations = {it}, outside its "
                f"deformation phase ({warm}, {it}); choose freeze_at in ({warm / it:.3g}, 1) "
                "or set models/ours/freeze_below_px: 0 to turn freezing off",
            )


def omega_search_is_runnable(cfg: dict) -> Iterator[Problem]:
    """models/omega_search names oscillator priors only, and its bank phase ends after the
    warm-up and before freezing in the training runs ([`physgs.models.omega_search`][]).

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    osr = cfg["models"].get("omega_search")
    if not osr:
        return
    known = (*MODEL_NAMES, *PRIOR_VARIANT_NAMES)
    for i, m in enumerate(osr["models"]):
        if m not in known or not is_prior(m):
            yield (
                ("models", "omega_search", "models", i),
                f"{m!r} is not an oscillator prior; valid: {[n for n in known if is_prior(n)]}",
            )
    o = cfg["models"]["ours"]
    it, warm = int(cfg["train"]["iterations"]), int(cfg["train"]["warmup"])
    if not 0 <= warm < it:
        return  # warmup_below_iterations reports it
    frz = None if float(o["freeze_below_px"]) == 0 else _freeze_iteration(o, it)
    why = search_problem(float(osr["until"]), it, warm, frz)
    if why is not None:
        yield (("models", "omega_search", "until"), why)


def kselect_priors_are_runnable(cfg: dict) -> Iterator[Problem]:
    """models/kselect/priors names wind-driven priors, and their short runs fit the search.

    The priors listed must be wind-driven oscillator priors of the methods besides ours
    (trained in every configuration: ``<prior>_auto`` joins its rows), and the short runs of a
    prior that searches omega leave room for the search's bank phase (after the warm-up, before
    freezing): never adjusted, the key is named.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem; none when the config passes.
    """
    valid = [m for m in MODELS if m != BASE_MODEL and is_prior(m) and spec_of(m).forcing == "wind"]
    own = cfg["models"]["kselect"].get("priors") or {}
    for m in own:
        if m not in valid:
            yield (
                ("models", "kselect", "priors", m),
                f"{m!r} is not a wind-driven oscillator prior besides ours (ours' K is "
                f"chosen by the section's own keys); valid: {valid}",
            )
    o, osr = cfg["models"]["ours"], cfg["models"].get("omega_search")
    for m, where, ks in _kselect_runs(cfg):
        if m not in valid or not searches_omega(cfg["models"], m):
            continue
        it, warm = int(ks["iterations"]), int(ks["warmup"])
        if not 0 <= warm < it:
            continue  # warmup_below_iterations reports it
        frz = None if float(o["freeze_below_px"]) == 0 else _freeze_iteration(o, it)
        why = search_problem(float(osr["until"]), it, warm, frz)
        if why is not None:
            key = "/".join(where)
            shared = [k for k in ("iterations", "warmup") if k not in own.get(m, {})]
            note = f"; {' and '.join(shared)} from models/kselect" if shared else ""
            yield (
                where + ("iterations",),
                f"{m} searches omega in its K-selection runs (iterations = {it}, warmup = "
                f"{warm}{note}), and models/omega_search/until = {why}; set "
                f"{key}/iterations higher or {key}/warmup lower",
            )


def ours_bounds_ordered(cfg: dict) -> Iterator[Problem]:
    """omega_hz and zeta are (low, high) with the initial values strictly inside.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    o = cfg["models"]["ours"]
    for pair, init in (("omega_hz", "omega_init_hz"), ("zeta", "zeta_init")):
        lo, hi = (float(v) for v in o[pair])
        x = float(o[init])
        if not lo < hi:
            yield (
                ("models", "ours", pair),
                f"[{lo:g}, {hi:g}] must be [low, high] with low < high; swap them",
            )
        elif not lo < x < hi:
            yield (
                ("models", "ours", init),
                f"{x:g} lies outside models/ours/{pair} = [{lo:g}, {hi:g}]; choose a value "
                "strictly inside the bounds",
            )


def configs_have_single(cfg: dict) -> Iterator[Problem]:
    """models/configs holds `single` (every model trains in it) and not the reserved `auto`.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    configs = cfg["models"]["configs"]
    if "single" not in configs:
        yield (
            ("models", "configs", "single"),
            "missing: every model is trained in configuration 'single'; add "
            "single: {conditions: train, K: 32} under models/configs",
        )
    if "auto" in configs:
        yield (
            ("models", "configs", "auto"),
            "is reserved for ours with K chosen from the data (models/kselect); rename it",
        )


@functools.lru_cache(maxsize=16)
def _skeleton(preset_json: str, seed: int, tree: str):
    """A tree's skeleton (built once per load for presets_reach_bone_counts and the K bound)."""
    return generate(json.loads(preset_json), seed=seed, name=tree)


def _preset_key(preset: dict) -> str:
    return json.dumps(preset, sort_keys=True, default=str)


def _gaussians(cfg: dict, tree: str) -> int | None:
    """The vertex count of ``tree``'s mesh (its Gaussians); None when it cannot be built (a
    missing preset or a preset or budget error, which other checks report)."""
    preset = cfg["presets"].get(tree)
    if preset is None:
        return None
    try:
        skel = _skeleton(_preset_key(preset), int(cfg["seed"]), tree)
        return gaussian_count(cfg["testbed"], preset, skel, tree)
    except ValueError:  # PresetError, MeshBudgetError
        return None


def k_within_gaussians(cfg: dict) -> Iterator[Problem]:
    """Every K (configurations, K-selection candidates, sweep knob) is at most the Gaussian count.

    The Gaussian count is the vertex count of the tree's mesh
    ([`physgs.testbed.dataset.gaussian_count`][], from the skeleton, without the mesh); it can
    fall a little short of the target testbed/vertices (385 of 400 on the quick sparse tree). The
    smallest among the trees bounds what runs on every tree, the sweep tree's the sweep.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    vertices = cfg["testbed"]["vertices"]
    gaussians = functools.cache(lambda t: _gaussians(cfg, t))
    counts = {t: gaussians(t) for t in cfg["trees"] if t in vertices}
    counts = {t: n for t, n in counts.items() if n is not None}
    if not counts:
        return  # trees_have_settings (or presets_reach_bone_counts) reports it
    smallest = min(counts.values())
    tmin = min(counts, key=counts.get)
    fix = (
        f"the {smallest} Gaussians of tree '{tmin}' (its mesh, for testbed/vertices/{tmin} = "
        f"{vertices[tmin]})"
    )
    for name, c in cfg["models"]["configs"].items():
        if int(c["K"]) > smallest:
            yield (
                ("models", "configs", name, "K"),
                f"K = {c['K']} parts exceeds {fix}; lower K or raise the vertex count",
            )
    for _, where, ks in _kselect_runs(cfg, "candidates"):
        for i, k in enumerate(ks["candidates"]):
            if int(k) > smallest:
                yield (
                    (*where, "candidates", i),
                    f"K = {k} exceeds {fix}; drop it from the candidates or raise the vertex count",
                )
    sa = cfg["speed_accuracy"]
    tree = sa["tree"]
    n = gaussians(tree) if tree in vertices else None
    if n is not None:
        for i, k in enumerate(sa["knobs"].get("K", [])):
            if int(k) > n:
                yield (
                    ("speed_accuracy", "knobs", "K", i),
                    f"K = {k} exceeds the {n} Gaussians of the sweep tree '{tree}' (its mesh, "
                    f"for testbed/vertices/{tree} = {vertices[tree]}); lower it",
                )
    single = cfg["models"]["configs"].get("single")
    if single is not None:
        for i, n in enumerate(sa["knobs"].get("vertices", [])):
            if int(n) < int(single["K"]):
                yield (
                    ("speed_accuracy", "knobs", "vertices", i),
                    f"{n} Gaussians is fewer than models/configs/single/K = {single['K']} "
                    "parts, which the sweep trains at every vertex count; raise it",
                )


def presets_reach_bone_counts(cfg: dict) -> Iterator[Problem]:
    """Every listed tree's preset builds its exact bone count (clone variation included). The
    skeleton alone is built (well under a second for all three trees), not the mesh or frames.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    for tree in cfg["trees"]:
        preset = cfg["presets"].get(tree)
        if preset is None:
            continue  # trees_have_settings reports it
        try:
            _skeleton(_preset_key(preset), int(cfg["seed"]), tree)
        except PresetError as e:
            yield (("presets", tree), str(e))


def sweep_tree_is_listed(cfg: dict) -> Iterator[Problem]:
    """The speed-accuracy sweep runs on a tree the pipeline builds.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    tree = cfg["speed_accuracy"]["tree"]
    if tree not in cfg["trees"]:
        yield (
            ("speed_accuracy", "tree"),
            f"'{tree}' is not in trees {cfg['trees']}; choose one of them or add it to trees",
        )


def fit_curve_is_runnable(cfg: dict) -> Iterator[Problem]:
    """The fit curve's trees are built by the pipeline (its profile-budget point is the
    pipeline's own job) and its budgets give at least three points with the profile's.

    Args:
        cfg: The resolved config (profile merged, schema-valid).

    Yields:
        ``(key path, message)`` per problem (the module docstring); none when the config passes.
    """
    fc = cfg["speed_accuracy"]["fit_curve"]
    for t in fc.get("trees", []):
        if t not in cfg["trees"]:
            yield (
                ("speed_accuracy", "fit_curve", "trees"),
                f"'{t}' is not in trees {cfg['trees']}; choose among them or add it to trees",
            )
    own = int(cfg["train"]["iterations"])
    if len({*map(int, fc["iterations"]), own}) < 3:
        yield (
            ("speed_accuracy", "fit_curve", "iterations"),
            f"{fc['iterations']} and the profile's own budget (train/iterations = {own}) make "
            "fewer than three budgets; list at least two others",
        )


#: Every cross-key check, in the order their problems are reported.
CHECKS: list[Check] = [
    trees_have_settings,
    tree_names_distinct,
    conditions_have_unseen_wind,
    band_ordered,
    lead_in_fits_wind_period,
    damping_range_valid,
    damping_transient_fits,
    warmup_below_iterations,
    recipes_are_known,
    search_is_runnable,
    device_is_available,
    holdout_leaves_training_frames,
    stopping_has_held_out_frames,
    freeze_inside_deformation_phase,
    ours_bounds_ordered,
    omega_search_is_runnable,
    kselect_priors_are_runnable,
    configs_have_single,
    k_within_gaussians,
    sweep_tree_is_listed,
    fit_curve_is_runnable,
    field_time_scales_valid,
    study_seeds_in_seeds,
    damping_benchmark_is_runnable,
    parts_study_is_runnable,
    tracks_is_runnable,
    oma_is_runnable,
    presets_reach_bone_counts,
]


def problems(cfg: dict, checks: list[Check] | None = None) -> list[Problem]:
    """All problems of a resolved, schema-valid config.

    Args:
        cfg: the resolved config.
        checks: the checks to run; None: every check in ``CHECKS``.

    Returns:
        ``(key path, message)`` pairs, empty when the config passes.
    """
    out: list[Problem] = []
    for chk in CHECKS if checks is None else checks:
        out.extend(chk(cfg))
    return out
