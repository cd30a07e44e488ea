"""results/summary.md (physgs.report.summary) on small fixtures: a ledger made by the claims
module from chosen values, a tab_fit made by the table code from chosen PSNRs, and benchmark files
with chosen durations and end times."""

import os

import numpy as np
import pytest

from physgs.experiments.cost import read_costs, wall_spans
from physgs.models.registry import label
from physgs.report import claims as C
from physgs.report import images as IM
from physgs.report.summary import run_summary

STAMP = {"profile": "quick", "config_hash": "0123456789ab", "physgs_version": "0.1.0"}
T0 = 1_700_000_000.0


def write_claims(path, config_hash=STAMP["config_hash"]):
    def claim(i, threshold, side):
        return C.Claim(f"c{i}", f"claim {i}", "--", "fixture", threshold, side, "dB")

    measured = [
        (claim(0, 0.0, ">"), [2.0, 2.1, 1.9]),  # decided above 0
        (claim(1, 0.0, ">"), [-2.0, -2.1, -1.9]),  # decided below
        (claim(2, 0.0, "<"), [-5.0, 5.0, 0.5]),  # straddles
        (claim(3, 0.0, "<"), [-1.0, -1.1, -0.9]),
    ]
    df = C.ledger(measured).assign(config_hash=config_hash)
    df.to_csv(path, index=False)
    return df


FRAC = {"mlp": 0.25, "ours": 0.75}  # the fit's fraction of the way from static to the ceiling


def write_tab_fit(path, seeds=(0, 1)):
    per_seed = {}
    for s in seeds:
        rows = {}
        for t, (lo, hi) in {"sparse": (20.0, 30.0), "medium": (18.0, 34.0)}.items():
            lo += 0.1 * s  # each seed moves static and ceiling together: fractions unchanged
            hi += 0.1 * s
            fits = {
                "static": lo,
                "truth_motion": hi,
                **{m: lo + f * (hi - lo) for m, f in FRAC.items()},
            }
            for m, fit in fits.items():
                rows[(t, m)] = {
                    "fit": fit,
                    "heldout": fit,
                    "view": fit,
                    "time": fit,
                    "train_s": 1.0,
                    "iterations": 3000,
                }
        per_seed[s] = rows
    tab = IM.tab_fit(
        per_seed,
        ["sparse", "medium"],
        {"sparse": 22, "medium": 224},
        ["static", *FRAC],
        "truth_motion",
    )
    tab.df.assign(config_hash=STAMP["config_hash"]).to_csv(path, index=False)
    return tab.df


# (stage/path, wall seconds, end time relative to T0)
JOBS = [
    ("testbed/sparse.tsv", 100.0, 100.0),
    ("train/sparse/seed0/ours_single.tsv", 300.0, 400.0),
    ("train/sparse/seed1/ours_single.tsv", 240.0, 340.0),
    ("evaluate/sparse/seed0/ours_single.tsv", 60.0, 460.0),
]


def write_benchmarks(root):
    for rel, s, end in JOBS:
        f = root / rel
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(f"s\th:m:s\tmax_rss\n{s}\t0:00:00\t1.0\n")
        os.utime(f, (T0 + end, T0 + end))
    return root


@pytest.fixture
def run(tmp_path):
    claims = write_claims(tmp_path / "claims.csv")
    fit = write_tab_fit(tmp_path / "tab_fit.csv")
    bench = write_benchmarks(tmp_path / "benchmarks")
    text = run_summary(STAMP, tmp_path / "claims.csv", tmp_path / "tab_fit.csv", bench)
    return text, claims, fit


def test_stamp_seeds_and_trees(run):
    text, _, _ = run
    assert "profile=quick, config_hash=0123456789ab, physgs_version=0.1.0" in text
    assert "training seeds 0, 1; trees sparse, medium" in text
    assert "Warning" not in text


def test_verdict_counts_and_each_verdict_come_from_the_ledger(run):
    text, claims, _ = run
    kinds = claims["verdict"].str.split(":").str[0]
    assert set(kinds) == {"holds", "fails", "undecided"}  # the fixture exercises all three
    words = {"holds": "hold", "fails": "fail", "undecided": "undecided"}
    for who, kind in {tuple(x) for x in claims[["origin", "kind"]].to_numpy()}:
        mine = kinds[(claims["origin"] == who) & (claims["kind"] == kind)]
        by = ", ".join(f"{(mine == v).sum()} {w}" for v, w in words.items() if (mine == v).any())
        assert f"{len(mine)} {kind}{'s' if len(mine) > 1 else ''} ({by})" in text
    for _, r in claims.iterrows():
        row = next(line for line in text.splitlines() if line.startswith(f"| `{r['id']}` |"))
        assert row.split(" | ")[3] == r["verdict"]  # the verdict column, before the estimate


def test_fit_fractions_per_tree_and_model(run):
    text, _, _ = run
    lines = text.splitlines()
    assert "| model | sparse | medium |" in lines
    for m, f in FRAC.items():
        row = next(line for line in lines if line.startswith(f"| {label(m)} |"))
        cells = [c.strip() for c in row.strip("|").split("|")][1:]
        assert len(cells) == 2
        for c in cells:  # two seeds with the same fraction: an interval of zero width
            assert c == f"{100 * f:.0f}% [{100 * f:.0f}, {100 * f:.0f}]"
    assert f"| {label('static')} | 0% [0, 0] | 0% [0, 0] |" in lines
    assert "True motion" not in text and "truth_motion" not in text  # the reference is the scale


