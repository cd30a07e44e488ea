"""Recovery of one trained oscillator prior, and its null control, as the Snakemake rules call them.

The workflow imports ``null_settings`` to plan jobs; the solver and torch load inside the
functions that run it, so a dry run does not pay torch's start-up."""

from __future__ import annotations

import dataclasses

import numpy as np

from physgs.recovery.null import NullResult
from physgs.recovery.record import RecoveryRecord, run_null, score_recovery, with_damping_scores


def recover_model(
    model, observed, truth, bone_visible=None, damping: dict | None = None
) -> RecoveryRecord:
    """Match the trained parts to bones (training wind, training window) and summarise damping.

    Args:
        model (OscillatorPrior): a trained ``ours`` model (``part_theta``, ``omega`` rad/s,
            ``zeta``).
        observed (Observed): the dataset.
        truth (Truth): its ground truth.
        bone_visible (np.ndarray | None): [B] bool
            ([`physgs.testbed.stats`][physgs.testbed.stats]): also score the parts matched to
            visible bones.
        damping: ``{zeta_range, seed}`` to also score each trusted part's zeta against its bone's
            true zeta and against the untrained null drawn log-uniformly from zeta_range with
            that seed ([`physgs.recovery.damping_scores`][physgs.recovery.damping_scores];
            tab_damping).

    Returns:
        The [`RecoveryRecord`][physgs.recovery.record.RecoveryRecord], ``n_frozen`` set.

    Raises:
        TypeError: for a model without ``part_theta``.
        RuntimeError: if a frozen part were matched as trusted.
    """
    import torch  # here: the workflow imports this module to plan jobs (module docstring)

    if not hasattr(model, "part_theta"):
        raise TypeError(f"recovery needs the oscillator prior ('ours'); got {type(model).__name__}")
    with torch.no_grad():
        wind = torch.as_tensor(np.asarray(observed.wind[0]), dtype=torch.float64)  # [L+F]
        theta = model.part_theta(wind).cpu().numpy()  # [K, L+F]
        omega = model.omega.detach().cpu().numpy().astype(np.float64)
        zeta = model.zeta.detach().cpu().numpy().astype(np.float64)
    rec = score_recovery(
        theta, omega, zeta, truth, int(observed.lead_in_frames), int(observed.n_train)
    )
    if bone_visible is not None:
        rec = rec.with_visibility(bone_visible)
    if damping is not None:
        rec = with_damping_scores(rec, zeta, truth, damping)
    frozen = getattr(model, "frozen", None)
    if frozen is None or not bool(frozen.any()):
        return rec
    fz = frozen.cpu().numpy()
    if np.any(rec.match.trusted & fz):  # theta = 0 correlates with nothing; guard the invariant
        raise RuntimeError("a frozen part was matched as trusted; its theta is not zero")
    return dataclasses.replace(rec, n_frozen=int(fz.sum()))


def null_settings(cfg: dict, K: int, seed: int | None = None) -> dict:
    """What the null control for K parts reads from the resolved config.

    Keyed by K, not by configuration, so configurations sharing a K share one null.

    Args:
        cfg: the resolved config.
        K: number of parts.
        seed: a training seed (each seed draws its own null, paired with that seed's model);
            default ``cfg['seed']``.

    Returns:
        ``K``, ours' solver settings (``omega_hz`` bounds in Hz, ``zeta`` bounds, ``zeta_init``,
            ``substeps``, ``rk4_guard``) and ``seed``.
    """
    o = cfg["models"]["ours"]
    return {
        "K": int(K),
        "omega_hz": [float(x) for x in o["omega_hz"]],
        "zeta": [float(x) for x in o["zeta"]],
        "zeta_init": float(o["zeta_init"]),
        "substeps": int(o["substeps"]),
        "rk4_guard": float(o["rk4_guard"]),
        "seed": int(cfg["seed"] if seed is None else seed),
    }


def null_control(observed, truth, settings: dict, bone_visible=None) -> NullResult:
    """The untrained null for ``settings['K']`` parts (``null_settings``), through the solver
    settings ours uses: substeps are raised exactly as the model raises them, so the null
    integrates with the trained model's step.

    Args:
        observed (Observed): the dataset.
        truth (Truth): its ground truth.
        settings: [`null_settings`][physgs.recovery.run.null_settings] (``rk4_guard`` defaults
            to ``STABILITY_GUARD``).
        bone_visible (np.ndarray | None): [B] bool; also score the draws on visible bones.

    Returns:
        The [`NullResult`][physgs.recovery.null.NullResult].
    """
    # here: this loads torch, and the workflow imports this module to plan jobs
    from physgs.models.ours import settings_substeps

    substeps = settings_substeps(settings, 1.0 / observed.fps)
    return run_null(
        truth,
        observed,
        n_parts=int(settings["K"]),
        zeta_init=float(settings["zeta_init"]),
        substeps=substeps,
        seed=int(settings["seed"]),
        bone_visible=bone_visible,
    )
