"""The committed record of a run (physgs.report.record, tools/record.py): what it writes, that the
README and the home page say what the record holds, and that no page types a result table."""

import json
import re
import subprocess
import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from physgs.report import catalogue, record
from physgs.report import claims as ledger

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "docs" / "record"


def _run(tmp_path):
    """A finished run's files, small: two tables, a ledger, a summary, a wide and a small PNG."""
    r = tmp_path / "results"
    (r / "tables").mkdir(parents=True)
    (r / "figures").mkdir()
    fit = pd.DataFrame(
        {
            "tree": ["sparse", "sparse"],
            "model": ["ours", "ours"],
            "seed": [0, 1],
            "ceiling_frac": [0.13456789, np.nan],
            "profile": ["default"] * 2,
            "config_hash": ["0123abcd"] * 2,
        }
    )
    fit.to_csv(r / "tables" / "tab_fit.csv", index=False)
    pd.DataFrame({"tree": ["medium"], "psnr_db": [24.6049]}).to_csv(
        r / "tables" / "tab_psnr.csv", index=False
    )
    claims = pd.DataFrame(
        {
            "id": [
                "ours_above_static_beyond/sparse",
                "ours_above_static_beyond/medium",
                "null_factor/sparse",
                "fits_window/medium/mlp",
            ],
            "measured": [1.99, 6.25, 1.27, 0.346],
            "ci_low": [1.2, 4.1, 0.56, np.nan],
            "ci_high": [2.77, 8.4, 1.97, np.nan],
            "unit": ["dB", "dB", "x", ""],
            "threshold": [0, 0, 2.5, 0.5],
            "verdict": ["holds", "holds", "fails", "undecided: one seed"],
        }
    )
    claims.to_csv(r / "claims.csv", index=False)
    (r / "claims.md").write_text("# Claims ledger\n\ntext\n")
    (r / "summary.md").write_text("# Run summary\n\n## Claims ledger\n\n#not a heading\n")
    Image.new("RGB", (2400, 600), (10, 20, 30)).save(r / "figures" / "fig_temporal.png")
    Image.new("RGB", (300, 200), (200, 20, 30)).save(r / "figures" / "testbed_sparse.png")
    return r, fit, claims


def _stamp():
    return record.Stamp(
        date="2026-01-02",
        commit="abc1234",
        profile="default",
        config_hash="0123abcd",
        seeds=(0, 1),
        trees=("sparse",),
        cpu="test CPU (no bf16)",
        wall_s=11285.0,
        job_min_by_stage={"training": 287.0, "evaluation": 29.0},
    )


def _record(r, out, tables=None, figures=None, summary=None, stamp=None, **kw):
    """write_record over the run ``r`` (every table and figure unless given)."""
    return record.write_record(
        out,
        stamp=stamp or _stamp(),
        summary_md=summary or r / "summary.md",
        claims_csv=r / "claims.csv",
        claims_md=r / "claims.md",
        tables=sorted((r / "tables").glob("*.csv")) if tables is None else tables,
        figures=sorted((r / "figures").glob("*.png")) if figures is None else figures,
        **kw,
    )


def test_the_record_never_holds_the_snakemake_report_and_says_how_to_make_it(tmp_path):
    r, _, _ = _run(tmp_path)
    out = tmp_path / "record"
    _record(r, out)
    assert not (out / "report.html").exists()
    assert "python tools/record.py --report-html" in (out / "index.md").read_text()
    with pytest.raises(TypeError):
        _record(r, out, report_html=r / "report.html")


def test_no_tracked_file_exceeds_one_megabyte():
    """A clone stays light: no file over 1 MB enters the repository (a Snakemake report is
    ~10 MB; each record's would be in every clone's history)."""
    files = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split("\0")
    big = [
        f"{f}: {(ROOT / f).stat().st_size / 1e6:.1f} MB"
        for f in files
        if f and (ROOT / f).is_file() and (ROOT / f).stat().st_size > 1_000_000
    ]
    assert not big, "tracked files over 1 MB:\n" + "\n".join(big)


def _parse_md_table(text):
    rows = [ln.strip().strip("|").split("|") for ln in text.strip().splitlines()]
    head, body = [c.strip().replace("<wbr>", "") for c in rows[0]], rows[2:]
    return head, [[c.strip() for c in row] for row in body]


def test_write_record_copies_every_table_as_csv_and_summarises_it_over_seeds(tmp_path):
    r, fit, _ = _run(tmp_path)
    out = tmp_path / "record"
    _record(r, out)
    assert (out / "tables" / "tab_fit.csv").read_bytes() == (r / "tables/tab_fit.csv").read_bytes()
    head, body = _parse_md_table((out / "tables" / "tab_fit.md").read_text())
    assert head == ["tree", "model", "ceiling_frac"]  # no seed, no stamp columns
    assert body == [["sparse", "ours", "0.1346"]]  # one seed has a value: shown alone
    tables = (out / "tables.md").read_text()
    assert '--8<-- "docs/record/tables/tab_fit.md"' in tables and "tab_psnr" in tables
    assert "[tab_fit.csv](record/tables/tab_fit.csv)" in tables  # per-seed rows: a download
    assert "mean ± sd over training seeds 0, 1" in tables
    index = (out / "index.md").read_text()
    assert '--8<-- "docs/record/summary.md"' in index
    # the figures first, then the ledger, then the tables, then the run
    heads = [ln for ln in index.splitlines() if ln.startswith("## ")]
    assert heads == ["## Figures", "## The paper against the measured", "## Tables", "## The run"]
    assert (
        "4 claims: 3 findings (2 hold, 1 fail), 1 premise (1 undecided)" in index
        and "(ledger.md)" in index
    )
    stamp = json.loads((out / "stamp.json").read_text())
    assert stamp["seeds"] == [0, 1] and stamp["wall_s"] == 11285.0
    assert "3 h 8 min" in (out / "stamp.md").read_text()
    assert "316 job-minutes" in (out / "stamp.md").read_text()
    # headings one level down, so the included summary sits under the Results page's title
    summary = (out / "summary.md").read_text().splitlines()
    assert summary[0] == "## Run summary" and "### Claims ledger" in summary
    assert "#not a heading" in summary


