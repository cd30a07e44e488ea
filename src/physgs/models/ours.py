"""Ours: the physically parameterised deformation prior.

K rigid parts (k-means on canonical positions). Part p swings by theta_p(t), the response of a
damped oscillator (omega_p, zeta_p) driven by gain_p * (v(t)^2 - vbar^2) of the observed wind,
integrated by RK4 from rest at the first wind sample (start of the lead-in), so the recorded
window is at steady state. Each part rotates rigidly by theta_p about its swing axis through its
pivot; positions and orientations rotate together.

Parameterisation (all bounded or normalised so one Adam rate suits every tree):
- omega = exp(log lo + (log hi - log lo) * sigmoid(raw)), rad/s, inside [omega_lo, omega_hi];
- zeta = zeta_lo + (zeta_hi - zeta_lo) * sigmoid(raw);
- gain = raw * omega_init^2 / std(v^2 - vbar^2) of the training wind, so raw is roughly the
  quasi-static swing in radians; starts at 0, so the model starts at the canonical pose;
- swing axis = raw / |raw|; the wind direction is not an input, so it starts along the
  horizontal part of the training camera's viewing direction (a swing in the image plane, the
  motion the camera sees best) and is learned;
- pivot (world units), initialised at the part's member nearest the base of the tree.

Two options (registry ids ``ours_topo`` and ``ours_chain``; ``ours`` is the paper's):
- ``segmentation="topology"``: parts cut along the tree ([`physgs.models.topology`][]) instead of
  k-means; each part has a parent (``part_parent`` [K], root -1, parents numbered first) and
  its pivot starts at the joint with that parent.
- ``chain=True`` (topology parts only): each part keeps its own oscillator, but its rigid
  transform is composed with its ancestors' ([`physgs.models.chain`][]): a branch is carried by
  its parent. ``part_theta`` stays each part's OWN angle theta_p(t), the quantity the
  oscillator models and recovery compares with each bone's own angle.

The models listed in ``models.omega_search`` (the topology variants) start with a search over
omega ([`physgs.models.omega_search`][]): until ``until`` x iterations each part's angle is a
linear combination of a fixed bank of oscillators' responses (``bank_weights``), then each part
is projected onto the single oscillator of a grid that best fits it (``end_bank_phase``) and
the oscillators take over. After training ``bank_active`` is False: the model is the prior above.
``models.topology.canonical_pose`` says what the topology variants take the canonical set for
(``CANONICAL_POSES``): ``rest``, each part turned by theta_p(t) as if the canonical set were the
rest pose; ``frame0``, the pose at recorded frame 0, which it is (the canonical Gaussians sit at
frame 0's vertices): frame 0's transform is undone before theta(t)'s is applied
([`physgs.models.chain.chain_deform_from`][]; for independent parts, a turn by theta_p(t) -
theta_p(frame 0)), so frame 0 poses the canonical set and the motion cannot displace it;
``frame0_angles``, each part turned by theta_p(t) - theta_p(frame 0) (the same as ``frame0`` for
independent parts, to first order in the angles for chained ones); ``frame0_offset``, as
``frame0`` with a learned turn per part (``pose_offset`` [K] rad, from 0 at the pivot rate)
added to frame 0's angles. In the frame-0 poses the search's projection fits each part's angle
relative to frame 0 (what the images see). ``rest`` is the default: the frame-0 poses fit the
sparse tree's training window worse (docs/parts.md, the held-out views of the sparse tree).
``part_theta`` and recovery are unchanged.
"""

from __future__ import annotations

import math

import numpy as np
import torch
from torch import nn

from physgs.models.base import BaseModel, ModelContext
from physgs.models.chain import chain_deform, chain_deform_from, depth_levels
from physgs.models.gaussians import GaussianState, rotate_parts
from physgs.models.oscillator import STABILITY_GUARD, fastest_rate, integrate, required_substeps
from physgs.models.omega_search import (
    GRID_INSET,
    OmegaSearch,
    log_grid,
    project_to_oscillators,
    unit_responses,
)
from physgs.models.oscillator_params import OscillatorBounds, condition_vbar
from physgs.models.parts import kmeans_parts
from physgs.models.topology import KNN, topology_parts

