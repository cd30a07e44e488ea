"""A tree's role is a field of its preset (config ``presets.<tree>.role``): which claims apply to
a tree, and which of the paper's trees it is read against, never its name."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml

import physgs.config
from physgs.report import claims
from physgs.report.claim_cells import roles_of
from physgs.report.images import teaser_tree
from roles import ROLES
from workflow_helpers import workflow_copy

ROOT = Path(__file__).resolve().parents[1]
REPORT = ROOT / "src" / "physgs" / "report"
#: role-scoped families: asked only of a tree whose preset declares the role
SEPARATED = {
    "null_factor",
    "null_loses",
    "oma_beats_null",
    "tracks_beats_null",
    "tracks_match_ours",
}
TILED = {"null_matches"}


def test_no_tree_name_in_the_report_code():
    """No "sparse", "medium" or "dense" string in src/physgs/report/: a preset's role decides.
    paper.py is exempt: its keys are the paper's labels for its own three trees, reached only
    through a preset's ``role.paper``."""
    found = [
        f"{p.relative_to(ROOT)}:{i}: {line.strip()}"
        for p in sorted(REPORT.rglob("*.py"))
        if p.name != "paper.py"
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if re.search(r"""["'](sparse|medium|dense)["']""", line)
    ]
    assert not found, "\n".join(found)


def test_the_shipped_presets_declare_their_roles():
    assert ROLES["sparse"] == {"frequencies": "separated", "paper": "sparse"}
    assert ROLES["medium"]["frequencies"] == ROLES["dense"]["frequencies"] == "tiled"


def _null(trees):
    """tab_null / tab_recovery rows of ours, the 2D tracks and the output-only analysis on every
    tree (three seeds)."""
    return pd.DataFrame(
        [
            {
                "seed": s,
                "tree": t,
                "config": "joint32",
                "method": m,
                "K": 32,
                "trained_median_rel_err_pct": 2.0 + 0.01 * s,
                "null_median_rel_err_pct": 6.0,
            }
            for s in range(3)
            for t in trees
            for m in ("ours", "tracks", "oma")
        ]
    )


def _families_of(tree: str, roles) -> set[str]:
    trees = ["sparse", "medium", "dense", tree]
    tabs = {"tab_null": _null(trees)[lambda d: d.method == "ours"], "tab_recovery": _null(trees)}
    return {
        c.id.split("/")[0]
        for c, _ in claims.measure(tabs, {}, trees, roles=roles)
        if c.id.split("/")[-1] == tree
    }


@pytest.mark.parametrize(
    "role, want",
    [
        ({}, set()),  # no role: none of a role's claims, never the tiled trees' by default
        ({"frequencies": "tiled"}, TILED),
        ({"frequencies": "separated"}, SEPARATED),
    ],
)
def test_a_fourth_preset_gets_the_claims_of_its_role_or_none(role, want):
    got = _families_of("oak", {**ROLES, "oak": role})
    assert got & (SEPARATED | TILED) == want
    assert "ours_above_static_beyond" in got  # the claims of every tree it gets all the same


def test_the_papers_figures_follow_the_role_not_the_name():
    """A tree standing for the paper's sparse tree is read against its figures; one that stands
    for none gets none (the paper's null ratio of the sparse tree: 4.56 / 1.80)."""
    for role, want in (({"frequencies": "separated", "paper": "sparse"}, 4.56 / 1.80), ({}, None)):
        tabs = {"tab_null": _null(["oak"])[lambda d: d.method == "ours"]}
        roles = {"oak": {"frequencies": "separated", **role}}
        df = claims.ledger(claims.measure(tabs, {}, ["oak"], roles=roles)).set_index("id")
        low = df.loc["null_loses/oak", "paper_low"]
        assert (low == pytest.approx(want)) if want else pd.isna(low)
    assert teaser_tree(["sparse", "oak"], {"oak": {"paper": "medium"}}) == "oak"
    assert teaser_tree(["sparse", "oak"], {}) == "oak"  # none stands for it: the last


def _fourth(tmp_path: Path, role: dict | None) -> Path:
    raw = yaml.safe_load((ROOT / "config" / "trees.yaml").read_text())
    oak = {k: v for k, v in raw["presets"]["sparse"].items() if k != "role"}
    if role is not None:
        oak["role"] = role
    extra = tmp_path / "oak.yaml"
    extra.write_text(
        yaml.safe_dump(
            {
                "trees": ["sparse", "oak"],
                "presets": {"oak": oak},
                "testbed": {"vertices": {"oak": 400}},
            }
        )
    )
    return extra


@pytest.mark.parametrize("role", [None, {"frequencies": "tiled"}])
def test_a_fourth_preset_in_the_quick_dag(tmp_path, role):
    """The quick DAG with a fourth preset: the workflow's own config loading gives the claims
    rule its declared role (or none), and the plan builds its testbed and its claims."""
    extra = _fourth(tmp_path, role)
    raw = yaml.safe_load((ROOT / "config" / "trees.yaml").read_text())
    cfg = physgs.config.load_workflow_config(
        raw, command_line={"profile": "quick"}, configfiles=[extra]
    )
    got = roles_of(cfg["presets"], cfg["trees"])
    assert got["oak"] == (role or {}) and got["sparse"] == ROLES["sparse"]
    fams = _families_of("oak", got)
    assert fams & (SEPARATED | TILED) == (TILED if role else set())
    wd = workflow_copy(tmp_path / "wf")
    cmd = [sys.executable, "-m", "snakemake", "-n", "--cores", "1", "results/claims.md"]
    cmd += ["--config", "profile=quick", "--configfile", str(extra)]  # nargs: the target first
    out = subprocess.run(cmd, cwd=wd, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "results/testbed/oak/observed.npz" in out.stdout and "rule claims:" in out.stdout
