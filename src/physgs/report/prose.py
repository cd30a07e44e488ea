"""The sentences of the record's pages, the README's block and the run summary, each written once
in ``prose.yaml`` beside this module (``str.format`` templates), and ``say``, which fills one in.
"""

from __future__ import annotations

from importlib import resources

import yaml


def data(name: str) -> str:
    """A text file of the package's ``report/`` (text, apart from the code that fills it).

    Args:
        name: its path under ``report/``.

    Returns:
        Its text.
    """
    return resources.files("physgs.report").joinpath(name).read_text(encoding="utf-8")


#: name -> a sentence's template, or a list of them (``prose.yaml``)
PROSE: dict = yaml.safe_load(data("prose.yaml"))


def say(name: str, /, **fields: object) -> str:
    """The sentence ``name`` of ``PROSE``, its fields filled in. A field with a clause of its own
    (``<name>_<field>``: a template, or a pair) becomes that clause, filled in, where the field is
    set (non-zero, non-empty), else "" (or the pair's second).

    Args:
        name: the sentence's key.
        **fields: its fields.

    Returns:
        The sentence.
    """
    filled = dict(fields)
    for f, clause in [(f, PROSE.get(f"{name}_{f}")) for f in fields]:
        if clause is not None:
            yes, no = clause if isinstance(clause, list) else (clause, "")
            filled[f] = yes.format(**fields) if fields[f] else no
    return PROSE[name].format(**filled)