def test_a_markdown_table_aligns_the_columns_named_right_and_prints_floats_to_four_digits():
    df = pd.DataFrame({"table": ["a|b", "c"], "rows": [3, 12], "x": [1.23456, np.nan]})
    assert record.markdown_table(df, right=["rows", "x"]) == (
        "| table | rows | x |\n"
        "|---|---:|---:|\n"
        "| a\\|b | 3 | 1.235 |\n"  # a pipe in a cell escaped, a float to 4 digits
        "| c | 12 | -- |\n"  # NaN
    )


def test_a_table_summary_is_mean_and_sd_over_seeds_in_readable_widths():
    rng = np.random.default_rng(0)
    rows = []
    for seed in (0, 1, 2):
        for tree in ("sparse", "dense"):
            rows.append(
                {"seed": seed, "tree": tree, "bones": 22 if tree == "sparse" else 562}
                | {f"v{i}": rng.normal(10 * i, 1) for i in range(12)}
                | {"profile": "default", "config_hash": "00ff"}
            )
    df = pd.DataFrame(rows)
    summary, keys, seeds = record.table_summary(df)
    assert keys == ["tree"] and seeds == [0, 1, 2]
    assert list(summary["bones"]) == ["22", "562"]  # the same on every seed: no "± 0"
    m, sd = summary.loc[1, "v3"].split(" ± ")
    want = df[df["tree"] == "dense"]["v3"]
    assert float(m) == pytest.approx(want.mean(), rel=1e-3)
    assert float(sd) == pytest.approx(want.std(ddof=1), rel=0.05)  # two significant digits
    parts = record.summary_markdown(df).strip().split("\n\n")
    heads = [_parse_md_table(t)[0] for t in parts]
    assert all(h[0] == "tree" for h in heads)  # the key repeated in each part
    assert all(len(h) <= 1 + record.VALUE_COLUMNS_SHOWN for h in heads)
    assert sum(len(h) - 1 for h in heads) == 13  # bones and v0..v11, each once


def test_figures_are_shown_in_reading_order_each_with_a_caption_from_its_declaration(tmp_path):
    from physgs.report import captions
    from physgs.report.outputs import OUTPUTS

    r, _, _ = _run(tmp_path)
    for name in ("testbed_medium", "fig_damping"):
        Image.new("RGB", (300, 200)).save(r / "figures" / f"{name}.png")
    out = tmp_path / "record"
    _record(r, out, stamp=record.Stamp(**{**asdict(_stamp()), "trees": ("sparse", "medium")}))
    text = (out / "figures.md").read_text()
    shown = re.findall(r"!\[(\w+)\]", text)
    assert shown == ["fig_temporal", "fig_damping", "testbed_sparse", "testbed_medium"]
    assert "*Seeds:* mean over training seeds 0, 1." in text  # fig_temporal reads all seeds
    assert OUTPUTS["fig_damping"].seeds == "first"
    assert "*Seeds:* training seed 0 (the first of the run's 2)." in text
    assert "The synthetic medium tree" in text and "no training seed" in text
    # every figure a run draws has a caption
    for name in OUTPUTS:
        if OUTPUTS[name].kind == "figure":
            captions.find(name)
    assert captions.find("fig_stabilisation")[2] == ""  # one figure, every tree a column
    assert captions.find("testbed_dense_damping")[2] == "dense"
    with pytest.raises(KeyError, match="fig_new"):
        captions.caption("fig_new", [0])
    # a caption of captions.yaml with a misspelled or a missing key is refused, naming it
    entry = {"pattern": "fig_x", "title": "t", "shows": "s", "read": "r"}
    assert captions.checked([entry])[0]["seeds"] == "first"
    with pytest.raises(ValueError, match="'fig_x' has keys"):
        captions.checked([{**entry, "raed": "r"}])
    with pytest.raises(ValueError, match="'fig_x'"):
        captions.checked([{k: v for k, v in entry.items() if k != "read"}])


def test_the_committed_record_re_renders_from_its_own_files(tmp_path):
    """The committed pages are what render_pages makes of the committed record's files."""
    import shutil

    copy = tmp_path / "record"
    shutil.copytree(RECORD, copy)
    assert not record.derive_claims(copy)  # the committed ledger has every derived column
    record.render_pages(copy)
    for page in (
        "index.md",
        "figures.md",
        "ledger.md",
        "tables.md",
        "stamp.md",
        *(f"tables/{t.stem}.md" for t in RECORD.glob("tables/*.csv")),
    ):
        assert (copy / page).read_text() == (RECORD / page).read_text(), (
            f"docs/record/{page} is stale: run `python tools/record.py --pages-only`"
        )


