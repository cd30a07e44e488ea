"""The parts study: segmentation records, tab_parts, its ledger claims, its config
check and its place in the job plan."""

from __future__ import annotations

from collections import Counter
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from physgs.evaluate.parts import load_segmentations, save_segmentations, segmentation_record
from physgs.models import build_model
from physgs.report import claims
from physgs.report.build import Plan, needs
from physgs.report.parts import row, tab_parts
from oracles import model_context, quick_models_cfg
from test_config import _refused
from roles import ROLES


def _majority_share(labels, bone):
    """Purity by counting with Counter: an oracle independent of part_purity's bincount."""
    hit = 0
    for p in set(labels.tolist()):
        hit += Counter(bone[labels == p].tolist()).most_common(1)[0][1]
    return hit / labels.size


def test_segmentation_record_holds_each_priors_parts_and_their_purity(tmp_path):
    ctx, _ = model_context(300, seed=3, lead_in=20)
    cfg = quick_models_cfg()
    models = {m: build_model(m, ctx, cfg, K=6, seed=1) for m in ("ours", "ours_chain")}
    rng = np.random.default_rng(0)
    bone = (ctx.canonical_xyz[:, 2] > 2.0).astype(int) * 2 + rng.integers(0, 2, 300)
    rec = segmentation_record(models, bone)
    assert list(rec["models"]) == ["ours", "ours_chain"]
    for m, model in models.items():
        lab = model.part_labels.numpy()
        assert np.array_equal(rec[f"{m}/labels"], lab)
        assert float(rec[f"{m}/overall"]) == pytest.approx(_majority_share(lab, bone))
        assert rec[f"{m}/pivots"].shape == (6, 3) and rec[f"{m}/size"].sum() == 300
    assert np.all(rec["ours/parent"] == -1)  # k-means parts are independent
    par = rec["ours_chain/parent"]
    assert par[0] == -1 and np.all(par[1:] < np.arange(1, 6))  # a tree: parents come first
    save_segmentations(tmp_path / "p.npz", rec)
    back = load_segmentations(tmp_path / "p.npz")
    assert set(back) == set(rec) and np.array_equal(back["ours_chain/parent"], par)
    with pytest.raises(ValueError, match="part labels for"):
        segmentation_record(models, bone[:10])


def _rec(err, zeta_err=None):
    m = SimpleNamespace(n_trusted=5, median_rel_err=err)
    if zeta_err is None:
        return SimpleNamespace(match=m, damping_scores=None, damping_null=None)
    return SimpleNamespace(
        match=m,
        damping_scores=SimpleNamespace(median_rel_err=zeta_err),
        damping_null=SimpleNamespace(median_median_rel_err=0.6),
    )


def _rows(seeds=(0, 1, 2), chain_gain=0.2, topo_zeta=0.3):
    null = SimpleNamespace(median_median_rel_err=0.05)
    out = {}
    for s in seeds:
        out[s] = {}
        for t in ("sparse", "medium"):
            for m, fit, z in (
                ("ours", 25.0, 0.5),
                ("ours_topo", 25.5, topo_zeta),
                ("ours_chain", 25.5 + 13.3 * chain_gain + 0.01 * s, 0.35),
            ):
                f = {"fit": fit, "view": 24.0, "time": 23.0 + s, "train_s": 100.0}
                out[s][(t, m, "single")] = row(
                    f, 23.42, 36.72, _rec(0.02), null, _rec(0.02, z + 0.01 * s), purity=0.8
                )
    return out


def test_tab_parts_rows_fractions_and_differences():
    t = tab_parts(
        _rows(),
        ["sparse", "medium"],
        {"sparse": 22, "medium": 90},
        ["ours", "ours_topo", "ours_chain"],
        {"single": "single ($K{=}32$)"},
    )
    df = t.df
    assert len(df) == 3 * 2 * 3 and set(df["seed"]) == {0, 1, 2}
    r = df[(df.seed == 0) & (df.tree == "sparse") & (df.model == "ours")].iloc[0]
    assert r.ceiling_frac == pytest.approx((25.0 - 23.42) / (36.72 - 23.42))
    assert r.omega_rel_err_pct == pytest.approx(2.0) and r.zeta_null_rel_err_pct == 60.0
    # the chained prior's gain over ours is decided (+~24 pp at every seed): bold, no dagger
    assert r"\textbf{$+24$" in t.tex
    with pytest.raises(KeyError, match="no results"):
        tab_parts(_rows(), ["dense"], {"dense": 1}, ["ours"], {"single": "s"})


def test_tab_parts_without_a_damping_testbed_shows_no_damping_cell():
    null = SimpleNamespace(median_median_rel_err=0.05)
    f = {"fit": 25.0, "view": 24.0, "time": 23.0, "train_s": 1.0}
    r = row(f, 23.0, 27.0, _rec(0.02), null, None)
    assert np.isnan(r["zeta_rel_err_pct"]) and r["ceiling_frac"] == pytest.approx(0.5)
    with pytest.raises(ValueError, match="no damping scores"):
        row(f, 23.0, 27.0, _rec(0.02), null, _rec(0.02))


def _parts_claims(parts, trees):
    """The parts study's claims of the ledger, measured on tab_parts."""
    fams = ("coupling_lifts_sparse_fit", "topology_parts_reduce_damping_error")
    measured = claims.measure({"tab_parts": parts}, {}, trees, roles=ROLES)
    return [(c, v) for c, v in measured if c.id.split("/")[0] in fams]


