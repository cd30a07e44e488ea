"""The recipe search (physgs.experiments.search) and a tree's recipe (``recipes``) in its jobs."""

import copy
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import optuna
import pandas as pd
import pytest
import yaml

from physgs.config_checks import recipes_are_known, search_is_runnable, warmup_below_iterations
from physgs.experiments.recipe import fit, job_spec, tree_recipe
from physgs.experiments import search
from physgs.experiments.search import (
    SearchSettings,
    recipe_yaml,
    run_search,
    recipes_block,
    space_of,
    summary,
    trade,
    trial_job,
    window_scorer,
)
from oracles import quick_config, quick_train_cfg
from workflow_helpers import workflow_copy


def test_a_trees_recipe_reaches_its_jobs_and_its_damping_variant_only():
    cfg = quick_config()
    cfg["recipes"] = {
        "medium": {
            "d3dgs_wind": {"train": {"iterations": 60}, "settings": {"d3dgs": {"width": 32}}}
        }
    }
    shared = job_spec(cfg, "d3dgs_wind", "single")
    for tree in ("medium", "medium_damping"):
        j = job_spec(cfg, "d3dgs_wind", "single", tree=tree)
        assert j["train"]["iterations"] == 60 and j["settings"]["d3dgs"]["width"] == 32
        # everything the recipe does not set is the shared job's
        assert j["settings"]["d3dgs"]["depth"] == shared["settings"]["d3dgs"]["depth"]
        assert j["train"]["lr"] == shared["train"]["lr"]
    assert job_spec(cfg, "d3dgs_wind", "single", tree="dense") == shared
    assert job_spec(cfg, "d3dgs", "single", tree="medium") == job_spec(cfg, "d3dgs", "single")
    assert tree_recipe(cfg, None, "d3dgs_wind") == {}
    # a forcing-free variant trains as long as its prior (the claims compare the two)
    cfg["recipes"] = {"medium": {"ours": {"train": {"iterations": 60}}}}
    assert job_spec(cfg, "ours_blind", "single", tree="medium")["train"]["iterations"] == 60
    assert job_spec(cfg, "ours_chain_blind", "single", tree="medium") == job_spec(
        cfg, "ours_chain_blind", "single"
    )


def test_a_misspelt_or_misplaced_recipe_is_refused_naming_its_key():
    cfg = quick_config()
    cfg["recipes"] = {
        "medium": {
            "d3dgs_wind": {"settings": {"d3dgs": {"widht": 32}}, "train": {"lr": {"deformm": 1}}},
            "tree_of_life": {},
        },
        "oak": {"mlp": {}},
    }
    paths = {p for p, _ in recipes_are_known(cfg)}
    assert paths == {
        ("recipes", "medium", "d3dgs_wind", "settings", "d3dgs", "widht"),
        ("recipes", "medium", "d3dgs_wind", "train", "lr", "deformm"),
        ("recipes", "medium", "tree_of_life"),
        ("recipes", "oak"),
    }
    cfg["recipes"] = {"medium": {"mlp": {"train": {"iterations": 20, "warmup": 25}}}}
    assert [p for p, _ in warmup_below_iterations(cfg)] == [
        ("recipes", "medium", "mlp", "train", "warmup")
    ]


def test_a_search_scored_never_is_refused():
    cfg = quick_config()
    cfg["search"]["every"] = cfg["train"]["iterations"]
    cfg["search"]["trees"] = ["oak"]
    assert {p for p, _ in search_is_runnable(cfg)} == {("search", "every"), ("search", "trees")}


@pytest.mark.parametrize("model", ["mlp_wind", "d3dgs", "ours_chain"])
def test_the_first_trial_is_the_configs_own_recipe(model):
    """The space's parameters of a job, suggested back, rebuild that job exactly."""
    base = job_spec(quick_config(), model, "single", tree="sparse")
    space = space_of(model)
    trial = optuna.trial.FixedTrial(space.params(trial_job(base, {})))
    assert trial_job(base, space.suggest(trial, model)).to_dict() == base


def test_a_model_without_a_recipe_to_search_is_refused():
    with pytest.raises(ValueError, match="static"):
        space_of("static")


