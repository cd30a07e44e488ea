"""The whole DAG end to end on the quick profile, and the plans of single targets.

The quick DAG runs once (module fixture) in a scratch copy of the workflow, every rule of it but
on the sparse tree alone so the suite stays within its time budget; the tests then read what it
produced as a reviewer would: every table's rows and columns, finite numbers, .tex agreeing with
.csv, and every figure present.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
import yaml

from physgs import config as pconfig
from physgs.report.build import FIGURES, TABLES
from workflow_helpers import ROOT, snakemake, workflow_copy

pytestmark = pytest.mark.slow
QUICK = pconfig.resolve(yaml.safe_load((ROOT / "config" / "trees.yaml").read_text()), "quick")
TREES = ["sparse"]
# the quick profile builds no damping testbed (its 2.5 s window cannot hold a calm): no tab_damping
BUILT = [n for n in TABLES if n != "tab_damping" or QUICK["damping_benchmark"]["trees"]]
MODELS = ["static", "mlp", "mlp_wind", "d3dgs", "d3dgs_wind", "ours", "ours_chain"]


@pytest.fixture
def run(quick_dag):  # function scope: the suite's workers share these tests one by one
    return quick_dag


def _csv(run, name) -> pd.DataFrame:
    return pd.read_csv(run / "results" / "tables" / f"{name}.csv")


def _tex_numbers(run, name) -> list[tuple[float, int]]:
    """Each decimal number in the table's rows (not its caption): (value, decimals printed)."""
    tex = (run / "results" / "tables" / f"{name}.tex").read_text()
    body = tex.split(r"\midrule", 1)[1].split(r"\bottomrule", 1)[0]
    decimals = re.finditer(r"(?<![\w{])[-+]?\d+\.(\d+)", body)
    return [(float(m.group(0)), len(m.group(1))) for m in decimals]


def test_every_output_exists(run):
    assert "tab_damping" not in BUILT  # see BUILT; tests/test_train_workflow.py plans it
    for name in BUILT:
        for ext in ("tex", "csv"):
            assert (run / "results" / "tables" / f"{name}.{ext}").stat().st_size > 0
    for name in (*FIGURES, "fig_speed_accuracy"):
        for ext in ("pdf", "png"):
            assert (run / "results" / "figures" / f"{name}.{ext}").stat().st_size > 1000
    for tree in TREES:
        assert (run / "results" / "figures" / f"testbed_{tree}.png").is_file()


def test_tab_psnr_rows_columns_and_finite(run):
    df = _csv(run, "tab_psnr")
    # the models, the reference, then each prior's two paired differences; one seed; ids (the
    # labels are the .tex's)
    assert list(df["model"]) == [
        *MODELS,
        "truth_motion",
        "ours-static",
        "ours-best_field",
        "ours_chain-static",
        "ours_chain-best_field",
    ]
    assert list(df["reference"]) == [False] * len(MODELS) + [True] + [False] * 4
    assert list(df["difference"]) == [False] * (len(MODELS) + 1) + [True] * 4
    assert set(df["seed"]) == set(QUICK["seeds"])
    cols = [f"{t}_{s}" for t in TREES for s in ("view", "time")]
    assert list(df.columns[2 : 2 + len(cols)]) == cols
    vals = df.loc[~df["difference"], cols].to_numpy(float)
    assert np.isfinite(vals).all() and (vals > 5).all() and (vals < 60).all()
    diff = df.loc[df["difference"], cols].to_numpy(float)
    ours, static = (df.loc[df["model"] == m, cols].to_numpy(float) for m in ("ours", "static"))
    np.testing.assert_allclose(diff[0], (ours - static)[0], atol=1e-4)
    tex = (run / "results" / "tables" / "tab_psnr.tex").read_text()
    assert "Chained prior (this project) $-$ best learned field" in tex
    # one seed: no interval, so no best is decided and nothing is bold
    assert r"\toprule" in tex and r"\bottomrule" in tex and r"\textbf{" not in tex


