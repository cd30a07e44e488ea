"""Output-only modal analysis: SSI's settings, the clustering presets, the modes' sigmas and intervals.

    python benchmarks/oma.py settings results/testbed/sparse [results/testbed/medium ...]
        [--err-fn 0.01,0.02,0.03,0.05] [--profile default]
    python benchmarks/oma.py clustering [results/testbed/sparse results/testbed/medium ...]
        [--profile default] [--oracle-seeds 4]
    python benchmarks/oma.py uncertainty [--seconds 25,50,200] [--nb 3,5,10] [--records 30]
    python benchmarks/oma.py intervals results/testbed/sparse_damping [...] [--seeds 0,1,2]
        [--configs single,joint32] [--profile default]

``settings``: choose SSI's frequency tolerance on training data only, from which modes come back
from every wind. The three winds' training videos of one tree are three independent records of
the same system (the joint configurations train on them; no frame beyond the window and no truth
is read). For each candidate `oma.ssi.err_fn` (it sets both the stability criterion between
successive model orders and the cut that groups stable poles into modes), each record is
identified on its own (the same cells and principal components for all three) and a mode counts
as *reproduced* when both other records hold a mode within its half-power half-bandwidth
(|f - f'| <= zeta f, with the pair's mean zeta and f): closer than that, two responses cannot be
told apart. A tolerance that is too tight splits one mode's poles into groups too small to count;
one too loose merges neighbours into a mode no other record shares. The table prints, per tree
and candidate, the modes found per record, the reproduced ones, and their share; the choice is
the candidate with the most reproduced modes summed over the trees (ties: the larger share).

``clustering``: pyOMA-2's clustering presets beside the hand-written grouping of stable poles.
Two measures, neither reading a tree's truth:

* the ``scipy.signal.lsim`` oracle of ``tests/test_oma_ssi.py`` (three modes 0.5, 0.9, 1.4 Hz,
  zeta 0.03, 0.05, 0.08, six channels, 200 s records at 24 Hz, block rows 20, orders to 40): per
  method, the true modes found (a mode within four record-length sigmas of the truth in
  frequency, ``tests/test_oma_ssi.tolerances``), the modes it reports that match none
  (spurious), over ``--oracle-seeds`` independent records;
* each testbed's training window: the three winds' records identified one by one (the same
  cells and principal components for all three, the config's SSI settings), and a mode counts
  as reproduced when both other records hold one within its half-power half-bandwidth
  ([`reproduced_modes`][physgs.oma.agreement.reproduced_modes], as ``settings``).

Per method: ``grouping`` ([`group_stable_poles`][physgs.oma.ssi.group_stable_poles]) and each of
[`PRESETS`][physgs.oma.clustering.PRESETS]; the same poles feed all of them.

``uncertainty``: the modes' standard deviations against independent records of one lsim system,
by record length and nb. The oracle of ``tests/test_oma_uncertainty.py`` (two modes, 0.6 and
1.2 Hz, zeta 0.04 and 0.08, four channels, block rows 12, orders to 16): for each record length
and number of data blocks, ``--records`` independent records are identified one by one; of those
that show both modes and nothing else, it prints per mode the spread of the estimates over their
median sigma (1: the sigmas are right; below 1: conservative), the coverage of the +-1.96 sigma
intervals, and the damping's relative bias (which no block-based sigma sees).

``intervals``: coverage of the output-only analysis' 95% intervals on testbeds, and the parts
each trust rule keeps. The rules' own code, run in one process (``oma_identify``:
identify_video; ``oma_recovery``: part_modes, recover_oma), so it prints what the pipeline's
records hold: per testbed and configuration, over the matcher's trusted parts with an estimate
(pooled over the training seeds), the fraction of +-1.96 sigma intervals that hold the matched
bone's true omega and zeta with its Clopper-Pearson 95% interval (and over the distinct
mode-bone pairs, since parts share modes), and the parts kept by ours' rule (trajectory
correlation >= 0.7), by the modes' own sigma rule, and by both. The seeds resample only the
k-means of cells into parts: the video, and so every mode and sigma, is the same at every seed.
Evaluation: reads the truth (the scoring rule's).
"""

from __future__ import annotations

import argparse
import logging
import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

import physgs.config
from physgs.oma.agreement import reproduced_modes
from physgs.oma.clustering import PRESETS, ClusteringFailed, cluster_modes
from physgs.oma.intervals import coverage, interval_hits
from physgs.oma.run import (
    OMASettings,
    identify_video,
    in_bounds,
    part_modes,
    projected_records,
    recover_oma,
)
from physgs.oma.settings import identify_params, recovery_params
from physgs.oma.ssi import Modes, SSISettings, group_stable_poles, identify, ssi_poles
from physgs.testbed.dataset import load_observed, load_truth

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_oma_ssi import FS, simulate, tolerances  # noqa: E402 (the tests' oracle)


