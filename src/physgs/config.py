"""Configuration: load `config/trees.yaml`, validate it, and resolve a profile.

A profile (``quick`` | ``default`` | ``paper``) is a partial copy of the top-level sections whose
values replace the base ones (deep merge). The resolved config is what every rule and library
function reads; it no longer holds the ``profiles`` table.

One entry point does everything, for the Snakefile and for Python alike:
[`load_workflow_config`][physgs.config.load_workflow_config] (or [`load`][physgs.config.load] for a
file) validates the raw config against the packaged schema (``physgs/schemas/config.schema.yaml``;
each profile body against the same schema with every ``required`` dropped,
[`partial_schema`][physgs.config.partial_schema]), resolves the profile, validates the resolved
config, and runs the cross-key checks of [`physgs.config_checks`][physgs.config_checks]. Every
failure is a [`ConfigError`][physgs.config.ConfigError] that names the full key path
(``profiles/quick/trian``), the nearest valid key where one exists, where the value came from and
the fix.

Sources, in order (a later one wins on the leaves it sets): ``config/trees.yaml`` and its chosen
profile, then each ``--configfile`` and the ``--config`` pairs (or a script's ``--set``). What the
command line sets beats the profile: ``--config 'tracks={configs: [single]}'`` means those
configurations under any profile. Numbers are read as YAML 1.2 and Python read them at every depth
and from every source (``1e-3`` is a number; [`scalars`][physgs.config.scalars]), and NaN or
infinity is refused wherever a number is allowed.
"""

from __future__ import annotations

import copy
import difflib
import functools
import math
import re
from collections.abc import Iterator
from importlib import resources
from pathlib import Path

import jsonschema
import yaml

from physgs import config_checks
from physgs.mappings import deep_merge  # noqa: F401 (re-exported: profiles merge with it)

#: The packaged schema (a Traversable; a plain file in any regular install).
SCHEMA = resources.files("physgs").joinpath("schemas", "config.schema.yaml")
#: Where the config normally lives; named in every fix.
DEFAULT_SOURCE = "config/trees.yaml"


class ConfigError(ValueError):
    """A configuration that cannot be used; the message names the key and the fix."""


# --------------------------------------------------------------------------------------------
# Schema


