"""The caption of every figure the record shows: what it shows, how to read it, and its seeds.

What a figure shows and how to read it is written once per figure, in ``captions.yaml`` beside this
module (it describes the drawing code, not a result); its seeds come from its output's declaration
(``physgs.report.outputs.OUTPUTS[name].seeds``, else the caption's own ``seeds``) and the record's
stamp, so a caption never retypes a number of the run. ``FIGURES`` orders the figures as a results
section reads them: the headline comparison first, the testbed last.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from importlib import resources

import yaml

from physgs.report.outputs import OUTPUTS


#: The figures in reading order (``captions.yaml``: text, kept apart from the code that reads it),
#: each ``pattern`` (its name, ``{tree}`` standing for a tree), ``title`` (a few words), ``shows``
#: (what is drawn: every colour, band, line and unit), ``read`` (how to read it) and ``seeds`` (its
#: seed scope when it is not a report output: ``physgs.report.output.SEEDS``).
def checked(entries: list[dict]) -> tuple[dict, ...]:
    """Captions as ``FIGURES`` holds them: the seed scope defaulted, a wrong key refused.

    Args:
        entries: the entries of ``captions.yaml``.

    Returns:
        The entries, each with ``seeds``.

    Raises:
        ValueError: naming an entry that lacks a key or has one no caption reads.
    """
    need, keys = (
        {"pattern", "title", "shows", "read"},
        {"pattern", "title", "shows", "read", "seeds"},
    )
    for c in entries:
        if not need <= set(c) <= keys:
            raise ValueError(
                f"captions.yaml: {c.get('pattern')!r} has keys {sorted(c)}: {sorted(keys)}"
            )
    return tuple({"seeds": "first", **c} for c in entries)


FIGURES: tuple[dict, ...] = checked(
    yaml.safe_load(resources.files("physgs.report").joinpath("captions.yaml").read_text())
)
#: each figure's index and name as a regular expression (a tree: the group ``tree``), in the order
#: ``find`` tries them: the plain names, then the per-tree ones, the longer first
_NAMES = [
    (i, re.compile(re.escape(p).replace(r"\{tree\}", "(?P<tree>[a-z0-9_]+?)") + "$"))
    for i, p in sorted(
        enumerate(c["pattern"] for c in FIGURES), key=lambda ip: ("{" in ip[1], -len(ip[1]))
    )
]


def find(name: str) -> tuple[int, dict, str]:
    """The caption of figure ``name``, its place in ``FIGURES`` and its tree.

    Per-tree patterns are tried after the plain names, the longer first, so that
    ``testbed_medium_damping`` is the damping testbed's, not a tree ``medium_damping``'s.

    Args:
        name: the figure's file stem.

    Returns:
        ``(index, caption, tree)``: the tree '' when the caption's pattern has none.

    Raises:
        KeyError: naming a figure without a caption.
    """
    for i, rx in _NAMES:
        if m := rx.match(name):
            return i, FIGURES[i], m.groupdict().get("tree") or ""
    raise KeyError(f"figure {name!r} has no caption: add it to physgs.report.captions.FIGURES")


def _seeds(what: str, seeds: list[int]) -> str:
    """The seeds a figure of seed scope ``what`` draws, in words."""
    if what == "all" and len(seeds) == 1:
        return f"training seed {seeds[0]} (the run's one seed)"
    if what == "all":
        return f"mean over training seeds {', '.join(map(str, seeds))}"
    if what == "first":
        return f"training seed {seeds[0]} (the first of the run's {len(seeds)})"
    return "the testbed itself: no training seed" if what == "none" else "the studies' seeds"


def caption(name: str, seeds: Sequence[int]) -> str:
    """The Markdown caption of figure ``name`` in a run of training ``seeds``.

    Args:
        name: the figure's file stem.
        seeds: the run's training seeds (its stamp's).

    Returns:
        One paragraph: title, what it shows, how to read it, its seeds.
    """
    _, c, tree = find(name)
    what = OUTPUTS[c["pattern"]].seeds if c["pattern"] in OUTPUTS else c["seeds"]
    title, shows, read = (c[k].format(tree=tree) for k in ("title", "shows", "read"))
    return (
        f"**Figure: {title}** (`{name}`). {shows} "
        f"*How to read it:* {read} *Seeds:* {_seeds(what, list(seeds))}."
    )


def order(names: Sequence[str], trees: Sequence[str] = ()) -> list[str]:
    """``names`` in reading order: by their caption's place in ``FIGURES``, then per-tree
    figures in the run's order of trees, then by name.

    Args:
        names: figure file stems.
        trees: the run's trees, in order.

    Returns:
        The same names, ordered.

    Raises:
        KeyError: naming a figure without a caption.
    """
    rank = {t: i for i, t in enumerate(trees)}

    def key(n: str) -> tuple[int, int, str]:
        i, _, tree = find(n)
        return i, rank.get(tree, len(rank)), n

    return sorted(names, key=key)
