"""The catalogue of claims: its entries are well formed, every count of claims keeps the
paper's apart from this project's, and docs/claims.md's list of claims is the catalogue's
(tools/claims_reference.py)."""

import subprocess
import sys
from pathlib import Path

import pytest

from physgs.report import catalogue
from physgs.report.catalogue import CATALOGUE, ClaimSpec, origin_of

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


def test_a_spec_refuses_what_it_cannot_decide():
    base = CATALOGUE[0]
    kw = {f: getattr(base, f) for f in base.__dataclass_fields__}
    for bad in ({"side": ">="}, {"origin": "both"}, {"of": "fields"}, {"threshold": "NOPE"}):
        with pytest.raises(ValueError, match=base.family):
            ClaimSpec(**{**kw, **bad})


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
