"""The committed record of a finished run (``docs/record/``): its stamp, summary, ledger, tables
and web-sized figures. [`render_pages`][physgs.report.record.render_pages] lays the Results
page's parts out from those files alone and [`readme_block`][physgs.report.record.readme_block]
prints the README's findings and costs (``costs.csv``, ``tools/timed.py``) from them, so neither
can disagree with the run. Pure over paths.
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
from physgs.provenance import read_stamped
from physgs.report import captions, catalogue, claims as ledger, rerun
from physgs.report.prose import PROSE, data, say

#: The commands whose cost the README states, keyed as ``tools/timed.py --name`` records them.
COMMANDS: tuple[tuple[str, str], ...] = tuple(PROSE["commands"].items())
#: Widest figure in the record, px: the documentation's content column.
FIGURE_WIDTH_PX = 1200
#: Value columns of one summary table on the page: a wider one is cut, its keys repeated.
VALUE_COLUMNS_SHOWN = 4
#: Lines of a table's summary up to which it shows open (a longer one folds), and the tables
#: open whatever their length (the fit bar, and the null control the README points to).
OPEN_TABLE_ROWS, OPEN_TABLES = 30, ("tab_fit", "tab_null")
#: Columns every table carries that the record's stamp already states.
STAMP_COLUMNS = ("profile", "config_hash", "physgs_version")
#: Cells moved beyond their row's seed spread that the comparison with the last record lists.
RERUN_CELLS_SHOWN = 10
COSTS_COLUMNS = ("name", "command", "wall_s", "date", "commit", "cpu", "from_nothing", "segments")
BEGIN, END = "<!-- record:begin -->", "<!-- record:end -->"
#: Files of the record that no run makes, kept when a new record replaces the old: each
#: command's cost, the paper profile's measured rates and the estimate made from them.
OUTLIVE = ("costs.csv", "rates_paper.csv", "paper_estimate.md")

#: A commit as the record names it: a plain (abbreviated) hash.
COMMIT = re.compile(r"^[0-9a-f]{7,40}$")
#: The run's folder of the jobs' benchmark files (``physgs.experiments.cost``).
BENCHMARKS = "benchmarks"
#: The heading of the run summary's claims section as the record holds it (demoted).
SUMMARY_CLAIMS = "### Claims ledger"


#: The Results page's part the record lays out (``index.md``): its figures, its ledger's counts,
#: its tables and its run, each included from its own page.
INDEX_PAGE = data("templates/index.md")
#: One table's entry on the Results page (``tables.md``): where its rows come from, its CSV, and
#: its summary over seeds (``fold``: open, ``???+``, or folded, ``???``).
TABLE_ENTRY = data("templates/table_entry.md")


def _join(xs: Iterable) -> str:
    return ", ".join(map(str, xs))


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
        wall_s: the time the run's command ran, s, summed over its segments (``tools/timed.py``).
        job_min_by_stage: job-minutes per stage, from the run's benchmark files.
        note: what a reader should know about how the run was made (apart from the commit).
        jobs: the run's benchmarked jobs (one benchmark file each; light jobs have none).
        instances: tree -> the testbed seeds of its tree instances; {} in an older record.
        overrides: the run's ``--configfile`` and ``--config`` words (none: the committed config).
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

    def markdown(self) -> str:
        """The stamp as a Markdown list (``PROSE["stamp"]``; an empty field leaves its line out).

        Returns:
            Bullet lines (run, instances, overrides, commit and date, note, machine, wall time
                with jobs and job-minutes by stage) and a blank line.
        """
        by: dict[tuple[int, ...], list[str]] = {}  # the trees of each set of testbed seeds
        for t, seeds in self.instances.items():
            by.setdefault(tuple(seeds), []).append(t)
        stages = ", ".join(f"{k} {v:.1f}" for k, v in self.job_min_by_stage.items())
        fields = {
            "instances": "; ".join(
                f"{', '.join(trees)}: testbed seed{'s' if len(s) > 1 else ''} {_join(s)}"
                for s, trees in by.items()
            ),
            "overrides": shlex.join(self.overrides),
            "note": self.note,
            "seeds": _join(self.seeds),
            "trees": ", ".join(self.trees),
            "wall": format_duration(self.wall_s),
            "jobs": f"{self.jobs} benchmarked jobs, " if self.jobs else "",
            "total": sum(self.job_min_by_stage.values()),
            "stages": f" ({stages})" if stages else "",
        }
        lines = PROSE["stamp"].items()
        return "\n".join([*(t.format(s=self, **fields) for k, t in lines if fields.get(k, 1)), ""])


def instances_of(testbed: pd.DataFrame, seeds: Sequence[int], seed: int) -> dict[str, list[int]]:
    """Each tree's testbed seeds: the training seeds if one instance per seed, else ``seed``.

    Args:
        testbed: the run's tab_testbed (``tree``, ``instances``; without it, one instance each).
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


