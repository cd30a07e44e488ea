"""Tree mesh: a capped tube per stem (rings per segment) and leaf quads on the terminal level,
every vertex bound to exactly one bone (rigid skinning, no blending).

Geometry on levels below the armature is skinned to the nearest ancestor bone (the bone of the
parent stem where it attaches), so no generated vertex is left unskinned.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physgs.testbed.weberpenn import Skeleton, Stem

BARK = np.array([0.42, 0.30, 0.20])
LEAF = np.array([0.28, 0.52, 0.18])


class MeshBudgetError(ValueError):
    """A vertex target the tree's stems cannot fit; the message names the minimum."""


@dataclass(frozen=True)
class TreeMesh:
    """vertices [N, 3] (m), faces [M, 3] int, vertex_bone [N] int, vertex_colors [N, 3] in [0, 1],
    stem_tip_vertex [S_stems] index of each stem's tip-cap vertex, sides / rings_per_segment used."""

    vertices: np.ndarray
    faces: np.ndarray
    vertex_bone: np.ndarray
    vertex_colors: np.ndarray
    stem_tip_vertex: np.ndarray
    sides: int
    rings_per_segment: int
    n_leaves: int

    def to_trimesh(self) -> "trimesh.Trimesh":  # noqa: F821
        """The mesh as a ``trimesh.Trimesh`` (vertex colours kept, vertices not merged).

        Returns:
            A new ``trimesh.Trimesh`` over the same vertices [N, 3] (m) and faces [M, 3].
        """
        import trimesh  # here: ~1 s of start-up that jobs reading a dataset never need

        return trimesh.Trimesh(
            self.vertices, self.faces, vertex_colors=self.vertex_colors, process=False
        )


def tube_vertex_count(stems: tuple[Stem, ...], sides: int, rings_per_segment: int) -> int:
    """Vertices of all capped tubes: per stem (segments * rings + 1) rings of `sides`, + 2 caps.

    Args:
        stems: the skeleton's stems (their polylines' segment counts are used).
        sides: vertices per ring.
        rings_per_segment: rings per polyline segment.

    Returns:
        The vertex count of all tubes, caps included.
    """
    return sum((len(s.points) - 1) * rings_per_segment * sides + sides + 2 for s in stems)


def choose_resolution(stems, target_tube: int) -> tuple[int, int]:
    """(sides, rings_per_segment) whose tube count is the largest not above target_tube,
    preferring rounder tubes (more sides) on ties within 2%.

    Args:
        stems (tuple[Stem, ...]): the skeleton's stems.
        target_tube: the tube vertex budget.

    Returns:
        ``(sides, rings_per_segment)``, each in [3, 16] and [1, 16].

    Raises:
        MeshBudgetError: when even 3 sides and 1 ring per segment exceed ``target_tube``.
    """
    best = None
    for sides in range(3, 17):
        for rings in range(1, 17):
            n = tube_vertex_count(stems, sides, rings)
            if n > target_tube:
                continue
            key = (round(n / max(target_tube, 1) * 50), -abs(sides - 8))
            if best is None or key > best[0]:
                best = (key, sides, rings)
    if best is None:
        need = tube_vertex_count(stems, 3, 1)
        raise MeshBudgetError(
            f"vertex target too small: the tubes alone need at least {need} vertices "
            f"(3 sides, 1 ring per segment) for {len(stems)} stems; raise testbed.vertices for "
            "this tree (or lower the leaf fraction) in config/trees.yaml"
        )
    return best[1], best[2]


