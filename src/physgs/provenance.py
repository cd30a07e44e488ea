"""Which settings made a result: a stamp (profile, resolved-config hash, package version)
written into every table's CSV and the report, so copied results say where they came from."""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass
from importlib.metadata import PackageNotFoundError, version


def package_version() -> str:
    """physgs' installed version ('unknown' when run from a tree that is not installed)."""
    try:
        return version("physgs")
    except PackageNotFoundError:
        return "unknown"


def config_hash(cfg: dict) -> str:
    """12 hex digits of the SHA-256 of the resolved config as canonical JSON (sorted keys), so
    reordering keys keeps the hash and changing any value changes it."""
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
        return asdict(self)


def stamp(cfg: dict) -> Stamp:
    """The stamp of a resolved config (its ``profile`` key names the profile)."""
    return Stamp(str(cfg.get("profile", "unknown")), config_hash(cfg), package_version())
