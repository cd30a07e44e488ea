"""The chained prior as a method of every table: a model joins the outputs of its
registry role, its recovery rows stand beside ours' against the same null, and its headline
claims point the right way on constructed tables."""

import numpy as np
import pandas as pd
import pytest

from physgs.experiments.recipe import canonical
from physgs.models.registry import MODELS, label, models_of, training_jobs
from physgs.report import build
from physgs.report import claims as C
from physgs.report import recovery as R
from physgs.report.summary import prior_lines
from test_report_tables import BONES, null, paired, record
from roles import ROLES

CONFIGS = {"single": {"K": 32}, "joint32": {"K": 32}, "joint96": {"K": 96}}
PLAN = build.Plan(
    ["sparse"],
    CONFIGS,
    [0, 1],
    damping_trees=["sparse"],
    damping_configs=["single", "joint32"],
)


# --- a model joins every output of its role -----------------------------------------------------
def test_the_chained_prior_is_a_prior_trained_in_every_configuration():
    assert models_of("prior") == ("ours", "ours_chain")
    assert MODELS["ours_chain"].role == "prior" and "this project" in label("ours_chain")
    jobs = training_jobs(CONFIGS)
    assert {("ours_chain", c) for c in CONFIGS} <= set(jobs)
    assert ("mlp", "joint32") not in jobs  # fields stay single
    with pytest.raises(ValueError, match="unknown model role"):
        models_of("blind")


def test_every_output_that_reads_ours_reads_every_prior():
    """ours is one prior among the registry's: no output reads it by a need kind of its own."""
    from physgs.report.outputs import NEED_FIELDS

    # one need kind serves every recovery method: ours' records are read as every prior's
    assert [k for k in NEED_FIELDS if "recovery" in k] == ["recovery"]
    for name in ("tab_psnr", "tab_transfer", "tab_margin", "fig_temporal", "fig_results"):
        got = {n[2] for n in build.needs(name, PLAN) if n[0] == "eval"}
        assert {"ours", "ours_chain"} <= got, name
    for name in ("tab_recovery", "tab_damping", "fig_damping"):
        got = {n[2] for n in build.needs(name, PLAN) if n[0] == "recovery"}
        assert got == {"ours", "ours_chain"}, name
    # tab_null is the paper's table: ours alone
    assert {n[2] for n in build.needs("tab_null", PLAN) if n[0] == "recovery"} == {"ours"}
    assert ("loss", "sparse", "ours_chain", "single", 1) in build.needs("tab_fit", PLAN)
    assert ("traj", "sparse", "ours_chain", "single", 0) in build.needs("fig_teaser", PLAN)


def test_recovery_outputs_read_the_chained_prior_in_every_configuration_and_testbed():
    null_needs = build.needs("tab_recovery", PLAN)
    for c in CONFIGS:
        assert ("recovery", "sparse", "ours_chain", c, 1) in null_needs
    assert ("null", "sparse", 96, 0) in null_needs  # its K's null, shared with ours'
    assert not any(n[0] == "null" and n[2] not in (32, 96) for n in null_needs)
    damp = build.needs("tab_damping", PLAN)
    for tb in ("sparse", "sparse_damping"):
        for c in ("single", "joint32"):
            assert ("recovery", tb, "ours_chain", c, 0) in damp
    assert not any(n[0] == "recovery" and n[3] == "joint96" for n in damp)
    ledger = build.claims_needs(build.Plan(["sparse"], CONFIGS, [0, 1]))
    assert ("recovery", "sparse", "ours_chain", "joint32", 1) in ledger


# --- its rows ----------------------------------------------------------------------------------
def _priors(ours, chain, nl, configs):
    """tab_recovery's methods: ours and the chained prior, each beside the null of its K."""
    return {
        m: R.method_rows(m, configs, paired(per_seed, nl))
        for m, per_seed in (("ours", ours), ("ours_chain", chain))
    }


