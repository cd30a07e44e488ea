"""Tables: known best in bold, .tex and .csv agree, bad input stops."""

import re

import numpy as np
import pandas as pd
import pytest

from physgs.recovery.damping import damping_summary
from physgs.recovery.matcher import MatchResult
from physgs.recovery.null import NullResult
from physgs.recovery.record import RecoveryRecord
from physgs.models.registry import MODEL_NAMES, label
from physgs.report import images as IM
from physgs.report import seeds as seedstats
from physgs.report import recovery as R
from physgs.report import tables as T

TREES = ["sparse", "medium"]
BONES = {"sparse": 22, "medium": 224}
COND = [1.0, 0.84, 0.71]


def summaries():
    rng = np.random.default_rng(0)
    S = {}
    for t in TREES:
        for m in MODEL_NAMES:
            d = {"view": 25 + rng.random(), "time": 24 + rng.random()}
            for c in range(3):
                d[f"train_c{c}"] = 26 + rng.random()
                d[f"beyond_c{c}"] = 24 + rng.random()
            S[(t, m)] = d
    S[("medium", "ours")]["time"] = 31.0  # known best in its column
    S[("sparse", "d3dgs")]["beyond_c2"] = 30.0  # known best in its row
    return S


def tex_rows(tex):
    """Numeric cells of each body row of a booktabs tabular, in order, and which were bold.

    A cell counts when, stripped of bold/math/percent markup, it is a number or 'n/K'; a
    'mean $\\pm$ sd' cell counts as two numbers.
    """
    body = tex.split("\\midrule", 1)[1].split("\\bottomrule")[0]
    out = []
    for line in body.split("\\\\"):
        if "&" not in line:
            continue
        nums, bold = [], []
        for c in line.split("&"):
            plain = (
                re.sub(r"\\textbf\{(.*)\}", r"\1", c.strip()).replace("$", "").replace("\\%", "")
            )
            plain = plain.replace("^{\\dagger}", "")  # the undecided mark
            for part in plain.split("\\pm"):
                m = re.fullmatch(r"([-+]?\d+(?:\.\d+)?)(?:/\d+)?", part.strip())
                if m:
                    nums.append(float(m.group(1)))
                    bold.append("textbf" in c)
        out.append((nums, bold))
    return out


def per_seed(n_seeds, noise=0.0):
    """{seed: summaries()} with seed-specific noise (0: the same values for every seed)."""
    rng = np.random.default_rng(1)
    out = {}
    for s in range(n_seeds):
        S = summaries()
        shift = rng.normal(0, 1.0)  # a seed-wide offset every model shares (pairing cancels it)
        out[s] = {
            k: {kk: v + shift + noise * rng.normal() for kk, v in d.items()} for k, d in S.items()
        }
    return out


def test_one_seed_tab_psnr_agrees_and_bolds_nothing(tmp_path):
    tab = IM.tab_psnr(per_seed(1), TREES, BONES)
    cols = ["sparse_view", "sparse_time", "medium_view", "medium_time"]
    assert list(tab.df.columns) == ["seed", "model", *cols, "difference"]
    n = len(MODEL_NAMES)  # the paper's five and its prior, and this project's chained prior
    assert list(tab.df.model[:n]) == list(MODEL_NAMES) and n == 7  # ids; labels in the .tex
    T.write_table(tab, tmp_path / "t.tex", tmp_path / "t.csv")
    csv = pd.read_csv(tmp_path / "t.csv")
    rows = tex_rows((tmp_path / "t.tex").read_text())
    assert len(rows) == len(csv) == n + 4  # the models, two differences per prior
    for (nums, bold), (_, r) in zip(rows, csv.iterrows()):
        np.testing.assert_allclose(nums, np.round(r[cols].to_numpy(float), 2), atol=1e-9)
        assert not any(bold)  # one seed: no interval, nothing decided
    S = per_seed(1)[0]
    best_view = max(S[("sparse", m)]["view"] for m in ("mlp", "mlp_wind", "d3dgs", "d3dgs_wind"))
    for i, p in ((n, "ours"), (n + 2, "ours_chain")):  # each prior: - static, - best field
        assert csv.loc[i, "model"] == f"{p}-static" and csv.loc[i + 1, "model"] == f"{p}-best_field"
        p_static = S[("medium", p)]["time"] - S[("medium", "static")]["time"]
        assert csv.loc[i, "medium_time"] == pytest.approx(p_static)
        assert csv.loc[i + 1, "sparse_view"] == pytest.approx(S[("sparse", p)]["view"] - best_view)
    assert seedstats.UNDECIDED in tab.tex


