"""The committed record of a finished default-profile run, and the README lines read from it.

    python tools/record.py [results] [--out docs/record] [--wall-s S] [--commit REV]
        [--snakemake-report]

Copies the run's summary, ledger, every table (CSV and Markdown) and every figure (PNG, web
sized) into `docs/record/` with the run's stamp (`physgs.report.record.write_record`), then
rewrites the README's block between `<!-- record:begin -->` and `<!-- record:end -->` from it
(`physgs.report.record.readme_block`). The run's layout is the workflow's (`results/`:
`summary.md`, `claims.{csv,md}`, `tables/*.csv`, `figures/*.png`, `benchmarks/`). The wall time
is the benchmark files' span unless `--wall-s` gives the measured one (`tools/timed.py` measures
it). `--snakemake-report` also makes Snakemake's report of the run (`snakemake --report
<results>/report.html all`) and puts it in the record, linked from its page; `--report-html
FILE` takes one already made (by `snakemake --report` in the folder the run ran in, whose
`.snakemake/` holds the jobs' metadata). `--readme-only` rewrites the README's block from the
record already there.
"""

from __future__ import annotations

import argparse
import datetime
import subprocess
from pathlib import Path

import pandas as pd

from physgs.experiments.cost import read_costs, summarise, wall_spans
from physgs.provenance import git_commit, machine_cpu
from physgs.report import record


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="?", default="results", type=Path)
    ap.add_argument("--out", default="docs/record", type=Path)
    ap.add_argument("--readme", default="README.md", type=Path)
    ap.add_argument("--wall-s", type=float, help="the run's measured wall time, s")
    ap.add_argument("--commit", help="the commit the run was made at (default: git describe)")
    ap.add_argument("--readme-only", action="store_true")
    ap.add_argument("--snakemake-report", action="store_true", help="add `snakemake --report`")
    ap.add_argument("--report-html", type=Path, help="a `snakemake --report` of the run, made")
    args = ap.parse_args()
    if not args.readme_only:
        r = args.results
        fit = pd.read_csv(r / "tables" / "tab_fit.csv", dtype={"config_hash": str})
        jobs = read_costs(r / "benchmarks")
        by_stage = summarise(jobs)["by_stage"]
        stamp = record.Stamp(
            date=datetime.date.today().isoformat(),
            commit=args.commit or git_commit(),
            profile=str(fit["profile"].iloc[0]),
            config_hash=str(fit["config_hash"].iloc[0]),
            seeds=tuple(sorted(int(s) for s in fit["seed"].unique())),
            trees=tuple(dict.fromkeys(fit["tree"])),
            cpu=machine_cpu(),
            wall_s=args.wall_s if args.wall_s is not None else wall_spans(jobs)["run_s"],
            job_min_by_stage={k: sum(v.values()) / 60 for k, v in sorted(by_stage.items())},
        )
        report = args.report_html
        if args.snakemake_report:
            report = r / "report.html"
            subprocess.run(["snakemake", "--report", str(report), "all"], check=True)
        written = record.write_record(
            args.out,
            stamp=stamp,
            summary_md=r / "summary.md",
            claims_csv=r / "claims.csv",
            claims_md=r / "claims.md",
            tables=sorted((r / "tables").glob("*.csv")),
            figures=sorted((r / "figures").glob("*.png")),
            report_html=report,
        )
        print(f"{args.out}: {len(written)} files")
    if not (args.out / "stamp.json").is_file():
        record.write_unrecorded(args.out)
    found = record.found_lines(args.out)
    (args.out / "found.md").write_text("\n".join(found))
    costs = record.cost_lines(record.read_costs(args.out / "costs.csv"))
    (args.out / "costs.md").write_text("\n".join(costs) + "\n")
    text = args.readme.read_text()
    args.readme.write_text(record.replace_block(text, record.readme_block(found)))
    print(f"{args.readme}: the record block rewritten")


if __name__ == "__main__":
    main()
