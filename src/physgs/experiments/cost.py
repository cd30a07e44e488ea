"""What a pipeline run cost, from Snakemake's per-job benchmark files.

Every heavy rule writes ``results/benchmarks/<stage>/.../<job>.tsv`` (Snakemake ``benchmark:``),
one row with the job's wall seconds ``s``; the jobs only the ``studies`` target plans write theirs
under ``results/studies/benchmarks/``, so that a studies run adds nothing to the cost of ``all``.
The path says what the job was: its stage (first folder), its training seed (a ``seed<N>``
folder, or a ``_seed<N>`` suffix for a seeded testbed) and whether it belongs to the damping
benchmark (a ``<tree>_damping`` tree).
From those rows this module answers the questions a user asks before adding seeds: how many
job-seconds one seed costs, what is shared by all seeds (the testbeds), and what the damping
benchmark adds. Light jobs without a benchmark (tables, figures, recovery) are not counted: the
measured wall time of the run says how much they and the scheduling add.
"""

from __future__ import annotations

import csv
import datetime as dt
import math
import os
import re
import statistics
import subprocess
import sys
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from physgs.testbed.variant import DAMPING, parse_id

_SEED = re.compile(r"(?:^|_)seed(\d+)$")


@dataclass(frozen=True)
class JobCost:
    """One benchmarked job: ``stage`` (train, evaluate, ...), ``seed`` (None = shared by every
    seed), ``damping`` (part of the damping benchmark), wall seconds, its path, and when it ended
    (``end``: the benchmark file's modification time, seconds since the epoch; Snakemake writes
    it as the job finishes, so the job ran from ``end - wall_s`` to ``end``), its CPU seconds and
    peak resident memory (NaN where the file has no such column or Snakemake wrote '-').

    ``cpu_s`` and ``max_rss_mb`` are sampled: Snakemake 9.27 reads the job's processes every
    0.5 s for its first ~15 s and then every 30 s, and keeps the last reading, so a job's last
    (up to 30) seconds are missing from ``cpu_s`` (a lower bound; a 90-s training at full speed
    reads ~75) and a late peak from ``max_rss_mb``. ``wall_s`` is exact."""

    stage: str
    seed: int | None
    damping: bool
    wall_s: float
    path: str
    end: float = float("nan")
    cpu_s: float = float("nan")  # user + system CPU seconds (``cpu_time``)
    max_rss_mb: float = float("nan")  # peak resident memory, MB (``max_rss``)


def _seed_of(parts: tuple[str, ...]) -> int | None:
    for part in parts:
        m = _SEED.search(part)
        if m:
            return int(m.group(1))
    return None


def _is_damping(part: str) -> bool:
    """Whether a path part names a damping testbed: a tree folder ('medium_damping') or a testbed
    job ('stats_medium_damping_seed1'), read by the testbed ids' own parser."""
    testbed = _SEED.sub("", part).removeprefix("stats_")
    return parse_id(testbed)[1] == DAMPING


def _number(x) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):  # absent, or '-' where psutil could not measure
        return float("nan")


def read_costs(benchmark_dir, only: Collection[str] | None = None) -> list[JobCost]:
    """Every ``*.tsv`` under ``benchmark_dir`` as a JobCost, or only the files ``only`` names.

    Args:
        benchmark_dir (str | Path): the run's benchmark folder (searched recursively).
        only: the benchmark files to read, relative to ``benchmark_dir``
            (``train/sparse/seed0/ours_single.tsv``): one target's jobs of a folder that
            other targets' runs wrote into too (``physgs.report.record.run_files``).

    Returns:
        One [`JobCost`][physgs.experiments.cost.JobCost] per file, sorted by path.

    Raises:
        FileNotFoundError: if the folder is missing or holds no ``*.tsv``, or naming the files
            of ``only`` that are missing.
        ValueError: naming the file if one has no ``s`` column or no data row.
    """
    root = Path(benchmark_dir)
    if not root.is_dir():
        raise FileNotFoundError(f"{root}: no benchmark folder (run the pipeline first)")
    if only is None:
        files = sorted(root.rglob("*.tsv"))
    else:
        files = sorted({root / p for p in only})
        missing = [str(f.relative_to(root)) for f in files if not f.is_file()]
        if missing:
            raise FileNotFoundError(
                f"{root}: {len(missing)} benchmark files of the plan missing "
                f"({', '.join(missing[:5])}{', ...' if len(missing) > 5 else ''}): "
                "finish the run first"
            )
    jobs = []
    for f in files:
        with f.open() as fh:
            rows = list(csv.DictReader(fh, delimiter="\t"))
        if not rows or "s" not in rows[-1]:
            raise ValueError(
                f"{f}: not a Snakemake benchmark file (needs a header with `s` and a row)"
            )
        row = rows[-1]  # one row per run (benchmark repeats would add rows: the last counts)
        rel = f.relative_to(root)
        parts = rel.with_suffix("").parts
        jobs.append(
            JobCost(
                stage=parts[0],
                seed=_seed_of(parts[1:]),
                damping=any(_is_damping(p) for p in parts[1:]),
                wall_s=float(row["s"]),
                path=str(rel),
                end=f.stat().st_mtime,
                cpu_s=_number(row.get("cpu_time")),
                max_rss_mb=_number(row.get("max_rss")),
            )
        )
    if not jobs:
        raise FileNotFoundError(f"{root}: no benchmark files (*.tsv)")
    return jobs


