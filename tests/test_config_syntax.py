"""A YAML syntax error in the config names the file, line and column, with the parser's message."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest

from physgs.config import ConfigError, check_yaml_syntax
from workflow_helpers import ROOT


@pytest.mark.parametrize(
    "text, where, says",
    [
        ("a:\n  b: 1\n\tc: 2\n", "3:1", "found character '\\t' that cannot start any token"),
        ("a:\n  b: 1\n c: 2\n", "3:2", "expected <block end>, but found '<block mapping start>'"),
        ("a: 'open\n", "2:1", "found unexpected end of stream"),
    ],
)
def test_a_syntax_error_names_file_line_and_column(tmp_path, text, where, says):
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as e:
        check_yaml_syntax(path)
    msg = str(e.value)
    assert msg.startswith(f"{path}:{where}: not valid YAML"), msg
    assert says in msg, msg


def test_valid_yaml_passes(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("a: [1, 2]\nb: {c: 3}\n")
    check_yaml_syntax(path)
    check_yaml_syntax(ROOT / "config" / "trees.yaml")


def test_the_workflow_names_the_line_of_a_broken_trees_yaml(tmp_path):
    """An unclosed list on the `seeds:` line: Snakemake alone says "not valid JSON or YAML ... do
    not mix whitespace and tab indentation", naming no file or line."""
    for p in ("Snakefile", "config", "workflow"):
        src = ROOT / p
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / p)
    cfg = tmp_path / "config" / "trees.yaml"
    lines = cfg.read_text().split("\n")
    n = next(i for i, line in enumerate(lines) if line.startswith("seeds:"))
    lines[n] = "seeds: [0, 1"
    cfg.write_text("\n".join(lines))
    r = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "--cores", "1", "all"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    out = r.stdout + r.stderr
    assert r.returncode != 0
    assert "config/trees.yaml:" in out and "not valid YAML" in out, out
    assert f'in "config/trees.yaml", line {n + 1}, column 8' in out, out  # where the list opens
    assert "whitespace and tab indentation" not in out, out