def test_seeds_give_mean_sd_and_a_decided_best(tmp_path):
    data = per_seed(4, noise=0.05)
    tab = IM.tab_psnr(data, TREES, BONES)
    assert sorted(tab.df.seed.unique()) == [0, 1, 2, 3] and len(tab.df) == 4 * 11
    ours = tab.df[tab.df.model == "ours"]["medium_time"].to_numpy()
    m, sd = ours.mean(), ours.std(ddof=1)  # independent of the module: numpy
    assert f"{m:.2f} $\\pm$ {sd:.2f}" in tab.tex
    # ours is 31 + shift + noise on every seed: ~5 dB above every other model, paired -> bold
    assert rf"\textbf{{{m:.2f} $\pm$ {sd:.2f}}}" in tab.tex


def test_an_undecided_best_is_not_bold():
    data = per_seed(3, noise=2.0)  # noise far above the gaps between the best two
    for s in data:  # two models tied on average in one column
        data[s][("sparse", "mlp")]["view"] = 40.0 + (1.0 if s % 2 else -1.0)
        data[s][("sparse", "mlp_wind")]["view"] = 40.0
    tab = IM.tab_psnr(data, TREES, BONES)
    line = [ln for ln in tab.tex.splitlines() if ln.strip().startswith(label("mlp") + " &")][0]
    assert "textbf" not in line.split("&")[1]


def test_paired_differences_use_scipy_t_interval():
    from scipy import stats

    data = per_seed(5, noise=0.3)
    tab = IM.tab_margin(data, TREES, BONES, COND)
    d = tab.df[tab.df.tree == "medium"]["margin_0.84v0"].to_numpy()
    exp = [
        data[s][("medium", "ours")]["train_c1"] - data[s][("medium", "mlp_wind")]["train_c1"]
        for s in range(5)
    ]
    np.testing.assert_allclose(d, exp)
    lo, hi = stats.t.interval(0.95, len(d) - 1, loc=d.mean(), scale=stats.sem(d))
    cell = f"${d.mean():+.2f}$ [{lo:.2f}, {hi:.2f}]"
    assert cell in tab.tex
    assert (rf"\textbf{{{cell}}}" in tab.tex) == (lo > 0 or hi < 0)


def test_pairing_decides_what_unpaired_seeds_cannot():
    """A large seed-wide offset shared by both models hides a constant 0.5 dB margin from any
    unpaired comparison; per-seed pairing recovers it exactly."""
    base = per_seed(4, noise=0.0)
    for S in base.values():
        for c in range(3):
            S[("sparse", "ours")][f"train_c{c}"] = S[("sparse", "mlp_wind")][f"train_c{c}"] + 0.5
    from scipy import stats

    tab = IM.tab_margin(base, ["sparse"], BONES, COND)
    np.testing.assert_allclose(tab.df["margin_v0"], 0.5)
    assert tab.df["seed"].tolist() == [0, 1, 2, 3]
    assert r"\textbf{$+0.50$ [0.50, 0.50]}" in tab.tex
    ours = [base[s][("sparse", "ours")]["train_c0"] for s in base]
    mlpw = [base[s][("sparse", "mlp_wind")]["train_c0"] for s in base]
    assert stats.ttest_ind(ours, mlpw).pvalue > 0.05  # unpaired, the offsets drown the margin


def test_tab_transfer_rows_and_decided_bold():
    data = per_seed(3, noise=0.01)
    tab = IM.tab_transfer(data, TREES, BONES, COND)
    assert len(tab.df) == 3 * 2 * len(TREES) * 2
    assert list(tab.df.columns) == ["seed", "split", "tree", "bones", "condition", *MODEL_NAMES]
    first = tab.df[tab.df.seed == 0]
    rows = tex_rows(tab.tex)
    for (nums, bold), (_, r) in zip(rows, first.iterrows()):
        vals = tab.df[
            (tab.df.split == r.split) & (tab.df.tree == r.tree) & (tab.df.condition == r.condition)
        ][list(MODEL_NAMES)].to_numpy(float)
        np.testing.assert_allclose(nums[::2], np.round(vals.mean(0), 2))  # mean, then sd
        top = np.sort(vals.mean(0))
        if top[-1] - top[-2] > 0.1:  # a gap ten times the noise: decided
            assert bold[2 * int(np.argmax(vals.mean(0)))] and sum(bold) == 2
    r = tab.df[(tab.df.split == "beyond") & (tab.df.tree == "sparse") & (tab.df.condition == 0.71)]
    assert (r.d3dgs - r[["static", "mlp", "ours"]].max(axis=1) > 2).all()


