"""The 2D-track control as a method of the pipeline: its config, its files, its rows in
tab_recovery / tab_damping, tab_tracks, its ledger claims, what its outputs read, and its rules' plan
(the tracker and the fit never read truth.npz)."""

from __future__ import annotations

import dataclasses
import re
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from physgs.models.families import OSCILLATOR_KEYS
from physgs.recovery.damping import damping_summary
from physgs.recovery.damping_scores import damping_null, damping_scores
from physgs.recovery.matcher import MatchResult
from physgs.recovery.null import NullResult
from physgs.recovery.record import RecoveryRecord, load_recovery
from physgs.report import build, claims, thresholds
from physgs.report import recovery as R
from physgs.report.damping import tab_damping
from physgs.report.tracks import tab_tracks
from physgs.tracks import settings as tsettings
from oracles import quick_config
from test_config import _refused
from test_report_tables import ours as ours_rows
from workflow_helpers import ROOT
from roles import ROLES

BONES = {"sparse": 22, "medium": 224}


# --- config ------------------------------------------------------------------------------------


def test_tracks_configs_must_be_configurations_of_ours():
    msg = _refused(lambda c: c["tracks"].update(configs=["single", "joint64"]))
    assert "tracks/configs/1" in msg and "joint64" in msg and "models/configs" in msg


def test_min_track_frames_longer_than_the_window_is_refused():
    msg = _refused(lambda c: c["tracks"].update(min_track_frames=400))
    assert "tracks/min_track_frames" in msg and "testbed/n_train = 300" in msg


@pytest.mark.parametrize(
    "edit, key",
    [
        (lambda c: c["tracks"]["tracker"].update(win_px=10), "tracks/tracker/win_px"),
        (lambda c: c["tracks"].update(K="all"), "tracks/K"),
        (lambda c: c["tracks"].update(K=0), "tracks/K"),
        (lambda c: c["tracks"]["tracker"].update(reference="next"), "tracks/tracker/reference"),
        (lambda c: c["tracks"].update(min_tracks=0), "tracks/min_tracks"),
    ],
)
def test_bad_tracks_values_are_refused_by_the_schema(edit, key):
    assert key in _refused(edit)


def test_fit_params_are_the_configurations_k_and_conditions_or_the_override():
    cfg = quick_config()  # quick: tracks/K = 2 for every configuration
    job = tsettings.fit_job(cfg, "joint32", seed=3)
    assert job["K"] == 2 and job["K_key"] == "tracks/K"
    assert job["conditions"] == list(range(len(cfg["testbed"]["conditions"])))
    assert job["seed"] == 3 and job["lr"] == cfg["train"]["lr"]["physics"]
    assert set(job["ours"]) == set(OSCILLATOR_KEYS)
    cfg["tracks"]["K"] = "same"
    job = tsettings.fit_job(cfg, "single", seed=0)
    assert job["K"] == cfg["models"]["configs"]["single"]["K"] and job["conditions"] == [0]
    assert job["K_key"] == "models/configs/single/K"
    with pytest.raises(ValueError, match="joint96"):  # quick fits single and joint32 only
        tsettings.fit_job(cfg, "joint96", seed=0)


def test_a_k_above_the_tracks_kept_stops_the_fit_naming_the_key():
    from physgs.tracks.run import fit_job
    from physgs.tracks.track import Tracks

    T = 40
    valid = np.zeros((5, T), bool)
    valid[:3] = True  # three tracks span the window, two last 10 frames (< min_track_frames)
    valid[3:, :10] = True
    xy = np.where(valid[..., None], 10.0, np.nan)
    tracks = Tracks(xy, valid, np.zeros(5, np.int64))
    job = tsettings.fit_job(quick_config(), "single", seed=0)
    job.update(K=4, K_key="models/configs/single/K")
    with pytest.raises(ValueError, match=r"models/configs/single/K = 4 parts exceeds the 3 tracks"):
        fit_job([tracks], SimpleNamespace(), job)