def test_tab_null_sets_each_prior_beside_the_null_of_its_k():
    configs = {"single": "single", "joint96": "joint96"}
    rec = {s: {("sparse", c): record(3, 0.03) for c in configs} for s in (0, 1, 2)}
    chain = {s: {("sparse", c): record(4, 0.010 + 0.001 * s) for c in configs} for s in (0, 1, 2)}
    nl = {s: {("sparse", c): null(0.0456) for c in configs} for s in (0, 1, 2)}
    tab = R.recovery_table("tab_recovery", _priors(rec, chain, nl, configs), ["sparse"], BONES)
    df = tab.df[tab.df.seed == 1]
    assert list(df.method) == ["ours", "ours", "ours_chain", "ours_chain"]
    mine = df[df.method == "ours_chain"]
    # trained 1.1 %, null 4.56 %: an oracle by hand
    np.testing.assert_allclose(mine.trained_minus_null_pp, [1.1 - 4.56] * 2)
    np.testing.assert_allclose(df[df.method == "ours"].trained_median_rel_err_pct, [3.0, 3.0])
    assert f"{label('ours_chain')}, joint96" in tab.tex
    with pytest.raises(KeyError, match="ours_chain"):
        R.recovery_table("tab_recovery", _priors(rec, {0: {}}, nl, configs), ["sparse"], BONES)


def test_a_prior_added_to_the_registry_gets_recovery_rows_through_its_entries_alone(
    tmp_path, monkeypatch
):
    """A new model of role "prior" (its registry entry and its entry in the list of recovery
    methods, nothing else) is read and scored by tab_recovery beside ours, against the null of
    its K; tab_null stays the paper's."""
    from physgs.models import registry
    from physgs.recovery.record import save_null, save_recovery
    from physgs.report.outputs import key

    spec = registry.ModelSpec("A new prior", "New", "ours", True, "prior")
    monkeypatch.setitem(registry.MODELS, "new_prior", spec)
    new = registry.RecoveryMethod(None, "recovery", note="a note.")
    monkeypatch.setitem(registry.RECOVERY_METHODS, "new_prior", new)
    cfg = {
        "trees": ["sparse"],
        "presets": {"sparse": {"bones": 22}},
        "seeds": [0, 1],
        "report": {"tab_recovery": {"digits": 2}},
        "models": {"configs": {"joint32": {"K": 4, "conditions": "all"}}},
        "tracks": {"configs": []},
        "oma": {"configs": []},
    }
    plan = build.Plan(["sparse"], cfg["models"]["configs"], [0, 1])
    err = {"ours": 0.03, "ours_chain": 0.02, "new_prior": 0.012}  # each prior's median error
    inputs = {}
    assert {n[2] for n in build.needs("tab_null", plan) if n[0] == "recovery"} == {"ours"}
    for need in build.needs("tab_recovery", plan):
        path = tmp_path / (key(need).replace("/", "_") + ".json")
        if need[0] == "null":
            save_null(path, null(0.0456))
        else:
            assert need[0] == "recovery", need
            save_recovery(path, record(3, err[need[2]]))
        inputs[key(need)] = str(path)
    assert {k.split("/")[2] for k in inputs if k.startswith("recovery")} == set(err)
    # the rule's params arrive with their keys sorted (recipe.canonical): rows keep the list's order
    settings = canonical(build.settings_for("tab_recovery", cfg))
    assert list(settings["methods"]) == ["new_prior", "ours", "ours_chain"]  # sorted
    tab = build.make_table("tab_recovery", inputs, settings, tmp_path / "n.tex", tmp_path / "n.csv")
    df = tab.df[tab.df.seed == 1]
    assert list(df.method) == ["ours", "ours_chain", "new_prior"]
    new = df[df.method == "new_prior"]
    # trained 1.2 %, the null of its K 4.56 %: by hand
    np.testing.assert_allclose(new.trained_median_rel_err_pct, 1.2)
    np.testing.assert_allclose(new.trained_minus_null_pp, 1.2 - 4.56)
    assert "A new prior, joint ($K{=}4$)" in tab.tex and " A new prior: a note." in tab.tex


