"""Config loading: the packaged schema, profile resolution, unknown keys and cross-key checks."""

import copy
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from physgs import config as pconfig
from physgs import config_checks

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "trees.yaml"
PROFILES = ("quick", "default", "paper")


def _base() -> dict:
    return yaml.safe_load(CONFIG.read_text())


def _refused(edit, profile: str | None = None) -> str:
    """The ConfigError message for the shipped config after ``edit``."""
    raw = _base()
    edit(raw)
    with pytest.raises(pconfig.ConfigError) as e:
        pconfig.load_workflow_config(raw, profile)
    return str(e.value)


# --- the shipped config, the schema as package data -------------------------------------------


@pytest.mark.parametrize("name", PROFILES)
def test_shipped_config_is_accepted_for_every_profile(name):
    base = _base()
    assert set(PROFILES) <= set(base["profiles"])
    cfg = pconfig.load_workflow_config(base, name)
    assert cfg["profile"] == name
    assert "profiles" not in cfg
    assert config_checks.problems(cfg) == []
    assert pconfig.load(CONFIG, name) == cfg


def test_config_profile_key_selects_the_profile_like_snakemake_config():
    base = _base()
    base["profile"] = "quick"  # what `--config profile=quick` puts into Snakemake's config
    assert pconfig.load_workflow_config(base) == pconfig.load_workflow_config(_base(), "quick")


def test_schema_ships_inside_the_package():
    assert pconfig.SCHEMA.is_file()
    assert Path(str(pconfig.SCHEMA)).is_relative_to(Path(pconfig.__file__).parent)
    assert not (ROOT / "workflow" / "schemas" / "config.schema.yaml").exists()
    assert pconfig.schema()["additionalProperties"] is False


def test_partial_schema_drops_required_and_inlines_refs():
    s = {
        "type": "object",
        "required": ["a"],
        "properties": {
            "a": {"$ref": "#/$defs/x"},
            "b": {"type": "array", "items": {"required": ["c"]}},
        },
        "$defs": {"x": {"type": "object", "required": ["y"], "properties": {"y": {}}}},
    }
    p = pconfig.partial_schema(s)
    assert p == {
        "type": "object",
        "properties": {
            "a": {"type": "object", "properties": {"y": {}}},
            "b": {"type": "array", "items": {}},
        },
    }
    assert s["required"] == ["a"]  # the input is not changed


def test_profile_overrides_only_what_it_names():
    base = _base()
    quick = pconfig.resolve(base, "quick")
    default = pconfig.resolve(base, "default")
    assert quick["testbed"]["resolution"] < default["testbed"]["resolution"]
    # untouched leaves survive the merge
    assert quick["testbed"]["fps"] == default["testbed"]["fps"] == base["testbed"]["fps"]


def test_an_empty_profile_changes_nothing():
    base = _base()
    base["profiles"]["default"] = None
    assert pconfig.load_workflow_config(base, "default") == pconfig.load(CONFIG, "default")


@pytest.mark.parametrize(
    "path, value",
    [
        (("testbed", "zeta"), -0.1),
        (("train", "warmup"), -5),  # a recipe setting out of range
        (("train", "lr_final_ratio"), 0.0),
        (("train", "stopping", "patience"), 0),
        (("train", "stopping", "tol"), 1.0),
        (("speed_accuracy", "fit_curve", "iterations"), [500, 1]),
        (("speed_accuracy", "fit_curve", "models"), ["mlp", "truth_motion"]),
    ],
)
def test_schema_violation_names_the_key(path, value):
    base = _base()
    _set(path, value)(base)
    with pytest.raises(pconfig.ConfigError, match="/".join(path)):
        pconfig.validate(base)


@pytest.mark.parametrize("seeds", [[], [0, 0], [0, "a"], [1.5], 3, [-1]])
def test_bad_seeds_stop_at_load_naming_the_key(seeds):
    """An empty, repeated or non-integer seed list is refused before any job, whether it comes
    from the file or from the command line."""
    for cmd in (None, {"seeds": seeds}):
        raw = _base()
        raw["seeds"] = seeds
        with pytest.raises(pconfig.ConfigError, match=r"config key 'seeds"):
            pconfig.load_workflow_config(raw, command_line=cmd)


