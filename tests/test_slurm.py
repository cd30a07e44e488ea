"""The cluster profile on a real SLURM: tools/slurm_up.sh boots a one-node SLURM (root, Debian
packages; skipped with the reason where it cannot), and a slice of the quick DAG (a testbed, its
statistics and table, a training and its evaluation) runs through
`--workflow-profile workflow/profiles/cluster`. Every SLURM job must reach COMPLETED in sacct,
and every output must equal the same slice run locally with the same threads (bitwise; the
wall-time columns aside, as for any rerun).

Marker `slurm`: deselected from the suite (pyproject addopts) and run by the README's test
command as a second pytest invocation (`python -m pytest -q -m slurm`). The daemons the test
booted are stopped after it (tools/slurm_down.sh); a SLURM that was up before is left up."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch

from conftest import MACHINE_SLURM_CONF
from workflow_helpers import ROOT, snakemake, workflow_copy

# one worker, in file order: the last test checks what the first one left
pytestmark = [pytest.mark.slurm, pytest.mark.xdist_group("slurm")]

TARGETS = ["results/tables/tab_testbed.csv", "results/eval/sparse/seed0/static_single.npz"]
CONFIG = ["--config", "profile=quick", 'trees=["sparse"]']
#: wall-time fields: the only values a rerun may change
WALL = {"seconds", "train_s", "wall_s", "s_per_iter", "holdout_s"}


#: the daemons tools/slurm_up.sh starts that outlive a test unless stopped (MariaDB and munged
#: are stopped with them by tools/slurm_down.sh)
DAEMONS = ("slurmdbd", "slurmctld", "slurmd")


def _running(name: str) -> list[int]:
    """The pids of the processes named ``name`` (their ``comm``)."""
    pids = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                if (d / "comm").read_text().strip() == name:
                    pids.append(int(d.name))
            except OSError:  # ended meanwhile
                pass
    return pids


#: the daemons running before this module booted anything (read when it is collected)
BEFORE = {d: _running(d) for d in DAEMONS}


@pytest.fixture
def slurm_cluster(monkeypatch):
    """A one-node SLURM for the test; stopped after it unless one was running before. The
    machine's SLURM configuration, not the suite's ``conftest.NO_CONTROLLER``."""
    if MACHINE_SLURM_CONF is None:
        monkeypatch.delenv("SLURM_CONF")
    else:
        monkeypatch.setenv("SLURM_CONF", MACHINE_SLURM_CONF)
    _boot()
    yield
    if not any(BEFORE.values()):
        down = subprocess.run(
            [str(ROOT / "tools" / "slurm_down.sh")], capture_output=True, text=True, timeout=120
        )
        assert down.returncode == 0, f"tools/slurm_down.sh failed:\n{down.stdout}\n{down.stderr}"


def _boot() -> None:
    if os.geteuid() != 0:
        pytest.skip(
            "booting SLURM needs root (tools/slurm_up.sh installs packages, starts daemons)"
        )
    if shutil.which("slurmctld") is None and shutil.which("apt-get") is None:
        pytest.skip("SLURM is not installed and there is no apt-get to install it")
    pytest.importorskip("snakemake_executor_plugin_slurm", reason='pip install -e ".[cluster]"')
    proc = subprocess.run(
        [str(ROOT / "tools" / "slurm_up.sh")], capture_output=True, text=True, timeout=600
    )
    if proc.returncode == 2:  # cannot boot here (the script says why)
        pytest.skip(f"tools/slurm_up.sh cannot boot SLURM here: {proc.stderr.strip()}")
    assert proc.returncode == 0, f"tools/slurm_up.sh failed:\n{proc.stdout}\n{proc.stderr}"


def _outputs(wd: Path) -> dict[str, Path]:
    res = wd / "results"
    return {
        str(p.relative_to(res)): p
        for p in sorted(res.rglob("*"))
        if p.is_file() and "benchmarks" not in p.parts
    }


def _equal(x, y, where: str) -> None:
    """Exact equality of nested dicts/lists of tensors, arrays and plain values."""
    assert type(x) is type(y), where
    if isinstance(x, dict):
        assert list(x) == list(y), where
        for k in x:
            _equal(x[k], y[k], f"{where}:{k}")
    elif isinstance(x, (list, tuple)):
        assert len(x) == len(y), where
        for i, (u, v) in enumerate(zip(x, y)):
            _equal(u, v, f"{where}[{i}]")
    elif isinstance(x, torch.Tensor):
        assert x.dtype == y.dtype and torch.equal(x, y), where
    elif isinstance(x, np.ndarray):
        assert x.dtype == y.dtype and np.array_equal(x, y), where
    else:
        assert x == y, where


def _same(a: Path, b: Path) -> None:
    name = a.name
    if name.endswith(".npz"):
        za, zb = np.load(a), np.load(b)
        assert sorted(za.files) == sorted(zb.files), name
        for k in za.files:
            assert za[k].dtype == zb[k].dtype and np.array_equal(za[k], zb[k]), f"{name}:{k}"
    elif name.endswith(".csv"):
        da, db = pd.read_csv(a), pd.read_csv(b)
        keep = [c for c in da.columns if c not in WALL]
        assert list(da.columns) == list(db.columns), name
        pd.testing.assert_frame_equal(da[keep], db[keep], check_exact=True, obj=name)
    elif name.endswith(".pt"):
        ca, cb = torch.load(a, weights_only=False), torch.load(b, weights_only=False)
        sa, sb = ca.pop("state_dict"), cb.pop("state_dict")
        assert list(sa) == list(sb), name
        for k in sa:
            assert torch.equal(sa[k], sb[k]), f"{name}:{k}"
        for c in (ca, cb):
            c["stats"] = {k: v for k, v in c["stats"].items() if k not in WALL}
        _equal(ca, cb, name)
    elif name.endswith(".png") or name.endswith(".pdf"):
        pass  # renderings of the compared arrays; their metadata carries dates
    else:
        assert a.read_bytes() == b.read_bytes(), name


def test_slice_on_slurm_completes_and_equals_the_local_run(tmp_path, slurm_cluster):
    local = workflow_copy(tmp_path / "local")
    slurm = workflow_copy(tmp_path / "slurm")
    # the local run beside the SLURM one (results do not depend on timing)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    loc = subprocess.Popen(
        [sys.executable, "-m", "snakemake", "--cores", "1", *CONFIG, "--", *TARGETS],
        cwd=local,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    proc = snakemake(
        slurm,
        "--workflow-profile",
        "workflow/profiles/cluster",
        "--slurm-init-seconds-before-status-checks",
        "2",
        "--seconds-between-status-checks",
        "2",
        "--latency-wait",
        "20",
        "--retries",
        "0",
        *CONFIG,
        "--",
        *TARGETS,
        timeout=900,
    )
    out, _ = loc.communicate(timeout=900)
    assert loc.returncode == 0, out[-4000:]
    log = proc.stdout + proc.stderr
    ids = re.findall(r"submitted with SLURM jobid (\d+)", log)
    # testbed; train + evaluate (group fit); statistics; table (neither is grouped: see the
    # profile's comment)
    assert len(ids) == 4, log[-4000:]
    acct = subprocess.run(
        ["sacct", "-X", "-n", "-P", "-o", "JobID,State,Comment", "-j", ",".join(ids)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    states = dict(line.split("|")[:2] for line in acct.splitlines() if line)
    assert sorted(states) == sorted(ids) and set(states.values()) == {"COMPLETED"}, acct
    a, b = _outputs(local), _outputs(slurm)
    assert sorted(a) == sorted(b) and len(a) >= 8, (sorted(a), sorted(b))
    for k in a:
        _same(a[k], b[k])


def test_the_daemons_it_started_are_stopped():
    """Runs after the test above (same worker, file order): no daemon it booted is left."""
    if any(BEFORE.values()):
        pytest.skip(f"SLURM was running before these tests ({BEFORE}): left as it was")
    left = {d: _running(d) for d in DAEMONS}
    assert not any(left.values()), f"left running after the SLURM test: {left}"