def test_wall_time_and_job_minutes_by_stage(run, tmp_path):
    text, _, _ = run
    start = min(end - s for _, s, end in JOBS)
    stop = max(end for _, _, end in JOBS)
    assert f"benchmarked jobs span **{(stop - start) / 60:.1f} min**" in text
    assert "Wall time" not in text  # one definition: the stamp's, measured by tools/timed.py
    assert f"{len(JOBS)} benchmarked jobs, {sum(s for _, s, _ in JOBS) / 60:.1f} job-min" in text
    lines = text.splitlines()
    train = next(line for line in lines if line.startswith("| train |"))
    # train spans seed 1's start (340 - 240) to seed 0's end (400); job-minutes per seed
    assert train == f"| train | {(400 - 100) / 60:.1f} |  | {300 / 60:.1f} | {240 / 60:.1f} |"
    testbed = next(line for line in lines if line.startswith("| testbed |"))
    assert testbed.startswith(f"| testbed | {100 / 60:.1f} | {100 / 60:.1f} |")


def test_wall_spans_match_read_costs(tmp_path):
    spans = wall_spans(read_costs(write_benchmarks(tmp_path)))
    assert spans["run_s"] == pytest.approx(460.0)
    assert spans["by_stage"]["evaluate"] == pytest.approx(60.0)


def test_one_seed_has_no_interval(tmp_path):
    write_claims(tmp_path / "claims.csv")
    write_tab_fit(tmp_path / "tab_fit.csv", seeds=(0,))
    text = run_summary(
        STAMP, tmp_path / "claims.csv", tmp_path / "tab_fit.csv", write_benchmarks(tmp_path / "b")
    )
    assert "one seed, no interval" in text
    assert f"| {label('ours')} | 75% | 75% |" in text


def test_a_file_from_another_config_is_flagged(tmp_path):
    write_claims(tmp_path / "claims.csv", config_hash="ffffffffffff")
    write_tab_fit(tmp_path / "tab_fit.csv")
    text = run_summary(
        STAMP, tmp_path / "claims.csv", tmp_path / "tab_fit.csv", write_benchmarks(tmp_path / "b")
    )
    assert "Warning**: results/claims.csv was made under config_hash ffffffffffff" in text
    assert "tab_fit.csv was made" not in text


def test_bad_input_stops_with_the_file_named(tmp_path):
    write_tab_fit(tmp_path / "tab_fit.csv")
    b = write_benchmarks(tmp_path / "b")
    with pytest.raises(FileNotFoundError, match="claims.csv"):
        run_summary(STAMP, tmp_path / "claims.csv", tmp_path / "tab_fit.csv", b)
    df = write_claims(tmp_path / "claims.csv")
    df.assign(verdict="maybe").to_csv(tmp_path / "claims.csv", index=False)
    with pytest.raises(ValueError, match="unknown verdicts"):
        run_summary(STAMP, tmp_path / "claims.csv", tmp_path / "tab_fit.csv", b)
    with pytest.raises(FileNotFoundError, match="benchmark"):
        write_claims(tmp_path / "claims.csv")
        run_summary(STAMP, tmp_path / "claims.csv", tmp_path / "tab_fit.csv", tmp_path / "none")
    assert np.isfinite(df["measured"]).all()


def test_the_paper_apart_and_the_seeds_that_would_decide():
    from physgs.report.summary import claims_section

    def claim(i, origin):
        return C.Claim(f"c{i}", f"claim {i}", "--", "fixture", 0.0, ">", "dB", origin=origin)

    measured = [
        (claim(0, "paper"), [2.0, 2.1, 1.9]),  # holds
        (claim(1, "paper"), [1.0, -0.8, 0.5]),  # undecided, effect 0.23, sd 0.95
        (claim(2, "paper"), [1.0, 0.2, 0.6]),  # undecided, effect 0.6, sd 0.4
        (claim(3, "project"), [-2.0, -2.1, -1.9]),  # fails
        (claim(4, "project"), [0.4]),  # one seed: no estimate
    ]
    df = C.ledger(measured)
    text = "\n".join(claims_section(df))
    assert "The paper's 3 claims: 3 findings (1 hold, 2 undecided)" in text
    assert "This project's own 2 claims: 2 findings (1 fail, 1 undecided)" in text
    # by hand (t half-width 2.776 sd / sqrt(3) > effect now): claim 2 decides at
    # t_{0.975, n-1} 0.4 / sqrt(n) < 0.6, first at n = 5 (2.776 * 0.4 / 2.236 = 0.497)
    assert df.loc[2, "seeds_to_decide_t_est"] == 5
    n1 = df.loc[1, "seeds_to_decide_t_est"]
    assert n1 > 6
    row = next(ln for ln in text.splitlines() if ln.startswith("| the paper's (2) | plug-in t |"))
    assert row == "| the paper's (2) | plug-in t | 0 | 1 | 1 | 1 |"
    assert "| this project's (0) | plug-in t | 0 | 0 | 0 | 0 |" in text
    assert "| `c2` | " in text and "| t 5 / power" in text