def test_the_ledger_page_puts_the_papers_claims_first_one_row_each_filterable():
    from html.parser import HTMLParser

    claims = pd.read_csv(RECORD / "claims.csv", dtype={"config_hash": str})
    page = record.ledger_page(RECORD / "claims.csv", ("sparse", "medium", "dense"))

    class Rows(HTMLParser):
        def __init__(self):
            super().__init__()
            self.rows, self.cells, self.cell = [], [], None

        def handle_starttag(self, tag, attrs):
            if tag == "tr" and dict(attrs).get("data-origin"):
                self.rows.append(dict(attrs))
                self.cells.append([])
            elif tag == "td":
                self.cell = ""

        def handle_data(self, data):
            if self.cell is not None:
                self.cell += data

        def handle_endtag(self, tag):
            if tag == "td":
                self.cells[-1].append(self.cell)
                self.cell = None

    p = Rows()
    p.feed(page)
    assert len(p.rows) == len(claims)
    origins = [r["data-origin"] for r in p.rows]
    n_paper = int((claims["origin"] == "paper").sum())
    assert origins == ["paper"] * n_paper + ["project"] * (len(claims) - n_paper)
    by_id = {r["id"]: (r, c) for r, c in zip(p.rows, p.cells)}
    row, cells = by_id["claim-fits-window-dense-mlp"]
    want = claims.set_index("id").loc["fits_window/dense/mlp"]
    assert (row["data-verdict"], row["data-tree"], row["data-kind"]) == (
        want["verdict"],
        "dense",
        "premise",
    )
    assert cells[1:] == [
        "dense",
        want["paper"],
        f"{want['measured']:+.3g} [{want['ci_low']:+.3g}, {want['ci_high']:+.3g}] fraction",
        want["verdict"],
        "premise",
        "paper",
    ]
    assert want["claim"] in cells[0] and want["source"] in cells[0]  # one click away
    assert "if it fails, it undermines every comparison that model enters" in cells[0]
    assert f'class="verdict-{want["verdict"]}"' in page.split('id="claim-fits-window-dense-mlp"')[1]


def test_a_ledger_gains_its_kind_from_the_catalogue_and_keeps_every_number(tmp_path):
    """A record written before the kind column gains it from its ids; nothing else moves, and
    its claims.md is the claims rule's printer's (the committed one, kind and counts aside)."""
    import shutil

    copy = tmp_path / "record"
    shutil.copytree(RECORD, copy)
    committed = pd.read_csv(RECORD / "claims.csv", dtype=str, keep_default_na=False)
    committed.drop(columns="kind").to_csv(copy / "claims.csv", index=False)
    (copy / "claims.md").write_text("stale")
    summary = (RECORD / "summary.md").read_text()
    a, b = summary.index(record.SUMMARY_CLAIMS), summary.index("### Fit to the training window")
    (copy / "summary.md").write_text(summary[:a] + "### Claims ledger\n\nstale\n\n" + summary[b:])
    written = record.derive_claims(copy)
    assert set(written) == {copy / "claims.csv", copy / "claims.md", copy / "summary.md"}
    # the claims section printed again, the rest (made from the benchmarks) as it was
    assert (copy / "summary.md").read_text() == summary
    again = pd.read_csv(copy / "claims.csv", dtype=str, keep_default_na=False)
    pd.testing.assert_frame_equal(again, committed)  # text for text, kind where it was
    premises = set(again.loc[again["kind"] == "premise", "id"].str.split("/").str[0])
    assert premises == {"fits_window", "nearest_bone_gap"}
    assert set(again["kind"]) == {"premise", "finding"}
    assert (copy / "claims.md").read_text() == (RECORD / "claims.md").read_text()
    assert not record.derive_claims(copy)  # once is enough


def test_a_stamp_names_a_plain_commit_and_keeps_its_note_apart():
    with pytest.raises(ValueError, match="plain commit hash"):
        record.Stamp(**{**asdict(_stamp()), "commit": "50d07ab (as e78f42e)"})
    with pytest.raises(ValueError, match="plain commit hash"):
        record.Stamp(**{**asdict(_stamp()), "commit": "v0.1.0-240-gfbbbfaa"})
    s = record.Stamp(**{**asdict(_stamp()), "note": "resumed twice", "jobs": 498})
    md = s.markdown()
    assert "commit `abc1234`;" in md and "- **Note**: resumed twice" in md
    assert "498 benchmarked jobs" in md
    committed = json.loads((RECORD / "stamp.json").read_text())
    assert record.COMMIT.match(committed["commit"])
    costs = record.read_costs(RECORD / "costs.csv")
    assert all(record.COMMIT.match(str(c)) for c in costs["commit"]), list(costs["commit"])


def test_git_commit_is_a_plain_hash():
    from physgs.provenance import git_commit

    assert record.COMMIT.match(git_commit(ROOT))


def test_figures_are_web_sized_and_keep_their_aspect(tmp_path):
    r, _, _ = _run(tmp_path)
    out = tmp_path / "record"
    _record(r, out, tables=[])
    with Image.open(out / "figures" / "fig_temporal.png") as im:
        assert (im.width, im.height) == (record.FIGURE_WIDTH_PX, 300)
    with Image.open(out / "figures" / "testbed_sparse.png") as im:
        assert (im.width, im.height) == (300, 200)  # never enlarged


