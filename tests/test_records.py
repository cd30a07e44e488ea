"""JSON records (physgs.records): what to_dict writes, from_dict reads back cast by each field's
annotation, and load refuses a file that is JSON but not such a record."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from physgs.intermediate import IntermediateFileError
from physgs.records import JsonRecord, floats


@dataclass(frozen=True)
class _Rec(JsonRecord):
    counts: np.ndarray
    rates: np.ndarray = floats()
    n: int = 0
    x: float = 0.0
    tags: list | None = None
    extra: np.ndarray | None = floats(default=None)


def test_a_record_reads_back_with_its_fields_types(tmp_path):
    rec = _Rec(np.array([1, 2]), np.array([0.5, np.nan]), 3, 2.0, ["a"], np.array([4, 5]))
    rec.save(tmp_path / "r.json")
    back = _Rec.load(tmp_path / "r.json", rule="r")
    assert back.counts.dtype == np.int64 and back.counts.tolist() == [1, 2]
    assert back.rates.dtype == np.float64 and np.isnan(back.rates[1])
    # a float field written from ints reads back as floats (its metadata's dtype)
    assert back.extra.dtype == np.float64 and back.extra.tolist() == [4.0, 5.0]
    assert (back.n, back.x, back.tags) == (3, 2.0, ["a"])


def test_absent_and_none_fields_take_their_defaults_and_extra_keys_are_ignored():
    back = _Rec.from_dict({"counts": [1], "rates": [1], "n": 2.0, "extra": None, "other": 1})
    assert back.extra is None and back.tags is None and back.x == 0.0
    assert isinstance(back.n, int) and back.rates.dtype == np.float64


def test_a_file_that_is_no_such_record_is_removed_and_refused(tmp_path):
    path = tmp_path / "r.json"
    path.write_text('{"rates": [1.0]}')  # no counts
    with pytest.raises(IntermediateFileError, match=r"is not a record .*rule `make_r`"):
        _Rec.load(path, rule="make_r")
    assert not path.exists()
