"""Recovery of one trained oscillator prior, and its null control, as the Snakemake rules call them."""
from __future__ import annotations

import dataclasses

import numpy as np
import torch

from physgs.models.oscillator import STABILITY_GUARD
from physgs.models.ours import prior_substeps
from physgs.recovery.null import NullResult
from physgs.recovery.record import RecoveryRecord, run_null, score_recovery


def recover_model(model, observed, truth) -> RecoveryRecord:
    """Match the trained parts to bones (training wind, training window) and summarise damping.

    model: a trained ``ours`` model (``part_theta``, ``omega`` rad/s, ``zeta``).
    """
    if not hasattr(model, "part_theta"):
        raise TypeError(f"recovery needs the oscillator prior ('ours'); got {type(model).__name__}")
    with torch.no_grad():
        wind = torch.as_tensor(np.asarray(observed.wind[0]), dtype=torch.float64)  # [L+F]
        theta = model.part_theta(wind).cpu().numpy()  # [K, L+F]
        omega = model.omega.detach().cpu().numpy().astype(np.float64)
        zeta = model.zeta.detach().cpu().numpy().astype(np.float64)
    rec = score_recovery(theta, omega, zeta, truth, int(observed.lead_in_frames),
                         int(observed.n_train))
    frozen = getattr(model, "frozen", None)
    if frozen is None or not bool(frozen.any()):
        return rec
    fz = frozen.cpu().numpy()
    if np.any(rec.match.trusted & fz):  # theta = 0 correlates with nothing; guard the invariant
        raise RuntimeError("a frozen part was matched as trusted; its theta is not zero")
    return dataclasses.replace(rec, n_frozen=int(fz.sum()))


def null_for_config(observed, truth, cfg: dict, config: str) -> NullResult:
    """The untrained null for the configuration's K, through the solver settings ours uses.

    cfg: the resolved config (``models.ours``, ``models.configs``, ``seed``). Substeps are raised
    exactly as the model raises them, so the null integrates with the trained model's step.
    """
    ours = cfg["models"]["ours"]
    K = int(cfg["models"]["configs"][config]["K"])
    dt = 1.0 / observed.fps
    substeps = prior_substeps(ours["omega_hz"], ours["zeta"], ours["substeps"], dt,
                              float(ours.get("rk4_guard", STABILITY_GUARD)))
    return run_null(truth, observed, n_parts=K, zeta_init=float(ours["zeta_init"]),
                    substeps=substeps, seed=int(cfg["seed"]))
