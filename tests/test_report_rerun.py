"""compare_seeded on small tables whose spreads and changes are known by construction."""

import math

import pandas as pd
import pytest

from physgs.report.rerun import compare_seeded


def _old():
    return pd.DataFrame(
        {
            "seed": [0, 1, 2, 0, 1, 2],
            "tree": ["a"] * 3 + ["b"] * 3,
            "err": [1.0, 2.0, 4.0, 10.0, 10.0, 10.0],  # spreads: a 3.0, b 0.0
            "n": [5, 5, 6, 7, 7, 7],
            "label": ["x"] * 6,
        }
    )


def test_cells_sorted_into_identical_within_and_beyond():
    new = _old().copy()
    new.loc[0, "err"] = 3.9  # a, seed 0: moved 2.9 <= 3.0
    new.loc[1, "err"] = 5.5  # a, seed 1: moved 3.5 > 3.0
    new.loc[3, "err"] = 10.5  # b: any move exceeds a zero spread
    new.loc[4, "n"] = math.nan  # a NaN in one run only
    r = compare_seeded(_old(), new, ["seed", "tree"])
    assert (r.rows, r.cells) == (6, 12)
    assert (r.identical, r.within, len(r.beyond)) == (8, 1, 3)
    moved = {(ch.key["tree"], ch.key["seed"], ch.column) for ch in r.beyond}
    assert moved == {("a", 1, "err"), ("b", 0, "err"), ("b", 1, "n")}
    assert r.beyond[-1].column == "err" and r.beyond[-1].spread == 3.0  # finite ratio last


def test_unmatched_rows_and_bad_keys():
    new = _old().iloc[1:]
    r = compare_seeded(_old(), new, ["seed", "tree"])
    assert r.only_old == [(0, "a")] and r.only_new == [] and r.rows == 5
    with pytest.raises(ValueError, match="seed column"):
        compare_seeded(_old(), _old(), ["tree"])
    with pytest.raises(ValueError, match="repeats keys"):
        compare_seeded(_old(), _old(), ["seed", "label"])
    with pytest.raises(ValueError, match="lacks key"):
        compare_seeded(_old(), _old().drop(columns="tree"), ["seed", "tree"])


def test_keys_are_the_seed_and_the_non_numeric_columns():
    from physgs.report.rerun import seeded_keys

    t = _old().assign(profile="default")
    assert seeded_keys(t) == ["seed", "tree", "label"]
    with pytest.raises(ValueError, match="repeat"):
        seeded_keys(t.drop(columns="tree"))
    with pytest.raises(ValueError, match="no 'seed' column"):
        seeded_keys(t.drop(columns="seed"))


def test_flag_columns_are_not_compared():
    old = _old().assign(reference=True)
    new = old.assign(reference=False)
    r = compare_seeded(old, new, ["seed", "tree"])
    assert r.cells == 12 and r.identical == 12 and not r.beyond


def _ledger(verdicts, measured):
    return pd.DataFrame(
        {
            "id": ["a/sparse", "b/sparse", "c/dense"][: len(verdicts)],
            "claim": ["a holds", "b holds", "c holds"][: len(verdicts)],
            "measured": measured,
            "ci_low": [m - 1.0 for m in measured],
            "ci_high": [m + 1.0 for m in measured],
            "unit": ["dB"] * len(verdicts),
            "threshold": ["> 0"] * len(verdicts),
            "verdict": verdicts,
        }
    )


def test_verdicts_compared_by_kind_with_both_intervals():
    from physgs.report.rerun import compare_claims

    old = _ledger(["holds", "undecided: one seed", "fails"], [2.0, 0.5, -3.0])
    new = _ledger(
        ["undecided: interval spans 0", "undecided: two seeds", "fails"], [0.5, 0.4, -2.0]
    )
    c = compare_claims(old, new)
    assert c.same == 2 and [v.id for v in c.changed] == ["a/sparse"]  # reasons are not verdicts
    v = c.changed[0]
    assert (v.old, v.new) == ("holds", "undecided")
    assert v.old_value == "+2 [+1, +3] dB" and v.new_value == "+0.5 [-0.5, +1.5] dB"
    assert v.threshold == "> 0 dB" and v.overlap == "yes"  # [1, 3] and [-0.5, 1.5]


