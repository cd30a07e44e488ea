"""What each job of the tracks control reads from the resolved config (its narrow params).

The workflow imports this module to plan jobs, so it imports neither torch nor OpenCV. A job's
params hold only what it reads: editing the fit's iterations leaves the tracks up to date, and
editing a tracker setting leaves ours' jobs alone.

Config: ``tracks`` (``configs``: which of ``models.configs`` the control is fitted in, with their
conditions and K; ``K``: ``same`` for each configuration's own K, or one integer for every
configuration; ``iterations``, ``min_track_frames``, ``min_tracks``, ``kmeans_n_init``: the fit;
``tracker``: [`physgs.tracks.track.TrackSettings`][]; ``fields``: the learned fields scored at
the tracked points beside ours), ``models.ours`` (the oscillator's bounds,
initialisation, RK4 substeps and guard) and ``train.lr.physics`` (Adam's rate on omega/zeta).
"""

from __future__ import annotations

from physgs.models.families import OSCILLATOR_KEYS
from physgs.models.registry import SAME_K, condition_indices, configs_for, section_k
from physgs.testbed.variant import FAITHFUL, parse_id


def tracker_settings(cfg: dict) -> dict:
    """The tracker's settings (``TrackSettings`` fields), the only params of rule ``track``.

    Args:
        cfg: the resolved config.

    Returns:
        A copy of ``tracks.tracker``.
    """
    return dict(cfg["tracks"]["tracker"])


def parts(cfg: dict, config: str) -> tuple[int, str]:
    """The tracks control's K in configuration ``config``, and the key that sets it.

    Args:
        cfg: the resolved config.
        config: a configuration name.

    Returns:
        (K, the config key): ``models/configs/<config>/K``, or ``tracks/K`` when that overrides it.
    """
    key = f"models/configs/{config}/K" if cfg["tracks"]["K"] == SAME_K else "tracks/K"
    return section_k(cfg, "tracks", config), key


def fields_scored(cfg: dict, config: str, testbed: str) -> list[str]:
    """The learned fields of ``tracks.fields`` scored at the tracked points beside ours in
    configuration ``config`` on ``testbed`` (a tree or a damping variant's id): those the
    pipeline trains there anyway, i.e. in the base configuration on a faithful testbed (the
    fields train in ``single`` only, [`physgs.models.registry.configs_for`][], and on the damping
    benchmark's testbeds only ours and its variants train).

    Args:
        cfg: the resolved config.
        config: a configuration name.
        testbed: a testbed id.

    Returns:
        Model ids from ``tracks.fields``, in its order.
    """
    if parse_id(testbed)[1] != FAITHFUL:
        return []
    configs = cfg["models"]["configs"]
    return [m for m in cfg["tracks"].get("fields", []) if config in configs_for(m, configs)]


def fit_job(cfg: dict, config: str, seed: int) -> dict:
    """The params of one track fit.

    Args:
        cfg: the resolved config.
        config: a configuration name (one of ``tracks.configs``).
        seed: the training seed (the k-means seed).

    Returns:
        K and its key, the conditions fitted (indices), FitSettings' other fields (lr =
            ``train.lr.physics``) and ours' oscillator settings.

    Raises:
        ValueError: the configuration is not one of ``tracks.configs``.
    """
    if config not in cfg["tracks"]["configs"]:
        raise ValueError(
            f"configuration {config!r} is not one of tracks/configs {cfg['tracks']['configs']}"
        )
    tr = cfg["tracks"]
    K, key = parts(cfg, config)
    n_cond = len(cfg["testbed"]["conditions"])
    return {
        "K": K,
        "K_key": key,
        "conditions": condition_indices(cfg["models"]["configs"][config]["conditions"], n_cond),
        "iterations": int(tr["iterations"]),
        "lr": float(cfg["train"]["lr"]["physics"]),
        "min_track_frames": int(tr["min_track_frames"]),
        "min_tracks": int(tr["min_tracks"]),
        "kmeans_n_init": int(tr["kmeans_n_init"]),
        "seed": int(seed),
        # ours' oscillator settings, what the fit reads (``Oscillators.from_config``)
        "ours": {k: cfg["models"]["ours"][k] for k in OSCILLATOR_KEYS},
    }