def test_tab_margin_values():
    S = per_seed(1)
    tab = IM.tab_margin(S, TREES, BONES, COND)
    assert list(tab.df.columns) == [
        "seed",
        "model",
        "tree",
        "bones",
        "margin_v0",
        "margin_0.84v0",
        "margin_0.71v0",
    ]
    exp = S[0][("medium", "ours")]["train_c1"] - S[0][("medium", "mlp_wind")]["train_c1"]
    assert tab.df.loc[1, "margin_0.84v0"] == pytest.approx(exp)
    assert f"${exp:+.2f}$" + seedstats.UNDECIDED in tab.tex
    # every prior a block of its own, ours first and unchanged
    both = IM.tab_margin(S, TREES, BONES, COND, priors=("ours", "ours_chain"))
    assert list(both.df.model) == ["ours", "ours", "ours_chain", "ours_chain"]
    pd.testing.assert_frame_equal(both.df.iloc[:2], tab.df)
    chain = S[0][("sparse", "ours_chain")]["train_c2"] - S[0][("sparse", "mlp_wind")]["train_c2"]
    assert both.df.loc[2, "margin_0.71v0"] == pytest.approx(chain)
    assert rf"{label('ours_chain')} $-$ (Deformation MLP" in both.tex


def test_results_not_keyed_by_seed_are_refused():
    with pytest.raises(TypeError, match="keyed by training seed"):
        IM.tab_psnr(summaries(), TREES, BONES)


def record(n_trusted, med):
    K = 4
    trusted = np.arange(K) < n_trusted
    m = MatchResult(
        np.zeros(K, int),
        np.ones(K),
        trusted,
        np.ones(K),
        np.ones(K),
        np.zeros(K),
        n_trusted,
        K,
        med,
        0.9,
    )
    return RecoveryRecord(m, damping_summary(np.array([1.0, 2, 3, 4]), np.full(4, 0.1), 0.08))


def null(med):
    return NullResult(
        np.array([4, 3, 4]),
        np.array([med, med, np.nan]),
        np.array([0.99, 0.98, np.nan]),
        np.ones((3, 4)),
        4,
        0.004,
        0,
    )


def paired(rec, nl):
    """tab_null's per-seed (record, null of its K) of per-seed records and nulls."""
    return {s: {k: (r, nl[s][k]) for k, r in d.items()} for s, d in rec.items()}


def ours(rec, nl, configs):
    """tab_null's methods holding ours' rows alone."""
    return {"ours": R.method_rows("ours", configs, paired(rec, nl))}


def test_tab_null_per_seed_difference_and_nan_cells(tmp_path):
    cfg = {"single": "single ($K{=}32$)"}
    rec = {
        s: {
            ("sparse", "single"): record(3, 0.018 + 0.001 * s),
            ("medium", "single"): record(0, float("nan")),
        }
        for s in range(3)
    }
    nl = {
        s: {("sparse", "single"): null(0.0456 + 0.002 * s), ("medium", "single"): null(0.0177)}
        for s in range(3)
    }
    tab = R.recovery_table("tab_null", ours(rec, nl, cfg), TREES, BONES)
    sp = tab.df[tab.df.tree == "sparse"]
    np.testing.assert_allclose(sp.trained_median_rel_err_pct, [1.8, 1.9, 2.0])
    np.testing.assert_allclose(sp.null_median_rel_err_pct, [4.56, 4.76, 4.96])
    np.testing.assert_allclose(sp.trained_minus_null_pp, [-2.76, -2.86, -2.96])
    assert (sp.null_parts_trusted == 4).all() and sp.nearest_bone_gap_pct.iloc[0] == pytest.approx(
        0.4
    )
    # trained beats the null on every seed by ~2.9 points with sd 0.1: decided, bold
    assert r"\textbf{$-2.86$" in tab.tex
    assert "1.90 $\\pm$ 0.10\\%" in tab.tex
    T.write_table(tab, tmp_path / "n.tex", tmp_path / "n.csv")
    csv = pd.read_csv(tmp_path / "n.csv")
    assert np.isnan(csv[csv.tree == "medium"].trained_median_rel_err_pct).all()
    assert "--" in tab.tex  # the medium model has no trusted part
    with pytest.raises(KeyError, match="dense"):
        R.recovery_table("tab_null", ours(rec, nl, cfg), ["sparse", "dense"], BONES)


