"""The pipeline's rule graph as a picture for the documentation.

    python tools/rulegraph.py [--out docs/img]

Writes `rulegraph.dot` (`snakemake --rulegraph dot all studies`) and `rulegraph.svg` (Graphviz's
`dot`: `apt-get install graphviz`). `tests/test_docs_pictures.py` checks that the committed graph
is the workflow's; rerun this after adding or renaming a rule.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

TARGETS = ("all", "studies")


def rulegraph_dot() -> str:
    """The rule graph of :data:`TARGETS` in Graphviz's language, as Snakemake prints it."""
    out = subprocess.run(
        ["snakemake", "--rulegraph", "dot", "--cores", "1", *TARGETS],
        capture_output=True,
        text=True,
        check=True,
    )
    return out.stdout


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/img", type=Path)
    args = ap.parse_args()
    if shutil.which("dot") is None:
        print("Graphviz's dot is missing: apt-get install graphviz", file=sys.stderr)
        return 2
    dot = rulegraph_dot()
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "rulegraph.dot").write_text(dot)
    svg = subprocess.run(["dot", "-Tsvg"], input=dot, capture_output=True, text=True, check=True)
    (args.out / "rulegraph.svg").write_text(svg.stdout)
    print(f"{args.out}/rulegraph.dot, rulegraph.svg: {dot.count('label = ')} rules")
    return 0


if __name__ == "__main__":
    sys.exit(main())
