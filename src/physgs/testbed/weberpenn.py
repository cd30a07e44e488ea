"""Weber-Penn procedural trees (the model behind Blender's Sapling add-on), reduced to what the
testbed needs: stem polylines with curvature, trunk split clones, child stems placed along the
parent with down-angle and phyllotactic rotation, lengths from the shape ratio, radii from
``ratio``/``ratio_power``/``taper``, and an armature of rigid bones.

Units: metres and degrees in the preset, metres and radians inside. World frame: z up, the trunk
base at the origin.

Exact bone counts: the number of stems per level is fixed by the preset (``stems``) and spread over
the parent stems in proportion to their length (largest remainder, no random splits), so bones = sum
over armature levels of stems x ceil(curve_res / bone_step). The generator counts the bones it
actually built and stops with [`PresetError`][physgs.testbed.weberpenn.PresetError] if that differs
from ``bones``.

Split clones (``split``) vary per clone as Weber-Penn stems do: ``length_v`` scales each clone's
length by 1 + U(-length_v, length_v) and ``curve_v_deg`` sets its random bend (default: the trunk
level's ``curve_v_deg``). The length draws come from their own seeded stream and the bend reuses
the draws made without variation, so every other random draw of the tree stays the same (stems
on a longer clone still grow with it). Neither can change a bone count: a clone has
ceil(curve_res / bone_step) bones whatever its length or bend, and length_v < 1 keeps every
clone's length positive.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import numpy as np


class PresetError(ValueError):
    """A tree preset that cannot be built as declared; the message names the cause and the fix."""


SHAPES = (
    "conical",
    "spherical",
    "hemispherical",
    "cylindrical",
    "tapered_cylindrical",
    "flame",
    "inverse_conical",
    "tend_flame",
)


def shape_ratio(shape: str, r: float) -> float:
    """Weber-Penn shape ratio for relative position r in [0, 1] (1 = base of the crown).

    Args:
        shape: one of ``SHAPES``.
        r: relative position, clipped to [0, 1].

    Returns:
        The ratio (a length factor).

    Raises:
        PresetError: for an unknown shape.
    """
    r = min(max(r, 0.0), 1.0)
    if shape == "conical":
        return 0.2 + 0.8 * r
    if shape == "spherical":
        return 0.2 + 0.8 * math.sin(math.pi * r)
    if shape == "hemispherical":
        return 0.2 + 0.8 * math.sin(0.5 * math.pi * r)
    if shape == "cylindrical":
        return 1.0
    if shape == "tapered_cylindrical":
        return 0.5 + 0.5 * r
    if shape == "flame":
        return r / 0.7 if r <= 0.7 else (1.0 - r) / 0.3
    if shape == "inverse_conical":
        return 1.0 - 0.8 * r
    if shape == "tend_flame":
        return 0.5 + 0.5 * r / 0.7 if r <= 0.7 else 0.5 + 0.5 * (1.0 - r) / 0.3
    raise PresetError(f"unknown shape '{shape}'; use one of {SHAPES}")


@dataclass(frozen=True)
class Stem:
    """One stem: a polyline of ``curve_res`` segments.

    points [S+1, 3] (m); radius: base radius (m), r(z) = radius * (1 - taper z), z in [0, 1];
    level: stem level (0 = trunk and its clones); parent: parent stem index (-1 for the trunk);
    segment_bone [S]: the bone that carries each segment (its own bone on armature levels, the
    nearest ancestor bone on deeper levels).
    """

    points: np.ndarray  # [S+1, 3]
    radius: float
    taper: float
    level: int
    parent: int
    segment_bone: np.ndarray  # [S] int
    armature: bool

    @property
    def length(self) -> float:
        """The polyline's length, m."""
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    def radius_at(self, z: np.ndarray | float) -> np.ndarray:
        """Radius (m) at relative arc position z in [0, 1].

        Args:
            z: relative arc position(s), 0 at the base, 1 at the tip.

        Returns:
            The radius, m, the shape of ``z``.
        """
        return self.radius * (1.0 - self.taper * np.asarray(z, dtype=np.float64))


