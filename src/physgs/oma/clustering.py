"""pyOMA-2's automatic mode selection (its clustering presets) on the poles SSI-cov found.

pyOMA-2's ``SSI.run_clustering`` reads the poles of its own ``run``; here the poles come from
[`ssi_poles`][physgs.oma.ssi.ssi_poles] (several records' Hankel matrices averaged, the
uncertainty propagated as in [`physgs.oma.uncertainty`][]), so they are handed to an ``SSI``
object as its result and its clustering runs on them unchanged: the presets after Reynders,
Neu, Kvaale and Dederichs (hard and soft criteria, a pre-clustering of stable from spurious
poles, then hierarchical or HDBSCAN clustering, then post-processing), each choosing its
representative pole or average. ``benchmarks/oma.py clustering`` measures them beside
[`group_stable_poles`][physgs.oma.ssi.group_stable_poles] (docs/blind.md).
"""

from __future__ import annotations

import numpy as np
from pyoma2.algorithms.data.result import SSIResult
from pyoma2.algorithms.data.run_params import Clustering
from pyoma2.algorithms.ssi import SSI

from physgs.oma.ssi import Modes, Poles, SSISettings, _normalise

#: pyOMA-2's clustering presets compared (``Clustering(quick=...)``)
PRESETS = ("Reynders", "Neu", "Kvaale", "Dederichs")


class ClusteringFailed(RuntimeError):
    """pyOMA-2's clustering stopped on a set of poles (too few clusters for its own steps)."""


def cluster_modes(p: Poles, s: SSISettings, preset: str, seed: int = 0) -> Modes:
    """The modes pyOMA-2's clustering preset ``preset`` selects from the poles.

    Args:
        p: the poles (all of them: the presets apply their own hard and soft criteria).
        s: the SSI settings (orders; ``err_fn``, ``err_xi``, ``err_phi`` are the presets' own).
        preset: one of ``PRESETS`` (Reynders, Neu, Kvaale, Dederichs).
        seed: numpy's global seed while it runs (its k-means and GMM pre-clustering draw from it).

    Returns:
        The [`Modes`][physgs.oma.ssi.Modes]: frequency, damping and shape of each cluster's
            representative, its standard deviations, and the cluster's size in ``n_stable``.

    Raises:
        ValueError: for a preset not in ``PRESETS``.
        ClusteringFailed: when pyOMA-2's clustering stops on these poles.
    """
    if preset not in PRESETS:
        raise ValueError(f"unknown clustering preset {preset!r}; one of {PRESETS}")
    alg = SSI(
        name="ssi",
        br=int(s.block_rows),
        ordmax=int(s.order_max),
        step=int(s.order_step),
        calc_unc=True,
        nb=int(s.nb),
    )
    alg.result = SSIResult(
        Fn_poles=p.freq,
        Xi_poles=p.xi,
        Phi_poles=p.phi,
        Lambds=p.lam,
        Fn_poles_std=p.freq_std,
        Xi_poles_std=p.xi_std,
        Phi_poles_std=np.full(p.phi.shape, np.nan),
    )
    alg.add_clustering(Clustering(name=preset, quick=preset))
    state = np.random.get_state()
    np.random.seed(int(seed))
    try:
        alg.run_clustering(name=preset)
    except (ValueError, IndexError) as e:  # e.g. its k-means of cluster sizes on one cluster
        raise ClusteringFailed(f"pyOMA-2's {preset} clustering failed on these poles: {e}") from e
    finally:
        np.random.set_state(state)
    r = alg.result.clustering_results[preset]
    f = np.atleast_1d(np.asarray(r.Fn, np.float64))
    order = np.argsort(f)
    C = p.phi.shape[-1]
    shape = np.asarray(r.Phi, np.complex128).T.reshape(-1, C) if f.size else np.zeros((0, C))
    labels = np.asarray(r.labels)
    sizes = np.array([int((labels == k).sum()) for k in sorted(set(labels) - {-1})], np.int64)
    sizes = sizes if sizes.size == f.size else np.full(f.size, -1, np.int64)
    return Modes(
        f[order],
        np.atleast_1d(np.asarray(r.Xi, np.float64))[order],
        np.stack([_normalise(v) for v in shape[order]]) if f.size else shape,
        sizes[order],
        np.full(f.size, np.nan),
        p.stabilisation(),
        np.atleast_1d(np.asarray(r.Fn_std, np.float64))[order],
        np.atleast_1d(np.asarray(r.Xi_std, np.float64))[order],
    )