def test_command_line_seeds_beat_the_profiles():
    raw = _base()
    assert pconfig.load_workflow_config(raw, "quick")["seeds"] == [0]
    assert pconfig.load_workflow_config(raw, "paper")["seeds"] == [0, 1, 2, 3, 4]
    got = pconfig.load_workflow_config(raw, "quick", command_line={"seeds": [3, 1]})
    assert got["seeds"] == [3, 1]
    bad = pconfig.load_workflow_config  # a bad command-line value is validated like the file's
    with pytest.raises(pconfig.ConfigError, match="seeds"):
        bad(raw, "quick", command_line={"seeds": [2, 2]})
    # Snakemake hands `--config seeds=[0,1]` over as strings (YAML BaseLoader)
    assert bad({**raw, "seeds": ["0", "1"]}, "quick", command_line={"seeds": ["0", "1"]})[
        "seeds"
    ] == [0, 1]
    with pytest.raises(pconfig.ConfigError, match="seeds/0"):
        bad({**raw, "seeds": ["1.5"]}, "quick", command_line={"seeds": ["1.5"]})


def test_schema_violation_in_a_profile_body_names_the_profile_key():
    msg = _refused(lambda c: c["profiles"]["quick"]["train"].update(warmup="ten"), "quick")
    assert "profiles/quick/train/warmup" in msg and "Fix config/trees.yaml" in msg


def test_unknown_profile_is_refused_with_the_choices():
    with pytest.raises(pconfig.ConfigError, match="quick"):
        pconfig.resolve(_base(), "fastest")


def test_load_rejects_a_bad_file(tmp_path):
    base = _base()
    base["trees"] = ["sparse", "Oak"]  # not a tree name (a preset's: lower case, no underscore)
    bad = tmp_path / "trees.yaml"
    bad.write_text(yaml.safe_dump(base))
    with pytest.raises(pconfig.ConfigError, match="trees/1"):
        pconfig.load(bad)


def test_missing_section_is_named():
    assert "'models/configs/single'" in _refused(lambda c: c["models"]["configs"].pop("single"))
    assert "'train/lr/pivot' is missing" in _refused(lambda c: c["train"]["lr"].pop("pivot"))


# --- unknown keys, with the nearest valid key ---------------------------------------------------


@pytest.mark.parametrize(
    "edit, key, suggestion",
    [
        (
            lambda c: c["profiles"]["quick"].update(trian={"iterations": 5}),
            "profiles/quick/trian",
            "profiles/quick/train",
        ),
        (
            lambda c: c["profiles"]["quick"]["train"].update(iteration=5),
            "profiles/quick/train/iteration",
            "profiles/quick/train/iterations",
        ),
        (
            lambda c: c["profiles"]["paper"].update(testbed={"resolutoin": 256}),
            "profiles/paper/testbed/resolutoin",
            "profiles/paper/testbed/resolution",
        ),
        (
            lambda c: c["profiles"]["quick"]["models"].update(mlp={"widht": 64}),
            "profiles/quick/models/mlp/widht",
            "profiles/quick/models/mlp/width",
        ),
        (
            lambda c: c["profiles"]["quick"]["presets"]["medium"]["leaves"].update(fractoin=0.2),
            "profiles/quick/presets/medium/leaves/fractoin",
            "profiles/quick/presets/medium/leaves/fraction",
        ),
        (
            lambda c: c["profiles"]["quick"].update(iterations=5),
            "profiles/quick/iterations",
            "profiles/quick/train/iterations",
        ),
        (lambda c: c.update(seds=[0, 1]), "seds", "seeds"),
        (lambda c: c["train"]["lr"].update(mens=1e-4), "train/lr/mens", "train/lr/means"),
        (lambda c: c["testbed"]["wind"].update(v_0=5.0), "testbed/wind/v_0", "testbed/wind/v0"),
    ],
)
def test_unknown_key_is_refused_with_the_nearest_valid_key(edit, key, suggestion):
    msg = _refused(edit)
    assert f"unknown config key '{key}'" in msg
    assert f"did you mean '{suggestion}'" in msg
    assert "Fix config/trees.yaml" in msg


@pytest.mark.parametrize(
    "edit, key, suggestion",
    [
        (
            lambda c: c["testbed"]["vertices"].update(sprase=400),
            "testbed/vertices/sprase",
            "sparse",
        ),
        (lambda c: c["presets"].update(mediun=c["presets"]["medium"]), "presets/mediun", "medium"),
    ],
)
def test_a_tree_named_like_another_is_refused_as_a_typo(edit, key, suggestion):
    """Presets are an open set (a new tree has its own); a name no tree lists, close to
    another's, is still refused with the nearest."""
    msg = _refused(edit)
    assert key in msg and f"did you mean '{suggestion}'" in msg