def test_tab_null_refuses_a_null_with_another_k():
    cfg = {"single": "single ($K{=}32$)"}
    rec = {0: {("sparse", "single"): record(3, 0.018)}}
    other = NullResult(
        np.array([4]), np.array([0.04]), np.array([0.9]), np.ones((1, 8)), 8, 0.004, 0
    )
    with pytest.raises(ValueError, match="K=8"):
        R.recovery_table(
            "tab_null", ours(rec, {0: {("sparse", "single"): other}}, cfg), ["sparse"], BONES
        )


def test_missing_model_names_the_cause():
    S = per_seed(2)
    del S[1][("sparse", "mlp")]
    with pytest.raises(KeyError, match="mlp"):
        IM.tab_psnr(S, TREES, BONES)


def test_tab_psnr_reference_row_is_separate_and_never_bold():
    S = per_seed(3, noise=0.01)
    for s in S:
        for t in TREES:
            S[s][(t, "truth_motion")] = {"view": 40.0 + 0.1 * s, "time": 40.0}  # above every method
    tab = IM.tab_psnr(S, TREES, BONES, references=("truth_motion",))
    first = tab.df[tab.df.seed == 0]
    n = len(MODEL_NAMES)  # the methods, the reference, two differences per prior
    assert first.reference.tolist() == [False] * n + [True] + [False] * 4
    assert r"\textbf{40.10" not in tab.tex and r"\emph{True motion" in tab.tex
    # one bold per column at most, on a method row (the reference is never a candidate)
    body = [ln for ln in tab.tex.splitlines() if "textbf" in ln]
    assert all(not ln.strip().startswith(r"\emph") for ln in body)


def test_tab_fit_fraction_of_the_ceiling():
    models = ("static", "mlp", "ours")
    rows = {}
    for t in TREES:
        for m, fit in zip((*models, "truth_motion"), (20.0, 22.0, 26.0, 30.0)):
            rows[(t, m)] = {
                "fit": fit,
                "heldout": fit - 0.5,
                "view": 21.0,
                "time": 21.5,
                "train_s": 12.0,
                "iterations": 1800.0 if m == "static" else 3000.0,
            }
    tab = IM.tab_fit({0: rows}, TREES, BONES, models, "truth_motion")
    frac = dict(zip(tab.df.model[tab.df.tree == "sparse"], tab.df.ceiling_frac))
    # (model - static) / (ceiling - static): 0, 2/10, 6/10, 1
    assert frac == pytest.approx({"static": 0.0, "mlp": 0.2, "ours": 0.6, "truth_motion": 1.0})
    assert "60\\%" in tab.tex and "20\\%" in tab.tex
    # the iterations each model used, in the CSV and as the last .tex column
    assert dict(zip(tab.df.model[tab.df.tree == "sparse"], tab.df.iterations))["static"] == 1800
    static = next(ln for ln in tab.tex.splitlines() if "& Static pose &" in ln)
    assert static.rstrip(" \\").endswith("& 12 & 1800")


def test_tab_fit_held_out_fraction_beside_the_trained_one(tmp_path):
    """The held-out window frames' fraction of the ceiling's gain, against the static pose's and
    the ceiling's held-out frames, beside the trained frames' (a memorising field: the gap)."""
    from physgs.report.build import read_table

    models = ("static", "mlp", "ours")
    # (fit, heldout) per model; the ceiling last
    psnr = {"static": (20.0, 19.0), "mlp": (28.0, 21.0), "ours": (26.0, 24.0)}
    psnr["truth_motion"] = (30.0, 29.0)
    per_seed = {}
    for s in (0, 1):
        per_seed[s] = {
            (t, m): {
                "fit": f,
                "heldout": h + (0.5 if (m == "ours" and s == 1) else 0.0),
                "view": 21.0,
                "time": 21.5,
                "train_s": 12.0,
                "iterations": 3000.0,
            }
            for t in TREES
            for m, (f, h) in psnr.items()
        }
    tab = IM.tab_fit(per_seed, TREES, BONES, models, "truth_motion")
    d = tab.df[tab.df.tree == TREES[0]].set_index(["seed", "model"])
    # trained: (28 - 20) / (30 - 20) = 0.8, (26 - 20) / 10 = 0.6
    assert d.loc[(0, "mlp"), "ceiling_frac"] == pytest.approx(0.8)
    assert d.loc[(0, "ours"), "ceiling_frac"] == pytest.approx(0.6)
    # held out: (21 - 19) / (29 - 19) = 0.2; ours (24 - 19) / 10 = 0.5, seed 1 (24.5 - 19) / 10
    assert d.loc[(0, "mlp"), "heldout_ceiling_frac"] == pytest.approx(0.2)
    assert d.loc[(0, "ours"), "heldout_ceiling_frac"] == pytest.approx(0.5)
    assert d.loc[(1, "ours"), "heldout_ceiling_frac"] == pytest.approx(0.55)
    assert d.loc[(0, "static"), "heldout_ceiling_frac"] == pytest.approx(0.0)
    assert d.loc[(0, "truth_motion"), "heldout_ceiling_frac"] == pytest.approx(1.0)
    # the .tex: the held-out fraction right after the trained one
    assert "& Of ceiling & Held-out of ceiling &" in tab.tex
    mlp = next(ln for ln in tab.tex.splitlines() if f"& {label('mlp')} &" in ln)
    cells = [c.strip() for c in mlp.split("&")]
    i = cells.index(label("mlp"))
    assert cells[i + 3].startswith("80") and cells[i + 4].startswith("20")
    # the CSV holds it, and reads back through the table's declared columns
    T.write_table(tab, tmp_path / "tab_fit.tex", tmp_path / "tab_fit.csv")
    back = read_table("tab_fit", tmp_path / "tab_fit.csv")
    assert back["heldout_ceiling_frac"].tolist() == pytest.approx(tab.df.heldout_ceiling_frac)


