"""Choose SSI's frequency tolerance on training data only: which modes come back from every wind.

    python benchmarks/oma_settings.py results/testbed/sparse [results/testbed/medium ...]
        [--err-fn 0.01,0.02,0.03,0.05] [--profile default]

The three winds' training videos of one tree are three independent records of the same system
(the joint configurations train on them; no frame beyond the window and no truth is read). For
each candidate `oma.ssi.err_fn` (it sets both the stability criterion between successive model
orders and the cut that groups stable poles into modes), each record is identified on its own
(the same cells and principal components for all three) and a mode counts as *reproduced* when
both other records hold a mode within its half-power half-bandwidth (|f - f'| <= zeta f, with the
pair's mean zeta and f): closer than that, two responses cannot be told apart. A tolerance that is
too tight splits one mode's poles into groups too small to count; one too loose merges
neighbours into a mode no other record shares. The table prints, per tree and candidate, the
modes found per record, the reproduced ones, and their share; the choice is the candidate with
the most reproduced modes summed over the trees (ties: the larger share).
"""

from __future__ import annotations

import argparse
import logging
from dataclasses import replace

import physgs.config
from physgs.oma.agreement import reproduced_modes
from physgs.oma.run import OMASettings, in_bounds, projected_records
from physgs.oma.ssi import identify
from physgs.testbed.dataset import load_observed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("testbeds", nargs="+", help="results/testbed/<tree> folders")
    ap.add_argument("--err-fn", default="0.01,0.02,0.03,0.05")
    ap.add_argument("--profile", default="default")
    args = ap.parse_args()
    logging.disable(logging.INFO)  # pyoma2 logs each stage of every identification
    cfg = physgs.config.load("config/trees.yaml", args.profile)
    base = OMASettings.from_config(cfg["oma"], cfg["models"]["ours"])
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


if __name__ == "__main__":
    main()