#: What the canonical set is taken for (``models.topology.canonical_pose``; module docstring).
CANONICAL_POSES = ("rest", "frame0", "frame0_angles", "frame0_offset")


def prior_substeps(omega_hz, zeta, substeps: int, dt: float, guard: float = STABILITY_GUARD) -> int:
    """RK4 substeps per wind sample for the prior's bounds: the configured count, raised until
    every (omega, zeta) the bounds allow passes the guard. The fastest rate is at the top of both
    bounds (above zeta = 1 it exceeds omega). The null control integrates with this same step.

    Args:
        omega_hz (Sequence[float]): ``[lo, hi]`` natural-frequency bounds, Hz.
        zeta (Sequence[float]): ``[lo, hi]`` damping-ratio bounds.
        substeps: the configured substeps per sample.
        dt: the wind's sample interval, s.
        guard: the largest stable rate x step allowed.

    Returns:
        The substep count, at least ``substeps``.
    """
    hi = 2 * math.pi * float(omega_hz[1])
    rate = float(fastest_rate(hi, float(zeta[1])))
    return max(int(substeps), required_substeps(rate, dt, guard))


def settings_substeps(settings: dict, dt: float) -> int:
    """[`prior_substeps`][physgs.models.ours.prior_substeps] of a settings dict that holds ours'
    ``omega_hz``, ``zeta``, ``substeps`` and optionally ``rk4_guard`` (default
    ``STABILITY_GUARD``): ``models.ours``, or a null's solver settings. Every method that
    integrates ours' oscillators from settings (the null, the 2D-track control, the output-only
    analysis) takes its step from here, so each integrates with the trained prior's step.

    Args:
        settings: the settings.
        dt: the wind's sample interval, s.

    Returns:
        The substep count.
    """
    guard = float(settings.get("rk4_guard", STABILITY_GUARD))
    return prior_substeps(settings["omega_hz"], settings["zeta"], settings["substeps"], dt, guard)