def other_configs(files: Iterable[str | Path], config_hash: str) -> list[str]:
    """The files, among ``files``, whose rows were made under another config than the run's.

    Args:
        files: CSVs (a file without a ``config_hash`` column is not judged).
        config_hash: the run's config hash.

    Returns:
        One phrase per file that disagrees: its path and the hashes it holds.
    """
    found = [(f, config_hashes(read_stamped(f))) for f in files]
    return [
        f"{f}: config_hash {', '.join(h) or 'none'}, not {config_hash}"
        for f, h in found
        if h is not None and h != [config_hash]
    ]


def config_hashes(df: pd.DataFrame) -> list[str] | None:
    """The config hashes a table's or the ledger's rows were made under.

    Args:
        df: the table (its ``config_hash`` column read as text).

    Returns:
        The hashes, sorted; None for a table without the column (not judged).
    """
    return sorted({str(h) for h in df["config_hash"].dropna()}) if "config_hash" in df else None


def format_duration(seconds: float) -> str:
    """``3 h 8 min``, ``29 min 9 s`` or ``42 s``, rounded to the second; ``--`` if not finite.

    Args:
        seconds: a duration, s.

    Returns:
        The duration in words.
    """
    if not math.isfinite(seconds):
        return "--"
    h, rest = divmod(round(seconds), 3600)
    m, s = divmod(rest, 60)
    if h:
        return f"{h} h {m} min"
    return f"{m} min {s} s" if m else f"{s} s"


def _cell(x) -> str:
    if isinstance(x, (float, np.floating)):
        return f"{x:.4g}" if math.isfinite(x) else "--"
    return "--" if x is None else str(x).replace("|", "\\|")


def markdown_table(df: pd.DataFrame, right: Iterable[str] = ()) -> str:
    """A DataFrame as a Markdown table: floats to 4 significant digits, NaN as ``--``.

    Args:
        df: the table (its index is dropped).
        right: the columns aligned right.

    Returns:
        The table's lines, ending in a newline.
    """
    rule = "".join("---:|" if c in set(right) else "---|" for c in df.columns)
    lines = ["| " + " | ".join(map(str, df.columns)) + " |", "|" + rule]
    lines += ["| " + " | ".join(map(_cell, row)) + " |" for row in df.itertuples(index=False)]
    return "\n".join(lines) + "\n"


def _table(rows: Iterable, columns: Sequence[str], right: Iterable[str] = ()) -> str:
    """``rows`` under ``columns`` as a Markdown table (no newline after its last row)."""
    return markdown_table(pd.DataFrame(rows, columns=list(columns)), right)[:-1]


def _blocks(*blocks: str) -> str:
    """A page of ``blocks`` (paragraphs, tables), blank-line separated, ending in a newline."""
    return "\n\n".join(blocks) + "\n"


def _demote(markdown: str) -> str:
    """Every heading one level down, so an included page sits under the including page's title."""
    return re.sub(r"^#+ ", r"#\g<0>", markdown, flags=re.MULTILINE)


def web_sized(png: str | Path, to: str | Path) -> None:
    """Copy a figure at most ``FIGURE_WIDTH_PX`` wide (its aspect kept), as the record keeps it.

    Args:
        png: the figure (an image file; PNG in the record).
        to: where the copy goes.
    """
    with Image.open(png) as im:
        if im.width > FIGURE_WIDTH_PX:
            h = round(im.height * FIGURE_WIDTH_PX / im.width)
            im = im.resize((FIGURE_WIDTH_PX, h), Image.LANCZOS)
        im.save(to, optimize=True)


