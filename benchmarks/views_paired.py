"""Held-out views of two settings of one model, paired by training seed: the test, run ONCE.

    python benchmarks/views_paired.py results/testbed/sparse --a DIR_A --b DIR_B \
        [--model ours_chain] [--seeds 0,1,2]

Reads the checkpoints ``<DIR>/<model>_seed<s>.pt`` of two settings (e.g. written by
``benchmarks/omega_search.py --save DIR``, which trains by the pipeline's recipe) and prints,
per seed, the view split's mean PSNR (dB; every held-out azimuth at every held-out frame of
the training wind, ``physgs.evaluate.splits.view_psnr``, the pipeline's own scoring), the paired
difference A - B, and its mean with the 95% interval over seeds
(``physgs.report.seeds.interval``). The views are a test split: a setting is chosen on
training-window frames first (``benchmarks/omega_search.py``, ``benchmarks/fit_recipe.py``),
then this measures the chosen one against the current one once, whichever way it falls.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from physgs.evaluate.adapter import model_render_fn
from physgs.evaluate.splits import view_psnr
from physgs.models import load_checkpoint
from physgs.report.seeds import interval
from physgs.testbed.dataset import load_observed


def main(argv: list[str] | None = None) -> None:
    """Run with ``argv`` (default: the command line)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("dataset", type=Path, help="folder with observed.npz")
    ap.add_argument("--a", type=Path, required=True, help="checkpoints of setting A")
    ap.add_argument("--b", type=Path, required=True, help="checkpoints of setting B")
    ap.add_argument("--model", default="ours_chain")
    ap.add_argument("--seeds", default="0,1,2")
    args = ap.parse_args(argv)
    obs = load_observed(args.dataset / "observed.npz")
    seeds = [int(s) for s in args.seeds.split(",")]
    print(f"# {args.dataset} {args.model}: view PSNR (dB), A = {args.a}, B = {args.b}")
    print(f"{'seed':>4s} {'A':>8s} {'B':>8s} {'A - B':>8s}")
    rows = []
    for s in seeds:
        a, b = (
            float(
                view_psnr(
                    model_render_fn(load_checkpoint(d / f"{args.model}_seed{s}.pt"), obs), obs
                ).mean()
            )
            for d in (args.a, args.b)
        )
        rows.append((a, b))
        print(f"{s:4d} {a:8.2f} {b:8.2f} {a - b:+8.2f}", flush=True)
    a, b = np.array(rows).T  # [S] each
    for name, v in (("A", a), ("B", b), ("A - B", a - b)):
        m, sd, lo, hi = interval(v)
        print(f"{name:>6s} mean {m:+.2f} sd {sd:.2f} 95% [{lo:+.2f}, {hi:+.2f}]")


if __name__ == "__main__":
    main()