def test_tab_transfer_rows_columns_and_finite(run):
    df = _csv(run, "tab_transfer")
    unseen = len(QUICK["testbed"]["conditions"]) - 1
    assert len(df) == 2 * len(TREES) * unseen
    assert set(df["split"]) == {"train", "beyond"}
    models = ["static", "mlp", "mlp_wind", "d3dgs", "d3dgs_wind", "ours", "ours_chain"]
    assert [c for c in df.columns if c in models] == models
    assert np.isfinite(df[models].to_numpy(float)).all()


def test_tab_margin_is_ours_minus_mlp_wind(run):
    df = _csv(run, "tab_margin")
    assert list(df["tree"]) == TREES * 2 and list(df["model"]) == ["ours"] * len(TREES) + [
        "ours_chain"
    ] * len(TREES)
    assert [c for c in df.columns if c.startswith("margin_")] == [
        "margin_v0",
        "margin_0.84v0",
        "margin_0.71v0",
    ]
    from physgs.evaluate.splits import load_eval

    for _, row in df.iterrows():
        ev = run / "results" / "eval" / row["tree"] / f"seed{row['seed']}"
        ours = load_eval(ev / f"{row['model']}_single.npz").summary()
        base = load_eval(ev / "mlp_wind_single.npz").summary()
        assert row["margin_v0"] == pytest.approx(ours["train_c0"] - base["train_c0"], abs=1e-4)


def test_tab_null_holds_the_papers_rows_alone(run):
    """tab_null: ours in every configuration beside the null of the same K (the paper's)."""
    df = _csv(run, "tab_null")
    configs = list(QUICK["models"]["configs"])
    assert list(df["method"]) == ["ours"] * len(TREES) * len(configs)
    assert sorted(df["config"]) == sorted(configs * len(TREES))
    want_k = df["config"].map(lambda c: QUICK["models"]["configs"][c]["K"])
    assert (df["K"] == want_k).all()  # each beside the null of the same K
    rec = _csv(run, "tab_recovery")
    mine = rec[rec["method"] == "ours"].reset_index(drop=True)
    pd.testing.assert_frame_equal(df, mine)  # the same rows in both tables


def test_tab_recovery_rows_columns_and_finite_where_defined(run):
    df = _csv(run, "tab_recovery")
    configs = list(QUICK["models"]["configs"])
    from physgs.models.registry import BLIND_PRIORS

    # ours' rows, the chained prior's, then the 2D-track control's (docs/tracks.md) and the
    # output-only analysis' (docs/blind.md), each at its own K beside its own null, then the
    # forcing-free priors' (single only)
    assert list(df["method"]) == ["ours"] * len(TREES) * len(configs) + ["ours_chain"] * len(
        TREES
    ) * len(configs) + ["tracks"] * len(TREES) * len(QUICK["tracks"]["configs"]) + ["oma"] * len(
        TREES
    ) * len(QUICK["oma"]["configs"]) + list(BLIND_PRIORS) * len(TREES)
    assert (df.loc[df["method"] == "tracks", "K"] == QUICK["tracks"]["K"]).all()
    assert (df.loc[df["method"] == "oma", "K"] == QUICK["oma"]["K"]).all()
    assert set(df.loc[df["method"].isin(BLIND_PRIORS), "config"]) == {"single"}
    for col in ("trained_parts_trusted", "null_parts_trusted", "nearest_bone_gap_pct"):
        assert np.isfinite(df[col].to_numpy(float)).all(), col
    # a median over no trusted part is undefined (empty cell), and only then
    for who in ("trained", "null"):
        err = df[f"{who}_median_rel_err_pct"].to_numpy(float)
        assert np.isfinite(err[df[f"{who}_parts_trusted"].to_numpy(float) >= 1]).all()
    assert (df["nearest_bone_gap_pct"] >= 0).all()


@pytest.mark.parametrize("name", BUILT)
def test_tex_braces_balance(run, name):
    """An unbalanced brace stops LaTeX (tab_parts_k's header once had one too many)."""
    tex = (run / "results" / "tables" / f"{name}.tex").read_text()
    depth = 0
    for ch in re.sub(r"\\[{}%]|(?<!\\)%.*", "", tex):
        depth += {"{": 1, "}": -1}.get(ch, 0)
        assert depth >= 0, f"{name}.tex closes a brace it never opened"
    assert depth == 0, f"{name}.tex leaves {depth} brace(s) open"


