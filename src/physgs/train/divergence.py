"""Divergence checks for the training loop: stop a run whose fit has blown up, and say why.

A learning rate far too high does not always give a NaN loss: Adam moves every parameter by about
the learning rate per step, so at 1e6 a field's Gaussians fly millions of metres away (the render
shows only background, a finite loss) and ours' bounded oscillators spin chaotically in place.
[`DivergenceGuard`][physgs.train.divergence.DivergenceGuard] is a pure checker on numpy arrays and
floats, built from the canonical positions and the initial parameters; the loop feeds it every
iteration and turns a [`Divergence`][physgs.train.divergence.Divergence] into a ``TrainingError``
naming the model, the iteration and the setting.

Three checks, each cheap next to a render:

- parameters: non-finite, or grown to PARAM_GROWTH x their initial scale;
- Gaussians: non-finite means, or more than BOUNDS_FRACTION of them farther than BOUNDS_FACTOR
  scene extents from the centre of the canonical bounding box;
- loss: its running median (LOSS_WINDOW iterations) above LOSS_RATIO x its warm-up level (the
  median of the last LOSS_WINDOW warm-up iterations), checked from LOSS_GRACE iterations after
  the warm-up on.

Parameter groups are named as in ``BaseModel.param_groups``, which are the keys of the config's
``train.lr``; a Divergence lists the groups most likely responsible, most likely first.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

#: Distance from the canonical box's centre, in scene extents (half the box diagonal), beyond
#: which a Gaussian counts as gone: a swaying tree stays within about 2, and a camera framing the
#: tree sees nothing that far out.
BOUNDS_FACTOR = 10.0

#: Share of the Gaussians that may be beyond BOUNDS_FACTOR before the run counts as diverged: a
#: stray Gaussian is not a divergence, while a diverged field or pivot moves them by the hundred.
BOUNDS_FRACTION = 0.01

#: Growth of a parameter's largest |value| over its initial one (floored at 1, for parameters
#: that start at zero) that counts as exploding. Adam moves a parameter by at most about its
#: rate per step, so the configured rates (<= 5e-2) drift by a few hundred over the longest run
#: even in the worst case (a healthy 1500-iteration run grows none past 12x); a rate of 1e6
#: gets there in one step.
PARAM_GROWTH = 1e4

#: Iterations in the running median of the loss (and in the warm-up level): one iteration draws
#: one frame of one condition, and in a healthy run (ours_joint96, default profile) single
#: losses vary 4x between draws, 15-iteration medians 1.7x, 50-iteration ones 1.1x.
LOSS_WINDOW = 50

#: Iterations after the end of the warm-up before the loss check starts, so that the window
#: holds deformation-phase losses only (the first steps of a freshly started deformation can
#: legitimately jump a little; the median then ignores them).
LOSS_GRACE = LOSS_WINDOW

#: Running median over the warm-up level that counts as diverged. The deformation starts at the
#: canonical pose the warm-up fitted and only has to improve on it; a sustained tripling of the
#: photometric loss means the tree has been lost from the render (healthy runs stay below 1.1x,
#: about 1.7x with a 15-iteration window).
LOSS_RATIO = 3.0

#: A group grown less than this share of the most grown one is not named as a likely setting.
SUSPECT_SHARE = 0.1

#: Growth below which no group counts as grown (healthy parameters wander by a few times their
#: initial scale), so every candidate group is named.
SUSPECT_GROWN = 2.0

#: A bounded physical parameter (omega, zeta: a sigmoid of a raw value between two bounds) whose
#: sigmoid is within this of 0 or 1 sits on its bound (raw beyond +-6.9). A fit with every one
#: of them there has no physics left to fit (train.lr.physics at 1e3 pins all 64 of the sparse
#: tree's; the default rate none).
PIN_TOL = 1e-3

#: Parameter groups of the canonical set (``BaseModel.param_groups``); the rest deform it.
CANONICAL_GROUPS = ("means", "quats", "scales", "opacities", "colors")


@dataclass(frozen=True)
class Divergence:
    """What diverged (a sentence) and the parameter groups (= ``train.lr`` keys) most likely
    responsible, most likely first."""

    what: str
    groups: tuple[str, ...]


def pinned(positions: Mapping[str, np.ndarray], group: str = "physics") -> Divergence | None:
    """A Divergence when every bounded parameter sits on a bound (within PIN_TOL), else None.

    Args:
        positions: name -> [n] places between the bounds, 0..1
            ([`bounded_positions`][physgs.models.base.BaseModel.bounded_positions]).
        group: the parameter group (``train.lr`` key) that trains them.

    Returns:
        The [`Divergence`][physgs.train.divergence.Divergence] naming ``group``, or None (also
            when there is no bounded parameter).
    """
    arrays = {k: np.asarray(v, np.float64).ravel() for k, v in positions.items()}
    n = sum(a.size for a in arrays.values())
    if n == 0:
        return None
    on = {k: (a <= PIN_TOL) | (a >= 1 - PIN_TOL) for k, a in arrays.items()}
    if not all(m.all() for m in on.values()):
        return None
    counts = ", ".join(
        f"{k}: {int((a <= PIN_TOL).sum())} low / {int((a >= 1 - PIN_TOL).sum())} high"
        for k, a in arrays.items()
    )
    return Divergence(
        f"every bounded physical parameter sits on a bound ({counts}): the fit has no physics "
        "left (a saturated fit, not a result)",
        (group,),
    )


@dataclass
class DivergenceGuard:
    """Divergence checks for one training run (see the module docstring).

    center [3], extent: centre and half-diagonal of the canonical positions' bounding box (world
    units); warmup: iterations of the static warm-up; scale: parameter name -> initial largest
    |value| floored at 1; group: parameter name -> its parameter group.
    """

    center: np.ndarray
    extent: float
    warmup: int
    scale: dict[str, float]
    group: dict[str, str]
    _warm: deque = field(default_factory=lambda: deque(maxlen=LOSS_WINDOW), repr=False)
    _recent: deque = field(default_factory=lambda: deque(maxlen=LOSS_WINDOW), repr=False)
    _level: float | None = field(default=None, repr=False)
    _growth: dict[str, float] = field(default_factory=dict, repr=False)

    @classmethod
    def build(
        cls, canonical_xyz, params: Mapping[str, object], group: Mapping[str, str], warmup: int
    ) -> "DivergenceGuard":
        """Guard from the canonical positions, the initial parameters, their groups and the warm-up.

        Args:
            canonical_xyz (ArrayLike): [N, 3] canonical positions, world units (their box's centre
                and half-diagonal set the scene's centre and extent).
            params: name -> array, or its largest |value| (the initial scale, at least 1).
            group: each parameter's group (``train.lr`` key).
            warmup: static warm-up iterations.

        Returns:
            The guard.

        Raises:
            ValueError: for positions that are not finite [N > 0, 3], or a parameter without a
                group.
        """
        xyz = np.asarray(canonical_xyz, dtype=np.float64)
        if xyz.ndim != 2 or xyz.shape[1] != 3 or xyz.shape[0] == 0 or not np.isfinite(xyz).all():
            raise ValueError(
                f"DivergenceGuard: canonical positions must be finite [N, 3], N > 0; "
                f"got shape {xyz.shape}"
            )
        missing = sorted(set(params) - set(group))
        if missing:
            raise ValueError(f"DivergenceGuard: parameters {missing} belong to no parameter group")
        lo, hi = xyz.min(0), xyz.max(0)
        extent = max(float(0.5 * np.linalg.norm(hi - lo)), 1e-6)
        scale = {k: max(1.0, _abs_max(v)) for k, v in params.items()}
        return cls(0.5 * (lo + hi), extent, int(warmup), scale, dict(group))

    # -- suspects --------------------------------------------------------------------------------

    def growth(self) -> dict[str, float]:
        """Group -> largest |value| / initial scale over its parameters at the last check_params
        (empty before the first).

        Returns:
            A copy of the growth ratios by group.
        """
        return dict(self._growth)

    def suspects(self, groups) -> tuple[str, ...]:
        """``groups`` (those present) ordered by growth at the last check_params, largest first,
        leaving out those grown less than SUSPECT_SHARE of the largest (a group that did not
        move is no suspect next to one that did). While no group has grown past SUSPECT_GROWN,
        growth says nothing: all of them, in the order given.

        Args:
            groups (Iterable[str]): candidate groups (duplicates and absent groups dropped).

        Returns:
            The suspect groups, most grown first.
        """
        present = [g for g in dict.fromkeys(groups) if g in set(self.group.values())]
        top = max((self._growth.get(g, 0.0) for g in present), default=0.0)
        if top <= SUSPECT_GROWN:
            return tuple(present)
        ranked = sorted(present, key=lambda g: -self._growth.get(g, 0.0))
        return tuple(g for g in ranked if self._growth.get(g, 0.0) >= SUSPECT_SHARE * top)

    def deformation_groups(self) -> tuple[str, ...]:
        """The groups that deform the canonical set (none for the static model).

        Returns:
            The guard's groups that are not in ``CANONICAL_GROUPS``, in first-seen order.
        """
        return tuple(g for g in dict.fromkeys(self.group.values()) if g not in CANONICAL_GROUPS)

    def deformation_suspects(self) -> tuple[str, ...]:
        """The deformation groups by growth, or, for a model without any, the canonical ones.

        Returns:
            The suspect groups, most grown first.
        """
        return self.suspects(self.deformation_groups() or CANONICAL_GROUPS)

    # -- checks ----------------------------------------------------------------------------------

    def check_params(self, params: Mapping[str, object]) -> Divergence | None:
        """Parameters (name -> array, or its largest |value|) after an optimiser step: a
        non-finite value, or one grown past PARAM_GROWTH x its initial scale, diverged.

        Args:
            params: name -> array, or its largest |value|; every name must be one the guard was
                built with.

        Returns:
            The [`Divergence`][physgs.train.divergence.Divergence] (every group over the limit, the
                worst first), or None. Records each group's growth for
                [`suspects`][physgs.train.divergence.DivergenceGuard.suspects].
        """
        worst, worst_ratio = None, 0.0
        growth: dict[str, float] = {}
        for name, v in params.items():
            m = _abs_max(v)
            g = self.group[name]
            if not np.isfinite(m):
                self._growth = growth
                return Divergence(f"parameter '{name}' (group {g}) is non-finite ({m})", (g,))
            r = m / self.scale[name]
            growth[g] = max(growth.get(g, 0.0), r)
            if r > worst_ratio:
                worst, worst_ratio = name, r
        self._growth = growth
        if worst is None or worst_ratio <= PARAM_GROWTH:
            return None
        g = self.group[worst]
        over = tuple(
            sorted((k for k in growth if growth[k] > PARAM_GROWTH), key=lambda k: -growth[k])
        )  # every group over the limit, g first
        also = "".join(f"; group {k} too ({growth[k]:.3g}x)" for k in over if k != g)
        value = worst_ratio * self.scale[worst]
        return Divergence(
            f"parameter '{worst}' (group {g}) reached |value| {value:.3g}, "
            f"{worst_ratio:.3g}x its initial scale {self.scale[worst]:.3g} (limit "
            f"{PARAM_GROWTH:g}x){also}",
            over,
        )

    def check_means(self, means) -> Divergence | None:
        """Gaussian positions [N, 3] (world units) about to be rendered.

        Args:
            means (ArrayLike): [N, 3] Gaussian positions, world units.

        Returns:
            A [`Divergence`][physgs.train.divergence.Divergence] when a mean is not finite or more
                than BOUNDS_FRACTION of them lie over BOUNDS_FACTOR x the extent from the centre,
                else None.
        """
        x = np.asarray(means)
        lo, hi = x.min(0), x.max(0)
        if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
            bad = int((~np.isfinite(x).all(1)).sum())
            return Divergence(
                f"{bad} of the {x.shape[0]} Gaussian means are NaN or inf",
                self.suspects(("means", *self.deformation_groups())),
            )
        r = BOUNDS_FACTOR * self.extent
        # the farthest corner of the means' own box bounds every distance: usually one test
        corner = np.maximum(np.abs(lo - self.center), np.abs(hi - self.center))
        if float(np.dot(corner, corner)) <= r * r:
            return None
        d = np.sqrt(((x.astype(np.float64) - self.center) ** 2).sum(1)) / self.extent
        frac = float((d > BOUNDS_FACTOR).mean())
        if frac <= BOUNDS_FRACTION:
            return None
        return Divergence(
            f"{frac:.0%} of the {x.shape[0]} Gaussians are more than {BOUNDS_FACTOR:g}x the scene "
            f"extent ({self.extent:.3g}) from its centre (median {np.median(d):.3g}x, farthest "
            f"{d.max():.3g}x)",
            self.suspects(("means", *self.deformation_groups())),
        )

    def check_loss(self, it: int, loss: float) -> Divergence | None:
        """The loss of iteration ``it`` (0-based, called once per iteration in order).

        Args:
            it: the iteration, 0-based.
            loss: its loss.

        Returns:
            A [`Divergence`][physgs.train.divergence.Divergence] when the loss's recent median
                exceeds LOSS_RATIO x its warm-up level (checked from LOSS_GRACE iterations after the
                warm-up), else None.
        """
        loss = float(loss)
        if it < self.warmup:
            self._warm.append(loss)
            return None
        if self._level is None:
            # level: the last warm-up iterations, or with no warm-up the first LOSS_WINDOW
            if self._warm:
                self._level = float(np.median(self._warm))
            else:
                self._warm.append(loss)
                if len(self._warm) < LOSS_WINDOW:
                    return None
                self._level = float(np.median(self._warm))
        self._recent.append(loss)
        if it < self.warmup + LOSS_GRACE or len(self._recent) < LOSS_WINDOW:
            return None
        med = float(np.median(self._recent))
        if not med > LOSS_RATIO * self._level:
            return None
        return Divergence(
            f"the loss (median {med:.3g} over the last {LOSS_WINDOW} iterations) is "
            f"{med / max(self._level, 1e-12):.3g}x its warm-up level {self._level:.3g} (limit "
            f"{LOSS_RATIO:g}x)",
            self.deformation_suspects(),
        )


def _abs_max(v) -> float:
    """Largest |value| of an array or scalar; NaN if any value is NaN, inf if any is inf."""
    a = np.asarray(v)
    if a.size == 0:
        return 0.0
    return float(np.max(np.abs(a)))