def partial_schema(node, defs: dict | None = None):
    """``node`` with every ``required`` dropped and local ``$ref``s inlined (recursively).

    A profile body overrides only the keys it names, so it is checked against this "partial" form
    of the one schema: types, ranges and unknown keys are still refused, missing keys are not.

    Args:
        node (dict | list | Any): a JSON-schema node (dict), a list of nodes, or a leaf value
            (returned as is).
        defs: the root ``$defs`` the ``$ref``s point into (default: ``node``'s own).

    Returns:
        (dict | list | Any): The node rebuilt without ``required`` and ``$defs`` keys, each
            ``#/$defs/NAME`` reference replaced by the definition merged with the node's other keys.
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
    """The schema in use (a copy): the packaged file with the profile bodies' partial schema.

    Returns:
        A deep copy of the schema dict, so a caller's edits do not reach the cached one.
    """
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


# --------------------------------------------------------------------------------------------
# Scalars as YAML 1.2 and Python read them

#: a decimal number as YAML 1.2's core schema and Python's float() read it (1e-3, .5, 2., -1.0E+6)
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
_INT = re.compile(r"[+-]?\d+")
#: YAML 1.2's and Python's spellings of infinity and NaN (.inf, -.Inf, .nan, inf, nan)
_SPECIAL = re.compile(r"[+-]?\.?(inf|infinity|nan)", re.IGNORECASE)
_BOOL = {"true": True, "True": True, "TRUE": True, "false": False, "False": False, "FALSE": False}
_NULL = ("null", "Null", "NULL", "~")


def scalar(value):
    """A string read as YAML 1.2's core schema and Python read it (anything else unchanged):
    '1e-3' -> 0.001, '3' -> 3, '.nan' -> nan, 'true' -> True, 'null' -> None, 'single' ->
    'single'. PyYAML follows YAML 1.1, where ``1e-3`` (no dot) is a string, and Snakemake hands a
    ``--config`` value's nested scalars over as strings (YAML's BaseLoader).

    Args:
        value (Any): any value; only a ``str`` is read.

    Returns:
        (Any): An ``int``, ``float``, ``bool`` or ``None`` where the stripped string spells one in
            YAML 1.2's core schema, else ``value`` unchanged.
    """
    if not isinstance(value, str):
        return value
    v = value.strip()
    if _INT.fullmatch(v):
        return int(v)
    if _NUMBER.fullmatch(v) or _SPECIAL.fullmatch(v):
        return float(re.sub(r"\.(?=[a-zA-Z])", "", v))  # '.nan', '-.inf' as Python spells them
    if v in _BOOL:
        return _BOOL[v]
    return None if v in _NULL else value


def scalars(value):
    """``value`` with [`scalar`][physgs.config.scalar] applied to every string at every depth (keys
    unchanged).

    Args:
        value (Any): a dict, list, tuple or scalar (tuples come back as lists).

    Returns:
        (Any): The same structure rebuilt with every string leaf passed through
            [`scalar`][physgs.config.scalar].
    """
    if isinstance(value, dict):
        return {k: scalars(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [scalars(v) for v in value]
    return scalar(value)


def check_yaml_syntax(path: Path | str) -> None:
    """Parse a YAML file and refuse it, naming the file, line and column, if it is not YAML.

    Snakemake reads a ``configfile:`` as JSON, then as YAML, and a file that is neither stops with
    "Config file is not valid JSON or YAML ... do not mix whitespace and tab indentation": no
    file, no line, and often not the problem. The Snakefile calls this first, so the error is
    the YAML parser's own, where it found it.

    Args:
        path: the YAML file.

    Raises:
        ConfigError: the file is not valid YAML: ``FILE:LINE:COLUMN`` (from 1) of the problem,
            then the parser's own message, which names the file and quotes the line.
        FileNotFoundError: the file does not exist.
    """
    with open(path, encoding="utf-8") as f:
        try:
            yaml.safe_load(f)  # the parser names the file from the stream
        except yaml.MarkedYAMLError as e:
            mark = e.problem_mark or e.context_mark
            line = f"{path}:{mark.line + 1}:{mark.column + 1}" if mark else f"{path}"
            raise ConfigError(f"{line}: not valid YAML (fix the file there):\n{e}") from None
        except yaml.YAMLError as e:
            raise ConfigError(f"{path}: not valid YAML:\n{e}") from None


def read_yaml(path: Path | str):
    """A config file's contents, numbers read as YAML 1.2 reads them
    ([`scalars`][physgs.config.scalars]).

    Args:
        path: the YAML file.

    Returns:
        (Any): The file's contents (``yaml.safe_load``) with [`scalars`][physgs.config.scalars]
            applied; ``None`` for an empty file.
    """
    with open(path) as f:
        return scalars(yaml.safe_load(f))


def _non_finite(node, path: tuple = ()) -> Iterator[tuple[tuple, float]]:
    """(key path, value) of every NaN or infinite number below ``node``."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _non_finite(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _non_finite(v, path + (i,))
    elif isinstance(node, float) and not math.isfinite(node):
        yield path, node


# --------------------------------------------------------------------------------------------
# Where a value came from


#: (source, values): one command-line source of settings (``--configfile FILE``, ``--config``,
#: ``--set KEY=VALUE``) and the nested values it sets, in the order they apply
Layer = tuple[str, dict]


def _beats_profile(values: dict) -> bool:
    """Whether a layer's values beat the profile's: an overlay does; a file with a ``profiles``
    section is a config file of its own (a copy of config/trees.yaml, say), whose top-level
    values are defaults that the profile overrides, as the base file's are."""
    return "profiles" not in values


def _sets(values, path: tuple) -> bool:
    """Whether nested ``values`` set the leaf at ``path`` (or a whole value above it)."""
    node = values
    for k in path:
        if not isinstance(node, dict) or k not in node:
            return False
        node = node[k]
        if not isinstance(node, dict):
            return True
    return True


