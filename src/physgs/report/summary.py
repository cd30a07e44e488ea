"""results/summary.md: what one finished run says, printed from the run's own files.

The run's stamp, the claims ledger's verdicts (``results/claims.csv``), ``tab_fit``'s fraction of
the true-motion ceiling's gain per tree and model, and what the run cost, from Snakemake's
benchmark files ([`physgs.experiments.cost`][]): nothing typed by hand, so nothing goes stale.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from physgs.experiments.cost import read_costs, summarise, wall_spans
from physgs.models.registry import label
from physgs.provenance import read_stamped
from physgs.report.thresholds import FIT_BAR
from physgs.report.catalogue import AHEAD
from physgs.report.claims import column, counted, decide_cell, failed_premises, number
from physgs.report.prose import PROSE, say
from physgs.report.record import config_hashes, markdown_table, story_line
from physgs.report.rerun import verdict_kind
from physgs.statistics import interval

VERDICTS = ("holds", "fails", "undecided")
#: The columns of the summary's table of claims (and the seeds that would decide each).
CLAIM_COLUMNS = ("claim", "measured [95% interval]", "threshold", "verdict")
#: The seed counts the undecided claims' estimate is tabulated at (the default profile runs 3).
DECIDE_AT = (4, 5, 6)


def _md(df: pd.DataFrame, right=()) -> list[str]:
    """A Markdown table's lines and a blank one."""
    return markdown_table(df, right=right).split("\n")


def _stale(stamp: Mapping[str, str], df: pd.DataFrame, name: str) -> list[str]:
    """A warning when a file was made under another config than the run's stamp."""
    found = config_hashes(df)
    if found and "config_hash" in stamp and found != [str(stamp["config_hash"])]:
        hash_ = stamp["config_hash"]
        return [say("summary_stale", name=name, found=", ".join(found), hash=hash_), ""]
    return []


def claims_section(claims: pd.DataFrame) -> list[str]:
    """The ledger's counts, the paper's story, and one line per claim with its interval.

    Args:
        claims: the ledger (``claims.csv``).

    Returns:
        The section's Markdown lines, ending in a blank one.

    Raises:
        ValueError: for a verdict not in ``VERDICTS``.
    """
    bad = sorted(set(claims["verdict"].map(verdict_kind)) - set(VERDICTS))
    if bad:
        raise ValueError(f"claims: unknown verdicts {bad} (expected one of {VERDICTS})")
    story = story_line(claims)
    rows = []
    for _, r in claims.iterrows():
        unit = r["unit"]
        meas = "--" if not np.isfinite(r["measured"]) else f"{number(r['measured'], unit)} {unit}"
        if np.isfinite(r["ci_low"]):
            meas += f" [{number(r['ci_low'], unit)}, {number(r['ci_high'], unit)}]"
        rows.append((f"`{r['id']}`", meas, str(r["threshold"]), str(r["verdict"]), decide_cell(r)))
    return [
        "## Claims ledger",
        "",
        say("summary_claims", paper=counted(claims, "paper"), project=counted(claims, "project")),
        "",
        *[f"- {s[0].upper() + s[1:]}" for s in failed_premises(claims)],
        "",
        *([story, ""] if story else []),
        *prior_lines(claims),
        *_decide_lines(claims),
        *_md(pd.DataFrame(rows, columns=[*CLAIM_COLUMNS, "seeds to decide (est.)"])),
    ]


def _decide_lines(claims: pd.DataFrame) -> list[str]:
    """How many undecided claims would decide at ``DECIDE_AT`` seeds at their observed effect
    and sd (the ledger's plug-in t and 80%-power estimates), the paper's apart from this
    project's; none for a ledger without the estimates."""
    cols = {"plug-in t": "seeds_to_decide_t_est", "80% power": "seeds_to_decide_power80_est"}
    if not set(cols.values()) <= set(claims.columns):
        return []
    undecided = claims["verdict"].astype(str) == "undecided"
    origin = column(claims, "origin")
    rows = []
    for who, words in (("paper", "the paper's"), ("project", "this project's")):
        mine = claims[undecided & (origin == who)]
        for est, col in cols.items():
            n = mine[col].to_numpy(dtype=float)
            at = [int((n <= k).sum()) for k in DECIDE_AT]
            rows.append([f"{words} ({len(mine)})", est, *at, len(n) - at[-1]])
    head = ["undecided claims", "estimate", *(f"by {n} seeds" for n in DECIDE_AT), "more"]
    return [PROSE["summary_decide"], "", *_md(pd.DataFrame(rows, columns=head), head[2:])]


