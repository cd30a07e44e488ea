"""Atomic writes: outputs get the mode of an ordinary new file (0666 less the umask)."""

import os
import stat

import numpy as np
import pytest

import physgs.atomic
from physgs.atomic import atomic_path, current_umask, save_npz, write_json, write_text


@pytest.fixture
def umask():
    """Set the process umask for one test and restore it afterwards."""
    old = os.umask(0o022)
    os.umask(old)
    yield lambda m: os.umask(m)
    os.umask(old)


def _mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


def _write_binary(path):
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        f.write(b"\x00\x01")


WRITERS = {
    "text": lambda p: write_text(p, "x\n"),
    "json": lambda p: write_json(p, {"a": 1}),
    "npz": lambda p: save_npz(p, a=np.arange(3)),
    "binary": _write_binary,
}


@pytest.mark.parametrize(
    "mask, expected", [(0o022, 0o644), (0o027, 0o640), (0o077, 0o600), (0o002, 0o664)]
)
@pytest.mark.parametrize("writer", sorted(WRITERS))
def test_outputs_get_the_umask_mode(tmp_path, umask, mask, expected, writer):
    umask(mask)
    path = tmp_path / "sub" / ("out.npz" if writer == "npz" else "out.bin")
    WRITERS[writer](path)
    assert _mode(path) == expected, oct(_mode(path))
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no temporary left


def test_rewriting_an_old_0600_output_gives_it_the_umask_mode(tmp_path, umask):
    umask(0o022)
    path = tmp_path / "table.csv"
    path.write_text("old\n")
    os.chmod(path, 0o600)  # as written before the fix
    write_text(path, "new\n")
    assert path.read_text() == "new\n" and _mode(path) == 0o644


def test_a_failed_write_leaves_nothing(tmp_path, umask):
    umask(0o022)
    with pytest.raises(RuntimeError):
        with atomic_path(tmp_path / "x.txt") as tmp:
            tmp.write_text("partial")
            raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []


def test_current_umask_reads_the_process_umask_without_changing_it(umask, monkeypatch):
    umask(0o027)
    assert current_umask() == 0o027
    # the fallback when /proc is unavailable (not Linux): set-and-restore

    def no_proc(*args, **kwargs):
        raise OSError("no /proc")

    monkeypatch.setattr(physgs.atomic, "open", no_proc, raising=False)
    assert current_umask() == 0o027
    assert os.umask(0o027) == 0o027  # restored


@pytest.mark.parametrize("writer", sorted(WRITERS))
def test_the_file_is_on_the_disk_before_the_rename_and_the_rename_after(
    tmp_path, monkeypatch, writer
):
    """Each writer flushes the written file before the rename and the directory after it: a
    power loss can then leave the old output or the new one, never an empty one."""
    path = tmp_path / ("out.npz" if writer == "npz" else "out.bin")
    events = []
    real_fsync, real_replace = os.fsync, os.replace

    def fsync(fd):
        st = os.fstat(fd)
        what = "dir" if stat.S_ISDIR(st.st_mode) else f"file of {st.st_size} bytes"
        events.append(("fsync", what, st.st_ino))
        real_fsync(fd)

    def replace(src, dst):
        events.append(("rename", os.stat(src).st_ino))
        real_replace(src, dst)

    monkeypatch.setattr(os, "fsync", fsync)
    monkeypatch.setattr(os, "replace", replace)
    WRITERS[writer](path)
    ino = os.stat(path).st_ino
    size = os.stat(path).st_size
    assert size > 0
    assert events == [
        ("fsync", f"file of {size} bytes", ino),
        ("rename", ino),
        ("fsync", "dir", os.stat(tmp_path).st_ino),
    ], events
