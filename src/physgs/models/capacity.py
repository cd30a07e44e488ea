"""What the oscillator prior's parts can represent of a tree's true motion, apart from training.

A shortfall of the prior's fit has two possible causes: the descent did not find the motion, or
the prior cannot hold it. To tell them apart, its parts are fitted to the true Gaussian
trajectories directly (the testbed's truth, a diagnostic: no setting is chosen on it), in two
steps of decreasing freedom:

1. **Rigid parts, free angles** ([`rigid_part_angles`][physgs.models.capacity.rigid_part_angles]):
   each part turns about the true swing axis through one fixed pivot by any angle at each frame.
   For a fixed pivot the least-squares angle of a frame is closed-form (a 2-D Procrustes turn in
   the plane normal to the axis); the pivot is searched by Nelder-Mead.
2. **One oscillator per part** ([`oscillator_angles`][physgs.models.capacity.oscillator_angles]):
   each part's free angle replaced by the single damped oscillator's response to the measured
   wind that fits it best ([`project_to_oscillators`][physgs.models.omega_search.project_to_oscillators]),
   the prior's own constraint. A part's true angle is its bone's and its ancestors', a sum of
   several modes, which one oscillator follows only in part.

``benchmarks/fit_recipe.py --capacity`` renders both through the prior with its appearance
trained and its motion held, beside the prior trained as the pipeline trains it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch
from scipy.optimize import minimize

from physgs.models.base import BaseModel, ModelContext
from physgs.models.gaussians import GaussianState, axis_angle_quat, rodrigues_minus_identity
from physgs.models.part_transform import transform_parts


@dataclass(frozen=True)
class PartAngles:
    """Parts fitted as rigid turns about one axis (``rigid_part_angles``).

    Attributes:
        pivot: [K, 3] each part's pivot (world units; on the axis through it, the part's mean
            coordinate along the axis). NaN for a part without points.
        theta: [K, T] each part's own angle at each frame, rad, relative to frame 0
            (theta[:, 0] = 0); in a chain, relative to its parent's turn.
        fitted: [T, N, 3] the points moved by their part's turn.
        shift: [K, T, 3] in a chain, each part's translation after its total turn (its
            ancestors'); None for independent parts.
    """

    pivot: np.ndarray
    theta: np.ndarray
    fitted: np.ndarray
    shift: np.ndarray | None = None


def plane_basis(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A right-handed orthonormal frame ``(e1, e2, a)`` with ``a`` along ``axis``.

    Args:
        axis: [3] the swing axis (any length > 0).

    Returns:
        ``(e1, e2, a)``, [3] each: a turn by +theta about ``a`` takes e1 towards e2.
    """
    a = np.asarray(axis, dtype=np.float64)
    a = a / np.linalg.norm(a)
    e1 = np.cross(a, [1.0, 0.0, 0.0] if abs(a[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(a, e1), a


def _turn(y: np.ndarray, y0: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each frame's least-squares angle about in-plane pivot ``q`` and the points it moves.

    Args:
        y: [T, n, 2] the points' in-plane positions over the frames.
        y0: [n, 2] their positions at frame 0.
        q: [2] the pivot.

    Returns:
        ``(theta [T] rad, moved [T, n, 2])``.
    """
    u, v = y0 - q, y - q
    cos = (v * u).sum((1, 2))
    sin = (u[None, :, 0] * v[..., 1] - u[None, :, 1] * v[..., 0]).sum(1)
    th = np.arctan2(sin, cos)
    c, s = np.cos(th)[:, None], np.sin(th)[:, None]
    moved = np.stack([c * u[:, 0] - s * u[:, 1], s * u[:, 0] + c * u[:, 1]], -1) + q
    return th, moved


def rigid_part_angles(
    points: np.ndarray,
    labels: np.ndarray,
    K: int,
    axis: np.ndarray,
    parent: np.ndarray | None = None,
) -> PartAngles:
    """Each part's best fixed pivot and per-frame angle about ``axis`` for true trajectories.

    Args:
        points: [T, N, 3] the points' true positions over T frames (frame 0 the reference).
        labels: [N] each point's part, in [0, K).
        K: the number of parts.
        axis: [3] the swing axis every part turns about.
        parent: [K] each part's parent (-1: a root; parents numbered before their children) for
            a chain, whose part turns on its parent's turn: fitted top-down, each part's points
            taken back by its ancestors' fitted turns first. None: independent parts.

    Returns:
        The [`PartAngles`][physgs.models.capacity.PartAngles]. A point's motion along the axis
            is not a turn's: it is kept as it is at frame 0.

    Raises:
        ValueError: when the shapes disagree or a label is outside [0, K).
    """
    x = np.asarray(points, dtype=np.float64)
    lab = np.asarray(labels)
    if x.ndim != 3 or x.shape[2] != 3 or lab.shape != (x.shape[1],):
        raise ValueError(f"points [T, N, 3] and labels [N]; got {x.shape} and {lab.shape}")
    if lab.size and (lab.min() < 0 or lab.max() >= K):
        raise ValueError(f"labels must lie in [0, {K})")
    e1, e2, a = plane_basis(axis)
    y = np.stack([x @ e1, x @ e2], -1)  # [T, N, 2]
    along = x[0] @ a  # [N]
    T = x.shape[0]
    pivot = np.full((K, 3), np.nan)
    theta, total = np.zeros((K, T)), np.zeros((K, T))
    shift = np.zeros((K, T, 2))  # in-plane: x -> R(total) (x - q) + q + shift
    q2 = np.zeros((K, 2))
    moved = np.empty_like(y)
    for p in range(K):
        i = lab == p
        a_ = -1 if parent is None else int(parent[p])
        if not i.any():
            if a_ >= 0:  # an empty part passes its parent's turn on
                q2[p], total[p] = q2[a_], total[a_]
                shift[p] = shift[a_]
            continue
        yp, y0 = y[:, i], y[0, i]
        if a_ >= 0:  # the part's points in its parent's frame: the parent's turn undone
            yp = _rotate(yp - q2[a_] - shift[a_][:, None], -total[a_]) + q2[a_]

        def cost(q, yp=yp, y0=y0):
            return float(((_turn(yp, y0, q)[1] - yp) ** 2).sum())

        # the part's centre and its two ends across the plane: a pivot off the part is common
        starts = (y0.mean(0), y0[np.argmin(y0[:, 1])], y0[np.argmax(y0[:, 1])])
        fits = [
            minimize(cost, s, method="Nelder-Mead", options={"xatol": 1e-9, "fatol": 1e-14})
            for s in starts
        ]
        q2[p] = min(fits, key=lambda r: r.fun).x
        theta[p], _ = _turn(yp, y0, q2[p])
        if a_ >= 0:  # T_p = T_a o turn_p: the turns add, the pivot's offset turns with the parent
            total[p] = total[a_] + theta[p]
            shift[p] = _rotate((q2[p] - q2[a_])[None], total[a_])[:, 0] + q2[a_] + shift[a_] - q2[p]
        else:
            total[p] = theta[p]
        moved[:, i] = _rotate(y0 - q2[p], total[p]) + q2[p] + shift[p][:, None]
        pivot[p] = q2[p, 0] * e1 + q2[p, 1] * e2 + along[i].mean() * a
    fitted = moved[..., :1] * e1 + moved[..., 1:] * e2 + along[None, :, None] * a
    shift3 = None if parent is None else shift[..., :1] * e1 + shift[..., 1:] * e2
    return PartAngles(pivot, theta, fitted, shift3)


def _rotate(v: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """In-plane vectors ``v`` [T, n, 2] turned by ``angle`` [T] rad (e1 towards e2)."""
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]], -1)


def chain_turns(
    theta: np.ndarray, pivot: np.ndarray, parent: np.ndarray, axis: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Each chained part's total turn from its own angles: x -> R(total) (x - pivot) + pivot +
    shift, R about ``axis``, each part's turn composed after its ancestors'.

    Args:
        theta: [K, T] each part's own angle, rad, relative to its parent's turn.
        pivot: [K, 3] each part's pivot, world units (NaN: an empty part, its parent's taken).
        parent: [K] each part's parent (-1: a root; parents numbered before their children).
        axis: [3] the axis every part turns about.

    Returns:
        ``(total [K, T] rad, shift [K, T, 3] world units)``.
    """
    e1, e2, _ = plane_basis(axis)
    K, T = theta.shape
    q = np.stack([pivot @ e1, pivot @ e2], -1)  # [K, 2]
    total, shift = np.array(theta, dtype=np.float64), np.zeros((K, T, 2))
    for p in range(K):
        a = int(parent[p])
        if a < 0:
            continue
        if np.isnan(q[p]).any():
            q[p] = q[a]
        total[p] = total[a] + theta[p]
        shift[p] = _rotate((q[p] - q[a])[None], total[a])[:, 0] + q[a] + shift[a] - q[p]
    return total, shift[..., :1] * e1 + shift[..., 1:] * e2


def turned(
    x0: np.ndarray,
    labels: np.ndarray,
    axis: np.ndarray,
    pivot: np.ndarray,
    theta: np.ndarray,
    shift: np.ndarray | None = None,
) -> np.ndarray:
    """Points moved by their parts' turns: R(theta) (x - pivot) + pivot + shift, about ``axis``.

    Args:
        x0: [N, 3] the points at frame 0, world units.
        labels: [N] each point's part.
        axis: [3] the axis every part turns about.
        pivot: [K, 3] each part's pivot (NaN rows: parts without points).
        theta: [K, T] each part's (total) angle, rad.
        shift: [K, T, 3] each part's translation after its turn; None: none.

    Returns:
        [T, N, 3] the points at each frame.
    """
    e1, e2, a = plane_basis(axis)
    lab = np.asarray(labels)
    q = np.nan_to_num(np.stack([pivot @ e1, pivot @ e2], -1))[lab]  # [N, 2]
    y0 = np.stack([x0 @ e1, x0 @ e2], -1) - q  # [N, 2]
    th = np.asarray(theta)[lab].T  # [T, N]
    c, s = np.cos(th), np.sin(th)
    y = np.stack([c * y0[:, 0] - s * y0[:, 1], s * y0[:, 0] + c * y0[:, 1]], -1) + q
    out = y[..., :1] * e1 + y[..., 1:] * e2 + (x0 @ a)[None, :, None] * a
    return out if shift is None else out + np.transpose(np.asarray(shift), (1, 0, 2))[:, lab]


def oscillator_angles(
    theta: np.ndarray, responses: np.ndarray, omega: np.ndarray, zeta: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each part's free angle replaced by the one oscillator of a grid that fits it best.

    Args:
        theta: [K, T] free angles relative to frame 0, rad (``PartAngles.theta``).
        responses: [G, T] the grid's unit-gain responses to the wind at the same frames, each
            relative to its value at frame 0 (the angles' reference).
        omega: [G] the grid's natural frequencies, rad/s.
        zeta: [G] its damping ratios.

    Returns:
        ``(omega [K], zeta [K], gain [K], theta [K, T])``: each part's oscillator and the angle
            it gives (gain x its response).
    """
    from physgs.models.omega_search import project_to_oscillators

    om, ze, gain, _ = project_to_oscillators(theta, responses, omega, zeta)
    rr = np.einsum("gs,gs->g", responses, responses)
    best = np.argmax((theta @ responses.T) ** 2 / rr, axis=1)  # the grid point each part took
    return om, ze, gain, gain[:, None] * responses[best]


class PartsAtAngles(BaseModel):
    """Rigid parts turned by given angles: the canonical set (frame 0) turned part by part about
    one axis by ``theta[:, j]`` at recorded frame j (then shifted by ``shift[:, j]``). Only its appearance trains; it predicts the
    frames its angles cover, under the wind they were fitted to.
    """

    name = "parts_at_angles"

    def __init__(
        self,
        ctx: ModelContext,
        canonical_cfg: dict,
        labels: np.ndarray,
        axis: np.ndarray,
        pivot: np.ndarray,
        theta: np.ndarray,
        shift: np.ndarray | None = None,
    ):
        """Hold the parts' motion as buffers.

        Args:
            ctx: the observed-dataset facts (its canonical positions: frame 0's).
            canonical_cfg: config ``models.canonical``.
            labels: [N] each Gaussian's part, in [0, K).
            axis: [3] the axis every part turns about.
            pivot: [K, 3] each part's pivot, world units (NaN for a part without Gaussians).
            theta: [K, F] each part's angle at recorded frames 0 .. F-1, rad, relative to frame 0.
            shift: [K, F, 3] each part's translation after its turn (a chain's, from
                ``chain_turns``, with ``theta`` its total angles); None: none.
        """
        super().__init__(ctx, canonical_cfg)
        theta = torch.as_tensor(np.asarray(theta), dtype=torch.float32)
        K = theta.shape[0]
        a = torch.as_tensor(plane_basis(axis)[2], dtype=torch.float32)
        self.register_buffer("part_labels", torch.as_tensor(np.asarray(labels)).long())
        self.register_buffer("axis", a.expand(K, 3).clone())
        self.register_buffer("pivot", torch.nan_to_num(torch.as_tensor(pivot).float()))
        self.register_buffer("theta", theta)
        shift = np.zeros((*theta.shape, 3)) if shift is None else np.asarray(shift)
        self.register_buffer("shift", torch.as_tensor(shift, dtype=torch.float32))

    def defined(self, frame_idx: int, condition: int) -> bool:
        """Whether ``frame_idx`` is among the frames the angles cover (condition 0's only).

        Args:
            frame_idx: recorded frame, 0-based.
            condition: wind condition index.

        Returns:
            True for condition 0 and frame_idx < F.
        """
        return condition == 0 and frame_idx < self.theta.shape[1]

    def deform(self, frame_idx: int, wind: torch.Tensor) -> GaussianState:
        """The canonical set turned part by part by its angles at ``frame_idx``.

        Args:
            frame_idx: recorded frame, 0-based (< F).
            wind: [L+F] the observed wind, m/s (not read: the angles were fitted under it).

        Returns:
            The turned Gaussians.
        """
        c, th = self.canonical, self.theta[:, frame_idx]
        means, quats = transform_parts(
            c.means,
            c.quats,
            self.part_labels,
            rodrigues_minus_identity(self.axis, th),
            self.pivot,
            self.shift[:, frame_idx],
            axis_angle_quat(self.axis, th),
        )
        return dataclasses.replace(c.state(), means=means, quats=quats)


def refine_oscillators(
    theta: np.ndarray,
    omega: np.ndarray,
    zeta: np.ndarray,
    response: Callable[[float, float], np.ndarray],
    bounds: tuple[tuple[float, float], tuple[float, float]],
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each part's oscillator refined from its grid point: (log omega, zeta) by Nelder-Mead on
    the residual of its free angle, the gain by least squares (a grid's step dephases a
    response over a long window).

    Args:
        theta: [K, T] free angles, rad.
        omega: [K] the grid's choice, rad/s.
        zeta: [K] the grid's choice.
        response: ``(omega, zeta) -> [T]`` the unit-gain response at the angles' frames, relative
            to frame 0.
        bounds: ``((omega_lo, omega_hi), (zeta_lo, zeta_hi))``, the prior's.

    Returns:
        ``(omega [K], zeta [K], gain [K], theta [K, T])``.
    """
    (wlo, whi), (zlo, zhi) = bounds
    K = theta.shape[0]
    om, ze, gain, out = (
        np.array(omega, float),
        np.array(zeta, float),
        np.zeros(K),
        np.zeros_like(theta),
    )

    def fit(v, th):
        w, z = float(np.exp(v[0])), float(v[1])
        if not (wlo < w < whi and zlo < z < zhi):
            return np.inf, 0.0, None
        r = response(w, z)
        g = float(th @ r / (r @ r)) if r @ r > 0 else 0.0
        return float(((th - g * r) ** 2).sum()), g, r

    for p in range(K):
        if not np.any(theta[p]):
            continue
        best = minimize(
            lambda v, th=theta[p]: fit(v, th)[0],
            [np.log(om[p]), ze[p]],
            method="Nelder-Mead",
            options={"xatol": 1e-6, "fatol": 1e-14, "maxiter": 400},
        )
        v = (
            best.x
            if fit(best.x, theta[p])[0] <= fit([np.log(om[p]), ze[p]], theta[p])[0]
            else [np.log(om[p]), ze[p]]
        )
        _, gain[p], r = fit(v, theta[p])
        om[p], ze[p], out[p] = np.exp(v[0]), v[1], gain[p] * r
    return om, ze, gain, out