def prior_lines(claims: pd.DataFrame) -> list[str]:
    """Per prior with ``<model>/ahead_of_fields/...`` claims: where it beats every learned field.

    Args:
        claims: the ledger.

    Returns:
        Two lines per prior (the sentence and a blank one).
    """
    ids = claims["id"].astype(str)
    ahead = claims[ids.str.contains(f"/{AHEAD}/", regex=False)]
    lines = []
    for m in dict.fromkeys(ids[ahead.index].str.split("/").str[0]):
        mine = ahead[ahead["id"].astype(str).str.startswith(f"{m}/{AHEAD}/")]
        held = mine[mine["verdict"].astype(str) == "holds"]
        where = ", ".join(i.split(f"/{AHEAD}/", 1)[1] for i in held["id"].astype(str))
        said = say("summary_prior", model=label(m), held=len(held), n=len(mine), where=where)
        lines += [said, ""]
    return lines


def _fit_section(tab_fit: pd.DataFrame) -> list[str]:
    """Each model's (rows) fraction of the ceiling's in-window gain per tree (columns), %: the
    mean over seeds, with its 95% interval from two seeds on."""
    trees = list(dict.fromkeys(tab_fit["tree"]))
    models = list(dict.fromkeys(tab_fit.loc[~tab_fit["reference"].astype(bool), "model"]))
    n = tab_fit["seed"].nunique()

    def cell(v: pd.Series) -> str:  # the mean over seeds, %, and its 95% interval
        mean, _, lo, hi = interval(100 * v.to_numpy(float))
        text = "--" if not np.isfinite(mean) else f"{mean:.0f}%"
        return text + (f" [{lo:.0f}, {hi:.0f}]" if np.isfinite(lo) else "")

    fit = tab_fit.groupby(["model", "tree"], sort=False)["ceiling_frac"].agg(cell).unstack()
    fit = fit.reindex(index=models, columns=trees, fill_value="--")
    fit = fit.rename(index=label).rename_axis(index="model").reset_index()
    text = say("summary_fit", bar=FIT_BAR, seeds=n if n > 1 else 0)
    return ["## Fit to the training window (`tab_fit`)", "", text, "", *_md(fit)]


def _cost_section(benchmark_dir) -> list[str]:
    """The span (first job start to last job end) of the run's benchmarked jobs and of each
    stage's, and job-minutes by stage, shared and per seed; not the run's wall time (a resumed
    run's span holds its pauses: ``tools/timed.py`` measures that)."""
    jobs = read_costs(benchmark_dir)
    s, spans = summarise(jobs), wall_spans(jobs)
    cols = ["shared", *s["per_seed"]]
    head = ["stage", "span min", "job-min shared", *(f"job-min seed {c}" for c in s["per_seed"])]
    rows = [
        [stage, spans["by_stage"][stage], *(row.get(c, np.nan) for c in cols)]
        for stage, row in sorted(s["by_stage"].items())
    ]
    rows.append(["**all**", spans["run_s"], s["shared_s"], *s["per_seed"].values()])
    minutes = pd.DataFrame(rows, columns=head).set_index("stage") / 60
    minutes = minutes.map(lambda x: "" if np.isnan(x) else f"{x:.1f}").reset_index()
    text = say("summary_cost", span=spans["run_s"] / 60, jobs=len(jobs), job_min=s["total_s"] / 60)
    return ["## What the run cost", "", text, "", *_md(minutes)]


def run_summary(stamp: Mapping[str, str], claims_csv, tab_fit_csv, benchmark_dir) -> str:
    """results/summary.md of a finished run, from its ledger, ``tab_fit`` and benchmarks.

    Args:
        stamp: the run's stamp fields.
        claims_csv (str | Path): the claims ledger's CSV.
        tab_fit_csv (str | Path): ``tab_fit``'s CSV.
        benchmark_dir (str | Path): the benchmark folder.

    Returns:
        The page's Markdown.

    Raises:
        FileNotFoundError: naming a missing file or folder.
    """
    for p in (claims_csv, tab_fit_csv):
        if not Path(p).is_file():
            raise FileNotFoundError(f"{p}: missing (run `snakemake --cores 2 all` first)")
    claims, tab_fit = read_stamped(claims_csv), read_stamped(tab_fit_csv)
    seeds = sorted(int(x) for x in tab_fit["seed"].unique())
    made_by = ", ".join(f"{k}={v}" for k, v in stamp.items())
    trees = ", ".join(dict.fromkeys(tab_fit["tree"]))
    lines = [
        "# Run summary",
        "",
        say("summary_head", made_by=made_by, seeds=", ".join(map(str, seeds)), trees=trees),
        "",
        *_stale(stamp, claims, "results/claims.csv"),
        *_stale(stamp, tab_fit, "results/tables/tab_fit.csv"),
        *claims_section(claims),
        *_fit_section(tab_fit),
        *_cost_section(benchmark_dir),
    ]
    return "\n".join(lines)
