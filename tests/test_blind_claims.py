"""The forcing-free methods' ledger claims follow the direction of their values."""

from __future__ import annotations

import pandas as pd
import pytest

from physgs.report import claims
from roles import ROLES


BLIND = (
    "anemometer_needed",
    "oma_beats_null",
    "oma_recovers_zeta",
    "oma_frequency_interval_covers",
    "oma_damping_interval_covers",
)


def _blind_claims(null, damping, trees):
    """The forcing-free methods' claims of the ledger measured on tab_recovery (and
    tab_damping)."""
    tabs = {"tab_recovery": null, **({"tab_damping": damping} if damping is not None else {})}
    return [
        (c, v)
        for c, v in claims.measure(tabs, {}, trees, roles=ROLES)
        if set(BLIND) & set(c.id.split("/"))
    ]


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
        for c, v in _blind_claims(_null(ours, blind, oma, [4.0] * 3), _damping(dz), ["sparse"])
    }
    assert got["anemometer_needed/sparse"] == anem
    assert got["oma_beats_null/sparse"] == beats
    assert got["oma_recovers_zeta/sparse"] == zeta


def test_no_rows_no_claims():
    df = _null([2.0], [3.0], [2.0], [4.0])
    df = df[df["method"] == "ours"]
    assert _blind_claims(df, None, ["sparse"]) == []


def test_every_blind_prior_is_paired_with_a_prior_that_reads_the_wind():
    from physgs.models.registry import BLIND_PRIORS, MODELS, spec_of

    assert {m: spec_of(m).blind_of for m in BLIND_PRIORS} == {
        "ours_blind": "ours",
        "ours_chain_blind": "ours_chain",
    }
    for m in BLIND_PRIORS:
        wind = MODELS[spec_of(m).blind_of]
        assert wind.role == "prior" and wind.forcing == "wind", m


def test_each_blind_prior_gets_its_anemometer_claim_against_its_counterpart():
    """tab_recovery rows of two winds' priors and their forcing-free variants: each variant's
    claim is its error minus its own counterpart's, ours' under the old id, the chain's under
    its prefix (the catalogue's prefix convention)."""
    err = {  # median omega error (%) per seed
        "ours": [2.0, 2.2, 2.4],
        "ours_chain": [1.0, 1.1, 1.2],
        "ours_blind": [3.0, 3.3, 3.6],
        "ours_chain_blind": [0.5, 0.6, 0.7],
    }
    null = pd.DataFrame(
        [
            dict(
                seed=s,
                tree="sparse",
                config="single",
                method=m,
                trained_median_rel_err_pct=v[s],
                null_median_rel_err_pct=5.0,
            )
            for s in range(3)
            for m, v in err.items()
        ]
    )
    got = {c.id: (c, v) for c, v in _blind_claims(null, None, ["sparse"])}
    ours, v_ours = got["anemometer_needed/sparse"]
    chain, v_chain = got["ours_chain/anemometer_needed/sparse"]
    # by hand: 3.0 - 2.0, 3.3 - 2.2, 3.6 - 2.4; 0.5 - 1.0, 0.6 - 1.1, 0.7 - 1.2
    assert v_ours == pytest.approx([1.0, 1.1, 1.2])
    assert v_chain == pytest.approx([-0.5, -0.5, -0.5])
    assert claims.verdict(ours, v_ours) == "holds"
    assert claims.verdict(chain, v_chain) == "fails"
    assert "ours_chain_blind - ours_chain" in chain.source and "ours_blind - ours" in ours.source
    # a blind prior without its rows in the table has no claim
    alone = _blind_claims(null[null.method != "ours_chain_blind"], None, ["sparse"])
    assert [c.id for c, _ in alone] == ["anemometer_needed/sparse"]


@pytest.mark.parametrize(
    "cover, want", [([0.95, 0.97, 0.96], "holds"), ([0.5, 0.55, 0.52], "fails")]
)
def test_interval_claims_read_the_damping_testbeds_coverage(cover, want):
    """This project's interval claims read tab_damping's coverage cells of the damping testbed
    (the faithful testbed's, opposite, are ignored) and are marked as not the paper's."""
    df = _damping([-9.0, -8.5, -9.5])
    df["omega_interval_cover"] = [
        1 - c if tb == "faithful" else c
        for c, tb in zip([c for c in cover for _ in range(2)], df["testbed"])
    ]
    df["zeta_interval_cover"] = df["omega_interval_cover"]
    got = {
        c.id: (c, claims.verdict(c, v))
        for c, v in _blind_claims(_null([2.0] * 3, [3.0] * 3, [2.0] * 3, [4.0] * 3), df, ["sparse"])
    }
    for q in ("frequency", "damping"):
        c, v = got[f"oma_{q}_interval_covers/sparse"]
        assert v == want and "this project" in c.paper and c.threshold == 0.8
