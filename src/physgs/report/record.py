"""The committed record of a finished run: what the documentation and the README show.

A run's outputs (``results/``) are not committed; the record is: the run's stamp (date, commit,
profile, config hash, seeds, the machine's CPU, wall time and job-minutes by stage), its
``summary.md``, the claims ledger, every table as CSV and as a Markdown table, and the figures as
PNG sized for the web. The Results page includes the record's pages, which
[`render_pages`][physgs.report.record.render_pages] writes from the record's own files (so the
pages can be laid out again without a new run): the figures first, each with its caption
([`physgs.report.captions`][physgs.report.captions]), then the ledger's counts, then each table
as its summary over seeds beside its per-seed CSV, then the run's stamp and summary. The README's "what it found" and "what it costs" lines are printed from the record
by [`readme_block`][physgs.report.record.readme_block], so neither can disagree with the run they
describe.

What each command costs is measured by ``tools/timed.py`` (one row per command in
``costs.csv``, the command's last measured wall time on this machine's CPU).

Pure over paths: every function takes the files it reads and the folder it writes.
"""

from __future__ import annotations

import html
import json
import math
import re
import shlex
import shutil
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path, PurePosixPath

import numpy as np
import pandas as pd
from PIL import Image

from physgs.experiments import cost
from physgs.report import captions, catalogue, claims as ledger, rerun

#: The commands whose cost the README states, keyed as ``tools/timed.py --name`` records them.
COMMANDS: tuple[tuple[str, str], ...] = (
    ("quick_all", "snakemake --cores 2 all --config profile=quick"),
    ("tab_null", "snakemake --cores 2 results/tables/tab_null.tex"),
    ("all", "snakemake --cores 2 all"),
    ("studies", "snakemake --cores 2 studies"),
    ("tests", "python -m pytest -q"),
)
#: Widest figure in the record, px: the documentation's content column.
FIGURE_WIDTH_PX = 1200
#: Value columns of one summary table on the page: a wider table is cut into several, its key
#: columns repeated, so it reads in the content column.
VALUE_COLUMNS_SHOWN = 4
#: Lines of a summary (its rows times its parts) up to which it shows open on the Results page;
#: a longer one is folded, its heading and CSV link still shown.
OPEN_TABLE_ROWS = 30
#: Tables shown open whatever their length: the fit bar (the premise every comparison rests on)
#: and the null control's (the table the README points a reviewer to).
OPEN_TABLES = ("tab_fit", "tab_null")
#: Columns every table carries that the record's stamp already states.
STAMP_COLUMNS = ("profile", "config_hash", "physgs_version")
#: Cells moved beyond their row's seed spread that the record lists, largest first.
RERUN_CELLS_SHOWN = 10
#: The columns of the record's comparison with the one it replaces: its moved verdicts, its
#: tables and its cells moved furthest (``rerun_lines``).
RERUN_VERDICT_COLUMNS = ("claim", "before", "after", "threshold", "intervals overlap")
RERUN_TABLE_COLUMNS = (
    "table",
    "rows in both",
    "numeric cells",
    "identical",
    "within the seed spread",
    "beyond it",
)
RERUN_CELL_COLUMNS = ("table", "row", "column", "before", "after", "seed spread")
COSTS_COLUMNS = ("name", "command", "wall_s", "date", "commit", "cpu", "from_nothing", "segments")
BEGIN, END = "<!-- record:begin -->", "<!-- record:end -->"

#: Files of the record's folder that no run makes, kept when a new record replaces the old:
#: each command's measured cost (``tools/timed.py``), the paper profile's measured iteration
#: rates (``benchmarks/training.py``) and the estimate ``tools/paper_estimate.py`` computes
#: from them and today's plan.
OUTLIVE = ("costs.csv", "rates_paper.csv", "paper_estimate.md")

#: The words and units of the findings, defined once under them (the glossary says more).
WORDS = (
    "<sub>Each finding: the measured mean over seeds and its 95% interval; **holds** / **fails** "
    "when the interval lies on one side of the paper's threshold, **undecided** when it straddles "
    "it. dB: a difference of PSNR (peak signal-to-noise ratio, decibels) on held-out frames; "
    "points (pp): percentage points of relative error; fraction: a share of the true value; "
    "ratio: a quotient of errors (its interval on the log scale, so it stays positive); "
    "`sparse/0.84`: a tree under an unseen wind of 0.84 times the training speed. "
    "*Headline claim*: one of the paper's claims that carry its story (the lines below the "
    "counts); *premise*: what the comparison rests on (the fit bar, the testbed's nearest-bone "
    "gap), *finding*: what it says. *Static pose*: the Gaussians frozen at rest; *learned field*: a neural deformation field "
    "(the baselines); *untrained null*: oscillators with ω drawn over the true range, not "
    "fitted; *chained prior*: ours with each part riding on its parent; *learned forcing*: "
    "ours with the wind learned instead of measured; *from nothing*: after `rm -rf results`; "
    "*segment*: one stretch of a run resumed with the same command (the glossary defines the rest).</sub>",
)

#: A commit as the record names it: a plain (abbreviated) hash.
COMMIT = re.compile(r"^[0-9a-f]{7,40}$")