def test_a_min_track_frames_that_leaves_too_few_tracks_names_the_largest_that_works():
    """min_track_frames at the window's length keeps the 3 full tracks only: K = 4 cannot be
    made, and the refusal names tracks/min_track_frames with the 4th longest track's length (10),
    the largest value that keeps 4 tracks (checked: at 10 the fit goes past this check)."""
    from physgs.tracks.run import fit_job
    from physgs.tracks.track import Tracks

    T = 40
    valid = np.zeros((5, T), bool)
    valid[:3] = True
    valid[3:, :10] = True
    tracks = Tracks(np.where(valid[..., None], 10.0, np.nan), valid, np.zeros(5, np.int64))
    job = tsettings.fit_job(quick_config(), "single", seed=0)
    job.update(K=4, K_key="tracks/K", min_track_frames=T)
    with pytest.raises(ValueError, match=r"tracks/min_track_frames \(now 40\) to at most 10\b"):
        fit_job([tracks], SimpleNamespace(), job)
    job.update(min_track_frames=11)
    with pytest.raises(ValueError, match="at most 10"):
        fit_job([tracks], SimpleNamespace(), job)
    job.update(min_track_frames=10)  # past the check: it now needs the observed record
    with pytest.raises(AttributeError):
        fit_job([tracks], SimpleNamespace(), job)


def test_a_min_tracks_no_part_reaches_names_the_key_and_the_largest_that_works():
    from physgs.tracks.fit import FitSettings, fit_tracks
    from test_tracks import _synthetic

    tracks, wind, osc, _, _ = _synthetic()  # two parts of 6 tracks each
    s = dict(K=2, iterations=1, seed=0)
    with pytest.raises(ValueError) as e:
        fit_tracks([tracks], [0], wind, osc, FitSettings(**s, min_tracks=1000))
    msg = str(e.value)
    assert "tracks/min_tracks = 1000" in msg and "to at most 6" in msg, msg
    with pytest.raises(ValueError, match="at most 6"):
        fit_tracks([tracks], [0], wind, osc, FitSettings(**s, min_tracks=7))
    assert fit_tracks([tracks], [0], wind, osc, FitSettings(**s, min_tracks=6)).estimated.all()


def test_a_min_track_frames_that_leaves_no_part_enough_tracks_names_the_largest_that_works():
    """Part 0's six tracks last 240, 240, 240, 200, 200 and 200 frames, part 1's 100 each: at
    min_track_frames 201 three tracks are kept, and two parts of three tracks cannot give one
    3; at 200 six are kept, and two parts of six always give one at least 3: 200 is the largest
    value that works, whatever k-means does (checked: 200 fits)."""
    from physgs.tracks.fit import FitSettings, fit_tracks
    from physgs.tracks.track import Tracks
    from test_tracks import _synthetic

    tracks, wind, osc, _, _ = _synthetic()
    valid = tracks.valid.copy()
    for i, n in enumerate([240] * 3 + [200] * 3 + [100] * 6):
        valid[i, n:] = False
    cut = Tracks(np.where(valid[..., None], tracks.xy, np.nan), valid, tracks.start)
    s = dict(K=2, iterations=1, seed=0, min_tracks=3)
    for frames in (239, 201):
        with pytest.raises(ValueError, match=r"lower tracks/min_track_frames to at most 200$"):
            fit_tracks([cut], [0], wind, osc, FitSettings(**s, min_track_frames=frames))
    assert fit_tracks([cut], [0], wind, osc, FitSettings(**s, min_track_frames=200)).estimated.any()


def test_a_tracks_fit_pinned_at_its_bounds_stops_naming_the_rate():
    from physgs.tracks.fit import FitSettings, fit_tracks
    from test_tracks import _synthetic

    tracks, wind, osc, _, _ = _synthetic()
    with pytest.raises(ValueError, match=r"sits on a bound.*train\.lr\.physics \(now 1000"):
        fit_tracks([tracks], [0], wind, osc, FitSettings(K=2, iterations=20, lr=1e3))
    fit_tracks([tracks], [0], wind, osc, FitSettings(K=2, iterations=20))  # the default rate


# --- files -------------------------------------------------------------------------------------


