"""Reading the workflow's intermediate files (tracks, fits, trajectories, records): one loader
that names the file and the rule that rebuilds it, and removes a file it cannot read.

Every intermediate file is written atomically ([`physgs.atomic`][physgs.atomic]), so a corrupt one
comes from outside the pipeline (a full disk, a copy cut short, a hand edit). Snakemake reruns a job
only when its output is missing or older than its inputs, so a corrupt file left in place would be
read again, and fail again, by every later run. The loader therefore deletes it before raising.
Snakemake remakes a missing file only when a job that reads it has to run: when what was made from
it is up to date (made before it was damaged), rerunning the same command has nothing to do. The
message therefore gives the flag that remakes it and what is made from it in any case:
``--forcerun <file>`` added to the command ([`remake_hint`][physgs.intermediate.remake_hint]).
"""

from __future__ import annotations

import json
import zipfile
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np


class IntermediateFileError(ValueError):
    """A missing or unreadable intermediate file; the message names the file and its rule."""


def remake_hint(path: str | Path) -> str:
    """How to remake ``path`` and everything made from it with the settings of the command that
    stopped: ``--forcerun <path>`` added to that command (Snakemake runs the job that makes it
    even if the file is there, and every job of the command downstream of it).

    Args:
        path: the file, as the workflow names it.

    Returns:
        The sentence to end an error message with.
    """
    return (
        f"to remake it and what is made from it, rerun this command with `--forcerun {path}` "
        "added (as it was, the command remakes it only if a job that reads it still has to run: "
        "Snakemake leaves a missing file alone when what was made from it is up to date)"
    )


def refuse(path: str | Path, what: str, rule: str) -> IntermediateFileError:
    """Remove the unreadable ``path`` and say so: the error to raise.

    Args:
        path: the intermediate file (removed if present).
        what: what is wrong with it (the message's predicate, e.g. "is corrupt").
        rule: the workflow rule that writes it.

    Returns:
        The error, naming the file, the fault and the rule; the caller raises it.
    """
    path = Path(path)
    path.unlink(missing_ok=True)
    return IntermediateFileError(
        f"{path} {what}; it was removed (rule `{rule}` makes it); {remake_hint(path)}"
    )


def _missing(path: Path, rule: str) -> IntermediateFileError:
    return IntermediateFileError(
        f"{path} does not exist; build it with rule `{rule}` (snakemake --cores 2 {path})"
    )


def load_npz(
    path: str | Path, keys: Iterable[str], error: Callable[[str, str], Exception]
) -> dict[str, np.ndarray]:
    """The arrays of an ``.npz`` of plain arrays (no pickled objects), every one of ``keys``
    present; what the caller raises when it is not is ``error``'s (``read_npz``: an
    intermediate file's; ``physgs.testbed.dataset``: a dataset's).

    Args:
        path: the file.
        keys: names the file must hold (it may hold more).
        error: ``error(problem, detail)`` -> the exception to raise: problem "missing" (detail
            ""), "corrupt" (detail: the exception's type and message) or "lacks" (detail: the
            absent keys).

    Returns:
        name -> array, for every array in the file.

    Raises:
        Exception: ``error``'s; a ``PermissionError`` as it is (not the file's fault).
    """
    path = Path(path)
    if not path.is_file():
        raise error("missing", "")
    try:
        with np.load(path, allow_pickle=False) as z:
            d = {k: z[k] for k in z.files}
    except PermissionError:
        raise  # not the file's fault: keep it
    except (zipfile.BadZipFile, ValueError, OSError, EOFError, KeyError) as e:
        raise error("corrupt", f"{type(e).__name__}: {e}") from None
    absent = [k for k in keys if k not in d]
    if absent:
        raise error("lacks", str(absent))
    return d


def read_npz(path: str | Path, keys: Iterable[str], *, rule: str) -> dict[str, np.ndarray]:
    """The arrays of an intermediate ``.npz`` (no pickled objects), every one of ``keys`` present.

    Args:
        path: the file.
        keys: names the file must hold (it may hold more).
        rule: the workflow rule that writes it (named in the error).

    Returns:
        name -> array, for every array in the file.

    Raises:
        IntermediateFileError: the file is missing, or is not a readable ``.npz`` of plain arrays
            holding ``keys`` (then it is removed first, and the message says how to remake it).
    """

    def error(problem: str, detail: str) -> IntermediateFileError:
        if problem == "missing":
            return _missing(Path(path), rule)
        what = {
            "corrupt": f"is corrupt ({detail})",
            "lacks": f"lacks {detail} (another version, or not this rule's file)",
        }[problem]
        return refuse(path, what, rule)

    return load_npz(path, keys, error)


def read_json(path: str | Path, keys: Iterable[str] = (), *, rule: str) -> dict:
    """The mapping of an intermediate ``.json`` holding every one of ``keys``.

    Args:
        path: the file.
        keys: names the mapping must hold (it may hold more).
        rule: the workflow rule that writes it (named in the error).

    Returns:
        The mapping.

    Raises:
        IntermediateFileError: the file is missing, corrupt, not a mapping or lacks a key (a
            file that is there is then removed, and the message says how to remake it).
    """
    path = Path(path)
    if not path.is_file():
        raise _missing(path, rule)
    try:
        with open(path) as fh:
            d = json.load(fh)
    except PermissionError:
        raise
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise refuse(path, f"is corrupt ({type(e).__name__}: {e})", rule) from None
    if not isinstance(d, dict):
        raise refuse(path, f"holds a {type(d).__name__}, not a mapping", rule)
    absent = [k for k in keys if k not in d]
    if absent:
        raise refuse(path, f"lacks {absent} (another version, or not this rule's file)", rule)
    return d
