"""A corrupt intermediate file (tracks, fits, evaluations, records) is named with the rule that
rebuilds it and removed, so no later run fails again on the same bytes, and its message gives the
flag that remakes it and what is made from it (physgs.intermediate)."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import numpy as np
import pytest

from physgs.intermediate import IntermediateFileError, read_json, read_npz
from workflow_helpers import ROOT


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


SNAKEFILE = """
rule mid:
    output:
        "mid.json",
    run:
        import json

        json.dump({"v": 1}, open(output[0], "w"))
        open("mid.made", "a").write("x")


rule fit:
    input:
        "mid.json",
    output:
        "fit.txt",
    run:
        from physgs.intermediate import read_json

        open(output[0], "w").write(str(read_json(input[0], ["v"], rule="mid")["v"]))


rule out:
    input:
        "fit.txt",
    output:
        "out.txt",
    shell:
        "cp {input} {output}"
"""


def test_the_command_in_the_message_remakes_the_file_and_what_is_made_from_it(tmp_path):
    """Snakemake remakes a missing file only when a job that reads it has to run: after the
    reading job (fit) stopped on it, the same command has nothing to do, the target made from it
    (out.txt) being up to date. The command the message gives remakes it and what is made from
    it."""
    (tmp_path / "Snakefile").write_text(SNAKEFILE)
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}

    def snakemake(*args):
        # run: blocks in Snakemake's own process (--force-use-threads), not in a Snakemake
        # started again for each job (~3 s each); the block reads the file all the same
        cmd = [sys.executable, "-m", "snakemake", "--cores", "1", "--force-use-threads"]
        cmd += ["out.txt", *args]
        r = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
        return r.returncode, r.stdout + r.stderr

    assert snakemake()[0] == 0 and (tmp_path / "mid.made").read_text() == "x"
    (tmp_path / "mid.json").write_text("{not json")  # damaged (and newer) after fit.txt was made
    rc, failed = snakemake()
    assert rc != 0 and "mid.json is corrupt" in failed and "rule `mid`" in failed, failed
    assert not (tmp_path / "mid.json").exists()
    rc, log = snakemake()  # the same command: nothing to do, mid.json stays missing
    assert rc == 0 and "Nothing to be done" in log and not (tmp_path / "mid.json").exists()
    flags = re.findall(r"rerun this command with `([^`]+)` added", failed)
    assert flags, f"the message gives no command that remakes the file:\n{failed}"
    rc, log = snakemake(*flags[0].split())
    assert rc == 0, log
    assert (tmp_path / "mid.made").read_text() == "xx" and (tmp_path / "fit.txt").read_text() == "1"
    assert "localrule out:" in log  # what is made from it was remade