@dataclass(frozen=True)
class Stamp:
    """Where a record comes from.

    Attributes:
        date: ISO date the record was made.
        commit: the commit the run was made at: a plain hash a clone can check out.
        profile: the config profile of the run.
        config_hash: the run's config hash (the tables' stamp).
        seeds: training seeds of the run.
        trees: trees of the run.
        cpu: the machine's CPU model and its bf16/AMX flags.
        wall_s: wall time of the run, s: the time its command ran, summed over the segments
            of a run resumed after an interruption, as ``tools/timed.py`` measures it (the one
            definition the record, the costs and the README use).
        job_min_by_stage: job-minutes per stage, from the run's benchmark files.
        note: what a reader should know about how the run was made (apart from the commit).
        jobs: the run's benchmarked jobs (one benchmark file each; light jobs have none).
        instances: tree -> the testbed seeds of its tree instances (``testbed_seeds``: one per
            training seed; without, the one of ``seed``); {} in a record made before it.
        overrides: the ``--configfile`` and ``--config`` words the run was made with, as
            Snakemake's command line takes them (none: the config file as committed, at the
            stamp's profile).
    """

    date: str
    commit: str
    profile: str
    config_hash: str
    seeds: tuple[int, ...]
    trees: tuple[str, ...]
    cpu: str
    wall_s: float
    job_min_by_stage: dict[str, float] = field(default_factory=dict)
    note: str = ""
    jobs: int = 0
    instances: dict[str, list[int]] = field(default_factory=dict)
    overrides: tuple[str, ...] = ()

    def __post_init__(self):
        """Refuse a commit that is not a plain hash (a sentence, or a tag a clone lacks)."""
        if not COMMIT.match(self.commit):
            raise ValueError(
                f"stamp commit {self.commit!r}: a plain commit hash (7-40 hex digits); say the "
                "rest in the stamp's note"
            )

    def instances_words(self) -> str:
        """The trees' instances in words: ``sparse, medium: testbed seeds 0-4``.

        Returns:
            One phrase per set of testbed seeds, "; "-joined.
        """
        by: dict[tuple[int, ...], list[str]] = {}
        for t, seeds in self.instances.items():
            by.setdefault(tuple(seeds), []).append(t)
        words = [
            f"{', '.join(trees)}: {'testbed seed' if len(s) == 1 else 'testbed seeds'} "
            + ", ".join(map(str, s))
            for s, trees in by.items()
        ]
        return "; ".join(words)

    def markdown(self) -> str:
        """The stamp as a short Markdown list.

        Returns:
            Bullet lines (run, commit and date, the note if any, machine, wall time with jobs
                and job-minutes by stage) and a blank line.
        """
        stages = ", ".join(f"{k} {v:.1f}" for k, v in self.job_min_by_stage.items())
        total = sum(self.job_min_by_stage.values())
        jobs = f"{self.jobs} benchmarked jobs, " if self.jobs else ""
        return "\n".join(
            [
                f"- **Run**: profile `{self.profile}`, config hash `{self.config_hash}`, "
                f"seeds {', '.join(map(str, self.seeds))}, trees {', '.join(self.trees)}",
                *([f"- **Tree instances**: {self.instances_words()}"] if self.instances else []),
                *(
                    [f"- **Overrides**: `{overrides_words(self.overrides)}`"]
                    if self.overrides
                    else []
                ),
                f"- **Made at** commit `{self.commit}`; record written {self.date}",
                *([f"- **Note**: {self.note}"] if self.note else []),
                f"- **Machine**: {self.cpu}, 2 cores",
                f"- **Wall time** {format_duration(self.wall_s)} (the time the run's command ran, "
                f"summed over its segments; `tools/timed.py`); {jobs}{total:.0f} job-minutes"
                + (f" ({stages})" if stages else ""),
                "",
            ]
        )


def instances_of(testbed: pd.DataFrame, seeds: Sequence[int], seed: int) -> dict[str, list[int]]:
    """Each tree's instances as a run's ``tab_testbed.csv`` says (its ``instances`` column): the
    training seeds' testbed seeds where a tree has one per seed, else the one of ``seed``.

    Args:
        testbed: the run's tab_testbed CSV (``tree``, ``instances``; a table made before the
            column: one instance each).
        seeds: the run's training seeds.
        seed: the config's testbed seed (the one instance of the paper's protocol).

    Returns:
        tree -> testbed seeds.
    """
    seeds = sorted(int(x) for x in seeds)
    n = testbed["instances"] if "instances" in testbed else pd.Series(1, testbed.index)
    return {
        str(t): seeds if k > 1 and k == len(seeds) else [int(seed)]
        for t, k in zip(testbed["tree"], n)
    }


def overrides_words(overrides: Iterable[str]) -> str:
    """A run's overrides as one command-line fragment, each word quoted as a shell needs.

    Args:
        overrides: the words (``["--configfile", "config/float32.yaml"]``).

    Returns:
        The fragment (``--configfile config/float32.yaml``).
    """
    return " ".join(shlex.quote(w) for w in overrides)


def other_configs(files: Iterable[str | Path], config_hash: str) -> list[str]:
    """The files of a run, among ``files``, whose rows were made under another config.

    Every table's CSV and the ledger carry the config hash of the run that wrote them: a table
    rebuilt alone under an edited config carries the new one while the rest keep the old, and
    such a folder is no one run.

    Args:
        files: CSVs (a file without a ``config_hash`` column is not judged).
        config_hash: the run's config hash.

    Returns:
        One phrase per file that disagrees: its path and the hashes it holds.
    """
    out = []
    for f in files:
        found = config_hashes(read_run_csv(f))
        if found is not None and found != [config_hash]:
            out.append(f"{f}: config_hash {', '.join(found) or 'none'}, not {config_hash}")
    return out


def config_hashes(df: pd.DataFrame) -> list[str] | None:
    """The config hashes a table's or the ledger's rows were made under.

    Args:
        df: the table (its ``config_hash`` column read as text).

    Returns:
        The hashes, sorted; None for a table without the column (not judged).
    """
    return sorted({str(h) for h in df["config_hash"].dropna()}) if "config_hash" in df else None


def read_run_csv(path: str | Path) -> pd.DataFrame:
    """A table's or the ledger's CSV of a run.

    Args:
        path: the CSV.

    Returns:
        Its rows, the config hash read as text (a hash of digits stays one).
    """
    return pd.read_csv(path, dtype={"config_hash": str})


def format_duration(seconds: float) -> str:
    """``3 h 8 min``, ``29 min 9 s`` or ``42 s``; ``--`` for a missing value.

    Args:
        seconds: a duration, s (NaN or inf: missing).

    Returns:
        The duration in words, rounded to the second.
    """
    if not math.isfinite(seconds):
        return "--"
    s = round(seconds)
    h, rest = divmod(s, 3600)
    m, s = divmod(rest, 60)
    if h:
        return f"{h} h {m} min"
    return f"{m} min {s} s" if m else f"{s} s"


def _cell(x) -> str:
    if isinstance(x, (float, np.floating)):
        if not math.isfinite(x):
            return "--"
        return f"{x:.4g}"
    if x is None:
        return "--"
    return str(x).replace("|", "\\|")


def markdown_table(df: pd.DataFrame, right: Iterable[str] = ()) -> str:
    """A DataFrame as a Markdown table; floats to 4 significant digits, NaN as ``--``: every
    table of the record and of the run's summary is written here.

    Args:
        df: the table (its index is dropped).
        right: the columns aligned right (counts read down a column).

    Returns:
        The table's lines, ending in a newline.
    """
    rule = "".join("---:|" if c in set(right) else "---|" for c in df.columns)
    lines = ["| " + " | ".join(map(str, df.columns)) + " |", "|" + rule]
    lines += ["| " + " | ".join(map(_cell, row)) + " |" for row in df.itertuples(index=False)]
    return "\n".join(lines) + "\n"


def demote(markdown: str) -> str:
    """Every Markdown heading one level down (``# x`` -> ``## x``), so that an included page sits
    under the including page's title.

    Args:
        markdown: the page's text.

    Returns:
        The text, headings one ``#`` deeper.
    """
    return re.sub(r"^#+ ", r"#\g<0>", markdown, flags=re.MULTILINE)


