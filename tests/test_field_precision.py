"""bfloat16 deformation fields: close to a float32 oracle, float32 where precision matters, and
refused (naming the setting) on a CPU that would emulate bf16."""

import copy
from pathlib import Path

import pytest
import torch
import yaml

import physgs.config as pconfig
from physgs.experiments import fit, job_spec
from physgs.models import build_model, load_checkpoint, save_checkpoint
from physgs.models.fields import DeformationField
from oracles import model_context, quick_config, quick_models_cfg

HEADS = ("dx", "dq", "ds")
ROOT = Path(__file__).resolve().parents[1]


def _pair(in_dim=40, depth=4, width=64, skip=1, seed=0):
    """(float32 field, bfloat16 field) with identical weights and non-zero heads."""
    torch.manual_seed(seed)
    f32 = DeformationField(in_dim, depth, width, skip, HEADS)
    for h in f32.heads.values():
        torch.nn.init.normal_(h.weight, std=0.1)
    b16 = DeformationField(in_dim, depth, width, skip, HEADS, "bfloat16")
    b16.load_state_dict(f32.state_dict())
    return f32, b16


def test_bf16_field_matches_a_float64_oracle_to_bf16_accuracy():
    f32, b16 = _pair()
    f64 = copy.deepcopy(f32).double()
    x = torch.rand(500, 40) * 2 - 1
    with torch.no_grad():
        ref, o16, o32 = f64(x.double()), b16(x), f32(x)
    for k in HEADS:
        scale = ref[k].abs().max()
        assert o16[k].dtype == torch.float32  # the heads run in float32
        err16 = float((o16[k].double() - ref[k]).abs().max() / scale)
        err32 = float((o32[k].double() - ref[k]).abs().max() / scale)
        # bf16 keeps 8 significant bits (2^-8 = 0.4%); four layers compound it to a few percent
        assert 1e-4 < err16 < 5e-2, (k, err16)
        assert err32 < 1e-5  # the float32 path is untouched by the autocast wrapper


def test_bf16_gradients_are_float32_and_point_the_same_way():
    f32, b16 = _pair()
    x = torch.rand(500, 40) * 2 - 1
    grads = []
    for f in (f32, b16):
        f.zero_grad()
        sum(o.square().sum() for o in f(x).values()).backward()
        grads.append(torch.cat([p.grad.flatten() for p in f.parameters()]))
    g32, g16 = grads
    assert g16.dtype == torch.float32 and torch.isfinite(g16).all()
    assert float(torch.nn.functional.cosine_similarity(g32, g16, dim=0)) > 0.99
    assert all(p.dtype == torch.float32 for p in b16.parameters())  # Adam's master weights


@pytest.mark.parametrize("name", ["mlp", "mlp_wind", "d3dgs", "d3dgs_wind"])
def test_bf16_field_starts_exactly_at_the_canonical_pose_and_reloads_as_bf16(name, tmp_path):
    ctx, wind = model_context(300, 0, lead_in=200)
    cfg = quick_models_cfg()
    for arch in ("mlp", "d3dgs"):
        cfg[arch]["precision"] = "bfloat16"
    m = build_model(name, ctx, cfg)
    assert m.field.precision == "bfloat16"
    st = m.deform(5, torch.as_tensor(wind[None], dtype=torch.float32)[0])
    assert torch.equal(st.means, m.canonical.means)  # zero heads: exactly no offset
    save_checkpoint(
        tmp_path / "m.pt",
        m,
        name=name,
        config="single",
        seed=0,
        models_cfg=cfg,
        train_cfg={},
        stats={},
    )
    assert load_checkpoint(tmp_path / "m.pt").field.precision == "bfloat16"


def test_an_unknown_precision_stops_at_config_load_naming_the_key():
    cfg = yaml.safe_load((ROOT / "config" / "trees.yaml").read_text())
    cfg["models"]["d3dgs"]["precision"] = "float16"
    with pytest.raises(pconfig.ConfigError, match="models/d3dgs/precision"):
        pconfig.validate(cfg)


