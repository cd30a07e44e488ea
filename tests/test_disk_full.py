"""A full disk names ENOSPC and the file: checkpoints (torch.save), npz, text and a job's log,
on a real full file system (a small tmpfs; skipped where one cannot be mounted)."""

from __future__ import annotations

import errno
import subprocess
from types import SimpleNamespace

import numpy as np
import pytest

from physgs.atomic import atomic_path, save_npz, write_text
from physgs.jobs import job


@pytest.fixture
def full_fs(tmp_path):
    """A 256 KiB tmpfs: every write below of a few MB fills it."""
    mnt = tmp_path / "full"
    mnt.mkdir()
    r = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(mnt)],
        capture_output=True,
        text=True,
    )
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here (needs root): {r.stderr.strip()}")
    try:
        yield mnt
    finally:
        subprocess.run(
            ["umount", "--lazy", str(mnt)], check=True
        )  # a traceback may hold a file open


def _checkpoint(path):
    import torch

    with atomic_path(path) as tmp:  # as physgs.models.checkpoint.save_checkpoint writes
        torch.save({"state_dict": {"w": torch.zeros(1_000_000)}}, tmp)


WRITERS = {
    "checkpoint": ("m.pt", _checkpoint),
    "npz": ("a.npz", lambda p: save_npz(p, a=np.zeros(1_000_000))),
    "text": ("t.txt", lambda p: write_text(p, "x" * 2_000_000)),
}


@pytest.mark.parametrize("writer", sorted(WRITERS))
def test_a_write_to_a_full_disk_names_enospc_and_the_file(full_fs, writer):
    name, write = WRITERS[writer]
    path = full_fs / name
    with pytest.raises(OSError) as e:
        write(path)
    assert e.value.errno == errno.ENOSPC and e.value.filename == str(path), repr(e.value)
    assert "ENOSPC" in str(e.value) and str(path) in str(e.value), str(e.value)
    assert list(full_fs.iterdir()) == []  # the partial temporary is gone, its space freed


def test_a_job_whose_log_fills_the_disk_names_the_log_and_shows_its_traceback(
    full_fs, tmp_path, capfd
):
    log = full_fs / "job.log"
    sm = SimpleNamespace(
        output=[str(tmp_path / "out.txt")], log=[str(log)], threads=1, rule="r", params=[]
    )
    with pytest.raises(OSError) as e:
        with job(sm):
            for _ in range(100):
                print("progress " * 10_000, flush=True)
    assert e.value.errno == errno.ENOSPC and e.value.filename == str(log), repr(e.value)
    assert "ENOSPC" in str(e.value), str(e.value)
    err = capfd.readouterr().err
    # the log cannot hold the traceback: the console has it, not a "see" pointing at the log
    assert f"its log {log} could not be written" in err and "Traceback" in err, err
    assert f"job failed; see {log}" not in err, err