def test_a_missing_input_is_named_and_what_no_run_makes_outlives_a_new_record(tmp_path):
    r, _, _ = _run(tmp_path)
    out = tmp_path / "record"
    record.record_costs(
        out / "costs.csv",
        dict(
            name="all",
            command="snakemake --cores 2 all",
            wall_s=100.0,
            date="d",
            commit="c",
            cpu="x",
            from_nothing=True,
            segments=1,
        ),
    )
    with pytest.raises(FileNotFoundError, match="summary.md"):
        _record(r, out, tables=[], figures=[], summary=r / "nope" / "summary.md")
    (out / "rates_paper.csv").write_text("model,ms\nours,1\n")
    (out / "paper_estimate.md").write_text("an estimate\n")
    (out / "from_the_old_run.md").write_text("gone\n")
    _record(r, out, tables=[], figures=[])
    assert record.read_costs(out / "costs.csv")["wall_s"].tolist() == [100.0]
    # what no run makes outlives the record; what the old run made goes with it
    assert (out / "rates_paper.csv").read_text() == "model,ms\nours,1\n"
    assert (out / "paper_estimate.md").read_text() == "an estimate\n"
    assert not (out / "from_the_old_run.md").exists()


def test_premises_are_counted_apart_and_a_failed_one_says_what_it_undermines():
    claims = pd.DataFrame(
        {
            "id": [
                "ours_above_static_beyond/sparse",
                "fits_window/sparse/mlp",
                "fits_window/dense/mlp",
                "nearest_bone_gap/sparse",
                "fits_window/dense/ours_chain",
            ],
            "measured": [1.99, 0.05, 0.1, 0.01, 0.6],
            "ci_low": [1.2, 0.03, 0.08, np.nan, 0.55],
            "ci_high": [2.77, 0.07, 0.12, np.nan, 0.65],
            "unit": ["dB", "fraction", "fraction", "fraction", "fraction"],
            "verdict": ["holds", "fails", "fails", "holds", "holds"],
            "origin": ["paper", "paper", "paper", "paper", "project"],
        }
    )  # no kind column: a ledger written before it takes the kind from the catalogue
    lines = record.headline_lines(claims)
    assert lines[0].startswith(
        "- **The paper's 4 claims: 1 finding (1 hold), 3 premises (1 hold, 2 fail)**; this "
        "project's own 1 claim: 1 premise (1 hold)"
    )
    assert lines[1].startswith("- **Premises that fail**: the premise `fits_window` fails on ")
    assert (
        "sparse (mlp), dense (mlp): this undermines every comparison that model enters" in lines[1]
    )
    assert "nearest_bone_gap" not in lines[1]  # it holds
    written = claims.assign(kind="finding")  # a written column is read, not the catalogue's
    assert "premise" not in record.headline_lines(written)[0].split("(95%")[0]


def test_headline_counts_the_verdicts_and_gives_each_story_claim_its_interval():
    claims = pd.DataFrame(
        {
            "id": ["ours_above_static_beyond/sparse", "null_factor/sparse", "other/x", "other/y"],
            "measured": [1.99, 1.27, 0.0, 0.0],
            "ci_low": [1.2, 0.56, np.nan, np.nan],
            "ci_high": [2.77, 1.97, np.nan, np.nan],
            "unit": ["dB", "x", "", ""],
            "verdict": ["holds", "fails", "undecided: one seed", "holds"],
            "origin": ["paper", "paper", "project", "project"],
        }
    )
    lines = record.headline_lines(claims)
    # the paper's claims counted apart from this project's, the paper's first
    assert "The paper's 2 claims: 2 findings (1 hold, 1 fail)" in lines[0]
    assert "this project's own 2 claims: 2 findings (1 hold, 1 undecided)" in lines[0]
    # whether the paper's story stands, from its headline families' verdicts
    assert "stands in part**: 1 of its 2 headline claims hold" in lines[1]
    assert "fails on ours beats the untrained null by the paper's factor" in lines[1]
    assert len(lines) == 4  # counts, story, then the two story families present, in order
    assert lines[2].startswith("- Ours above the static pose")
    assert "sparse **holds** (+1.99 [+1.2, +2.77] dB)" in lines[2]
    assert "sparse **fails** (+1.27 [+0.56, +1.97] x)" in lines[3]


def test_headline_says_the_direction_and_whether_the_papers_size_is_reproduced():
    """The record's medium tree: ours above static by +6.27 [+6.13, +6.42] dB holds, where the
    paper reported +2.80: outside the interval; a range of the paper's that meets it: inside."""
    claims = pd.DataFrame(
        {
            "id": ["ours_above_static_beyond/medium", "damping_not_recovered/dense"],
            "measured": [6.27, 0.498],
            "ci_low": [6.13, 0.237],
            "ci_high": [6.42, 0.759],
            "unit": ["dB", "fraction"],
            "verdict": ["holds", "holds"],
            "origin": ["paper", "paper"],
            "paper_low": [2.80, 0.5625],
            "paper_high": [2.80, 0.775],
            "paper_in_interval": ["outside", "inside"],
        }
    )
    lines = record.headline_lines(claims)
    assert "medium **holds** (+6.27 [+6.13, +6.42] dB; the paper's +2.8 outside)" in lines[2]
    assert (
        "dense **holds** (+0.498 [+0.237, +0.759] fraction; the paper's +0.562 to +0.775 inside)"
        in lines[3]
    )


def test_the_stamp_names_the_tree_instances():
    """Five instances per tree (testbed_seeds): the training seeds' testbed seeds; one (the
    paper's protocol, or a table made before the column): the config's testbed seed."""
    tb = pd.DataFrame({"tree": ["sparse", "medium"], "instances": [5, 1]})
    got = record.instances_of(tb, [4, 3, 2, 1, 0], 0)
    assert got == {"sparse": [0, 1, 2, 3, 4], "medium": [0]}
    assert record.instances_of(tb.drop(columns="instances"), [0, 1], 7) == {
        "sparse": [7],
        "medium": [7],
    }
    s = record.Stamp(**{**asdict(_stamp()), "instances": got})
    assert "- **Tree instances**: sparse: testbed seeds 0, 1, 2, 3, 4; medium: testbed seed 0" in (
        s.markdown()
    )
    assert "Tree instances" not in _stamp().markdown()  # a record made before the field


