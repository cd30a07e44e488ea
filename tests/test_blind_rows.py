"""The forcing-free methods' rows: the output-only analysis and the forcing-free
priors in tab_recovery and tab_damping, each in its own configurations beside the null of its own
K, ours' and the other rows left as they were; the forcing-free priors in tab_fit with their
undefined splits written as not defined; what the outputs read."""

import dataclasses

import numpy as np
import pandas as pd
import pytest

from physgs.models.registry import BLIND_PRIORS, label, recovery_label
from physgs.report import build
from physgs.report import images as IM
from physgs.report import recovery as R
from physgs.report import tables as T
from physgs.report.damping import tab_damping
from test_report_damping import _record as damping_record
from test_report_tables import BONES, null, paired, record

SEEDS = (0, 1, 2)
CONFIGS = {"single": "single", "joint32": "joint32"}


def _null_inputs():
    rec = {s: {("sparse", c): record(3, 0.03) for c in CONFIGS} for s in SEEDS}
    nl = {s: {("sparse", c): null(0.0456) for c in CONFIGS} for s in SEEDS}
    tracks = {s: {("sparse", "single"): (record(2, 0.05), null(0.0456))} for s in SEEDS}
    chain = {s: {("sparse", c): record(4, 0.01) for c in CONFIGS} for s in SEEDS}
    return rec, nl, tracks, chain


def _methods(oma_null=0.10):
    # the output-only analysis in both configurations, 2.0 + 0.5 s % against its own null (10 %);
    # ours with a learned forcing in single only, 6 %, against the null of its K (4.56 %)
    oma = {
        s: {("sparse", c): (record(2, 0.020 + 0.005 * s), null(oma_null)) for c in CONFIGS}
        for s in SEEDS
    }
    blind = {s: {("sparse", "single"): (record(1, 0.06), null(0.0456))} for s in SEEDS}
    return {
        R.OMA: R.method_rows(R.OMA, {"single": "single (K=2)", "joint32": "joint (K=2)"}, oma),
        "ours_blind": R.method_rows("ours_blind", {"single": "single"}, blind),
    }


def _tab_recovery(methods=None):
    rec, nl, tracks, chain = _null_inputs()
    priors = {
        m: R.method_rows(m, CONFIGS, paired(d, nl))
        for m, d in (("ours", rec), ("ours_chain", chain))
    }
    rows = {**priors, R.TRACKS: R.method_rows(R.TRACKS, {"single": "single"}, tracks)}
    return R.recovery_table("tab_recovery", {**rows, **(methods or {})}, ["sparse"], BONES)


def test_tab_recovery_adds_the_forcing_free_rows_with_their_own_null():
    tab = _tab_recovery(_methods())
    df = tab.df[tab.df.seed == 1]
    assert list(zip(df.method, df.config)) == [
        ("ours", "single"),
        ("ours", "joint32"),
        ("ours_chain", "single"),
        ("ours_chain", "joint32"),
        ("tracks", "single"),
        ("oma", "single"),
        ("oma", "joint32"),
        ("ours_blind", "single"),
    ]
    oma = tab.df[tab.df.method == "oma"]
    # by hand: 2.0 + 0.5 s % trained, 10 % null (its own draws, not ours' 4.56 %)
    np.testing.assert_allclose(oma.trained_median_rel_err_pct, np.repeat([2.0, 2.5, 3.0], 2))
    np.testing.assert_allclose(oma.null_median_rel_err_pct, 10.0)
    np.testing.assert_allclose(oma.trained_minus_null_pp, np.repeat([-8.0, -7.5, -7.0], 2))
    blind = tab.df[tab.df.method == "ours_blind"]
    np.testing.assert_allclose(blind.trained_minus_null_pp, 6.0 - 4.56)
    assert rf"{recovery_label(R.OMA)}, joint (K=2)" in tab.tex
    assert f"{label('ours_blind')}, single" in tab.tex


def test_tab_recovery_leaves_the_other_rows_as_they_were():
    before, after = _tab_recovery().df, _tab_recovery(_methods()).df
    kept = after[~after.method.isin([R.OMA, "ours_blind"])].reset_index(drop=True)
    pd.testing.assert_frame_equal(kept, before)


def test_tab_recovery_refuses_a_method_row_without_its_record_or_with_another_k():
    methods = _methods()
    short = dataclasses.replace(methods[R.OMA], per_seed={s: {} for s in SEEDS})
    with pytest.raises(KeyError, match="oma"):
        _tab_recovery({R.OMA: short})
    rec2 = {s: {k: (r, dataclasses.replace(n, n_parts=2)) for k, (r, n) in v.items()}
            for s, v in methods[R.OMA].per_seed.items()}  # fmt: skip
    with pytest.raises(ValueError, match="K=2"):
        _tab_recovery({R.OMA: dataclasses.replace(methods[R.OMA], per_seed=rec2)})