def _png_for_web(src: Path, dst: Path) -> None:
    """Copy a PNG, downscaled to ``FIGURE_WIDTH_PX`` wide if wider."""
    with Image.open(src) as im:
        if im.width > FIGURE_WIDTH_PX:
            h = round(im.height * FIGURE_WIDTH_PX / im.width)
            im = im.resize((FIGURE_WIDTH_PX, h), Image.LANCZOS)
        im.save(dst, optimize=True)


def _same_run(a: Mapping, b: Mapping) -> bool:
    """Two stamps of one run (its record rewritten, say to add the Snakemake report)."""

    def plain(v):  # a stamp read from JSON holds lists where the dataclass holds tuples
        return list(v) if isinstance(v, (list, tuple)) else v

    keys = ("commit", "config_hash", "profile", "seeds", "trees")
    return all(plain(a.get(k)) == plain(b.get(k)) for k in keys)


def rerun_lines(
    previous: str | Path, stamp: Stamp, claims_csv: str | Path, tables: Sequence[str | Path]
) -> list[str]:
    """The record's "Against the previous record" section: this run's ledger verdict by verdict
    and its seeded tables cell by cell against the record it replaces
    ([`physgs.report.rerun`][physgs.report.rerun]).

    A change that only reorders floating-point work moves every training's trajectory; this says
    which verdicts and how many numbers moved, and whether beyond the seeds' own spread.

    Args:
        previous: the record folder being replaced (``stamp.json``, ``claims.csv``,
            ``tables/*.csv``).
        stamp: this run's stamp.
        claims_csv: this run's ledger.
        tables: this run's table CSVs.

    Returns:
        The section's Markdown lines (heading included); a line saying there is nothing to
            compare with when ``previous`` holds no record.
    """
    prev = Path(previous)
    head = ["## Against the previous record", ""]
    if not ((prev / "stamp.json").is_file() and (prev / "claims.csv").is_file()):
        return [*head, "No earlier record to compare with.", ""]
    old = json.loads((prev / "stamp.json").read_text())
    settings = (
        "the same config hash"
        if old.get("config_hash") == stamp.config_hash
        else f"config hash `{old.get('config_hash')}`: the comparison spans a change of settings"
    )
    c = rerun.compare_claims(read_run_csv(prev / "claims.csv"), read_run_csv(claims_csv))
    apart = f" ({len(c.only_new)} claims new in this run, {len(c.only_old)} no longer asked.)"
    lines = [
        *head,
        f"This run (commit `{stamp.commit}`) against the record it replaced: commit "
        f"`{old.get('commit')}`, written {old.get('date')}, {settings}. What changed between the "
        "two commits is in `CHANGELOG.md`; `python tools/compare_runs.py OLD NEW` repeats the "
        "tables' comparison for any two runs.",
        "",
        f"**The ledger**: {c.same} of {c.same + len(c.changed)} claims in both runs keep their "
        "verdict"
        + (f", {len(c.changed)} changed:" if c.changed else ".")
        + (apart if c.only_new or c.only_old else ""),
        "",
    ]
    if c.changed:
        verdicts = pd.DataFrame(
            [
                (f"`{v.id}`: {v.claim}", f"{v.old}, {v.old_value}", f"**{v.new}**, {v.new_value}")
                + (v.threshold, v.overlap)
                for v in c.changed
            ],
            columns=RERUN_VERDICT_COLUMNS,
        )
        n = Counter(v.overlap for v in c.changed)
        lines += [
            *markdown_table(verdicts).splitlines(),
            "",
            f"Of the {len(c.changed)} moved verdicts, {n['yes']} moved with overlapping intervals "
            f"(within the seeds' noise: an interval that now clears or now touches its "
            f"threshold), {n['no']} with intervals apart (the runs disagree beyond that noise)"
            + (f", {n['--']} without an interval in one of the runs" if n["--"] else "")
            + ".",
            "",
        ]
    rows, moved = [], []
    for t in sorted(Path(p) for p in tables):
        before = prev / "tables" / t.name
        if not before.is_file():
            continue
        a, b = read_run_csv(before), read_run_csv(t)
        if "seed" not in a.columns or "seed" not in b.columns:
            same = "identical" if a.equals(b) else "changed"
            rows.append((f"`{t.stem}` (not seeded)", len(b), "", same, "", ""))
            continue
        r = rerun.compare_table_csv(before, t)
        rows.append((f"`{t.stem}`", r.rows, r.cells, r.identical, r.within, len(r.beyond)))
        moved += [(t.stem, ch) for ch in r.beyond]
    tabled = pd.DataFrame(rows, columns=RERUN_TABLE_COLUMNS)
    lines += [
        "**The seeded tables**, each numeric cell beside the previous run's spread (max - min) "
        "over seeds of its row; job timings are left out:",
        "",
        *markdown_table(tabled, right=RERUN_TABLE_COLUMNS[1:]).splitlines(),
        "",
    ]
    if moved:
        moved.sort(key=lambda m: rerun.spreads_moved(m[1]), reverse=True)
        cells = pd.DataFrame(
            [
                (f"`{name}`", ", ".join(f"{k} {v}" for k, v in ch.key.items()), f"`{ch.column}`")
                + (ch.old, ch.new, ch.spread)
                for name, ch in moved[:RERUN_CELLS_SHOWN]
            ],
            columns=RERUN_CELL_COLUMNS,
        )
        lines += [
            f"The largest moves beyond the spread ({len(cells)} of {len(moved)}):",
            "",
            *markdown_table(cells, right=RERUN_CELL_COLUMNS[3:]).splitlines(),
            "",
        ]
    return lines


#: What the record takes of a run's folder (``results/``), as the workflow lays it out: each
#: table's CSV and each figure's PNG (folder, suffix), and the jobs' benchmark files (below
#: ``benchmarks/``, ``physgs.experiments.cost``).
RUN_FILES = {"tables": ("tables", ".csv"), "figures": ("figures", ".png")}
BENCHMARKS = "benchmarks"


@dataclass(frozen=True)
class RunFiles:
    """The files of a finished run that its record takes: exactly what its target's plan makes
    ([`run_files`][physgs.report.record.run_files]).

    Attributes:
        target: the target whose plan it is (``all``).
        tables: the plan's table CSVs, sorted.
        figures: the plan's figure PNGs, sorted.
        jobs: the plan's benchmarked jobs, one per benchmark file
            ([`JobCost`][physgs.experiments.cost.JobCost]).
        left_out: the tables, figures and benchmark files the folder holds that the plan does
            not make (another target's, such as ``studies``, or an earlier run's), relative to
            the folder, sorted.
    """

    target: str
    tables: tuple[Path, ...]
    figures: tuple[Path, ...]
    jobs: tuple[cost.JobCost, ...]
    left_out: tuple[str, ...] = ()

    def left_out_line(self) -> str:
        """What was left out, in a line: the tables and figures by name, the benchmark files
        counted by stage.

        Returns:
            ``left out (not made by all): tables/x.csv, ...; N benchmark files (stage n, ...)``,
                or ``left out (not made by all): nothing``.
        """
        parts = [PurePosixPath(p).parts for p in self.left_out]
        files = [p for p, (top, *_) in zip(self.left_out, parts) if top != BENCHMARKS]
        stages = Counter(x[1] for x in parts if x[0] == BENCHMARKS)
        by_stage = ", ".join(f"{k} {n}" for k, n in sorted(stages.items()))
        bench = f"{stages.total()} benchmark files ({by_stage})" if stages else ""
        what = "; ".join(x for x in (", ".join(files), bench) if x) or "nothing"
        return f"left out (not made by {self.target}): {what}"