def _rerun_page(
    previous: Path, stamp: Stamp, claims_csv: str | Path, tables: Sequence[str | Path], roles=None
) -> str:
    """The record's "Against the previous record" page: this run's ledger verdict by verdict
    (beside its first seed alone, ``claims.first_seed`` with ``roles``, where the run has several
    instances of a tree and the previous record one) and its seeded tables cell by cell against
    the record in ``previous``."""
    if not ((previous / "stamp.json").is_file() and (previous / "claims.csv").is_file()):
        return _blocks(PROSE["rerun_head"], PROSE["rerun_none"])
    old = json.loads((previous / "stamp.json").read_text())
    first = None
    # the first seed alone is the old record's own tree only where that record had one per preset
    # (a stamp from before instances has none): two runs over instances compare mean with mean
    if any(len(s) > 1 for s in stamp.instances.values()) and not any(
        len(s) > 1 for s in old.get("instances", {}).values()
    ):
        from physgs.report.build import read_table  # build reads every output's module

        tabs = {Path(t).stem: read_table(Path(t).stem, t) for t in tables}
        tabs = {n: d for n, d in tabs.items() if n in catalogue.tables()}
        first = ledger.first_seed(tabs, stamp.trees, roles)
    h = old.get("config_hash")
    settings = PROSE["rerun_same"] if h == stamp.config_hash else say("rerun_other", hash=h)
    c = rerun.compare_claims(read_stamped(previous / "claims.csv"), read_stamped(claims_csv), first)
    n, new, gone = len(c.changed), len(c.only_new), len(c.only_old)
    old_run = {"commit": stamp.commit, "old": old.get("commit"), "date": old.get("date")}
    both = {"same": c.same, "both": c.same + n, "changed": n, "new": new, "old": gone}
    page = [
        PROSE["rerun_head"],
        say("rerun_intro", **old_run, settings=settings),
        say("rerun_ledger", **both, apart=new + gone),
    ]
    if c.changed:
        k = Counter(v.overlap for v in c.changed)
        heads = PROSE["rerun_verdict_heads"][: 6 if first else 5]
        verdicts = [
            (f"`{v.id}`: {v.claim}", f"{v.old}, {v.old_value}", f"**{v.new}**, {v.new_value}")
            + (v.threshold, v.overlap)
            + ((v.alone,) if first else ())
            for v in c.changed
        ]
        overlap = say("rerun_overlap", n=n, yes=k["yes"], no=k["no"], none=k["--"])
        page += [_table(verdicts, heads), overlap]
    if c.changed and first:
        k = Counter(v.alone.split(",")[0] for v in c.changed)
        seed = min(min(s) for s in stamp.instances.values())
        same, crossed = k[rerun.FIRST_SAME], k[rerun.FIRST_CROSSED]
        page.append(say("rerun_first", seed=seed, same=same, crossed=crossed, none=k["--"]))
    rows, moved = [], []
    for t in sorted(Path(p) for p in tables):
        before = previous / "tables" / t.name
        if not before.is_file():
            continue
        a, b = read_stamped(before), read_stamped(t)
        if "seed" not in a.columns or "seed" not in b.columns:
            same = "identical" if a.equals(b) else "changed"
            rows.append((f"`{t.stem}` (not seeded)", len(b), "", same, "", ""))
            continue
        r = rerun.compare_table_csv(before, t)
        rows.append((f"`{t.stem}`", r.rows, r.cells, r.identical, r.within, len(r.beyond)))
        moved += [(t.stem, ch) for ch in r.beyond]
    heads = PROSE["rerun_table_heads"]
    page += [PROSE["rerun_tables"], _table(rows, heads, right=heads[1:])]
    if moved:
        moved.sort(key=lambda m: rerun.spreads_moved(m[1]), reverse=True)
        cells = [
            (f"`{name}`", ", ".join(f"{k} {v}" for k, v in ch.key.items()), f"`{ch.column}`")
            + (ch.old, ch.new, ch.spread)
            for name, ch in moved[:RERUN_CELLS_SHOWN]
        ]
        heads = PROSE["rerun_move_heads"]
        page += [
            say("rerun_moves", shown=len(cells), n=len(moved)),
            _table(cells, heads, right=heads[3:]),
        ]
    return _blocks(*page)