def test_tab_damping_adds_the_forcing_free_rows_with_their_own_scores():
    zb = np.array([0.03, 0.06, 0.1, 0.2])
    ours = {
        s: {
            ("sparse", v, c): damping_record(zb * 1.02, zb, s)
            for v in ("faithful", "damping")
            for c in CONFIGS
        }
        for s in SEEDS
    }
    # the output-only analysis 50 % off every bone's zeta; ours with a learned forcing 10 %
    oma = {s: {("sparse", v, "single"): damping_record(zb * 1.5, zb, s) for v in ("faithful", "damping")}
           for s in SEEDS}  # fmt: skip
    blind = {s: {("sparse", v, "single"): damping_record(zb * 0.9, zb, s) for v in ("faithful", "damping")}
             for s in SEEDS}  # fmt: skip
    methods = {
        R.OMA: R.method_rows(R.OMA, {"single": "single"}, oma, damping=True),
        "ours_blind": R.method_rows("ours_blind", {"single": "single"}, blind, damping=True),
    }
    mine = {"ours": R.method_rows("ours", CONFIGS, ours, damping=True)}
    before = tab_damping(mine, ["sparse"], {"sparse": 22})
    tab = tab_damping({**mine, **methods}, ["sparse"], {"sparse": 22})
    d = tab.df[(tab.df.seed == 0) & (tab.df.testbed == "damping")]
    assert list(d.method) == ["ours", "ours", "oma", "ours_blind"]
    np.testing.assert_allclose(tab.df[tab.df.method == "oma"].rel_err_pct, 50.0, atol=1e-9)
    np.testing.assert_allclose(tab.df[tab.df.method == "ours_blind"].rel_err_pct, 10.0, atol=1e-9)
    kept = tab.df[tab.df.method == "ours"].reset_index(drop=True)
    pd.testing.assert_frame_equal(kept, before.df)
    assert rf"{recovery_label(R.OMA)}, single" in tab.tex and label("ours_blind") in tab.tex


def test_tab_fit_writes_the_blind_priors_undefined_splits_as_not_defined(tmp_path):
    def row(fit, time):
        return {
            "fit": fit,
            "heldout": fit - 1,
            "view": fit - 2,
            "time": time,
            "train_s": 60.0,
            "iterations": 3000,
        }

    rows = {
        s: {
            ("sparse", "static"): row(20.0, 19.0),
            ("sparse", "ours"): row(24.0, 23.0),
            ("sparse", "ours_blind"): row(23.0 + 0.1 * s, float("nan")),
            ("sparse", "truth_motion"): row(30.0, 29.0),
        }
        for s in SEEDS
    }
    tab = IM.tab_fit(rows, ["sparse"], BONES, ("static", "ours", "ours_blind"), "truth_motion")
    b = tab.df[tab.df.model == "ours_blind"]
    assert len(b) == len(SEEDS) and b.time_psnr_db.isna().all()
    # (23 + 0.1 s - 20) / (30 - 20): by hand
    np.testing.assert_allclose(b.ceiling_frac, [0.30, 0.31, 0.32])
    line = next(x for x in tab.tex.splitlines() if label("ours_blind") in x)
    assert line.count(IM.NOT_DEFINED) == 1 and "0.00" not in line
    assert IM.NOT_DEFINED not in next(
        x for x in tab.tex.splitlines() if x.strip().startswith("& Ours")
    )
    T.write_table(tab, tmp_path / "f.tex", tmp_path / "f.csv")
    csv = pd.read_csv(tmp_path / "f.csv")
    assert csv[csv.model == "ours_blind"].time_psnr_db.isna().all()


# --- what the outputs read --------------------------------------------------------------------
PLAN = build.Plan(
    ["sparse"],
    {"single": {"K": 32}, "joint32": {"K": 32}},
    [0, 1],
    damping_trees=["sparse"],
    damping_configs=["single"],
    recovery={
        "ours": {"single": 32, "joint32": 32},
        "ours_chain": {"single": 32, "joint32": 32},
        "oma": {"single": 2, "joint32": 32},
        **{m: {"single": 32} for m in BLIND_PRIORS},
    },
)


def test_tab_recovery_and_tab_damping_read_the_forcing_free_records_and_their_nulls():
    needs = build.needs("tab_recovery", PLAN)
    for c in ("single", "joint32"):
        assert ("recovery", "sparse", "oma", c, 1) in needs
    for m in BLIND_PRIORS:
        assert ("recovery", "sparse", m, "single", 0) in needs
        assert not any(n[0] == "recovery" and n[2] == m and n[3] != "single" for n in needs)
    assert ("null", "sparse", 2, 1) in needs  # the analysis' own K
    damp = build.needs("tab_damping", PLAN)
    for tb in ("sparse", "sparse_damping"):
        assert ("recovery", tb, "oma", "single", 0) in damp
        assert ("recovery", tb, "ours_blind", "single", 0) in damp
    assert not any(n[2] == "oma" and n[3] == "joint32" for n in damp)
    # tab_null: the paper's rows alone (ours and the null of its K)
    assert {n[2] for n in build.needs("tab_null", PLAN) if n[0] == "recovery"} == {"ours"}
    assert ("null", "sparse", 2, 1) not in build.needs("tab_null", PLAN)
    bare = dataclasses.replace(PLAN, recovery={m: PLAN.recovery[m] for m in ("ours", "ours_chain")})
    assert not any(n[2] == "oma" for n in build.needs("tab_recovery", bare))
    assert bare.blind == () and PLAN.blind == BLIND_PRIORS
    assert ("eval", "sparse", "ours_blind", "single", 1) in build.needs("tab_fit", PLAN)
    assert ("table", "tab_damping") in build.claims_needs(PLAN)
    assert ("table", "tab_damping") not in build.claims_needs(
        dataclasses.replace(PLAN, damping_trees=())
    )


def test_fig_stabilisation_reads_the_first_seeds_first_configuration_and_its_truth():
    assert build.needs("fig_stabilisation", PLAN) == [
        ("oma_modes", "sparse", "single", 0),
        ("truth", "sparse", 0),
    ]
    assert build.in_report("fig_stabilisation", PLAN)
    no_oma = dataclasses.replace(PLAN, recovery={"ours": {"single": 32}})
    assert not build.in_report("fig_stabilisation", no_oma)  # nothing to draw: not built