def test_search_scores_every_trial_on_its_held_out_window_frames_and_keeps_the_best(swaying):
    cfg = quick_train_cfg(18, 4)
    base = job_spec(cfg, "mlp_wind", "single", tree="sparse")
    # no trial pruned before half its budget (9 of 18 iterations): a pruned trial's last score
    # is at 12
    settings = SearchSettings(trials=3, every=6, startup=1, seed=3, prune_after=0.5)
    lines = []
    trials, steps, best = run_search(swaying, base, settings, tree="sparse", log=lines.append)
    # a line per trial and the closing line, and one per held-out score a trial reported
    scored = [line for line in lines if ", iteration " in line]
    assert len(trials) == 3 and len(lines) - len(scored) == 4
    # each trial's line says what is left; after the last trial, nothing
    ends = [line for line in lines if "/3 " in line]
    assert len(ends) == 3 and all(re.search(r"\(about \d+ min left\)$", e) for e in ends)
    assert ends[-1].endswith("(about 0 min left)")
    assert list(trials["number"]) == [0, 1, 2]
    # trial 0 is the config's recipe: its objective is that job's held-out window loss (an
    # independent training and scoring of the job)
    own = fit(swaying, trial_job(base, {}), progress=False)
    loss0, psnr0 = window_scorer(swaying, trial_job(base, {})).evaluate(own.model)
    row0 = trials.iloc[0]
    assert row0["state"] == "COMPLETE"
    assert row0["holdout_loss"] == pytest.approx(loss0, rel=1e-6)
    assert row0["holdout_psnr"] == pytest.approx(psnr0, rel=1e-6)
    # the best recipe is the recipe of the complete trial of the lowest held-out loss
    done = trials[trials["state"] == "COMPLETE"]
    row = done.loc[done["holdout_loss"].idxmin()]
    params = {k[len("params_") :]: row[k] for k in trials if k.startswith("params_")}
    params = {k: (int(v) if k in ("width", "depth") else v) for k, v in params.items()}
    fixed = optuna.trial.FixedTrial(params)
    assert best == space_of("mlp_wind").suggest(fixed, "mlp_wind")
    # every score a trial reported is in the steps, after the warm-up, every `every` iterations
    # and at the end of a complete trial
    assert set(steps["trial"]) == set(trials["number"])
    ends = steps.groupby("trial")["iteration"].max()
    assert (ends[done["number"]] == 18).all()
    assert set(steps["iteration"]) <= {6, 12, 18}
    pruned = trials[trials["state"] == "PRUNED"]
    assert (ends[pruned["number"]] == 12).all()
    # the progress lines are the scores the pruner read: each is a step, a pruned trial's all
    logged = {tuple(map(int, re.search(r"trial (\d+), iteration (\d+):", line).groups()))
              for line in scored}  # fmt: skip
    assert logged and logged <= set(zip(steps["trial"], steps["iteration"]))
    assert set(zip(pruned["number"], ends[pruned["number"]])) <= logged
    text = recipe_yaml("sparse", "mlp_wind", trials, best)
    assert text.startswith("# sparse mlp_wind: trial ") and "mlp_wind:" in text


