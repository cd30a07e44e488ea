"""How much of each tree's true in-window motion a field's time encoding can reach.

For every dataset folder given (with truth.npz), prints the median frequency of the ground-truth
Gaussian displacement energy over the training window (training wind) and, for the Deformation
MLP's and Deformable-3DGS's time bands (config models.mlp / models.d3dgs), the top band's
frequency and the share of that energy at or below it. A wind-blind field can only reach the
rest through harmonics its ReLU layers build, which is slow to learn (spectral bias).

    python benchmarks/motion_spectrum.py results/testbed/sparse results/testbed/medium
"""

from __future__ import annotations

import argparse
from pathlib import Path

import physgs.config
from physgs.testbed.dataset import load_truth
from physgs.testbed.stats import displacement_energy_below, time_band_top_hz, truth_motion_window


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("datasets", type=Path, nargs="+")
    ap.add_argument("--profile", default="default")
    args = ap.parse_args()
    cfg = physgs.config.load("config/trees.yaml", args.profile)
    n, fps = int(cfg["testbed"]["n_train"]), float(cfg["testbed"]["fps"])
    fields = {m: int(cfg["models"][m]["time_bands"]) for m in ("mlp", "d3dgs")}
    tops = {m: time_band_top_hz(b, n, fps) for m, b in fields.items()}
    print(
        f"{'dataset':24s} {'median Hz':>9s} "
        + " ".join(f"{f'<= {m} top ({tops[m]:.2f} Hz)':>24s}" for m in fields)
    )
    for d in args.datasets:
        x = truth_motion_window(load_truth(d / "truth.npz"), n)
        grid = [i / 100 for i in range(0, 1201)]  # Hz, for the median
        shares = displacement_energy_below(x, fps, [*tops.values(), *grid])  # one FFT
        share, cum = shares[: len(tops)], shares[len(tops) :]
        median = next(f for f, c in zip(grid, cum) if c >= 0.5)
        print(f"{str(d):24s} {median:9.2f} " + " ".join(f"{100 * s:23.1f}%" for s in share))


if __name__ == "__main__":
    main()
