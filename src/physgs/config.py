"""Configuration: load `config/trees.yaml`, validate it, and resolve a profile.

A profile (``quick`` | ``default`` | ``paper``) is a partial copy of the top-level sections whose
values replace the base ones (deep merge). The resolved config is what every rule and library
function reads; it no longer holds the ``profiles`` table.
"""
from __future__ import annotations

import copy
from pathlib import Path

import jsonschema
import yaml

SCHEMA = Path(__file__).resolve().parents[2] / "workflow" / "schemas" / "config.schema.yaml"


class ConfigError(ValueError):
    """A configuration that cannot be used; the message names the key and the fix."""


def deep_merge(base: dict, override: dict) -> dict:
    """Return ``base`` with ``override`` merged in recursively (override wins on leaves)."""
    out = copy.deepcopy(base)
    for k, v in override.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def validate(cfg: dict, schema_path: Path | str = SCHEMA) -> None:
    """Validate ``cfg`` against the JSON schema; raise ConfigError naming the offending key."""
    with open(schema_path) as f:
        schema = yaml.safe_load(f)
    try:
        jsonschema.validate(cfg, schema)
    except jsonschema.ValidationError as e:
        where = "/".join(str(p) for p in e.absolute_path) or "<top level>"
        raise ConfigError(
            f"config key '{where}': {e.message}. Fix config/trees.yaml (schema: {schema_path})."
        ) from None


def resolve(cfg: dict, profile: str | None = None) -> dict:
    """Merge the chosen profile over the base config and return the resolved config."""
    profile = profile or cfg.get("profile", "default")
    profiles = cfg.get("profiles", {})
    if profile not in profiles:
        raise ConfigError(
            f"unknown profile '{profile}'; choose one of {sorted(profiles)} "
            "(snakemake --config profile=NAME)"
        )
    base = {k: v for k, v in cfg.items() if k != "profiles"}
    out = deep_merge(base, profiles[profile] or {})
    out["profile"] = profile
    return out


def load(path: Path | str, profile: str | None = None) -> dict:
    """Read, validate and resolve a config file."""
    with open(path) as f:
        cfg = yaml.safe_load(f)
    validate(cfg)
    out = resolve(cfg, profile)
    validate(out)
    return out
