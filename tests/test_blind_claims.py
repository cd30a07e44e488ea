"""The forcing-free methods' ledger claims follow the direction of their values."""

from __future__ import annotations

import pandas as pd
import pytest

from physgs.report import claims


def _null(ours, blind, oma, null_oma):
    rows = []
    for s, (o, b, m, n) in enumerate(zip(ours, blind, oma, null_oma)):
        for method, tr, nu in (("ours", o, 5.0), ("ours_blind", b, 5.0), ("oma", m, n)):
            rows.append(
                dict(
                    seed=s,
                    tree="sparse",
                    config="single",
                    method=method,
                    K=32,
                    trained_median_rel_err_pct=tr,
                    null_median_rel_err_pct=nu,
                )
            )
    return pd.DataFrame(rows)


def _damping(diff):
    """tab_damping's rows: the damping testbed's ``diff``, the faithful one's the opposite (its
    rows come first, as in the table: the claim reads the damping testbed's)."""
    return pd.DataFrame(
        [
            dict(
                seed=s,
                tree="sparse",
                testbed=tb,
                config="single",
                method="oma",
                trained_minus_null_pp=d if tb == "damping" else -d,
            )
            for s, d in enumerate(diff)
            for tb in ("faithful", "damping")
        ]
    )


@pytest.mark.parametrize(
    "blind, oma, dz, anem, beats, zeta",
    [
        ([3.0, 3.2, 3.1], [2.0, 2.1, 2.2], [-9.0, -8.5, -9.5], "holds", "holds", "holds"),
        ([1.0, 1.1, 1.2], [8.0, 8.2, 8.4], [4.0, 5.0, 4.5], "fails", "fails", "fails"),
    ],
)
def test_blind_claims_follow_the_values(blind, oma, dz, anem, beats, zeta):
    ours = [2.0, 2.1, 2.05]
    got = {
        c.id: claims.verdict(c, v)
        for c, v in claims._blind_claims(
            _null(ours, blind, oma, [4.0] * 3), _damping(dz), ["sparse"]
        )
    }
    assert got["anemometer_needed/sparse"] == anem
    assert got["oma_beats_null/sparse"] == beats
    assert got["oma_recovers_zeta/sparse"] == zeta


def test_no_rows_no_claims():
    df = _null([2.0], [3.0], [2.0], [4.0])
    df = df[df["method"] == "ours"]
    assert claims._blind_claims(df, None, ["sparse"]) == []
