"""docs/claims.md's list of claims: generated from the catalogue (`physgs.report.catalogue`).

    python tools/claims_reference.py [--check]

Rewrites the block between `<!-- catalogue:begin -->` and `<!-- catalogue:end -->` of
`docs/claims.md` with `physgs.report.catalogue.markdown()`: one row per claim family (what it is
asked of and ranges over, its sentence, threshold, the cells it reads, the paper's figure and
whether it is the paper's claim or this project's). `--check` writes nothing and exits 1 when the
page is out of date.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from physgs.report import catalogue
from physgs.report.record import replace_block


def render(page: str) -> str:
    """``page`` with its catalogue block replaced by the catalogue's.

    Args:
        page: the claims page's text.

    Returns:
        The new text.

    Raises:
        ValueError: when the page has no catalogue block.
    """
    return replace_block(page, catalogue.markdown(), (catalogue.BEGIN, catalogue.END))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--page", default="docs/claims.md", type=Path)
    ap.add_argument("--check", action="store_true", help="exit 1 if --page is out of date")
    args = ap.parse_args()
    old = args.page.read_text()
    new = render(old)
    if args.check:
        if new != old:
            print(f"{args.page} is out of date: python tools/claims_reference.py", file=sys.stderr)
            return 1
        return 0
    args.page.write_text(new)
    print(f"{args.page}: {len(catalogue.CATALOGUE)} claim families")
    return 0


if __name__ == "__main__":
    sys.exit(main())