def run_files(
    results: str | Path,
    outputs: Iterable[str],
    benchmarks: Iterable[str],
    target: str = "all",
) -> RunFiles:
    """The tables, figures and benchmarked jobs of a run's folder that its target's plan makes.

    A folder may hold more than one target's files (``snakemake studies`` run in it after
    ``all``, or an earlier run's): the record of ``all`` takes ``all``'s alone, so its stamp's
    jobs and job-minutes are those of the run whose wall time it states. The plan is
    Snakemake's own (``snakemake -n --forceall all``: the jobs' outputs and benchmark files,
    [`plan_outputs`][physgs.experiments.cost.plan_outputs] and
    [`plan_jobs`][physgs.experiments.cost.plan_jobs]), so no second list of what ``all`` makes
    is kept here.

    Args:
        results: the run's folder (``results/``).
        outputs: every output file of the plan, relative to ``results``
            (``tables/tab_fit.csv``); those outside ``RUN_FILES`` are not the record's.
        benchmarks: every benchmark file of the plan, relative to ``results``
            (``benchmarks/train/sparse/seed0/ours_single.tsv``).
        target: the plan's target, named in messages.

    Returns:
        The [`RunFiles`][physgs.report.record.RunFiles].

    Raises:
        FileNotFoundError: naming every table or figure of the plan that the folder lacks, or
            the benchmark files of the plan it lacks (an unfinished run, or another config's).
    """
    root = Path(results)
    made = {PurePosixPath(p) for p in outputs}
    picked: dict[str, list[Path]] = {}
    missing: list[str] = []
    left_out: list[str] = []
    for kind, (folder, suffix) in RUN_FILES.items():
        planned = {p for p in made if p.parent == PurePosixPath(folder) and p.suffix == suffix}
        missing += sorted(str(p) for p in planned if not (root / p).is_file())
        picked[kind] = sorted(root / p for p in planned)
        present = {PurePosixPath(folder, f.name) for f in (root / folder).glob(f"*{suffix}")}
        left_out += [str(p) for p in present - planned]
    if missing:
        raise FileNotFoundError(
            f"{root}: {', '.join(missing)} missing: {target} makes them (finish the run: "
            f"snakemake --cores 2 {target})"
        )
    bench = {PurePosixPath(p).relative_to(BENCHMARKS).as_posix() for p in benchmarks}
    jobs = cost.read_costs(root / BENCHMARKS, only=bench)
    present = {
        f.relative_to(root / BENCHMARKS).as_posix() for f in (root / BENCHMARKS).rglob("*.tsv")
    }
    left_out += [f"{BENCHMARKS}/{p}" for p in present - bench]
    return RunFiles(
        target,
        tuple(picked["tables"]),
        tuple(picked["figures"]),
        tuple(jobs),
        tuple(sorted(left_out)),
    )


