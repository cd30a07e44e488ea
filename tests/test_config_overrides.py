"""`--set KEY.PATH=VALUE` overrides (benchmarks/fit_recipe.py) go through the config's schema and
cross-key checks: a bad one is refused with the key named before any work starts."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest
import yaml

import physgs.config
from workflow_helpers import ROOT


@pytest.fixture(scope="module")
def cfg():
    return physgs.config.load(ROOT / "config" / "trees.yaml", "quick")


def test_a_valid_override_is_applied(cfg):
    out = physgs.config.apply_overrides(cfg, ["train.lr.deform=1.0e-3", "train.iterations=70"])
    assert out["train"]["lr"]["deform"] == 1.0e-3 and out["train"]["iterations"] == 70
    assert out is not cfg


def test_numbers_are_read_as_people_type_them(cfg):
    """1e-3 is a number (YAML 1.2, Python), not the string PyYAML's YAML 1.1 makes of it."""
    out = physgs.config.apply_overrides(cfg, ["train.lr.deform=1e-3", "train.lr.means=.5e-4"])
    assert out["train"]["lr"]["deform"] == 0.001 and out["train"]["lr"]["means"] == 5e-5


@pytest.mark.parametrize(
    ("text", "value"),
    [("1e-3", 1e-3), ("-1E+6", -1e6), (".5", 0.5), ("2.", 2.0), ("7", 7), ("true", True)],
)
def test_scalar_reads_yaml_1_2_numbers(text, value):
    got = physgs.config.scalar(text)
    assert got == value and type(got) is type(value)


@pytest.mark.parametrize("text", ["single", "1e", "e3", "0.5.1", "joint32", "window"])
def test_scalar_leaves_words_alone(text):
    assert physgs.config.scalar(text) == text


def test_a_string_for_a_number_is_refused_naming_the_key_and_the_set(cfg):
    with pytest.raises(physgs.config.ConfigError) as e:
        physgs.config.apply_overrides(cfg, ["train.iterations=70", "train.lr.deform=fast"])
    msg = str(e.value)
    assert "train/lr/deform" in msg and "not of type 'number'" in msg
    assert "Fix --set train.lr.deform=fast." in msg, msg  # not "Fix config/trees.yaml"


@pytest.mark.parametrize(
    "assignment",
    [
        "train.lr.physics=.nan",
        "models.omega_search.bank_scale=.inf",
        "tracks.tracker.fb_max_px=nan",
        "train.lr.deform=-.inf",
    ],
)
def test_nan_and_infinity_are_refused_with_the_key(cfg, assignment):
    key = assignment.partition("=")[0].replace(".", "/")
    with pytest.raises(physgs.config.ConfigError, match=f"'{key}'.*not a finite number"):
        physgs.config.apply_overrides(cfg, [assignment])


def test_an_unknown_key_names_the_nearest(cfg):
    with pytest.raises(physgs.config.ConfigError, match="did you mean 'train/lr/deform'"):
        physgs.config.apply_overrides(cfg, ["train.lr.defrom=0.001"])


def test_a_malformed_assignment_is_refused(cfg):
    with pytest.raises(physgs.config.ConfigError, match="KEY.PATH=VALUE"):
        physgs.config.apply_overrides(cfg, ["train.iterations"])


def test_fit_recipe_refuses_before_reading_the_dataset(tmp_path, monkeypatch):
    """The dataset folder does not exist: a ConfigError (not FileNotFoundError, not a TypeError
    from inside training) proves the override was checked before any work."""
    monkeypatch.chdir(ROOT)
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    sys.modules.pop("fit_recipe", None)
    import fit_recipe

    with pytest.raises(physgs.config.ConfigError, match="train/lr/deform"):
        fit_recipe.main(
            [str(tmp_path / "absent"), "--models", "static", "--set", "train.lr.deform=.nan"]
        )


# --- --config and --configfile: what the command line sets beats the profile ----------------------


def _raw():
    with open(ROOT / "config" / "trees.yaml") as f:
        return yaml.safe_load(f)  # as Snakemake reads it: YAML 1.1, '1e-3' would stay a string


def test_a_nested_command_line_value_beats_the_profile():
    """`--config 'tracks={"configs":["single"]}'` under quick: the quick profile's
    [single, joint32] must not win over what was typed."""
    raw = _raw()
    quick = physgs.config.load_workflow_config(raw, "quick")
    assert quick["tracks"]["configs"] == ["single", "joint32"]  # what the profile sets
    cl = {"profile": "quick", "trees": ["sparse"], "tracks": {"configs": ["single"]}}
    got = physgs.config.load_workflow_config(raw, command_line=cl)
    assert got["tracks"]["configs"] == ["single"] and got["trees"] == ["sparse"]
    assert got["tracks"]["K"] == quick["tracks"]["K"]  # the profile's other tracks keys hold