def test_tracks_and_fit_files_round_trip(tmp_path):
    from physgs.tracks.fit import FitSettings, fit_tracks
    from physgs.tracks.store import load_fit, load_tracks, save_fit, save_tracks
    from test_tracks import _synthetic

    tracks, wind, osc, _, _ = _synthetic()
    save_tracks(tmp_path / "c0.npz", tracks, 0)
    back, c = load_tracks(tmp_path / "c0.npz")
    assert c == 0 and np.array_equal(back.xy, tracks.xy, equal_nan=True)
    assert np.array_equal(back.valid, tracks.valid) and np.array_equal(back.start, tracks.start)
    fit = fit_tracks([tracks], [0], wind, osc, FitSettings(K=2, iterations=3))
    save_fit(tmp_path / "fit.npz", fit, osc, "models/configs/single/K", 3)
    f2, o2, meta = load_fit(tmp_path / "fit.npz")
    assert o2 == osc and meta == {"K_key": "models/configs/single/K", "min_tracks": 3}
    for name in ("omega", "zeta", "estimated", "n_tracks", "loss_px2"):
        np.testing.assert_array_equal(getattr(f2, name), getattr(fit, name))
    np.testing.assert_array_equal(f2.d[0], fit.d[0])
    assert f2.conditions == [0] and f2.seconds == fit.seconds


def test_the_recovery_record_counts_parts_without_an_estimate(tmp_path):
    """Six tracks in part 0, two in part 1 (< min_tracks = 3): part 1 has no estimate, is never
    trusted, and the record says so with both counts; ours' loader reads the same file."""
    from physgs.tracks.fit import FitSettings, fit_tracks
    from physgs.tracks.recover import load_tracks_block, recover_tracks, save_tracks_recovery
    from physgs.tracks.track import Tracks
    from test_tracks import _synthetic

    tracks, wind, osc, truth_om, _ = _synthetic(n_per_part=6)
    keep = np.r_[np.arange(6), 6, 7]
    few = Tracks(tracks.xy[keep], tracks.valid[keep], tracks.start[keep])
    fit = fit_tracks([few], [0], wind, osc, FitSettings(K=2, iterations=5))
    L, T = osc.lead_in, few.xy.shape[1]
    theta = np.zeros((1, L + T, 2))  # two bones swinging like the two parts' true oscillators
    from test_tracks import _simulate

    for b, (om, ze) in enumerate(truth_om):
        theta[0, :, b] = _simulate(om, ze, wind[0, : L + T], wind[0].mean(), 1 / 24, 1.0)
    truth = SimpleNamespace(
        omega=np.array([om for om, _ in truth_om]), zeta=np.array([0.06, 0.12]), theta=theta
    )
    observed = SimpleNamespace(wind=wind[:, : L + T], lead_in_frames=L, n_train=T)
    rec = recover_tracks(fit, osc, observed, truth, min_tracks=3)
    save_tracks_recovery(tmp_path / "r.json", rec)
    block = load_tracks_block(tmp_path / "r.json")
    assert block["n_tracks_per_part"] == [6, 2] and block["min_tracks"] == 3
    assert block["no_estimate"] == [1] and block["n_no_estimate"] == 1
    back = load_recovery(tmp_path / "r.json")
    assert back.match.n_parts == 2 and not back.match.trusted[1]


# --- tables ------------------------------------------------------------------------------------


def _record(err, n_trusted=3, K=4):
    rel = np.full(K, np.nan)
    rel[:n_trusted] = err
    trusted = np.arange(K) < n_trusted
    m = MatchResult(
        np.arange(K), np.ones(K), trusted, np.ones(K), np.ones(K), rel, n_trusted, K, err, 0.9
    )
    return RecoveryRecord(m, damping_summary(np.ones(K), np.full(K, 0.1), 0.08), 0, 2, err)


def _null(err, K=4):
    return NullResult(
        np.array([3] * 8), np.full(8, err), np.full(8, 0.5), np.ones((1, 8)), K, 0.01, 0
    )


