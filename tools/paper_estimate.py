"""What a profile's run would cost in CPU-hours, priced from today's plan and measured rates.

    python tools/paper_estimate.py [--profile paper] [--rates docs/record/rates_paper.csv]
        [--gpu-rates FILE] [--out docs/record/paper_estimate.md]

Lists the profile's plan (`snakemake -n --forceall all --config profile=PROFILE`), prices each
planned training at the measured CPU seconds per iteration of its tree, model and configuration
(`benchmarks/training.py --profile PROFILE --variants --csv RATES`) through
`physgs.experiments.cost.training_estimate`, and writes the paragraph the cluster page includes.
A training without a measured rate is named and left out of the total, never guessed; jobs that
do not train (K selection, evaluation, recovery) are not priced.

With ``--gpu-rates FILE`` (written by ``benchmarks/gpu_check.py --rates FILE`` on a GPU) a second
paragraph prices the same plan on one GPU: each training at the device's wall seconds per
iteration at the profile's resolution, one training after another.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import pandas as pd

import physgs.config
from physgs.experiments.cost import dry_run, plan_jobs, training_estimate
from physgs.experiments.recipe import tree_recipe
from physgs.report.record import format_duration


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", default="paper")
    ap.add_argument("--rates", default="docs/record/rates_paper.csv", type=Path)
    ap.add_argument("--gpu-rates", default=None, type=Path, help="benchmarks/gpu_check.py's CSV")
    ap.add_argument("--out", default="docs/record/paper_estimate.md", type=Path)
    args = ap.parse_args()
    planned = plan_jobs(dry_run(["all"], [f"profile={args.profile}"]))
    cfg = physgs.config.load_workflow_config(
        physgs.config.read_yaml("config/trees.yaml"), args.profile
    )
    rates_df = pd.read_csv(args.rates, dtype={"commit": str})
    if set(rates_df["profile"]) != {args.profile}:
        raise SystemExit(f"{args.rates}: rates of {set(rates_df['profile'])}, not {args.profile}")
    rates = {(r.tree, r.model, r.config): r.cpu_s_per_iter for r in rates_df.itertuples()}
    configs = sorted({c for _, _, c in rates} | set(cfg["models"]["configs"]))
    it, warm = cfg["train"]["iterations"], cfg["train"]["warmup"]
    est = training_estimate(planned, rates, configs, it, warm, budget=budget_of(cfg))
    seeds = sorted(est["per_seed"])
    per_seed = sorted(set(est["per_seed"].values()))
    own = "" if not cfg.get("recipes") else ", or the budget its tree's recipe gives a model"
    r0 = rates_df.iloc[0]
    unrated = ", ".join(f"{k} {n}" for k, n in _by_model(est["unrated"]).items())
    lines = [
        f"The `{args.profile}` profile ({cfg['testbed']['resolution']} px, {it:,} iterations of "
        f"which {warm:,} static warm-up{own}, seeds {', '.join(map(str, seeds))}) plans "
        f"**{sum(est['per_seed'].values())} trainings**, "
        f"{' or '.join(map(str, per_seed))} per seed (`snakemake -n --forceall all --config "
        f"profile={args.profile}`). The {est['jobs']} with a measured rate cost "
        f"**{est['cpu_s'] / 3600:,.0f} CPU-hours** ({est['cpu_s'] / 3600 / len(seeds):,.0f} a "
        f"seed): each its iterations at the CPU seconds per iteration of its tree, model and "
        f"configuration, measured {r0['date']} at commit `{r0['commit']}` on {r0['cpu']}, one "
        f"thread (`python benchmarks/training.py --profile {args.profile} --iters 2 --variants "
        f"--csv {args.rates}`, on a machine shared with other work: CPU time, not wall time).",
        "",
        f"Not priced: {sum(est['unrated'].values())} trainings without a measured rate "
        f"({unrated or 'none'}), and the jobs that do not train (K selection, evaluation, "
        "recovery, the control). At one thread per job CPU-hours are job-hours; no run takes "
        f"less than its longest training, {format_duration(est['longest_s'])}.",
        "",
    ]
    if args.gpu_rates is not None:
        lines += gpu_paragraph(args.gpu_rates, planned, cfg, configs, args.profile)
    args.out.write_text("\n".join(lines))
    print(args.out.read_text())


def budget_of(cfg: dict):
    """(iterations, warmup) of a model's trainings on a tree: its recipe's, else the profile's."""

    def budget(tree: str, model: str) -> tuple[int, int]:
        train = {**cfg["train"], **tree_recipe(cfg, tree, model).get("train", {})}
        return train["iterations"], train["warmup"]

    return budget


def _by_model(unrated: dict) -> dict[str, int]:
    """Unrated trainings counted by model and configuration, over trees."""
    groups: dict[str, int] = {}
    for (_, m, c), n in unrated.items():
        key = f"`{m}`" + (f" {c}" if c else "")
        groups[key] = groups.get(key, 0) + n
    return dict(sorted(groups.items()))


def gpu_paragraph(path: Path, planned, cfg: dict, configs, profile: str) -> list[str]:
    """The plan priced on one GPU at ``path``'s rates of the profile's resolution."""
    df = pd.read_csv(path, dtype={"commit": str})
    res = int(cfg["testbed"]["resolution"])
    at = df[df["resolution"] == res]
    if at.empty:
        raise SystemExit(
            f"{path}: rates at {sorted(set(df['resolution']))} px, none at the {profile} "
            f"profile's {res} px (benchmarks/gpu_check.py --resolutions {res})"
        )
    rates = {(r.tree, r.model, r.config): r.wall_s_per_iter for r in at.itertuples()}
    it, warm = cfg["train"]["iterations"], cfg["train"]["warmup"]
    est = training_estimate(planned, rates, configs, it, warm, budget=budget_of(cfg))
    r0 = at.iloc[0]
    unrated = ", ".join(f"{k} {n}" for k, n in _by_model(est["unrated"]).items())
    where = "one GPU" if r0["device"] == "cuda" else f"one {r0['device']} device"
    return [
        f"On {where} ({r0['device_name']}), at the wall seconds per iteration "
        f"`benchmarks/gpu_check.py` measured {r0['date']} at commit `{r0['commit']}` ({res} px, "
        f"the real training loop), the {est['jobs']} rated trainings take "
        f"**{est['cpu_s'] / 3600:,.1f} {'GPU-hours' if r0['device'] == 'cuda' else 'hours'}** "
        "one after another "
        f"({est['cpu_s'] / max(est['jobs'], 1) / 60:,.1f} min a training; slowest "
        f"{format_duration(est['longest_s'])}). Not priced: "
        f"{sum(est['unrated'].values())} trainings ({unrated or 'none'}).",
        "",
    ]


if __name__ == "__main__":
    main()