def test_a_ledger_without_origins_takes_them_from_the_catalogue():
    claims = pd.DataFrame(
        {
            "id": [
                "fits_window/sparse/mlp",
                "fits_window/sparse/ours_chain",
                "oma_beats_null/sparse",
            ],
            "verdict": ["holds", "fails", "undecided"],
        }
    )
    # the paper's family, but a model the paper did not train; the output-only analysis
    assert ledger.column(claims, "origin").tolist() == ["paper", "project", "project"]
    assert record.story_line(claims) == ""  # none of the paper's headline claims
    with pytest.raises(ValueError, match="no family"):
        ledger.column(pd.DataFrame({"id": ["nothing/x"], "verdict": ["holds"]}), "origin")


def test_a_headline_family_of_another_prior_is_found_by_its_id_prefix():
    claims = pd.DataFrame(
        {
            "id": [
                "ours_chain/above_static_beyond/dense",
                "ours_chain_blind/above_static_beyond/dense",  # another model: not the family
                "anemometer_needed/sparse",
            ],
            "measured": [2.0, 9.0, 23.5],
            "ci_low": [1.0, 8.0, -15.0],
            "ci_high": [3.0, 10.0, 62.0],
            "unit": ["dB", "dB", "points"],
            "verdict": ["holds", "holds", "undecided: interval spans 0"],
        }
    )
    lines = record.headline_lines(claims)
    chain = [ln for ln in lines if ln.startswith("- The chained prior")]
    assert len(chain) == 1 and "dense **holds** (+2 [+1, +3] dB)" in chain[0]
    assert "+9" not in chain[0]
    wind = [ln for ln in lines if ln.startswith("- Without the anemometer")]
    assert len(wind) == 1 and "sparse **undecided** (+23.5 [-15, +62] points)" in wind[0]


def test_costs_say_not_measured_rather_than_guess():
    lines = record.cost_lines(record.read_costs("/nonexistent/costs.csv"))
    assert len(lines) == 2 + len(record.COMMANDS)
    assert all("not measured" in ln for ln in lines[2:])