def _source_of(path: tuple, layers: list[Layer], base: str) -> str:
    """The last of ``layers`` that sets ``path``, else ``base`` (the config file)."""
    return next((src for src, vals in reversed(layers) if _sets(vals, path)), base)


def _attribute(
    path: tuple, raw: dict | None, profile: str | None, layers: list[Layer], base: str
) -> tuple[str, str]:
    """(' (set by 'profiles/<p>/...')' or '', the source holding the value) for a resolved (or
    raw) config's key path: a command-line layer that sets it wins, then the profile."""
    src = _source_of(path, [(s, v) for s, v in layers if _beats_profile(v)], "")
    if src:
        return "", src
    by = _origin(path, raw, profile)
    if by:
        return by, _source_of(("profiles", profile, *path), layers, base)
    return "", _source_of(path, layers, base)


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
        flow = functools.partial(yaml.safe_dump, default_flow_style=True, width=1000)
        nested_cl = flow(_nest(hits[0][1:], value)).strip()
        override = flow(_nest(("profiles", profile) + hits[0], value)).strip()
        msg += (
            f" --config sets a nested key as a mapping: --config '{hits[0][0]}={nested_cl}' "
            f"(it beats the profile's value); or set "
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


def _line(path: tuple, msg: str, attr: tuple[str, str], base: str) -> tuple[str, str]:
    by, src = attr
    came = f" (from {src})" if src != base else ""
    return f"config key '{_fmt(path)}'{by}{came}: {msg}", src


def _problems(
    cfg: dict, *, raw: dict | None, profile: str | None, source: str, layers: list[Layer]
) -> list[tuple[str, str]]:
    """(line, source) of every problem: schema violations and non-finite numbers."""
    root = _schema()
    cls = jsonschema.validators.validator_for(root)
    errors = sorted(cls(root).iter_errors(cfg), key=lambda e: [str(p) for p in e.absolute_path])
    lines: list[tuple[str, str]] = []
    for e in errors:
        where = tuple(e.absolute_path)
        if e.validator == "additionalProperties" and e.validator_value is False:
            for key in e.instance:
                if not _declared(key, e.schema):
                    src = _source_of(where + (key,), layers, source)
                    lines.append(
                        (
                            _unknown_key(
                                where, key, e.schema, e.instance, raw if raw is cfg else None, src
                            ),
                            src,
                        )
                    )
        elif e.validator == "required":
            for key in e.validator_value:
                if isinstance(e.instance, dict) and key not in e.instance:
                    lines.append((f"config key '{_fmt(where + (key,))}' is missing", source))
        else:
            attr = _attribute(where, raw, profile, layers, source)
            lines.append(_line(where, e.message, attr, source))
    for path, v in _non_finite(cfg):
        attr = _attribute(path, raw, profile, layers, source)
        lines.append(
            _line(path, f"{v} is not a finite number (NaN and infinity are refused)", attr, source)
        )
    return list(dict.fromkeys(lines))  # one line per problem, in order


def _raise(lines: list[tuple[str, str]], source: str, profile: str | None) -> None:
    if not lines:
        return
    fix = " and ".join(dict.fromkeys(src for _, src in lines))
    if len(lines) == 1:
        raise ConfigError(f"{lines[0][0]}\nFix {fix}.")
    where = source + (f" (profile '{profile}')" if profile else "")
    items = "\n".join(f"  - {ln}" for ln, _ in lines)
    raise ConfigError(f"{len(lines)} problems in {where}:\n{items}\nFix {fix}.")


def validate(
    cfg: dict,
    *,
    raw: dict | None = None,
    source: str = DEFAULT_SOURCE,
    layers: list[Layer] = (),
) -> None:
    """Validate ``cfg`` (raw, with ``profiles``, or resolved) against the packaged schema and
    refuse NaN and infinity wherever they stand.

    Args:
        cfg: the config to check.
        raw: the raw config ``cfg`` was resolved from, to say which values a profile set;
            None when ``cfg`` is itself the raw config.
        source: the file named in messages as where the values came from.
        layers: the command-line sources over ``source``, each ``(name, values)``.

    Raises:
        ConfigError: naming every offending key path, where its value came from and the fix; an
            unknown key gets the nearest valid one. Also when ``cfg`` is not a mapping.
    """
    if not isinstance(cfg, dict):
        raise ConfigError(
            f"{source} must hold a mapping of settings, got {type(cfg).__name__}. Fix {source}."
        )
    profile = cfg.get("profile") if raw is not None else None
    _raise(
        _problems(
            cfg,
            raw=raw if raw is not None else cfg,
            profile=profile,
            source=source,
            layers=list(layers),
        ),
        source,
        profile,
    )


def check(
    cfg: dict,
    *,
    raw: dict | None = None,
    source: str = DEFAULT_SOURCE,
    layers: list[Layer] = (),
) -> None:
    """Run the cross-key checks (``physgs.config_checks.CHECKS``) on a resolved config.

    Args:
        cfg: the resolved config.
        raw: the raw config it was resolved from, to attribute a value to its profile.
        source: the file named in messages as where the values came from.
        layers: the command-line sources over ``source``, each ``(name, values)``.

    Raises:
        ConfigError: naming every problem's key path, its source and the fix.
    """
    profile = cfg.get("profile")
    flags = [(s, v) for s, v in layers if _beats_profile(v)]
    lines = []
    for path, msg, read in _problems_and_reads(cfg):
        line, src = _line(
            tuple(path), msg, _attribute(tuple(path), raw, profile, list(layers), source), source
        )
        # a cross-key problem can come from another key than the one to change: name what the
        # command line set among the keys its check read (--set train.iterations=20 against the
        # profile's warm-up is the command line's doing, not config/trees.yaml's)
        named = [(p, _source_of(p, flags, "")) for p in read if p != tuple(path)]
        named = [(p, s) for p, s in named if s and s != src]
        if named:
            said = ", ".join(f"{_fmt(p)} = {_value_at(cfg, p)} from {s}" for p, s in named)
            line = f"{line} (with {said})"
            src = " or ".join(dict.fromkeys([*(s for _, s in named), src]))
        lines.append((line, src))
    _raise(lines, source, profile)


class _Reads(dict):
    """A config mapping that records the key path of every leaf read through it: what a
    cross-key check looked at."""

    def __init__(self, d: dict, path: tuple, log: dict):
        super().__init__(d)
        self._path, self._log = path, log

    def __getitem__(self, k):
        v, p = super().__getitem__(k), self._path + (k,)
        if isinstance(v, dict):
            return _Reads(v, p, self._log)
        self._log[p] = None  # ordered, once
        return v

    def get(self, k, default=None):
        return self[k] if k in self else default


def _problems_and_reads(cfg: dict) -> Iterator[tuple[tuple, str, list[tuple]]]:
    """Each problem of ``config_checks.CHECKS`` with the key paths its check had read by then."""
    for chk in config_checks.CHECKS:
        log: dict = {}
        for path, msg in chk(_Reads(cfg, (), log)):
            yield tuple(path), msg, list(log)


def _value_at(cfg: dict, path: tuple):
    for k in path:
        cfg = cfg[k]
    return cfg


# --------------------------------------------------------------------------------------------
# Profiles and the entry points


def resolve(cfg: dict, profile: str | None = None) -> dict:
    """Merge the chosen profile over the base config and return the resolved config.

    Args:
        cfg: the raw config, with its ``profiles`` section.
        profile: the profile to apply; None: ``cfg['profile']``, else ``default``.

    Returns:
        The base config without ``profiles``, the profile's body deep-merged over it, and
            ``profile`` set to the chosen name.

    Raises:
        ConfigError: for a profile that ``profiles`` does not hold (with the nearest name).
    """
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


def load_workflow_config(
    config: dict,
    profile: str | None = None,
    *,
    source: str = DEFAULT_SOURCE,
    command_line: dict | None = None,
    configfiles=(),
) -> dict:
    """The one way in: validate a raw config, resolve its profile, put the command line over it,
    validate and check the result.

    Whatever ``configfiles`` and ``command_line`` set, at any depth, beats the profile's value
    (``--config 'tracks={configs: [single]}'`` fits single only under any profile), except in a
    ``--configfile`` that holds a ``profiles`` section: such a file is a config of its own
    (``--configfile config/trees.yaml`` is the base again), merged under the profile. Every number
    is read as YAML 1.2 reads it ([`scalars`][physgs.config.scalars]), and a problem names the
    source that holds the bad value.

    Args:
        config: the raw config (what Snakemake's ``config`` holds: ``config/trees.yaml`` with any
            ``--configfile`` and ``--config`` merged in).
        profile: overrides ``config['profile']``.
        source: the file named in messages as where the values came from.
        command_line: the ``--config KEY=VALUE`` pairs (Snakemake's
            ``workflow.config_settings.config``).
        configfiles (Iterable[str | Path]): the ``--configfile`` paths (Snakemake's
            ``workflow.config_settings.configfiles``), read again here as YAML 1.2.

    Returns:
        The resolved config.

    Raises:
        ConfigError: before anything runs, naming every bad key and its source.
    """
    layers: list[Layer] = [(f"--configfile {p}", read_yaml(p) or {}) for p in configfiles]
    if command_line:
        layers.append(("--config", scalars(dict(command_line))))
    if not isinstance(config, dict):
        validate(config, source=source)
    config = scalars(config)
    for _, values in layers:
        config = deep_merge(config, values)
    if profile is not None:
        config = {**config, "profile": profile}
    validate(config, source=source, layers=layers)
    resolved = resolve(config, config.get("profile"))
    for _, values in layers:  # the command line beats the profile
        if _beats_profile(values):
            resolved = deep_merge(resolved, {k: v for k, v in values.items() if k != "profile"})
    validate(resolved, raw=config, source=source, layers=layers)
    check(resolved, raw=config, source=source, layers=layers)
    return resolved


def load(path: Path | str, profile: str | None = None) -> dict:
    """Read, validate, resolve and check a config file.

    Args:
        path: the YAML file (read as YAML 1.2).
        profile: overrides the file's ``profile``.

    Returns:
        The resolved config.

    Raises:
        ConfigError: the config is invalid (the message names the key and the fix).
    """
    return load_workflow_config(read_yaml(path), profile, source=str(path))


def apply_overrides(cfg: dict, assignments: list[str]) -> dict:
    """A resolved config with ``KEY.PATH=VALUE`` overrides (a script's ``--set``) applied, then
    validated against the schema and the cross-key checks exactly as the config is: an unknown key,
    a value of the wrong type or a NaN is refused with the key and its ``--set`` named, before any
    work. VALUE is read as YAML 1.2 and Python read it (``1e-3`` is a number).

    Args:
        cfg: a resolved config (not modified: a deep copy is returned).
        assignments: ``KEY.PATH=VALUE`` strings, dots between keys.

    Returns:
        The overridden, validated config.

    Raises:
        ConfigError: for an assignment without ``=`` or a key, a path through a key that is not a
            section, or a result the schema or the cross-key checks refuse.
    """
    out = copy.deepcopy(cfg)
    layers: list[Layer] = []
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
        node[last] = scalars(yaml.safe_load(value))
        layers.append((f"--set {a}", _nest([*path, last], node[last])))
    source = f"{DEFAULT_SOURCE} (profile '{cfg.get('profile')}')"
    validate(out, source=source, layers=layers)
    check(out, source=source, layers=layers)
    return out


def study_seeds(cfg: dict) -> list[int]:
    """The training seeds the studies of the trade (speed-accuracy sweep, fit curve) run at:
    ``speed_accuracy.seeds`` of a resolved config ('first' = the first of ``seeds``, 'all' =
    every one, or a list from ``seeds``, which the config checks enforce).

    Args:
        cfg: a resolved config.

    Returns:
        The seeds, in the order of ``seeds`` for 'first' and 'all', else in the listed order.
    """
    seeds = [int(s) for s in cfg["seeds"]]
    v = cfg["speed_accuracy"]["seeds"]
    if v == "first":
        return seeds[:1]
    if v == "all":
        return seeds
    return [int(s) for s in v]
