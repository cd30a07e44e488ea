"""Targeted reruns: on a finished quick DAG, a config edit plans only the jobs that read the
edited key (each rule's params are its narrow settings), and profiles name only real rules."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

import physgs.config
from physgs.experiments import job_spec
from workflow_helpers import ROOT, snakemake

pytestmark = pytest.mark.slow
QUICK = ["--config", "profile=quick", 'trees=["sparse"]']  # as the quick_dag fixture ran


#: every config edit whose plan a test reads; their dry runs run two at a time (``plans``)
EDITS = {
    "unchanged": {},
    "sweep_K": {"profiles": {"quick": {"speed_accuracy": {"knobs": {"K": [8, 16]}}}}},
    # two scoped edits in one dry run (each dry run costs seconds): a leak shows as an extra model
    "mlp_width_and_search": {
        "models": {"mlp": {"width": 96}, "omega_search": {"bank_scale": 0.01}}
    },
    "table_digits": {"report": {"tab_psnr": {"digits": 3}}},
    "freeze_at": {"models": {"ours": {"freeze_at": 0.6}}},
    "kselect_tie": {"models": {"kselect": {"tie_db": 0.2}}},
    # the chained prior's own candidates (the quick profile sets them, so the edit goes there)
    "kselect_chain": {
        "profiles": {
            "quick": {"models": {"kselect": {"priors": {"ours_chain": {"candidates": [4]}}}}}
        }
    },
    "tracks_iterations": {"tracks": {"iterations": 200}},
}


def _dry_run(wd: Path, override: Path) -> str:
    """The dry-run plan of `all` and `studies` with the config file ``override`` merged into the
    config."""
    return snakemake(
        wd,
        "-n",
        "--nolock",
        "--cores",
        "2",
        "all",
        "studies",
        "--configfile",
        "config/trees.yaml",
        str(override),
        *QUICK,
    ).stdout


@pytest.fixture(scope="module")
def plans(quick_dag, tmp_path_factory) -> dict[str, str]:
    """edit name -> dry-run output on the finished quick DAG; each dry run is seconds of
    single-threaded DAG building, so two run side by side. The edits are written outside the
    DAG's folder, which other tests' workers read at the same time."""
    from concurrent.futures import ThreadPoolExecutor

    edits = tmp_path_factory.mktemp("edits")
    for k, v in EDITS.items():
        (edits / f"{k}.yaml").write_text(yaml.safe_dump(v))
    with ThreadPoolExecutor(2) as pool:
        futures = {k: pool.submit(_dry_run, quick_dag, edits / f"{k}.yaml") for k in EDITS}
        return {k: f.result() for k, f in futures.items()}


def _counts(out: str) -> dict[str, int]:
    """Job counts per rule of a dry-run's output ({} when nothing is to be done)."""
    if "Nothing to be done" in out:
        return {}
    table = out.split("Job stats:", 1)[1].split("total", 1)[0]
    return {r: int(n) for r, n in re.findall(r"(?m)^(\w+)\s+(\d+)\s*$", table)}


def _checkpoints(out: str) -> set[str]:
    """The checkpoints a dry-run's output (re)trains, as '<model>_<config>': its jobs' outputs
    (a job that reruns lists checkpoints it only reads among its inputs: `all`, the summary)."""
    outputs = "\n".join(re.findall(r"(?m)^    output: (.*)$", out))
    return set(re.findall(r"results/models/\w+/seed\d+/(\w+?)\.pt", outputs))


def test_an_unchanged_config_plans_nothing(plans):
    assert _counts(plans["unchanged"]) == {}


def test_sweep_knobs_plan_no_training(plans):
    plan = _counts(plans["sweep_K"])
    # a study: `all` and its summary do not wait for it
    # the sweep's CSV, and fig_speed_accuracy drawn from it by the generic figure rule
    assert plan == {"speed_accuracy_point": 1, "speed_accuracy": 1, "figure": 1, "studies": 1}, plan


