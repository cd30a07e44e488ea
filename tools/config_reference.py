"""config/README.md: every configuration key, generated from the schema's annotations.

    python tools/config_reference.py [--check]

Reads `src/physgs/schemas/config.schema.yaml` (each key's `description`, each section's
`x-reruns`) and `config/trees.yaml` (defaults and the profiles' values) and writes
`config/README.md` (`physgs.config_reference.reference`). `--check` writes nothing and exits 1
when the file is out of date. A key without a description stops it, naming the key.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from physgs.config import read_yaml, schema
from physgs.config_reference import reference


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default="config/trees.yaml", type=Path)
    ap.add_argument("--out", default="config/README.md", type=Path)
    ap.add_argument("--check", action="store_true", help="exit 1 if --out is out of date")
    args = ap.parse_args()
    text = reference(schema(), read_yaml(args.config))
    if args.check:
        if not args.out.is_file() or args.out.read_text() != text:
            print(f"{args.out} is out of date: python tools/config_reference.py", file=sys.stderr)
            return 1
        return 0
    args.out.write_text(text)
    print(f"{args.out}: {text.count(chr(10) + '| `')} keys")
    return 0


if __name__ == "__main__":
    sys.exit(main())