@pytest.mark.parametrize("name", BUILT)
def test_tex_agrees_with_csv(run, name):
    df = _csv(run, name)
    nums = df.select_dtypes("number").to_numpy(float).ravel()
    nums = nums[np.isfinite(nums)]
    tex = _tex_numbers(run, name)
    assert tex, f"{name}.tex has no numbers"
    # every decimal in the .tex is a rounded CSV value (percentages are written x100)
    for x, decimals in tex:
        atol = 0.6 * 10.0**-decimals  # half a unit of the last digit shown, and some slack
        ok = np.isclose(nums, x, rtol=0, atol=atol) | np.isclose(nums * 100, x, rtol=0, atol=atol)
        assert ok.any(), f"{name}.tex shows {x}, which is in no CSV cell"


def test_tab_tracks_scores_every_tracks_fit(run):
    """One row per tree and configuration of the tracks control: the tracker's numbers are the
    same on every row of a tree (one training video), the fit took seconds, and each recovery
    record lists its parts' track counts (summing to the tracks fitted) and the parts left
    without an estimate."""
    import json

    df = _csv(run, "tab_tracks")
    assert sorted(df["config"]) == sorted(QUICK["tracks"]["configs"])
    assert (df["K"] == QUICK["tracks"]["K"]).all() and (df["fit_s"] > 0).all()
    for col in ("n_tracks", "track_median_px", "track_p90_px", "tail_px", "tail_static_px"):
        assert np.isfinite(df[col].to_numpy(float)).all(), col
    for col in ("n_tracks", "track_median_px", "share_kept"):  # one video per tree
        assert df.groupby("tree")[col].nunique().max() == 1, col
    # the learned fields, trained in single only, are scored at the same points there
    per_field = [f"tail_field_{m}_px" for m in QUICK["tracks"]["fields"]]
    single = df["config"] == "single"
    assert np.isfinite(df.loc[single, per_field].to_numpy(float)).all()
    np.testing.assert_allclose(
        df.loc[single, "tail_best_field_px"], df.loc[single, per_field].min(axis=1)
    )
    assert df.loc[~single, "tail_best_field_px"].isna().all()
    for _, r in df.iterrows():
        rec = (
            run
            / "results"
            / "recovery"
            / r["tree"]
            / f"seed{r['seed']}"
            / f"tracks_{r['config']}.json"
        )
        block = json.loads(rec.read_text())["tracks"]
        assert len(block["n_tracks_per_part"]) == r["K"]
        est = [n >= block["min_tracks"] for n in block["n_tracks_per_part"]]
        assert block["no_estimate"] == [p for p, e in enumerate(est) if not e]
        assert sum(est) == r["parts_estimated"]


def test_speed_accuracy_csv(run):
    df = pd.read_csv(run / "results" / "tables" / "speed_accuracy.csv")
    assert set(df["knob"]) == {"resolution", "iterations", "substeps", "K", "vertices"}
    assert np.isfinite(df[["wall_s", "psnr_time"]].to_numpy(float)).all()
    assert (df["wall_s"] > 0).all()


def test_tab_null_plan_trains_ours_only():
    """`snakemake results/tables/tab_null.tex` trains ours alone (the paper's table) and runs no
    other recovery method (tab_recovery's)."""
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as d:
        wd = workflow_copy(Path(d))
        out = snakemake(
            wd, "-n", "--cores", "2", "results/tables/tab_null.tex", "--config", "profile=quick"
        ).stdout
    trained = re.findall(r"results/models/\w+/seed\d+/(\w+?)_(single|joint32|joint96)\.pt", out)
    assert trained, "the plan trains nothing"
    assert {m for m, _ in trained} == {"ours"}
    assert "rule evaluate:" not in out
    for rule in ("track", "fit_tracks", "tracks_evaluate", "oma_identify", "oma_recovery"):
        assert f"rule {rule}:" not in out, rule


