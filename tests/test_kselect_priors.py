"""K from the data for the priors besides ours (``models.kselect.priors``: the chained prior):
its own settings over the shared ones, a refusal at load where its search over omega cannot run,
its selection by the one criterion, its jobs in the default plan and its rows in tab_kselect."""

from __future__ import annotations

import copy
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
import yaml

import physgs.experiments.kselect as ksel
from physgs import config as pconfig
from physgs.experiments import job_spec
from physgs.experiments.kselect import (
    auto_job,
    choose_heldout,
    select_k,
    selected_models,
    settings_for,
)
from physgs.report.build import Plan, needs
from physgs.report.kselect import tab_kselect
from oracles import quick_config
from workflow_helpers import ROOT, workflow_copy

RAW = yaml.safe_load((ROOT / "config" / "trees.yaml").read_text())
OURS_KEYS = ("candidates", "method", "every", "iterations", "warmup", "tie_db", "conditions")


# --- settings -----------------------------------------------------------------------------------
def test_ours_settings_are_the_sections_own_keys_whatever_the_chain_sets():
    cfg = pconfig.resolve(copy.deepcopy(RAW), "default")
    ks = cfg["models"]["kselect"]
    assert selected_models(ks) == ("ours", "ours_chain")
    ours = settings_for(ks, "ours")
    assert ours == {k: ks[k] for k in OURS_KEYS}  # what ours' rule read before priors had entries
    chain = settings_for(ks, "ours_chain")
    assert chain["candidates"] == [4, 8, 16, 32] and chain["iterations"] == 400
    assert {k: chain[k] for k in ("method", "every", "tie_db", "conditions")} == {
        k: ks[k] for k in ("method", "every", "tie_db", "conditions")
    }
    edited = copy.deepcopy(ks)
    edited["priors"]["ours_chain"]["iterations"] = 800
    assert settings_for(edited, "ours") == ours  # the chain's edit leaves ours' selection alone
    with pytest.raises(ValueError, match="'ours_topo' has no K selection"):
        settings_for(ks, "ours_topo")


# --- refused at load, naming the key ------------------------------------------------------------
def test_a_schedule_the_search_cannot_run_in_stops_at_load_naming_the_key():
    raw = copy.deepcopy(RAW)
    raw["models"]["kselect"]["priors"]["ours_chain"] = {"candidates": [4, 8]}  # ours' 160 / 40
    with pytest.raises(pconfig.ConfigError) as e:
        pconfig.load_workflow_config(raw, "default")
    msg = str(e.value)
    assert "config key 'models/kselect/priors/ours_chain/iterations'" in msg
    assert "iterations and warmup from models/kselect" in msg
    assert "bank phase at iteration 24 of 160, outside (40, 80)" in msg
    # the shipped schedule leaves room: bank phase ends at round(0.15 x 400) = 60 in (40, 200)
    pconfig.load_workflow_config(copy.deepcopy(RAW), "default")


def test_the_quick_profiles_chain_schedule_is_refused_when_its_warmup_passes_the_search():
    raw = copy.deepcopy(RAW)
    raw["profiles"]["quick"]["models"]["kselect"]["priors"]["ours_chain"]["warmup"] = 12
    with pytest.raises(pconfig.ConfigError, match="models/kselect/priors/ours_chain/iterations"):
        pconfig.load_workflow_config(raw, "quick")