def test_a_moved_verdict_says_whether_its_two_intervals_overlap():
    from physgs.report.rerun import compare_claims

    old = _ledger(["holds", "holds"], [4.0, 2.0])  # [3, 5] and [1, 3]
    new = _ledger(["fails", "fails"], [-4.0, 1.0])  # [-5, -3] and [0, 2]
    new.loc[1, ["ci_low", "ci_high"]] = float("nan")  # one seed: no interval
    c = compare_claims(old, new)
    assert [(v.id, v.overlap) for v in c.changed] == [("a/sparse", "no"), ("b/sparse", "--")]
    new.loc[1, ["ci_low", "ci_high"]] = [3.0, 3.5]  # touching at 3 counts as overlapping
    assert compare_claims(old, new).changed[1].overlap == "yes"


def test_claims_in_one_ledger_only_and_bad_ledgers():
    from physgs.report.rerun import compare_claims

    old = _ledger(["holds", "fails"], [1.0, -1.0])
    new = _ledger(["holds", "fails", "holds"], [1.0, -1.0, 2.0]).iloc[[0, 2]]
    c = compare_claims(old, new)
    assert (c.same, c.changed, c.only_old, c.only_new) == (1, [], ["b/sparse"], ["c/dense"])
    with pytest.raises(ValueError, match="repeats claim ids"):
        compare_claims(pd.concat([old, old]), new)
    with pytest.raises(ValueError, match="lacks column"):
        compare_claims(old.drop(columns="verdict"), new)


def test_timings_are_not_compared_and_named_tables_take_their_keys():
    from physgs.report.outputs import OUTPUTS
    from physgs.report.rerun import TIMING_COLUMNS, table_keys, timing_columns

    old = _old().assign(train_s=[1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    new = old.assign(train_s=old["train_s"] * 10)  # a slower machine: not a result
    r = compare_seeded(old, new, ["seed", "tree"])
    assert r.cells == 12 and r.identical == 12
    t = pd.DataFrame(
        {
            "seed": [0, 0],
            "split": ["v", "v"],
            "tree": ["s", "s"],
            "condition": [1, 2],
            "x": [1.0, 2.0],
        }
    )
    # the declared keys (a numeric wind among them), never a hand-kept list
    assert table_keys("tab_transfer", t) == ["seed", "split", "tree", "condition"]
    assert table_keys("tab_transfer", t) == list(OUTPUTS["tab_transfer"].columns.keys)
    assert timing_columns("tab_kselect") == ("train_s", "select_s", "cost_x")
    assert set(TIMING_COLUMNS) == {"train_s", "select_s", "cost_x", "fit_s", "ours_train_s"}
    with pytest.raises(ValueError, match="repeat"):
        table_keys("tab_other", t)


def test_a_moved_verdict_says_where_the_first_seed_alone_lies():
    """Against a one-instance record: a verdict the other instances moved keeps its first seed
    (the record's tree) on the old mean's side; one whose first seed crossed too moved on that
    tree itself; a claim without a first-seed value says so."""
    from physgs.report.claims import Claim
    from physgs.report.rerun import FIRST_CROSSED, FIRST_SAME, compare_claims

    def claim(i):
        return Claim(id=i, text=i, paper="--", source="--", threshold=0.0, side=">", unit="dB")

    old = _ledger(["holds", "holds", "holds"], [2.0, 2.0, 2.0])
    new = _ledger(["undecided", "fails", "undecided"], [0.5, -2.0, 0.5])
    first = {"a/sparse": (claim("a/sparse"), 1.7), "b/sparse": (claim("b/sparse"), -0.4)}
    c = compare_claims(old, new, first)
    got = {v.id: v.alone for v in c.changed}
    assert got == {"a/sparse": f"{FIRST_SAME}, +1.7", "b/sparse": f"{FIRST_CROSSED}, -0.4",
                   "c/dense": "--"}  # fmt: skip
    assert all(v.alone == "--" for v in compare_claims(old, new).changed)  # none set beside
