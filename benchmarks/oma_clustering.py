"""pyOMA-2's clustering presets beside the hand-written grouping of stable poles.

    python benchmarks/oma_clustering.py [results/testbed/sparse results/testbed/medium ...]
        [--profile default] [--oracle-seeds 4]

Two measures, neither reading a tree's truth:

* the ``scipy.signal.lsim`` oracle of ``tests/test_oma_ssi.py`` (three modes 0.5, 0.9, 1.4 Hz,
  zeta 0.03, 0.05, 0.08, six channels, 200 s records at 24 Hz, block rows 20, orders to 40): per
  method, the true modes found (a mode within four record-length sigmas of the truth in
  frequency, ``tests/test_oma_ssi.tolerances``), the modes it reports that match none
  (spurious), over ``--oracle-seeds`` independent records;
* each testbed's training window: the three winds' records identified one by one (the same
  cells and principal components for all three, the config's SSI settings), and a mode counts
  as reproduced when both other records hold one within its half-power half-bandwidth
  ([`reproduced_modes`][physgs.oma.agreement.reproduced_modes], as
  ``benchmarks/oma_settings.py``).

Per method: ``grouping`` ([`group_stable_poles`][physgs.oma.ssi.group_stable_poles]) and each of
[`PRESETS`][physgs.oma.clustering.PRESETS]; the same poles feed all of them.
"""

from __future__ import annotations

import argparse
import logging
import sys
import warnings
from pathlib import Path

import numpy as np

import physgs.config
from physgs.oma.agreement import reproduced_modes
from physgs.oma.clustering import PRESETS, ClusteringFailed, cluster_modes
from physgs.oma.run import OMASettings, in_bounds, projected_records
from physgs.oma.ssi import Modes, SSISettings, group_stable_poles, ssi_poles
from physgs.testbed.dataset import load_observed

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_oma_ssi import FS, simulate, tolerances  # noqa: E402 (the tests' oracle)

METHODS = ("grouping", *PRESETS)
FREQ, ZETA, SECONDS = [0.5, 0.9, 1.4], [0.03, 0.05, 0.08], 200.0


def modes_of(p, s: SSISettings, method: str) -> Modes:
    """The modes ``method`` selects from the poles ``p`` (none where its clustering fails:
    counted in ``FAILED``)."""
    if method == "grouping":
        fm, zm, sh, ns, sp, fsd, zsd = group_stable_poles(
            p.freq, p.xi, p.phi, p.stable, s, p.freq_std, p.xi_std
        )
        return Modes(fm, zm, sh, ns, sp, p.stabilisation(), fsd, zsd)
    try:
        return cluster_modes(p, s, method)
    except ClusteringFailed:
        FAILED[method] = FAILED.get(method, 0) + 1
        e = np.zeros(0)
        return Modes(e, e, np.zeros((0, p.phi.shape[-1])), e, e, p.stabilisation(), e, e)


FAILED: dict[str, int] = {}  # method -> identifications its clustering stopped on


def oracle(n_seeds: int, nb: int) -> dict:
    """method -> (found, spurious, total true modes) over the oracle's records."""
    s = SSISettings(block_rows=20, order_max=40, nb=nb)
    out = {m: [0, 0, 0] for m in METHODS}
    for seed in range(n_seeds):
        p = ssi_poles([simulate(FREQ, ZETA, 6, SECONDS, seed)], FS, s)
        for m in METHODS:
            md = modes_of(p, s, m)
            hit = np.zeros(md.n_modes, bool)
            for f, z in zip(FREQ, ZETA):
                tf, _ = tolerances(f, z, SECONDS)
                close = np.abs(md.freq_hz - f) / f < tf
                out[m][0] += bool(close.any())
                hit |= close
            out[m][1] += int((~hit).sum())
            out[m][2] += len(FREQ)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("testbeds", nargs="*", help="results/testbed/<tree> folders")
    ap.add_argument("--profile", default="default")
    ap.add_argument("--oracle-seeds", type=int, default=4)
    args = ap.parse_args()
    logging.disable(logging.INFO)  # pyoma2 logs each stage of every identification
    warnings.filterwarnings("ignore")  # sklearn / hdbscan chatter inside the presets
    cfg = physgs.config.load("config/trees.yaml", args.profile)
    base = OMASettings.from_config(cfg["oma"], cfg["models"]["ours"])
    print(f"oracle (lsim, {args.oracle_seeds} records of {SECONDS:.0f} s, 3 true modes each)")
    print(f"{'method':<12}{'found':>8}{'spurious':>10}")
    for m, (hit, spur, tot) in oracle(args.oracle_seeds, base.ssi.nb).items():
        print(f"{m:<12}{f'{hit}/{tot}':>8}{spur:>10}")
    totals = {m: [0, 0] for m in METHODS}
    if args.testbeds:
        print(f"\n{'tree':<10}{'method':<12}{'modes per record':>18}{'reproduced':>12}")
    for tb in args.testbeds:
        obs = load_observed(f"{tb}/observed.npz")
        videos = [obs.frames[c, : obs.n_train] for c in range(obs.frames.shape[0])]
        rec = projected_records(videos, obs.background, base)
        poles = [ssi_poles([y], obs.fps, base.ssi) for y in rec.projected]
        for m in METHODS:
            per = []
            for p in poles:
                md = modes_of(p, base.ssi, m)
                keep = in_bounds(md, base.omega_hz)
                per.append((md.freq_hz[keep], md.zeta[keep]))
            hit, found = reproduced_modes(per)
            totals[m][0] += hit
            totals[m][1] += found
            counts = "/".join(str(f.size) for f, _ in per)
            print(f"{Path(tb).name:<10}{m:<12}{counts:>18}{f'{hit}/{found}':>12}")
    if args.testbeds:
        print("\nall trees: " + ", ".join(f"{m}: {h}/{f}" for m, (h, f) in totals.items()))
    print(f"clustering stopped (counted as no mode): {FAILED or 'never'}")


if __name__ == "__main__":
    main()