def test_timed_records_a_command_and_passes_a_failure_on(tmp_path):
    costs = tmp_path / "costs.csv"
    ok = subprocess.run(
        [sys.executable, "tools/timed.py", "--name", "tests", "--costs", str(costs), "--", "true"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert ok.returncode == 0, ok.stderr
    row = record.read_costs(costs).iloc[0]
    assert row["name"] == "tests" and row["command"] == "true" and 0 <= row["wall_s"] < 30
    bad = subprocess.run(
        [sys.executable, "tools/timed.py", "--name", "all", "--costs", str(costs), "--", "false"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert bad.returncode == 1
    assert record.read_costs(costs)["name"].tolist() == ["tests"]


def test_a_resumed_run_records_the_sum_of_its_segments(tmp_path):
    costs = tmp_path / "costs.csv"
    cmd = [sys.executable, "tools/timed.py", "--name", "all", "--costs", str(costs)]
    ok = subprocess.run(
        [*cmd, "--from-nothing", "--earlier", "3600", "1800", "--", "true"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert ok.returncode == 0, ok.stderr
    row = record.read_costs(costs).iloc[0]
    assert 5400 <= row["wall_s"] < 5430 and row["segments"] == 3
    line = [ln for ln in record.cost_lines(record.read_costs(costs)) if "1 h 30 min" in ln][0]
    assert "(from nothing), in 3 segments" in line


def test_a_resumed_run_reads_its_earlier_segments_from_snakemakes_logs(tmp_path):
    logs = tmp_path / "log"
    logs.mkdir()
    (logs / "2026-11-09T080000.1.snakemake.log").write_text(
        "[Mon Nov  9 09:00:00 2026]\nFinished jobid: 1 (Rule: a)\n"
    )
    (logs / "2026-11-09T100000.2.snakemake.log").write_text("Unlocked working directory.\n")
    (logs / "2026-11-10T080000.3.snakemake.log").write_text(
        "[Tue Nov 10 08:30:00 2026]\nFinished job 2.\n"
    )
    costs = tmp_path / "costs.csv"
    cmd = [sys.executable, "tools/timed.py", "--name", "all", "--costs", str(costs)]
    ok = subprocess.run(
        [*cmd, "--earlier-logs", str(logs), "--", "true"], cwd=ROOT, capture_output=True, text=True
    )
    assert ok.returncode == 0, ok.stderr
    row = record.read_costs(costs).iloc[0]
    assert 5400 <= row["wall_s"] < 5430 and row["segments"] == 3  # 1 h + 30 min + this one
    assert "earlier segment 2026-11-10T080000.3.snakemake.log: 30 min 0 s" in ok.stderr
    both = subprocess.run(
        [*cmd, "--earlier-logs", str(logs), "--earlier", "5", "--", "true"], cwd=ROOT,
        capture_output=True, text=True,
    )  # fmt: skip
    assert both.returncode == 2 and "one way" in both.stderr


def test_a_cost_is_shown_with_the_command_it_was_measured_with(tmp_path):
    # tab_null timed at three seeds while the default profile runs five: the row must say so
    costs = tmp_path / "costs.csv"
    costs.write_text(
        "name,command,wall_s,date,commit,cpu,from_nothing,segments\n"
        "tab_null,\"snakemake --cores 2 results/tables/tab_null.tex --config 'seeds=[0,1,2]'\","
        "622.6,2026-11-27,090cbb9,cpu,True,1\n"
    )
    line = [ln for ln in record.cost_lines(record.read_costs(costs)) if "tab_null" in ln]
    assert line == [
        "| `snakemake --cores 2 results/tables/tab_null.tex --config 'seeds=[0,1,2]'` | "
        "10 min 23 s (from nothing) | 2026-11-27, commit `090cbb9`, cpu |"
    ]


def test_costs_recorded_before_segments_read_as_one_segment(tmp_path):
    old = tmp_path / "costs.csv"
    old.write_text("name,command,wall_s,date,commit,cpu,from_nothing\nall,x,60.0,d,c,u,True\n")
    assert record.read_costs(old)["segments"].tolist() == [1]


def test_readme_and_home_page_say_what_the_record_holds():
    readme = (ROOT / "README.md").read_text()
    want = record.readme_block(record.found_lines(RECORD))
    assert record.replace_block(readme, want) == readme, (
        "the README's record block differs from docs/record: run `python tools/record.py "
        "--readme-only`"
    )
    assert (RECORD / "found.md").read_text() == "\n".join(record.found_lines(RECORD))
    costs = record.cost_lines(record.read_costs(RECORD / "costs.csv"))
    assert (RECORD / "costs.md").read_text() == "\n".join(costs) + "\n"
    assert '--8<-- "docs/record/costs.md"' in (ROOT / "docs" / "performance.md").read_text()
    assert '--8<-- "docs/record/found.md"' in (ROOT / "docs" / "index.md").read_text()
    assert '--8<-- "docs/record/index.md"' in (ROOT / "docs" / "results.md").read_text()


#: A table cell that states a measured result: a PSNR, a percentage, an interval, a duration.
#: A table of the evidence a setting was chosen on (training-window data, the measurements that
#: size a request) says so in the comment :data:`CHOSEN` on the line before it. The claims page's
#: list of claims is generated from the catalogue (its thresholds and the paper's figures, no
#: result; tests/test_claims_catalogue.py holds it in sync): not typed.
CHOSEN = "<!-- how a setting was chosen"
GENERATED = (catalogue.BEGIN, catalogue.END)
RESULT_CELL = re.compile(r"\d\s*dB\b|\d\s*%|±|\d\s*(min|ms)\b|\[\s*[-+]?\d[\d.]*\s*,")


def test_no_page_types_a_result_table():
    found = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        lines = page.read_text().splitlines()
        chosen = generated = False
        for n, line in enumerate(lines, 1):
            generated = (generated or line == GENERATED[0]) and line != GENERATED[1]
            if generated:
                continue
            if not line.startswith("|"):
                chosen = line.startswith(CHOSEN)
                continue
            if chosen or re.match(r"^\|[-| :]+\|\s*$", line):
                continue
            cells = line.strip().strip("|").split("|")[1:]
            if any(RESULT_CELL.search(c) for c in cells):
                found.append(f"docs/{page.name}:{n}: {line[:90]}")
    assert not found, "result tables typed by hand (the record shows results):\n" + "\n".join(found)


def test_a_new_record_says_what_moved_against_the_one_it_replaces(tmp_path):
    r, fit, claims = _run(tmp_path)
    out = tmp_path / "record"
    _record(r, out)
    assert "No earlier record" in (out / "rerun.md").read_text()
    # a rerun at another commit: one verdict and one table cell move, beyond the seed spread
    claims.loc[2, ["measured", "ci_low", "ci_high", "verdict"]] = [3.1, 2.6, 3.6, "holds"]
    claims.to_csv(r / "claims.csv", index=False)
    fit.loc[0, "ceiling_frac"] = 0.5
    fit.to_csv(r / "tables" / "tab_fit.csv", index=False)
    stamp = record.Stamp(**{**json.loads((out / "stamp.json").read_text()), "commit": "def5678"})
    _record(r, out, figures=[], stamp=stamp)
    text = (out / "rerun.md").read_text()
    assert "commit `abc1234`" in text and "the same config hash" in text
    assert "3 of 4 claims in both runs keep their verdict, 1 changed" in text
    assert "| fails, +1.27 [+0.56, +1.97] x | **holds**, +3.1 [+2.6, +3.6] x | 2.5 x | no |" in text
    assert "Of the 1 moved verdicts, 0 moved with overlapping intervals" in text
    assert "1 with intervals apart" in text
    head, body = _parse_md_table(text.split("**The seeded tables**")[1].split("\n\n")[1])
    row = dict(zip(head, body[0]))
    assert row["table"] == "`tab_fit`" and (row["identical"], row["beyond it"]) == ("1", "1")
    assert "`ceiling_frac` | 0.1346 | 0.5 |" in text
    assert '--8<-- "docs/record/rerun.md"' in (out / "index.md").read_text()
    # the same run recorded again (say, with Snakemake's report) keeps its comparison
    _record(r, out, figures=[], stamp=stamp)
    assert (out / "rerun.md").read_text() == text


def test_the_readme_s_first_screen_names_the_ledger_and_each_command_s_cost_from_the_record():
    """The README's first 25 lines: the ledger linked, each command beside its cost as the
    record measured it, the paper profile's CPU-hours as its estimate computed them; the home
    page links the ledger in its first lines."""
    head = (ROOT / "README.md").read_text().splitlines()[:25]
    assert any("(docs/ledger.md)" in ln for ln in head)  # the site's page
    assert any("(docs/record/claims.md)" in ln for ln in head)  # the one GitHub renders
    costs = record.read_costs(RECORD / "costs.csv").set_index("name")
    for name, command in (
        ("all", "snakemake --cores 2 all`"),
        ("tests", "`python -m pytest -q`"),
        ("quick_all", "snakemake --cores 2 all --config profile=quick`"),
    ):
        (line,) = [ln for ln in head if command in ln]
        assert record.format_duration(float(costs.loc[name, "wall_s"])) in line, (name, line)
    hours = re.search(r"\*\*(\d[\d,]*) CPU-hours\*\*", (RECORD / "paper_estimate.md").read_text())
    text = " ".join(" ".join(head).split())
    assert f"{hours.group(1)} CPU-hours" in text and "paper_estimate.md" in text
    home = [ln for ln in (ROOT / "docs" / "index.md").read_text().splitlines() if ln.strip()]
    assert any("(ledger.md)" in ln for ln in home[:3])


def test_leftovers_of_a_write_that_stopped_are_settled_not_an_oserror(tmp_path):
    r, _, _ = _run(tmp_path)
    out = tmp_path / "record"
    _record(r, out)
    # stopped after the swap: an old record beside the new one, and a half-written one
    (tmp_path / "record.old" / "tables").mkdir(parents=True)
    (tmp_path / "record.old" / "tables" / "stale.csv").write_text("a\n1\n")
    (tmp_path / "record.partial").mkdir()
    (tmp_path / "record.partial" / "stamp.json").write_text("{")
    _record(r, out)
    assert not (tmp_path / "record.old").exists()
    assert not (tmp_path / "record.partial").exists()
    assert json.loads((out / "stamp.json").read_text())["commit"] == "abc1234"
    # stopped between the renames: the last record is only record.old; it is put back, and what
    # no run makes (its costs) outlives the new record
    (out / "costs.csv").write_text("name,wall_s\nall,5\n")
    out.rename(tmp_path / "record.old")
    _record(r, out)
    assert (out / "costs.csv").read_text() == "name,wall_s\nall,5\n"
    assert not (tmp_path / "record.old").exists()


def test_the_findings_say_when_a_trees_name_stands_for_several_instances():
    from physgs.report.record import instances_phrase

    assert instances_phrase({}) == ""
    assert instances_phrase({"sparse": [0], "medium": [0]}) == ""  # the paper's one instance
    five = instances_phrase({"sparse": [0, 1, 2, 3, 4], "medium": [0, 1, 2, 3, 4]})
    assert five == (
        "; each of sparse, medium measured on five instances of its preset (testbed seeds "
        '0, 1, 2, 3, 4), so "sparse" below means sparse-preset trees'
    )
    mixed = instances_phrase({"sparse": [0, 1], "dense": [0, 1, 2]})
    assert "several instances" in mixed and "testbed seeds" not in mixed


def test_every_data_file_of_the_package_ships_with_it():
    """A data file the library reads (the schema, the captions, the record's page templates) is
    in the wheel only when pyproject's package-data names it: a wheel would otherwise lose it."""
    import fnmatch
    import tomllib
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    patterns = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"][
        "package-data"
    ]["physgs"]
    pkg = root / "src" / "physgs"
    data = [p.relative_to(pkg).as_posix() for e in ("yaml", "md") for p in pkg.rglob(f"*.{e}")]
    shipped = ("captions", "prose", "image_tables", "table_captions")
    assert {f"report/{n}.yaml" for n in shipped} | {"report/templates/index.md"} <= set(data)
    assert all(any(fnmatch.fnmatch(d, pat) for pat in patterns) for d in data), (data, patterns)


def test_a_record_on_instances_says_where_the_first_seed_alone_lies(tmp_path):
    """A run with several instances of a tree against a one-instance record: each moved verdict
    beside its first seed alone (the record's own tree), recomputed from the run's tables, and a
    sentence counting which the other instances moved."""
    r, fit, claims = _run(tmp_path)
    psnr = pd.DataFrame(
        [
            {"seed": s, "model": m, "sparse_view": 22.0, "sparse_time": t}
            for s, offsets in enumerate([(0.0, 1.5), (0.0, -2.0), (0.0, -2.5)])
            for m, t in zip(("static", "ours"), (20.0 + offsets[0], 20.0 + offsets[1]))
        ]
    )
    out = tmp_path / "record"
    _record(r, out, tables=[r / "tables" / "tab_fit.csv"], figures=[])
    psnr.to_csv(r / "tables" / "tab_psnr.csv", index=False)
    claims.loc[0, ["measured", "ci_low", "ci_high", "verdict"]] = [-1.0, -4.0, 2.0, "undecided"]
    claims.to_csv(r / "claims.csv", index=False)
    stamp = record.Stamp(
        **{
            **asdict(_stamp()),
            "commit": "def5678",
            "seeds": (0, 1, 2),
            "instances": {"sparse": [0, 1, 2]},
        }
    )
    _record(r, out, tables=sorted((r / "tables").glob("*.csv")), figures=[], stamp=stamp,
            roles={"sparse": {}})  # fmt: skip
    text = (out / "rerun.md").read_text()
    head, body = _parse_md_table(text.split("keep their verdict")[1].split("\n\n")[1])
    assert head[-1] == "first seed alone"
    assert body[0][-1].strip() == "same side, +1.5"  # the record's tree still above static
    assert "for 1 it lies on the record's side of the threshold" in text
    assert "for 0 it crossed too" in text
    claims.loc[0, ["measured", "ci_low", "ci_high", "verdict"]] = [1.99, 1.2, 2.77, "holds"]
    claims.to_csv(r / "claims.csv", index=False)
    one = record.Stamp(**{**asdict(stamp), "instances": {"sparse": [0]}, "commit": "0a1b2c3"})
    _record(r, out, tables=sorted((r / "tables").glob("*.csv")), figures=[], stamp=one)
    text = (out / "rerun.md").read_text()
    assert "1 changed" in text and "first seed alone" not in text  # one instance: not asked
    # two runs over instances: the first seed is no longer the record's own tree, so not asked
    claims.loc[0, ["measured", "ci_low", "ci_high", "verdict"]] = [-1.0, -4.0, 2.0, "undecided"]
    claims.to_csv(r / "claims.csv", index=False)
    _record(r, out, tables=sorted((r / "tables").glob("*.csv")), figures=[], stamp=stamp,
            roles={"sparse": {}})  # fmt: skip
    claims.loc[0, ["measured", "ci_low", "ci_high", "verdict"]] = [1.99, 1.2, 2.77, "holds"]
    claims.to_csv(r / "claims.csv", index=False)
    _record(r, out, tables=sorted((r / "tables").glob("*.csv")), figures=[],
            stamp=record.Stamp(**{**asdict(stamp), "commit": "1b2c3d4"}), roles={"sparse": {}})  # fmt: skip
    text = (out / "rerun.md").read_text()
    assert "1 changed" in text and "first seed alone" not in text
    assert "several instances of a tree (the stamp's), the record one" not in text


def test_a_sentence_of_the_prose_takes_its_clause_only_where_the_field_is_set():
    """``prose.say``: a field with a clause of its own (``<name>_<field>``) becomes the clause,
    filled in, where it is set, else "" (or a pair's second); every sentence is a template."""
    from physgs.report.prose import PROSE, say

    assert say("rerun_overlap", n=3, yes=1, no=2, none=0).endswith("beyond that noise).")
    assert say("rerun_overlap", n=3, yes=1, no=1, none=1).endswith("in one of the runs.")
    ledger = dict(same=1, both=2, changed=1, new=0, old=0, apart=0)
    assert say("rerun_ledger", **ledger).endswith("keep their verdict, 1 changed:")
    assert say("rerun_ledger", **{**ledger, "changed": 0}).endswith("keep their verdict.")
    # claims in one run only: said before the colon that opens the table of moved verdicts
    apart = say("rerun_ledger", **{**ledger, "apart": 3, "new": 2, "old": 1})
    assert apart.endswith(
        "keep their verdict (2 claims new in this run, 1 no longer asked), 1 changed:"
    )
    assert all(isinstance(v, (str, list, dict)) for v in PROSE.values())


def test_a_folder_without_a_run_says_how_to_make_one_and_a_record_without_its_stamp_is_refused(
    tmp_path,
):
    """An empty folder gets the unrecorded index; a record's files without stamp.json are an
    error, never silently laid out as "no run yet"."""
    import shutil

    (written,) = record.render_pages(tmp_path / "empty")
    assert written.read_text() == record.PROSE["unrecorded"]
    copy = tmp_path / "record"
    shutil.copytree(RECORD, copy)
    (copy / "stamp.json").unlink()
    with pytest.raises(FileNotFoundError, match="stamp.json"):
        record.render_pages(copy)


def test_the_ledger_page_prints_the_digits_the_csv_stores(tmp_path, monkeypatch):
    """A value at a rounding edge (1.2149999 in memory, 1.215 in the CSV's 6 digits) prints on
    the page make_claims writes as on a page rendered again from the CSV (derive_claims)."""
    from physgs.provenance import Stamp
    from physgs.report import build

    df = pd.read_csv(RECORD / "claims.csv", dtype={"config_hash": str})
    df = df.drop(columns=list(record.STAMP_COLUMNS)).head(3)
    df.loc[0, ["measured", "ci_low", "ci_high"]] = [2.0, 1.2149999999999999, 3.0]
    df.loc[0, ["unit", "scale"]] = ["fraction", "linear"]
    monkeypatch.setattr(build, "claims_frame", lambda *a: df.copy())
    out = tmp_path / "record"
    out.mkdir()
    stamp = Stamp("default", "f9b6aa0f2d2f", "0.1.0")
    build.make_claims({}, ["sparse"], out / "claims.md", out / "claims.csv", stamp=stamp)
    assert "1.215" in (out / "claims.csv").read_text()
    assert "[+1.22, +3]" in (out / "claims.md").read_text()  # as re-rendered from the CSV


def test_recording_a_run_without_its_tables_says_to_finish_it(tmp_path):
    (tmp_path / "results").mkdir()
    cmd = [sys.executable, str(ROOT / "tools" / "record.py")]
    unfinished = subprocess.run(
        [*cmd, str(tmp_path / "results"), "--out", str(tmp_path / "rec")],
        cwd=ROOT, capture_output=True, text=True,
    )  # fmt: skip
    assert unfinished.returncode == 1 and "Traceback" not in unfinished.stderr
    assert "no tables/tab_fit.csv" in unfinished.stderr
    assert "finish it: snakemake --cores 2 all" in unfinished.stderr
    elsewhere = subprocess.run(
        [*cmd, str(tmp_path), "--out", str(tmp_path / "rec")],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert elsewhere.returncode == 1 and "not a run's folder" in elsewhere.stderr
    assert not (tmp_path / "rec").exists()
