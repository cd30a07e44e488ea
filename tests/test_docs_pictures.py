"""The documentation's pictures say what the code does: the rule graph is the workflow's."""

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _graph(dot: str) -> tuple[set[str], set[tuple[str, str]]]:
    """Rule names and edges (by name) of a Snakemake rule graph in Graphviz's language."""
    names = dict(re.findall(r"^\s*(\d+)\[label = \"(\w+)\"", dot, re.M))
    edges = {(names[a], names[b]) for a, b in re.findall(r"^\s*(\d+) -> (\d+)", dot, re.M)}
    return set(names.values()), edges


def test_committed_rule_graph_is_the_workflows():
    fresh = subprocess.run(
        ["snakemake", "--rulegraph", "dot", "--cores", "1", "all", "studies"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    committed = (ROOT / "docs" / "img" / "rulegraph.dot").read_text()
    rules, edges = _graph(fresh)
    assert len(rules) > 20 and ("train", "evaluate") in edges  # the parser reads the graph
    assert _graph(committed) == (rules, edges), "rerun `python tools/rulegraph.py`"
    svg = (ROOT / "docs" / "img" / "rulegraph.svg").read_text()
    assert all(f">{r}<" in svg for r in rules), "rulegraph.svg is not rulegraph.dot's drawing"
    assert "img/rulegraph.svg" in (ROOT / "docs" / "protocol.md").read_text()
