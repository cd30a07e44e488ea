"""Which settings made a result: a stamp (profile, resolved-config hash, package version)
written into every table's CSV and the report, so copied results say where they came from."""

from __future__ import annotations

import hashlib
import json
import platform
import subprocess
from dataclasses import asdict, dataclass
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path


def package_version() -> str:
    """physgs' installed version ('unknown' when run from a tree that is not installed).

    Returns:
        The version string of the installed distribution, or ``'unknown'``.
    """
    try:
        return version("physgs")
    except PackageNotFoundError:
        return "unknown"


def config_hash(cfg: dict) -> str:
    """Hash of the resolved config, unchanged by key order and changed by any value.

    Args:
        cfg: the resolved config.

    Returns:
        12 hex digits of the SHA-256 of the config as canonical JSON (sorted keys).
    """
    blob = json.dumps(cfg, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:12]


@dataclass(frozen=True)
class Stamp:
    """Provenance of one result.

    A class rather than a dict on purpose: Snakemake does not track params it cannot represent,
    so passing a Stamp as a rule's param records it without making every table out of date
    whenever any key of the config changes (the narrow settings and the inputs decide that).
    """

    profile: str
    config_hash: str
    physgs_version: str

    def to_dict(self) -> dict:
        """The stamp as a plain dict (profile, config_hash, physgs_version).

        Returns:
            A new dict of the dataclass fields.
        """
        return asdict(self)


def stamp(cfg: dict) -> Stamp:
    """The stamp of a resolved config.

    Args:
        cfg: the resolved config (its ``profile`` key names the profile).

    Returns:
        The [`Stamp`][physgs.provenance.Stamp]: profile, config hash and physgs' version.
    """
    return Stamp(str(cfg.get("profile", "unknown")), config_hash(cfg), package_version())


def machine_cpu(cpuinfo: str | Path = "/proc/cpuinfo") -> str:
    """The CPU's model and whether it computes bf16 natively (AVX-512 BF16, AMX): what a
    timing depends on (the fields run in bf16).

    Args:
        cpuinfo: the kernel's CPU description (Linux); elsewhere ``platform.processor()``.

    Returns:
        ``'<model> (<flags>)'``, the flags among ``avx512_bf16`` and ``amx_bf16`` or ``no bf16``.
    """
    info = Path(cpuinfo).read_text() if Path(cpuinfo).is_file() else ""
    model = next(
        (ln.split(":", 1)[1].strip() for ln in info.splitlines() if "model name" in ln), ""
    )
    flags = [f for f in ("avx512_bf16", "amx_bf16") if f in info.split()]
    return f"{model or platform.processor() or 'unknown CPU'} ({', '.join(flags) or 'no bf16'})"


def git_commit(cwd: str | Path = ".") -> str:
    """The abbreviated hash of ``cwd``'s HEAD, or ``unknown`` outside a checkout.

    A plain hash, never ``git describe``'s ``tag-N-gHASH`` (a clone without the tag cannot
    resolve it) nor a ``-dirty`` suffix ([`git_dirty`][physgs.provenance.git_dirty] says that).

    Args:
        cwd: the directory git runs in.

    Returns:
        The hash (e.g. ``77c3389``), or ``'unknown'`` when git prints nothing.
    """
    out = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=cwd
    )
    return out.stdout.strip() or "unknown"


def git_dirty(cwd: str | Path = ".") -> bool:
    """Whether ``cwd``'s tracked files differ from its HEAD.

    Args:
        cwd: the directory git runs in.

    Returns:
        True when a tracked file is changed (False outside a checkout).
    """
    out = subprocess.run(
        ["git", "status", "--porcelain", "--untracked-files=no"],
        capture_output=True,
        text=True,
        cwd=cwd,
    )
    return bool(out.stdout.strip())
