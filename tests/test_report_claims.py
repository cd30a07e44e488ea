"""The claims ledger: verdicts from seed intervals, and claims measured from table CSVs."""

import numpy as np
import pandas as pd
import pytest

from physgs.report import claims as C

CLAIM = C.Claim("x", "x is positive", "--", "--", 0.0, ">", "dB")


def test_interval_is_students_t_on_the_mean():
    v = [1.0, 2.0, 3.0, 4.0, 5.0]
    m, sd, lo, hi = C.interval(v)
    # t_{0.975, 4} = 2.7764 (tables); sd = sqrt(2.5)
    half = 2.7764 * np.sqrt(2.5) / np.sqrt(5)
    assert m == 3.0 and sd == pytest.approx(np.sqrt(2.5))
    assert (lo, hi) == (pytest.approx(3 - half, abs=1e-3), pytest.approx(3 + half, abs=1e-3))


@pytest.mark.parametrize(
    "values, want",
    [
        ([1.0, 1.2, 0.9], "holds"),  # interval above 0
        ([-1.0, -1.2, -0.9], "fails"),  # interval below 0
        ([1.0, -0.8, 0.5], "undecided"),  # interval straddles 0
    ],
)
def test_verdict_from_the_interval(values, want):
    assert C.verdict(CLAIM, values) == want


def test_one_seed_is_undecided_but_says_where_the_point_falls():
    assert C.verdict(CLAIM, [0.4]) == "undecided: one seed (point estimate on the claim)"
    assert C.verdict(CLAIM, [-0.4]).endswith("against the claim)")
    fixed = C.Claim("g", "gap", "--", "--", 0.25, "<", "fraction", needs_variance=False)
    assert C.verdict(fixed, [0.01]) == "holds" and C.verdict(fixed, [0.5]) == "fails"


def _tables(seeds=(0,)):
    models = ["static", "mlp", "mlp_wind", "d3dgs", "d3dgs_wind", "ours"]
    psnr, transfer, margin, null, testbed, fit = [], [], [], [], [], []
    for s in seeds:
        for t in ("sparse", "medium"):
            for m in models:  # the wind-blind MLP at 30% of the ceiling's gain, the rest at 60%
                fit.append(
                    {
                        "seed": s,
                        "tree": t,
                        "model": m,
                        "ceiling_frac": 0.3 if m == "mlp" else 0.6 + 0.01 * s,
                    }
                )
        for m in models:
            r = {"seed": s, "model": C.LABELS[m]}
            for t in ("sparse", "medium"):
                # learned fields 1 dB below static beyond the window, ours 2 dB above it
                r[f"{t}_time"] = 20.0 + {"static": 0.0, "ours": 2.0}.get(m, -1.0) + 0.01 * s
                r[f"{t}_view"] = 22.0 + {"static": 0.0, "ours": 0.5}.get(m, 1.0)
            psnr.append(r)
        for t in ("sparse", "medium"):
            for c in (0.84, 0.71):
                transfer.append(
                    {
                        "seed": s,
                        "split": "beyond",
                        "tree": t,
                        "condition": c,
                        "static": 20.0,
                        "mlp": 19.0,
                        "mlp_wind": 19.5,
                        "d3dgs": 18.0,
                        "d3dgs_wind": 19.2,
                        "ours": 21.0,
                    }
                )
            margin.append(
                {
                    "seed": s,
                    "tree": t,
                    "margin_v0": -1.0,
                    "margin_0.84v0": 0.0,
                    "margin_0.71v0": 1.0 + 0.1 * s,
                }
            )
            null.append(
                {
                    "seed": s,
                    "tree": t,
                    "config": "joint32",
                    "trained_median_rel_err_pct": 2.0,
                    "null_median_rel_err_pct": 5.0 if t == "sparse" else 2.1,
                }
            )
            testbed.append({"tree": t, "nearest_bone_gap_pct": 5.45 if t == "sparse" else 0.24})
    return {
        "tab_psnr": pd.DataFrame(psnr),
        "tab_transfer": pd.DataFrame(transfer),
        "tab_margin": pd.DataFrame(margin),
        "tab_null": pd.DataFrame(null),
        "tab_testbed": pd.DataFrame(testbed),
        "tab_fit": pd.DataFrame(fit),
    }


