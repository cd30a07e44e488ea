"""Tables: known best in bold, .tex and .csv agree, bad input stops."""
import re

import numpy as np
import pandas as pd
import pytest

from physgs.recovery.damping import damping_summary
from physgs.recovery.matcher import MatchResult
from physgs.recovery.null import NullResult
from physgs.recovery.record import RecoveryRecord
from physgs.report import tables as T

TREES = ["sparse", "medium"]
BONES = {"sparse": 22, "medium": 224}
COND = [1.0, 0.84, 0.71]


def summaries():
    rng = np.random.default_rng(0)
    S = {}
    for t in TREES:
        for m in T.MODELS:
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

    A cell counts when, stripped of bold/math/percent markup, it is a number or 'n/K'.
    """
    body = tex.split("\\midrule", 1)[1].split("\\bottomrule")[0]
    out = []
    for line in body.split("\\\\"):
        if "&" not in line:
            continue
        nums, bold = [], []
        for c in line.split("&"):
            plain = re.sub(r"\\textbf\{(.*)\}", r"\1", c.strip()).replace("$", "").replace("\\%", "")
            m = re.fullmatch(r"([-+]?\d+(?:\.\d+)?)(?:/\d+)?", plain)
            if m:
                nums.append(float(m.group(1)))
                bold.append("textbf" in c)
        out.append((nums, bold))
    return out


def test_tab_psnr_bold_and_agreement(tmp_path):
    tab = T.tab_psnr(summaries(), TREES, BONES)
    assert list(tab.df.model) == [T.label(m) for m in T.MODELS]
    assert list(tab.df.columns) == ["model", "sparse_view", "sparse_time", "medium_view", "medium_time"]
    T.write_table(tab, tmp_path / "t.tex", tmp_path / "t.csv")
    csv = pd.read_csv(tmp_path / "t.csv")
    rows = tex_rows((tmp_path / "t.tex").read_text())
    assert len(rows) == len(csv) == 6
    for (nums, bold), (_, r) in zip(rows, csv.iterrows()):
        np.testing.assert_allclose(nums, np.round(r.iloc[1:].to_numpy(float), 2), atol=1e-9)
    ours = rows[-1]
    assert ours[0][3] == 31.0 and ours[1][3]
    # exactly one bold per column (no ties in this data), and it is the column maximum
    for j, col in enumerate(csv.columns[1:]):
        flags = [b[j] for _, b in rows]
        assert sum(flags) == 1 and flags[int(csv[col].idxmax())]


def test_tab_transfer_rows_and_bold():
    tab = T.tab_transfer(summaries(), TREES, BONES, COND)
    assert len(tab.df) == 2 * len(TREES) * 2
    assert list(tab.df.columns) == ["split", "tree", "bones", "condition", *T.MODELS]
    rows = tex_rows(tab.tex)
    for (nums, bold), (_, r) in zip(rows, tab.df.iterrows()):
        vals = r[list(T.MODELS)].to_numpy(float)
        np.testing.assert_allclose(nums, np.round(vals, 2))
        assert bold[int(np.argmax(vals))]
    r = tab.df[(tab.df.split == "beyond") & (tab.df.tree == "sparse") & (tab.df.condition == 0.71)]
    assert float(r.d3dgs.iloc[0]) == 30.0


def test_tab_margin_values():
    S = summaries()
    tab = T.tab_margin(S, TREES, BONES, COND)
    assert list(tab.df.columns) == ["tree", "bones", "margin_v0", "margin_0.84v0", "margin_0.71v0"]
    exp = S[("medium", "ours")]["train_c1"] - S[("medium", "mlp_wind")]["train_c1"]
    assert tab.df.loc[1, "margin_0.84v0"] == pytest.approx(exp)
    assert f"${exp:+.2f}$" in tab.tex


def record(n_trusted, med):
    K = 4
    trusted = np.arange(K) < n_trusted
    m = MatchResult(np.zeros(K, int), np.ones(K), trusted, np.ones(K), np.ones(K), np.zeros(K),
                    n_trusted, K, med, 0.9)
    return RecoveryRecord(m, damping_summary(np.array([1.0, 2, 3, 4]), np.full(4, 0.1), 0.08))


def null(med):
    return NullResult(np.array([4, 3, 4]), np.array([med, med, np.nan]), np.array([0.99, 0.98, np.nan]),
                      np.ones((3, 4)), 4, 0.004, 0)


def test_tab_null_bold_lower_error_and_nan_cells(tmp_path):
    rec = {("sparse", "single"): record(3, 0.018), ("medium", "single"): record(0, float("nan"))}
    nl = {("sparse", "single"): null(0.0456), ("medium", "single"): null(0.0177)}
    tab = T.tab_null(rec, nl, TREES, BONES, configs={"single": "single ($K{=}32$)"})
    assert tab.df.loc[0, "trained_median_rel_err_pct"] == pytest.approx(1.8)
    assert tab.df.loc[0, "null_median_rel_err_pct"] == pytest.approx(4.56)
    assert tab.df.loc[0, "null_parts_trusted"] == 4 and tab.df.loc[0, "nearest_bone_gap_pct"] == pytest.approx(0.4)
    assert r"\textbf{1.80\%}" in tab.tex and r"\textbf{4.56\%}" not in tab.tex
    assert r"\textbf{1.77\%}" in tab.tex and "--" in tab.tex  # trained has no trusted part
    T.write_table(tab, tmp_path / "n.tex", tmp_path / "n.csv")
    csv = pd.read_csv(tmp_path / "n.csv")
    rows = tex_rows((tmp_path / "n.tex").read_text())
    cols = ["trained_parts_trusted", "trained_median_rel_err_pct", "trained_loglog_r2", "null_parts_trusted",
            "null_median_rel_err_pct", "null_loglog_r2", "nearest_bone_gap_pct"]
    np.testing.assert_allclose(rows[0][0], [round(v, 3) for v in csv.loc[0, cols]], atol=5e-3)
    assert np.isnan(csv.loc[1, "trained_median_rel_err_pct"])
    with pytest.raises(KeyError, match="dense"):
        T.tab_null(rec, nl, ["sparse", "dense"], BONES, configs={"single": "single ($K{=}32$)"})


def test_missing_model_names_the_cause():
    S = summaries()
    del S[("sparse", "mlp")]
    with pytest.raises(KeyError, match="mlp"):
        T.tab_psnr(S, TREES, BONES)


def test_tab_psnr_reference_row_is_separate_and_never_bold():
    S = summaries()
    for t in TREES:
        S[(t, "truth_motion")] = {"view": 40.0, "time": 40.0}  # above every method
    tab = T.tab_psnr(S, TREES, BONES, references=("truth_motion",))
    assert list(tab.df.model)[-1] == T.label("truth_motion") and tab.df.reference.iloc[-1]
    assert r"\textbf{40.00}" not in tab.tex and r"\emph{True motion" in tab.tex
    assert tab.tex.count(r"\textbf{") == 2 * len(TREES)  # still one bold per column, a method


def test_tab_fit_fraction_of_the_ceiling():
    models = ("static", "mlp", "ours")
    rows = {}
    for t in TREES:
        for m, fit in zip((*models, "truth_motion"), (20.0, 22.0, 26.0, 30.0)):
            rows[(t, m)] = {"fit": fit, "heldout": fit - 0.5, "view": 21.0, "time": 21.5,
                            "train_s": 12.0}
    tab = T.tab_fit(rows, TREES, BONES, models, "truth_motion")
    frac = dict(zip(tab.df.model[tab.df.tree == "sparse"], tab.df.ceiling_frac))
    # (model - static) / (ceiling - static): 0, 2/10, 6/10, 1
    assert frac == pytest.approx({"static": 0.0, "mlp": 0.2, "ours": 0.6, "truth_motion": 1.0})
    assert "60\\%" in tab.tex and "20\\%" in tab.tex


def test_fit_row_splits_trained_and_held_out_frames(tmp_path):
    from physgs.evaluate.splits import EvalResult
    from physgs.report.build import fit_row

    n_train, n_tail = 30, 5
    cam = np.full((3, n_train + n_tail), 5.0)
    cam[0, :n_train] = 10.0
    cam[0, 9:n_train:10] = 20.0  # frames 9, 19, 29: the held-out ones (every 10th)
    ev = EvalResult(camera_psnr=cam, centroid_err=np.zeros_like(cam), view_psnr=np.full((2, 3), 7.0),
                    conditions=np.array(COND), heldout_azimuths_deg=np.array([-5.0, 5.0]),
                    heldout_frame_idx=np.array([0, 10, 20]), n_train=n_train, n_tail=n_tail)
    ev.save(tmp_path / "e.npz")
    pd.DataFrame({"seconds": [1.0, 2.0, 42.5]}).to_csv(tmp_path / "l.csv", index=False)
    r = fit_row(tmp_path / "e.npz", tmp_path / "l.csv", n_train, 10)
    assert r["fit"] == pytest.approx(10.0) and r["heldout"] == pytest.approx(20.0)
    assert r["train_s"] == 42.5 and r["view"] == pytest.approx(7.0)
