"""Atomic, durable file writes: write to a temporary sibling, flush it to the disk, then rename,
so neither a crash nor a power loss leaves a partial or empty output that a later step would take
as good."""

from __future__ import annotations

import errno
import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import numpy as np


def current_umask() -> int:
    """The process's file-mode creation mask.

    Read from /proc/self/status ("Umask:", Linux 4.7+) where available; otherwise by setting it
    and restoring it at once (``os.umask`` has no read-only form). That fallback is
    process-global: a thread creating a file between the two calls would get mode 0666 & ~0o077;
    acceptable here (the pipeline writes from one thread), and it never runs on Linux.

    Returns:
        The mask's bits (e.g. 0o022).
    """
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    old = os.umask(0o077)
    os.umask(old)
    return old


#: a file system with less free space than this (bytes) counts as full when a write to it fails
FULL_BELOW = 1 << 20


def free_bytes(path: str | os.PathLike) -> int:
    """Free bytes on the file system holding ``path`` (or its nearest existing folder), as this
    user may use them (root may use the blocks reserved for it).

    Args:
        path: a file or folder, existing or not.

    Returns:
        The bytes free.
    """
    p = os.path.abspath(path)
    while not os.path.exists(p):
        p = os.path.dirname(p)
    st = os.statvfs(p)
    blocks = st.f_bfree if os.geteuid() == 0 else st.f_bavail
    return blocks * st.f_frsize


def disk_full_error(path: str | os.PathLike, error: BaseException) -> OSError | None:
    """An ``OSError`` naming ENOSPC and ``path`` when ``error`` came from a full file system.

    A write to a full disk fails with ``OSError(ENOSPC)`` that names no file (numpy, Python's
    ``write``), or with a message that does not say why (``torch.save``: ``[enforce fail at
    inline_container.cc:672] unexpected pos``). Call it before the partial file is removed: its
    blocks are what fills the disk.

    Args:
        path: the file being written.
        error: what the write raised.

    Returns:
        The error to raise instead (``errno`` ENOSPC, ``filename`` the path; the message names the
        free bytes left and, for an error that did not say ENOSPC itself, quotes it), or None when
        the error is not ENOSPC and the file system has at least ``FULL_BELOW`` bytes free.
    """
    said = isinstance(error, OSError) and error.errno == errno.ENOSPC
    if said and error.filename is not None and not _same_file(error.filename, path):
        return None  # it names the file it could not write, a file of the body's own
    try:
        free = free_bytes(path)
    except OSError:
        free = None
    if not said and (free is None or free >= FULL_BELOW):
        return None
    left = "" if free is None else f" ({free} bytes left on its file system)"
    quote = "" if said else f"; the writer said: {type(error).__name__}: {error}"
    return OSError(
        errno.ENOSPC,
        f"No space left on device (ENOSPC) writing {path}{left}: free space there, then rerun"
        + quote,
        str(path),
    )


def _same_file(name, path) -> bool:
    """Whether ``name`` is ``path`` or a temporary sibling of it (``atomic_path``'s)."""
    name, path = Path(os.path.abspath(name)), Path(os.path.abspath(path))
    return name == path or (name.parent == path.parent and name.name.startswith(f".{path.stem}."))


def fsync_path(path: str | os.PathLike) -> None:
    """Flush a file's or a directory's data and metadata to the disk (``fsync``).

    Args:
        path: a file or a directory.
    """
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it onto ``path``.

    The temporary name keeps the final suffix, so writers that pick a format from the extension
    (matplotlib, numpy) behave as for the real name. On error it is removed. The output gets the
    mode of an ordinary new file: 0666 less the process's umask.

    Durable: the temporary file is flushed to the disk (``fsync``) before the rename, and the
    directory after it. A rename is atomic but not durable by itself: after a power loss, a file
    system may keep the rename and lose the data written before it (XFS, btrfs, ext4 mounted
    ``noauto_da_alloc``), leaving an empty "complete" file; flushing the file first orders the
    two. The rename is an entry of the directory, so it is on the disk only once the directory is
    flushed: until then a power loss undoes it and brings the old output back, which Snakemake
    would take as made by this job.

    A write that fails because the disk is full raises an ``OSError`` with errno ENOSPC that
    names ``path`` ([`disk_full_error`][physgs.atomic.disk_full_error]), whatever the writer
    raised.

    Args:
        path: the final file.

    Yields:
        The temporary path to write.

    Raises:
        OSError: ENOSPC, naming ``path``, when the disk filled during the write.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    tmp = Path(tmp)
    try:
        # mkstemp creates the file 0600; give it the mode an ordinary open() would (0666 less
        # the umask), so collaborators in the group can read the output. Writers reopen the
        # path, which keeps the mode, and the rename keeps it too.
        os.chmod(tmp, 0o666 & ~current_umask())
        yield tmp
        fsync_path(tmp)
        os.replace(tmp, path)
        fsync_path(path.parent)
    except Exception as e:
        full = disk_full_error(path, e)
        if full is None:
            raise
        raise full from e
    finally:
        if tmp.exists():
            tmp.unlink()


def write_text(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` atomically.

    Args:
        path: the file.
        text: its contents.
    """
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def write_json(path: str | os.PathLike, obj) -> None:
    """Write a JSON-serialisable object atomically, keys sorted, indented by 2.

    NaN is written as NaN, as Python's json does.

    Args:
        path: the file.
        obj (Any): the object.
    """
    write_text(path, json.dumps(obj, indent=2, sort_keys=True) + "\n")


def save_npz(path: str | os.PathLike, **arrays: np.ndarray) -> None:
    """``np.savez`` to ``path`` atomically.

    Args:
        path: the file; it must end in ``.npz`` (numpy would append it silently).
        **arrays: name -> array.

    Raises:
        ValueError: ``path`` does not end in ``.npz``.
    """
    if not str(path).endswith(".npz"):
        raise ValueError(f"save_npz: {path!r} must end in .npz (numpy would append it silently)")
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
