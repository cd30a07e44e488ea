"""The trade's hygiene, checked in seconds: ruff's lint rules (pyproject.toml), ruff format and
snakefmt over every tracked file, so a commit that skips the pre-commit hook fails CI."""

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def tracked(*patterns: str) -> list[str]:
    """Tracked files matching the patterns (an untracked draft in a shared checkout is not
    checked); the whole tree when this is not a git checkout."""
    try:
        out = subprocess.run(
            ["git", "ls-files", "--", *patterns], cwd=ROOT, capture_output=True, text=True
        )
    except FileNotFoundError:
        return ["."]
    if out.returncode != 0:
        return ["."]
    return [f for f in out.stdout.split() if (ROOT / f).exists()]


@pytest.mark.parametrize(
    "cmd, patterns",
    [
        (["ruff", "check", "--no-cache"], ("*.py",)),
        (["ruff", "format", "--check", "--no-cache"], ("*.py",)),
        (["snakefmt", "--check"], ("Snakefile", "*.smk")),
    ],
    ids=["ruff-check", "ruff-format", "snakefmt"],
)
def test_tree_is_clean(cmd, patterns):
    assert shutil.which(cmd[0]), f"{cmd[0]} is in the test extra: pip install -e '.[test]'"
    files = tracked(*patterns)
    assert files, f"no files match {patterns}"
    r = subprocess.run([*cmd, *files], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, f"{' '.join(cmd)} found problems:\n{r.stdout}\n{r.stderr}"