def _base_settings(profile: str) -> OMASettings:
    """The config's OMA settings with ours' frequency bounds."""
    cfg = physgs.config.load("config/trees.yaml", profile)
    return OMASettings.from_config(cfg["oma"], cfg["models"]["ours"])


# --- settings -------------------------------------------------------------------------------


def settings(args: argparse.Namespace) -> None:
    """Per tree and candidate err_fn: modes per record, the reproduced ones, their share."""
    base = _base_settings(args.profile)
    grid = [float(x) for x in args.err_fn.split(",")]
    totals = {e: [0, 0] for e in grid}
    print(f"{'tree':<10}{'err_fn':>8}{'modes per record':>20}{'reproduced':>12}{'share':>8}")
    for tb in args.testbeds:
        obs = load_observed(f"{tb}/observed.npz")
        videos = [obs.frames[c, : obs.n_train] for c in range(obs.frames.shape[0])]
        rec = projected_records(videos, obs.background, base)
        for e in grid:
            s = replace(base.ssi, err_fn=e)
            per = []
            for y in rec.projected:
                m = identify(y, obs.fps, s)
                keep = in_bounds(m, base.omega_hz)
                per.append((m.freq_hz[keep], m.zeta[keep]))
            hit, found = reproduced_modes(per)
            totals[e][0] += hit
            totals[e][1] += found
            counts = "/".join(str(f.size) for f, _ in per)
            print(
                f"{tb.rstrip('/').split('/')[-1]:<10}{e:>8.3f}{counts:>20}{hit:>12}"
                f"{hit / max(found, 1):>8.2f}"
            )
    best = max(grid, key=lambda e: (totals[e][0], totals[e][0] / max(totals[e][1], 1)))
    print("\nall trees: " + ", ".join(f"{e}: {h}/{f}" for e, (h, f) in totals.items()))
    print(f"chosen err_fn: {best}")


# --- clustering -----------------------------------------------------------------------------

METHODS = ("grouping", *PRESETS)
FREQ, ZETA, SECONDS = [0.5, 0.9, 1.4], [0.03, 0.05, 0.08], 200.0
FAILED: dict[str, int] = {}  # method -> identifications its clustering stopped on


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


def clustering(args: argparse.Namespace) -> None:
    """Per method: the oracle's modes found and spurious; per testbed, the reproduced modes."""
    base = _base_settings(args.profile)
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


# --- uncertainty ----------------------------------------------------------------------------

U_FREQ, U_ZETA = [0.6, 1.2], [0.04, 0.08]


def uncertainty(args: argparse.Namespace) -> None:
    """Per record length and nb: spread over sigma, coverage and the damping's bias."""
    print(f"{'T (s)':>6}{'nb':>4}{'kept':>6}   per mode (0.6 Hz, 1.2 Hz): spread / sigma, coverage")
    for sec in (float(x) for x in args.seconds.split(",")):
        for nb in (int(x) for x in args.nb.split(",")):
            s = SSISettings(block_rows=12, order_max=16, nb=nb, min_stable=3)
            got = []
            for seed in range(args.records):
                m = identify(simulate(U_FREQ, U_ZETA, 4, sec, 100 + seed, shape_seed=9), FS, s)
                if m.n_modes == 2:
                    got.append((m.freq_hz, m.zeta, m.freq_std, m.zeta_std))
            f, z, fs, zs = (np.array(x) for x in zip(*got))
            n = len(f)

            def cov(est, sd, truth):
                return interval_hits(est, sd, np.broadcast_to(truth, est.shape)).mean(axis=0)

            print(
                f"{sec:>6.0f}{nb:>4}{n:>6}   f: {np.round(f.std(0, ddof=1) / np.median(fs, 0), 2)}"
                f" cover {np.round(cov(f, fs, U_FREQ), 2)};  zeta: "
                f"{np.round(z.std(0, ddof=1) / np.median(zs, 0), 2)} cover "
                f"{np.round(cov(z, zs, U_ZETA), 2)}, bias {np.round(z.mean(0) / U_ZETA - 1, 2)}"
            )


# --- intervals ------------------------------------------------------------------------------