# --- its claims --------------------------------------------------------------------------------
LEARNED = ("mlp", "mlp_wind", "d3dgs", "d3dgs_wind")


def _tables(ahead: float, seeds=(0, 1, 2)):
    """Tables holding ours and the chained prior: the chain ``ahead`` dB above the best learned
    field everywhere (negative: behind), its margin growing by 2 dB, its recovery 3 points
    under the null's."""
    psnr, transfer, margin, null_rows = [], [], [], []
    for s in seeds:
        jitter = 0.05 * s
        for m in ("static", *LEARNED, "ours", "ours_chain"):
            base = {"static": 20.0, "ours": 21.0, "ours_chain": 22.0 + ahead}.get(m, 22.0)
            psnr.append(
                {
                    "seed": s,
                    "model": m,
                    "sparse_view": base + jitter,
                    "sparse_time": base + jitter,
                }
            )
        for sp in ("train", "beyond"):
            transfer.append(
                {
                    "seed": s,
                    "split": sp,
                    "tree": "sparse",
                    "condition": 0.71,
                    **{m: 22.0 for m in LEARNED},
                    "static": 20.0,
                    "ours": 21.0,
                    "ours_chain": 22.0 + ahead + jitter,
                }
            )
        for m, grow in (("ours", -1.0), ("ours_chain", 2.0)):
            margin.append(
                {
                    "seed": s,
                    "model": m,
                    "tree": "sparse",
                    "margin_v0": 0.0,
                    "margin_0.71v0": grow + jitter,
                }
            )
            null_rows.append(
                {
                    "seed": s,
                    "tree": "sparse",
                    "config": "joint32",
                    "method": m,
                    "trained_median_rel_err_pct": {"ours": 2.0, "ours_chain": 1.0}[m] + jitter,
                    "null_median_rel_err_pct": 4.0,
                }
            )
    return {
        "tab_psnr": pd.DataFrame(psnr),
        "tab_transfer": pd.DataFrame(transfer),
        "tab_margin": pd.DataFrame(margin),
        "tab_null": pd.DataFrame([r for r in null_rows if r["method"] == "ours"]),
        "tab_recovery": pd.DataFrame(null_rows),
    }


def prior_claims(model, tables, damping, trees):
    """The ledger's claims asked of ``model`` (ids ``<model>/...``) measured on ``tables``."""
    measured = C.measure(tables, {}, trees, {model: damping}, roles=ROLES)
    return [(c, v) for c, v in measured if c.id.startswith(f"{model}/")]


@pytest.mark.parametrize("ahead, want", [(1.0, "holds"), (-1.0, "fails")])
def test_the_chained_priors_claims_point_the_right_way(ahead, want):
    damping = {
        "sparse": [
            {"median_zeta": z, "zeta_true": 0.08, "loglog_exponent": 0.9}
            for z in (0.081, 0.082, 0.0805)
        ]
    }
    v = C.ledger(prior_claims("ours_chain", _tables(ahead), damping, ["sparse"])).set_index("id")
    for cid, mean in (  # tab_psnr: every model shares the seed's jitter; tab_transfer: not
        ("ours_chain/ahead_of_fields/sparse/view", ahead),
        ("ours_chain/ahead_of_fields/sparse/time", ahead),
        ("ours_chain/ahead_of_fields/sparse/wind_train/0.71", ahead + 0.05),
        ("ours_chain/ahead_of_fields/sparse/wind_beyond/0.71", ahead + 0.05),
    ):
        assert v.loc[cid, "verdict"] == want, cid
        assert v.loc[cid, "measured"] == pytest.approx(mean, abs=1e-9)
    # 22 + ahead + jitter over static's 20 + jitter: above static either way
    assert v.loc["ours_chain/above_static_beyond/sparse", "measured"] == pytest.approx(2 + ahead)
    assert v.loc["ours_chain/margin_grows/sparse", "verdict"] == "holds"
    assert v.loc["ours_chain/margin_grows/sparse", "measured"] == pytest.approx(2.05)
    assert v.loc["ours_chain/beats_null/sparse", "measured"] == pytest.approx(-2.95)
    assert v.loc["ours_chain/beats_null/sparse", "verdict"] == "holds"
    assert v.loc["ours_chain/damping_recovered/sparse", "verdict"] == "holds"  # within 3%
    assert v.loc["ours_chain/decay_rate_flat/sparse", "verdict"] == "fails"  # p = 0.9