def test_a_fourth_preset_with_its_own_name_and_role_is_accepted():
    raw = _base()
    raw["presets"]["oak"] = {**raw["presets"]["sparse"], "role": {"frequencies": "tiled"}}
    raw["testbed"]["vertices"]["oak"] = 400
    raw["trees"] = [*raw["trees"], "oak"]
    cfg = pconfig.resolve(raw, "default")
    assert cfg["presets"]["oak"]["role"] == {"frequencies": "tiled"}


def test_a_profile_cannot_name_a_profile():
    msg = _refused(lambda c: c["profiles"]["quick"].update(profile="paper"))
    assert "unknown config key 'profiles/quick/profile'" in msg


def test_nested_key_given_with_config_at_top_level_is_refused_with_how_to_set_it():
    """`snakemake --config iterations=5` puts `iterations` at the top level of the config."""
    raw = _base()
    raw.update(profile="quick", iterations=5)
    with pytest.raises(pconfig.ConfigError) as e:
        pconfig.load_workflow_config(raw)
    msg = str(e.value)
    assert "unknown config key 'iterations'" in msg
    assert "did you mean 'train/iterations'" in msg
    assert "--config" in msg and "profiles/quick/train/iterations" in msg
    assert "{profiles: {quick: {train: {iterations: 5}}}}" in msg  # the --configfile to pass


def test_every_problem_is_reported_at_once():
    def edit(c):
        c["profiles"]["quick"]["trian"] = {}
        c["testbed"]["fsp"] = 24

    msg = _refused(edit)
    assert "2 problems" in msg and "profiles/quick/trian" in msg and "testbed/fsp" in msg


# --- cross-key checks on the resolved config ----------------------------------------------------


def _set(path, value, profile=None):
    def edit(c):
        node = c["profiles"][profile] if profile else c
        for k in path[:-1]:
            node = node.setdefault(k, {})
        node[path[-1]] = value

    return edit