def test_nested_command_line_numbers_are_numbers():
    """Snakemake hands a --config mapping's scalars over as strings (YAML BaseLoader)."""
    cl = {
        "models": {"omega_search": {"bank_scale": "0.01"}, "mlp": {"time_top_hz": {"mlp": "3"}}},
        "tracks": {"K": "3"},
    }
    got = physgs.config.load_workflow_config(_raw(), "quick", command_line=cl)
    assert got["models"]["omega_search"]["bank_scale"] == 0.01
    assert got["models"]["mlp"]["time_top_hz"]["mlp"] == 3 and got["tracks"]["K"] == 3


def test_a_command_line_value_the_checks_refuse_is_named():
    """damping_benchmark={"trees":["sparse"]} under quick used to resolve to trees: [] silently;
    now it is the user's value, and the window check refuses it, naming that key."""
    cl = {"damping_benchmark": {"trees": ["sparse"]}}
    with pytest.raises(physgs.config.ConfigError) as e:
        physgs.config.load_workflow_config(_raw(), "quick", command_line=cl)
    msg = str(e.value)
    assert "damping_benchmark/trees is ['sparse']" in msg, msg


def test_a_configfile_is_read_as_yaml_1_2_and_a_bad_value_names_it(tmp_path):
    good = tmp_path / "good.yaml"
    good.write_text("train: {lr: {deform: 1e-3}}\nmodels: {omega_search: {bank_scale: 2e-3}}\n")
    got = physgs.config.load_workflow_config(_raw(), "quick", configfiles=[good])
    assert got["train"]["lr"]["deform"] == 1e-3  # and it beats quick's profile
    assert got["models"]["omega_search"]["bank_scale"] == 2e-3
    bad = tmp_path / "bad.yaml"
    bad.write_text("train: {lr: {physics: .nan}}\n")
    with pytest.raises(physgs.config.ConfigError) as e:
        physgs.config.load_workflow_config(_raw(), "quick", configfiles=[bad])
    msg = str(e.value)
    assert "'train/lr/physics' (from --configfile " in msg and "not a finite number" in msg, msg
    assert f"Fix --configfile {bad}." in msg


def test_a_configfile_with_profiles_is_a_base_not_an_overlay(tmp_path):
    """`--configfile config/trees.yaml extra.yaml` (tests/test_workflow_reruns.py) must still run
    the quick profile: a file with a profiles section sits under the profile, as the base does."""
    copy = tmp_path / "trees.yaml"
    copy.write_text((ROOT / "config" / "trees.yaml").read_text())
    got = physgs.config.load_workflow_config(_raw(), "quick", configfiles=[copy])
    assert got == physgs.config.load_workflow_config(_raw(), "quick")
    assert got["train"]["iterations"] == 30  # quick's, not the file's top-level 3000


def test_the_config_file_reads_1e_3_as_a_number_and_refuses_nan_naming_itself():
    raw = _raw()
    raw["train"]["lr"]["deform"] = "1e-3"  # what PyYAML makes of a plain 1e-3
    assert physgs.config.load_workflow_config(raw, "quick")["train"]["lr"]["deform"] == 1e-3
    raw["tracks"]["tracker"]["fb_max_px"] = float("inf")
    with pytest.raises(physgs.config.ConfigError, match=r"tracks/tracker/fb_max_px.*finite"):
        physgs.config.load_workflow_config(raw, "quick")
    with pytest.raises(physgs.config.ConfigError, match=r"Fix config/trees\.yaml\.$"):
        physgs.config.load_workflow_config(raw, "quick")


def test_the_snakefile_plans_what_the_command_line_says(tmp_path):
    """The Snakefile hands its --config and --configfile to the loader: under quick, a typed
    tracks configuration list is the one planned (quick's joint32 fit is not), and a number typed
    1e-3 in a --configfile plans."""
    for p in ("Snakefile", "config", "workflow"):
        src = ROOT / p
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / p)
    (tmp_path / "lr.yaml").write_text("train: {lr: {deform: 1e-3}}\n")
    cmd = [sys.executable, "-m", "snakemake", "-n", "--cores", "1", "results/tables/tab_tracks.tex"]
    cmd += ["--configfile", "lr.yaml", "--config", "profile=quick", 'trees=["sparse"]']
    cmd += ['tracks={"configs":["single"]}', 'models={"omega_search":{"bank_scale":0.01}}']
    r = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=120)
    out = r.stdout + r.stderr
    assert r.returncode == 0, out
    assert "fit_single.npz" in out and "fit_joint32.npz" not in out, out