def test_ours_claims_read_ours_rows_only_and_the_chain_joins_the_ledger():
    """ours' margin and null claims keep reading ours' rows where the chain's follow; the
    ledger asks the chain's claims only of a run whose tables hold it."""
    tabs = _tables(1.0)
    v = C.ledger(C.measure(tabs, {}, ["sparse"], roles=ROLES)).set_index("id")
    assert v.loc["margin_grows/sparse", "measured"] == pytest.approx(-0.95)  # ours': -1 + jitter
    assert "ours_chain/beats_null/sparse" in v.index
    old = {
        k: d[d.get("method", d.get("model", pd.Series("x", d.index))) != "ours_chain"]
        for k, d in tabs.items()
    }
    old["tab_psnr"] = tabs["tab_psnr"][tabs["tab_psnr"].model != "ours_chain"]
    old["tab_transfer"] = tabs["tab_transfer"].drop(columns="ours_chain")
    assert not any(
        i.startswith("ours_chain/")
        for i in C.ledger(C.measure(old, {}, ["sparse"], roles=ROLES)).id
    )


def test_the_summary_counts_the_splits_where_the_chain_beats_every_field():
    led = C.ledger(prior_claims("ours_chain", _tables(1.0), {}, ["sparse"]))
    line = prior_lines(led)[0]
    assert "**4 of 4**" in line and "sparse/view" in line and label("ours_chain") in line
    behind = C.ledger(prior_claims("ours_chain", _tables(-1.0), {}, ["sparse"]))
    assert "**0 of 4**" in prior_lines(behind)[0]
    assert prior_lines(C.ledger(C.measure({}, {}, ["sparse"], roles=ROLES))) == []


def test_tab_damping_sets_each_prior_beside_ours_on_both_testbeds():
    from physgs.report.damping import tab_damping
    from test_tracks_wiring import _damped

    zb = np.array([0.03, 0.06, 0.1, 0.2])  # the bones' zeta in _damped
    keys = [("sparse", v, c) for v in ("faithful", "damping") for c in ("a", "b")]
    ours = {s: {k: _damped(zb * 1.1, s) for k in keys} for s in (0, 1)}
    chain = {s: {k: _damped(zb * 1.02, s) for k in keys} for s in (0, 1)}
    configs = {"a": "A", "b": "B"}

    def methods(chain):
        return {
            m: R.method_rows(m, configs, d, damping=True)
            for m, d in (("ours", ours), ("ours_chain", chain))
        }

    tab = tab_damping(methods(chain), ["sparse"], {"sparse": 22})
    df = tab.df
    assert list(df[df.seed == 0].method) == ["ours", "ours", "ours_chain", "ours_chain"] * 2
    # |1.1 zeta - zeta| / zeta = 10 %, |1.02 zeta - zeta| / zeta = 2 %: by hand
    np.testing.assert_allclose(df[df.method == "ours"].rel_err_pct, 10.0)
    np.testing.assert_allclose(df[df.method == "ours_chain"].rel_err_pct, 2.0)
    assert f"{label('ours_chain')}, B" in tab.tex and r"\multirow[c]{8}{*}" in tab.tex
    with pytest.raises(KeyError, match="ours_chain"):
        tab_damping(methods({0: {}}), ["sparse"], {"sparse": 22})
