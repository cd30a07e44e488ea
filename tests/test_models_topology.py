"""Topology-aware parts (physgs.models.topology) on synthetic trees whose branches are known."""

import numpy as np
import pytest

from physgs.models.chain import depth_levels
from physgs.models.topology import (
    join_components,
    neighbour_graph,
    part_depth,
    topology_parts,
)


def tube(a, b, radius, rings, per_ring, rng):
    """Points [rings * per_ring, 3] on a tube from a to b (rings evenly along it)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    ax = (b - a) / np.linalg.norm(b - a)
    u = np.cross(ax, [1.0, 0.0, 0.0])
    if np.linalg.norm(u) < 1e-6:
        u = np.cross(ax, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(ax, u)
    s = np.linspace(0, 1, rings)[:, None, None]
    phi = np.linspace(0, 2 * np.pi, per_ring, endpoint=False)[None, :, None]
    pts = a + s * (b - a) + radius * (np.cos(phi) * u + np.sin(phi) * v)
    return (pts + 1e-4 * rng.standard_normal(pts.shape)).reshape(-1, 3)


def y_tree(seed=0):
    """A trunk (z 0..1) forking into two branches (left, right); branch id per point [N]
    (0 trunk, 1 left, 2 right)."""
    rng = np.random.default_rng(seed)
    trunk = tube([0, 0, 0], [0, 0, 1], 0.03, 40, 8, rng)
    left = tube([0, 0, 1.02], [-0.7, 0, 1.7], 0.02, 40, 8, rng)
    right = tube([0, 0, 1.02], [0.7, 0, 1.7], 0.02, 40, 8, rng)
    xyz = np.concatenate([trunk, left, right])
    branch = np.repeat([0, 1, 2], [len(trunk), len(left), len(right)])
    order = rng.permutation(len(xyz))  # a seeded random order, as observed.npz stores them
    return xyz[order], branch[order]


@pytest.mark.parametrize("K", [3, 6, 12])
def test_parts_follow_the_branches_and_parents_come_first(K):
    xyz, branch = y_tree()
    tp = topology_parts(xyz, K)
    assert tp.labels.shape == (len(xyz),) and set(np.unique(tp.labels)) == set(range(K))
    assert tp.parent[0] == -1 and np.all(tp.parent[1:] < np.arange(1, K))  # a tree, no cycle
    assert tp.root == int(np.argmin(xyz[:, 2]))
    # the cut follows the topology: a part holds one branch, or both only right at the fork
    # (the first slab above it, here under 0.15 m of the 1 m branches)
    for p in range(K):
        m = tp.labels == p
        if len(set(branch[m]) - {0}) > 1:
            assert np.all(xyz[m & (branch > 0), 2] < 1.02 + 0.15), p
    # every parent sits nearer the root than its child (entry geodesic distance)
    entry = np.array([tp.geodesic[tp.labels == p].min() for p in range(K)])
    assert np.all(entry[tp.parent[1:]] < entry[1:])
    # every part is connected in the neighbour graph
    import scipy.sparse.csgraph as csgraph

    g = neighbour_graph(xyz)
    for p in range(K):
        idx = np.nonzero(tp.labels == p)[0]
        n, _ = csgraph.connected_components(g[idx][:, idx], directed=False)
        assert n == 1, p


def test_the_fork_is_a_branching_point_with_two_children():
    xyz, branch = y_tree()
    tp = topology_parts(xyz, 6)
    # the part holding the fork's trunk end has children on both branches
    top = np.nonzero(branch == 0)[0][np.argmax(xyz[branch == 0, 2])]
    fork = tp.labels[top]
    kids = np.nonzero(tp.parent == fork)[0]
    sides = {int(np.bincount(branch[tp.labels == k]).argmax()) for k in kids}
    assert sides == {1, 2}


def test_pivot_sits_at_the_joint_on_the_stem_axis():
    rng = np.random.default_rng(1)
    xyz = tube([0, 0, 0], [0, 0, 1], 0.03, 41, 8, rng)
    tp = topology_parts(xyz, 2)
    # the cut: between the top of part 0 and the bottom of part 1 (a slab may split a ring:
    # the two may overlap by less than a ring spacing, 0.025 m)
    z0, z1 = xyz[tp.labels == 0, 2].max(), xyz[tp.labels == 1, 2].min()
    assert abs(z0 - z1) < 0.025
    assert abs(tp.pivots[1, 2] - 0.5 * (z0 + z1)) < 0.025
    assert np.hypot(*tp.pivots[1, :2]) < 2e-3  # on the axis, not on the surface (r = 0.03)
    assert tp.pivots[0, 2] < 0.05 and np.hypot(*tp.pivots[0, :2]) < 2e-3  # the base ring


def test_disconnected_graph_is_joined_at_the_nearest_pair():
    rng = np.random.default_rng(2)
    main = tube([0, 0, 0], [0, 0, 1], 0.03, 30, 8, rng)
    island = tube([0.5, 0, 0.6], [0.9, 0, 0.9], 0.02, 10, 8, rng)  # 0.47 m from the trunk
    xyz = np.concatenate([main, island])
    root = int(np.argmin(xyz[:, 2]))
    g, joins = join_components(xyz, neighbour_graph(xyz), root)
    assert len(joins) == 1
    i, j, d = joins[0]
    # oracle: the brute-force closest pair between the two sets
    D = np.linalg.norm(main[:, None] - island[None], axis=-1)
    a, b = np.unravel_index(np.argmin(D), D.shape)
    assert (i, j) == (a, len(main) + b) and d == pytest.approx(D[a, b])
    tp = topology_parts(xyz, 4)
    island_parts = set(tp.labels[len(main) :])
    # the island's parts hang off the trunk's parts, nearer the root
    for p in island_parts:
        assert tp.parent[p] < p


def test_k_too_large_is_refused_naming_the_maximum():
    rng = np.random.default_rng(3)
    xyz = tube([0, 0, 0], [0, 0, 1], 0.03, 10, 6, rng)
    with pytest.raises(ValueError, match=r"K = 500 .*at most \d+"):
        topology_parts(xyz, 500)
    with pytest.raises(ValueError, match="K must be >= 1"):
        topology_parts(xyz, 0)


def test_parent_arrays_with_a_cycle_are_refused():
    with pytest.raises(ValueError, match="parents first"):
        depth_levels([-1, 2, 1])  # 1 -> 2 -> 1
    with pytest.raises(ValueError, match="parents first"):
        part_depth([0, -1])  # the root must be part 0
    assert list(part_depth([-1, 0, 1, 0])) == [0, 1, 2, 1]


def test_deterministic_and_order_free():
    xyz, _ = y_tree(seed=4)
    a = topology_parts(xyz, 5)
    b = topology_parts(xyz.copy(), 5)
    assert np.array_equal(a.labels, b.labels) and np.array_equal(a.parent, b.parent)
