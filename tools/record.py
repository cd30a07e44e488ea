"""The committed record of a finished default-profile run, and the README lines read from it.

    python tools/record.py [results] [--out docs/record] [--wall-s S] [--commit HASH] [--note TEXT]
                           [--configfile FILE ...] [--config KEY=VALUE ...]   # the run's overrides
    python tools/record.py --pages-only      # lay the record's pages out again from its own files
                                             # (and add the ledger's catalogue-derived columns)
    python tools/record.py --readme-only     # rewrite the README's block from the record
    python tools/record.py --report-html [results/report.html]   # Snakemake's report, on demand

Copies the run's summary, ledger, the tables (CSV) and figures (PNG, web sized) that `all`
makes into `docs/record/` with the run's stamp (`physgs.report.record.write_record`), lays out
the Results page's parts from them (`physgs.report.record.render_pages`: the figures with their
captions, the ledger's counts, each table's summary over seeds), then rewrites the README's
block between `<!-- record:begin -->` and `<!-- record:end -->`
(`physgs.report.record.readme_block`). The run's layout is the workflow's (`results/`:
`summary.md`, `claims.{csv,md}`, `tables/*.csv`, `figures/*.png`, `benchmarks/`).

It takes exactly what `all`'s plan makes, not what the folder holds: Snakemake's dry run of
`all` in the run's checkout (`snakemake -n --forceall all --config profile=P`, P the profile of the
run's `tab_fit.csv`) names every output and benchmark file of `all`'s jobs
(`physgs.experiments.cost.plan_outputs`, `plan_jobs`), and `physgs.report.record.run_files`
keeps those: the tables and figures among the outputs, and the jobs of those benchmark files
for the stamp's job count and job-minutes by stage (the jobs of the run whose wall time it
states). A table, figure or benchmark file of the plan that the folder lacks stops it, named;
what the folder holds beyond the plan (a `snakemake studies` run's tables and figures, whose
jobs keep their benchmark files under `results/studies/benchmarks/`, or an earlier run's files)
is left out and listed. It works in the checkout that holds `results` (the run's folder, named
`results`): that checkout's config, plan and commit are the run's, so a run made in another
worktree is recorded from here with `python tools/record.py ../wt/results` (`--out`, `--readme`
and this checkout's library stay this checkout's; `--configfile` paths are the run's checkout's).
Give the `--configfile` and `--config` words the run was given
(`profile=P` is added, P the profile of the run's `tab_fit.csv`, unless they set it): they are
written into the stamp and the README's block. A config whose hash is not the run's (its tables'
`config_hash`) is refused, since its plan is another run's. It takes one run of one config: every
table of the plan and the ledger must carry the run's hash, and `all` must have nothing left to do
under the overrides, with every file of its plan carrying the provenance record of its job's
settings in this plan (`physgs.provenance.check_plan` on every job: `EVERY_JOB_ENV`); otherwise it
stops, naming each file that disagrees and the key that differs.

The wall time is the run's command's, measured by `tools/timed.py --name all` (summed over the
segments of a resumed run): `--wall-s` gives it, else the `all` row of `costs.csv` when it was
measured at the run's commit; there is no other definition. The commit is a plain hash
(`--commit`, default HEAD's); anything else a reader should know goes in `--note`.

`--report-html` makes Snakemake's report of the run (`snakemake --report PATH all`, run in the
folder the run ran in, whose `.snakemake/` holds the jobs' metadata) into `results/`; it is ~10 MB
and never enters the record.
"""

from __future__ import annotations

import argparse
import datetime
import os
import shlex
import subprocess
from pathlib import Path

import pandas as pd

import physgs.config
from physgs.experiments.cost import dry_run, plan_jobs, plan_outputs, summarise
from physgs.provenance import EVERY_JOB_ENV, config_hash, git_commit, machine_cpu, read_stamped
from physgs.report import record
from physgs.report.claim_cells import roles_of
from snakemake.cli import parse_config


#: the run's folder as the workflow's paths name it: every output and benchmark file is below it
RUN_ROOT = Path("results")
TARGET = "all"  # the record is of the run of `all`
CONFIGFILE = "config/trees.yaml"  # the Snakefile's configfile


def _run_items(profile: str, config: list[str]) -> list[str]:
    """The run's ``--config`` items: ``config``, with ``profile=P`` first unless it sets the
    profile (P: the profile of the run's tables)."""
    return config if "profile" in parse_config(config) else [f"profile={profile}", *config]


