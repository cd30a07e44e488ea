"""The claims ledger of a partial run: every claim whose tables the run built, the rest listed as
"undecided: not measured".

    python tools/ledger.py [--results results] [--config config/trees.yaml] [--profile default]
        [--seeds 0 1 2] [--trees medium] [--out PATH.md]

`snakemake claims` needs every table (the whole DAG). A run of some targets (for example the
parts study and the 2D-track control at three seeds, without the learned fields) still decides
the claims its tables hold; this reads the tables' CSVs and ours' joint K = 32 recovery records
where the workflow writes them (`workflow/rules/common.smk`: TABLE, RECOVERY) and prints the
ledger (`physgs.report.build.claims_frame`, the claims rule's own code) with its verdict counts.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import physgs.config
from physgs.report import build, claims
from physgs.report.claim_cells import roles_of


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", default="results", type=Path)
    ap.add_argument("--config", default="config/trees.yaml")
    ap.add_argument("--profile", default="default")
    ap.add_argument("--seeds", type=int, nargs="+", help="training seeds (default: the config's)")
    ap.add_argument("--trees", nargs="+", help="the trees the run built (default: the config's)")
    ap.add_argument("--out", type=Path, help="also write the ledger here (Markdown)")
    args = ap.parse_args()
    cfg = physgs.config.load(args.config, args.profile)
    seeds = args.seeds if args.seeds is not None else cfg["seeds"]
    trees = args.trees or cfg["trees"]
    plan = dataclasses.replace(build.Plan.from_config(cfg), trees=trees, seeds=seeds)
    needs = build.claims_needs(plan, every=True)
    paths = {  # the workflow's layout (common.smk: TABLE, RECOVERY)
        "table": "tables/{name}.csv",
        "recovery": "recovery/{tree}/seed{seed}/{method}_{config}.json",
    }
    inputs = {}
    for need in needs:
        fields = dict(zip(build.NEED_FIELDS[need[0]], need[1:]))
        path = args.results / paths[need[0]].format(**fields)
        if path.exists():
            inputs[need] = str(path)
    missing = sorted(build.key(n) for n in needs if n not in inputs)
    df = build.claims_frame(inputs, trees, roles_of(cfg["presets"], trees))
    md = claims.ledger_markdown(df, {"seeds": " ".join(map(str, seeds)), "partial": "yes"})
    print(md)
    print(f"not found under {args.results} ({len(missing)}): {', '.join(missing) or 'none'}")
    measured = df[df["seeds"] > 0]
    print(
        f"{len(measured)} of {len(df)} claims measured: the paper's "
        f"{claims.counted(measured, 'paper')}; this project's own "
        f"{claims.counted(measured, 'project')}"
    )
    if args.out:
        args.out.write_text(md)


if __name__ == "__main__":
    main()
