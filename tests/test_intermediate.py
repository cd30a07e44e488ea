"""A corrupt intermediate file (tracks, fits, evaluations, records) is named with the rule that
rebuilds it and removed, so the next run of the same command rebuilds it instead of failing again
on the same bytes (physgs.intermediate)."""

from __future__ import annotations

import numpy as np
import pytest

from physgs.intermediate import IntermediateFileError, read_json, read_npz


def _tracks_file(path):
    from physgs.tracks.store import save_tracks
    from test_tracks import _synthetic

    save_tracks(path, _synthetic()[0], 0)


def _corrupt(kind, path):
    if kind == "random":
        path.write_bytes(np.random.default_rng(0).bytes(5000))
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "truncated":
        path.write_bytes(path.read_bytes()[:300])
    elif kind == "pickled":  # an object array: np.load refuses to unpickle it
        obj = np.array([{"a": 1}], dtype=object)
        np.savez(open(path, "wb"), xy=obj, valid=obj, start=obj, condition=obj)
    elif kind == "wrong_keys":
        np.savez(open(path, "wb"), something=np.zeros(3))
    elif kind == "wrong_shapes":
        np.savez(open(path, "wb"), xy=np.zeros(3), valid=np.zeros(3), start=0, condition=0)


@pytest.mark.parametrize(
    "kind", ["random", "empty", "truncated", "pickled", "wrong_keys", "wrong_shapes"]
)
def test_a_corrupt_tracks_file_is_named_with_its_rule_and_removed(tmp_path, kind):
    from physgs.tracks.store import load_tracks

    path = tmp_path / "c0.npz"
    _tracks_file(path)
    load_tracks(path)  # the good file reads
    _corrupt(kind, path)
    with pytest.raises(IntermediateFileError) as e:
        load_tracks(path)
    msg = str(e.value)
    assert str(path) in msg and "rule `track`" in msg and "removed" in msg, msg
    assert not path.exists()  # so the next run's plan rebuilds it with `track`
    with pytest.raises(IntermediateFileError, match=r"does not exist; build it with rule `track`"):
        load_tracks(path)


def test_a_corrupt_fit_file_names_fit_tracks(tmp_path):
    from physgs.tracks.store import load_fit

    path = tmp_path / "fit_single.npz"
    np.savez(open(path, "wb"), omega=np.zeros(2))
    with pytest.raises(IntermediateFileError, match=r"fit_single\.npz lacks .*rule `fit_tracks`"):
        load_fit(path)
    assert not path.exists()


def test_json_records_are_read_the_same_way(tmp_path):
    from physgs.recovery.record import load_null

    path = tmp_path / "null_K2.json"
    path.write_text('{"trusted": [1, ')  # cut short
    with pytest.raises(IntermediateFileError, match=r"null_K2\.json is corrupt.*`null_control`"):
        load_null(path)
    assert not path.exists()
    path.write_text("[1, 2]")
    with pytest.raises(IntermediateFileError, match="not a mapping"):
        read_json(path, rule="r")


def test_a_good_file_is_kept_and_read(tmp_path):
    path = tmp_path / "a.npz"
    np.savez(open(path, "wb"), a=np.arange(3))
    assert read_npz(path, ("a",), rule="r")["a"].tolist() == [0, 1, 2]
    assert path.exists()
    (tmp_path / "b.json").write_text('{"x": 1}')
    assert read_json(tmp_path / "b.json", ("x",), rule="r") == {"x": 1}
