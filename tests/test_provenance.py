"""The provenance record beside every output (physgs.provenance): what a job writes, and the plan's
check that refuses a file made with other settings, naming the file, the key and the command."""

import json
import sys

import pytest

from physgs import provenance
from physgs.provenance import (
    ProvenanceError,
    Stamp,
    check_plan,
    disagreement,
    read_provenance,
    sidecar,
    write_provenance,
)

PARAMS = {"settings": {"testbed": {"resolution": 32, "frames": 72}, "tree": "sparse"}}


def _made(tmp_path, name, params=PARAMS, rule="testbed_dataset", inputs=()):
    out = tmp_path / name
    out.write_text("data\n")
    write_provenance([out], rule, params, inputs, commit="abc1234")
    return out


def test_a_job_records_its_rule_settings_commit_and_inputs(tmp_path):
    tb = _made(tmp_path, "observed.npz")
    ck = _made(tmp_path, "ours.pt", {"job": {"lr": 0.01}}, rule="train", inputs=[tb])
    rec = read_provenance(ck)
    assert sidecar(ck).name == "ours.pt.provenance"
    assert rec["settings"] == {"rule": "train", "params": {"job": {"lr": 0.01}}}
    assert rec["commit"] == "abc1234"
    assert rec["inputs"] == {str(tb): read_provenance(tb)["settings_hash"]}
    assert rec["settings_hash"] != read_provenance(tb)["settings_hash"]


def test_the_same_settings_agree_whatever_their_key_order_and_a_stamp_is_no_setting(tmp_path):
    out = _made(tmp_path, "observed.npz", {**PARAMS, "stamp": Stamp("quick", "0" * 12, "1")})
    reordered = {"settings": {"tree": "sparse", "testbed": {"frames": 72, "resolution": 32}}}
    other_stamp = {**reordered, "stamp": Stamp("quick", "1" * 12, "2")}
    assert disagreement(out, "testbed_dataset", other_stamp, []) is None


def test_a_changed_setting_is_named_with_both_values(tmp_path):
    out = _made(tmp_path, "observed.npz")
    now = {"settings": {"testbed": {"resolution": 8, "frames": 72}, "tree": "sparse"}}
    why = disagreement(out, "testbed_dataset", now, [])
    assert "`params.settings.testbed.resolution` 32 when it was made, 8 in this plan" in why
    assert "frames" not in why
    added = {"settings": {**PARAMS["settings"], "variant": "damping"}}
    assert "`params.settings.variant` absent when it was made" in disagreement(
        out, "testbed_dataset", added, []
    )


def test_a_file_made_from_an_input_since_made_with_other_settings_is_named(tmp_path):
    tb = _made(tmp_path, "observed.npz")
    ck = _made(tmp_path, "ours.pt", {"job": {"lr": 0.01}}, rule="train", inputs=[tb])
    assert disagreement(ck, "train", {"job": {"lr": 0.01}}, [tb]) is None
    previous = provenance.take_provenance([tb])
    write_provenance(
        [tb], "testbed_dataset", {"settings": {"tree": "medium"}}, commit="abc", previous=previous
    )
    why = disagreement(ck, "train", {"job": {"lr": 0.01}}, [tb])
    assert f"made from {tb} before that was made again" in why
    assert "`params.settings.tree` 'sparse' then, 'medium' now" in why


def test_a_file_without_a_record_or_with_a_broken_one_is_refused(tmp_path):
    bare = tmp_path / "old.npz"
    bare.write_text("x")
    assert "carries no provenance record" in disagreement(bare, "r", {}, [])
    broken = _made(tmp_path, "b.npz")
    sidecar(broken).write_text("{")
    assert "unreadable" in disagreement(broken, "testbed_dataset", PARAMS, [])


def test_the_plan_check_names_each_file_and_the_command_that_remakes_them(tmp_path):
    good = _made(tmp_path, "good.npz")
    stale = _made(tmp_path, "stale.npz")
    now = {"settings": {"testbed": {"resolution": 8, "frames": 72}, "tree": "sparse"}}
    jobs = [
        ("testbed_dataset", PARAMS, [good], []),
        ("testbed_dataset", now, [stale, good], []),
        ("testbed_dataset", now, [tmp_path / "not_made_yet.npz"], []),  # Snakemake makes it
    ]
    cmd = "snakemake --cores 2 all --config 'testbed={resolution: 8}' {forcerun} -- x"
    with pytest.raises(ProvenanceError) as e:
        check_plan(jobs, cmd)
    msg = str(e.value)
    assert f"{stale} (rule `testbed_dataset`)" in msg and "resolution` 32" in msg
    assert f"--forcerun {stale} -- x" in msg
    assert f"- {good}" not in msg
    assert check_plan(jobs[:1], cmd).checked == 1


def test_a_file_without_a_record_that_snakemake_s_metadata_vouches_for_is_adopted(tmp_path):
    now = {"settings": {"tree": "sparse"}}
    bare = tmp_path / "made_before.npz"
    bare.write_text("x")
    cmd = "snakemake all {forcerun}"
    with pytest.raises(ProvenanceError, match="carries no provenance record"):
        check_plan([("testbed_dataset", now, [bare], [], False)], cmd)
    found = check_plan([("testbed_dataset", now, [bare], [], True)], cmd)
    assert found.checked == 0 and [j[2] for j in found.adopted] == [[str(bare)]]
    assert provenance.adopt(found.adopted) == 1
    assert disagreement(bare, "testbed_dataset", now, []) is None
    # a job adopted with its input in one pass records the input's settings, in any order
    up, down = tmp_path / "up.npz", tmp_path / "down.npz"
    up.write_text("x")
    down.write_text("y")
    pair = [("evaluate", {"a": 1}, [str(down)], [str(up)]), ("train", {"b": 2}, [str(up)], [])]
    provenance.adopt(pair)
    assert check_plan([(*j, False) for j in pair], cmd).checked == 2
    # a record that is there is read whatever the metadata says
    other = {"settings": {"tree": "medium"}}
    with pytest.raises(ProvenanceError, match="'sparse' when it was made, 'medium'"):
        check_plan([("testbed_dataset", other, [bare], [], True)], cmd)


def test_the_command_given_back_is_the_run_s_without_dry_run_flags(monkeypatch):
    argv = ["/x/snakemake", "-n", "--cores", "2", "--config", "trees=[sparse]", "--", "all"]
    monkeypatch.setattr(sys, "argv", argv)
    assert provenance._command() == (
        "snakemake --cores 2 --config 'trees=[sparse]' {forcerun} -- all"
    )


def test_a_job_clears_the_old_record_before_it_runs(tmp_path):
    out = _made(tmp_path, "observed.npz")
    provenance.clear_provenance([out])
    assert read_provenance(out) is None
    assert json.loads(json.dumps(provenance.job_settings("r", {"t": (1, 2)}))) == {
        "rule": "r",
        "params": {"t": [1, 2]},
    }