@pytest.mark.parametrize(
    "edit, profile, key",
    [
        # the K-selection warm-up is its own key, not train/warmup
        (_set(("models", "kselect", "warmup"), 30, "quick"), "quick", "models/kselect/warmup"),
        (_set(("models", "kselect", "warmup"), 160), "default", "models/kselect/warmup"),
        (_set(("train", "warmup"), 40, "quick"), "quick", "train/warmup"),
        (_set(("train", "warmup"), 40000, "paper"), "paper", "train/warmup"),
        (_set(("models", "ours", "omega_hz"), [3.0, 0.1]), "default", "models/ours/omega_hz"),
        (_set(("models", "ours", "omega_init_hz"), 5.0), "default", "models/ours/omega_init_hz"),
        (_set(("models", "ours", "zeta"), [0.5, 0.01]), "default", "models/ours/zeta"),
        (_set(("models", "ours", "zeta_init"), 0.6), "default", "models/ours/zeta_init"),
        (_set(("models", "ours", "freeze_at"), 0.1), "default", "models/ours/freeze_at"),
        # quick's sparse tree has 400 Gaussians
        (_set(("models", "configs", "joint96", "K"), 500), "quick", "models/configs/joint96/K"),
        (
            _set(("models", "kselect", "candidates"), [4, 401], "quick"),
            "quick",
            "models/kselect/candidates/1",
        ),
        (_set(("speed_accuracy", "knobs", "K"), [8, 3000]), "default", "speed_accuracy/knobs/K/1"),
        # a prior's own K selection: its candidates, its schedule, and only a wind-driven prior
        (
            _set(("models", "kselect", "priors", "ours_chain", "candidates"), [4, 401], "quick"),
            "quick",
            "models/kselect/priors/ours_chain/candidates/1",
        ),
        (
            _set(("models", "kselect", "priors", "ours_chain", "warmup"), 400),
            "default",
            "models/kselect/priors/ours_chain/warmup",
        ),
        (
            _set(("models", "kselect", "priors", "ours_blind"), {"candidates": [4]}),
            "default",
            "models/kselect/priors/ours_blind",
        ),
        (
            lambda c: (
                _set(("models", "configs", "single", "K"), 100)(c),
                _set(("speed_accuracy", "knobs", "vertices"), [60, 2000])(c),
            ),
            "default",
            "speed_accuracy/knobs/vertices/0",
        ),
        (lambda c: c.update(trees=["medium", "dense"]), "default", "speed_accuracy/tree"),
        (_set(("speed_accuracy", "tree"), "dense", "quick"), "quick", None),
        (_set(("testbed", "lead_in_tau"), 20.0), "default", "testbed/lead_in_tau"),
        (_set(("testbed", "band_hz"), [1.5, 0.35]), "default", "testbed/band_hz"),
        (_set(("testbed", "wind", "f_lo_hz"), 9.0), "default", "testbed/wind/f_lo_hz"),
        (_set(("testbed", "conditions"), [1.0]), "default", "testbed/conditions"),
        (_set(("testbed", "conditions"), [0.84, 1.0]), "quick", "testbed/conditions/0"),
        (lambda c: c["testbed"]["vertices"].pop("sparse"), "default", "testbed/vertices/sparse"),
        (lambda c: c["presets"].pop("medium"), "default", "presets/medium"),
        (lambda c: c["models"]["configs"].pop("single"), "default", "models/configs/single"),
        (
            _set(("models", "configs", "auto"), {"conditions": "train", "K": 8}),
            "default",
            "models/configs/auto",
        ),
        # a preset that cannot reach its bone count (here: one more bone than it builds)
        (_set(("presets", "sparse", "bones"), 23), "default", "presets/sparse"),
        (_set(("train", "holdout_every"), 1), "default", "train/holdout_every"),
        # the fit curve's profile point is the pipeline's own job on its tree; three budgets at least
        (
            _set(("speed_accuracy", "fit_curve", "trees"), ["oak"]),
            "quick",
            "speed_accuracy/fit_curve/trees",
        ),
        (
            _set(("speed_accuracy", "fit_curve", "iterations"), [1500]),
            "default",
            "speed_accuracy/fit_curve/iterations",
        ),
        # a field's time scale: positive, at most half the frame rate (24 fps: 12 Hz), every id
        (_set(("models", "mlp", "time_top_hz", "mlp"), 0), "default", "models/mlp/time_top_hz/mlp"),
        (
            _set(("models", "d3dgs", "time_top_hz", "d3dgs_wind"), -1.5),
            "default",
            "models/d3dgs/time_top_hz/d3dgs_wind",
        ),
        (
            _set(("models", "mlp", "time_top_hz", "mlp_wind"), 12.5),
            "default",
            "models/mlp/time_top_hz/mlp_wind",
        ),
        (_set(("models", "mlp", "time_top_hz", "mlp_wind"), 12.0), "default", None),
        (
            _set(("models", "mlp", "time_top_hz", "mlp"), "seconds"),
            "quick",
            "models/mlp/time_top_hz/mlp",
        ),
        (
            lambda c: c["models"]["mlp"]["time_top_hz"].pop("mlp"),
            "default",
            "models/mlp/time_top_hz/mlp",
        ),
        (
            _set(("models", "mlp", "time_top_hz", "d3dgs"), 1.0),
            "default",
            "models/mlp/time_top_hz/d3dgs",
        ),
        # the stopping rule, enabled, reads held-out window frames and scores them
        (
            lambda c: c["train"].update(
                holdout_every=0, stopping={**c["train"]["stopping"], "enabled": True, "every": 300}
            ),
            "default",
            "train/stopping/enabled",
        ),
        (
            lambda c: c["train"].update(
                stopping={**c["train"]["stopping"], "enabled": True, "every": 0}
            ),
            "default",
            "train/stopping/every",
        ),
        (
            lambda c: c["train"].update(
                holdout_every=0, stopping={**c["train"]["stopping"], "enabled": False}
            ),
            "default",
            None,
        ),
        # the studies' seeds come from seeds
        (_set(("speed_accuracy", "seeds"), [0, 7]), "default", "speed_accuracy/seeds"),
        (_set(("speed_accuracy", "seeds"), "all"), "default", None),
    ],
)
def test_cross_key_problem_is_refused_naming_the_key(edit, profile, key):
    if key is None:  # a control: the edit alone is fine
        raw = _base()
        edit(raw)
        pconfig.load_workflow_config(raw, profile)
        return
    msg = _refused(edit, profile)
    assert f"config key '{key}'" in msg, msg
    assert "Fix config/trees.yaml" in msg


def test_kselect_warmup_message_names_its_own_key_and_the_profile_that_set_it():
    msg = _refused(_set(("models", "kselect", "warmup"), 30, "quick"), "quick")
    assert "(set by 'profiles/quick/models/kselect/warmup')" in msg
    assert "models/kselect/iterations = 20" in msg
    assert "train/warmup" not in msg


