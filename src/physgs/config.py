"""Configuration: load `config/trees.yaml`, validate it, and resolve a profile.

A profile (``quick`` | ``default`` | ``paper``) is a partial copy of the top-level sections whose
values replace the base ones (deep merge). The resolved config is what every rule and library
function reads; it no longer holds the ``profiles`` table.

One entry point does everything, for the Snakefile and for Python alike:
:func:`load_workflow_config` (or :func:`load` for a file) validates the raw config against the
packaged schema (``physgs/schemas/config.schema.yaml``; each profile body against the same schema
with every ``required`` dropped, :func:`partial_schema`), resolves the profile, validates the
resolved config, and runs the cross-key checks of :mod:`physgs.config_checks`. Every failure is a
:class:`ConfigError` that names the full key path (``profiles/quick/trian``), the nearest valid key
where one exists, and the fix.
"""

from __future__ import annotations

import copy
import difflib
import functools
import re
from importlib import resources
from pathlib import Path

import jsonschema
import yaml

from physgs import config_checks

#: The packaged schema (a Traversable; a plain file in any regular install).
SCHEMA = resources.files("physgs").joinpath("schemas", "config.schema.yaml")
#: Where the config normally lives; named in every fix.
DEFAULT_SOURCE = "config/trees.yaml"


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


# --------------------------------------------------------------------------------------------
# Schema


def partial_schema(node, defs: dict | None = None):
    """``node`` with every ``required`` dropped and local ``$ref``s inlined (recursively).

    A profile body overrides only the keys it names, so it is checked against this "partial" form
    of the one schema: types, ranges and unknown keys are still refused, missing keys are not.
    ``defs``: the root ``$defs`` the ``$ref``s point into (default: ``node``'s own).
    """
    if defs is None and isinstance(node, dict):
        defs = node.get("$defs", {})
    if isinstance(node, dict):
        ref = node.get("$ref")
        if isinstance(ref, str) and ref.startswith("#/$defs/"):
            merged = {**defs[ref.split("/")[-1]], **{k: v for k, v in node.items() if k != "$ref"}}
            return partial_schema(merged, defs)
        return {
            k: partial_schema(v, defs) for k, v in node.items() if k not in ("required", "$defs")
        }
    if isinstance(node, list):
        return [partial_schema(v, defs) for v in node]
    return node


@functools.lru_cache(maxsize=1)
def _schema() -> dict:
    with SCHEMA.open("r") as f:
        schema = yaml.safe_load(f)
    body = copy.deepcopy(schema)
    for k in ("profile", "profiles"):  # a profile cannot choose or define profiles
        body["properties"].pop(k)
    profile = partial_schema(body)
    profile["type"] = ["object", "null"]  # `default: ` (empty) is a profile that changes nothing
    profile.pop("$schema", None)
    schema["properties"]["profiles"]["additionalProperties"] = profile
    return schema


def schema() -> dict:
    """The schema in use (a copy): the packaged file with the profile bodies' partial schema."""
    return copy.deepcopy(_schema())


def _deref(node: dict, root: dict) -> dict:
    ref = node.get("$ref") if isinstance(node, dict) else None
    if isinstance(ref, str) and ref.startswith("#/$defs/"):
        return root["$defs"][ref.split("/")[-1]]
    return node if isinstance(node, dict) else {}


def _nested_paths(node: dict, root: dict, prefix: tuple = (), depth: int = 0) -> list[tuple]:
    """Every key path below an object schema node (maps of names shown as ``<name>``)."""
    node = _deref(node, root)
    out = []
    if depth > 6:
        return out
    children = dict(node.get("properties", {}))
    for pat, sub in node.get("patternProperties", {}).items():  # the names it requires, or <name>
        names = [r for r in node.get("required", []) if re.search(pat, r)] or ["<name>"]
        children.update({n: sub for n in names if n not in children})
    if isinstance(node.get("additionalProperties"), dict) and not children:
        children = {"<name>": node["additionalProperties"]}
    for k, sub in children.items():
        out.append(prefix + (k,))
        out += _nested_paths(sub, root, prefix + (k,), depth + 1)
    return out


def _declared(key: str, node: dict) -> bool:
    """Whether an object schema node declares ``key`` (properties or patternProperties)."""
    return key in node.get("properties", {}) or any(
        re.search(pat, key) for pat in node.get("patternProperties", {})
    )


def _fmt(path) -> str:
    return "/".join(str(p) for p in path) or "<top level>"


def _nest(path, value):
    for k in reversed(list(path)):
        value = {k: value}
    return value