def test_tab_recovery_adds_the_tracks_rows_after_ours_and_leaves_ours_rows_as_they_were():
    cfg = {"single": "single", "joint32": "joint"}
    rec = {s: {(t, c): _record(0.02 + 0.001 * s) for t in BONES for c in cfg} for s in (0, 1)}
    nl = {s: {(t, c): _null(0.05) for t in BONES for c in cfg} for s in (0, 1)}
    tracks = {
        s: {(t, "joint32"): (_record(0.03 + 0.002 * s, K=2), _null(0.06, K=2)) for t in BONES}
        for s in (0, 1)
    }
    plain = R.recovery_table("tab_null", ours_rows(rec, nl, cfg), list(BONES), BONES).df
    both = R.recovery_table(
        "tab_recovery",
        {**ours_rows(rec, nl, cfg), "tracks": R.method_rows("tracks", {"joint32": "j2"}, tracks)},
        list(BONES),
        BONES,
    )
    df = both.df
    ours = df[df.method == "ours"].drop(columns="method").reset_index(drop=True)
    pd.testing.assert_frame_equal(ours, plain.drop(columns="method"))
    mine = df[df.method == "tracks"]
    assert list(mine.config) == ["joint32"] * 4 and set(mine.K) == {2}
    np.testing.assert_allclose(mine.trained_median_rel_err_pct, [3.0, 3.0, 3.2, 3.2])
    np.testing.assert_allclose(mine.null_median_rel_err_pct, 6.0)
    # each tree's rows together, the tracks row last, in the .tex as in the CSV
    first = df[df.seed == 0]
    assert list(zip(first.tree, first.method)) == [
        ("sparse", "ours"),
        ("sparse", "ours"),
        ("sparse", "tracks"),
        ("medium", "ours"),
        ("medium", "ours"),
        ("medium", "tracks"),
    ]
    assert r"\emph{2D tracks}, j2" in both.tex
    bad = {0: {(t, "joint32"): (_record(0.03, K=2), _null(0.06, K=4)) for t in BONES}}
    with pytest.raises(ValueError, match="K=4 but the model has K=2"):
        R.recovery_table(
            "tab_recovery",
            {
                **ours_rows({0: rec[0]}, {0: nl[0]}, cfg),
                "tracks": R.method_rows("tracks", {"joint32": "j"}, bad),
            },
            list(BONES),
            BONES,
        )


def _damped(zeta_hat, seed):
    zb = np.array([0.03, 0.06, 0.1, 0.2])
    om = np.array([2.0, 3.0, 5.0, 8.0])
    m = MatchResult(np.arange(4), np.ones(4), np.ones(4, bool), om, om, np.zeros(4), 4, 4, 0.0, 1.0)
    rec = RecoveryRecord(m, damping_summary(om, np.asarray(zeta_hat), 0.08))
    return dataclasses.replace(
        rec,
        damping_scores=damping_scores(m.bone, m.trusted, zeta_hat, om, zb, om),
        damping_null=damping_null(m.bone, m.trusted, om, zb, om, [0.03, 0.2], seed=seed),
    )


def test_tab_damping_adds_the_tracks_rows_with_their_own_scores():
    zb = np.array([0.03, 0.06, 0.1, 0.2])
    ours = {
        s: {("sparse", v, c): _damped(zb * 1.1, s) for v in ("faithful", "damping") for c in "ab"}
        for s in (0, 1)
    }
    mine = {
        s: {("sparse", v, "a"): _damped(zb * 1.5, s) for v in ("faithful", "damping")}
        for s in (0, 1)
    }
    methods = {
        "ours": R.method_rows("ours", {"a": "A", "b": "B"}, ours, damping=True),
        "tracks": R.method_rows("tracks", {"a": "A"}, mine, damping=True),
    }
    tab = tab_damping(methods, ["sparse"], {"sparse": 22})
    df = tab.df
    assert len(df) == 2 * 2 * 3 and set(df.method) == {"ours", "tracks"}
    np.testing.assert_allclose(df[df.method == "ours"].rel_err_pct, 10.0)
    np.testing.assert_allclose(df[df.method == "tracks"].rel_err_pct, 50.0)
    assert list(df[df.seed == 0].method) == ["ours", "ours", "tracks"] * 2
    assert r"\multirow[c]{6}{*}" in tab.tex and r"\emph{2D tracks}, A" in tab.tex
    none = {
        s: {k: dataclasses.replace(r, damping_scores=None) for k, r in d.items()}
        for s, d in mine.items()
    }
    with pytest.raises(ValueError, match="tracks control"):
        tab_damping(
            {**methods, "tracks": R.method_rows("tracks", {"a": "A"}, none, damping=True)},
            ["sparse"],
            {"sparse": 22},
        )