def test_fit_row_splits_trained_and_held_out_frames(tmp_path):
    from physgs.evaluate.splits import EvalResult
    from physgs.report.build import fit_row

    n_train, n_tail = 30, 5
    cam = np.full((3, n_train + n_tail), 5.0)
    cam[0, :n_train] = 10.0
    cam[0, 9:n_train:10] = 20.0  # frames 9, 19, 29: the held-out ones (every 10th)
    ev = EvalResult(
        camera_psnr=cam,
        centroid_err=np.zeros_like(cam),
        view_psnr=np.full((2, 3), 7.0),
        conditions=np.array(COND),
        heldout_azimuths_deg=np.array([-5.0, 5.0]),
        heldout_frame_idx=np.array([0, 10, 20]),
        n_train=n_train,
        n_tail=n_tail,
    )
    ev.save(tmp_path / "e.npz")
    log = pd.DataFrame({"iteration": [0, 1, 2], "seconds": [1.0, 2.0, 42.5]})
    log.to_csv(tmp_path / "l.csv", index=False)
    r = fit_row(tmp_path / "e.npz", tmp_path / "l.csv", n_train, 10)
    assert r["fit"] == pytest.approx(10.0) and r["heldout"] == pytest.approx(20.0)
    assert r["train_s"] == 42.5 and r["view"] == pytest.approx(7.0)
    assert r["iterations"] == 3  # the loss log's rows: iterations 0, 1, 2


def test_render_is_one_booktabs_table_grouped_and_bold_where_asked():
    from physgs.report import latex

    cells = pd.DataFrame(
        {("A", "x"): ["1", "2"], ("A", "y"): ["3", "4"]},
        index=pd.MultiIndex.from_tuples([("g", "r1"), ("g", "r2")]),
    )
    tex = latex.render(cells, "Cap.", "tab:t", bold=np.array([[False, True], [False, False]]))
    assert tex.count(r"\toprule") == tex.count(r"\midrule") == tex.count(r"\bottomrule") == 1
    assert r"\caption{Cap.}" in tex and r"\label{tab:t}" in tex
    assert r"\multicolumn{2}{c}{A}" in tex  # the heading spans its two columns
    assert r"\multirow[c]{2}{*}{g} & r1 & 1 & \textbf{3} \\" in tex
    assert " & r2 & 2 & 4 \\\\" in tex  # the group's label once; nothing else bold
    assert "\\textbf{" not in latex.render(cells, "Cap.", "tab:t")


def test_cells_summarise_each_row_over_the_seed_blocks():
    from physgs.report import latex

    df = pd.DataFrame({"seed": [0, 0, 1, 1], "x": [1.0, np.nan, 3.0, np.nan]})
    assert latex.cells(df, "x", ".1f", r"\%") == [r"2.0 $\pm$ 1.4\%", "--"]  # sd of (1, 3)
    assert latex.cells(df, "x", ".0f", cell=latex.mean, scale=10) == ["20", "--"]


def test_seed_rows_lays_out_one_block_per_seed():
    df = T.seed_rows([3, 7], [("a", 1), ("b", 2)], lambda s, t, k: {"tree": t, "v": 10 * s + k})
    assert list(df.columns) == ["seed", "tree", "v"]
    assert df.to_dict("list") == {
        "seed": [3, 3, 7, 7],
        "tree": ["a", "b", "a", "b"],
        "v": [31, 32, 71, 72],
    }
