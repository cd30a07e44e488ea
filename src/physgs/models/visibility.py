"""Model only what the image can see: find parts whose swing never reaches a pixel, freeze them.

A part's image swing is the largest displacement, in training-camera pixels, of any of its
Gaussians over the training frames at the training wind, when the part rotates by its own
theta_p(t) about its pivot (ancestors' motion is not the part's own, so it is not counted).
Below about a pixel the photometric loss carries no usable signal about that part's physics:
its omega, zeta and gain are whatever the initialisation and noise made them, and its theta
only adds parameters the data cannot pin down. Freezing such a part sets theta_p = 0 and stops
updates of its physics parameters; recovery then counts it as untrusted (a constant trajectory
correlates with nothing).

In a chained prior (``model.chain``) a part's own rotation also carries its descendants, so
its swing counts their Gaussians too (a trunk part barely moves its own members but moves the
whole tree); there it is evaluated at the frames of the part's largest and smallest theta
(a rigid rotation displaces every point monotonically in |theta|).

By default the swing uses the model's current theta (what its motion actually does in the
image), so freezing happens part-way through training (config ``models.ours.freeze_at``) once
the gains have grown. ``probe_rad`` instead rotates every part by a fixed angle: a purely
geometric check (a part whose members sit near its pivot or move along the viewing ray is
invisible whatever its gain), usable on an untrained model whose theta is still zero.
"""

from __future__ import annotations

import numpy as np
import torch

from physgs.models.gaussians import rotate_about_pivot

#: Parameters of the oscillator prior that hold one row per part.
PART_PARAMS = ("omega_raw", "zeta_raw", "gain_raw", "axis_raw", "pivot")


def part_image_swing(
    model, observed, *, condition: int = 0, frames=None, probe_rad: float | None = None
) -> np.ndarray:
    """[K] largest image displacement (pixels, training camera) of each part's Gaussians.

    Frozen parts swing 0 under their own theta.

    Args:
        model (OscillatorPrior): an oscillator prior (``part_theta``, ``part_labels`` [N], ``axis``
            [K, 3], ``pivot`` [K, 3], ``K``).
        observed (Observed): the dataset (wind [C, L+F] m/s, train_camera, n_train,
            lead_in_frames).
        condition: the wind condition whose theta is used.
        frames (ArrayLike | None): recorded-frame indices (default: the training window).
        probe_rad: if given, every part is rotated by +-probe_rad (rad) instead of its theta(t).

    Returns:
        [K] swing, px.

    Raises:
        ValueError: for a ``probe_rad`` that is not > 0.
    """
    cam = observed.train_camera
    lab = model.part_labels.cpu().numpy()
    K = int(model.K)
    with torch.no_grad():
        # the projections run in numpy: the geometry comes to the CPU once (a no-op there)
        c = model.canonical_state()
        means0 = c.means.double().cpu()
        axis = model.axis.double()[model.part_labels].cpu()  # [N, 3]
        pivot = model.pivot.double()[model.part_labels].cpu()  # [N, 3]
        if probe_rad is not None:
            if not probe_rad > 0:
                raise ValueError(f"probe_rad must be > 0 rad, got {probe_rad}")
            angles = torch.tensor([[probe_rad], [-probe_rad]], dtype=torch.float64).expand(2, K)
        else:
            wind = torch.as_tensor(np.asarray(observed.wind[condition]), dtype=torch.float64)
            theta = model.part_theta(wind.to(model.omega_raw.device)).double().cpu()  # [K, L+F]
            idx = np.arange(observed.n_train) if frames is None else np.asarray(frames)
            angles = theta[:, int(observed.lead_in_frames) + idx].T  # [M, K]
    uv0, _ = cam.project(means0.numpy())  # [N, 2] pixels
    if getattr(model, "chain", False):
        return _chain_swing(model, means0, uv0, cam, angles)
    swing = np.zeros(K)
    q0 = torch.tensor([[1.0, 0.0, 0.0, 0.0]], dtype=torch.float64).expand(means0.shape[0], 4)
    for a in angles:  # [K] rad at one frame
        if not bool(a.abs().max() > 0):
            continue
        m, _ = rotate_about_pivot(means0, q0, axis, a[model.part_labels], pivot)
        uv, _ = cam.project(m.numpy())
        d = np.linalg.norm(uv - uv0, axis=1)  # [N] pixels
        np.maximum.at(swing, lab, d)
    return swing