class OscillatorPrior(BaseModel):
    """Per-part wind-driven oscillators with rigid rotation (see module docstring)."""

    name = "ours"

    def __init__(
        self,
        ctx: ModelContext,
        canonical_cfg: dict,
        *,
        K: int,
        omega_hz: list,
        zeta: list,
        omega_init_hz: float,
        zeta_init: float,
        substeps: int,
        rk4_guard: float = STABILITY_GUARD,
        kmeans_n_init: int = 4,
        seed: int = 0,
        labels: np.ndarray | None = None,
        segmentation: str = "kmeans",
        knn: int = KNN,
        chain: bool = False,
        parent: np.ndarray | None = None,
        search: OmegaSearch | None = None,
        canonical_pose: str = "rest",
    ):
        """The prior's parts, oscillators, axes and pivots (module docstring).

        Args:
            ctx: the observed-dataset facts (canonical positions [N, 3], fps, wind statistics).
            canonical_cfg: keyword arguments of the canonical set (config ``models.canonical``).
            K: parts.
            omega_hz: [lo, hi] natural-frequency bounds, Hz.
            zeta: [lo, hi] damping-ratio bounds.
            omega_init_hz: starting natural frequency, Hz.
            zeta_init: starting damping ratio.
            substeps: RK4 substeps per wind sample (raised until every allowed oscillator is
                stable).
            rk4_guard: the stability guard on the step (rate x step).
            kmeans_n_init: k-means restarts (k-means parts).
            seed: seeds k-means.
            labels: [N] part of each Gaussian, in [0, K); None: computed here.
            segmentation: ``kmeans`` or ``topology``.
            knn: neighbours of the topology graph.
            chain: compose each part's transform with its ancestors' (topology parts only).
            parent: [K] parent of each part (root -1); None: computed with the topology parts.
            search: the search over omega, or None.
            canonical_pose: what the canonical set is taken for, one of ``CANONICAL_POSES``.

        Raises:
            ValueError: inconsistent options (unknown segmentation or pose, chain without topology,
                labels or parents of the wrong shape).
        """
        super().__init__(ctx, canonical_cfg)
        # the parameterisation the 2D-track control shares (physgs.models.oscillator_params)
        self.bounds = b = OscillatorBounds.from_config(omega_hz, zeta, omega_init_hz, zeta_init)
        w0 = b.omega_init
        self.omega_lo, self.omega_hi, self.zeta_lo, self.zeta_hi = (
            b.omega_lo,
            b.omega_hi,
            b.zeta_lo,
            b.zeta_hi,
        )
        self.dt = 1.0 / ctx.fps
        self.vbar_ratio = float(ctx.vbar_ratio)
        self.guard = float(rk4_guard)
        self.substeps = prior_substeps(omega_hz, zeta, substeps, self.dt, self.guard)
        xyz = np.asarray(ctx.canonical_xyz, dtype=np.float64)
        if segmentation not in ("kmeans", "topology"):
            raise ValueError(f"segmentation must be 'kmeans' or 'topology', got {segmentation!r}")
        if chain and segmentation != "topology":
            raise ValueError("a chained prior needs topology parts (a parent per part)")
        topo_pivots = None
        if segmentation == "topology" and (labels is None or parent is None):
            tp = topology_parts(xyz, K, knn)  # deterministic: no seed
            labels, parent, topo_pivots = tp.labels, tp.parent, tp.pivots
        if labels is None:
            labels = kmeans_parts(xyz, K, seed, kmeans_n_init)
        labels = np.asarray(labels, dtype=np.int64)
        if labels.shape != (xyz.shape[0],) or labels.min() < 0 or labels.max() >= K:
            raise ValueError(f"part labels must be [N] in [0, K={K}); got shape {labels.shape}")
        self.K = K
        self.segmentation, self.chain = segmentation, bool(chain)
        self.register_buffer("part_labels", torch.tensor(labels))
        self.levels = None  # [(parts, parents)] per depth, for the chained transform
        if segmentation == "topology":
            parent = np.asarray(parent, dtype=np.int64)
            if parent.shape != (K,):
                raise ValueError(f"part parents must be [K = {K}], got shape {parent.shape}")
            self.levels = depth_levels(parent)  # refuses a cycle or unnumbered parents
            self.register_buffer("part_parent", torch.tensor(parent))
        self.omega_raw = nn.Parameter(torch.full((K,), b.omega_raw_init()))
        self.zeta_raw = nn.Parameter(torch.full((K,), b.zeta_raw_init()))
        self.gain_raw = nn.Parameter(torch.zeros(K))
        self.register_buffer("gain_scale", torch.tensor(w0**2 / ctx.wind_force_std))
        axis = np.asarray(ctx.view_dir, dtype=np.float64).copy()
        axis[2] = 0.0
        if np.linalg.norm(axis) < 1e-6:  # camera looking straight down: any horizontal axis
            axis = np.array([1.0, 0.0, 0.0])
        axis /= np.linalg.norm(axis)
        self.axis_raw = nn.Parameter(torch.tensor(axis, dtype=torch.float32).repeat(K, 1))
        base = np.array([*xyz[:, :2].mean(0), xyz[:, 2].min()])
        pivots = np.empty((K, 3))
        for p in range(K):
            members = xyz[labels == p]
            pivots[p] = members[np.argmin(np.linalg.norm(members - base, axis=1))]
        if topo_pivots is not None:  # the joint with the parent (loading overwrites it anyway)
            pivots = topo_pivots
        self.pivot = nn.Parameter(torch.tensor(pivots, dtype=torch.float32))
        # Parts whose motion never reaches the image (physgs.models.visibility): theta = 0 and
        # their physics parameters take no further updates. Saved in checkpoints.
        self.register_buffer("frozen", torch.zeros(K, dtype=torch.bool))
        # The search over omega (physgs.models.omega_search): while bank_active, theta is a
        # linear combination of a fixed bank's responses with weights W [K, M] (each response
        # scaled as the gain is, by omega_m^2 / std of the training forcing, times bank_scale).
        self.search = search
        # what the canonical set is: the rest pose, or the pose at recorded frame 0 (module
        # docstring); in the frame-0 poses frame 0 poses the canonical set exactly
        if canonical_pose not in CANONICAL_POSES:
            raise ValueError(
                f"models.topology.canonical_pose must be one of {CANONICAL_POSES}, got "
                f"{canonical_pose!r}"
            )
        if canonical_pose != "rest" and segmentation != "topology":
            raise ValueError("canonical_pose other than 'rest' is a topology variants' option")
        self.canonical_pose = canonical_pose
        if canonical_pose == "frame0_offset":  # frame 0's angles plus a learned turn per part
            self.pose_offset = nn.Parameter(torch.zeros(K))  # [K] rad
        if search is not None:
            self.bank_omega = log_grid(b.omega_lo, b.omega_hi, search.bank_size)  # [M] rad/s
            self.bank_weights = nn.Parameter(torch.zeros(K, search.bank_size))
            self.register_buffer("bank_active", torch.tensor(True))
            self._bank_memo: dict = {}  # wind bytes -> scaled responses [M, L+F]
        self._theta_memo = None  # (versions, wind [L+F], theta [K, L+F]): part_theta, no autograd

    def freeze_parts(self, mask) -> None:
        """Freeze the parts in ``mask`` [K] bool (added to those already frozen).

        Args:
            mask (ArrayLike): [K] bool, True for a part to freeze.

        Raises:
            ValueError: when the mask is not [K].
        """
        mask = torch.as_tensor(np.asarray(mask, dtype=bool), device=self.frozen.device)
        if mask.shape != (self.K,):
            raise ValueError(f"freeze mask must be [K = {self.K}], got shape {tuple(mask.shape)}")
        self.frozen |= mask

    def _load_from_state_dict(self, state_dict, prefix, *args, **kwargs):
        # checkpoints written before freezing existed have no mask: nothing was frozen
        state_dict.setdefault(prefix + "frozen", torch.zeros(self.K, dtype=torch.bool))
        super()._load_from_state_dict(state_dict, prefix, *args, **kwargs)

    @property
    def omega(self) -> torch.Tensor:
        """[K] natural frequencies, rad/s."""
        return self.bounds.omega(self.omega_raw)

    @property
    def zeta(self) -> torch.Tensor:
        """[K] damping ratios (dimensionless)."""
        return self.bounds.zeta(self.zeta_raw)

    @property
    def gain(self) -> torch.Tensor:
        """[K] force gains, rad / m^2 (angular acceleration per unit of v^2 - vbar^2)."""
        return self.gain_raw * self.gain_scale

    @property
    def axis(self) -> torch.Tensor:
        """[K, 3] unit swing axes (world)."""
        return self.axis_raw / self.axis_raw.norm(dim=-1, keepdim=True)

    def part_theta(self, wind: torch.Tensor, upto: int | None = None) -> torch.Tensor:
        """Swing angles theta [K, L+F] (rad) under one condition's observed wind [L+F] (m/s).

        vbar, the condition's mean speed, is the record's mean times the calibration ratio frozen
        from the training condition (``ModelContext.vbar_ratio``). Frozen parts have theta = 0.

        Args:
            wind: [L+F] the condition's observed wind, m/s.
            upto: with autograd, integrate only samples [0, upto): the oscillators start from
                rest at sample 0 and are causal, so these are the full series' first ``upto``
                columns (a training iteration needs one frame, not the whole record). None (and
                always without autograd): the whole record.

        Returns:
            [K, L+F] theta, rad, in the dtype of omega (the bank's angle during the bank phase);
                [K, upto] when ``upto`` is given with autograd on.
                Without autograd the last result is kept and returned again for the same wind and
                parameters: callers must not write to it.

        Raises:
            ValueError: when ``wind`` is not one-dimensional.
        """
        wind = torch.as_tensor(wind, dtype=torch.float64)
        if wind.ndim != 1:
            raise ValueError(f"part_theta: wind must be [L+F], got shape {tuple(wind.shape)}")
        if torch.is_grad_enabled():
            return self._integrate_theta(wind, upto)
        # Without autograd (evaluation, recovery) every frame of a series asks for the same
        # series: keep the last one, keyed by the wind's values and the versions of everything
        # theta reads, so an in-place edit of a parameter or of the frozen mask (or a new tensor,
        # e.g. after load_state_dict or .double()) recomputes it. Callers must not write to it.
        reads = (self.omega_raw, self.zeta_raw, self.gain_raw, self.gain_scale, self.frozen)
        if self.search is not None:
            reads = (*reads, self.bank_weights, self.bank_active)
        key = tuple((t.data_ptr(), t._version) for t in reads)
        hit = self._theta_memo
        if hit is not None and hit[0] == key and torch.equal(hit[1], wind):
            return hit[2]
        theta = self._integrate_theta(wind)
        self._theta_memo = (key, wind.clone(), theta)
        return theta

    def _bank_responses(self, wind: torch.Tensor) -> torch.Tensor:
        """The bank's responses [M, L+F] to wind [L+F] (m/s), scaled to quasi-static radians."""
        key = wind.cpu().numpy().tobytes()
        if key not in self._bank_memo:
            vbar = condition_vbar(self.vbar_ratio, wind)
            om = self.bank_omega
            r = unit_responses(
                om, np.full_like(om, self.search.bank_zeta), wind, vbar, self.dt, self.substeps
            )  # [M, L+F]
            scale = self.search.bank_scale * om**2 / float(self.ctx.wind_force_std)
            self._bank_memo[key] = torch.as_tensor(
                r * scale[:, None], dtype=torch.float32, device=self.bank_weights.device
            )
        return self._bank_memo[key]

    def end_bank_phase(self, windows) -> dict:
        """Project each part's bank angle onto one oscillator and hand over to the oscillators.

        Sets omega, zeta (grid of ``search.grid`` over the bounds) and gain by least squares
        ([`project_to_oscillators`][physgs.models.omega_search.project_to_oscillators]); the bank is
        switched off.

        Args:
            windows (list[tuple[ArrayLike, slice]]): ``(wind [L+F] m/s, slice of the samples
                fitted)`` of the trained conditions.

        Returns:
            ``omega_search_explained_median`` (the median share of each part's angle energy the
                oscillator explains) and ``omega_search_hz_quartiles`` (omega's quartiles, Hz).

        Raises:
            RuntimeError: when the prior has no bank phase running.
        """
        if self.search is None or not bool(self.bank_active):
            raise RuntimeError("end_bank_phase: this prior has no bank phase running")
        b, (n_om, n_ze) = self.bounds, self.search.grid
        # strictly inside the bounds: the raw parameters are logits of them
        inset = GRID_INSET
        om_g = log_grid(b.omega_lo * (1 + inset), b.omega_hi * (1 - inset), n_om)
        dz = inset * (b.zeta_hi - b.zeta_lo)
        ze_g = np.linspace(b.zeta_lo + dz, b.zeta_hi - dz, n_ze)
        om_all, ze_all = (a.ravel() for a in np.meshgrid(om_g, ze_g, indexing="ij"))  # [G]
        thetas, resp = [], []  # [K, S_c] and [G, S_c] per condition c
        with torch.no_grad():
            for wind, samples in windows:
                w = torch.as_tensor(np.asarray(wind), dtype=torch.float64)
                theta = (self.bank_weights @ self._bank_responses(w)).double().cpu().numpy()
                vbar = condition_vbar(self.vbar_ratio, w)
                r = unit_responses(om_all, ze_all, w, vbar, self.dt, self.substeps)
                theta, r = theta[:, samples], r[:, samples]  # [K, S], [G, S]
                if self.canonical_pose != "rest":
                    # the images see each angle relative to frame 0 (the window's first sample):
                    # the bank's angle there is unconstrained, so fit the differences
                    theta, r = theta - theta[:, :1], r - r[:, :1]
                thetas.append(theta)
                resp.append(r)
            omega, zeta, gain, explained = project_to_oscillators(
                np.concatenate(thetas, axis=1), np.concatenate(resp, axis=1), om_all, ze_all
            )
            self.omega_raw.copy_(torch.tensor([b.omega_raw(float(o)) for o in omega]))
            self.zeta_raw.copy_(torch.tensor([b.zeta_raw(float(z)) for z in zeta]))
            self.gain_raw.copy_(torch.as_tensor(gain / float(self.gain_scale)))
            self.bank_active.fill_(False)
        hz = np.percentile(omega / (2 * np.pi), [25, 50, 75])
        return {
            "omega_search_explained_median": float(np.median(explained)),
            "omega_search_hz_quartiles": [float(h) for h in hz],
        }

    def _integrate_theta(self, wind: torch.Tensor, upto: int | None = None) -> torch.Tensor:
        if self.search is not None and bool(self.bank_active):
            return self.bank_weights @ self._bank_responses(wind)[:, :upto]  # [K, upto]
        vbar = condition_vbar(self.vbar_ratio, wind)  # of the whole record, whatever upto
        theta = integrate(
            self.omega,
            self.zeta,
            self.gain,
            wind[:upto],
            vbar,
            self.dt,
            self.substeps,
            guard=self.guard,
            backend="auto",  # numba on the CPU, the closed form on a GPU (no host round trip)
        )  # [K, upto]
        if not bool(self.frozen.any()):
            return theta
        # where(), not a product: frozen rows get exactly zero gradient, so with their Adam
        # moments reset (visibility.freeze_invisible) their parameters stay put
        return torch.where(self.frozen[:, None], torch.zeros_like(theta), theta)

    def deform(self, frame_idx: int, wind: torch.Tensor) -> GaussianState:
        """The canonical set turned part by part by theta_p at recorded frame ``frame_idx``.

        Args:
            frame_idx: recorded frame, 0-based.
            wind: the condition's observed wind [L+F], m/s, lead-in included.

        Returns:
            The deformed Gaussians (positions and orientations rotated; scales, opacities, colours
                those of the canonical set).
        """
        theta_all = self.part_theta(wind, upto=self.lead_in + frame_idx + 1)  # [K, >= that]
        theta = theta_all[:, self.lead_in + frame_idx]  # [K]
        theta0 = theta_all[:, self.lead_in]  # [K] at recorded frame 0
        if self.canonical_pose == "frame0_offset":
            theta0 = theta0 + self.pose_offset
        lab = self.part_labels
        c = self.canonical
        composed = self.chain and self.canonical_pose in ("frame0", "frame0_offset")
        if self.canonical_pose != "rest" and not composed:
            theta = theta - theta0  # one rotation per part: undoing frame 0's is the difference
        if composed:
            means, quats = chain_deform_from(
                c.means, c.quats, lab, self.axis, theta, theta0, self.pivot, self.levels
            )
        elif self.chain:
            means, quats = chain_deform(
                c.means, c.quats, lab, self.axis, theta, self.pivot, self.levels
            )
        else:
            means, quats = rotate_parts(c.means, c.quats, lab, self.axis, theta, self.pivot)
        return GaussianState(
            means,
            quats,
            torch.exp(c.log_scales),
            torch.sigmoid(c.opacity_logits),
            torch.sigmoid(c.color_logits),
        )

    def bounded_positions(self) -> dict[str, np.ndarray]:
        """sigmoid of omega_raw and zeta_raw (their place between the bounds) of the parts that
        are not frozen (a frozen part's parameters take no updates).

        Returns:
            ``omega`` and ``zeta``: [n] each, in [0, 1], over the n parts not frozen.
        """
        live = ~self.frozen.cpu().numpy()
        with torch.no_grad():
            return {
                name: torch.sigmoid(raw.detach().double()).cpu().numpy()[live]
                for name, raw in (("omega", self.omega_raw), ("zeta", self.zeta_raw))
            }

    def scale_settings(self) -> dict[str, list[tuple[str, float]]]:
        """With the search, the physics group's bank weights act through bank_scale, and the
        hand-over sets the gains from them.

        Returns:
            ``{"physics": [("models.omega_search.bank_scale", value)]}`` with the search, else
                empty.
        """
        if self.search is not None:
            return {"physics": [("models.omega_search.bank_scale", float(self.search.bank_scale))]}
        return {}

    def deformation_param_groups(self, lr: dict) -> list[dict]:
        """The ``physics`` group (omega, zeta, gain, axis, bank weights) and the ``pivot`` group.

        Args:
            lr: config ``train.lr`` (the pivot rate is multiplied by the scene extent).

        Returns:
            The parameter groups.
        """
        return [
            {
                "name": "physics",
                "params": [self.omega_raw, self.zeta_raw, self.gain_raw, self.axis_raw]
                + ([self.bank_weights] if self.search is not None else []),
                "lr": lr["physics"],
            },
            {"name": "pivot", "params": [self.pivot], "lr": lr["pivot"] * self.extent},
        ] + (
            # radians of the rest pose's turn: the pivot's rate without the scene's extent
            [{"name": "pivot", "params": [self.pose_offset], "lr": lr["pivot"]}]
            if self.canonical_pose == "frame0_offset"
            else []
        )
