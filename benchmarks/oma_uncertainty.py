"""The modes' standard deviations against independent records of one lsim system, by record length and nb.

    python benchmarks/oma_uncertainty.py [--seconds 25,50,200] [--nb 3,5,10] [--records 30]

The oracle of ``tests/test_oma_uncertainty.py`` (two modes, 0.6 and 1.2 Hz, zeta 0.04 and 0.08,
four channels, block rows 12, orders to 16): for each record length and number of data blocks,
``--records`` independent records are identified one by one; of those that show both modes and
nothing else, it prints per mode the spread of the estimates over their median sigma (1: the
sigmas are right; below 1: conservative), the coverage of the +-1.96 sigma intervals, and the
damping's relative bias (which no block-based sigma sees).
"""

from __future__ import annotations

import argparse
import logging
import sys
import warnings
from pathlib import Path

import numpy as np

from physgs.oma.intervals import interval_hits
from physgs.oma.ssi import SSISettings, identify

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_oma_ssi import FS, simulate  # noqa: E402 (the tests' oracle)

FREQ, ZETA = [0.6, 1.2], [0.04, 0.08]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", default="25,50,200")
    ap.add_argument("--nb", default="3,5,10")
    ap.add_argument("--records", type=int, default=30)
    args = ap.parse_args()
    logging.disable(logging.INFO)
    warnings.filterwarnings("ignore")
    print(f"{'T (s)':>6}{'nb':>4}{'kept':>6}   per mode (0.6 Hz, 1.2 Hz): spread / sigma, coverage")
    for sec in (float(x) for x in args.seconds.split(",")):
        for nb in (int(x) for x in args.nb.split(",")):
            s = SSISettings(block_rows=12, order_max=16, nb=nb, min_stable=3)
            got = []
            for seed in range(args.records):
                m = identify(simulate(FREQ, ZETA, 4, sec, 100 + seed, shape_seed=9), FS, s)
                if m.n_modes == 2:
                    got.append((m.freq_hz, m.zeta, m.freq_std, m.zeta_std))
            f, z, fs, zs = (np.array(x) for x in zip(*got))
            n = len(f)

            def cov(est, sd, truth):
                return interval_hits(est, sd, np.broadcast_to(truth, est.shape)).mean(axis=0)

            print(
                f"{sec:>6.0f}{nb:>4}{n:>6}   f: {np.round(f.std(0, ddof=1) / np.median(fs, 0), 2)}"
                f" cover {np.round(cov(f, fs, FREQ), 2)};  zeta: "
                f"{np.round(z.std(0, ddof=1) / np.median(zs, 0), 2)} cover "
                f"{np.round(cov(z, zs, ZETA), 2)}, bias {np.round(z.mean(0) / ZETA - 1, 2)}"
            )


if __name__ == "__main__":
    main()