def _config_hash(config: list[str], configfiles: list[str]) -> str:
    """This checkout's config hash under ``--configfile configfiles --config config``, resolved
    as the Snakefile resolves them (the hash its tables carry)."""
    command_line = parse_config(config)
    raw = physgs.config.read_yaml(CONFIGFILE) or {}
    for f in configfiles:
        raw = physgs.config.deep_merge(raw, physgs.config.read_yaml(f) or {})
    raw = physgs.config.deep_merge(raw, command_line)
    cfg = physgs.config.load_workflow_config(
        raw, command_line=command_line, configfiles=configfiles
    )
    return config_hash(cfg)


def _plan(config: list[str], configfiles: list[str], run_hash: str) -> tuple[list[str], list[str]]:
    """`all`'s outputs and benchmark files under the run's overrides, relative to the run's
    folder, from Snakemake's dry run in the run's checkout (the current folder); refused unless
    its config with those overrides is the run's."""
    here = _config_hash(config, configfiles)
    if here != run_hash:
        raise SystemExit(
            f"{Path.cwd()}: its config with `{_words(config, configfiles).strip()}` hashes to "
            f"{here}, the run's tables to {run_hash}: its plan is another run's; name the run's "
            "folder in the checkout it was made in, giving the run's own overrides (`--config "
            "KEY=VALUE ...`, `--configfile FILE ...`)"
        )
    dry = dry_run([TARGET], config, configfiles=configfiles)

    def below(paths):
        return [str(Path(p).relative_to(RUN_ROOT)) for p in paths if RUN_ROOT in Path(p).parents]

    return below(plan_outputs(dry)), below(b for _, b in plan_jobs(dry) if b)


def _finished(config: list[str], configfiles: list[str]) -> None:
    """Refuse the run unless `all` has nothing left to do under its overrides and every file of
    its plan was made with the plan's settings (its provenance record, checked for every job,
    physgs.provenance.EVERY_JOB_ENV), naming each file that disagrees and the key."""
    words = _words(config, configfiles)
    try:
        pending = dry_run(
            [TARGET],
            config,
            configfiles=configfiles,
            forceall=False,
            env={EVERY_JOB_ENV: "1"},
        )
    except RuntimeError as e:  # the plan's provenance check refused files, or Snakemake did
        raise SystemExit(
            f"{TARGET}'s plan under `{words.strip()}` is not this run's: {e}"
        ) from None
    remade = [o for o in plan_outputs(pending) if RUN_ROOT in Path(o).parents]
    if remade:
        shown = ", ".join(remade[:12]) + (
            f" and {len(remade) - 12} more" if len(remade) > 12 else ""
        )
        raise SystemExit(
            f"{TARGET} under `{words.strip()}` is not finished: Snakemake would make "
            f"{len(remade)} of its files again ({shown}); finish the run (snakemake --cores 2 "
            f"{TARGET}{words}) and record it then"
        )


def _words(config: list[str], configfiles: list[str]) -> str:
    """The overrides as Snakemake's command line words (a leading space when any)."""
    words = [*(["--configfile", *configfiles] if configfiles else [])]
    words += ["--config", *config] if config else []
    return "".join(" " + shlex.quote(w) for w in words)


def _run_folder(args) -> Path:
    """Move into the checkout that holds the run's folder (its config, plan and commit are the
    run's), ``--out`` and ``--readme`` kept where they were named; refuse a folder that is not a
    run's or a run whose tables are not made yet."""
    r = args.results
    if r.name != RUN_ROOT.name or not r.is_dir():
        raise SystemExit(f"{r}: not a run's folder (the `{RUN_ROOT}` folder of its checkout)")
    args.out, args.readme = args.out.resolve(), args.readme.resolve()
    os.chdir(r.resolve().parent)
    fit = RUN_ROOT / "tables" / "tab_fit.csv"
    if not fit.is_file():
        raise SystemExit(
            f"{r}: no {fit.relative_to(RUN_ROOT)}: the run has not made its tables yet "
            f"(finish it: snakemake --cores 2 {TARGET})"
        )
    return RUN_ROOT


