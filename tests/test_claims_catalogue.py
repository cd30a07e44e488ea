"""The catalogue of claims: its entries are well formed, every count of claims keeps the
paper's apart from this project's, and docs/claims.md's list of claims is the catalogue's
(tools/claims_reference.py)."""

import subprocess
import sys
from pathlib import Path

import pytest

from physgs.report import catalogue
from physgs.report.catalogue import CATALOGUE, ClaimSpec, origin_of
from roles import ROLES

ROOT = Path(__file__).resolve().parents[1]


def test_the_committed_claims_page_is_the_catalogues():
    r = subprocess.run(
        [sys.executable, "tools/claims_reference.py", "--check"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr


def test_the_page_lists_every_family_with_its_origin_and_threshold():
    page = catalogue.markdown()
    rows = [ln for ln in page.splitlines() if ln.startswith("| `")]
    assert len(rows) == len(CATALOGUE)
    for spec, row in zip(CATALOGUE, rows):
        assert spec.family in row and row.endswith(f"| {spec.origin} |")
        assert f"`{spec.threshold.lstrip('-')}` = {spec.value:g}" in row


def test_kinds_by_id_and_the_page_marks_the_premises():
    """The fit bar and the testbed's gap are premises, whoever the id names; the rest findings."""
    assert catalogue.kind_of("fits_window/dense/ours_chain") == "premise"
    assert catalogue.kind_of("fits_window/sparse/mlp") == "premise"
    assert catalogue.kind_of("nearest_bone_gap/medium") == "premise"
    assert catalogue.kind_of("null_factor/sparse") == "finding"
    assert catalogue.kind_of("ours_chain/above_static_beyond/sparse") == "finding"
    assert "training window" in catalogue.undermines("fits_window/dense/mlp")
    assert catalogue.undermines("null_factor/sparse") == ""
    marked = {ln.split("`")[1] for ln in catalogue.markdown().splitlines() if "(premise)" in ln}
    assert marked == set(catalogue.PREMISES) == {"fits_window", "nearest_bone_gap"}


def test_a_spec_refuses_what_it_cannot_decide():
    base = CATALOGUE[0]
    kw = {f: getattr(base, f) for f in base.__dataclass_fields__}
    for bad in (
        {"side": ">="},
        {"origin": "both"},
        {"of": "fields"},
        {"threshold": "NOPE"},
        {"over": "every_leaf"},  # a name, not the scope itself
        {"read": "a_cell"},
    ):
        with pytest.raises(ValueError, match=base.family):
            ClaimSpec(**{**kw, **bad})
    with pytest.raises(TypeError):  # keyword fields only: an entry names what each value is
        ClaimSpec(*kw.values())


def test_origins_by_id():
    assert origin_of("null_factor/sparse") == "paper"
    assert origin_of("fits_window/dense/mlp_wind") == "paper"
    # a family of the paper, but about a model the paper did not train
    assert origin_of("fits_window/dense/ours_chain") == "project"
    assert origin_of("ours_chain/decay_rate_flat/sparse") == "project"
    assert origin_of("ours_chain/anemometer_needed/sparse") == "project"
    assert origin_of("coupling_lifts_sparse_fit") == "project"
    with pytest.raises(ValueError, match="no family"):
        origin_of("made_up/sparse")


def test_the_ledgers_tables_come_from_the_catalogue():
    assert set(catalogue.required_tables()) == {
        "tab_psnr",
        "tab_transfer",
        "tab_margin",
        "tab_null",
        "tab_recovery",
        "tab_testbed",
        "tab_fit",
    }
    assert set(catalogue.tables()) - set(catalogue.required_tables()) == {
        "tab_damping",
        "tab_parts",
        "tab_tracks",
    }
    assert catalogue.reads_recovery()
    fams = [f for f, _, _ in catalogue.headline(["ours_chain"])]
    assert fams[:2] == ["ours_above_static_beyond", "baselines_below_static_beyond"]
    assert "ours_chain/above_static_beyond" in fams


def test_a_new_family_is_one_entry(monkeypatch):
    """One more ClaimSpec (an existing scope and reader) reaches the ledger, its origin, the
    README's headline families, the tables the ledger reads and the claims page."""
    import pandas as pd

    from physgs.report import claims, record

    fits = next(s for s in CATALOGUE if s.family == "fits_window")
    new = ClaimSpec(
        family="fits_window_strictly", over=fits.over, table="tab_fit", read=fits.read,
        threshold="FIT_BAR", side=">", unit="fraction",
        text="{tree}: {fit_label} fits its window", source="tab_fit: ceiling fraction",
        paper="this project", origin="project", headline="every model fits its window",
        one_sided="a bar",
    )  # fmt: skip
    monkeypatch.setattr(catalogue, "CATALOGUE", (*CATALOGUE, new))
    monkeypatch.setattr(claims, "CATALOGUE", catalogue.CATALOGUE)
    fit = pd.DataFrame(
        [
            {"seed": s, "tree": "sparse", "model": m, "ceiling_frac": 0.8 + 0.01 * s}
            for s in range(3)
            for m in ("mlp", "mlp_wind", "d3dgs", "d3dgs_wind", "ours")
        ]
    )
    led = claims.ledger(claims.measure({"tab_fit": fit}, {}, ["sparse"], roles=ROLES)).set_index(
        "id"
    )
    row = led.loc["fits_window_strictly/sparse/mlp"]
    assert row["verdict"] == "holds" and row["origin"] == "project"
    assert origin_of("fits_window_strictly/sparse/mlp") == "project"
    assert ("fits_window_strictly", "every model fits its window", "project") in (
        catalogue.headline()
    )
    assert any(
        ln.startswith("- Every model fits its window")
        for ln in record.headline_lines(led.reset_index())
    )
    assert "`fits_window_strictly` (headline)" in catalogue.markdown()
    assert "tab_fit" in catalogue.required_tables()


def test_moving_a_family_to_another_table_is_its_table_field(monkeypatch):
    """The scopes read only the family's own table: the 2D-track control's rows read from a
    table of another name give the same claims when the entries name that table."""
    import dataclasses

    import pandas as pd

    from physgs.report import claims

    rows = pd.DataFrame(
        [
            dict(
                seed=s,
                tree="sparse",
                config="joint32",
                method=m,
                K=32,
                trained_median_rel_err_pct=e + 0.1 * s,
                null_median_rel_err_pct=5.0,
            )
            for s in range(3)
            for m, e in (("ours", 2.0), ("tracks", 1.5))
        ]
    )

    def tracks(tables):
        got = claims.ledger(claims.measure(tables, {}, ["sparse"], roles=ROLES)).set_index("id")
        return got.loc[["tracks_beats_null/sparse", "tracks_match_ours/sparse"]]

    before = tracks({"tab_recovery": rows})
    moved = tuple(
        dataclasses.replace(s, table="tab_other") if s.family.startswith("tracks_") else s
        for s in CATALOGUE
    )
    monkeypatch.setattr(catalogue, "CATALOGUE", moved)
    monkeypatch.setattr(claims, "CATALOGUE", moved)
    after = tracks({"tab_recovery": rows[rows.method == "ours"], "tab_other": rows})
    cols = ["measured", "ci_low", "ci_high", "verdict"]
    pd.testing.assert_frame_equal(before[cols], after[cols])
    assert after["source"].str.startswith("tab_other").all()
    assert "tab_other" in catalogue.tables()


def test_a_one_sided_claim_says_why_and_a_band_has_no_side():
    """Every family is an equivalence test (a band) or one-sided with its stated reason."""
    for spec in CATALOGUE:
        assert (spec.side == catalogue.WITHIN) != bool(spec.one_sided), spec.family
    base = next(s for s in CATALOGUE if s.side != catalogue.WITHIN)
    kw = {f: getattr(base, f) for f in base.__dataclass_fields__}
    with pytest.raises(ValueError, match="one_sided"):
        ClaimSpec(**{**kw, "one_sided": ""})
    with pytest.raises(ValueError, match="one_sided"):
        ClaimSpec(**{**kw, "side": catalogue.WITHIN})


def test_flatness_is_a_band_in_every_family_that_claims_it():
    """A claim of flatness is tested inside (-t, +t), for ours and every other prior."""
    flat = [s for s in CATALOGUE if s.family == "decay_rate_flat"]
    assert len(flat) == 2 and all(s.side == catalogue.WITHIN for s in flat)