@pytest.mark.parametrize(
    "chain_gain, topo_zeta, coupling, damping",
    [(0.2, 0.3, "holds", "holds"), (-0.2, 0.7, "fails", "fails")],
)
def test_parts_claims_follow_the_paired_seed_differences(chain_gain, topo_zeta, coupling, damping):
    df = tab_parts(
        _rows(chain_gain=chain_gain, topo_zeta=topo_zeta),
        ["sparse", "medium"],
        {"sparse": 22, "medium": 90},
        ["ours", "ours_topo", "ours_chain"],
        {"single": "s"},
    ).df
    measured = {c.id: (c, v) for c, v in _parts_claims(df, ["sparse", "medium"])}
    c, v = measured["coupling_lifts_sparse_fit"]
    assert v == pytest.approx([chain_gain + 0.01 * s / 13.3 for s in range(3)], rel=1e-6)
    assert claims.verdict(c, v) == coupling
    c, v = measured["topology_parts_reduce_damping_error/medium"]
    assert v == pytest.approx([100 * (topo_zeta - 0.5)] * 3)
    assert claims.verdict(c, v) == damping


def test_parts_needs_read_every_prior_and_no_damping_where_none_is_built():
    single = {"single": {"K": 32}}
    plan = Plan(
        ["sparse", "medium"],
        single,
        [0, 1],
        damping_trees=["medium", "dense"],  # dense: a damping tree the run does not build
        parts_models=["ours_chain"],
        parts_configs=single,
    )
    got = needs("tab_parts", plan)
    assert ("recovery", "sparse", "ours_chain", "single", 1) in got
    assert ("recovery", "medium_damping", "ours", "single", 0) in got
    assert not any(
        n[:2] in {("recovery", t) for t in ("sparse_damping", "dense_damping")} for n in got
    )
    assert ("eval", "sparse", "truth_motion", "single", 0) in got
    assert ("parts", "medium", 1) in got and ("null", "medium", 32, 0) in got
    plan = Plan(["sparse"], {}, [4, 5], parts_models=["ours_chain"])
    assert needs("fig_parts", plan) == [("parts", "sparse", 4)]


def test_parts_study_configs_must_be_configs_of_ours_and_of_the_damping_benchmark():
    msg = _refused(lambda c: c["parts_study"].update(configs=["joint64"]))
    assert "parts_study/configs" in msg and "joint64" in msg
    msg = _refused(lambda c: c["parts_study"].update(configs=["joint96"]))
    assert "parts_study/configs" in msg and "damping_benchmark/configs" in msg
    msg = _refused(lambda c: c["parts_study"].update(models=["ours"]))
    assert "parts_study" in msg


def test_ledger_frame_is_a_dataframe_with_the_parts_claims():
    df = tab_parts(
        _rows(), ["sparse"], {"sparse": 22}, ["ours", "ours_topo", "ours_chain"], {"single": "s"}
    ).df
    led = claims.ledger(_parts_claims(df, ["sparse"]))
    assert isinstance(led, pd.DataFrame) and len(led) == 2


def test_matched_k_is_the_smallest_k_within_the_tie():
    from physgs.experiments.kmatch import matched_k

    held = {4: 20.0, 8: 21.95, 16: 22.3, 32: 22.4}
    assert matched_k(held, 22.0, 0.1) == 8  # 21.95 >= 21.9
    assert matched_k(held, 22.4, 0.05) == 32
    assert matched_k(held, 23.0, 0.1) is None
    assert matched_k({4: float("nan"), 8: 22.0}, 22.0, 0.0) == 8


def test_tab_parts_k_rows_and_matched_k_per_seed():
    from physgs.report.parts import tab_parts_k

    per_seed = {
        0: {"sparse": {"ours": 25.0, "chain": {4: 24.0, 8: 24.95, 32: 25.5}}},
        1: {"sparse": {"ours": 25.0, "chain": {4: 23.0, 8: 24.5, 32: 24.0}}},
    }
    t = tab_parts_k(per_seed, ["sparse"], {"sparse": 22}, 32, 0.1)
    df = t.df
    assert len(df) == 2 * 4
    assert df.loc[df.seed == 0, "matched_k"].unique().tolist() == [8.0]
    assert np.isnan(df.loc[df.seed == 1, "matched_k"]).all()  # no K within 0.1 dB of 25.0
    assert "8, --" in t.tex
    row = df[(df.seed == 1) & (df.model == "ours_chain") & (df.K == 8)].iloc[0]
    assert row.heldout_psnr_db == 24.5


def test_kmatch_point_job_keeps_the_chained_job_but_k():
    from physgs.experiments.kmatch import point_job
    from physgs.experiments.recipe import job_spec
    from oracles import quick_config

    job = job_spec(quick_config(), "ours_chain", "single", seed=2)
    pj = point_job(job, 8)
    assert pj["K"] == 8 and {k: v for k, v in pj.items() if k != "K"} == {
        k: v for k, v in job.items() if k != "K"
    }


def test_k_candidates_must_be_below_the_base_k_and_train_the_chain():
    msg = _refused(lambda c: c["parts_study"].update(k_candidates=[8, 32]))
    assert "parts_study/k_candidates/1" in msg and "not below" in msg
    msg = _refused(lambda c: c["parts_study"].update(models=["ours_topo"]))
    assert "parts_study/k_candidates" in msg and "ours_chain" in msg
