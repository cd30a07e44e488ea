"""Every configuration key with its type, default, profile values, meaning and what it reruns:
``config/README.md``, generated from the schema's ``description`` and ``x-reruns`` annotations
(``tools/config_reference.py``), so the reference cannot drift from what the schema checks.

Pure: takes the schema and the config file's contents, returns Markdown.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from dataclasses import dataclass

#: Schema keywords rendered into the type column, in this order.
_BOUNDS = (
    ("minimum", "≥"),
    ("exclusiveMinimum", ">"),
    ("maximum", "≤"),
    ("exclusiveMaximum", "<"),
)
#: Object keys whose children get a section of their own (the rest are rows of their parent's).
SECTIONED = ("models",)
#: The section of the top-level keys that are not mappings (seeds, trees, ...).
TOP = "top level"


@dataclass(frozen=True)
class Row:
    """One configuration key.

    Attributes:
        path: dotted key, ``[]`` marking a list's items (``presets.<tree>.levels[].stems``).
        type: the schema's type and bounds in words.
        description: the schema's ``description``.
        reruns: the nearest ``x-reruns`` at or above the key.
    """

    path: str
    type: str
    description: str
    reruns: str


def _resolve(node: Mapping, schema: Mapping) -> Mapping:
    ref = node.get("$ref")
    if ref is None:
        return node
    target: Mapping = schema
    for part in ref.removeprefix("#/").split("/"):
        target = target[part]
    return {**target, **{k: v for k, v in node.items() if k != "$ref"}}


def type_words(node: Mapping, schema: Mapping) -> str:
    """A schema node's type in words: ``integer ≥ 1``, ``one of: rest, frame0``, ``list of ...``.

    Args:
        node: a schema node (a ``$ref`` is resolved against ``schema``).
        schema: the root schema, whose ``$defs`` the references point into.

    Returns:
        The words for the config reference's *type* column.
    """
    node = _resolve(node, schema)
    if "enum" in node:
        return "one of: " + ", ".join(map(str, node["enum"]))
    if "const" in node:
        return f"`{node['const']}`"
    if "oneOf" in node:
        return " or ".join(type_words(n, schema) for n in node["oneOf"])
    t = node.get("type", "any")
    t = " or ".join(map(str, t)) if isinstance(t, list) else str(t)
    if t == "array":
        items = node.get("items", {})
        n_min, n_max = node.get("minItems"), node.get("maxItems")
        size = f" of {n_min}" if n_min is not None and n_min == n_max else ""
        return f"list{size} of " + type_words(items, schema)
    bounds = [f"{sym} {node[k]}" for k, sym in _BOUNDS if k in node]
    return t + (" " + ", ".join(bounds) if bounds else "")


def rows(schema: Mapping) -> Iterator[Row]:
    """Every key of the schema, depth first in the schema's order.

    Args:
        schema: the config schema, annotated (``description``, ``x-reruns``).

    Yields:
        A [`Row`][physgs.config_reference.Row] per key (path, type in words, description, the jobs
            an edit reruns), then the rows of one tree preset under ``presets.<tree>``.

    Raises:
        ValueError: naming every key without a ``description``.
    """
    missing: list[str] = []

    def walk(node: Mapping, path: str, reruns: str) -> Iterator[Row]:
        raw = node
        node = _resolve(node, schema)
        reruns = raw.get("x-reruns", node.get("x-reruns", reruns))
        if path:
            desc = raw.get("description", node.get("description"))
            if not desc:
                missing.append(path)
            yield Row(path, _kind(node, schema), desc or "", reruns)
        if "properties" in node and not _is_preset(raw):
            for k, child in node["properties"].items():
                yield from walk(child, f"{path}.{k}" if path else k, reruns)
        items = node.get("items")
        if isinstance(items, Mapping) and "properties" in _resolve(items, schema):
            for k, child in _resolve(items, schema)["properties"].items():
                yield from walk(child, f"{path}[].{k}", reruns)

    yield from walk(schema, "", "")
    preset = schema["$defs"]["preset"]
    yield from walk({**preset, "description": "a tree preset"}, "presets.<tree>", "")
    if missing:
        raise ValueError(f"config keys without a description in the schema: {missing}")


def _is_preset(node: Mapping) -> bool:
    return node.get("$ref") == "#/$defs/preset"


def _kind(node: Mapping, schema: Mapping) -> str:
    if "properties" in node:
        return "mapping"
    if node.get("type") == "object" or "additionalProperties" in node:
        return "mapping (" + type_words(node.get("additionalProperties", {}), schema) + " values)"
    return type_words(node, schema)


def _get(cfg: Mapping, path: str):
    node = cfg
    for part in path.split("."):
        if not isinstance(node, Mapping) or part not in node:
            return None
        node = node[part]
    return node


def _value(v) -> str:
    if v is None:
        return ""
    return "`" + json.dumps(v, ensure_ascii=False).replace("|", "\\|") + "`"


def reference(schema: Mapping, config: Mapping) -> str:
    """``config/README.md``: a section per top-level key (per model group under ``models``),
    a row per key with its type, default, the quick and paper profiles' values where they set
    one, and its meaning.

    Args:
        schema: the config schema (``physgs/schemas/config.schema.yaml``), annotated.
        config: ``config/trees.yaml`` as read, its ``profiles`` included.

    Returns:
        The page's Markdown text, ending in a newline.
    """
    profiles = config.get("profiles", {}) or {}
    out = [
        "# Configuration reference",
        "",
        "Every key of `config/trees.yaml`, generated from the schema that checks it",
        "(`src/physgs/schemas/config.schema.yaml`) by `python tools/config_reference.py`; a test",
        "holds the two in sync. **default** is the file's value, **quick** and **paper** the",
        "profiles' own where they set one (`--config profile=NAME`). A value given on the command",
        "line (`--config`, `--configfile`) beats the profile's. **Reruns**: the jobs an edit of",
        "the key makes out of date (the rules read only the settings they use).",
        "",
    ]
    sections: dict[str, list[Row]] = {}
    for r in rows(schema):
        sections.setdefault(_section(r.path, r.type), []).append(r)
    for head, members in sections.items():
        first = members[0]
        title = "Top-level keys" if head == TOP else f"`{head}`"
        words = "The run's profile, seeds and trees." if head == TOP else first.description + "."
        section_reruns = "" if head == TOP else first.reruns
        out += ["", f"## {title}", "", words, ""]
        if section_reruns:
            out += [f"**Reruns:** {section_reruns}.", ""]
        body = [r for r in members if not (r.path == head and r.type == "mapping")]
        if not body:
            continue
        out += ["| key | type | default | quick | paper | meaning |", "|---|---|---|---|---|---|"]
        for r in body:
            # a mapping's values are its keys' rows; a tree preset's are in config/trees.yaml
            shown = r.type != "mapping" and "<tree>" not in r.path and r.path != "profiles"
            default, quick, paper = (
                _value(_get(c, r.path)) if shown else ""
                for c in (config, profiles.get("quick") or {}, profiles.get("paper") or {})
            )
            meaning = r.description
            if r.reruns and r.reruns != section_reruns:
                meaning += f". Reruns: {r.reruns}"
            out.append(f"| `{r.path}` | {r.type} | {default} | {quick} | {paper} | {meaning} |")
    return "\n".join(out).replace("\n\n\n", "\n\n") + "\n"


def _section(path: str, kind: str) -> str:
    parts = path.split(".")
    if len(parts) == 1 and not kind.startswith("mapping"):
        return TOP
    if parts[0] in SECTIONED and len(parts) > 1:
        return ".".join(parts[:2])
    if parts[0] == "presets" and len(parts) > 1 and parts[1] == "<tree>":
        return "presets.<tree>"
    return parts[0]