@dataclass(frozen=True)
class RunFiles:
    """The files of a run that its record takes ([`run_files`][physgs.report.record.run_files]).

    Attributes:
        target: the target whose plan it is (``all``).
        tables: the plan's table CSVs, sorted.
        figures: the plan's figure PNGs, sorted.
        jobs: the plan's benchmarked jobs ([`JobCost`][physgs.experiments.cost.JobCost]).
        left_out: the files of these kinds in the folder that the plan does not make, sorted.
    """

    target: str
    tables: tuple[Path, ...]
    figures: tuple[Path, ...]
    jobs: tuple[cost.JobCost, ...]
    left_out: tuple[str, ...] = ()

    def left_out_line(self) -> str:
        """What was left out: the tables and figures by name, the benchmark files by stage.

        Returns:
            ``left out (not made by all): tables/x.csv, ...; N benchmark files (stage n, ...)``.
        """
        parts = [PurePosixPath(p).parts for p in self.left_out]
        files = [p for p, (top, *_) in zip(self.left_out, parts) if top != BENCHMARKS]
        stages = Counter(x[1] for x in parts if x[0] == BENCHMARKS)
        by_stage = ", ".join(f"{k} {n}" for k, n in sorted(stages.items()))
        bench = f"{stages.total()} benchmark files ({by_stage})" if stages else ""
        what = "; ".join(x for x in (", ".join(files), bench) if x) or "nothing"
        return f"left out (not made by {self.target}): {what}"


def run_files(
    results: str | Path, outputs: Iterable[str], benchmarks: Iterable[str], target: str = "all"
) -> RunFiles:
    """The tables, figures and benchmarked jobs of a run's folder that its target's plan makes.

    Args:
        results: the run's folder (``results/``).
        outputs: every output of Snakemake's plan, relative to ``results``
            ([`plan_outputs`][physgs.experiments.cost.plan_outputs]).
        benchmarks: every benchmark file of the plan, relative to ``results``
            ([`plan_jobs`][physgs.experiments.cost.plan_jobs]).
        target: the plan's target, named in messages.

    Returns:
        The [`RunFiles`][physgs.report.record.RunFiles].

    Raises:
        FileNotFoundError: naming every table or figure of the plan that the folder lacks.
    """
    root = Path(results)
    made = {PurePosixPath(p) for p in outputs}
    picked, missing, left_out = [], [], []
    for folder, suffix in (("tables", ".csv"), ("figures", ".png")):
        planned = {p for p in made if p.parent == PurePosixPath(folder) and p.suffix == suffix}
        missing += sorted(str(p) for p in planned if not (root / p).is_file())
        picked.append(tuple(sorted(root / p for p in planned)))
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
    return RunFiles(target, *picked, tuple(jobs), tuple(sorted(left_out)))