def _scores(tail, tail_ours, n=40, kept=0.5):
    """An evaluation record as tracks_evaluate writes it (three conditions)."""
    mot = lambda a, b: {  # noqa: E731
        "tracks": {
            "motion_median_px": a,
            "static_median_px": 0.9,
            "median_px": a + 1,
            "n_tracks": 7,
        },
        "ours": {"motion_median_px": b, "static_median_px": 0.9, "median_px": b + 1, "n_tracks": 7},
    }
    return {
        "tracker": {
            "median_px": 0.8,
            "p90_px": 1.6,
            "disp_median_px": 0.3,
            "disp_p90_px": 0.7,
            "share_kept": kept,
            "n_tracks": n,
            "n_seed0": 10,
            "mean_length": 30.0,
            "median_start_px": 0.5,
        },
        "fit": {
            "K": 4,
            "seconds": 12.5,
            "loop_seconds": 10.0,
            "rms_px": 0.2,
            "n_fitted": 7,
            "n_estimated": 3,
        },
        "tail": mot(tail, tail_ours),
        "wind1": mot(0.41, 0.52),
        "wind2": mot(0.43, 0.54),
        "ours_train_s": 321.0,
    }


def test_tab_tracks_gives_the_best_learned_field_per_seed():
    cases = ("tail", "wind1", "wind2")
    per_seed = {}
    for s, (mlp, d3) in enumerate([(0.7, 0.6), (0.5, 0.8)]):
        rec = _scores(0.3, 0.5)
        for case in cases:
            rec[case]["fields"] = {
                "mlp": {"motion_median_px": mlp + (case != "tail")},
                "d3dgs": {"motion_median_px": d3 + (case != "tail")},
            }
        per_seed[s] = {("sparse", "single"): rec, ("sparse", "joint32"): _scores(0.3, 0.5)}
    configs = {
        "single": {"label": "s", "conditions": "train"},
        "joint32": {"label": "j", "conditions": "all"},
    }
    tab = tab_tracks(per_seed, ["sparse"], {"sparse": 22}, configs, [1.0, 0.84, 0.71])
    one = tab.df[tab.df.config == "single"].set_index("seed")
    np.testing.assert_allclose(one.tail_field_mlp_px, [0.7, 0.5])
    np.testing.assert_allclose(one.tail_best_field_px, [0.6, 0.5])  # d3dgs at seed 0, mlp at 1
    np.testing.assert_allclose(one["wind_0.84v0_best_field_px"], [1.6, 1.5])
    # no field trained in the joint configuration: no value, '--' in the .tex
    assert tab.df[tab.df.config == "joint32"].tail_best_field_px.isna().all()
    assert "0.55 $\\pm$ 0.07" in tab.tex  # mean +- sd of the per-seed best, 0.6 and 0.5
    assert "Tracks & Ours & Field & Still" in tab.tex


def test_tab_tracks_rows_are_the_records_values():
    per_seed = {s: {("sparse", "single"): _scores(0.3 + 0.01 * s, 0.5)} for s in (0, 1)}
    tab = tab_tracks(
        per_seed,
        ["sparse"],
        {"sparse": 22},
        {"single": {"label": "s", "conditions": "train"}},
        [1.0, 0.84, 0.71],
    )
    df = tab.df
    assert list(df.seed) == [0, 1]
    np.testing.assert_allclose(df.tail_px, [0.3, 0.31])
    np.testing.assert_allclose(df.tail_ours_px, 0.5)
    np.testing.assert_allclose(df["wind_0.84v0_px"], 0.41)
    np.testing.assert_allclose(df["wind_0.71v0_ours_px"], 0.54)
    np.testing.assert_allclose(df["wind_0.71v0_static_px"], 0.9)
    assert (
        (df.track_p90_px == 1.6).all() and (df.share_kept == 0.5).all() and (df.fit_s == 12.5).all()
    )
    assert (df.parts_estimated == 3).all() and (df.K == 4).all() and (df.ours_train_s == 321).all()
    assert "0.30 $\\pm$ 0.01" in tab.tex and "40 (50\\%)" in tab.tex and "3/4" in tab.tex
    del per_seed[1][("sparse", "single")]["wind2"]
    with pytest.raises(KeyError, match="wind2"):
        tab_tracks(
            per_seed,
            ["sparse"],
            {"sparse": 22},
            {"single": {"label": "s", "conditions": "train"}},
            [1.0, 0.84, 0.71],
        )


# --- the ledger --------------------------------------------------------------------------------