@pytest.mark.parametrize("cut", [KeyboardInterrupt, SystemExit], ids=["ctrl-c", "killed"])
def test_a_search_cut_short_resumes_from_its_journal(swaying, tmp_path, monkeypatch, cut):
    """A search stopped in its third training keeps its two finished trials (not trained again,
    their values those of a search run in one go) and trains the third's recipe again. Ctrl-C
    leaves that trial FAIL in the journal; a kill (SystemExit passes through Optuna's handler, as
    a kill does) leaves it RUNNING: both resume the same way."""
    cfg = quick_train_cfg(12, 2)
    base = job_spec(cfg, "ours", "single", tree="sparse")
    settings = SearchSettings(trials=3, every=6, startup=3, seed=5)
    whole, whole_steps, _ = run_search(swaying, base, settings, log=lambda _: None)
    journal = tmp_path / "ours.journal"
    calls = []

    def fit_cut_at_third(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise cut()
        return fit(*args, **kwargs)

    monkeypatch.setattr(search, "fit", fit_cut_at_third)
    with pytest.raises(cut):
        run_search(swaying, base, settings, log=lambda _: None, journal=journal)
    assert journal.exists()
    monkeypatch.setattr(search, "fit", lambda *a, **k: (calls.append(1), fit(*a, **k))[1])
    lines = []
    trials, steps, _ = run_search(swaying, base, settings, log=lines.append, journal=journal)
    assert len(calls) == 4  # the resumed search trained one recipe: the cut one's
    assert list(trials["state"]) == ["COMPLETE", "COMPLETE", "FAIL", "COMPLETE"]
    params = [c for c in trials if c.startswith("params_")]
    assert trials.loc[3, params].tolist() == trials.loc[2, params].tolist()
    assert trials.loc[:1, "holdout_loss"].tolist() == pytest.approx(
        whole.loc[:1, "holdout_loss"].tolist(), rel=1e-6
    )
    assert trials.loc[:1, params].equals(whole.loc[:1, params])
    assert np.isnan(trials.loc[2, "seconds"]) and not trials["seconds"].drop(2).isna().any()
    assert np.isnan(trials.loc[2, "cpu_seconds"]) and (trials["cpu_seconds"].drop(2) > 0).all()
    assert set(steps["trial"]) == {0, 1, 3}
    assert (
        steps[steps["trial"] < 2]
        .reset_index(drop=True)
        .equals(whole_steps[whole_steps["trial"] < 2].reset_index(drop=True))
    )
    assert any("trial 2 was cut short" in line for line in lines)
    assert any("2 of 3 trials finished" in line for line in lines)
    assert not journal.exists()  # a finished search leaves no journal to resume


def test_a_search_cut_short_in_its_first_trial_starts_afresh(swaying, tmp_path, monkeypatch):
    """The first trial is the config's own recipe: a search cut in it keeps nothing, so trial 0
    of the resumed search is still the config's own."""
    cfg = quick_train_cfg(12, 2)
    base = job_spec(cfg, "ours", "single", tree="sparse")
    settings = SearchSettings(trials=2, every=6, startup=2, seed=5)
    journal = tmp_path / "ours.journal"

    def killed(*args, **kwargs):
        raise SystemExit()

    monkeypatch.setattr(search, "fit", killed)
    with pytest.raises(SystemExit):
        run_search(swaying, base, settings, log=lambda _: None, journal=journal)
    monkeypatch.setattr(search, "fit", fit)
    trials, _, _ = run_search(swaying, base, settings, log=lambda _: None, journal=journal)
    assert list(trials["number"]) == [0, 1] and (trials["state"] == "COMPLETE").all()
    own = space_of("ours").params(trial_job(base, {}))
    assert {k: trials.loc[0, f"params_{k}"] for k in own} == pytest.approx(own)


def test_a_trial_that_fails_stops_the_search_naming_it(swaying):
    cfg = quick_train_cfg(24, 4)
    base = copy.deepcopy(job_spec(cfg, "mlp", "single", tree="sparse"))
    base["train"]["holdout_every"] = 0
    with pytest.raises(ValueError, match="holdout_every"):
        run_search(swaying, base, SearchSettings(2, 6, 1, 0), log=lambda _: None)


def test_the_search_is_a_target_of_its_own_over_every_tree(tmp_path):
    """``search`` plans one search per tree of the run and model of the config."""
    wd = workflow_copy(tmp_path)
    r = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "--cores", "1", "search"]
        + ["--config", "profile=quick", "trees=[sparse,dense]"],
        cwd=wd,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr[-3000:] + r.stdout[-3000:]
    planned = set(re.findall(r"output: results/search/(\w+)/(\w+)\.trials\.csv", r.stdout))
    models = quick_config()["search"]["models"]
    assert planned == {(t, m) for t in ("sparse", "dense") for m in models}


def test_the_summary_keeps_a_searched_recipe_only_above_the_adoption_gain():
    """Per search: the own recipe is trial 0, the best the complete trial of the lowest loss
    (a pruned trial never, however low its last score), the gain their PSNR difference."""
    rows = [  # tree, model, number, state, loss, psnr
        ("sparse", "mlp", 0, "COMPLETE", 0.030, 24.00),
        ("sparse", "mlp", 1, "COMPLETE", 0.020, 24.30),
        ("sparse", "mlp", 2, "PRUNED", 0.010, None),
        ("dense", "ours", 0, "COMPLETE", 0.010, 30.00),
        ("dense", "ours", 1, "COMPLETE", 0.009, 30.05),
        ("dense", "ours", 2, "FAIL", None, None),
    ]
    trials = pd.DataFrame(
        rows, columns=["tree", "model", "number", "state", "holdout_loss", "holdout_psnr"]
    )
    found = summary(trials, adopt_above_db=0.1).set_index(["tree", "model"])
    assert list(found.index) == [("sparse", "mlp"), ("dense", "ours")]
    mlp, ours = found.loc[("sparse", "mlp")], found.loc[("dense", "ours")]
    assert (mlp["trials"], mlp["complete"], mlp["best_trial"]) == (3, 2, 1)
    assert mlp["gain_db"] == pytest.approx(0.30) and mlp["recipe"] == "searched"
    assert (ours["trials"], ours["complete"], ours["cut"], ours["best_trial"]) == (2, 2, 1, 1)
    assert mlp["cut"] == 0
    cut = trials[trials["model"] == "ours"]  # the recipe's comment counts the budget's trials too
    assert recipe_yaml("dense", "ours", cut, {}).startswith(
        "# dense ours: trial 1 of 2 (2 complete)"
    )
    assert ours["gain_db"] == pytest.approx(0.05) and ours["recipe"] == "config's"
    assert summary(trials, adopt_above_db=0.5).set_index("model").loc["mlp", "recipe"] == "config's"


