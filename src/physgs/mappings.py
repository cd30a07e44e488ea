"""Nested mappings merged: the config's profiles and a tree's recipe over the shared settings."""

from __future__ import annotations

import copy


def deep_merge(base: dict, override: dict) -> dict:
    """Return ``base`` with ``override`` merged in recursively (override wins on leaves).

    Args:
        base: the mapping merged into (not modified: a deep copy is returned).
        override: the mapping whose values win; a dict under a key that is a dict in ``base`` too
            is merged key by key, anything else replaces ``base``'s value.

    Returns:
        A new dict: ``base`` deep-copied with ``override`` merged in.
    """
    out = copy.deepcopy(base)
    for k, v in override.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out