def _remove(path: Path) -> None:
    """Remove ``path``, a folder or a file, if it is there."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif path.exists() or path.is_symlink():
        path.unlink()


def _settle_swap(final: Path) -> None:
    """Finish what a write of the record at ``final`` left undone when it stopped.

    A write swaps the records by two renames (``final`` to ``final.old``, ``final.partial`` to
    ``final``) and then removes ``final.old``. Stopped between the renames, it leaves the last
    record as ``final.old`` and no ``final``: that record is put back. Stopped after them, or
    unable to remove it, it leaves a ``final.old`` beside a ``final`` that is the newer record:
    it is removed (a rename onto a folder that is not empty fails, ``OSError`` 39).
    """
    old = final.with_name(final.name + ".old")
    if not (old.exists() or old.is_symlink()):
        return
    if final.exists():
        print(f"{old}: left by an earlier write of the record after its swap; removed")
        _remove(old)
    else:
        print(f"{old}: the last record, left there by a write that stopped; put back at {final}")
        old.rename(final)


def write_record(
    out_dir: str | Path,
    *,
    stamp: Stamp,
    summary_md: str | Path,
    claims_csv: str | Path,
    claims_md: str | Path,
    tables: Sequence[str | Path],
    figures: Sequence[str | Path],
) -> list[Path]:
    """Write a run's record into ``out_dir`` (replacing the record there).

    Snakemake's report of a run is not part of the record (it is ~10 MB: every clone would
    carry each record's); ``tools/record.py --report-html`` makes it into ``results/``. What an
    earlier write left when it stopped is settled first, and said: a ``<out_dir>.partial`` is
    removed, a ``<out_dir>.old`` beside the record is removed, and one without a record beside
    it (the last record, stopped between the swap's renames) is put back.

    Args:
        out_dir: the record's folder (the project keeps it at ``docs/record``).
        stamp: where the run comes from.
        summary_md: the run's ``summary.md``.
        claims_csv: the claims ledger as CSV.
        claims_md: the claims ledger as Markdown.
        tables: the run's table CSVs; each becomes ``tables/<name>.csv`` and its summary
            ``tables/<name>.md``.
        figures: the run's figure PNGs; each becomes ``figures/<name>.png``, web-sized.

    Returns:
        The files written.

    Raises:
        FileNotFoundError: naming the first input that is missing.
    """
    inputs = [Path(p) for p in (summary_md, claims_csv, claims_md, *tables, *figures)]
    for p in inputs:
        if not p.is_file():
            raise FileNotFoundError(f"{p}: missing; finish the run first (snakemake --cores 2 all)")
    final = Path(out_dir)
    _settle_swap(final)
    kept = {n: (final / n).read_bytes() for n in OUTLIVE if (final / n).is_file()}
    # against the record this one replaces; the same run recorded again keeps its comparison
    old_stamp = final / "stamp.json"
    if (
        old_stamp.is_file()
        and (final / "rerun.md").is_file()
        and _same_run(json.loads(old_stamp.read_text()), asdict(stamp))
    ):
        against = (final / "rerun.md").read_text()
    else:
        against = "\n".join(rerun_lines(final, stamp, claims_csv, tables))
    out = final.with_name(final.name + ".partial")  # the old record stands until this is whole
    _remove(out)  # an earlier write that stopped before its swap
    (out / "tables").mkdir(parents=True)
    (out / "figures").mkdir()
    for name, data in kept.items():
        (out / name).write_bytes(data)
    (out / "stamp.json").write_text(json.dumps(asdict(stamp), indent=2) + "\n")
    (out / "rerun.md").write_text(against)
    for name, page in (("summary.md", summary_md), ("claims.md", claims_md)):
        (out / name).write_text(demote(Path(page).read_text()))
    shutil.copyfile(claims_csv, out / "claims.csv")
    for t in map(Path, tables):
        shutil.copyfile(t, out / "tables" / t.name)
    for f in map(Path, figures):
        _png_for_web(f, out / "figures" / f.name)
    render_pages(out)
    written = sorted(final / p.relative_to(out) for p in out.rglob("*") if p.is_file())
    old = final.with_name(final.name + ".old")
    if final.exists():
        final.rename(old)
    out.rename(final)
    _remove(old)
    return written


def _mean_sd(values: pd.Series) -> str:
    """``mean ± sd`` of a column's per-seed values (NaN dropped): the value alone where the seeds
    agree (to rounding) or one seed has it, ``--`` where none has."""
    v = pd.to_numeric(values, errors="coerce").dropna()
    if v.empty:
        return "--"
    m, sd = float(v.mean()), float(v.std(ddof=1)) if len(v) > 1 else 0.0
    if sd <= 1e-9 * max(1.0, abs(m)):  # a quantity the seeds do not change (the testbed's)
        return _cell(m)
    return f"{m:.4g} ± {sd:.2g}"


def table_summary(df: pd.DataFrame) -> tuple[pd.DataFrame, list[str], list[int]]:
    """A per-seed table as its summary over seeds: one row per key, each value column as
    ``mean ± sd`` over the seeds (NaN seeds left out; the value alone where the seeds agree).

    The keys are the text and true/false columns (tree, model, configuration...); the stamp's columns are
    dropped, and so are columns with no value. A table without a ``seed`` column is returned as
    it is, its keys its text columns.

    Args:
        df: the table, one row per seed (its CSV as read with the stamp's columns as text).

    Returns:
        ``(summary, key columns, seeds)``: the summary's cells as text, the key columns in
            the table's order, the seeds summarised over (empty without a seed column).
    """
    df = df.drop(columns=[c for c in STAMP_COLUMNS if c in df]).dropna(axis=1, how="all")
    keys = [c for c in df.columns if c != "seed" and not pd.api.types.is_numeric_dtype(df[c])]
    if "seed" not in df:
        return df.map(_cell).reset_index(drop=True), keys, []
    seeds = sorted(int(x) for x in df["seed"].unique())
    values = df.drop(columns=[*keys, "seed"])
    if not keys:
        return pd.DataFrame([values.agg(_mean_sd)]), keys, seeds
    summary = values.groupby([df[k] for k in keys], sort=False, dropna=False).agg(_mean_sd)
    summary = summary.reset_index()
    summary[keys] = summary[keys].map(_cell)
    return summary, keys, seeds


def summary_markdown(df: pd.DataFrame) -> str:
    """[`table_summary`][physgs.report.record.table_summary] as Markdown tables of at most
    ``VALUE_COLUMNS_SHOWN`` value columns each, the key columns repeated.

    Args:
        df: the table, one row per seed.

    Returns:
        The tables' lines, blank-line separated, ending in a newline.
    """
    summary, keys, _ = table_summary(df)
    values = [c for c in summary.columns if c not in keys]
    parts = [
        values[i : i + VALUE_COLUMNS_SHOWN] for i in range(0, len(values), VALUE_COLUMNS_SHOWN)
    ]
    # a long column name may break after an underscore (<wbr>: no character when copied)
    heads = {c: str(c).replace("_", "_<wbr>") for c in summary.columns}
    return "\n".join(
        markdown_table(summary[keys + cols].rename(columns=heads)) for cols in parts or [[]]
    )


#: The ledger's columns the catalogue derives from a claim's id: a record written before one of
#: them gains it from its own ids (``derive_claims``), placed after the column named.
DERIVED_COLUMNS = {"kind": "origin"}


def derive_claims(record_dir: str | Path) -> list[Path]:
    """Give a record's ledger the columns the catalogue derives from its ids that it lacks
    (``DERIVED_COLUMNS``: ``kind``), and print its ``claims.md`` and the claims section of its
    ``summary.md`` again from that ``claims.csv`` with the rules' own printers
    (``claims.ledger_markdown`` with the CSV's stamp columns, ``summary.claims_section``): on a
    ledger of today's columns and today's printers they print what the run printed. No number is
    touched: the CSV is read and written back as text.

    Args:
        record_dir: the record folder (``claims.csv``).

    Returns:
        The files that changed; none when the ledger and its page are up to date.
    """
    out = Path(record_dir)
    path, page = out / "claims.csv", out / "claims.md"
    written = []
    text = pd.read_csv(path, dtype=str, keep_default_na=False)
    missing = [c for c in DERIVED_COLUMNS if c not in text.columns]
    for name in missing:
        after = DERIVED_COLUMNS[name]
        at = text.columns.get_loc(after) + 1 if after in text else len(text.columns)
        text.insert(at, name, ledger.column(text, name))
    if missing:
        text.to_csv(path, index=False)
        written.append(path)
    df = read_run_csv(path)
    stamp = {c: str(df[c].iloc[0]) for c in STAMP_COLUMNS if c in df and len(df)}
    pages = {page: demote(ledger.ledger_markdown(df, stamp or None))}
    if (out / "summary.md").is_file():
        pages[out / "summary.md"] = _claims_section_again((out / "summary.md").read_text(), df)
    for p, printed in pages.items():
        if not p.is_file() or p.read_text() != printed:
            p.write_text(printed)
            written.append(p)
    return written


#: The heading of the run summary's claims section as the record holds it (demoted).
SUMMARY_CLAIMS = "### Claims ledger"


def _claims_section_again(text: str, claims: pd.DataFrame) -> str:
    """The record's ``summary.md`` with its claims section printed again from ``claims``
    (``summary.claims_section``, the summary rule's own printer); the rest, made from files the
    record does not keep (the benchmarks), as it was. Unchanged without the section."""
    from physgs.report.summary import claims_section  # summary imports this module

    lines = text.split("\n")
    if SUMMARY_CLAIMS not in lines:
        return text
    a = lines.index(SUMMARY_CLAIMS)
    b = next((i for i in range(a + 1, len(lines)) if lines[i].startswith("### ")), len(lines))
    section = demote("\n".join(claims_section(claims))).split("\n")
    return "\n".join([*lines[:a], *section, *lines[b:]])


#: The Results page's part the record lays out (``index.md``): its figures, its ledger's counts,
#: its tables and its run, each included from its own page.
INDEX_PAGE = """\
From the run at commit `{commit}` (profile `{profile}`, training seeds {seeds}; its stamp: [the run](#the-run)).

## Figures

--8<-- "docs/record/figures.md"

## The paper against the measured

{ledger}

## Tables

Each table of the run as its summary over seeds (a wide table cut into several, its key columns repeated); the per-seed rows are in the CSV beside it.

--8<-- "docs/record/tables.md"

## The run

--8<-- "docs/record/stamp.md"

Snakemake's report of a run (every table, figure and job, browsable) is made on demand, not kept in the record: after the run, `python tools/record.py --report-html` writes `results/report.html`.

??? note "The run's own summary (`results/summary.md`): every verdict with its interval, each model's fit, what the run cost"

    --8<-- "docs/record/summary.md"

--8<-- "docs/record/rerun.md"
"""
#: One table's entry on the Results page (``tables.md``): where its rows come from, its CSV, and
#: its summary over seeds (``fold``: open, ``???+``, or folded, ``???``).
TABLE_ENTRY = """\
### `{name}`

{over}; every seed's row: [{name}.csv](record/tables/{name}.csv) ({rows} rows).

{fold} note "{name}: the summary, {shown} rows"

    --8<-- "docs/record/tables/{name}.md"
"""


def render_pages(record_dir: str | Path) -> list[Path]:
    """Lay out the record's pages from its own files: the Results page's parts.

    From ``stamp.json``, ``claims.csv``, ``tables/*.csv`` and ``figures/*.png`` of the record,
    writes ``stamp.md``, ``figures.md`` (each figure with its caption, in reading order),
    ``tables/<name>.md`` (each table's summary over seeds), ``tables.md`` (the summaries, each
    beside a link to its per-seed CSV) and ``index.md`` (figures, then the ledger's counts, then
    the tables, then the run). No run is needed: ``tools/record.py --pages-only`` calls it on the
    committed record.

    Args:
        record_dir: the record folder.

    Returns:
        The files written.

    Raises:
        KeyError: naming a figure without a caption (``physgs.report.captions``).
    """
    out = Path(record_dir)
    stamp = Stamp(**json.loads((out / "stamp.json").read_text()))
    pages = {"stamp.md": stamp.markdown()}
    entries = []
    for t in sorted((out / "tables").glob("*.csv")):
        df = pd.read_csv(t, dtype={c: str for c in STAMP_COLUMNS})
        summary, _, seeds = table_summary(df)
        pages[f"tables/{t.stem}.md"] = text = summary_markdown(df)
        over = (
            f"mean ± sd over training seeds {', '.join(map(str, seeds))}"
            if len(seeds) > 1
            else ("training seed " + str(seeds[0]) if seeds else "not seeded: as the run wrote it")
        )
        lines = len(summary) * (text.count("\n\n") + 1)  # rows of all its parts
        # a long summary folds away (Material's collapsible block), a short one shows open
        fold = "???+" if lines <= OPEN_TABLE_ROWS or t.stem in OPEN_TABLES else "???"
        entries.append(
            TABLE_ENTRY.format(name=t.stem, over=over, rows=len(df), fold=fold, shown=len(summary))
        )
    pages["tables.md"] = "\n".join(entries)
    names = captions.order([f.stem for f in (out / "figures").glob("*.png")], stamp.trees)
    pages["figures.md"] = "\n".join(
        f"![{n}](record/figures/{n}.png)\n\n{captions.caption(n, stamp.seeds)}\n" for n in names
    )
    pages["ledger.md"] = ledger_page(out / "claims.csv", stamp.trees)
    pages["index.md"] = INDEX_PAGE.format(
        commit=stamp.commit,
        profile=stamp.profile,
        seeds=", ".join(map(str, stamp.seeds)),
        ledger="\n".join(ledger_lines(out / "claims.csv")),
    )
    for name, text in pages.items():
        (out / name).write_text(text)
    return [out / name for name in pages]


def _value_text(r: pd.Series) -> str:
    """A ledger row's measured mean and 95% interval, ``+2.26 [+1.94, +2.57] dB`` (``--``
    unmeasured, the value alone where one value gives no interval)."""
    if not math.isfinite(r["measured"]):
        return "--"
    if math.isfinite(r["ci_low"]):
        n = [ledger.number(r[c], r["unit"]) for c in ("measured", "ci_low", "ci_high")]
        return f"{n[0]} [{n[1]}, {n[2]}] {r['unit']}"
    return f"{ledger.number(r['measured'], r['unit'])} {r['unit']} (one value)"


def _tree_and_claim(text: str, trees: Sequence[str]) -> tuple[str, str]:
    """A claim's sentence as its tree and the rest (``sparse: ours is ...`` -> ``sparse``,
    ``ours is ...``); no tree where the sentence does not start with one."""
    for t in trees:
        if text.startswith(t) and text[len(t) : len(t) + 1] in (":", ",", " "):
            return t, text[len(t) :].lstrip(":, ")
    return "", text


#: The ledger page's columns (``ledger_page``).
LEDGER_COLUMNS = (
    "claim (click for the full claim)",
    "tree",
    "the paper",
    "measured: mean [95% interval]",
    "verdict",
    "kind",
    "origin",
)


def ledger_page(claims_csv: str | Path, trees: Sequence[str]) -> str:
    """The ledger page's table (``docs/ledger.md`` includes it): one compact row per claim, the
    paper's claims first, each with its tree, the paper's value, the measured mean and 95%
    interval, the verdict (coloured by ``docs/stylesheets/ledger.css``) and its kind; the full
    sentence, the threshold, the table cells it comes from and, for a premise, what its failure
    undermines, one click away (the row's ``<details>``). Each row carries its origin, verdict,
    tree and kind as data attributes, which ``docs/javascripts/ledger.js`` filters by.

    Args:
        claims_csv: the record's ``claims.csv``.
        trees: the run's trees (a sentence's leading tree becomes the tree column).

    Returns:
        The page part: raw HTML, ending in a newline.
    """
    claims = read_run_csv(claims_csv)
    # a ledger of fewer columns (an older or a partial one) shows what it has
    shown = {"paper": "--", "source": "--", "threshold": "", "unit": "", "seeds": 0}
    shown |= {c: np.nan for c in ("measured", "ci_low", "ci_high")}
    claims = claims.assign(**{c: v for c, v in shown.items() if c not in claims})
    if "claim" not in claims:
        claims["claim"] = claims["id"]
    claims = claims.assign(
        _origin=ledger.column(claims, "origin"),
        _kind=ledger.column(claims, "kind"),
        _verdict=claims["verdict"].map(rerun.verdict_kind),
    )
    order = {o: i for i, o in enumerate(catalogue.ORIGINS)}  # the paper's first
    claims = claims.iloc[claims["_origin"].map(order).argsort(kind="stable")]
    e = html.escape
    rows = []
    for _, r in claims.iterrows():
        tree, short = _tree_and_claim(str(r["claim"]), trees)
        more = [
            f"<b>{e(str(r['claim']))}</b>",
            f"id <code>{e(str(r['id']))}</code>; {e(r['_origin'])}'s {r['_kind']}",
            f"holds when the value is {e(str(r['threshold']))} {e(str(r['unit']))}; "
            f"{int(r['seeds'])} seed{'s' if int(r['seeds']) != 1 else ''}",
            f"from {e(str(r['source']))}",
        ]
        if str(r["verdict"]) != r["_verdict"]:
            more.append(e(str(r["verdict"])))
        if ledger.decide_cell(r):
            more.append(f"seeds that would decide it (est.): {e(ledger.decide_cell(r))}")
        if r["_kind"] == "premise":
            more.append(f"if it fails, it undermines {e(catalogue.undermines(str(r['id'])))}")
        anchor = "claim-" + re.sub(r"[^a-z0-9]+", "-", str(r["id"]).lower()).strip("-")
        rows.append(
            f'<tr id="{anchor}" data-origin="{e(r["_origin"])}" data-verdict="{r["_verdict"]}" '
            f'data-tree="{e(tree or "--")}" data-kind="{r["_kind"]}">'
            f"<td><details><summary>{e(short)}</summary>{'<br>'.join(more)}</details></td>"
            f"<td>{e(tree or '--')}</td><td>{e(str(r['paper']))}</td>"
            f"<td>{e(_value_text(r))}</td>"
            f'<td class="verdict-{r["_verdict"]}">{r["_verdict"]}</td>'
            f"<td>{r['_kind']}</td><td>{e(r['_origin'])}</td></tr>"
        )
    head = "".join(f"<th>{h}</th>" for h in LEDGER_COLUMNS)
    body = "".join(row + "\n" for row in rows)
    return f'<table class="ledger">\n<thead><tr>{head}</tr></thead>\n<tbody>\n{body}</tbody>\n</table>\n'


def ledger_lines(claims_csv: str | Path) -> list[str]:
    """The Results page's pointer to the ledger: its verdicts counted, and where the paper's value
    stands beside the measured one.

    Args:
        claims_csv: the record's ``claims.csv``.

    Returns:
        The Markdown lines.
    """
    claims = read_run_csv(claims_csv)
    story, premise = story_line(claims), premise_line(claims)
    return [
        f"The ledger holds the paper's {ledger.counted(claims, 'paper')}; and this project's own "
        f"{ledger.counted(claims, 'project')} (95% intervals over seeds; a premise is what the "
        "comparison rests on, a finding what it says). Each claim with the paper's value beside "
        "the measured one, its verdict and the table cells it comes from: "
        "[the paper against the measured](ledger.md).",
        *(["", premise[2:]] if premise else []),
        *(["", story[2:]] if story else []),
    ]


def write_unrecorded(out_dir: str | Path) -> Path:
    """``index.md`` of a record folder that holds no run yet, saying how to make one.

    Args:
        out_dir: the record folder (made if missing).

    Returns:
        The path of the ``index.md`` written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    (out / "index.md").write_text(
        "No full run is recorded yet. After `snakemake --cores 2 all` at the default profile, "
        "`python tools/record.py results` writes it here.\n"
    )
    return out / "index.md"


def count_line(claims: pd.DataFrame) -> str:
    """The ledger's counts, the paper's claims first and this project's apart, each with its
    findings apart from the premises of the comparison (``claims.counted``).

    Args:
        claims: the ledger (``id``, ``verdict``; ``origin``, ``kind`` where written).

    Returns:
        One Markdown bullet.
    """
    return (
        f"- **The paper's {ledger.counted(claims, 'paper')}**; this project's own "
        f"{ledger.counted(claims, 'project')} (95% intervals over seeds; a *premise* is what the "
        "comparison rests on, a *finding* what it says)."
    )


def premise_line(claims: pd.DataFrame) -> str:
    """The premises that fail and what each undermines (``claims.failed_premises``).

    Args:
        claims: the ledger.

    Returns:
        One Markdown bullet; "" when every premise holds.
    """
    failed = ledger.failed_premises(claims)
    return (
        f"- **Premises that fail**: {'; '.join(f.rstrip('.') for f in failed)}." if failed else ""
    )


def _headline_families(claims: pd.DataFrame, origin: str | None = None):
    """The headline families (``catalogue.headline``, of ``origin`` if given) the ledger holds,
    in the catalogue's order: their words, their claims (the id is the family's, or starts with
    it + "/"), each claim's cell (the id past the family's; ``all`` for the family's own) and
    verdict kind."""
    ids = claims["id"].astype(str)
    for fam, words, of in catalogue.headline():
        rows = (ids == fam) | ids.str.startswith(fam + "/")
        if rows.any() and origin in (None, of):
            cells = ids[rows].str[len(fam) + 1 :].replace("", "all")
            yield words, claims[rows], cells, claims.loc[rows, "verdict"].map(rerun.verdict_kind)


def story_line(claims: pd.DataFrame) -> str:
    """Whether the paper's story stands, and where it does not: its headline families'
    verdicts (``catalogue.headline`` of origin "paper"), cell by cell.

    Args:
        claims: the ledger.

    Returns:
        One Markdown bullet; "" when the ledger holds none of the paper's headline claims.
    """
    fams = list(_headline_families(claims, "paper"))
    n = sum(len(rows) for _, rows, _, _ in fams)
    held = sum(int((kind == "holds").sum()) for *_, kind in fams)

    def where(v: str) -> str:  # the families with a claim of verdict v, each with its cells
        return "; ".join(
            f"{words} ({', '.join(cells[kind == v])})"
            for words, _, cells, kind in fams
            if (kind == v).any()
        )

    if not n:
        return ""
    if held == n:
        return f"- **The paper's story stands**: all {n} of its headline claims hold."
    text = f"- **The paper's story stands in part**: {held} of its {n} headline claims hold"
    if where("fails"):
        text += "; it fails on " + where("fails")
    if where("undecided"):
        text += "; undecided: " + where("undecided")
    return text + "."


def headline_lines(claims: pd.DataFrame) -> list[str]:
    """What the run found, in a few lines: the ledger's counts (the paper's claims apart from
    this project's), whether the paper's story stands, then each headline family's
    (``catalogue.headline``) verdict per cell with its measured value and 95% interval, and,
    where the paper gives a number, whether it lies inside that interval (the direction and the
    size both: ``paper_in_interval``).

    Args:
        claims: the ledger (``claims.csv``: id, measured, ci_low, ci_high, unit, verdict).

    Returns:
        The Markdown lines.
    """
    story, premise = story_line(claims), premise_line(claims)
    lines = [count_line(claims), *([premise] if premise else []), *([story] if story else [])]
    for words, rows, where, kind in _headline_families(claims):
        cells = []
        for (_, r), w, k in zip(rows.iterrows(), where, kind):
            value = _value_text(r).replace(" (one value)", "")
            size = r.get("paper_in_interval")  # a record made before the column has none
            if isinstance(size, str) and size:
                p_lo, p_hi = r["paper_low"], r["paper_high"]
                fig = f"{p_lo:+.3g}" if p_lo == p_hi else f"{p_lo:+.3g} to {p_hi:+.3g}"
                value = f"{value.strip()}; the paper's {fig} {size}"
            cells.append(f"{w} **{k}** ({value.strip()})")
        lines.append(f"- {words[0].upper() + words[1:]}: " + "; ".join(cells) + ".")
    return lines


def cost_lines(costs: pd.DataFrame) -> list[str]:
    """What each of ``COMMANDS`` costs on 2 cores, from ``costs.csv``, each shown as the command
    it was measured with; ``not measured`` where the record has no row for it.

    Args:
        costs: ``costs.csv`` as [`read_costs`][physgs.report.record.read_costs] reads it.

    Returns:
        The lines of a Markdown table: command, wall time on 2 cores, when and where measured.
    """
    by_name = {r["name"]: r for _, r in costs.iterrows()}
    rows = []
    for name, command in COMMANDS:
        r = by_name.get(name)
        if r is None:
            rows.append((f"`{command}`", "not measured", ""))
            continue
        start = ""  # where a run starts from says something only of a workflow's targets
        if command.startswith("snakemake"):
            start = " (from nothing)" if bool(r["from_nothing"]) else " (on a finished run)"
        n = int(r["segments"])
        if n > 1:  # a run resumed after an interruption: its wall time is the segments' sum
            start += f", in {n} segments"
        # the command as it was measured (e.g. tab_null at three seeds), not the canonical one
        rows.append(
            (
                f"`{r['command']}`",
                format_duration(float(r["wall_s"])) + start,
                f"{r['date']}, commit `{r['commit']}`, {r['cpu']}",
            )
        )
    columns = ("command", "wall time on 2 cores", "measured on")
    return markdown_table(pd.DataFrame(rows, columns=columns)).splitlines()


def read_costs(path: str | Path) -> pd.DataFrame:
    """``costs.csv`` of a record, or an empty frame with its columns where there is none.

    Args:
        path: the ``costs.csv``.

    Returns:
        Its rows (``COSTS_COLUMNS``), text columns read as text.
    """
    p = Path(path)
    if not p.is_file():
        return pd.DataFrame(columns=list(COSTS_COLUMNS))
    text = {c: str for c in COSTS_COLUMNS if c not in ("wall_s", "from_nothing", "segments")}
    df = pd.read_csv(p, dtype=text)  # a commit of digits or a command `true` stays text
    if "segments" not in df:  # rows recorded before runs could be resumed: one command each
        df["segments"] = 1
    return df


def readme_block(found: Sequence[str]) -> str:
    """The README's "what it found" and "what it costs" block around
    [`found_lines`][physgs.report.record.found_lines].

    Args:
        found (Sequence[str]): the lines of [`found_lines`][physgs.report.record.found_lines]
            of the record.

    Returns:
        The block between the ``BEGIN`` and ``END`` markers.
    """
    return "\n".join([BEGIN, "", *found, END])


NUMBER_WORDS = ("no", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten")


def instances_phrase(instances: Mapping[str, Sequence[int]]) -> str:
    """What a tree's name stands for in the findings: ``"; each of <trees> measured on five
    instances of its preset (testbed seeds 0, 1, 2, 3, 4), so "<tree>" below means <tree>-preset
    trees"``, or "" where each tree is one instance (the paper's protocol) or the stamp names
    none.

    Args:
        instances: tree -> the testbed seeds of its instances (the stamp's).

    Returns:
        The phrase, starting with "; ", or "".
    """
    many = {t: list(s) for t, s in instances.items() if len(s) > 1}
    if not many:
        return ""
    counts = {len(s) for s in many.values()}
    n = counts.pop() if len(counts) == 1 else None
    number = (NUMBER_WORDS[n] if n < len(NUMBER_WORDS) else str(n)) if n else "several"
    seeds = {tuple(s) for s in many.values()}
    which = f" (testbed seeds {', '.join(map(str, seeds.pop()))})" if len(seeds) == 1 else ""
    first = next(iter(many))
    return (
        f"; each of {', '.join(many)} measured on {number} instances of its preset{which}, so "
        f'"{first}" below means {first}-preset trees'
    )


def found_lines(record_dir: str | Path) -> list[str]:
    """The lines of [`readme_block`][physgs.report.record.readme_block] without its markers: what
    the home page includes.

    Args:
        record_dir: the record folder (``claims.csv``, ``stamp.json``, ``costs.csv``).

    Returns:
        The Markdown lines, ending in a blank one.
    """
    record = Path(record_dir)
    lines = ["**What the last full run found** (its record: `docs/record/`):", ""]
    if (record / "claims.csv").is_file():
        stamp = json.loads((record / "stamp.json").read_text())
        claims = read_run_csv(record / "claims.csv")
        overrides = stamp.get("overrides") or []
        made_with = f", made with `{overrides_words(overrides)}`" if overrides else ""
        lines += [
            f"Profile `{stamp['profile']}`{made_with}, seeds {', '.join(map(str, stamp['seeds']))}, "
            f"commit `{stamp['commit']}`{instances_phrase(stamp.get('instances') or {})}:",
            "",
            *headline_lines(claims),
            "",
            *WORDS,
        ]
    else:
        lines.append(
            "no full run is recorded yet: `python tools/record.py results` writes the record "
            "after `snakemake --cores 2 all`."
        )
    lines += ["", "**What each command costs:**", "", *cost_lines(read_costs(record / "costs.csv"))]
    return [*lines, ""]


def replace_block(text: str, block: str) -> str:
    """``text`` with the part between ``BEGIN`` and ``END`` replaced by ``block``.

    Args:
        text: the page's text.
        block: the new block, markers included.

    Returns:
        The new text.

    Raises:
        ValueError: when the markers are missing or out of order.
    """
    i, j = text.find(BEGIN), text.find(END)
    if i < 0 or j < i:
        raise ValueError(f"no {BEGIN} ... {END} block to replace")
    return text[:i] + block + text[j + len(END) :]


def record_costs(path: str | Path, row: Mapping[str, object]) -> None:
    """Set the row of ``row['name']`` in ``costs.csv`` (the command's last measured cost).

    Args:
        path: the ``costs.csv`` (made if missing).
        row: the command's measurement, keyed by ``COSTS_COLUMNS``.
    """
    df = read_costs(path)
    df = df[df["name"] != row["name"]]
    df = pd.concat([df, pd.DataFrame([{k: row[k] for k in COSTS_COLUMNS}])], ignore_index=True)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(path, index=False)
