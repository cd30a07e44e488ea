"""Re-read a committed record's ledger with today's claims code, without a new run.

    python tools/reread_claims.py [--record docs/record]

The claims a table decides are measured again from the record's per-seed tables
(`tables/*.csv`, the ledger's own code: `physgs.report.claims.measure`); the claims read from
the recovery records (the damping summaries, not committed) are decided again from the
record's own estimate and interval (`claims.decide`), the same numbers under today's test (an
equivalence band where a family is one). Prints every verdict that moves, the claims only one
side has, and whether the paper's figures lie inside the measured intervals. Writes nothing:
the record stays what its run made.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd
import yaml

from physgs.report import catalogue, claims
from physgs.report.build import read_table
from physgs.report.claim_cells import RECOVERY, roles_of

ROOT = Path(__file__).resolve().parents[1]


def _spec(cid: str) -> catalogue.ClaimSpec | None:
    """The family of a claim id (``[<prior>/]<family>[/<cell>]``)."""
    parts = cid.split("/")
    for prior in (False, True):
        fam = parts[1] if prior and len(parts) > 1 else parts[0]
        for s in catalogue.CATALOGUE:
            if s.family == fam and (s.of == "priors") == prior:
                return s
    return None


def reread(record: Path, roles: dict) -> pd.DataFrame:
    """The record's ledger beside today's verdicts on the same evidence.

    Args:
        record: the record's folder (``claims.csv``, ``tables/``).
        roles: tree -> its preset's role.

    Returns:
        One row per claim id of either: ``id``, ``old``, ``new`` verdicts, ``from`` (tables
            or interval), ``paper_in_interval``.
    """
    old = pd.read_csv(record / "claims.csv")
    trees = list(dict.fromkeys(t for t in roles if (old["id"].str.contains(f"/{t}")).any()))
    tabs = {}
    for n in catalogue.tables():
        p = record / "tables" / f"{n}.csv"
        if p.exists():
            tabs[n] = read_table(n, p)
    new = claims.ledger(claims.measure(tabs, {}, trees, roles=roles)).set_index("id")
    rows = []
    for _, r in old.iterrows():
        spec = _spec(str(r["id"]))
        if spec is not None and spec.table == RECOVERY:  # no records: the record's interval
            tree = str(r["id"]).split("/")[-1]
            paper_tree = roles.get(tree, {}).get("paper")
            c = claims.Claim(
                r["id"], "", "", "", spec.value, spec.side, spec.unit, spec.needs_variance,
                paper_value=spec.value_of_paper({"paper": paper_tree}),
            )  # fmt: skip
            v = claims.decide(c, r["measured"], r["ci_low"], r["ci_high"], int(r["seeds"]))
            size = claims.paper_in_interval(c, r["ci_low"], r["ci_high"])
            rows.append((r["id"], r["verdict"], v, "interval", size))
        elif r["id"] in new.index:
            n = new.loc[r["id"]]
            rows.append((r["id"], r["verdict"], n["verdict"], "tables", n["paper_in_interval"]))
        else:
            rows.append((r["id"], r["verdict"], "", "gone", ""))
    for i in new.index.difference(old["id"]):
        rows.append((i, "", new.loc[i, "verdict"], "tables", new.loc[i, "paper_in_interval"]))
    return pd.DataFrame(rows, columns=["id", "old", "new", "from", "paper_in_interval"])


def main() -> int:
    """Print the verdicts that move and the paper's figures against the intervals."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--record", type=Path, default=ROOT / "docs" / "record")
    args = ap.parse_args()
    cfg = yaml.safe_load((ROOT / "config" / "trees.yaml").read_text())
    df = reread(args.record, roles_of(cfg["presets"], list(cfg["presets"])))
    kind = lambda v: str(v).split(":")[0]
    moved = df[(df["old"] != "") & (df["new"] != "") & (df["old"].map(kind) != df["new"].map(kind))]
    print(f"{len(df)} claims; {len(moved)} verdicts move:")
    for _, r in moved.iterrows():
        print(f"  {r['id']}: {r['old']} -> {r['new']} (from the {r['from']})")
    added = df[df["old"] == ""]
    print(
        f"new claims ({len(added)}): " + ", ".join(f"{i} {v}" for i, v in zip(added.id, added.new))
    )
    kinds = df["new"].map(kind).value_counts().to_dict()
    print("verdicts now: " + ", ".join(f"{k} {v}" for k, v in sorted(kinds.items())))
    size = df["paper_in_interval"].fillna("").value_counts().to_dict()
    print(
        f"the paper's figure inside the interval: {size.get('inside', 0)}, outside: "
        f"{size.get('outside', 0)}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