def test_lead_in_check_uses_the_testbed_formula():
    from physgs.testbed import physics, wind

    cfg = pconfig.load(CONFIG, "default")
    cfg["damping_benchmark"]["trees"] = []  # the faithful testbed alone: testbed/zeta decides
    tb = cfg["testbed"]
    F = tb["n_train"] + tb["n_tail"]
    P = round(wind.PERIOD_S * tb["fps"])
    lead = lambda tau: physics.lead_in_frames(
        2 * 3.141592653589793 * tb["band_hz"][0], tb["zeta"], tau, tb["fps"]
    )
    ok = max(t / 100 for t in range(1, 2000) if lead(t / 100) + F < P)
    for tau, fine in ((ok, True), (ok + 0.01, False)):
        c = copy.deepcopy(cfg)
        c["testbed"]["lead_in_tau"] = tau
        assert (config_checks.problems(c, [config_checks.lead_in_fits_wind_period]) == []) == fine


def test_trees_not_listed_may_keep_their_settings():
    cfg = pconfig.load_workflow_config({**_base(), "trees": ["sparse"]}, "quick")
    assert cfg["trees"] == ["sparse"] and "dense" in cfg["presets"]


def test_a_listed_tree_without_a_vertex_count_is_named_not_a_key_error():
    def edit(c):
        c.update(trees=["dense"])
        c["speed_accuracy"]["tree"] = "dense"
        c["testbed"]["vertices"].pop("dense")
        c["profiles"]["quick"]["testbed"]["vertices"].pop("dense")

    msg = _refused(edit, "quick")
    assert "config key 'testbed/vertices/dense'" in msg and "KeyError" not in msg


def test_checks_are_one_extensible_list():
    assert all(callable(f) for f in config_checks.CHECKS)
    cfg = pconfig.load(CONFIG, "quick")
    extra = lambda c: iter([(("seed",), "always wrong")])
    assert config_checks.problems(cfg, [*config_checks.CHECKS, extra]) == [
        (("seed",), "always wrong")
    ]


# --- the Snakefile stops at load time ----------------------------------------------------------


def test_snakefile_refuses_a_bad_override_in_seconds_and_writes_nothing(tmp_path):
    for p in ("Snakefile", "config", "workflow"):
        src = ROOT / p
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / p)
    (tmp_path / "bad.yaml").write_text("profiles: {quick: {models: {kselect: {warmup: 30}}}}\n")
    t0 = time.perf_counter()
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "snakemake",
            "-n",
            "--cores",
            "1",
            "all",
            "--config",
            "profile=quick",
            "--configfile",
            "bad.yaml",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    wall = time.perf_counter() - t0
    out = r.stdout + r.stderr
    assert r.returncode != 0
    assert "ConfigError" in out and "models/kselect/warmup" in out, out
    assert "profiles/quick/models/kselect/warmup" in out
    # no job ran: a refused plan costs the config load, not a training (minutes); generous for a
    # loaded shared machine (22 s measured under a load of ~4 on 2 cores)
    assert wall < 60, f"took {wall:.1f} s"
    assert not (tmp_path / "results").exists()


# --- the damping testbed variant (testbed/variant, testbed/damping) -----------------------------


def _damping(**transient):
    """Edit: the damping variant, with `transient` keys overridden (zeta_range via the key)."""

    def edit(c):
        c["testbed"]["variant"] = "damping"
        zr = transient.pop("zeta_range", None)
        if zr is not None:
            c["testbed"]["damping"]["zeta_range"] = zr
        c["testbed"]["damping"]["transient"].update(transient)

    return edit


def test_the_shipped_damping_variant_is_accepted_and_faithful_is_the_default():
    cfg = pconfig.load(CONFIG, "default")
    assert cfg["testbed"]["variant"] == "faithful"
    raw = _base()
    _damping()(raw)
    assert pconfig.load_workflow_config(raw, "default")["testbed"]["variant"] == "damping"
    # a config without the new keys (older checkouts) is the faithful testbed, still accepted
    raw = _base()
    raw["testbed"].pop("variant")
    raw["testbed"].pop("damping")
    raw["damping_benchmark"]["trees"] = []
    assert "variant" not in pconfig.load_workflow_config(raw, "default")["testbed"]
    # ... but the damping benchmark needs the damping block, and says so
    raw["damping_benchmark"]["trees"] = ["medium"]
    with pytest.raises(pconfig.ConfigError, match="damping_benchmark/trees.*testbed/damping"):
        pconfig.load_workflow_config(raw, "default")