@dataclass(frozen=True)
class Skeleton:
    """Bones of a tree (rest pose) and the stems they came from.

    head, tail [B, 3] (m); radius [B] (m, mean of the stem radius at head and tail); length [B]
    (m); parent [B] (-1 for the root); level [B] (stem level).
    """

    head: np.ndarray
    tail: np.ndarray
    radius: np.ndarray
    length: np.ndarray
    parent: np.ndarray
    level: np.ndarray
    stems: tuple[Stem, ...]

    @property
    def n_bones(self) -> int:
        """The number of bones, B."""
        return int(self.head.shape[0])


def _rot(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotate vector v [3] about unit axis [3] by angle (rad), Rodrigues."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + np.cross(axis, v) * s + axis * (axis @ v) * (1.0 - c)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _perp(d: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to d, horizontal where possible."""
    p = np.cross(d, [0.0, 0.0, 1.0])
    if np.linalg.norm(p) < 1e-6:
        p = np.cross(d, [1.0, 0.0, 0.0])
    return _unit(p)


def _polyline(start, direction, length, n_seg, curve_deg, curve_v_deg, rng) -> np.ndarray:
    """Stem axis: n_seg equal segments, each bent toward +z by curve/n_seg (+ random curveV/n_seg)."""
    pts = [np.asarray(start, dtype=np.float64)]
    d = _unit(np.asarray(direction, dtype=np.float64))
    seg = length / n_seg
    wobble_axis = _perp(d)  # fixed bend plane for near-vertical stems
    for _ in range(n_seg):
        pts.append(pts[-1] + d * seg)
        ang = math.radians(curve_deg / n_seg + rng.normal(0.0, 1.0) * curve_v_deg / n_seg)
        axis = np.cross(d, [0.0, 0.0, 1.0])
        axis = _unit(axis) if np.linalg.norm(axis) > 1e-3 else wobble_axis
        d = _unit(_rot(d, axis, ang))
    return np.array(pts)


def _apportion(total: int, weights: np.ndarray) -> np.ndarray:
    """Split an integer total in proportion to weights (largest remainder), exact sum."""
    if total == 0:
        return np.zeros(len(weights), dtype=int)
    if weights.sum() <= 0:
        raise PresetError(
            "no parent stem has room for children (all weights zero); "
            "lower base_size or add a parent level"
        )
    share = total * weights / weights.sum()
    n = np.floor(share).astype(int)
    rest = total - n.sum()
    n[np.argsort(-(share - n), kind="stable")[:rest]] += 1
    return n


def _stable_id(name: str) -> int:
    return zlib.crc32(name.encode())


def bones_per_stem(curve_res: int, bone_step: int) -> int:
    """Bones on one armature stem: ceil(curve_res / bone_step).

    Args:
        curve_res: the stem's polyline segments.
        bone_step: segments per bone.

    Returns:
        The bone count.
    """
    return -(-int(curve_res) // int(bone_step))


def generate(preset: dict, *, seed: int, name: str) -> Skeleton:
    """Build a tree from a preset (a ``presets.<name>`` entry of config/trees.yaml).

    Deterministic for (seed, name).

    Args:
        preset: the ``presets.<name>`` mapping (levels, armature_levels, scale, shape, split, ...).
        seed: the run's seed.
        name: the tree's name (it and ``seed`` seed the generator; named in errors).

    Returns:
        The [`Skeleton`][physgs.testbed.weberpenn.Skeleton]: bones in metres, and their stems.

    Raises:
        PresetError: naming the cause and the fix when the preset is inconsistent or its declared
            ``bones`` count is not what the geometry yields.
    """
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), _stable_id(name), 1]))
    levels = preset["levels"]
    n_arm = int(preset["armature_levels"])
    if not 1 <= n_arm <= len(levels):
        raise PresetError(
            f"preset '{name}': armature_levels={n_arm} must be between 1 and the "
            f"number of levels ({len(levels)}); fix presets.{name} in config/trees.yaml"
        )
    scale = float(preset["scale"])
    base_size = float(preset["base_size"])
    ratio, ratio_power, taper = (float(preset[k]) for k in ("ratio", "ratio_power", "taper"))
    shape = preset["shape"]

    stems: list[Stem] = []
    heads, tails, radii, lengths, parents, blevel = [], [], [], [], [], []

    def add_stem(points, radius, level, parent, attach_bone, rest_taper):
        n_seg = len(points) - 1
        arm = level < n_arm
        seg_bone = np.full(n_seg, attach_bone, dtype=int)
        if arm:
            step = int(levels[level].get("bone_step", 1))
            prev = attach_bone
            for k in range(bones_per_stem(n_seg, step)):
                a, b = k * step, min((k + 1) * step, n_seg)
                z0, z1 = a / n_seg, b / n_seg
                heads.append(points[a])
                tails.append(points[b])
                radii.append(radius * (1 - rest_taper * 0.5 * (z0 + z1)))
                lengths.append(float(np.linalg.norm(points[b] - points[a])))
                parents.append(prev)
                blevel.append(level)
                prev = len(heads) - 1
                seg_bone[a:b] = prev
        stems.append(Stem(points, float(radius), rest_taper, level, parent, seg_bone, arm))
        return len(stems) - 1

    # Trunk (level 0).
    lv0 = levels[0]
    L0 = float(lv0["length"]) * scale
    r0 = L0 * ratio
    trunk_pts = _polyline(
        [0, 0, 0],
        [0, 0, 1],
        L0,
        int(lv0["curve_res"]),
        float(lv0.get("curve_deg", 0)),
        float(lv0.get("curve_v_deg", 0)),
        rng,
    )
    add_stem(trunk_pts, r0, 0, -1, -1, taper)

    # Split clones at the trunk's end (still level 0): a fork.
    split = preset.get("split") or {}
    n_clones = int(split.get("clones", 0))
    length_v = float(split.get("length_v", 0.0))
    clone_curve_v = float(split.get("curve_v_deg", lv0.get("curve_v_deg", 0)))
    if not 0.0 <= length_v < 1.0:
        raise PresetError(
            f"preset '{name}': split.length_v = {length_v} must lie in [0, 1) (a clone's "
            "length is scaled by 1 + U(-length_v, length_v), which must stay positive); "
            f"fix presets.{name}.split.length_v in config/trees.yaml"
        )
    if clone_curve_v < 0:
        raise PresetError(
            f"preset '{name}': split.curve_v_deg = {clone_curve_v} must be >= 0; "
            f"fix presets.{name}.split.curve_v_deg in config/trees.yaml"
        )
    if n_clones:
        # per-clone length variation from its own stream: every other draw is as without it
        crng = np.random.default_rng(np.random.SeedSequence([int(seed), _stable_id(name), 2]))
        clone_scale = 1.0 + crng.uniform(-1.0, 1.0, n_clones) * length_v
        tip_dir = _unit(trunk_pts[-1] - trunk_pts[-2])
        side = _rot(_perp(tip_dir), tip_dir, math.radians(float(split.get("azimuth_deg", 0.0))))
        tip_bone = int(stems[0].segment_bone[-1])
        for i in range(n_clones):
            phi = 2 * math.pi * i / n_clones
            axis = _unit(_rot(np.cross(tip_dir, side), tip_dir, phi))
            d = _rot(tip_dir, axis, math.radians(float(split["angle_deg"])))
            Lc = float(split["length"]) * L0 * clone_scale[i]
            # the same draws from the tree stream as without variation (curve_res normals per
            # clone), scaled by the clone's curve_v_deg
            pts = _polyline(
                trunk_pts[-1],
                d,
                Lc,
                int(split["curve_res"]),
                float(lv0.get("curve_deg", 0)),
                clone_curve_v,
                rng,
            )
            add_stem(
                pts,
                r0 * (1 - taper) * float(split.get("radius", 0.8)),
                0,
                0,
                tip_bone,
                float(split.get("taper", taper)),
            )

    # Child levels.
    for n in range(1, len(levels)):
        lv = levels[n]
        parent_ids = [i for i, s in enumerate(stems) if s.level == n - 1]
        starts = np.array(
            [
                base_size if (n == 1 and stems[i].parent == -1) else float(lv.get("start", 0.1))
                for i in parent_ids
            ]
        )
        weights = np.array([stems[i].length for i in parent_ids]) * (1 - starts)
        if "stems" not in lv:
            raise PresetError(
                f"preset '{name}': level {n} has no 'stems' (total child stems at that "
                f"level); add it to presets.{name}.levels[{n}] in config/trees.yaml"
            )
        counts = _apportion(int(lv["stems"]), weights)
        for pid, start, cnt in zip(parent_ids, starts, counts):
            ps = stems[pid]
            p_len = ps.length
            seg = np.diff(ps.points, axis=0)
            seg_len = np.linalg.norm(seg, axis=1)
            cum = np.concatenate([[0.0], np.cumsum(seg_len)]) / seg_len.sum()
            phi0 = rng.uniform(0, 2 * math.pi)
            end = float(lv.get("end", 1.0))  # children occupy [start, end] of the parent
            for i in range(cnt):
                z = start + (end - start) * (i + 0.5) / cnt
                z = float(
                    np.clip(
                        z + rng.uniform(-0.25, 0.25) * (end - start) / cnt, start, min(end, 0.999)
                    )
                )
                s = int(np.clip(np.searchsorted(cum, z, side="right") - 1, 0, len(seg) - 1))
                frac = (z - cum[s]) / (cum[s + 1] - cum[s])
                pos = ps.points[s] + frac * seg[s]
                d_par = _unit(seg[s])
                if n == 1:
                    L = (
                        L0
                        * float(lv["length"])
                        * shape_ratio(shape, (1 - z) / max(1 - start, 1e-9))
                        if ps.parent == -1
                        else p_len * float(lv["length"]) * shape_ratio(shape, 1 - z)
                    )
                else:
                    L = float(lv["length"]) * (p_len - 0.6 * z * p_len)
                L *= 1 + rng.uniform(-1, 1) * float(lv.get("length_v", 0.0))
                if L <= 1e-6:
                    raise PresetError(
                        f"preset '{name}': a level-{n} stem gets zero length "
                        f"(shape '{shape}' at position {z:.2f}); use another shape "
                        "or raise length"
                    )
                rot = (
                    phi0
                    + i * math.radians(float(lv["rotate_deg"]))
                    + math.radians(rng.normal(0, float(lv.get("rotate_v_deg", 0))))
                )
                u = _rot(_perp(d_par), d_par, rot)
                down = math.radians(
                    float(lv["down_angle_deg"])
                    + rng.normal(0, float(lv.get("down_angle_v_deg", 0)))
                )
                d = _unit(math.cos(down) * d_par + math.sin(down) * u)
                r_par_here = float(ps.radius_at(z))
                rp = float(lv.get("ratio_power", ratio_power))
                r = min(ps.radius * (L / p_len) ** rp, r_par_here)
                pts = _polyline(
                    pos,
                    d,
                    L,
                    int(lv["curve_res"]),
                    float(lv.get("curve_deg", 0)),
                    float(lv.get("curve_v_deg", 0)),
                    rng,
                )
                add_stem(pts, r, n, pid, int(ps.segment_bone[s]), taper)

    B = len(heads)
    want = int(preset["bones"])
    if B != want:
        per_level = []
        for n in range(n_arm):
            cnt = sum(1 for s in stems if s.level == n)
            per_level.append(
                f"level {n}: {cnt} stems -> {sum(1 for lv_ in blevel if lv_ == n)} bones"
            )
        raise PresetError(
            f"preset '{name}' yields {B} animated bones but declares bones: {want} "
            f"({'; '.join(per_level)}). Bones = sum over the {n_arm} armature level(s) of stems x "
            f"ceil(curve_res / bone_step); fix presets.{name} (stems, curve_res, bone_step, split, "
            "armature_levels) in config/trees.yaml"
        )
    return Skeleton(
        np.array(heads),
        np.array(tails),
        np.array(radii),
        np.array(lengths),
        np.array(parents, dtype=int),
        np.array(blevel, dtype=int),
        tuple(stems),
    )
