"""Run a command, measure its wall time, and record it as that command's cost.

    python tools/timed.py --name all [--from-nothing] [--earlier S ...] -- snakemake --cores 2 all

Runs the command (its output goes through), then sets the row `--name` of
`docs/record/costs.csv` (`physgs.report.record.record_costs`): the command, its wall time, the
date, the commit (a plain hash) and the machine's CPU. The README's "what each command costs"
lines are printed from that file (`python tools/record.py --readme-only`). Names the README reads:
`physgs.report.record.COMMANDS`. A command that fails records nothing and passes its exit code on.

A run interrupted and resumed with the same command (a long pipeline spanning two sessions) is
one cost: give each earlier segment's wall seconds with `--earlier` (for a Snakemake run, from
its start to its last finished job in `.snakemake/log/`), and the row records their sum with
this segment's and the number of segments. `--earlier-logs .snakemake/log` reads them from
the run's Snakemake logs instead (each log with a finished job, to that job's end:
`physgs.experiments.cost.earlier_segments`), read before this segment starts its own.
"""

from __future__ import annotations

import argparse
import datetime
import shlex
import subprocess
import sys
import time
from pathlib import Path

from physgs.experiments import cost
from physgs.report import record
from physgs.provenance import git_commit, git_dirty, machine_cpu


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--name", required=True, choices=[n for n, _ in record.COMMANDS])
    ap.add_argument("--from-nothing", action="store_true", help="results/ was removed first")
    ap.add_argument(
        "--earlier",
        nargs="+",
        type=float,
        default=[],
        metavar="S",
        help="wall seconds of earlier segments of the same run (resumed with the same command)",
    )
    ap.add_argument(
        "--earlier-logs",
        type=Path,
        metavar="DIR",
        help="read the earlier segments from the run's Snakemake logs (.snakemake/log)",
    )
    ap.add_argument("--costs", default="docs/record/costs.csv", type=Path)
    ap.add_argument("command", nargs=argparse.REMAINDER)
    args = ap.parse_args()
    cmd = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not cmd:
        ap.error("no command given (after --)")
    if git_dirty():  # the row names HEAD's hash: what ran also had uncommitted changes
        print(
            f"warning: uncommitted changes; the cost is recorded at {git_commit()}", file=sys.stderr
        )
    if args.earlier_logs is not None:
        if args.earlier:
            ap.error("--earlier and --earlier-logs: give the segments one way")
        found = cost.earlier_segments(args.earlier_logs)
        for name, s in found:
            print(f"earlier segment {name}: {record.format_duration(s)}", file=sys.stderr)
        args.earlier = [s for _, s in found]
    t0 = time.monotonic()
    rc = subprocess.call(cmd)
    wall = time.monotonic() - t0 + sum(args.earlier)
    if rc != 0:
        print(f"{shlex.join(cmd)}: exit {rc}; no cost recorded", file=sys.stderr)
        return rc
    record.record_costs(
        args.costs,
        {
            "name": args.name,
            "command": shlex.join(cmd),
            "wall_s": round(wall, 1),
            "date": datetime.date.today().isoformat(),
            "commit": git_commit(),
            "cpu": machine_cpu(),
            "from_nothing": args.from_nothing,
            "segments": 1 + len(args.earlier),
        },
    )
    print(f"{args.name}: {record.format_duration(wall)} recorded in {args.costs}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
