"""tab_damping from recovery records: per-seed rows, paired trained - null, round trips."""

import dataclasses

import numpy as np
import pandas as pd
import pytest

from physgs.recovery.damping import damping_summary
from physgs.recovery.damping_scores import DampingNull, DampingScores, damping_null, damping_scores
from physgs.recovery.matcher import MatchResult
from physgs.recovery.record import RecoveryRecord, load_recovery, save_recovery
from physgs.report.damping import tab_damping
from physgs.report.recovery import method_rows
from physgs.report.tables import write_table

CONFIGS = {"single": "single", "joint32": "joint"}


def ours(per_seed, configs=CONFIGS):
    """tab_damping's methods holding ours' rows alone."""
    return {"ours": method_rows("ours", configs, per_seed, damping=True)}


def _record(zeta_hat, zeta_bones, seed):
    """A 4-part record whose parts match bones 0..3, all trusted, with real damping scores."""
    K = len(zeta_hat)
    omega = np.array([2.0, 3.0, 5.0, 8.0])
    m = MatchResult(
        np.arange(K), np.ones(K), np.ones(K, bool), omega, omega, np.zeros(K), K, K, 0.0, 1.0
    )
    rec = RecoveryRecord(m, damping_summary(omega, np.asarray(zeta_hat), 0.08))
    return dataclasses.replace(
        rec,
        damping_scores=damping_scores(m.bone, m.trusted, zeta_hat, omega, zeta_bones, omega),
        damping_null=damping_null(
            m.bone, m.trusted, omega, zeta_bones, omega, [0.03, 0.2], seed=seed
        ),
    )


def _data(n_seeds):
    zb = np.array([0.03, 0.06, 0.1, 0.2])
    out = {}
    for s in range(n_seeds):
        good = zb * (1 + 0.02 * (s + 1))  # recovered to 2-6%
        flat = 0.1 / np.array([2.0, 3.0, 5.0, 8.0]) * (1 + 0.01 * s)  # a flat decay rate
        out[s] = {
            ("sparse", v, c): _record(good if v == "damping" else flat, zb, s)
            for v in ("faithful", "damping")
            for c in CONFIGS
        }
    return out


def test_rows_are_per_seed_and_match_the_scores(tmp_path):
    data = _data(3)
    tab = tab_damping(ours(data), ["sparse"], {"sparse": 22})
    assert len(tab.df) == 3 * 2 * 2 and list(tab.df.seed.unique()) == [0, 1, 2]
    d = tab.df[(tab.df.testbed == "damping") & (tab.df.config == "single")]
    np.testing.assert_allclose(d.rel_err_pct, [2.0, 4.0, 6.0], atol=1e-9)
    np.testing.assert_allclose(d.log_corr, 1.0, atol=1e-9)  # exact ranking
    np.testing.assert_allclose(d.gamma_exponent, d.gamma_exponent_true, atol=1e-9)
    f = tab.df[(tab.df.testbed == "faithful") & (tab.df.config == "single")]
    np.testing.assert_allclose(f.gamma_exponent, 0.0, atol=1e-9)  # gamma = 0.1 for every part
    null = np.array(
        [
            data[s][("sparse", "damping", "single")].damping_null.median_median_rel_err
            for s in range(3)
        ]
    )
    np.testing.assert_allclose(d.trained_minus_null_pp, 100 * (d.rel_err_pct / 100 - null))
    assert r"\textbf{$" in tab.tex  # the damping model beats chance on every seed: decided
    write_table(tab, tmp_path / "d.tex", tmp_path / "d.csv")
    assert len(pd.read_csv(tmp_path / "d.csv")) == len(tab.df)


def test_a_record_without_damping_scores_is_named():
    data = _data(1)
    data[0][("sparse", "damping", "joint32")] = dataclasses.replace(
        data[0][("sparse", "damping", "joint32")], damping_scores=None
    )
    with pytest.raises(ValueError, match="sparse/damping/joint32"):
        tab_damping(ours(data), ["sparse"], {"sparse": 22})


def test_recovery_record_round_trips_its_damping_scores(tmp_path):
    rec = _data(1)[0][("sparse", "damping", "single")]
    save_recovery(tmp_path / "r.json", rec)
    back = load_recovery(tmp_path / "r.json")
    assert isinstance(back.damping_scores, DampingScores) and isinstance(
        back.damping_null, DampingNull
    )
    assert back.damping_scores == rec.damping_scores
    np.testing.assert_array_equal(back.damping_null.zeta, rec.damping_null.zeta)
    plain = dataclasses.replace(rec, damping_scores=None, damping_null=None)
    save_recovery(tmp_path / "p.json", plain)
    assert load_recovery(tmp_path / "p.json").damping_scores is None
