"""The true-motion reference (the ceiling): the canonical Gaussians moved by the ground-truth
skinning of the testbed ([`physgs.testbed.kinematics`][]).

Every Gaussian is a mesh vertex and follows its bone chain. All bones rotate about one world axis
(``truth.swing_axis``) through their heads and children move with their parents, so bone b's
world rotation at (condition c, recorded frame j) is a rotation about that axis by its cumulative
angle Phi_b(c, j) (its own theta plus its ancestors', ``kinematics.cumulative_angle``), and its
posed head is H_b(c, j). The canonical pose is recorded frame 0 of the training condition
(``canonical_xyz``), so Gaussian i on bone b moves by T_b(c, j) o T_b(0, 0)^-1:

    x -> H_b(c, j) + R(Phi_b(c, j) - Phi_b(0, 0)) (x - H_b(0, 0)),   q -> r(dPhi) * q,

with R / r the rotation matrix / unit quaternion about the swing axis, applied to the trainable
canonical mean x and quaternion q (position and orientation together). The kinematics run in
float64 and are cast to float32 at the end; at frame 0 of the training condition the canonical
Gaussians come back bit for bit.

The motion is fixed (no parameters): only the canonical set's own parameters (means, rotations,
scales, opacities, colours) are trained, by the same loop, loss, warm-up and schedule as every
model. It is the best any deformation of this appearance model can do: the ceiling every method
is measured against, and the only model whose training reads ``truth.npz``.

Conditions: ``gaussians_at(frame_idx, wind)`` gets a condition's observed wind [L+F], not its
index; the model finds the condition by matching that wind against the per-condition winds it
stores (the recorded ones only: a wind that matches none raises ``ValueError``). What it needs is
stored as buffers (``TrueMotion``), so a checkpoint reloads without ``truth.npz``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from physgs.models.base import BaseModel, ModelContext
from physgs.models.gaussians import (
    GaussianState,
    axis_angle_quat,
    quat_multiply,
    rodrigues_minus_identity,
)
from physgs.testbed import kinematics

#: How far (m) ``canonical_xyz`` may lie from the truth's pose at frame 0 of the training
#: condition (it is that pose rounded to float32): further means the two files do not belong
#: together.
CANONICAL_TOL_M = 1e-4
#: Largest |difference| (m/s) between a passed wind and a stored condition's wind that still
#: identifies that condition (float32 noise; the conditions differ by tenths of their speed).
WIND_MATCH_TOL = 1e-4

#: State-dict keys (buffers) of the stored motion.
BUFFERS = ("theta", "bone_head", "bone_parent", "swing_axis", "gaussian_bone", "winds")


@dataclass(frozen=True)
class TrueMotion:
    """What the reference needs from ``truth.npz`` and ``observed.npz``, in Gaussian order.

    theta [C, F, B] float64 rad: per-bone angle at the recorded frames (truth columns L..L+F-1);
    bone_head [B, 3] float64 m (rest pose); bone_parent [B] int (-1 root); swing_axis [3] unit;
    gaussian_bone [N] int: the bone of Gaussian i (``vertex_bone[gaussian_vertex[i]]``);
    winds [C, L+F] float32 m/s: each condition's observed wind (identifies the condition).
    """

    theta: np.ndarray
    bone_head: np.ndarray
    bone_parent: np.ndarray
    swing_axis: np.ndarray
    gaussian_bone: np.ndarray
    winds: np.ndarray

    @staticmethod
    def from_truth(truth, observed) -> "TrueMotion":
        """From a [`physgs.testbed.dataset.Truth`][] (or anything with its fields) and the
        ``Observed`` it belongs to; raises ValueError if they do not belong together.

        Args:
            truth (Truth): the dataset's ground truth.
            observed (Observed): the matching observed dataset.

        Returns:
            The motion at the recorded frames, float64, in Gaussian order.
        """
        wind = np.asarray(observed.wind, dtype=np.float32)  # [C, L+F]
        L = int(observed.lead_in_frames)
        theta = np.asarray(truth.theta, dtype=np.float64)  # [C, L+F, B]
        xyz = np.asarray(observed.canonical_xyz, dtype=np.float64)
        gv = np.asarray(truth.gaussian_vertex, dtype=np.int64)
        problems = []
        if theta.ndim != 3 or theta.shape[:2] != wind.shape:
            problems.append(
                f"theta has shape {theta.shape}, the observed wind {wind.shape} "
                "(expected [C, L+F, B] with the same C and L+F)"
            )
        if int(getattr(truth, "lead_in_frames", L)) != L:
            problems.append(f"lead-in {truth.lead_in_frames} frames, observed {L}")
        if gv.shape != (xyz.shape[0],):
            problems.append(
                f"{gv.shape[0]} Gaussians in gaussian_vertex, {xyz.shape[0]} in canonical_xyz"
            )
        if not problems:
            posed = kinematics.pose_gaussians(truth, theta[0, L])  # [N, 3] canonical pose
            err = float(np.abs(posed - xyz).max())
            if not err <= CANONICAL_TOL_M:
                problems.append(
                    f"canonical_xyz lies up to {err:.3g} m from the truth's pose at "
                    "frame 0 of the training condition"
                )
        if problems:
            raise ValueError(
                "truth_motion: truth.npz does not belong to this observed.npz ("
                + "; ".join(problems)
                + "); build both with the same testbed rule"
            )
        axis = np.asarray(truth.swing_axis, dtype=np.float64)
        return TrueMotion(
            theta=np.ascontiguousarray(theta[:, L:]),
            bone_head=np.asarray(truth.bone_head, dtype=np.float64),
            bone_parent=np.asarray(truth.bone_parent, dtype=np.int64),
            swing_axis=axis / np.linalg.norm(axis),
            gaussian_bone=np.asarray(truth.vertex_bone, dtype=np.int64)[gv],
            winds=wind,
        )

    @staticmethod
    def from_state_dict(sd: dict, prefix: str = "") -> "TrueMotion":
        """The motion a checkpoint's state dict stores (no truth.npz needed).

        Args:
            sd: the state dict.
            prefix: the keys' prefix (the module's name in a larger state dict).

        Returns:
            The motion, as numpy arrays.

        Raises:
            ValueError: when a buffer is missing.
        """
        missing = [k for k in BUFFERS if prefix + k not in sd]
        if missing:
            raise ValueError(
                f"truth_motion checkpoint lacks {missing}: to retrain it, rerun this command with "
                "`--forcerun <the checkpoint's path>` added"
            )
        return TrueMotion(**{k: sd[prefix + k].cpu().numpy() for k in BUFFERS})


class TruthMotionModel(BaseModel):
    """Canonical Gaussians moved by the ground-truth bone motion (see module docstring)."""

    name = "truth_motion"
    use_wind = True  # it reads the condition (off the wind), so it is not the same under every one

    def __init__(self, ctx: ModelContext, canonical_cfg: dict, motion: TrueMotion):
        """The reference over the recorded conditions of ``motion``.

        Args:
            ctx: the observed-dataset facts.
            canonical_cfg: keyword arguments of the canonical set (config ``models.canonical``).
            motion: the ground-truth bone motion in Gaussian order.

        Raises:
            ValueError: the motion's shapes disagree with each other or with the canonical set.
        """
        super().__init__(ctx, canonical_cfg)
        m = motion
        theta = torch.as_tensor(np.asarray(m.theta, dtype=np.float64))
        C, F, B = theta.shape
        N = self.canonical.n
        winds = torch.as_tensor(np.asarray(m.winds, dtype=np.float32))
        gb = torch.as_tensor(np.asarray(m.gaussian_bone, dtype=np.int64))
        parent = np.asarray(m.bone_parent, dtype=np.int64)
        head = np.asarray(m.bone_head, dtype=np.float64)
        if (
            winds.shape != (C, self.lead_in + F)
            or gb.shape != (N,)
            or head.shape != (B, 3)
            or parent.shape != (B,)
            or int(gb.min()) < 0
            or int(gb.max()) >= B
        ):
            raise ValueError(
                f"truth_motion: inconsistent motion (theta {tuple(theta.shape)} [C, F, B], winds "
                f"{tuple(winds.shape)} [C, L+F] with L = {self.lead_in}, gaussian_bone "
                f"{tuple(gb.shape)} [N = {N}] in [0, B), bone_head {head.shape}, bone_parent "
                f"{parent.shape})"
            )
        self.register_buffer("theta", theta)
        self.register_buffer("bone_head", torch.as_tensor(head))
        self.register_buffer("bone_parent", torch.as_tensor(parent))
        self.register_buffer("swing_axis", torch.as_tensor(np.asarray(m.swing_axis, np.float64)))
        self.register_buffer("gaussian_bone", gb)
        self.register_buffer("winds", winds)
        # Derived once (float64, not saved): each bone's cumulative angle and posed head at every
        # recorded frame, relative to the canonical pose (frame 0 of the training condition).
        axis = self.swing_axis.numpy()
        Phi, H, _ = kinematics.pose_bones(head, head, parent, axis, theta.numpy())
        self.register_buffer("_dphi", torch.as_tensor(Phi - Phi[0, 0]), persistent=False)
        self.register_buffer("_dhead", torch.as_tensor(H - H[0, 0]), persistent=False)
        self.register_buffer("_head0", torch.as_tensor(H[0, 0]), persistent=False)

    @property
    def n_conditions(self) -> int:
        """The number of recorded conditions, C."""
        return int(self.theta.shape[0])

    def condition_of(self, wind: torch.Tensor) -> int:
        """The recorded condition whose observed wind [L+F] this is (ValueError if none).

        Args:
            wind: [L+F] an observed wind, m/s.

        Returns:
            The condition's index.

        Raises:
            ValueError: when the shape differs or no recorded wind lies within ``WIND_MATCH_TOL``.
        """
        w = torch.as_tensor(wind, dtype=torch.float32, device=self.winds.device)
        if w.shape != self.winds.shape[1:]:
            raise ValueError(
                f"truth_motion: wind has {tuple(w.shape)} columns, the recorded "
                f"conditions {self.winds.shape[1]}; it replays only those"
            )
        gap = (self.winds - w).abs().amax(dim=1)  # [C] m/s
        c = int(torch.argmin(gap))
        if not float(gap[c]) <= WIND_MATCH_TOL:
            raise ValueError(
                f"truth_motion: the wind matches none of the {self.n_conditions} recorded "
                f"conditions (nearest: condition {c}, max |difference| {float(gap[c]):.3g} m/s "
                f"> {WIND_MATCH_TOL:g}); the true motion is known for the recorded winds only"
            )
        return c

    def bone_motion(self, frame_idx: int, condition: int) -> tuple[torch.Tensor, torch.Tensor]:
        """(dPhi [B] rad, dHead [B, 3] m): each bone's rotation angle about the swing axis and
        head displacement from the canonical pose to (condition, recorded frame_idx); float64.

        Args:
            frame_idx: recorded frame, 0-based.
            condition: wind condition index.

        Returns:
            ``(dPhi, dHead)``: [B] rad and [B, 3] m, float64.
        """
        return self._dphi[condition, frame_idx], self._dhead[condition, frame_idx]

    def deform(self, frame_idx: int, wind: torch.Tensor) -> GaussianState:
        """The canonical set moved rigidly with its bones at recorded frame ``frame_idx``.

        Args:
            frame_idx: recorded frame, 0-based.
            wind: one recorded condition's observed wind [L+F], m/s (it names the condition).

        Returns:
            The deformed Gaussians.

        Raises:
            ValueError: the wind is none of the recorded conditions'.
        """
        c = self.condition_of(wind)
        dphi, dhead = self.bone_motion(frame_idx, c)
        b = self.gaussian_bone
        angle, shift, pivot = dphi[b], dhead[b], self._head0[b]  # [N], [N, 3], [N, 3]
        axis = self.swing_axis.expand(angle.shape[0], 3)
        cn = self.canonical
        x = cn.means.double()
        # x' = H(j) + R (x - H(0)) = x + dHead + (R - I)(x - H(0)): exactly x when nothing moves
        means = x + shift + (rodrigues_minus_identity(axis, angle) @ (x - pivot)[..., None])[..., 0]
        quats = quat_multiply(axis_angle_quat(axis, angle), cn.quats.double())
        return GaussianState(
            means.to(cn.means.dtype),
            quats.to(cn.quats.dtype),
            torch.exp(cn.log_scales),
            torch.sigmoid(cn.opacity_logits),
            torch.sigmoid(cn.color_logits),
        )