def _remove(path: Path) -> None:
    """Remove ``path``, a folder or a file, if it is there."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif path.exists() or path.is_symlink():
        path.unlink()


def write_record(
    out_dir: str | Path,
    *,
    stamp: Stamp,
    summary_md: str | Path,
    claims_csv: str | Path,
    claims_md: str | Path,
    tables: Sequence[str | Path],
    figures: Sequence[str | Path],
    roles: Mapping[str, Mapping[str, str]] | None = None,
) -> list[Path]:
    """Write a run's record into ``out_dir``, swapped in whole for the record there.

    Args:
        out_dir: the record's folder (``docs/record``).
        stamp: where the run comes from.
        summary_md: the run's ``summary.md``.
        claims_csv: the claims ledger as CSV.
        claims_md: the claims ledger as Markdown.
        tables: the run's table CSVs, each copied to ``tables/`` and summarised beside.
        figures: the run's figure PNGs, each copied web-sized to ``figures/``.
        roles: tree -> its preset's role (``claim_cells.roles_of``), for the ledger on the
            first seed alone ([`first_seed`][physgs.report.claims.first_seed]) that a run with
            several instances of a tree sets beside each moved verdict.

    Returns:
        The files written.

    Raises:
        FileNotFoundError: naming the first input that is missing.
    """
    for p in map(Path, (summary_md, claims_csv, claims_md, *tables, *figures)):
        if not p.is_file():
            raise FileNotFoundError(f"{p}: missing; finish the run first (snakemake --cores 2 all)")
    final = Path(out_dir)
    # a write swaps the records by two renames (final -> final.old, final.partial -> final), then
    # removes final.old: one that stopped between the renames left the last record there
    old = final.with_name(final.name + ".old")
    if (old.exists() or old.is_symlink()) and final.exists():
        print(f"{old}: left by an earlier write of the record after its swap; removed")
        _remove(old)
    elif old.exists() or old.is_symlink():
        print(f"{old}: the last record, left there by a write that stopped; put back at {final}")
        old.rename(final)
    kept = {n: (final / n).read_bytes() for n in OUTLIVE if (final / n).is_file()}
    old_stamp, old_rerun = final / "stamp.json", final / "rerun.md"
    prior = json.loads(old_stamp.read_text()) if old_stamp.is_file() else {}
    now = json.loads(json.dumps(asdict(stamp)))  # its tuples as the JSON's lists
    keys = ("commit", "config_hash", "profile", "seeds", "trees")
    if old_rerun.is_file() and all(prior.get(k) == now[k] for k in keys):
        against = old_rerun.read_text()  # the same run recorded again keeps its comparison
    else:
        against = _rerun_page(final, stamp, claims_csv, tables, roles)
    out = final.with_name(final.name + ".partial")  # the old record stands until this is whole
    _remove(out)  # an earlier write that stopped before its swap
    (out / "tables").mkdir(parents=True)
    (out / "figures").mkdir()
    pages = {"summary.md": summary_md, "claims.md": claims_md}
    kept |= {n: _demote(Path(p).read_text()).encode() for n, p in pages.items()}
    kept |= {"stamp.json": (json.dumps(asdict(stamp), indent=2) + "\n").encode()}
    for name, text in {**kept, "rerun.md": against.encode()}.items():
        (out / name).write_bytes(text)
    for src, to in [(claims_csv, "claims.csv"), *((t, f"tables/{Path(t).name}") for t in tables)]:
        shutil.copyfile(src, out / to)
    for f in map(Path, figures):
        web_sized(f, out / "figures" / f.name)
    render_pages(out)
    written = sorted(final / p.relative_to(out) for p in out.rglob("*") if p.is_file())
    if final.exists():
        final.rename(old)
    out.rename(final)
    _remove(old)
    return written


def _mean_sd(values: pd.Series) -> str:
    """``mean ± sd`` over seeds, NaN dropped (the value alone where the seeds agree; ``--``)."""
    v = pd.to_numeric(values, errors="coerce").dropna()
    if v.empty:
        return "--"
    m, sd = float(v.mean()), float(v.std(ddof=1)) if len(v) > 1 else 0.0
    if sd <= 1e-9 * max(1.0, abs(m)):  # a quantity the seeds do not change (the testbed's)
        return _cell(m)
    return f"{m:.4g} ± {sd:.2g}"


def table_summary(df: pd.DataFrame) -> tuple[pd.DataFrame, list[str], list[int]]:
    """A per-seed table as ``mean ± sd`` over seeds per key (its text and true/false columns),
    the stamp's and empty columns dropped; a table without a ``seed`` column as it is.

    Args:
        df: the table, one row per seed (the stamp's columns read as text).

    Returns:
        ``(summary as text, key columns in the table's order, seeds summarised over)``.
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
    """[`table_summary`][physgs.report.record.table_summary] as Markdown tables, the keys repeated.

    Args:
        df: the table, one row per seed.

    Returns:
        Tables of ``VALUE_COLUMNS_SHOWN`` value columns at most, blank-line separated.
    """
    summary, keys, _ = table_summary(df)
    values = [c for c in summary.columns if c not in keys]
    n = VALUE_COLUMNS_SHOWN
    parts = [values[i : i + n] for i in range(0, len(values), n)] or [[]]
    # a long column name may break after an underscore (<wbr>: no character when copied)
    heads = {c: str(c).replace("_", "_<wbr>") for c in summary.columns}
    return "\n".join(markdown_table(summary[keys + cols].rename(columns=heads)) for cols in parts)


def derive_claims(record_dir: str | Path) -> list[Path]:
    """Derive a record ledger's ``kind`` if it lacks it; print its ``claims.md`` and claims again.

    Args:
        record_dir: the record folder (``claims.csv``).

    Returns:
        The files that changed; none when the ledger and its pages are up to date.
    """
    from physgs.report.summary import claims_section  # summary imports this module

    out = Path(record_dir)
    path, written = out / "claims.csv", []
    text = pd.read_csv(path, dtype=str, keep_default_na=False)  # no number is touched
    if "kind" not in text:
        at = text.columns.get_loc("origin") + 1 if "origin" in text else len(text.columns)
        text.insert(at, "kind", ledger.column(text, "kind"))
        text.to_csv(path, index=False)
        written.append(path)
    df = read_stamped(path)
    stamp = {c: str(df[c].iloc[0]) for c in STAMP_COLUMNS if c in df and len(df)}
    pages = {out / "claims.md": _demote(ledger.ledger_markdown(df, stamp or None))}
    if (out / "summary.md").is_file():  # its other sections come from files the record lacks
        section = _demote("\n".join(claims_section(df)))  # up to the next section, or the end
        at = re.compile(rf"^{re.escape(SUMMARY_CLAIMS)}$.*?(?=\n### |\Z)", re.M | re.S)
        pages[out / "summary.md"] = at.sub(lambda _: section, (out / "summary.md").read_text(), 1)
    for p, printed in pages.items():
        if not p.is_file() or p.read_text() != printed:
            p.write_text(printed)
            written.append(p)
    return written


def render_pages(record_dir: str | Path) -> list[Path]:
    """Lay out the Results page's parts (``index.md`` and what it includes) from the record; of a
    record folder that holds no run yet (no ``stamp.json``), ``index.md`` saying how to make one.

    Args:
        record_dir: the record folder (made if missing).

    Returns:
        The files written.

    Raises:
        KeyError: naming a figure without a caption (``physgs.report.captions``).
        FileNotFoundError: for a folder that holds a run's claims or tables but no stamp.
    """
    out = Path(record_dir)
    if not (out / "stamp.json").is_file():
        if (out / "claims.csv").exists() or (out / "tables").exists():  # a record lost its stamp
            raise FileNotFoundError(f"{out / 'stamp.json'}: a record's files without its stamp")
        out.mkdir(parents=True, exist_ok=True)
        (out / "index.md").write_text(PROSE["unrecorded"])
        return [out / "index.md"]
    stamp = Stamp(**json.loads((out / "stamp.json").read_text()))
    pages = {"stamp.md": stamp.markdown()}
    entries = []
    for t in sorted((out / "tables").glob("*.csv")):
        df = pd.read_csv(t, dtype={c: str for c in STAMP_COLUMNS})
        summary, _, seeds = table_summary(df)
        pages[f"tables/{t.stem}.md"] = text = summary_markdown(df)
        over = PROSE["over_none"] if not seeds else say("over_seed", seed=seeds[0])
        over = say("over_seeds", seeds=_join(seeds)) if len(seeds) > 1 else over
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
    counts, *bullets = _lead(read_stamped(out / "claims.csv"), "index_ledger")
    led = "\n\n".join([counts, *(b[2:] for b in bullets)])  # its bullets as paragraphs
    pages["index.md"] = INDEX_PAGE.format(s=stamp, seeds=_join(stamp.seeds), ledger=led)
    for name, text in pages.items():
        (out / name).write_text(text)
    return [out / name for name in pages]


def _value_text(r: pd.Series) -> str:
    """A ledger row's measured mean and 95% interval, ``+2.26 [+1.94, +2.57] dB``, or ``--``."""
    if not math.isfinite(r["measured"]):
        return "--"
    if math.isfinite(r["ci_low"]):
        n = [ledger.number(r[c], r["unit"]) for c in ("measured", "ci_low", "ci_high")]
        return f"{n[0]} [{n[1]}, {n[2]}] {r['unit']}"
    return f"{ledger.number(r['measured'], r['unit'])} {r['unit']} (one value)"


def ledger_page(claims_csv: str | Path, trees: Sequence[str]) -> str:
    """The ledger page's HTML table: a row per claim, its details one click away (``ledger.js``).

    Args:
        claims_csv: the record's ``claims.csv``.
        trees: the run's trees (a sentence's leading tree becomes the tree column).

    Returns:
        The page part: raw HTML, ending in a newline.
    """
    claims = read_stamped(claims_csv)
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
    lead = re.compile(f"({'|'.join(map(re.escape, trees)) or '(?!)'})[:, ]")  # a leading tree
    rows = []
    for _, r in claims.iterrows():
        text, m = str(r["claim"]), lead.match(str(r["claim"]))
        tree, short = (m[1], text[len(m[1]) :].lstrip(":, ")) if m else ("--", text)
        f = {c: str(r[c]) for c in ("claim", "id", "threshold", "unit", "source", "paper")}
        f |= {c: str(r["_" + c]) for c in ("origin", "kind", "verdict")}
        f |= {
            "tree": tree,
            "short": short,
            "value": _value_text(r),
            "decide": ledger.decide_cell(r),
        }
        f["full"] = str(r["verdict"]) if str(r["verdict"]) != r["_verdict"] else ""
        f["undermines"] = catalogue.undermines(f["id"]) if r["_kind"] == "premise" else ""
        anchor = "claim-" + re.sub(r"[^a-z0-9]+", "-", f["id"].lower()).strip("-")
        f, n = {k: html.escape(v) for k, v in f.items()}, int(r["seeds"])
        details = say("ledger_details", **f, seeds=n, s="s" if n != 1 else "")
        rows.append(say("ledger_row", **f, anchor=anchor, more=details) + "\n")
    return say("ledger_table", body="".join(rows))


def _lead(claims: pd.DataFrame, counts: str) -> list[str]:
    """The sentence ``counts`` of the ledger's counts (``claims.counted``) of the paper's claims
    and this project's, then a bullet naming the premises that fail and what each undermines,
    and the paper's story (``story_line``), each where there is one."""
    n = {who: ledger.counted(claims, who) for who in ("paper", "project")}
    failed = "; ".join(f.rstrip(".") for f in ledger.failed_premises(claims))
    premise = say("premises", failed=failed) if failed else ""
    return [line for line in (say(counts, **n), premise, story_line(claims)) if line]


def _headline_families(claims: pd.DataFrame, origin: str | None = None):
    """The ledger's headline families (``catalogue.headline``, of ``origin`` if given): their
    words, claims, each claim's cell (its id past the family's, or ``all``) and verdict kind."""
    ids = claims["id"].astype(str)
    for fam, words, of in catalogue.headline():
        rows = (ids == fam) | ids.str.startswith(fam + "/")
        if rows.any() and origin in (None, of):
            cells = ids[rows].str[len(fam) + 1 :].replace("", "all")
            yield words, claims[rows], cells, claims.loc[rows, "verdict"].map(rerun.verdict_kind)


def story_line(claims: pd.DataFrame) -> str:
    """Whether the paper's story stands: its headline families' verdicts, cell by cell.

    Args:
        claims: the ledger.

    Returns:
        One Markdown bullet; "" when the ledger holds none of the paper's headline claims.
    """
    fams = list(_headline_families(claims, "paper"))
    n = sum(len(rows) for _, rows, _, _ in fams)
    held = sum(int((kind == "holds").sum()) for *_, kind in fams)
    if not n:
        return ""
    if held == n:
        return say("story_all", n=n)
    text = say("story_part", held=held, n=n)
    for v in ("fails", "undecided"):
        where = [
            f"{w} ({', '.join(cells[kind == v])})"
            for w, _, cells, kind in fams
            if (kind == v).any()
        ]
        text += PROSE[f"story_{v}"] + "; ".join(where) if where else ""
    return text + "."


def headline_lines(claims: pd.DataFrame) -> list[str]:
    """What the run found: the ledger's counts (the paper's claims apart from this project's), the
    premises that fail, the paper's story, each headline family's verdicts.

    Args:
        claims: the ledger (``claims.csv``: id, measured, ci_low, ci_high, unit, verdict).

    Returns:
        The Markdown lines.
    """
    lines = _lead(claims, "count")
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
    """What each of ``COMMANDS`` costs on 2 cores, as measured (or ``not measured``).

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
        if int(r["segments"]) > 1:  # a resumed run: its wall time is the segments' sum
            start += f", in {int(r['segments'])} segments"
        # the command as it was measured (e.g. tab_null at three seeds), not the canonical one
        wall = format_duration(float(r["wall_s"])) + start
        rows.append((f"`{r['command']}`", wall, f"{r['date']}, commit `{r['commit']}`, {r['cpu']}"))
    return _table(rows, PROSE["cost_heads"]).split("\n")


def read_costs(path: str | Path) -> pd.DataFrame:
    """``costs.csv`` of a record, or an empty frame with its columns where there is none.

    Args:
        path: the ``costs.csv``.

    Returns:
        Its rows (``COSTS_COLUMNS``), text columns read as text.
    """
    if not Path(path).is_file():
        return pd.DataFrame(columns=list(COSTS_COLUMNS))
    text = {c: str for c in COSTS_COLUMNS if c not in ("wall_s", "from_nothing", "segments")}
    df = pd.read_csv(path, dtype=text)  # a commit of digits or a command `true` stays text
    if "segments" not in df:  # rows recorded before runs could be resumed: one command each
        df["segments"] = 1
    return df


def readme_block(found: Sequence[str]) -> str:
    """The README's "what it found" and "what it costs" block.

    Args:
        found (Sequence[str]): the record's [`found_lines`][physgs.report.record.found_lines].

    Returns:
        The block between the ``BEGIN`` and ``END`` markers.
    """
    return "\n".join([BEGIN, "", *found, END])


def instances_phrase(instances: Mapping[str, Sequence[int]]) -> str:
    """What a tree's name stands for in the findings where a tree is several instances.

    Args:
        instances: tree -> the testbed seeds of its instances (the stamp's).

    Returns:
        ``; each of <trees> measured on five instances of its preset ...``, or "" if none is.
    """
    many = {t: list(s) for t, s in instances.items() if len(s) > 1}
    if not many:
        return ""
    counts = {len(s) for s in many.values()}
    n = counts.pop() if len(counts) == 1 else None
    words = PROSE["number_words"]
    number = (words[n] if n < len(words) else str(n)) if n else "several"
    seeds = {tuple(s) for s in many.values()}
    which = _join(seeds.pop()) if len(seeds) == 1 else ""
    return say(
        "instances", trees=", ".join(many), number=number, which=which, first=next(iter(many))
    )


def found_lines(record_dir: str | Path) -> list[str]:
    """The lines of [`readme_block`][physgs.report.record.readme_block] (the home page's).

    Args:
        record_dir: the record folder (``claims.csv``, ``stamp.json``, ``costs.csv``).

    Returns:
        The Markdown lines, ending in a blank one.
    """
    record = Path(record_dir)
    found = [PROSE["found_none"]]
    if (record / "claims.csv").is_file():
        s = json.loads((record / "stamp.json").read_text())
        made_with = shlex.join(s.get("overrides") or [])
        phrase = instances_phrase(s.get("instances") or {})
        fields = {"profile": s["profile"], "seeds": _join(s["seeds"]), "commit": s["commit"]}
        run = say("found_run", **fields, made_with=made_with, instances=phrase)
        heads = headline_lines(read_stamped(record / "claims.csv"))
        found = [run, "\n".join(heads), PROSE["words"]]
    costs = "\n".join(cost_lines(read_costs(record / "costs.csv")))
    return _blocks(PROSE["found_head"], *found, PROSE["found_costs"], costs).split("\n")


def replace_block(text: str, block: str, markers: tuple[str, str] = (BEGIN, END)) -> str:
    """``text`` with the part between two markers replaced by ``block``.

    Args:
        text: the page's text.
        block: the new block, markers included.
        markers: the block's first and last marker (default: the README's findings).

    Returns:
        The new text.

    Raises:
        ValueError: when the markers are missing or out of order.
    """
    begin, end = markers
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < i:
        raise ValueError(f"no {begin} ... {end} block to replace")
    return text[:i] + block + text[j + len(end) :]


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