def test_mlp_width_and_search_retrain_their_own_models_only(plans):
    """The MLP's width retrains the two MLP models; the search over omega's settings the models
    it lists (the topology variants) and the chained prior's K-match points; ours, the other
    fields and the references stay."""
    out = plans["mlp_width_and_search"]
    trained = _checkpoints(out)
    assert trained == {
        "mlp_single",
        "mlp_wind_single",
        "ours_topo_single",
        # the chained prior: a method of every table, trained in every configuration
        "ours_chain_single",
        "ours_chain_joint32",
        "ours_chain_joint96",
        "ours_chain_auto",  # its K selection trains it with the search too
    }, trained
    assert _counts(out).get("kmatch_point"), _counts(out)


def test_table_format_rebuilds_that_table_only(plans):
    """The table, the claims ledger that reads its CSV and the run's summary that reads the
    ledger; nothing upstream, no other table."""
    plan = _counts(plans["table_digits"])
    assert plan == {"table": 1, "claims": 1, "summary": 1, "all": 1}, plan


@pytest.fixture(scope="module")
def fresh_recovery_plan(tmp_path_factory) -> str:
    """The dry-run plan of tab_recovery and tab_damping from an empty results folder (default
    profile, one seed): one dry run that the recovery rows' plan tests share."""
    from workflow_helpers import workflow_copy

    wd = workflow_copy(tmp_path_factory.mktemp("fresh"))
    targets = ["results/tables/tab_recovery.tex", "results/tables/tab_damping.tex"]
    return snakemake(wd, "-n", "--cores", "2", *targets, "--config", "seeds=[0]").stdout


def test_the_chained_priors_rows_plan_its_own_jobs_only(fresh_recovery_plan):
    """tab_recovery reads the chained prior's recovery in every configuration, tab_damping on both
    testbeds of the damping benchmark's configurations: a fresh plan trains and scores it there,
    and evaluates it in the base configuration only (no table reads a joint evaluation)."""
    out = fresh_recovery_plan
    trained = {c for c in _checkpoints(out) if c.startswith("ours_chain") and "blind" not in c}
    assert trained == {"ours_chain_single", "ours_chain_joint32", "ours_chain_joint96"}, trained
    outputs = "\n".join(re.findall(r"(?m)^    output: (.*)$", out))
    scored = set(
        re.findall(r"results/recovery/(\w+)/seed0/ours_chain_((?!blind)\w+)\.json", outputs)
    )
    trees = ("sparse", "medium", "dense")
    want = {(t, c) for t in trees for c in ("single", "joint32", "joint96")}
    want |= {(f"{t}_damping", c) for t in trees for c in ("single", "joint32")}
    assert scored == want, scored ^ want
    assert not re.search(r"results/eval/\w+/seed0/ours_chain_joint", outputs)


def test_the_forcing_free_rows_plan_their_jobs(fresh_recovery_plan):
    """tab_recovery and tab_damping read the output-only analysis in each of ``oma.configs`` and the
    forcing-free priors in ``single`` only, on every tree and on the damping testbeds of the
    damping benchmark's configurations: a fresh plan identifies, trains and scores them there,
    with the null of the analysis' own K."""
    from physgs.models.registry import BLIND_PRIORS

    out = fresh_recovery_plan
    cfg = physgs.config.load(ROOT / "config" / "trees.yaml", "default")
    trees, oma = cfg["trees"], cfg["oma"]["configs"]
    damping = [f"{t}_damping" for t in cfg["damping_benchmark"]["trees"]]
    dconf = cfg["damping_benchmark"]["configs"]
    assert oma and damping  # the plan below has something to show
    outputs = "\n".join(re.findall(r"(?m)^    output: (.*)$", out))
    scored = set(re.findall(r"results/recovery/(\w+)/seed0/oma_(\w+)\.json", outputs))
    want = {(t, c) for t in trees for c in oma}
    want |= {(tb, c) for tb in damping for c in oma if c in dconf}
    assert scored == want, scored ^ want
    assert len(re.findall(r"results/oma/\w+/seed0/modes_\w+\.npz", outputs)) == len(want)
    trained = {c for c in _checkpoints(out) if "blind" in c}
    assert trained == {f"{m}_single" for m in BLIND_PRIORS}, trained
    blind = set(re.findall(r"results/recovery/(\w+)/seed0/(ours\w*_blind)_(\w+)\.json", outputs))
    tbs = [*trees, *(damping if "single" in dconf else [])]
    assert blind == {(t, m, "single") for t in tbs for m in BLIND_PRIORS}, blind


