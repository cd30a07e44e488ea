"""Run the Snakemake workflow in a scratch copy of the repository's workflow files."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def workflow_copy(dest: Path) -> Path:
    """Copy Snakefile, workflow/, config/ and the profiles link into ``dest`` (results land
    there, not in the repo)."""
    dest.mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "Snakefile", dest / "Snakefile")
    if not (dest / "profiles").exists():  # where Snakemake looks for profiles/default
        (dest / "profiles").symlink_to(os.readlink(ROOT / "profiles"))
    for d in ("workflow", "config"):
        shutil.copytree(
            ROOT / d, dest / d, dirs_exist_ok=True, ignore=shutil.ignore_patterns("__pycache__")
        )
    return dest


def snakemake(workdir: Path, *args: str, timeout: int = 600) -> subprocess.CompletedProcess:
    """``snakemake`` in ``workdir``; raises with the tail of the log if it fails."""
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    cmd = [sys.executable, "-m", "snakemake", *args]
    proc = subprocess.run(
        cmd, cwd=workdir, env=env, capture_output=True, text=True, timeout=timeout
    )
    if proc.returncode != 0:
        tail = (proc.stdout + proc.stderr)[-6000:]
        raise AssertionError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{tail}")
    return proc
