"""Prose cannot drift from the record: a page that states a claim's verdict marks it, and the mark
agrees with the record's ledger (docs/record/claims.csv) and with the words before it.

The marker is an HTML comment (invisible on the site) right after the words that state the
verdict::

    `oma_beats_null/sparse` is undecided <!-- verdict oma_beats_null/sparse undecided -->

Checks: (1) the claim id is in the ledger and its verdict there is the marker's; (2) the last
verdict word (hold(s), fail(s), undecided) of the paragraph before the marker is the marker's
verdict, so the sentence says what the marker says; (3) a paragraph that names a claim of the
ledger in backticks beside a verdict word carries a marker, so an unmarked verdict cannot be
written; a paragraph that only says how verdicts are decided ("holds when ...") says so with
``<!-- no verdict -->``. A new record whose verdict moves fails (1) on every page that states
the old one.
"""

import re
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]
MARK = re.compile(r"<!--\s*verdict\s+(\S+)\s+(holds|fails|undecided)\s*-->")
WORD = re.compile(r"\b(holds?|fails?|undecided)\b")
NONE = "<!-- no verdict -->"  # a paragraph on how verdicts are decided, stating none
TICKED = re.compile(r"`([a-z0-9_]+(?:/[a-z0-9_.<>]+)*)`")


def _pages():
    return [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]


def _ledger():
    c = pd.read_csv(ROOT / "docs" / "record" / "claims.csv", dtype={"config_hash": str})
    return dict(zip(c["id"], c["verdict"].astype(str).str.split(":").str[0]))


def _paragraphs(text):
    return [p for p in re.split(r"\n\s*\n|\n(?=\s*- )", text) if p.strip()]


def _kind(word):
    return {"hold": "holds", "fail": "fails"}.get(word, word)


def marks_disagreeing(text, ledger):
    """The markers of ``text`` that disagree with ``ledger`` or with the words before them."""
    bad = []
    for para in _paragraphs(text):
        for m in MARK.finditer(para):
            cid, said = m.group(1), m.group(2)
            if cid not in ledger:
                bad.append(f"{cid}: not a claim of the record")
                continue
            if ledger[cid] != said:
                bad.append(f"{cid}: the page says {said}, the record {ledger[cid]}")
            words = WORD.findall(MARK.sub(" ", para[: m.start()]))
            if not words or _kind(words[-1]) != said:
                last = words[-1] if words else "no verdict word"
                bad.append(f"{cid}: marked {said} after the words '{last}'")
    return bad


def unmarked_verdicts(text, ledger):
    """The paragraphs of ``text`` that name a claim beside a verdict word without a marker."""
    prefixes = {i.rsplit("/", k)[0] for i in ledger for k in range(i.count("/") + 1)}
    out = []
    for para in _paragraphs(text):
        if MARK.search(para) or NONE in para or not WORD.search(para):
            continue
        named = [t for t in TICKED.findall(para) if re.sub(r"/<[^>]+>", "", t) in prefixes]
        if named:
            out.append(f"{named[0]}: {' '.join(para.split())[:100]}")
    return out


def test_every_stated_verdict_is_marked_and_agrees_with_the_record():
    ledger = _ledger()
    found, marked = [], set()
    for page in _pages():
        text = page.read_text()
        if page.name == "README.md":  # its record block is printed from the record itself
            text = re.sub(r"<!-- record:begin -->.*<!-- record:end -->", "", text, flags=re.S)
        if MARK.search(text):
            marked.add(page.name)
        found += [f"{page.name}: {b}" for b in marks_disagreeing(text, ledger)]
        found += [f"{page.name}: unmarked verdict of {u}" for u in unmarked_verdicts(text, ledger)]
    assert not found, "pages disagree with docs/record/claims.csv:\n" + "\n".join(found)
    assert {"blind.md", "parts.md", "tracks.md"} <= marked  # the pages that state verdicts


@pytest.mark.parametrize(
    "text, why",
    [
        ("`x/sparse` holds <!-- verdict x/sparse holds -->", "the record fails"),
        ("`x/sparse` fails <!-- verdict x/sparse fails -->\n\n`y` is fine", None),
        ("it fails on sparse <!-- verdict y/dense undecided -->", "after the words 'fails'"),
        ("`z/dense` <!-- verdict z/dense holds -->", "not a claim of the record"),
    ],
)
def test_a_marker_that_disagrees_is_caught(text, why):
    ledger = {"x/sparse": "fails", "y/dense": "undecided"}
    bad = marks_disagreeing(text, ledger)
    if why is None:
        assert not bad
    else:
        assert any(why in b for b in bad), bad


def test_an_unmarked_verdict_is_caught():
    ledger = {"anemometer_needed/sparse": "undecided"}
    assert unmarked_verdicts("`anemometer_needed` holds on sparse.", ledger)
    assert unmarked_verdicts("`anemometer_needed/<tree>` fails.", ledger)
    assert not unmarked_verdicts("`anemometer_needed` is measured per tree.", ledger)
    assert not unmarked_verdicts("`min_stable` holds poles.", ledger)
    assert not unmarked_verdicts(f"`anemometer_needed` holds when it grows. {NONE}", ledger)


def test_no_page_cites_a_tracker_no_reader_has():
    """The changelog and the pages say what was done, not "issue NN" of a private tracker."""
    pages = [*_pages(), ROOT / "CHANGELOG.md"]
    found = [
        f"{p.name}: {m.group(0)}"
        for p in pages
        for m in re.finditer(r"\bissues? #?\d+", p.read_text(), flags=re.I)
    ]
    assert not found, found