def test_the_docs_search_summary_is_the_committed_searches():
    """docs/studies/search_summary.md and search_trade.md are what tools/search_summary.py
    makes of the committed trials files."""
    files = sorted(str(p) for p in Path("docs/studies/search").glob("*.trials.csv"))
    r = subprocess.run(
        [sys.executable, "tools/search_summary.py", *files, "--check"]
        + ["--markdown", "docs/studies/search_summary.md"]
        + ["--trade", "docs/studies/search_trade.md"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr


def test_the_search_figure_draws_the_committed_searches_at_the_page_width(tmp_path):
    """tools/search_summary.py --figure writes a PNG as wide as the docs' page at its dpi."""
    from PIL import Image

    from physgs.report.figures import PAGE_WIDTH_IN

    files = sorted(str(p) for p in Path("docs/studies/search").glob("*.trials.csv"))
    png = tmp_path / "trade.png"
    r = subprocess.run(
        [sys.executable, "tools/search_summary.py", *files, "--figure", str(png)]
        + ["--markdown", str(tmp_path / "summary.md"), "--trade", str(tmp_path / "trade.md")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    width, _ = Image.open(png).size
    assert abs(width - PAGE_WIDTH_IN * 150) < 0.1 * PAGE_WIDTH_IN * 150  # tight bbox trims a little


def test_the_recipes_block_holds_only_the_recipes_that_replace_the_configs():
    """The block pasted into config/trees.yaml is the searched recipes the summary keeps,
    under ``recipes:``, with their comments; a recipe within the rule is left out."""
    texts = [
        recipe_yaml(
            "sparse",
            "mlp",
            trials_of("sparse", "mlp", 24.0, 24.5),
            {"train": {"lr": {"deform": 0.002}}},
        ),
        recipe_yaml(
            "dense",
            "ours",
            trials_of("dense", "ours", 30.0, 30.05),
            {"train": {"lr": {"pivot": 0.001}}},
        ),
    ]
    trials = pd.concat(
        [trials_of("sparse", "mlp", 24.0, 24.5), trials_of("dense", "ours", 30.0, 30.05)]
    )
    block = recipes_block(texts, summary(trials, adopt_above_db=0.1))
    assert yaml.safe_load(block) == {
        "recipes": {"sparse": {"mlp": {"train": {"lr": {"deform": 0.002}}}}}
    }
    assert "  # sparse mlp: trial 1 of 2" in block
    assert yaml.safe_load(recipes_block(texts, summary(trials, adopt_above_db=1.0))) == {
        "recipes": None
    }


def test_the_trade_keeps_the_trials_no_cheaper_one_scores_above():
    """Each search's front, against a brute force over its complete trials: a trial is on it
    when every trial cheaper (or as cheap and no better) scores below it; CPU seconds where the
    search has them for every trial, wall seconds otherwise."""
    rng = np.random.default_rng(7)
    rows = []
    for model, n in (("mlp", 9), ("ours", 7)):
        for i in range(n):
            state = "PRUNED" if i % 4 == 3 else "COMPLETE"
            rows.append(("dense", model, i, state, rng.uniform(20, 30), rng.uniform(50, 500)))
    trials = pd.DataFrame(
        rows, columns=["tree", "model", "number", "state", "holdout_psnr", "seconds"]
    )
    trials["holdout_loss"] = -trials["holdout_psnr"]
    cpu = trials["seconds"] * rng.uniform(0.5, 1.0, len(trials))
    trials["cpu_seconds"] = cpu.where(trials["model"] == "mlp")  # ours: wall time only
    found = trade(trials)
    for model, clock, name in (("mlp", "cpu_seconds", "cpu"), ("ours", "seconds", "wall")):
        t = trials[(trials["model"] == model) & (trials["state"] == "COMPLETE")]
        front = [
            r.number
            for r in t.itertuples()
            if not any(
                (getattr(o, clock) < getattr(r, clock) and o.holdout_psnr >= r.holdout_psnr)
                or (getattr(o, clock) == getattr(r, clock) and o.holdout_psnr > r.holdout_psnr)
                for o in t.itertuples()
                if o.number != r.number
            )
        ]
        mine = found[found["model"] == model]
        assert sorted(mine["number"]) == sorted(front)
        assert (mine["clock"] == name).all()
        own = t[t["number"] == 0].iloc[0]
        for r in mine.itertuples():
            row = t[t["number"] == r.number].iloc[0]
            assert r.seconds == row[clock] and r.cost_x == pytest.approx(row[clock] / own[clock])
            assert r.delta_db == pytest.approx(row["holdout_psnr"] - own["holdout_psnr"])
        assert list(mine["seconds"]) == sorted(mine["seconds"])


def trials_of(tree, model, own, best):
    """Two complete trials of a search: the config's own recipe and a better one (PSNR, dB)."""
    return pd.DataFrame(
        [(tree, model, 0, "COMPLETE", 0.02, own), (tree, model, 1, "COMPLETE", 0.01, best)],
        columns=["tree", "model", "number", "state", "holdout_loss", "holdout_psnr"],
    )