def _chain_swing(model, means0, uv0, cam, angles) -> np.ndarray:
    """[K] pixels: each part rotated alone by its theta, its Gaussians and its descendants'."""
    parent = model.part_parent.cpu().numpy()
    lab = model.part_labels.cpu().numpy()
    K = int(model.K)
    sub = np.eye(K, dtype=bool)  # sub[p, q]: q is p or a descendant of p
    for q in range(K - 1, 0, -1):  # parents are numbered first: children before their parents
        sub[parent[q]] |= sub[q]
    swing = np.zeros(K)
    q0 = torch.tensor([[1.0, 0.0, 0.0, 0.0]], dtype=torch.float64)
    with torch.no_grad():
        axis, pivot = model.axis.double().cpu(), model.pivot.double().cpu()  # [K, 3]
    for p in range(K):
        idx = np.nonzero(sub[p][lab])[0]
        for a in {float(angles[:, p].max()), float(angles[:, p].min())}:
            if a == 0.0:
                continue
            n = len(idx)
            m, _ = rotate_about_pivot(
                means0[idx],
                q0.expand(n, 4),
                axis[p].expand(n, 3),
                torch.full((n,), a, dtype=torch.float64),
                pivot[p].expand(n, 3),
            )
            uv, _ = cam.project(m.numpy())
            swing[p] = max(swing[p], float(np.linalg.norm(uv - uv0[idx], axis=1).max()))
    return swing


def freeze_invisible(
    model, observed, threshold_px: float, *, optimizer=None, probe_rad: float | None = None
) -> dict:
    """Freeze every part whose image swing is below ``threshold_px`` pixels.

    Also clears the Adam first moments of the frozen rows in ``optimizer`` (if given): their
    gradients are exactly zero from now on (theta = 0), so with a zero first moment Adam's step
    is exactly zero and the parameters stay put.

    Args:
        model (OscillatorPrior): the prior being trained.
        observed (Observed): the dataset.
        threshold_px: the swing below which a part freezes, px.
        optimizer (physgs.train.adam.FusedAdam | None): the training optimizer.
        probe_rad: see [`part_image_swing`][physgs.models.visibility.part_image_swing].

    Returns:
        Statistics for the training record: ``frozen_parts`` (count, all frozen so far),
            ``part_swing_px`` [K].

    Raises:
        ValueError: for a negative threshold.
    """
    if not threshold_px >= 0:
        raise ValueError(f"models.ours.freeze_below_px must be >= 0 pixels, got {threshold_px}")
    swing = part_image_swing(model, observed, probe_rad=probe_rad)
    model.freeze_parts(swing < threshold_px)
    frozen = model.frozen
    if optimizer is not None and bool(frozen.any()):
        for name in PART_PARAMS:
            p = getattr(model, name)
            state = optimizer.state.get(p)
            if state and "exp_avg" in state:
                state["exp_avg"][frozen] = 0.0
    return {"frozen_parts": int(frozen.sum()), "part_swing_px": [float(s) for s in swing]}


def freeze_schedule(models_cfg: dict, train_cfg: dict) -> int | None:
    """Iteration at which ours freezes invisible parts, or None when freezing is off.

    The iteration must fall after the static warm-up, when theta has had time to grow.

    Args:
        models_cfg: the ``models`` section (reads ``ours.freeze_below_px``, pixels, 0 = off, and
            ``ours.freeze_at``, a fraction of train.iterations).
        train_cfg: the ``train`` section (iterations, warmup).

    Returns:
        round(freeze_at x iterations), or None.

    Raises:
        ValueError: naming the fix when the iteration falls outside (warmup, iterations).
    """
    o = models_cfg["ours"]
    thr, at = float(o["freeze_below_px"]), float(o["freeze_at"])
    if thr == 0:
        return None
    iterations, warmup = int(train_cfg["iterations"]), int(train_cfg["warmup"])
    it = int(round(at * iterations))
    if not warmup < it < iterations:
        raise ValueError(
            f"models.ours.freeze_at = {at} puts freezing at iteration {it}, outside the "
            f"deformation phase ({warmup}, {iterations}); choose freeze_at in "
            f"({warmup / iterations:.3g}, 1) or set freeze_below_px: 0 to turn freezing off"
        )
    return it


def freeze_callback(observed, models_cfg: dict, train_cfg: dict):
    """``on_iteration`` callback for ``train_model`` that freezes invisible parts once, or None.

    Args:
        observed (Observed): the dataset.
        models_cfg: the ``models`` config section.
        train_cfg: the ``train`` config section.

    Returns:
        (Callable | None): ``on_iteration(it, model, optimizer)``, returning at the freezing
            iteration ``frozen_at``, ``freeze_below_px`` and
            [`freeze_invisible`][physgs.models.visibility.freeze_invisible]'s statistics (None at
            every other); None when freezing is off.

    Raises:
        ValueError: from [`freeze_schedule`][physgs.models.visibility.freeze_schedule].
    """
    at = freeze_schedule(models_cfg, train_cfg)
    if at is None:
        return None
    thr = float(models_cfg["ours"]["freeze_below_px"])

    def on_iteration(it, model, optimizer):
        if it != at:
            return None
        return {
            "frozen_at": it,
            "freeze_below_px": thr,
            **freeze_invisible(model, observed, thr, optimizer=optimizer),
        }

    return on_iteration
