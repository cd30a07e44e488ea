"""Cost of choosing K from the data (physgs.models.kselect) per tree, and what it picks.

    python benchmarks/kselect.py --profile default results/testbed/sparse/observed.npz [...]

Prints one row per candidate K (training + scoring seconds, held-out PSNR, BIC, frozen parts)
and the total per tree. Budget: quick well under a minute per tree; default all three
trees within about 5 minutes on 2 cores.
"""

import argparse
import time

import torch

import physgs.config
from physgs.models.kselect import select_k
from physgs.testbed.dataset import load_observed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("observed", nargs="+", help="observed.npz files (one per tree)")
    ap.add_argument("--profile", default="default", choices=["quick", "default", "paper"])
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    torch.set_num_threads(a.threads)
    cfg = physgs.config.load("config/trees.yaml", a.profile)
    ks = cfg["models"]["kselect"]
    print(
        f"profile {a.profile}: candidates {ks['candidates']}, {ks['iterations']} iterations "
        f"each, method {ks['method']}"
    )
    print(f"{'file':40s} {'K':>4s} {'seconds':>8s} {'heldout dB':>10s} {'BIC':>12s} {'frozen':>6s}")
    for path in a.observed:
        obs = load_observed(path)
        t0 = time.perf_counter()
        sel = select_k(obs, cfg)
        total = time.perf_counter() - t0
        for i, k in enumerate(sel.candidates):
            print(
                f"{path[-40:]:40s} {k:4d} {sel.wall_s[i]:8.1f} {sel.heldout_psnr[i]:10.3f} "
                f"{sel.bic[i]:12.4g} {sel.frozen[i]:6d}"
            )
        print(
            f"{path[-40:]:40s} total {total:.1f} s; chosen K {sel.chosen_k} (heldout "
            f"{sel.k_heldout}, bic {sel.k_bic})"
        )


if __name__ == "__main__":
    main()
