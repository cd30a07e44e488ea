"""Coverage of the output-only analysis' 95% intervals on testbeds, and the parts each trust rule keeps.

    python benchmarks/oma_intervals.py results/testbed/sparse_damping [...] [--seeds 0,1,2]
        [--configs single,joint32] [--profile default]

The rules' own code, run in one process (``oma_identify``: identify_video; ``oma_recovery``:
part_modes, recover_oma), so it prints what the pipeline's records hold: per testbed and
configuration, over the matcher's trusted parts with an estimate (pooled over the training
seeds), the fraction of +-1.96 sigma intervals that hold the matched bone's true omega and zeta
with its Clopper-Pearson 95% interval (and over the distinct mode-bone pairs, since parts
share modes), and the parts kept by ours' rule (trajectory
correlation >= 0.7), by the modes' own sigma rule, and by both. The seeds resample only the
k-means of cells into parts: the video, and so every mode and sigma, is the same at every seed.
Evaluation: reads the truth (the scoring rule's).
"""

from __future__ import annotations

import argparse
import logging
import warnings
from pathlib import Path

import numpy as np

import physgs.config
from physgs.oma.intervals import coverage, interval_hits
from physgs.oma.run import OMASettings, identify_video, part_modes, recover_oma
from physgs.oma.settings import identify_params, recovery_params
from physgs.testbed.dataset import load_observed, load_truth


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("testbeds", nargs="+")
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--configs", default="single,joint32")
    ap.add_argument("--profile", default="default")
    args = ap.parse_args()
    logging.disable(logging.INFO)
    warnings.filterwarnings("ignore")
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


if __name__ == "__main__":
    main()