def _wall_s(args, commit: str) -> float:
    """The run's wall time: ``--wall-s``, or the ``all`` row of the record's costs measured at
    the run's commit."""
    if args.wall_s is not None:
        return args.wall_s
    costs = record.read_costs(args.out / "costs.csv")
    row = costs[costs["name"] == "all"]
    if len(row) and str(row["commit"].iloc[0]) == commit:
        return float(row["wall_s"].iloc[0])
    raise SystemExit(
        f"no wall time for commit {commit}: run the pipeline under `python tools/timed.py "
        "--name all -- snakemake --cores 2 all`, or give --wall-s"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="?", default="results", type=Path)
    ap.add_argument("--out", default="docs/record", type=Path)
    ap.add_argument("--readme", default="README.md", type=Path)
    ap.add_argument("--wall-s", type=float, help="the run's wall time (tools/timed.py), s")
    ap.add_argument("--commit", help="the commit the run was made at (default: HEAD's hash)")
    ap.add_argument("--note", default="", help="what a reader should know of how it was made")
    ap.add_argument(
        "--config",
        nargs="+",
        default=[],
        metavar="KEY=VALUE",
        help="the run's --config overrides, as given to snakemake (profile: its tables')",
    )
    ap.add_argument(
        "--configfile",
        nargs="+",
        default=[],
        metavar="FILE",
        help="the run's --configfile overrides, as given to snakemake",
    )
    ap.add_argument("--readme-only", action="store_true")
    ap.add_argument("--pages-only", action="store_true", help="lay out the record's pages again")
    ap.add_argument(
        "--report-html",
        nargs="?",
        const=Path("results/report.html"),
        type=Path,
        help="make Snakemake's report of the run there (default results/report.html) and stop",
    )
    args = ap.parse_args()
    if args.report_html is not None:
        subprocess.run(["snakemake", "--report", str(args.report_html), "all"], check=True)
        print(f"{args.report_html}: Snakemake's report of the run (not part of the record)")
        return
    if args.pages_only:
        for p in record.derive_claims(args.out):  # the catalogue's columns, the ledger's page
            print(f"{p}: derived again from the record's claims.csv")
        print(f"{args.out}: {len(record.render_pages(args.out))} pages laid out again")
    elif not args.readme_only:
        r = _run_folder(args)
        fit = read_stamped(r / "tables" / "tab_fit.csv")
        config = _run_items(str(fit["profile"].iloc[0]), args.config)
        here = str(fit["config_hash"].iloc[0])
        outputs, benchmarks = _plan(config, args.configfile, here)
        run = record.run_files(r, outputs, benchmarks, target=TARGET)
        problems = [
            f"- {line}" for line in record.other_configs([*run.tables, r / "claims.csv"], here)
        ]
        if problems:
            problems.insert(0, f"{r}: files of {TARGET}'s plan made under another config:")
        try:
            _finished(config, args.configfile)
        except SystemExit as e:
            problems.append(str(e))
        if problems:
            raise SystemExit("\n".join(problems))
        print(f"{r}: {len(run.jobs)} benchmarked jobs of {TARGET}'s plan")
        print(run.left_out_line())
        by_stage = summarise(list(run.jobs))["by_stage"]
        commit = args.commit or git_commit()
        cfg = physgs.config.load("config/trees.yaml", str(fit["profile"].iloc[0]))
        stamp = record.Stamp(
            date=datetime.date.today().isoformat(),
            commit=commit,
            profile=str(fit["profile"].iloc[0]),
            config_hash=str(fit["config_hash"].iloc[0]),
            seeds=tuple(sorted(int(s) for s in fit["seed"].unique())),
            trees=tuple(dict.fromkeys(fit["tree"])),
            cpu=machine_cpu(),
            wall_s=_wall_s(args, commit),
            job_min_by_stage={k: sum(v.values()) / 60 for k, v in sorted(by_stage.items())},
            note=args.note,
            jobs=len(run.jobs),
            instances=record.instances_of(
                pd.read_csv(r / "tables" / "tab_testbed.csv"),
                fit["seed"].unique(),
                int(cfg["seed"]),
            ),
            overrides=tuple(shlex.split(_words(args.config, args.configfile))),
        )
        written = record.write_record(
            args.out,
            stamp=stamp,
            summary_md=r / "summary.md",
            claims_csv=r / "claims.csv",
            claims_md=r / "claims.md",
            tables=run.tables,
            figures=run.figures,
            roles=roles_of(cfg["presets"], stamp.trees),
        )
        print(f"{args.out}: {len(written)} files")
    if not (args.out / "stamp.json").is_file():
        record.render_pages(args.out)  # a folder without a run: how to make one
    found = record.found_lines(args.out)
    (args.out / "found.md").write_text("\n".join(found))
    costs = record.cost_lines(record.read_costs(args.out / "costs.csv"))
    (args.out / "costs.md").write_text("\n".join(costs) + "\n")
    text = args.readme.read_text()
    args.readme.write_text(record.replace_block(text, record.readme_block(found)))
    print(f"{args.readme}: the record block rewritten")


if __name__ == "__main__":
    main()