def _unknown_key(
    where: tuple, key: str, node: dict, instance: dict, raw: dict | None, source: str
) -> str:
    """Message for an unknown ``key`` in the object at ``where`` whose schema is ``node``."""
    root = _schema()
    node = _deref(node, root)
    path = where + (key,)
    msg = f"unknown config key '{_fmt(path)}'"
    siblings = [p[0] for p in _nested_paths(node, root) if len(p) == 1 and p[0] != "<name>"]
    # a key that lives deeper (`iterations` -> train/iterations), else a misspelt sibling, else a
    # misspelt deeper key
    nested = [
        p
        for p in _nested_paths(node, root)
        if len(p) > 1 and not (not where and p[0] == "profiles")
    ]
    hits = [p for p in nested if p[-1] == key]
    if not hits:
        close = difflib.get_close_matches(key, siblings, n=1, cutoff=0.6)
        if close:
            return msg + f": did you mean '{_fmt(where + (close[0],))}'?"
        names = sorted({p[-1] for p in nested})
        near = difflib.get_close_matches(key, names, n=1, cutoff=0.75)
        hits = [p for p in nested if near and p[-1] == near[0]]
    if not hits:
        valid = ", ".join(siblings) if siblings else "none"
        return msg + f" (valid keys here: {valid})"
    hits.sort(key=len)
    msg += f": did you mean '{_fmt(where + hits[0])}'"
    if len(hits) > 1:
        msg += " (or " + ", ".join(f"'{_fmt(where + h)}'" for h in hits[1:]) + ")"
    msg += "?"
    if not where and raw is not None:  # the raw config's top level is where --config lands
        profile = raw.get("profile", "default")
        value = instance.get(key)
        override = yaml.safe_dump(
            _nest(("profiles", profile) + hits[0], value), default_flow_style=True, width=1000
        ).strip()
        msg += (
            f" --config KEY=VALUE sets top-level keys only (profile, seed, ...); set "
            f"'{_fmt(('profiles', profile) + hits[0])}' in {source}, or pass "
            f"--configfile FILE with FILE holding {override}"
        )
    return msg


def _origin(path: tuple, raw: dict | None, profile: str | None) -> str:
    """' (set by profiles/<p>/...)' when the resolved value at ``path`` comes from the profile."""
    if raw is None or profile is None:
        return ""
    node = (raw.get("profiles") or {}).get(profile)
    for i, k in enumerate(path):
        if not isinstance(node, dict) or k not in node:
            return ""
        node = node[k]
        if not isinstance(node, dict):  # a leaf (or a whole list) the profile replaces
            return f" (set by '{_fmt(('profiles', profile) + tuple(path[: i + 1]))}')"
    return f" (set by '{_fmt(('profiles', profile) + tuple(path))}')"


def _problems(cfg: dict, *, raw: dict | None, profile: str | None, source: str) -> list[str]:
    root = _schema()
    cls = jsonschema.validators.validator_for(root)
    errors = sorted(cls(root).iter_errors(cfg), key=lambda e: [str(p) for p in e.absolute_path])
    lines: list[str] = []
    for e in errors:
        where = tuple(e.absolute_path)
        if e.validator == "additionalProperties" and e.validator_value is False:
            for key in e.instance:
                if not _declared(key, e.schema):
                    lines.append(
                        _unknown_key(
                            where, key, e.schema, e.instance, raw if raw is cfg else None, source
                        )
                    )
        elif e.validator == "required":
            for key in e.validator_value:
                if isinstance(e.instance, dict) and key not in e.instance:
                    lines.append(f"config key '{_fmt(where + (key,))}' is missing")
        else:
            lines.append(f"config key '{_fmt(where)}'{_origin(where, raw, profile)}: {e.message}")
    return list(dict.fromkeys(lines))  # one line per problem, in order


def _raise(lines: list[str], source: str, profile: str | None) -> None:
    if not lines:
        return
    if len(lines) == 1:
        raise ConfigError(f"{lines[0]}\nFix {source}.")
    where = source + (f" (profile '{profile}')" if profile else "")
    items = "\n".join(f"  - {ln}" for ln in lines)
    raise ConfigError(f"{len(lines)} problems in {where}:\n{items}\nFix {source}.")


def validate(cfg: dict, *, raw: dict | None = None, source: str = DEFAULT_SOURCE) -> None:
    """Validate ``cfg`` (raw, with ``profiles``, or resolved) against the packaged schema.

    Raise ConfigError naming every offending key path; an unknown key gets the nearest valid one.
    ``raw``: the raw config ``cfg`` was resolved from, to say which values a profile set.
    """
    if not isinstance(cfg, dict):
        raise ConfigError(
            f"{source} must hold a mapping of settings, got {type(cfg).__name__}. Fix {source}."
        )
    profile = cfg.get("profile") if raw is not None else None
    _raise(
        _problems(cfg, raw=raw if raw is not None else cfg, profile=profile, source=source),
        source,
        profile,
    )


def check(cfg: dict, *, raw: dict | None = None, source: str = DEFAULT_SOURCE) -> None:
    """Run the cross-key checks (:data:`physgs.config_checks.CHECKS`) on a resolved config."""
    profile = cfg.get("profile")
    lines = [
        f"config key '{_fmt(path)}'{_origin(path, raw, profile)}: {msg}"
        for path, msg in config_checks.problems(cfg)
    ]
    _raise(lines, source, profile)


# --------------------------------------------------------------------------------------------
# Profiles and the entry points


