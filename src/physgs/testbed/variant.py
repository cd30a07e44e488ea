"""Testbed variants (the protocol, section 1): which damping the bones get and what the wind does.

``faithful`` (the default, the paper's): every bone has ``testbed.zeta``, the wind is the
unmodified turbulence realisation. ``damping``: each bone's zeta is drawn log-uniformly from
``testbed.damping.zeta_range`` (its own seeded stream), and inside the recorded training window
a gust drops to calm on purpose: the turbulence fades out while a gust rises and falls, the wind
then stays exactly at the mean speed for ``calm_s`` seconds (drag forcing v^2 - vbar^2 = 0, so
every bone decays freely with envelope exp(-zeta_b omega_b t)), and the turbulence fades back in.

Times are seconds with t = 0 at recorded frame 0 (frame j at t = j / fps), as in
[`physgs.testbed.dataset`][]. Everything here is a pure function of the config and arrays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from physgs.testbed import physics

FAITHFUL, DAMPING = "faithful", "damping"
VARIANTS = (FAITHFUL, DAMPING)


#: a damping benchmark's testbed id: the tree's name and this suffix (``damping_id``)
DAMPING_SUFFIX = "_damping"


def damping_id(tree: str) -> str:
    """The testbed id of ``tree``'s damping variant ('medium' -> 'medium_damping').

    Args:
        tree: the tree's name.

    Returns:
        The damping variant's testbed id.
    """
    return tree + DAMPING_SUFFIX


def parse_id(testbed: str) -> tuple[str, str]:
    """(tree, variant) of a testbed id: 'medium_damping' -> ('medium', 'damping'), 'medium' ->
    ('medium', 'faithful'). The damping copy shares the tree's geometry, frequencies and wind.

    Args:
        testbed: a testbed id.

    Returns:
        ``(tree, variant)``, variant ``'damping'`` or ``'faithful'``.
    """
    if testbed.endswith(DAMPING_SUFFIX):
        return testbed[: -len(DAMPING_SUFFIX)], DAMPING
    return testbed, FAITHFUL


def variant_of(tb: dict) -> str:
    """The variant a ``testbed`` config section asks for (``faithful`` when it names none).

    Args:
        tb: the ``testbed`` config section.

    Returns:
        ``'faithful'`` or ``'damping'``.

    Raises:
        ValueError: for a ``variant`` that is not one of ``VARIANTS``.
    """
    v = tb.get("variant", FAITHFUL)
    if v not in VARIANTS:
        raise ValueError(f"testbed.variant '{v}' is not one of {VARIANTS}; fix config/trees.yaml")
    return v


def effective_settings(tb: dict) -> dict:
    """The ``testbed`` section with only what changes the dataset: for the faithful variant the
    ``variant`` and ``damping`` keys are dropped (they change nothing in it), so a job keyed on
    these settings is not rebuilt when the damping block is edited or first added.

    Args:
        tb: the ``testbed`` config section.

    Returns:
        A shallow copy of the section, without ``variant`` and ``damping`` for the faithful
            variant.

    Raises:
        ValueError: for an unknown variant (from [`variant_of`][physgs.testbed.variant.variant_of]).
    """
    if variant_of(tb) == FAITHFUL:
        return {k: v for k, v in tb.items() if k not in ("variant", "damping")}
    return dict(tb)


# --------------------------------------------------------------------------------------------
# Damping ratios


def draw_zeta(zeta_range, n_bones: int, seed_seq: np.random.SeedSequence) -> np.ndarray:
    """[n_bones] damping ratios, log-uniform on [lo, hi] = zeta_range, 0 < lo <= hi <= 1, seeded.

    Args:
        zeta_range (Sequence[float]): ``(lo, hi)``, the damping ratios' range.
        n_bones: number of ratios to draw.
        seed_seq: seeds the generator (one uniform draw per bone).

    Returns:
        [n_bones] damping ratios (dimensionless).

    Raises:
        ValueError: unless 0 < lo <= hi <= 1.
    """
    lo, hi = (float(z) for z in zeta_range)
    if not 0 < lo <= hi <= 1:
        raise ValueError(
            f"zeta_range {list(zeta_range)} must satisfy 0 < lo <= hi <= 1; fix "
            "testbed.damping.zeta_range in config/trees.yaml"
        )
    u = np.random.default_rng(seed_seq).uniform(size=n_bones)
    return np.exp(math.log(lo) + u * (math.log(hi) - math.log(lo)))


def bone_zeta(tb: dict, n_bones: int, seed_seq: np.random.SeedSequence) -> np.ndarray:
    """[n_bones] damping ratio of every bone: ``testbed.zeta`` for all (faithful) or drawn from
    ``testbed.damping.zeta_range`` with ``seed_seq`` (damping; the faithful variant ignores it).

    Args:
        tb: the ``testbed`` config section.
        n_bones: number of bones.
        seed_seq: seeds the draw of the damping variant.

    Returns:
        [n_bones] damping ratios (dimensionless).

    Raises:
        ValueError: for an unknown variant or a bad ``zeta_range``.
    """
    if variant_of(tb) == FAITHFUL:
        return np.full(n_bones, float(tb["zeta"]))
    return draw_zeta(tb["damping"]["zeta_range"], n_bones, seed_seq)


# --------------------------------------------------------------------------------------------
# The deliberate transient: a gust dropping to calm


@dataclass(frozen=True)
class Transient:
    """A gust dropping to calm, in seconds from recorded frame 0.

    start_s: the calm begins (the gust occupies [start_s - gust_s, start_s]); calm_s: the wind
    stays exactly at the mean speed over [start_s, start_s + calm_s]; gust_s: the gust's length,
    over which the turbulence also fades out; gust_gain: the gust's peak above the mean, as a
    fraction of the mean speed; ramp_s: the turbulence fades back in over
    [start_s + calm_s, start_s + calm_s + ramp_s].
    """

    start_s: float
    calm_s: float
    gust_s: float
    gust_gain: float
    ramp_s: float

    @property
    def calm_window_s(self) -> tuple[float, float]:
        """(start, end) of the calm, seconds from recorded frame 0."""
        return self.start_s, self.start_s + self.calm_s


def transient_of(tb: dict) -> Transient | None:
    """The transient a ``testbed`` section asks for (None for the faithful variant).

    Args:
        tb: the ``testbed`` config section (reads ``damping.transient`` for the damping variant).

    Returns:
        The [`Transient`][physgs.testbed.variant.Transient], or None.

    Raises:
        ValueError: for an unknown variant.
    """
    if variant_of(tb) == FAITHFUL:
        return None
    t = tb["damping"]["transient"]
    return Transient(
        float(t["start_s"]),
        float(t["calm_s"]),
        float(t["gust_s"]),
        float(t["gust_gain"]),
        float(t["ramp_s"]),
    )


def _rise(x: np.ndarray) -> np.ndarray:
    """sin^2(pi x / 2) clipped to [0, 1]: 0 for x <= 0, 1 for x >= 1, smooth (C1) between."""
    return np.sin(0.5 * np.pi * np.clip(x, 0.0, 1.0)) ** 2


def turbulence_weight(t: np.ndarray, tr: Transient) -> np.ndarray:
    """[T] weight of the turbulence at times t [T] (s): 1, fading to exactly 0 over the gust,
    0 through the calm, fading back to 1 over ramp_s.

    Args:
        t: [T] times, s from recorded frame 0.
        tr: the gust and calm.

    Returns:
        [T] weights in [0, 1].
    """
    t = np.asarray(t, dtype=np.float64)
    down = 1.0 - _rise((t - (tr.start_s - tr.gust_s)) / tr.gust_s)
    end = tr.start_s + tr.calm_s
    up = _rise((t - end) / tr.ramp_s) if tr.ramp_s > 0 else (t > end).astype(np.float64)
    return np.where(t < tr.start_s, down, np.where(t <= end, 0.0, up))


def gust_shape(t: np.ndarray, tr: Transient) -> np.ndarray:
    """[T] Hann bump sin^2(pi (t - t0) / gust_s) on [t0, t0 + gust_s], t0 = start_s - gust_s;
    0 elsewhere (it is back to exactly 0 when the calm begins).

    Args:
        t: [T] times, s from recorded frame 0.
        tr: the gust and calm.

    Returns:
        [T] bump values in [0, 1].
    """
    x = (np.asarray(t, dtype=np.float64) - (tr.start_s - tr.gust_s)) / tr.gust_s
    return np.where((x > 0) & (x < 1), np.sin(np.pi * np.clip(x, 0.0, 1.0)) ** 2, 0.0)


def shape_wind(v: np.ndarray, t: np.ndarray, v0: float, tr: Transient) -> np.ndarray:
    """The wind with the transient: v0 + w(t) (v - v0) + gust_gain v0 gust(t), m/s [T].

    Exactly v0 through the calm (w = gust = 0 there), so the drag forcing v^2 - v0^2 is exactly 0;
    never below min(v, v0), so a positive wind stays positive; v itself outside the transient.

    Args:
        v: [T] the unmodified wind speed, m/s.
        t: [T] its times, s from recorded frame 0.
        v0: the mean speed, m/s.
        tr: the gust and calm.

    Returns:
        [T] the shaped wind speed, m/s (bit-identical to ``v`` where untouched).
    """
    v = np.asarray(v, dtype=np.float64)
    w, g = turbulence_weight(t, tr), gust_shape(t, tr)
    shaped = v0 + w * (v - v0) + tr.gust_gain * v0 * g
    return np.where((w == 1.0) & (g == 0.0), v, shaped)  # untouched samples stay bit-identical


def calm_frames(tr: Transient, fps: int) -> tuple[int, int]:
    """(j0, j1): recorded frames j0 <= j < j1 lie inside the calm; between consecutive ones the
    forcing is exactly zero (the simulator holds the forcing linear between frames).

    Args:
        tr: the gust and calm.
        fps: frame rate, frames/s.

    Returns:
        ``(j0, j1)``, recorded-frame indices; a calm edge on a frame counts as inside.
    """
    t0, t1 = tr.calm_window_s
    eps = 1e-9  # a calm edge on a frame counts as inside
    return int(math.ceil(t0 * fps - eps)), int(math.floor(t1 * fps + eps)) + 1


def lead_in_frames(omega: np.ndarray, zeta: np.ndarray, lead_in_tau: float, fps: int) -> int:
    """Lead-in frames from the slowest-decaying bone, ceil(lead_in_tau / min(zeta_b omega_b) fps).

    For a constant zeta this is exactly ``physics.lead_in_frames(omega.min(), zeta, ...)`` (same
    operands, same rounding).

    Args:
        omega: [B] natural frequencies, rad/s.
        zeta: [B] damping ratios.
        lead_in_tau: lead-in length in units of the slowest decay time 1 / (zeta_b omega_b).
        fps: frames per second.

    Returns:
        The lead-in, frames.
    """
    i = int(np.argmin(np.asarray(zeta) * np.asarray(omega)))
    return physics.lead_in_frames(float(omega[i]), float(zeta[i]), lead_in_tau, fps)