def test_training_a_bf16_field_without_native_bf16_stops_naming_the_setting(monkeypatch):
    import physgs.models.fields as fields

    monkeypatch.setattr(fields, "native_bf16", lambda: False)
    cfg = quick_config()
    cfg["models"]["d3dgs"]["precision"] = "bfloat16"
    with pytest.raises(RuntimeError, match=r"models\.d3dgs\.precision.*float32"):
        fit(object(), job_spec(cfg, "d3dgs_wind", "single"), progress=False)
    cfg["models"]["d3dgs"]["precision"] = "float32"  # float32 passes the check (then fails later)
    with pytest.raises(Exception) as e:
        fit(object(), job_spec(cfg, "d3dgs_wind", "single"), progress=False)
    assert "precision" not in str(e.value)


def test_the_plan_stops_before_any_job_on_a_cpu_without_bf16_and_the_overlay_is_the_way_out(
    monkeypatch,
):
    """The workflow's plan-time check (Snakefile) refuses the default's bf16 fields on such a
    CPU, naming both keys and config/float32.yaml; that overlay, merged over trees.yaml as
    --configfile does, gives float32 fields that pass."""
    import physgs.models.fields as fields
    from physgs.experiments.recipe import check_precision_supported

    monkeypatch.setattr(fields, "native_bf16", lambda: False)
    raw = yaml.safe_load((ROOT / "config" / "trees.yaml").read_text())
    default = pconfig.load_workflow_config(copy.deepcopy(raw), "default")
    with pytest.raises(RuntimeError) as e:
        check_precision_supported(default["models"])
    msg = str(e.value)
    assert "models.mlp.precision and models.d3dgs.precision" in msg
    assert "config/float32.yaml" in msg
    overlay = yaml.safe_load((ROOT / "config" / "float32.yaml").read_text())
    for family, body in overlay["models"].items():
        raw["models"][family].update(body)
    check_precision_supported(pconfig.load_workflow_config(raw, "default")["models"])  # no raise
    quick = pconfig.load_workflow_config(
        yaml.safe_load((ROOT / "config" / "trees.yaml").read_text()), "quick"
    )
    check_precision_supported(quick["models"])  # the tests' profile runs on any CPU


def test_the_plans_check_trusts_the_cpus_bf16_flags_and_asks_onednn_without_them(monkeypatch):
    """At plan time (every Snakemake call) a CPU whose flags report native bf16 passes without
    oneDNN's probe (torch's start-up); without those flags the probe decides, and a training
    job always asks it."""
    import physgs.experiments.recipe as recipe
    import physgs.models.fields as fields

    default = pconfig.load_workflow_config(
        yaml.safe_load((ROOT / "config" / "trees.yaml").read_text()), "default"
    )["models"]
    monkeypatch.setattr(fields, "native_bf16", lambda: False)
    monkeypatch.setattr(recipe, "bf16_flags", lambda: ["avx512_bf16"])
    recipe.check_precision_supported(default, planning=True)  # the flags: no probe, no raise
    with pytest.raises(RuntimeError, match="config/float32.yaml"):
        recipe.check_precision_supported(default)  # a job asks oneDNN, whatever the flags
    monkeypatch.setattr(recipe, "bf16_flags", lambda: [])
    with pytest.raises(RuntimeError, match="config/float32.yaml"):
        recipe.check_precision_supported(default, planning=True)


def test_the_cpu_flags_are_read_as_the_kernel_writes_them_and_agree_with_onednn(tmp_path):
    from physgs.models.fields import native_bf16
    from physgs.provenance import bf16_flags, machine_cpu

    info = tmp_path / "cpuinfo"
    info.write_text("model name\t: Some CPU\nflags\t\t: fpu avx512f avx512_bf16 avx512_vnni\n")
    assert bf16_flags(info) == ["avx512_bf16"] and machine_cpu(info) == "Some CPU (avx512_bf16)"
    info.write_text("flags\t\t: fpu avx512f avx512_bf16x amx_tile amx_bf16\n")
    assert bf16_flags(info) == ["amx_bf16"]  # whole words only
    assert bf16_flags(tmp_path / "absent") == []
    if bf16_flags():  # this machine reports them: oneDNN's probe says the same
        assert native_bf16()


def test_bf16_field_gives_bitwise_equal_gradients_when_run_twice():
    _, b16 = _pair()
    x = torch.rand(300, 40) * 2 - 1
    grads = []
    for _ in range(2):
        b16.zero_grad()
        sum(o.square().sum() for o in b16(x).values()).backward()
        grads.append(torch.cat([p.grad.flatten() for p in b16.parameters()]))
    assert torch.equal(*grads)  # same command, same numbers holds for bf16 fields too