def test_job_params_ignore_key_order():
    cfg = physgs.config.load(ROOT / "config" / "trees.yaml", "default")
    rev = {k: cfg[k] for k in reversed(list(cfg))}
    rev["models"] = {k: cfg["models"][k] for k in reversed(list(cfg["models"]))}
    rev["train"] = {k: cfg["train"][k] for k in reversed(list(cfg["train"]))}
    for model in ("ours", "mlp_wind"):
        assert repr(job_spec(rev, model, "single")) == repr(job_spec(cfg, model, "single"))


def test_every_rule_a_profile_names_exists(tmp_path):
    rules = set(snakemake(ROOT, "--list-rules", "--config", "profile=quick").stdout.split())
    for prof in sorted((ROOT / "workflow" / "profiles").glob("*/config.yaml")):
        spec = yaml.safe_load(prof.read_text()) or {}
        named = set(spec.get("set-threads", {})) | set(spec.get("set-resources", {}))
        assert named <= rules, f"{prof}: no rule named {sorted(named - rules)}"


def test_a_bare_snakemake_call_uses_the_default_profile(tmp_path):
    """`snakemake <target>` with no --cores works: profiles/default (-> workflow/profiles) sets
    them, as docs/reliability.md says."""
    from workflow_helpers import workflow_copy

    wd = workflow_copy(tmp_path)
    out = snakemake(wd, "-n", "results/tables/tab_null.tex", "--config", "profile=quick")
    text = out.stdout + out.stderr
    assert "Using workflow specific profile" in text and "profiles/default" in text, text[-2000:]


def test_freeze_at_retrains_ours_and_no_baseline(plans):
    trained = _checkpoints(plans["freeze_at"])
    assert trained and all(t.startswith("ours_") for t in trained), trained


def test_kselect_tie_retrains_only_the_auto_models(plans):
    out = plans["kselect_tie"]
    plan = _counts(out)
    assert plan.get("kselect") and plan.get("kselect_prior"), plan
    assert "train" not in plan and "speed_accuracy_point" not in plan, plan
    assert _checkpoints(out) == {"ours_auto", "ours_chain_auto"}


def test_the_chains_own_kselect_keys_leave_ours_selection_alone(plans):
    out = plans["kselect_chain"]
    plan = _counts(out)
    assert plan.get("kselect_prior") == 1 and "kselect" not in plan and "train" not in plan, plan
    assert _checkpoints(out) == {"ours_chain_auto"}


def test_tracks_fit_settings_refit_the_tracks_control_only(plans):
    """The fit's iterations refit and rescore the tracks control (quick: sparse, two
    configurations) and rebuild what reads it; the tracks and every trained model stay."""
    plan = _counts(plans["tracks_iterations"])
    assert plan == {
        "fit_tracks": 1,  # one job fits (and one scores) both configurations
        "tracks_evaluate": 1,
        "tracks_fields": 1,  # the learned fields at the tracks of single
        "table": 2,  # tab_recovery (its tracks rows) and tab_tracks
        "figure": 1,  # fig_tracks colours the tracks by the fit's parts
        "claims": 1,
        "summary": 1,
        "all": 1,
    }, plan