def _frames(points: np.ndarray, n_rings: int, rings_per_segment: int):
    """Ring centres, stem directions and a parallel-transported normal per ring."""
    seg = np.diff(points, axis=0)
    S = len(seg)
    j = np.arange(n_rings)
    s = np.minimum(j // rings_per_segment, S - 1)
    frac = (j - s * rings_per_segment) / rings_per_segment
    centres = points[s] + frac[:, None] * seg[s]
    dirs = seg[s] / np.linalg.norm(seg[s], axis=1, keepdims=True)
    normals = np.empty_like(dirs)
    n = np.cross(dirs[0], [0.0, 0.0, 1.0])
    if np.linalg.norm(n) < 1e-6:
        n = np.cross(dirs[0], [1.0, 0.0, 0.0])
    for k in range(n_rings):  # parallel transport avoids twisting the tube
        n = n - (n @ dirs[k]) * dirs[k]
        n /= np.linalg.norm(n)
        normals[k] = n
    return centres, dirs, normals, s


def mesh_vertex_count(skeleton: Skeleton, *, target_vertices: int, leaf_fraction: float) -> int:
    """The vertex count [`build_mesh`][physgs.testbed.mesh.build_mesh] gives, without building it:
    the tubes at the chosen resolution, plus four vertices per leaf quad filling the rest of
    the budget. It can fall short of ``target_vertices`` (the tubes' count is the largest the
    resolutions reach within their budget; leaves come in fours).

    Args:
        skeleton: the tree's bones and stems.
        target_vertices: the vertex budget (tubes and leaves together).
        leaf_fraction: share of the budget given to leaves.

    Returns:
        The mesh's vertex count (= the Gaussians the models place).

    Raises:
        MeshBudgetError: when the budget cannot hold the tubes.
    """
    tube_budget = int(round(target_vertices * (1.0 - leaf_fraction)))
    n_tube = tube_vertex_count(skeleton.stems, *choose_resolution(skeleton.stems, tube_budget))
    n_leaves = max(0, (target_vertices - n_tube) // 4) if leaf_fraction > 0 else 0
    return n_tube + 4 * n_leaves


def build_mesh(
    skeleton: Skeleton,
    *,
    target_vertices: int,
    leaf_fraction: float,
    leaf_scale: float,
    seed_seq: np.random.SeedSequence,
) -> TreeMesh:
    """Mesh a skeleton near ``target_vertices`` vertices.

    Colours vary mildly per vertex (seeded).

    Args:
        skeleton: the tree's bones and stems.
        target_vertices: the vertex budget (tubes and leaves together).
        leaf_fraction: share of the vertex budget given to leaf quads (0 = no leaves) on the
            deepest stem level.
        leaf_scale: leaf side, m (varied by a factor in [0.8, 1.2]).
        seed_seq: seeds the colours and leaf placement.

    Returns:
        The [`TreeMesh`][physgs.testbed.mesh.TreeMesh]: capped tubes, then four vertices per leaf.

    Raises:
        MeshBudgetError: when the budget cannot hold the tubes.
    """
    rng = np.random.default_rng(seed_seq)
    stems = skeleton.stems
    tube_budget = int(round(target_vertices * (1.0 - leaf_fraction)))
    sides, rps = choose_resolution(stems, tube_budget)

    verts, faces, vbone, tips = [], [], [], []
    n0 = 0
    ang = 2 * np.pi * np.arange(sides) / sides
    for st in stems:
        S = len(st.points) - 1
        n_rings = S * rps + 1
        c, d, nrm, seg_idx = _frames(st.points, n_rings, rps)
        b = np.cross(d, nrm)
        r = st.radius_at(np.arange(n_rings) / (n_rings - 1))
        r = np.maximum(r, 0.03 * st.radius)  # keep a thin tip ring instead of a degenerate one
        ring = c[:, None, :] + r[:, None, None] * (
            np.cos(ang)[None, :, None] * nrm[:, None, :]
            + np.sin(ang)[None, :, None] * b[:, None, :]
        )
        verts.append(ring.reshape(-1, 3))
        vbone.append(np.repeat(st.segment_bone[seg_idx], sides))
        # side quads between consecutive rings
        k = np.arange(sides)
        for i in range(n_rings - 1):
            a0, a1 = n0 + i * sides + k, n0 + (i + 1) * sides + k
            b0, b1 = n0 + i * sides + (k + 1) % sides, n0 + (i + 1) * sides + (k + 1) % sides
            faces.append(np.stack([a0, b0, a1], 1))
            faces.append(np.stack([b0, b1, a1], 1))
        base, tip = n0 + n_rings * sides, n0 + n_rings * sides + 1
        verts.append(np.stack([st.points[0], st.points[-1]]))
        vbone.append(np.array([st.segment_bone[0], st.segment_bone[-1]]))
        faces.append(np.stack([np.full(sides, base), n0 + (k + 1) % sides, n0 + k], 1))
        last = n0 + (n_rings - 1) * sides
        faces.append(np.stack([np.full(sides, tip), last + k, last + (k + 1) % sides], 1))
        tips.append(tip)
        n0 = tip + 1

    n_tube = n0
    bark = np.clip(BARK + rng.normal(0, 0.03, (n_tube, 3)), 0, 1)
    colors = [bark]
    n_leaves = 0
    if leaf_fraction > 0:
        n_leaves = max(0, (target_vertices - n_tube) // 4)
        terminal = [s for s in stems if s.level == max(t.level for t in stems)]
        lengths = np.array([s.length for s in terminal])
        share = n_leaves * lengths / lengths.sum()
        per = np.floor(share).astype(int)
        per[np.argsort(-(share - per), kind="stable")[: n_leaves - per.sum()]] += 1
        quad = np.array([[-0.5, 0.0], [0.5, 0.0], [0.5, 1.0], [-0.5, 1.0]])
        for st, cnt in zip(terminal, per):
            seg = np.diff(st.points, axis=0)
            S = len(seg)
            for _ in range(cnt):
                z = rng.uniform(0.25, 1.0)
                s = min(int(z * S), S - 1)
                frac = z * S - s
                p = st.points[s] + frac * seg[s]
                d = seg[s] / np.linalg.norm(seg[s])
                out = rng.normal(size=3)
                out -= (out @ d) * d
                out /= np.linalg.norm(out)
                side = np.cross(d, out)
                tilt = rng.uniform(-0.6, 0.6)
                up = np.cos(tilt) * out + np.sin(tilt) * d  # leaf blade points away from the stem
                sz = leaf_scale * rng.uniform(0.8, 1.2)
                q = p + sz * (quad[:, :1] * side + quad[:, 1:] * up)
                verts.append(q)
                vbone.append(np.full(4, st.segment_bone[s]))
                faces.append(np.array([[n0, n0 + 1, n0 + 2], [n0, n0 + 2, n0 + 3]]))
                n0 += 4
        leaf_col = np.clip(LEAF + rng.normal(0, 0.04, (n0 - n_tube, 3)), 0, 1)
        colors.append(leaf_col)
    V = np.concatenate(verts)
    vb = np.concatenate(vbone).astype(np.int64)
    if (vb < 0).any():
        raise AssertionError("unskinned vertex: a stem has no ancestor bone")  # programming error
    return TreeMesh(
        V,
        np.concatenate(faces).astype(np.int64),
        vb,
        np.concatenate(colors),
        np.array(tips, dtype=np.int64),
        sides,
        rps,
        n_leaves,
    )