# --- the selection: the chain's short runs carry its search, one criterion picks K ---------------
def test_the_chains_selection_runs_its_search_and_picks_the_smallest_k_within_tie(
    swaying, monkeypatch
):
    cfg = quick_config()
    cfg["train"].update(iterations=24, warmup=4, backend="fast")
    cfg["models"]["omega_search"]["until"] = 0.5
    ks = {
        "candidates": [3, 2],
        "method": "heldout",
        "every": 5,
        "iterations": 24,
        "warmup": 4,
        "tie_db": 1e3,  # every candidate ties: the smallest wins
        "conditions": "train",
    }
    runs = []
    real_fit = ksel.fit

    def spy(observed, job, **kw):  # the real fit, its statistics kept
        res = real_fit(observed, job, **kw)
        runs.append((job.model, job.K, res.stats.get("omega_search_at")))
        return res

    monkeypatch.setattr(ksel, "fit", spy)
    job = job_spec(cfg, "ours_chain", "single", 0)
    sel = select_k(swaying, job, ks)
    # round(0.5 x 24) = 12: the bank phase ended after the warm-up in every candidate's run
    assert runs == [("ours_chain", 2, 12), ("ours_chain", 3, 12)]
    assert sel.candidates == [2, 3] and np.all(np.isfinite(sel.heldout_psnr))
    assert sel.chosen_k == sel.k_heldout == 2
    best = sel.candidates[int(np.argmax(sel.heldout_psnr))]
    assert choose_heldout(sel.candidates, sel.heldout_psnr, 0.0) == best
    spec = auto_job(job, sel, "train")
    assert (spec["model"], spec["config"], spec["K"]) == ("ours_chain", "auto", 2)


# --- the default plan -------------------------------------------------------------------------
@pytest.fixture(scope="module")
def default_plan() -> str:
    """The dry-run plan of tab_kselect from an empty results folder at the default profile."""
    with tempfile.TemporaryDirectory() as d:
        wd = workflow_copy(Path(d))
        r = subprocess.run(
            [sys.executable, "-m", "snakemake", "-n", "--cores", "2"]
            + ["results/tables/tab_kselect.tex"],
            cwd=wd,
            capture_output=True,
            text=True,
            timeout=300,
        )
    assert r.returncode == 0, r.stderr[-3000:] + r.stdout[-3000:]
    return r.stdout


def _outputs(out: str, rule: str) -> list[str]:
    return re.findall(rf"rule {rule}:\n(?:    .*\n)*?    output: (\S+?)[,\n]", out)


@pytest.mark.slow
def test_the_default_plan_selects_and_trains_the_chain_on_every_tree_and_seed(default_plan):
    cfg = pconfig.resolve(copy.deepcopy(RAW), "default")
    trees, seeds = cfg["trees"], cfg["seeds"]
    got = set(_outputs(default_plan, "kselect_prior"))
    assert got == {f"results/kselect/{t}/seed{s}/ours_chain.json" for t in trees for s in seeds}
    got = set(_outputs(default_plan, "train_auto_prior"))
    assert got == {f"results/models/{t}/seed{s}/ours_chain_auto.pt" for t in trees for s in seeds}
    # ours' jobs keep their rules and paths
    assert set(_outputs(default_plan, "kselect")) == {
        f"results/kselect/{t}/seed{s}.json" for t in trees for s in seeds
    }
    assert set(_outputs(default_plan, "train_auto")) == {
        f"results/models/{t}/seed{s}/ours_auto.pt" for t in trees for s in seeds
    }
    # the chain's auto model is scored by the generic rules
    for kind in ("eval", "recovery"):
        assert f"results/{kind}/sparse/seed0/ours_chain_auto." in default_plan


# --- tab_kselect's rows -------------------------------------------------------------------------
def _row(K, view, time, err, trusted, frozen, train_s, select_s=0.0, kh=4, kb=32):
    return dict(
        K=K,
        view_psnr=view,
        time_psnr=time,
        median_rel_err=err,
        trusted=trusted,
        frozen=frozen,
        k_heldout=kh,
        k_bic=kb,
        train_s=train_s,
        select_s=select_s,
    )