def test_snakemake_report_collects_tables_and_figures(run, tmp_path):
    """`snakemake --report` on the finished DAG gives one HTML with every section and output."""
    html = tmp_path / "report.html"
    snakemake(
        run,
        "--report",
        str(html),
        "all",
        "studies",
        "--config",
        "profile=quick",
        'trees=["sparse"]',
    )
    text = html.read_text(errors="replace")
    for name in (
        "1. Testbed",
        "2. Results",
        "3. Tables",
        "4. Speed-accuracy trade",
        "testbed_sparse",
        *BUILT,
        *FIGURES,
    ):
        assert name in text, f"the report lacks {name}"


def test_every_table_csv_carries_the_provenance_stamp(run):
    for name in BUILT:
        df = pd.read_csv(run / "results" / "tables" / f"{name}.csv", dtype={"config_hash": str})
        assert set(df["profile"]) == {"quick"}, name
        assert df["config_hash"].str.fullmatch(r"[0-9a-f]{12}").all(), name
        assert df["physgs_version"].notna().all(), name
        assert (
            (run / "results" / "tables" / f"{name}.tex")
            .read_text()
            .startswith("% profile=quick, config_hash=")
        ), name


def test_claims_ledger_has_a_computed_verdict_per_claim(run):
    df = pd.read_csv(run / "results" / "claims.csv")
    assert len(df) >= 10 and df["id"].is_unique
    ok = ("holds", "fails", "undecided")
    assert df["verdict"].str.split(":").str[0].isin(ok).all(), df["verdict"].tolist()
    # one seed: every claim that needs variance says so (or that it was not measured: a median
    # over no trusted part) rather than guessing
    needs = df[~df["id"].str.startswith("nearest_bone_gap")]
    assert needs["verdict"].str.match(r"undecided: (one seed|not measured)").all()
    assert "| claim | origin | paper | measured |" in (run / "results" / "claims.md").read_text()


def test_fit_curve_passes_through_the_tables_numbers(run):
    """Three budgets per swept model; the profile's point is the pipeline's own job, so its fit
    is tab_fit's cell for that model, not a retrained copy."""
    df = pd.read_csv(run / "results" / "tables" / "fit_curve.csv")
    fc = QUICK["speed_accuracy"]["fit_curve"]
    own = QUICK["train"]["iterations"]
    for m in fc["models"]:
        g = df[df["model"] == m]
        assert sorted(g["iterations"]) == sorted({*fc["iterations"], own})
        assert list(g.loc[g["is_profile"], "iterations"]) == [own]
    assert np.isfinite(df[["fit", "heldout", "time", "train_s"]].to_numpy(float)).all()
    fit = _csv(run, "tab_fit")
    for _, r in df[df["is_profile"]].iterrows():
        cell = fit[(fit["tree"] == r["tree"]) & (fit["model"] == r["model"])]
        assert cell["fit_psnr_db"].item() == pytest.approx(r["fit"], abs=1e-4)
    for name in ("fig_fit_curve", "fig_fit_vs_extrapolation"):
        for ext in ("pdf", "png"):
            assert (run / "results" / "figures" / f"{name}.{ext}").stat().st_size > 1000


def test_a_second_seed_pairs_with_the_first(run, tmp_path):
    """`--config seeds=[0,1]` on the finished one-seed DAG trains seed 1 only; tab_margin then
    holds both seeds, seed 0's row is the one-seed table's (same command, same numbers) and the
    .tex gives the paired mean with its 95% interval."""
    import shutil

    from scipy import stats

    wd = workflow_copy(tmp_path / "wf")
    shutil.copytree(run / "results", wd / "results")
    # a user's results folder keeps Snakemake's records (without them a present target counts
    # as done and nothing is planned)
    shutil.copytree(run / ".snakemake" / "metadata", wd / ".snakemake" / "metadata")
    one = _csv(run, "tab_margin")
    out = snakemake(
        wd,
        "--cores",
        "2",
        "results/tables/tab_margin.tex",
        "--config",
        "profile=quick",
        'trees=["sparse"]',
        "seeds=[0,1]",
    )
    out = out.stdout + out.stderr
    trained = set(re.findall(r"results/models/\w+/(seed\d+)/\w+\.pt", out))
    assert trained == {"seed1"}, trained
    two = pd.read_csv(wd / "results" / "tables" / "tab_margin.csv")
    assert list(two["seed"]) == [0, 0, 1, 1]  # ours', then the chained prior's, per seed
    cols = ["margin_v0", "margin_0.84v0", "margin_0.71v0"]
    np.testing.assert_allclose(two.loc[0, cols].to_numpy(float), one.loc[0, cols].to_numpy(float))
    d = two.loc[two["model"] == "ours", "margin_v0"].to_numpy(float)
    lo, hi = stats.t.interval(0.95, 1, loc=d.mean(), scale=stats.sem(d))
    tex = (wd / "results" / "tables" / "tab_margin.tex").read_text()
    assert f"${d.mean():+.2f}$ [{lo:.2f}, {hi:.2f}]" in tex


