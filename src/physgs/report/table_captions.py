"""The study tables' captions: text, kept in ``table_captions.yaml`` beside this module."""

from __future__ import annotations

import re
from importlib import resources

import yaml

#: caption entry -> its LaTeX, a ``<field>`` standing for a value its builder fills in
TEXT = yaml.safe_load(resources.files("physgs.report").joinpath("table_captions.yaml").read_text())


def caption(*names: str, **fields: object) -> str:
    """Caption entries joined by spaces, each ``<field>`` filled in.

    Args:
        *names: entries of ``TEXT``.
        **fields: field -> its value.

    Returns:
        The LaTeX.
    """
    text = " ".join(TEXT[n] for n in names)
    return re.sub(r"<(\w+)>", lambda m: str(fields[m.group(1)]), text)