def test_claims_measured_from_the_tables():
    damping = {"sparse": [{"median_zeta": 0.12, "zeta_true": 0.08, "loglog_exponent": 0.1}]}
    df = C.ledger(C.measure(_tables(seeds=(0, 1, 2)), damping, ["sparse", "medium"]))
    v = df.set_index("id")
    assert v.loc["baselines_below_static_beyond/sparse", "measured"] == pytest.approx(-1.0)
    assert v.loc["baselines_below_static_beyond/sparse", "verdict"] == "holds"
    assert v.loc["ours_above_static_beyond/medium", "measured"] == pytest.approx(2.0)
    assert v.loc["ours_behind_on_views/sparse", "measured"] == pytest.approx(-0.5)
    assert v.loc["null_loses/sparse", "measured"] == pytest.approx(2.5)
    assert v.loc["null_factor/sparse", "verdict"] == "fails"  # exactly 2.5 is not above 2.5
    assert v.loc["null_matches/medium", "measured"] == pytest.approx(-0.1)
    assert v.loc["nearest_bone_gap/sparse", "verdict"] == "holds"  # 5.45 vs the paper's 5.40
    assert v.loc["nearest_bone_gap/medium", "verdict"] == "fails"  # 0.24 vs 0.40
    assert v.loc["damping_not_recovered/sparse", "measured"] == pytest.approx(0.5)
    assert v.loc["transfer_ours_ahead/sparse/0.84", "measured"] == pytest.approx(1.5)
    assert v.loc["transfer_baselines_below_static/medium/0.71", "measured"] == pytest.approx(-0.5)
    assert v.loc["margin_grows/sparse", "measured"] == pytest.approx(2.1)
    assert v.loc["fits_window/medium/mlp", "verdict"] == "fails"
    assert v.loc["fits_window/medium/d3dgs_wind", "measured"] == pytest.approx(0.61)
    assert v.loc["fits_window/sparse/ours", "verdict"] == "holds"
    assert (
        v["seeds"].drop(
            [
                "nearest_bone_gap/sparse",
                "nearest_bone_gap/medium",
                "damping_not_recovered/sparse",
                "decay_rate_flat/sparse",
            ]
        )
        == 3
    ).all()
    md = C.ledger_markdown(df, {"profile": "default"})
    assert "| **holds** |" in md and "profile=default" in md


def test_a_single_seed_table_gives_one_seed_verdicts():
    t = {k: d.drop(columns=["seed"], errors="ignore") for k, d in _tables().items()}
    df = C.ledger(C.measure(t, {}, ["sparse"]))
    needs = df[~df["id"].str.startswith("nearest_bone_gap")]
    assert needs["verdict"].str.startswith("undecided: one seed").all()


def test_a_partial_run_gives_a_partial_ledger():
    full_tables = _tables(seeds=(0, 1, 2))
    full = C.ledger(C.measure(full_tables, {}, ["sparse", "medium"])).set_index("id")
    part = C.ledger(C.measure({"tab_null": full_tables["tab_null"]}, {}, ["sparse", "medium"]))
    part = part.set_index("id")
    measured = part[part["seeds"] > 0]
    # what tab_null holds is measured exactly as in the whole ledger
    assert sorted(measured.index) == [
        "null_factor/sparse",
        "null_loses/sparse",
        "null_matches/medium",
    ]
    for i in measured.index:
        assert measured.loc[i, "verdict"] == full.loc[i, "verdict"]
        assert measured.loc[i, "measured"] == pytest.approx(full.loc[i, "measured"])
    # the rest is listed, not measured; the per-wind transfer rows need their table to exist
    rest = part.drop(measured.index)
    assert (rest["verdict"] == "undecided: not measured").all()
    assert {
        "fits_window/medium/mlp",
        "margin_grows/sparse",
        "ours_above_static_beyond/medium",
    } <= set(rest.index)
    assert not any(i.startswith("transfer_") for i in part.index)
    assert set(part.index) <= set(full.index)
