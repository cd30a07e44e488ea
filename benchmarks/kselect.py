"""Cost of choosing K from the data (physgs.experiments.kselect) per tree, and what it picks.

    python benchmarks/kselect.py --profile default results/testbed/sparse/observed.npz [...]
        [--model ours|ours_chain] [--seed 0]

The rule `kselect`'s own call: the prior's training job (`physgs.experiments.recipe.job_spec`,
base configuration) and its K-selection settings (`physgs.experiments.kselect.settings_for`).

Prints one row per candidate K (training + scoring seconds, held-out PSNR, BIC, frozen parts)
and the total per tree. Budget: quick well under a minute per tree; default all three
trees within about 5 minutes on 2 cores.
"""

import argparse
import time

import torch

import physgs.config
from physgs.experiments.kselect import BASE_MODEL, select_k, selected_models, settings_for
from physgs.experiments.recipe import job_spec
from physgs.models.registry import BASE_CONFIG
from physgs.testbed.dataset import load_observed


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("observed", nargs="+", help="observed.npz files (one per tree)")
    ap.add_argument("--profile", default="default", choices=["quick", "default", "paper"])
    ap.add_argument("--model", default=BASE_MODEL, help="a prior whose K the config selects")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=1, help="the rule runs one thread")
    a = ap.parse_args()
    torch.set_num_threads(a.threads)
    cfg = physgs.config.load("config/trees.yaml", a.profile)
    if a.model not in selected_models(cfg["models"]["kselect"]):
        ap.error(f"--model: K is selected for {selected_models(cfg['models']['kselect'])} only")
    ks = settings_for(cfg["models"]["kselect"], a.model)
    job = job_spec(cfg, a.model, BASE_CONFIG, seed=a.seed)
    print(
        f"profile {a.profile}, {a.model}: candidates {ks['candidates']}, {ks['iterations']} "
        f"iterations each, method {ks['method']}"
    )
    print(f"{'file':40s} {'K':>4s} {'seconds':>8s} {'heldout dB':>10s} {'BIC':>12s} {'frozen':>6s}")
    for path in a.observed:
        obs = load_observed(path)
        t0 = time.perf_counter()
        sel = select_k(obs, job, ks)
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