def test_summary_is_printed_from_the_run(run):
    """results/summary.md (part of `all`): the run's stamp, the ledger's counts, tab_fit's trees
    and the benchmarked stages, read back from the run's own files."""
    text = (run / "results" / "summary.md").read_text()
    ledger = pd.read_csv(run / "results" / "claims.csv", dtype={"config_hash": str})
    stamp = ledger[["profile", "config_hash", "physgs_version"]].iloc[0]
    assert f"profile=quick, config_hash={stamp.config_hash}," in text
    kinds = ledger["verdict"].str.split(":").str[0]
    # the paper's claims counted apart from this project's, the paper's first
    paper = kinds[ledger["origin"] == "paper"]
    own = kinds[ledger["origin"] == "project"]
    assert len(paper) + len(own) == len(ledger)
    words = {"holds": "hold", "fails": "fail", "undecided": "undecided"}

    def counts(k, who):  # findings, then premises, each by verdict (a verdict none has left out)
        parts = []
        for kind in ("finding", "premise"):
            mine = k[ledger.loc[k.index, "kind"] == kind]
            by = ", ".join(
                f"{(mine == v).sum()} {w}" for v, w in words.items() if (mine == v).any()
            )
            parts += (
                [f"{len(mine)} {kind}{'s' if len(mine) != 1 else ''} ({by})"] if len(mine) else []
            )
        return f"{len(k)} claim{'s' if len(k) != 1 else ''}: " + (", ".join(parts) or "none")

    assert f"The paper's {counts(paper, 'paper')}." in text
    assert f"This project's own {counts(own, 'project')}." in text
    assert text.index("The paper's") < text.index("This project's own")
    assert "| model | sparse |" in text and "Warning" not in text
    for stage in ("testbed", "train", "evaluate"):
        assert f"| {stage} | " in text


def test_fit_recipe_capacity_scores_the_parts_at_the_true_motion(
    run, monkeypatch, capsys, tmp_path
):
    """`benchmarks/fit_recipe.py --capacity` on the quick DAG's tree: both motions of both priors'
    parts are trained and scored, and the free angles leave no more image error than one
    oscillator each (the oscillator's angles are among the free ones)."""
    import sys

    monkeypatch.chdir(ROOT)
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    sys.modules.pop("fit_recipe", None)
    import fit_recipe

    md = tmp_path / "capacity.md"
    fit_recipe.main(
        [
            str(run / "results/testbed/sparse"),
            "--capacity",
            "--profile",
            "quick",
            "--markdown",
            str(md),
        ]
    )
    out = capsys.readouterr().out
    err = {
        k: float(v) for k, v in re.findall(r"# (\w+_(?:free|osc)): image error ([\d.]+) px", out)
    }
    names = [f"{p}_{how}" for p in ("ours", "ours_chain") for how in ("free", "osc")]
    assert sorted(err) == sorted(names), out
    for p in ("ours", "ours_chain"):
        assert err[f"{p}_free"] <= err[f"{p}_osc"] + 0.01, out
    rows = re.findall(r"^(\w+_(?:free|osc))\s+([\d.]+)\s+([\d.]+)", out, flags=re.M)
    assert [r[0] for r in rows] == names, out
    assert all(np.isfinite(float(v)) for r in rows for v in r[1:]), out
    table = md.read_text()
    for name in ["static", "truth_motion", "ours", "ours_chain", *names]:
        assert re.search(rf"^\| {name} +\|", table, flags=re.M), table