def summarise(jobs: list[JobCost]) -> dict:
    """Job-seconds (wall) by stage and seed, shared (seed None) and damping-benchmark totals.

    Args:
        jobs: the benchmarked jobs.

    Returns:
        ``{"by_stage": {stage: {seed or "shared": s}}, "per_seed": {seed: s}, "shared_s": s,
            "damping_s": s, "damping_per_seed": {seed: s}, "total_s": s}``; seconds are job wall
            seconds summed (on c cores a perfectly packed run takes total_s / c).
    """
    by_stage: dict[str, dict] = {}
    per_seed: dict[int, float] = {}
    damping_per_seed: dict[int, float] = {}
    shared = damping = 0.0
    for j in jobs:
        key = "shared" if j.seed is None else j.seed
        stage = by_stage.setdefault(j.stage, {})
        stage[key] = stage.get(key, 0.0) + j.wall_s
        if j.seed is None:
            shared += j.wall_s
        else:
            per_seed[j.seed] = per_seed.get(j.seed, 0.0) + j.wall_s
        if j.damping:
            damping += j.wall_s
            if j.seed is not None:
                damping_per_seed[j.seed] = damping_per_seed.get(j.seed, 0.0) + j.wall_s
    return {
        "by_stage": by_stage,
        "per_seed": dict(sorted(per_seed.items())),
        "shared_s": shared,
        "damping_s": damping,
        "damping_per_seed": dict(sorted(damping_per_seed.items())),
        "total_s": shared + sum(per_seed.values()),
    }


def extra_seed_wall_s(summary: dict, *, run_wall_s: float) -> float:
    """Wall seconds one more seed adds to a run like the measured one: the mean per-seed
    job-seconds scaled by the run's own ratio of wall time to job-seconds (which carries the
    core count, the packing of jobs and the unbenchmarked light jobs).

    Args:
        summary: [`summarise`][physgs.experiments.cost.summarise] of the run's jobs.
        run_wall_s: the run's measured wall time, s.

    Returns:
        The extra wall time, s.

    Raises:
        ValueError: without a per-seed job or with a non-positive wall time.
    """
    if not summary["per_seed"]:
        raise ValueError("no per-seed jobs: nothing to scale")
    if not run_wall_s > 0:
        raise ValueError(f"run_wall_s = {run_wall_s}: the run's measured wall time must be > 0")
    mean_seed = sum(summary["per_seed"].values()) / len(summary["per_seed"])
    return mean_seed * run_wall_s / summary["total_s"]


def wall_spans(jobs: list[JobCost]) -> dict:
    """Elapsed wall seconds from the first job's start to the last job's end, for the whole run
    and per stage (stages overlap: jobs of different stages run side by side).

    Read from the benchmark files' times, so a run resumed after a pause counts the pause, and a
    stage rerun later spans both runs.

    Args:
        jobs: the jobs, as [`read_costs`][physgs.experiments.cost.read_costs] reads them (with end
            times).

    Returns:
        ``{"run_s": s, "by_stage": {stage: s}}``.

    Raises:
        ValueError: without jobs, or for a job without an end time.
    """
    if not jobs:
        raise ValueError("no jobs: nothing to span")
    if any(j.end != j.end for j in jobs):  # NaN: a JobCost built without its end time
        raise ValueError("a job has no end time (read the jobs with read_costs)")

    def span(js):
        return max(j.end for j in js) - min(j.end - j.wall_s for j in js)

    stages: dict[str, list[JobCost]] = {}
    for j in jobs:
        stages.setdefault(j.stage, []).append(j)
    return {"run_s": span(jobs), "by_stage": {k: span(v) for k, v in sorted(stages.items())}}