def _null_csv(tracks_err, ours_err=2.0, null_err=5.0, tracks_k=32):
    rows = []
    for s, te in enumerate(tracks_err):
        for method, err, K in (("ours", ours_err + 0.01 * s, 32), ("tracks", te, tracks_k)):
            rows.append(
                {
                    "seed": s,
                    "tree": "sparse",
                    "config": "joint32",
                    "method": method,
                    "K": K,
                    "trained_median_rel_err_pct": err,
                    "null_median_rel_err_pct": null_err,
                }
            )
    return pd.DataFrame(rows)


def _tracks_csv(diffs):
    return pd.DataFrame(
        [
            {
                "seed": s,
                "tree": "sparse",
                "config": "single",
                "tail_px": 0.4 + d,
                "tail_ours_px": 0.4,
            }
            for s, d in enumerate(diffs)
        ]
    )


def _tracks_claims(null, tracks, trees):
    """The 2D-track control's claims of the ledger measured on these two tables (its recovery
    rows beside ours' in tab_recovery)."""
    measured = claims.measure({"tab_recovery": null, "tab_tracks": tracks}, {}, trees, roles=ROLES)
    return [(c, v) for c, v in measured if c.id.startswith("tracks_")]


@pytest.mark.parametrize(
    "tracks_err, tail, beats, match, extrap",
    [
        ([2.0, 2.1, 2.05], [-0.1, -0.12, -0.11], "holds", "holds", "holds"),
        ([8.0, 8.2, 8.1], [0.2, 0.21, 0.22], "fails", "fails", "fails"),
    ],
)
def test_tracks_claims_follow_the_paired_values(tracks_err, tail, beats, match, extrap):
    got = {
        c.id: (c, v)
        for c, v in _tracks_claims(_null_csv(tracks_err), _tracks_csv(tail), ["sparse"])
    }
    c, v = got["tracks_beats_null/sparse"]
    assert v == pytest.approx([5.0 / e for e in tracks_err]) and claims.verdict(c, v) == beats
    c, v = got["tracks_match_ours/sparse"]
    assert v == pytest.approx([e - (2.0 + 0.01 * s) for s, e in enumerate(tracks_err)])
    assert c.threshold == thresholds.NULL_MATCH_PP and claims.verdict(c, v) == match
    c, v = got["tracks_extrapolate_as_ours/sparse"]
    assert v == pytest.approx(tail) and claims.verdict(c, v) == extrap


def test_a_tracks_fit_at_another_k_is_not_compared_with_ours():
    got = {
        c.id: (c, v)
        for c, v in _tracks_claims(
            _null_csv([2.0, 2.0], tracks_k=2), _tracks_csv([0, 0]), ["sparse"]
        )
    }
    c, v = got["tracks_match_ours/sparse"]
    assert np.isnan(v).all() and claims.verdict(c, v) == "undecided: not measured"


def test_ours_claims_read_ours_rows_of_a_table_with_tracks_rows():
    """null_loses/sparse reads ours' row even where the tracks row comes first."""
    df = _null_csv([1.0, 1.0]).iloc[::-1]
    got = {c.id: v for c, v in claims.measure({"tab_null": df}, {}, ["sparse"], roles=ROLES)}
    # ours' errors 2.0, 2.01 against the null's 5.0 (the tracks' 1.0 would give 5.0)
    assert got["null_loses/sparse"] == pytest.approx([5.0 / 2.0, 5.0 / 2.01])


# --- what each output reads --------------------------------------------------------------------