def test_damping_benchmark_trees_and_configs_must_exist():
    msg = _refused(lambda c: c["damping_benchmark"].update(trees=["medium"], configs=["joint64"]))
    assert "damping_benchmark/configs" in msg and "joint64" in msg
    msg = _refused(lambda c: c.update(trees=["sparse"]))
    assert "damping_benchmark/trees" in msg and "'medium' is not in trees" in msg


@pytest.mark.parametrize(
    "edit, key, fix",
    [
        (_damping(zeta_range=[0.2, 0.03]), "testbed/damping/zeta_range", "swap them"),
        (_damping(zeta_range=[0.05, 0.05]), "testbed/damping/zeta_range", "variant: faithful"),
        (_damping(zeta_range=[0.0, 0.2]), "testbed/damping/zeta_range", "must lie in (0, 1]"),
        (_damping(zeta_range=[0.03, 1.5]), "testbed/damping/zeta_range", "must lie in (0, 1]"),
        (
            _damping(start_s=-1.0),
            "testbed/damping/transient/start_s",
            "raise start_s to at least 1",
        ),
        (_damping(start_s=0.5), "testbed/damping/transient/start_s", "raise start_s to at least 1"),
        # 8 + 5 s ends after the 12.5 s window: both shifts fit, and so does a longer window
        (
            _damping(start_s=8.0),
            "testbed/damping/transient/calm_s",
            "lower start_s to at most 7.5, or lower calm_s to at most 4.5, or raise testbed/n_train to "
            "at least 312",
        ),
        # one period of band_hz[0] = 0.35 Hz is 2.86 s
        (_damping(calm_s=2.0), "testbed/damping/transient/calm_s", "raise calm_s to at least 2.86"),
        (_damping(calm_s=0.0), "testbed/damping/transient/calm_s", "raise calm_s to at least 2.86"),
    ],
)
def test_bad_damping_settings_stop_at_load_naming_the_key_and_the_fix(edit, key, fix):
    msg = _refused(edit)
    assert f"config key '{key}'" in msg, msg
    assert fix in msg, msg
    assert "Fix config/trees.yaml" in msg


def test_a_bad_zeta_range_is_refused_even_for_the_faithful_variant():
    msg = _refused(lambda c: c["testbed"]["damping"].update(zeta_range=[0.3, 0.1]))
    assert "config key 'testbed/damping/zeta_range'" in msg


def test_the_transient_is_checked_only_for_the_damping_variant():
    # quick's 2.5 s window holds no 5 s calm: fine while faithful, refused as damping
    pconfig.load(CONFIG, "quick")
    msg = _refused(_damping(), "quick")
    assert "config key 'testbed/damping/transient/calm_s'" in msg
    assert "n_train / fps = 2.5 s" in msg and "raise testbed/n_train to at least 264" in msg


def test_the_damping_variant_needs_its_settings():
    def edit(c):
        c["testbed"]["variant"] = "damping"
        c["testbed"].pop("damping")

    assert "config key 'testbed/damping' is missing" in _refused(edit)
    assert "testbed/variant" in _refused(lambda c: c["testbed"].update(variant="windy"))


def test_the_damping_lead_in_uses_the_lowest_zeta_of_the_range():
    # zeta 0.005 at 0.35 Hz: tau_max 91 s, a lead-in far beyond the 60 s wind period; the same
    # value as testbed/zeta would be refused too, but only the range matters for this variant
    msg = _refused(_damping(zeta_range=[0.005, 0.2]))
    assert "config key 'testbed/lead_in_tau'" in msg and "testbed/damping/zeta_range[0]" in msg
    raw = _base()
    raw["testbed"]["zeta"] = 0.005  # unused by the damping variant
    _damping()(raw)
    pconfig.load_workflow_config(raw, "default")


@pytest.mark.parametrize(
    "value, seeds, expected",
    [("first", [3, 1, 2], [3]), ("all", [0, 1, 2], [0, 1, 2]), ([2, 0], [0, 1, 2], [2, 0])],
)
def test_study_seeds_resolve_first_all_or_a_list(value, seeds, expected):
    raw = _base()
    raw.update(seeds=seeds)
    raw["speed_accuracy"]["seeds"] = value
    cfg = pconfig.load_workflow_config(raw, "default")
    assert pconfig.study_seeds(cfg) == expected