@dataclass(frozen=True)
class Occupancy:
    """How many jobs ran at once over a run (see [`occupancy`][physgs.experiments.cost.occupancy]).

    Attributes:
        bin_s: width of a bin, s.
        busy: [B] mean number of jobs running in each bin, from the first job's start.
        running: [B] the stages of the jobs running in each bin, with the job-seconds each
            spent in it (stage -> s).
        idle_core_s: core-seconds of ``cores`` left unused while at least one job ran.
        paused_s: seconds with no job running (the run stopped, or Snakemake between jobs).
    """

    bin_s: float
    busy: list[float]
    running: list[dict[str, float]]
    idle_core_s: float
    paused_s: float


def occupancy(jobs: list[JobCost], cores: int, bin_s: float = 600.0) -> Occupancy:
    """When the run's cores were busy: jobs running at once, per bin of time, and the core-time
    left unused while jobs ran (a run packs its jobs well when ``busy`` stays at ``cores``; a
    stretch below it says which stages ran alone, usually a tail of jobs that depend on each
    other or a job that needs more cores than are free).

    Each job ran from ``end - wall_s`` to ``end`` (its benchmark file's time) and counts as one
    core: every rule of the workflow runs on one thread (a job of more threads, as the K
    selection was before it ran on one, counts once). Light jobs without a benchmark file are
    not seen: a stretch where only they ran reads as paused.

    Args:
        jobs: the jobs, as [`read_costs`][physgs.experiments.cost.read_costs] reads them.
        cores: the cores the run had.
        bin_s: width of a bin, s.

    Returns:
        The [`Occupancy`][physgs.experiments.cost.Occupancy].

    Raises:
        ValueError: without jobs, for a job without an end time, or for cores or bin_s < 1.
    """
    if not jobs:
        raise ValueError("no jobs: nothing to place in time")
    if any(j.end != j.end for j in jobs):
        raise ValueError("a job has no end time (read the jobs with read_costs)")
    if cores < 1 or not bin_s >= 1:
        raise ValueError(f"occupancy needs cores >= 1 and bin_s >= 1 s (got {cores}, {bin_s})")
    t0 = min(j.end - j.wall_s for j in jobs)
    span = max(j.end for j in jobs) - t0
    n_bins = max(1, int(-(-span // bin_s)))
    busy = [0.0] * n_bins
    running: list[dict[str, float]] = [{} for _ in range(n_bins)]
    edges = []  # (time, +1 / -1): the number running changes only at a job's start or end
    for j in jobs:
        a, b = j.end - j.wall_s - t0, j.end - t0
        edges += [(a, 1), (b, -1)]
        for k in range(int(a // bin_s), min(n_bins - 1, int(b // bin_s)) + 1):
            overlap = min(b, (k + 1) * bin_s) - max(a, k * bin_s)
            if overlap > 0:
                busy[k] += overlap
                running[k][j.stage] = running[k].get(j.stage, 0.0) + overlap
    widths = [min(bin_s, span - k * bin_s) for k in range(n_bins)]
    busy = [b / w if w > 0 else 0.0 for b, w in zip(busy, widths)]
    idle = paused = 0.0
    n, last = 0, 0.0
    for t, d in sorted(edges, key=lambda e: (e[0], e[1])):
        if n == 0:
            paused += t - last
        else:
            idle += max(0, cores - n) * (t - last)
        n, last = n + d, t
    return Occupancy(bin_s, busy, running, idle, paused)


def by_job(jobs: list[JobCost]) -> dict[tuple[str, str], tuple[int, float]]:
    """Job-seconds per job of a stage over every tree and seed: what each model's trainings and
    evaluations cost a run (``train``, ``d3dgs_single``), for a user weighing a cheaper recipe.

    Args:
        jobs: the benchmarked jobs.

    Returns:
        ``(stage, job name without its seed) -> (jobs, wall seconds summed)``, largest first;
        the name ``-`` for a stage whose file is named by its seed alone (``kselect``).
    """
    out: dict[tuple[str, str], tuple[int, float]] = {}
    for j in jobs:
        key = (j.stage, _SEED.sub("", Path(j.path).stem) or "-")  # kselect/<tree>/seed<N>: "-"
        n, s = out.get(key, (0, 0.0))
        out[key] = (n + 1, s + j.wall_s)
    return dict(sorted(out.items(), key=lambda kv: -kv[1][1]))


def resources_by_stage(jobs: list[JobCost]) -> dict[str, dict]:
    """What each stage's jobs used, to size a cluster's requests from measurement: per stage
    {jobs, wall_mean_s, wall_max_s, cpu_mean_s, cpu_max_s, rss_max_mb} (NaN-free maxima and
    means over the jobs that report the quantity; NaN when none does).

    Args:
        jobs: the benchmarked jobs.

    Returns:
        Stage -> its statistics, stages sorted by name; seconds and MB.
    """

    def stats(xs):
        xs = [x for x in xs if not math.isnan(x)]
        return (sum(xs) / len(xs), max(xs)) if xs else (float("nan"), float("nan"))

    stages: dict[str, list[JobCost]] = {}
    for j in jobs:
        stages.setdefault(j.stage, []).append(j)
    out = {}
    for stage, js in sorted(stages.items()):
        wm, wx = stats([j.wall_s for j in js])
        cm, cx = stats([j.cpu_s for j in js])
        out[stage] = {
            "jobs": len(js),
            "wall_mean_s": wm,
            "wall_max_s": wx,
            "cpu_mean_s": cm,
            "cpu_max_s": cx,
            "rss_max_mb": stats([j.max_rss_mb for j in js])[1],
        }
    return out


#: A Snakemake log's name (``.snakemake/log/2026-11-29T085706.329317.snakemake.log``): its start.
_LOG_NAME = re.compile(r"^(\d{4}-\d\d-\d\dT\d{6})(?:\.\d+)?\.snakemake\.log$")
#: The time stamp Snakemake writes before each job's start and end (``[Sun Nov 29 08:57:51 2026]``).
_LOG_STAMP = re.compile(r"^\[(\w{3} \w{3} +\d+ \d\d:\d\d:\d\d \d{4})\]$")
#: A finished job, as Snakemake 8 (``Finished job 45.``) and 9 (``Finished jobid: 45 (...)``) say it.
_LOG_FINISHED = re.compile(r"^Finished job(?:id:)? \d+")


def segment_seconds(log: str | Path) -> float | None:
    """A Snakemake run's wall time up to its last finished job, from its log.

    A run cut by a session's end loses the jobs it had in flight: what it achieved ends with its
    last finished job, and a resumed run (``--rerun-incomplete``) starts those jobs again. So a
    segment counts from the log's start (its file name) to the stamp before that job's
    ``Finished`` line.

    Args:
        log: a log under ``.snakemake/log/`` (its name as Snakemake gives it).

    Returns:
        Seconds; None for a log with no finished job (a dry run, ``--unlock``, a run cut before
        its first job ended).

    Raises:
        ValueError: for a file not named as Snakemake names its logs.
    """
    m = _LOG_NAME.match(Path(log).name)
    if m is None:
        raise ValueError(f"{log}: not a Snakemake log (<date>T<hhmmss>.<us>.snakemake.log)")
    start = dt.datetime.strptime(m.group(1), "%Y-%m-%dT%H%M%S")
    stamp, last = None, None
    for line in map(str.strip, Path(log).read_text(errors="replace").splitlines()):
        if s := _LOG_STAMP.match(line):
            stamp = s.group(1)
        elif _LOG_FINISHED.match(line) and stamp is not None:
            last = stamp
    if last is None:
        return None
    end = dt.datetime.strptime(" ".join(last.split()), "%a %b %d %H:%M:%S %Y")
    return (end - start).total_seconds()


def earlier_segments(log_dir: str | Path) -> list[tuple[str, float]]:
    """The segments of a run resumed with the same command, from its ``.snakemake/log/``.

    Args:
        log_dir: the run's ``.snakemake/log`` folder (a worktree made for the run holds only its
            segments' logs and those of runs that finished no job).

    Returns:
        ``(log name, seconds)`` per log with a finished job, oldest first.

    Raises:
        FileNotFoundError: where ``log_dir`` is not a folder (a mistyped path would count none).
    """
    if not Path(log_dir).is_dir():
        raise FileNotFoundError(f"{log_dir}: no such folder of Snakemake logs")
    logs = sorted(p for p in Path(log_dir).glob("*.snakemake.log"))
    found = [(p.name, segment_seconds(p)) for p in logs]
    return [(n, s) for n, s in found if s is not None]


_BENCHMARK_LINE = re.compile(r"^\s*benchmark:\s*(\S+)\s*$")
_OUTPUT_LINE = re.compile(r"^\s*output:\s*(\S.*?)\s*$")
_RULE_LINE = re.compile(r"^\s*(?:local)?rule (\w+):\s*$")
_STATS_ROW = re.compile(r"^(\w+)\s+(\d+)\s*$")


def _job_stats(dry_run: str) -> dict[str, int]:
    """The job-stats table a dry run prints before its jobs ({rule: count}, without ``total``)."""
    lines = dry_run.splitlines()
    head = next((i for i, ln in enumerate(lines) if ln.split() == ["job", "count"]), None)
    if head is None:
        return {}
    out: dict[str, int] = {}
    for ln in lines[head + 1 :]:
        m = _STATS_ROW.match(ln.strip())
        if ln.startswith("-"):
            continue
        if not m or m.group(1) == "total":
            break
        out[m.group(1)] = int(m.group(2))
    return out


def dry_run(
    targets: Sequence[str],
    config: Sequence[str] = (),
    cwd=None,
    *,
    configfiles: Sequence[str] = (),
    forceall: bool = True,
    env: Mapping[str, str] | None = None,
) -> str:
    """Snakemake's printout of the whole plan of ``targets``: ``snakemake -n --forceall``, run in
    ``cwd`` (the workflow's folder; default the current one) whatever its ``results/`` holds.

    Args:
        targets: the targets (``["all"]``, or files).
        config: ``--config`` items (``["profile=quick"]``).
        cwd (str | Path | None): the workflow's folder.
        configfiles: ``--configfile`` paths, after ``config/trees.yaml`` (the Snakefile's).
        forceall: plan every job (the default); False: the jobs that would run now, after the
            plan's provenance check ([`physgs.provenance.check_plan`][]), which stops it.
        env: variables added to Snakemake's environment.

    Returns:
        The printout ([`plan_jobs`][physgs.experiments.cost.plan_jobs] and
            [`plan_outputs`][physgs.experiments.cost.plan_outputs] read it).

    Raises:
        RuntimeError: with the command and the end of Snakemake's error when it cannot plan.
    """
    cmd = [
        sys.executable,
        "-m",
        "snakemake",
        "-n",
        *(["--forceall"] if forceall else []),
        "--nolock",
    ]
    cmd += ["--configfile", *configfiles] if configfiles else []
    cmd += [*(["--config", *config] if config else []), "--", *targets]
    full_env = {**os.environ, **env} if env else None
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=full_env)
    if r.returncode:
        # a dry run prints its error to stdout, a real one to stderr
        raise RuntimeError(f"`{' '.join(cmd[1:])}` failed:\n{(r.stdout + r.stderr)[-6000:]}")
    return r.stdout


def plan_jobs(dry_run: str) -> list[tuple[str, str | None]]:
    """The jobs of a Snakemake dry run's printout (``snakemake -n --forceall TARGET``).

    Args:
        dry_run: the printout; each job is a ``rule <name>:`` block whose ``benchmark:`` line,
            if the rule declares one, gives the job's benchmark file.

    Returns:
        Per job, (rule name, benchmark path as printed, or None for a rule without one).

    Raises:
        ValueError: the printout has no job-stats table, or its jobs do not add up to it (a
            change of Snakemake's print format must not pass as a cheaper plan).
    """
    jobs: list[list] = []
    for line in dry_run.splitlines():
        m = _RULE_LINE.match(line)
        if m:
            jobs.append([m.group(1), None])
            continue
        b = _BENCHMARK_LINE.match(line)
        if b and jobs:
            jobs[-1][1] = b.group(1)
    stats = _job_stats(dry_run)
    if not jobs and not stats:  # "Nothing to be done": an empty plan, not an unread one
        return []
    counted: dict[str, int] = {}
    for r, _ in jobs:
        counted[r] = counted.get(r, 0) + 1
    if not stats or counted != stats:
        raise ValueError(
            "could not read the dry run's jobs: its job-stats table says "
            f"{stats or 'nothing'}, the job blocks read {counted}"
        )
    return [(r, b) for r, b in jobs]


def plan_outputs(dry_run: str) -> list[str]:
    """The output files of a Snakemake dry run's jobs (``snakemake -n --forceall TARGET``):
    what the target's plan makes, each once, in the printout's order.

    Args:
        dry_run: the printout; each job is a ``rule <name>:`` block whose ``output:`` line lists
            its outputs, comma-separated.

    Returns:
        The output paths as printed (relative to the workflow's folder).

    Raises:
        ValueError: the printout's jobs cannot be read
            ([`plan_jobs`][physgs.experiments.cost.plan_jobs]).
    """
    plan_jobs(dry_run)  # refuses a printout whose jobs do not add up to its job-stats table
    out: dict[str, None] = {}  # ordered, each path once (a job's outputs are another's inputs)
    for line in dry_run.splitlines():
        m = _OUTPUT_LINE.match(line)
        if m:
            out.update(dict.fromkeys(p.strip() for p in m.group(1).split(",")))
    return list(out)


def plan_cost(
    planned: list[tuple[str, str | None]], jobs: list[JobCost], benchmark_dir: str | Path
) -> dict:
    """What a target's plan would cost, from a finished run's measured jobs.

    Args:
        planned: the plan's jobs (``plan_jobs``).
        jobs: the finished run's benchmarked jobs (``read_costs(benchmark_dir)``).
        benchmark_dir: the folder ``jobs`` were read from (the planned paths start with it).

    Returns:
        {"job_s": benchmarked job-seconds of the planned jobs that the run measured,
        "by_rule": {rule: [jobs, job_s]}, "unmeasured": {rule: jobs} (a benchmark the run did
        not write), "light": {rule: jobs} (rules without a benchmark: tables, recovery)}.
    """
    root = Path(benchmark_dir)
    wall = {j.path: j.wall_s for j in jobs}
    out: dict = {"job_s": 0.0, "by_rule": {}, "unmeasured": {}, "light": {}}
    for rule, bench in planned:
        if bench is None:
            out["light"][rule] = out["light"].get(rule, 0) + 1
            continue
        rel = str(Path(bench).relative_to(root).with_suffix(".tsv"))
        if rel not in wall:
            out["unmeasured"][rule] = out["unmeasured"].get(rule, 0) + 1
            continue
        n, s = out["by_rule"].get(rule, (0, 0.0))
        out["by_rule"][rule] = (n + 1, s + wall[rel])
        out["job_s"] += wall[rel]
    return out


#: How near a finished job prices a job left (``left_cost``): its own kind (the benchmark path
#: without its seed), else its stage and tree (the path's first two parts), else its stage.
LEFT_MATCHES = ("kind", "tree", "stage")


def _kinds(rel: str) -> tuple[tuple[str, ...], ...]:
    """A benchmark path's keys, nearest first (``LEFT_MATCHES``): ``train/medium/seed0/mlp_single``
    -> (train, medium, mlp_single), (train, medium), (train,)."""
    parts = tuple(p for p in (_SEED.sub("", x) for x in Path(rel).with_suffix("").parts) if p)
    return parts, parts[:2], parts[:1]


def left_cost(
    planned: list[tuple[str, str | None]], jobs: list[JobCost], benchmark_dir: str | Path
) -> dict:
    """What a cut or running run has left, priced by its own finished jobs: an estimate.

    Each planned job with a benchmark costs the median wall seconds of the run's finished jobs
    nearest it (``LEFT_MATCHES``: the same job at other seeds, else its stage on its tree, else
    its stage); a job with no finished job of its stage is counted apart, never guessed. A job
    running now counts whole (its outputs are missing, so the plan holds it).

    Args:
        planned: the jobs the run would run now (``plan_jobs`` of ``snakemake -n TARGET``,
            without ``--forceall``).
        jobs: the run's finished benchmarked jobs (``read_costs(benchmark_dir)``).
        benchmark_dir: the folder ``jobs`` were read from (the planned paths start with it).

    Returns:
        {"job_s": job-seconds of the priced jobs, "done_s": job-seconds finished, "by_rule":
        {rule: (jobs, job_s)}, "by_match": {match: jobs} (``LEFT_MATCHES``), "unpriced":
        {rule: jobs}, "light": {rule: jobs} (rules without a benchmark)}.
    """
    root = Path(benchmark_dir)
    seen: dict[tuple[str, ...], list[float]] = {}
    for j in jobs:
        for key in dict.fromkeys(_kinds(j.path)):
            seen.setdefault(key, []).append(j.wall_s)
    median = {k: statistics.median(v) for k, v in seen.items()}  # once per kind, not per job
    out: dict = {"job_s": 0.0, "done_s": sum(j.wall_s for j in jobs), "by_rule": {},
                 "by_match": dict.fromkeys(LEFT_MATCHES, 0), "unpriced": {}, "light": {}}  # fmt: skip
    for rule, bench in planned:
        if bench is None:
            out["light"][rule] = out["light"].get(rule, 0) + 1
            continue
        keys = zip(LEFT_MATCHES, _kinds(str(Path(bench).relative_to(root))))
        match, s = next(((m, median[k]) for m, k in keys if k in median), (None, 0.0))
        if match is None:
            out["unpriced"][rule] = out["unpriced"].get(rule, 0) + 1
            continue
        n, total = out["by_rule"].get(rule, (0, 0.0))
        out["by_rule"][rule] = (n + 1, total + s)
        out["by_match"][match] += 1
        out["job_s"] += s
    return out


_TRAIN_JOB = re.compile(r"/train/(?P<tree>[^/]+)/seed(?P<seed>\d+)/(?P<job>[^/]+)\.tsv$")


def training_estimate(
    planned: list[tuple[str, str | None]],
    rates: dict[tuple[str, str, str], float],
    configs: list[str],
    iterations: int,
    warmup: int = 0,
    budget: Callable[[str, str], tuple[int, int]] | None = None,
) -> dict:
    """The CPU time a plan's trainings would take, from measured seconds per iteration.

    A planned job whose benchmark is ``train/<tree>/seed<s>/<model>_<config>`` (any rule that
    trains: methods, references, the K-selected trainings) costs ``warmup`` iterations at the
    static pose's rate on its tree and ``iterations - warmup`` at its own (tree, model,
    configuration)'s; a damping testbed costs as its tree (the same geometry). A job without a
    measured rate is counted apart, never guessed; other jobs (K selection, evaluation,
    recovery) are not trainings and are left out.

    Args:
        planned: the plan's jobs ([`plan_jobs`][physgs.experiments.cost.plan_jobs] of a dry run
            of the profile's target, e.g. ``snakemake -n --forceall all --config profile=paper``).
        rates: CPU seconds per iteration by ``(tree, model, configuration)``, measured at the
            profile's resolution (``benchmarks/training.py --profile paper``).
        configs: the configuration names a job name can end in (``models.configs`` and the
            others the plan trains, e.g. ``auto``).
        iterations: training iterations per job (``train.iterations``).
        warmup: the static warm-up's iterations among them (``train.warmup``).
        budget: ``(iterations, warmup)`` of a job by (tree id, model), where a profile gives
            models budgets of their own (``recipes``: ``physgs.experiments.recipe.tree_recipe``);
            None: every job trains ``iterations``.

    Returns:
        {"cpu_s": CPU seconds of the rated trainings, "longest_s": the longest one's, "jobs":
        their number, "per_seed": {seed: trainings planned}, "unrated": {(tree, model,
        configuration): jobs without a rate}}.
    """
    out: dict = {"cpu_s": 0.0, "jobs": 0, "per_seed": {}, "unrated": {}, "longest_s": 0.0}
    ends = sorted(configs, key=len, reverse=True)
    for _, bench in planned:
        m = _TRAIN_JOB.search(bench or "")
        if m is None:
            continue
        tree = parse_id(m["tree"])[0]
        seed, job = int(m["seed"]), m["job"]
        config = next((c for c in ends if job.endswith("_" + c)), "")
        model = job[: -len(config) - 1] if config else job
        out["per_seed"][seed] = out["per_seed"].get(seed, 0) + 1
        rate, static = rates.get((tree, model, config)), rates.get((tree, "static", "single"))
        it, warm = budget(m["tree"], model) if budget else (iterations, warmup)
        if rate is None or (warm and static is None):  # this job's own warm-up needs a rate
            key = (tree, model, config)
            out["unrated"][key] = out["unrated"].get(key, 0) + 1
            continue
        job_s = warm * (static or 0.0) + (it - warm) * rate
        out["cpu_s"] += job_s
        out["longest_s"] = max(out["longest_s"], job_s)
        out["jobs"] += 1
    return out