def test_needs_of_the_tracks_outputs():
    def plan(configs, seeds, fields=()):
        return build.Plan(
            ["sparse"],
            {"single": {"K": 32}},
            seeds,
            recovery={"ours": {"single": 32}, **({"tracks": configs} if configs else {})},
            tracks_fields=fields,
        )

    assert build.needs("tab_tracks", plan({"single": 2, "joint32": 2}, [0, 1])) == [
        ("tracks_eval", "sparse", "single", 0),
        ("loss", "sparse", "ours", "single", 0),  # ours' training seconds beside the fit's
        ("tracks_eval", "sparse", "joint32", 0),
        ("loss", "sparse", "ours", "joint32", 0),
        ("tracks_eval", "sparse", "single", 1),
        ("loss", "sparse", "ours", "single", 1),
        ("tracks_eval", "sparse", "joint32", 1),
        ("loss", "sparse", "ours", "joint32", 1),
    ]
    assert build.needs("tab_tracks", plan({"single": 2}, [3], [("sparse", "single")]))[-1] == (
        "tracks_fields",
        "sparse",
        "single",
        3,
    )
    assert build.needs("fig_tracks", plan({"joint32": 2}, [5, 6])) == [
        ("observed", "sparse", 5),
        ("tracks", "sparse", 0, 5),
        ("tracks_fit", "sparse", "joint32", 5),
    ]
    null = build.needs("tab_recovery", plan({"single": 2}, [0]))
    assert ("recovery", "sparse", "tracks", "single", 0) in null
    assert ("null", "sparse", 2, 0) in null and ("null", "sparse", 32, 0) in null
    # tab_null is the paper's: ours and the null of its K, never the control's
    paper = build.needs("tab_null", plan({"single": 2}, [0]))
    assert not any("tracks" in n for n in paper) and ("null", "sparse", 2, 0) not in paper
    damp = build.needs(
        "tab_damping",
        build.Plan(
            ["sparse"],
            {"single": {"K": 32}, "joint32": {"K": 32}},
            [0],
            recovery={"ours": {"single": 32, "joint32": 32}, "tracks": {"joint32": 2}},
            damping_trees=["sparse"],
            damping_configs=["single", "joint32"],
        ),
    )
    assert ("recovery", "sparse_damping", "tracks", "joint32", 0) in damp
    assert not any(n[2] == "tracks" and n[3] == "single" for n in damp)
    assert ("table", "tab_tracks") in build.claims_needs(plan({"single": 2}, [0]))
    assert ("table", "tab_tracks") not in build.claims_needs(plan({}, [0]))
    # a run without the control builds neither of its outputs (fig_tracks: without parts)
    assert not build.in_report("tab_tracks", plan({}, [0]))
    assert build.needs("fig_tracks", plan({}, [0])) == [
        ("observed", "sparse", 0),
        ("tracks", "sparse", 0, 0),
    ]


def test_settings_of_the_tracks_outputs_are_narrow():
    cfg = quick_config()
    s = build.settings_for("tab_tracks", cfg)
    assert set(s["configs"]) == set(cfg["tracks"]["configs"])
    assert s["configs"]["single"]["label"] == "single ($K{=}2$)"  # the control's own K
    assert build.settings_for("tab_recovery", cfg)["methods"]["tracks"]["joint32"]["K"] == 2
    assert set(build.settings_for("tab_null", cfg)["methods"]) == {"ours"}
    assert build.settings_for("fig_tracks", cfg)["seeds"] == [cfg["seeds"][0]]
    assert "tracks" not in build.settings_for("tab_psnr", cfg)


# --- the plan ----------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def plan():
    """One quick dry run of tab_tracks, fig_tracks and tab_recovery from an empty results folder (a
    scratch copy of the workflow)."""
    import tempfile
    from pathlib import Path

    from workflow_helpers import workflow_copy

    with tempfile.TemporaryDirectory() as d:
        wd = workflow_copy(Path(d))
        r = subprocess.run(
            [
                sys.executable,
                "-m",
                "snakemake",
                "-n",
                "--cores",
                "1",
                "--config",
                "profile=quick",
                "--",
                "results/tables/tab_tracks.tex",
                "results/figures/fig_tracks.png",
                "results/tables/tab_recovery.tex",
            ],
            cwd=wd,
            capture_output=True,
            text=True,
            timeout=300,
        )
    assert r.returncode == 0, r.stderr[-2000:] + r.stdout[-2000:]
    return r.stdout


def _blocks(out, rule):
    return re.findall(rf"rule {rule}:\n((?:    .*\n)+)", out)


