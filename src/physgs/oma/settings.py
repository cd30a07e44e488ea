"""What each job of the output-only analysis reads from the resolved config (its narrow params).

The workflow imports this module to plan jobs, so it imports neither pyOMA-2 nor OpenCV.
"""

from __future__ import annotations

from physgs.models.registry import condition_indices, section_k
from physgs.recovery.run import null_settings


def identify_params(cfg: dict, config: str) -> dict:
    """Rule ``oma_identify``: the conditions of ``config`` (``models.configs``: train -> [0],
    all -> every wind's video, one record each), the flow, components and SSI settings, and
    ours' omega bounds (a mode outside them is dropped). Nothing about the wind.

    Args:
        cfg: the resolved config.
        config: a configuration name of ``models.configs``.

    Returns:
        ``conditions``, ``flow``, ``components``, ``ssi`` and ``omega_hz`` (Hz).
    """
    o = cfg["oma"]
    n = len(cfg["testbed"]["conditions"])
    return {
        "conditions": condition_indices(cfg["models"]["configs"][config]["conditions"], n),
        "flow": dict(o["flow"]),
        "components": int(o["components"]),
        "ssi": dict(o["ssi"]),
        "omega_hz": [float(x) for x in cfg["models"]["ours"]["omega_hz"]],
    }


def parts(cfg: dict, config: str) -> int:
    """The output-only analysis' K in ``config`` (``oma.K``: ``same`` for the configuration's,
    or an integer): its recovery record's parts and its null's K.

    Args:
        cfg: the resolved config.
        config: a configuration name.

    Returns:
        K.
    """
    return section_k(cfg, "oma", config)


def recovery_params(cfg: dict, config: str, seed: int) -> dict:
    """Rule ``oma_recovery``: K (``oma.K``: ``same`` for the configuration's, or an integer),
    the training seed and ours' k-means
    restarts (the cells' parts), and ours' solver settings (the null's, ``null_settings``).

    Args:
        cfg: the resolved config.
        config: a configuration name.
        seed: the training seed.

    Returns:
        ``K``, ``seed``, ``kmeans_n_init`` and ``solver``.
    """
    K = parts(cfg, config)
    return {
        "K": K,
        "seed": int(seed),
        "kmeans_n_init": int(cfg["models"]["ours"]["kmeans_n_init"]),
        "solver": null_settings(cfg, K, seed),
    }