def resolve(cfg: dict, profile: str | None = None) -> dict:
    """Merge the chosen profile over the base config and return the resolved config."""
    profile = profile or cfg.get("profile", "default")
    profiles = cfg.get("profiles") or {}
    if profile not in profiles:
        near = difflib.get_close_matches(str(profile), list(profiles), n=1)
        hint = f" (did you mean '{near[0]}'?)" if near else ""
        raise ConfigError(
            f"unknown profile '{profile}'{hint}; choose one of {sorted(profiles)} "
            "(snakemake --config profile=NAME)"
        )
    base = {k: v for k, v in cfg.items() if k != "profiles"}
    out = deep_merge(base, profiles[profile] or {})
    out["profile"] = profile
    return out


_INT = re.compile(r"[+-]?\d+")


def _from_command_line(value):
    """A ``--config`` value as the YAML file would hold it: Snakemake parses a list value with
    YAML's BaseLoader, so ``seeds=[0,1]`` arrives as ['0', '1']; integer strings become ints
    (anything else, '1.5' or 'a', stays a string for the schema to refuse)."""
    if isinstance(value, str) and _INT.fullmatch(value.strip()):
        return int(value)
    if isinstance(value, (list, tuple)):
        return [_from_command_line(v) for v in value]
    return value


def load_workflow_config(
    config: dict,
    profile: str | None = None,
    *,
    source: str = DEFAULT_SOURCE,
    command_line: dict | None = None,
) -> dict:
    """The one way in: validate a raw config, resolve its profile, validate and check the result.

    config: the raw config (what Snakemake's ``config`` holds: ``config/trees.yaml`` plus any
    ``--config KEY=VALUE``, which arrive as top-level keys); profile: overrides
    ``config['profile']``; command_line: the command line's own overrides (Snakemake's
    ``workflow.config_settings.config``, the ``--config KEY=VALUE`` pairs only): their top-level
    values that are not sections (``seeds``, ``seed``, ...) beat the profile's, so ``--config
    seeds=[0,1,2]`` means those seeds under any profile. Returns the resolved config; raises
    ConfigError before anything runs.
    """
    cl = {
        k: _from_command_line(v)
        for k, v in dict(command_line or {}).items()
        if k != "profile" and not isinstance(v, dict)
    }
    if profile is not None and isinstance(config, dict):
        config = {**config, "profile": profile}
    if cl and isinstance(config, dict):
        config = {**config, **cl}
    validate(config, source=source)
    resolved = resolve(config, config.get("profile"))
    resolved.update(copy.deepcopy(cl))
    validate(resolved, raw=config, source=source)
    check(resolved, raw=config, source=source)
    return resolved


def load(path: Path | str, profile: str | None = None) -> dict:
    """Read, validate, resolve and check a config file."""
    with open(path) as f:
        cfg = yaml.safe_load(f)
    return load_workflow_config(cfg, profile, source=str(path))


_NUMBER_LIKE = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def apply_overrides(cfg: dict, assignments: list[str]) -> dict:
    """A resolved config with ``KEY.PATH=VALUE`` overrides (a script's ``--set``) applied, then
    validated against the schema and the cross-key checks exactly as the config is: an unknown key
    or a value of the wrong type is refused with the key and the ``--set`` named, before any work.

    VALUE is read as YAML, as the config file is (so ``1e6`` is the string '1e6', which a number
    key refuses; the message says to write ``1.0e+6``)."""
    out = copy.deepcopy(cfg)
    for a in assignments:
        key, eq, value = a.partition("=")
        if not eq or not key.strip():
            raise ConfigError(f"--set {a!r}: expected KEY.PATH=VALUE (e.g. train.iterations=300)")
        *path, last = key.strip().split(".")
        node = out
        for i, k in enumerate(path):
            if not isinstance(node.get(k), dict):
                where = "/".join(path[: i + 1])
                raise ConfigError(f"--set {a!r}: config key '{where}' is not a section")
            node = node[k]
        node[last] = yaml.safe_load(value)
    source = "the --set overrides " + " ".join(assignments)
    try:
        validate(out, source=source)
        check(out, source=source)
    except ConfigError as err:
        hints = [
            f" ('{v}' is read as a string, as in YAML 1.1; write a number as 1.0e+6)"
            for v in (a.partition("=")[2].strip() for a in assignments)
            if _NUMBER_LIKE.fullmatch(v) and isinstance(yaml.safe_load(v), str)
        ]
        raise ConfigError(f"{err}{hints[0] if hints else ''}") from None
    return out


def study_seeds(cfg: dict) -> list[int]:
    """The training seeds the studies of the trade (speed-accuracy sweep, fit curve) run at:
    ``speed_accuracy.seeds`` of a resolved config ('first' = the first of ``seeds``, 'all' =
    every one, or a list from ``seeds``, which the config checks enforce)."""
    seeds = [int(s) for s in cfg["seeds"]]
    v = cfg["speed_accuracy"]["seeds"]
    if v == "first":
        return seeds[:1]
    if v == "all":
        return seeds
    return [int(s) for s in v]