def intervals(args: argparse.Namespace) -> None:
    """Per testbed and configuration: the intervals' coverage and the parts each rule keeps."""
    cfg = physgs.config.load("config/trees.yaml", args.profile)
    seeds = [int(s) for s in args.seeds.split(",")]
    zr = [float(z) for z in cfg["testbed"]["damping"]["zeta_range"]]
    head = f"{'testbed':<16}{'config':<9}{'modes':>6}{'omega covered':>26}{'zeta covered':>26}"
    print(head + f"{'corr':>7}{'sigma':>7}{'both':>7}{'K':>5}{'rel sd f':>10}{'rel sd z':>10}")
    for tb in args.testbeds:
        obs, truth = load_observed(f"{tb}/observed.npz"), load_truth(f"{tb}/truth.npz")
        for c in args.configs.split(","):
            p = identify_params(cfg, c)
            s = OMASettings.from_config(p, {"omega_hz": p["omega_hz"]})
            videos = [obs.frames[i, : obs.n_train] for i in p["conditions"]]
            ident = identify_video(videos, obs.background, obs.fps, s)
            hw, hz, n, pairs = [], [], np.zeros(3, int), {}
            for seed in seeds:
                r = recovery_params(cfg, c, seed)
                pm = part_modes(ident, r["K"], seed, r["kmeans_n_init"])
                rec, _ = recover_oma(
                    pm, obs, truth, r["solver"], damping={"zeta_range": zr, "seed": seed}
                )
                b = rec.match.bone
                sc = rec.match.trusted & pm.estimated
                ow = interval_hits(pm.omega, pm.omega_std, truth.omega[b])
                oz = interval_hits(pm.zeta, pm.zeta_std, truth.zeta[b])
                hw += ow[sc].tolist()
                hz += oz[sc].tolist()
                for k in np.flatnonzero(sc):  # distinct (mode, bone) pairs: parts share modes
                    pairs[(int(pm.mode_of_part[k]), int(b[k]))] = (bool(ow[k]), bool(oz[k]))
                iv = rec.intervals
                n += [rec.match.n_trusted, iv["n_sigma_trusted"], iv["n_both_trusted"]]
            cw, cz = coverage(hw), coverage(hz)
            dw, dz = (sum(v[i] for v in pairs.values()) for i in (0, 1))
            m = ident.modes
            rf, rz = np.median(m.freq_std / m.freq_hz), np.median(m.zeta_std / m.zeta)

            def cell(cv):
                return f"{cv.k}/{cv.n} {cv.fraction:.2f} [{cv.lo:.2f}, {cv.hi:.2f}]"

            print(
                f"{Path(tb).name:<16}{c:<9}{ident.modes.n_modes:>6}{cell(cw):>26}{cell(cz):>26}"
                f"{n[0] / len(seeds):>7.1f}{n[1] / len(seeds):>7.1f}{n[2] / len(seeds):>7.1f}"
                f"{r['K']:>5}{rf:>10.3f}{rz:>10.2f}   distinct mode-bone pairs: omega"
                f" {dw}/{len(pairs)}, zeta {dz}/{len(pairs)}"
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("settings", help="SSI's err_fn: the modes every training wind gives back")
    p.add_argument("testbeds", nargs="+", help="results/testbed/<tree> folders")
    p.add_argument("--err-fn", default="0.01,0.02,0.03,0.05")
    p.add_argument("--profile", default="default")
    p.set_defaults(run=settings)
    p = sub.add_parser("clustering", help="pyOMA-2's clustering presets beside the grouping")
    p.add_argument("testbeds", nargs="*", help="results/testbed/<tree> folders")
    p.add_argument("--profile", default="default")
    p.add_argument("--oracle-seeds", type=int, default=4)
    p.set_defaults(run=clustering)
    p = sub.add_parser("uncertainty", help="the modes' sigmas against independent lsim records")
    p.add_argument("--seconds", default="25,50,200")
    p.add_argument("--nb", default="3,5,10")
    p.add_argument("--records", type=int, default=30)
    p.set_defaults(run=uncertainty)
    p = sub.add_parser("intervals", help="the 95%% intervals' coverage on testbeds")
    p.add_argument("testbeds", nargs="+")
    p.add_argument("--seeds", default="0,1,2")
    p.add_argument("--configs", default="single,joint32")
    p.add_argument("--profile", default="default")
    p.set_defaults(run=intervals)
    args = ap.parse_args()
    logging.disable(logging.INFO)  # pyoma2 logs each stage of every identification
    warnings.filterwarnings("ignore")  # sklearn / hdbscan chatter inside the presets
    args.run(args)


if __name__ == "__main__":
    main()
