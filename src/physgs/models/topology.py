"""Topology-aware rigid parts: cut the canonical Gaussians along the tree, give each a parent.

Reads the canonical positions only (``observed.npz``'s ``canonical_xyz``; never ``truth.npz``).

Method (pure functions over arrays; deterministic, no random source):

1. Neighbour graph: each Gaussian joined to its ``knn`` nearest others (Euclidean edge lengths,
   symmetrised), ``neighbour_graph``.
2. Join rule for a disconnected graph (``join_components``): the component holding the root is
   the main one; repeatedly the component nearest to the main one (smallest Euclidean gap
   between any of its points and any main point) is joined to it by one edge over that gap,
   until one component remains (Prim's rule over components, so a far island is attached via a
   nearer one rather than by a long edge). On the testbed trees the islands are child stems
   whose tube starts inside the parent's tube: the shortest gap is exactly their joint.
3. Root: the lowest Gaussian (smallest z), the trunk's lowest end. Geodesic distance from it
   along the graph (Dijkstra, scipy.sparse.csgraph), with the predecessor of each point on its
   shortest path.
4. Cut: geodesic distance into ``n_bins`` equal slabs; each connected piece of a slab (edges
   inside the slab only) is a segment. A slab crossing a fork falls into one piece per branch,
   so segments are cut along the distance and at branching points. The number of slabs is
   the smallest power-of-two multiple of 4 K that gives at least K segments (over-segment: thin
   slabs leave only a thin piece holding a fork, so the branches part soon after it), capped
   where a slab grows thinner than half the graph's median edge (thinner slabs hold no edge
   along the distance and only shred rings into single points); no K segments at the cap
   raises (K too large to cut). Half, not more: on the leafy trees the median edge is a leaf
   spacing (0.07-0.09 m), and a cap at two edges (about 30 slabs) could not cut K = 96 on dense.
5. Merge down to exactly K: repeatedly the smallest segment merges into its parent (its
   children become the parent's; if the root is the smallest, its smallest child merges into
   it), first only along stems (parent with no other child), across a fork only when no such
   pair is left. This removes first the slivers a slab leaves at a fork (into the stem below),
   keeps sibling branches apart, and balances part sizes (what the photometric loss weighs).
6. Parent of a segment: the segment holding the geodesic predecessor of the segment's nearest
   point to the root. That predecessor is strictly nearer the root and lies in an earlier slab
   (a predecessor in the same slab would be a neighbour inside the slab, i.e. in the same
   segment, with smaller distance), so parent links always point to a strictly smaller entry
   distance: no cycle can arise, and numbering parts by entry distance puts every parent before
   its children (``parent[p] < p``; the root is part 0 with parent -1). Merging keeps this.
7. Pivot of a part: the mean of the midpoints of the graph edges joining it to its parent (the
   ring where it meets its parent, whose centre lies on the stem's axis, where a bone's head
   is). The root's pivot: the centroid of its Gaussians in the lowest tenth of its height (the
   trunk's base rings).

Settings (chosen on the canonical positions, what every method sees):
- ``knn = 10``: on the sparse tree's tubes (many vertices per ring, rings further apart than
  the vertices on a ring) k = 8 links only within rings (185 components), k = 10 and 16 link
  successive rings (3 components, the separate child stems, joined by the rule above); a
  larger k lengthens edges (median edge 0.021 at k = 10, 0.059 at 16 on the sparse tree) and so
  short-circuits neighbouring branches. Medium and dense are nearly connected from k = 8.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# scipy (~0.25 CPU-s of start-up) is imported by the functions that build a topology: every job
# that loads a trained prior imports this module (ours, the chained prior) but builds nothing

#: Default neighbours per Gaussian of the graph (see module docstring for why).
KNN = 10
#: Slabs are no thinner than this many median graph edges (see the module docstring, step 4).
MIN_SLAB_EDGES = 0.5


@dataclass(frozen=True)
class TopologyParts:
    """A segmentation into K parts with a parent tree.

    labels [N] int64 in [0, K); parent [K] int64 (-1 for the root, part 0; parent[p] < p);
    pivots [K, 3] world units (the joint with the parent; the base ring for the root);
    geodesic [N] world units (distance from the root along the graph); root: index of the
    root Gaussian.
    """

    labels: np.ndarray
    parent: np.ndarray
    pivots: np.ndarray
    geodesic: np.ndarray
    root: int


def _check_xyz(xyz) -> np.ndarray:
    xyz = np.asarray(xyz, dtype=np.float64)
    if xyz.ndim != 2 or xyz.shape[1] != 3 or xyz.shape[0] < 2:
        raise ValueError(f"canonical positions must be [N >= 2, 3]; got shape {xyz.shape}")
    if not np.isfinite(xyz).all():
        raise ValueError("canonical positions contain NaN or inf; regenerate the testbed dataset")
    return xyz


def neighbour_graph(xyz: np.ndarray, knn: int = KNN):
    """Symmetric kNN graph (scipy CSR [N, N]); edge weight = Euclidean length (world units).

    Coincident points get a tiny positive weight, so a stored edge is never read as absent.

    Args:
        xyz: [N, 3] positions, world units.
        knn: neighbours per point, in [1, N - 1].

    Returns:
        (scipy.sparse.csr_matrix): [N, N] symmetric edge lengths, world units.

    Raises:
        ValueError: for ``knn`` outside [1, N - 1] or positions that are not [N, 3] and finite.
    """
    xyz = _check_xyz(xyz)
    n = xyz.shape[0]
    if not 1 <= knn < n:
        raise ValueError(f"models.topology.knn must lie in [1, N - 1 = {n - 1}], got {knn}")
    import scipy.sparse
    import scipy.spatial

    d, j = scipy.spatial.cKDTree(xyz).query(xyz, k=knn + 1)
    rows = np.repeat(np.arange(n), knn)
    w = np.maximum(d[:, 1:].ravel(), 1e-12)
    g = scipy.sparse.csr_matrix((w, (rows, j[:, 1:].ravel())), shape=(n, n))
    return g.maximum(g.T).tocsr()


def join_components(xyz: np.ndarray, graph, root: int):
    """The graph with every component joined to the root's by the rule of the module docstring.

    Args:
        xyz: [N, 3] positions, world units.
        graph (scipy.sparse.csr_matrix): [N, N] symmetric kNN graph, edge lengths in world units.
        root: index of the root point.

    Returns:
        (tuple[scipy.sparse.csr_matrix, list]): ``(graph, joins)``: the connected graph CSR
            [N, N] and the ``(i, j, length)`` edges added, i in the main part (the input graph
            and no joins when it is connected already).
    """
    xyz = _check_xyz(xyz)
    import scipy.sparse
    import scipy.spatial
    from scipy.sparse import csgraph

    n_comp, comp = csgraph.connected_components(graph, directed=False)
    joins = []
    in_main = comp == comp[root]
    others = {c: np.nonzero(comp == c)[0] for c in range(n_comp) if c != comp[root]}
    while others:
        main_idx = np.nonzero(in_main)[0]
        tree = scipy.spatial.cKDTree(xyz[main_idx])
        best = None
        for c, idx in others.items():
            d, k = tree.query(xyz[idx])
            a = int(np.argmin(d))
            cand = (float(d[a]), c, int(main_idx[k[a]]), int(idx[a]))
            if best is None or cand < best:
                best = cand
        dist, c, i, j = best
        joins.append((i, j, dist))
        in_main[others.pop(c)] = True
    if not joins:
        return graph, joins
    i, j, w = (np.array(v) for v in zip(*joins))
    w = np.maximum(w, 1e-12)
    n = graph.shape[0]
    extra = scipy.sparse.csr_matrix((w, (i, j)), shape=(n, n))
    return graph.maximum(extra).maximum(extra.T).tocsr(), joins


def geodesic_from_root(graph, root: int) -> tuple[np.ndarray, np.ndarray]:
    """(distance [N] world units, predecessor [N] int, -9999 at the root) along a connected graph.

    Args:
        graph (scipy.sparse.csr_matrix): [N, N] connected graph, edge lengths in world units.
        root: index of the root point.

    Returns:
        ``(distance, predecessor)``: distance [N] world units, predecessor [N] int (-9999 at the
            root).

    Raises:
        ValueError: when a point is unreachable (the graph is not connected).
    """
    from scipy.sparse import csgraph

    dist, pred = csgraph.dijkstra(graph, directed=False, indices=root, return_predecessors=True)
    if not np.isfinite(dist).all():
        raise ValueError("neighbour graph is not connected after joining; this is a bug")
    return dist, pred


def slab_segments(graph, dist: np.ndarray, n_bins: int) -> np.ndarray:
    """Segment id [N] per point: connected pieces of each of ``n_bins`` equal geodesic slabs.

    Ids are arbitrary (not ordered); see ``segment_tree`` for the parent links.

    Args:
        graph (scipy.sparse.csr_matrix): [N, N] connected graph.
        dist: [N] geodesic distance from the root, world units.
        n_bins: number of slabs over [0, max dist].

    Returns:
        [N] int64 segment ids.
    """
    top = float(dist.max())
    slab = np.zeros(len(dist), dtype=np.int64)
    if top > 0:
        slab = np.minimum((dist / top * n_bins).astype(np.int64), n_bins - 1)
    coo = graph.tocoo()
    keep = slab[coo.row] == slab[coo.col]
    inside = graph.__class__((coo.data[keep], (coo.row[keep], coo.col[keep])), shape=graph.shape)
    from scipy.sparse import csgraph

    _, seg = csgraph.connected_components(inside, directed=False)
    return seg.astype(np.int64)


def segment_tree(seg: np.ndarray, dist: np.ndarray, pred: np.ndarray, root: int):
    """Parent of each segment: the segment of the geodesic predecessor of its entry point.

    Args:
        seg: [N] segment ids in [0, S).
        dist: [N] geodesic distance from the root, world units.
        pred: [N] geodesic predecessor of each point.
        root: index of the root point.

    Returns:
        (tuple[np.ndarray, np.ndarray]): ``(parent, entry)``: parent [S] int64, -1 for the
            root's segment; entry [S] entry distances, world units.

    Raises:
        ValueError: when the ids are not contiguous in [0, S).
        AssertionError: if any link does not point strictly nearer the root.
    """
    S = int(seg.max()) + 1
    order = np.lexsort((np.arange(len(dist)), dist))  # nearest the root first, ties by index
    ids, first = np.unique(seg[order], return_index=True)
    if len(ids) != S:
        raise ValueError(f"segment ids must be contiguous in [0, {S}); got {len(ids)} ids")
    entry_pt = order[first]  # [S] each segment's point nearest the root
    parent = np.full(S, -1, dtype=np.int64)
    for s in range(S):
        e = entry_pt[s]
        if e == root:
            continue
        parent[s] = seg[pred[e]]
    entry = dist[entry_pt]
    nonroot = parent >= 0
    if (nonroot.sum() != S - 1) or np.any(entry[parent[nonroot]] >= entry[nonroot]):
        raise AssertionError("segment parents must lie strictly nearer the root")
    return parent, entry


def merge_to_k(seg: np.ndarray, parent: np.ndarray, k: int) -> np.ndarray:
    """Merge segments into their parents until k remain: each time the smallest segment whose
    parent has no other child merges into it (ties: the lowest id); only when none is left, the
    smallest of all; if the root is the smallest, its smallest child merges into it.

    Args:
        seg: [N] segment ids in [0, S).
        parent: [S] each segment's parent, -1 for the root.
        k: the number of segments to keep.

    Returns:
        [N] merged ids (the parent's id survives; not renumbered).
    """
    seg = seg.copy()
    parent = parent.copy()
    size = np.bincount(seg, minlength=len(parent)).astype(np.int64)
    alive = np.ones(len(parent), dtype=bool)
    while alive.sum() > k:
        c = np.nonzero(alive & (parent >= 0))[0]
        root = int(np.nonzero(alive & (parent < 0))[0][0])
        if size[root] < size[c].min():  # the root is the smallest: it takes its smallest child
            c = c[parent[c] == root]
        kids = np.bincount(parent[c], minlength=len(parent))  # alive children per segment
        across = kids[parent[c]] > 1  # merging c would join it to a sibling's stem
        child = int(c[np.lexsort((c, size[c], across))[0]])  # ties: the lowest id
        p = int(parent[child])
        seg[seg == child] = p
        size[p] += size[child]
        parent[parent == child] = p
        alive[child] = False
    return seg


def pivots_of(xyz, graph, labels, parent, root_fraction: float = 0.1) -> np.ndarray:
    """[K, 3] pivots: mean midpoint of the edges joining each part to its parent; the root's,
    the centroid of its Gaussians in the lowest ``root_fraction`` of its height (whole rings at
    the trunk's base: a fraction of the points nearest the root would take a one-sided patch of
    the base ring, off the axis).

    Args:
        xyz (np.ndarray): [N, 3] positions, world units.
        graph (scipy.sparse.csr_matrix): [N, N] the neighbour graph.
        labels (np.ndarray): [N] part of each point, in [0, K), parents numbered first.
        parent (np.ndarray): [K] each part's parent, -1 for part 0.
        root_fraction: share of the root part's height whose points give its pivot.

    Returns:
        [K, 3] pivots, world units.
    """
    K = len(parent)
    coo = graph.tocoo()
    a, b = labels[coo.row], labels[coo.col]
    piv = np.zeros((K, 3))
    mid = 0.5 * (xyz[coo.row] + xyz[coo.col])
    for p in range(1, K):
        m = (a == p) & (b == parent[p])
        piv[p] = mid[m].mean(0)
    z = xyz[labels == 0]
    lo, hi = z[:, 2].min(), z[:, 2].max()
    piv[0] = z[z[:, 2] <= lo + root_fraction * (hi - lo)].mean(0)
    return piv


def topology_parts(xyz: np.ndarray, k: int, knn: int = KNN) -> TopologyParts:
    """K topology-aware parts of the canonical positions xyz [N, 3] (see the module docstring).

    Args:
        xyz: [N, 3] canonical positions, world units.
        k: number of parts K.
        knn: neighbours per point of the graph.

    Returns:
        The [`TopologyParts`][physgs.models.topology.TopologyParts], parents numbered first.

    Raises:
        ValueError: if K < 1, or if fewer than K parts can be cut (naming the maximum).
    """
    xyz = _check_xyz(xyz)
    n = xyz.shape[0]
    if k < 1:
        raise ValueError(f"number of parts K must be >= 1, got {k} (config models.configs)")
    root = int(np.argmin(xyz[:, 2]))
    graph, _ = join_components(xyz, neighbour_graph(xyz, knn), root)
    dist, pred = geodesic_from_root(graph, root)
    # The finest slab still cuts across a stem: about MIN_SLAB_EDGES median edges thick.
    max_bins = max(1, int(dist.max() / (MIN_SLAB_EDGES * float(np.median(graph.data)))))
    n_bins = min(4 * k, max_bins)
    while True:
        seg = slab_segments(graph, dist, n_bins)
        if seg.max() + 1 >= k or n_bins == max_bins:
            break
        n_bins = min(2 * n_bins, max_bins)
    n_seg = int(seg.max()) + 1
    if n_seg < k:
        raise ValueError(
            f"K = {k} parts is more than the topology-aware segmentation can cut from these "
            f"{n} Gaussians: at most {n_seg} (slabs no thinner than {MIN_SLAB_EDGES} graph "
            f"edges); lower K in models.configs or use k-means parts"
        )
    parent, _ = segment_tree(seg, dist, pred, root)
    seg = merge_to_k(seg, parent, k)
    # renumber by entry distance (then id, for ties): parents come before their children
    ids = np.unique(seg)
    entry = np.array([dist[seg == s].min() for s in ids])
    order = ids[np.lexsort((ids, entry))]
    rank = np.full(int(seg.max()) + 1, -1)
    rank[order] = np.arange(k)
    labels = rank[seg].astype(np.int64)
    par_parent, _ = segment_tree(labels, dist, pred, root)
    if par_parent[0] != -1 or np.any(par_parent[1:] >= np.arange(1, k)):
        raise AssertionError("topology parts must be numbered parents first")
    pivots = pivots_of(xyz, graph, labels, par_parent)
    return TopologyParts(labels, par_parent, pivots, dist, root)


def part_depth(parent: np.ndarray) -> np.ndarray:
    """Depth [K] of each part (root 0) for parents numbered first (parent[p] < p).

    Args:
        parent: [K] each part's parent, -1 for part 0.

    Returns:
        [K] int64 depths.

    Raises:
        ValueError: when parents are not numbered first (parent[0] = -1, 0 <= parent[p] < p).
    """
    parent = np.asarray(parent, dtype=np.int64)
    K = len(parent)
    if K == 0 or parent[0] != -1 or np.any(parent[1:] < 0) or np.any(parent[1:] >= np.arange(1, K)):
        raise ValueError(
            "part parents must be numbered parents first: parent[0] = -1 and 0 <= parent[p] < p"
        )
    depth = np.zeros(K, dtype=np.int64)
    for p in range(1, K):
        depth[p] = depth[parent[p]] + 1
    return depth