def test_tab_kselect_sets_the_chain_beside_ours_with_its_cost_against_its_fixed_k():
    per_seed = {
        0: {
            ("sparse", "ours", "single"): _row(32, 20.0, 21.0, 0.05, 10, 3, 600.0),
            ("sparse", "ours", "auto"): _row(16, 20.1, 21.2, 0.04, 8, 2, 500.0, 300.0),
            ("sparse", "ours_chain", "single"): _row(32, 19.0, 24.0, 0.10, 12, 0, 800.0),
            ("sparse", "ours_chain", "auto"): _row(4, 19.5, 23.5, 0.02, 4, 0, 400.0, 1200.0),
        },
        1: {
            ("sparse", "ours", "single"): _row(32, 20.2, 21.4, 0.07, 12, 3, 620.0),
            ("sparse", "ours", "auto"): _row(16, 20.3, 21.6, 0.06, 8, 2, 520.0, 310.0),
            ("sparse", "ours_chain", "single"): _row(32, 19.4, 24.2, 0.12, 14, 0, 840.0),
            ("sparse", "ours_chain", "auto"): _row(8, 19.7, 23.9, 0.04, 6, 1, 420.0, 1260.0),
        },
    }
    t = tab_kselect(per_seed, ["sparse"], {"sparse": 22}, "heldout", models=("ours", "ours_chain"))
    df = t.df
    chain = df[(df.model == "ours_chain") & (df.config == "auto")].set_index("seed")
    # cost = (auto training + selection) / the chain's own K = 32 training, by hand
    assert chain.loc[0, "cost_x"] == pytest.approx((400 + 1200) / 800)  # 2.0
    assert chain.loc[1, "cost_x"] == pytest.approx((420 + 1260) / 840)  # 2.0
    assert chain["K"].tolist() == [4, 8] and chain.loc[1, "view_psnr_db"] == 19.7
    assert chain.loc[0, "median_rel_err_pct"] == pytest.approx(2.0)
    ours = df[(df.model == "ours") & (df.config == "auto")].set_index("seed")
    assert ours.loc[0, "cost_x"] == pytest.approx(800 / 600)
    assert df[df.config == "single"]["cost_x"].isna().all()
    assert df[df.config == "single"]["select_s"].isna().all()
    assert df["model"].tolist()[:4] == ["ours", "ours", "ours_chain", "ours_chain"]
    body = t.tex.split(r"\midrule", 1)[1]
    lines = [ln for ln in body.splitlines() if "Chained, chosen" in ln]
    assert len(lines) == 1
    cells = [c.strip() for c in lines[0].rstrip(" \\").split("&")]
    # model, K (each seed's), views, time, err, trusted, frozen, train, select, cost
    assert cells[1:] == [
        "Chained, chosen $K$",
        "4/8",
        r"19.60 $\pm$ 0.14",  # mean 19.6, sd of (19.5, 19.7) = 0.1414
        r"23.70 $\pm$ 0.28",
        r"3.00 $\pm$ 1.41\%",
        r"5 $\pm$ 1.41/4/8",
        r"0.5 $\pm$ 0.707",
        r"410 $\pm$ 14",
        r"1230 $\pm$ 42",
        r"2 $\pm$ 0$\times$",
    ]
    assert "Ours, fixed $K$" in t.tex and "Chained, fixed $K$" in t.tex


def test_tab_kselect_reads_the_chains_selection_and_models():
    plan = Plan(["sparse"], {}, [3], kselect_priors=["ours_chain"])
    got = needs("tab_kselect", plan)
    assert ("kselect", "sparse", 3) in got and ("prior_kselect", "sparse", "ours_chain", 3) in got
    for c in ("single", "auto"):
        assert ("eval", "sparse", "ours_chain", c, 3) in got
        assert ("recovery", "sparse", "ours_chain", c, 3) in got
        assert ("loss", "sparse", "ours_chain", c, 3) in got
        assert ("recovery", "sparse", "ours", c, 3) in got  # ours through every prior's kind
    assert not any(n[0] == "prior_kselect" for n in needs("tab_kselect", Plan(["sparse"], {}, [3])))