def test_the_tracker_and_the_fit_read_no_truth(plan):
    cfg = quick_config()
    n_cond = len(cfg["testbed"]["conditions"])
    tracks = _blocks(plan, "track")
    assert len(tracks) == len(cfg["trees"]) * n_cond  # joint32 fits every condition's tracks
    fits = _blocks(plan, "fit_tracks")
    # one job per tree and seed fits every configuration (they read the same files)
    assert len(fits) == len(cfg["trees"]) * len(cfg["seeds"])
    for b in fits:
        outputs = re.search(r"output: (.*)", b).group(1)
        assert all(f"fit_{c}.npz" in outputs for c in cfg["tracks"]["configs"]), outputs
    for b in tracks + fits:
        inputs = re.search(r"input: (.*)", b).group(1)
        assert "truth" not in inputs and "observed.npz" in inputs, inputs
    for b in fits:
        inputs = re.search(r"input: (.*)", b).group(1)
        assert re.search(r"results/tracks/\w+/c0\.npz", inputs), inputs
    evals = _blocks(plan, "tracks_evaluate")
    assert evals and all("truth.npz" in re.search(r"input: (.*)", b).group(1) for b in evals)
    # and in the rule file: only the evaluations name a truth-reading path or input function
    text = (ROOT / "workflow" / "rules" / "tracks.smk").read_text()
    rules = re.split(r"\n(?:rule|use rule) ", text)[1:]
    readers = [
        b.split(None, 1)[0].rstrip(":")
        for b in rules
        if re.search(r"TRUTH|truth_input|tracks_(evaluate|fields)_inputs|testbed_files", b)
    ]
    assert readers == ["tracks_evaluate", "tracks_fields"], readers
    common = (ROOT / "workflow" / "rules" / "common.smk").read_text()
    fit_inputs = common.split("def fit_tracks_inputs", 1)[1].split("\ndef ", 1)[0]
    assert not re.search(r"truth_input|testbed_files|TRUTH", fit_inputs)


def test_the_learned_fields_are_scored_beside_ours_where_they_are_trained(plan):
    cfg = quick_config()
    fields = cfg["tracks"]["fields"]
    assert fields and tsettings.fields_scored(cfg, "joint32", "sparse") == []
    assert tsettings.fields_scored(cfg, "single", "sparse") == fields
    assert tsettings.fields_scored(cfg, "single", "sparse_damping") == []  # no field trains there
    # the recovery tables never wait for a field: the fields are scored by a rule of their own
    for b in _blocks(plan, "tracks_evaluate"):
        inputs = re.search(r"input: (.*)", b).group(1)
        assert not re.search(r"/(mlp|d3dgs)\w*_\w+\.pt", inputs), inputs
    scored = _blocks(plan, "tracks_fields")
    assert scored and len(scored) == len(cfg["trees"])  # quick: one faithful tree, single only
    for b in scored:
        assert "fields_single.json" in re.search(r"output: (.*)", b).group(1)
        inputs = re.search(r"input: (.*)", b).group(1)
        for m in ("mlp", "mlp_wind", "d3dgs", "d3dgs_wind"):
            assert (f"/{m}_single.pt" in inputs) == (m in fields), (m, inputs)
    table = [b for b in _blocks(plan, "table") if "tab_tracks" in b][0]
    assert "fields_single.json" in table and "fields_joint32.json" not in table


def test_tab_recovery_pairs_the_tracks_rows_with_the_null_of_their_k(plan):
    table = [b for b in _blocks(plan, "table") if "tab_recovery" in b][0]
    assert "results/recovery/sparse/seed0/tracks_joint32.json" in table
    assert "results/recovery/sparse/seed0/null_K2.json" in table  # quick: tracks/K = 2
    assert "rule fit_tracks" in plan and "rule tracks_evaluate" in plan


def test_fig_tracks_draws_fitted_and_unfitted_tracks(tmp_path):
    from physgs.report.tracks import fig_tracks
    from physgs.tracks.track import Tracks

    valid = np.ones((3, 5), bool)
    valid[2, 3:] = False
    xy = np.cumsum(np.ones((3, 5, 2)), axis=1) + np.arange(3)[:, None, None] * 4
    tr = Tracks(np.where(valid[..., None], xy, np.nan), valid, np.zeros(3, np.int64))
    frame = np.full((16, 16, 3), 255, np.uint8)
    outs = [str(tmp_path / "f.png"), str(tmp_path / "f.pdf")]
    fig_tracks(
        {"a": frame, "b": frame},
        {"a": tr, "b": tr},
        {"a": np.array([0, 1, -1]), "b": None},
        ["a", "b"],
        outs,
        title="t",
    )
    assert all((tmp_path / f).stat().st_size > 1000 for f in ("f.png", "f.pdf"))
