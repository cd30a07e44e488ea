"""Where a training runs: ``train.device``, a job's GPU resources, the loop's device plumbing,
device-free checkpoints and the GPU check's CPU run (``benchmarks/gpu_check.py --device cpu``).

No GPU is needed: the CUDA paths are checked by the GPU check itself on a GPU machine
(docs/performance.md); here the same code runs on the CPU and is held to the CPU's results.
"""

from __future__ import annotations

import importlib.util
import io
from pathlib import Path

import numpy as np
import pytest
import torch

import physgs.config
from physgs.config_checks import device_is_available
from physgs.experiments import job_spec, train_and_save
from physgs.experiments.recipe import heldout_split
from physgs.models import build_model, load_checkpoint
from physgs.models.checkpoint import _device_free
from physgs.train import train_model
from physgs.device import asks_for_gpu, check_setting, resolve_device
from physgs.testbed.standin import geometry_stand_in
from physgs.train.holdout import HoldoutEval
from oracles import quick_train_cfg

ROOT = Path(__file__).resolve().parents[1]
NO_GPU = not torch.cuda.is_available()


def _script(name: str):
    """A benchmark or tool loaded as a module (as ``python script.py`` would run it)."""
    path = next(p for p in (ROOT / "benchmarks" / name, ROOT / "tools" / name) if p.is_file())
    spec = importlib.util.spec_from_file_location(path.stem, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize(
    "resources, gpu",
    [
        (None, False),
        ({}, False),
        ({"mem_mb": 4000, "runtime": 60}, False),
        ({"gres": "gpu:1"}, True),
        ({"gres": "gpu:h100:2"}, True),
        ({"gres": "tmpspace:10G,gpu:1"}, True),
        ({"gres": "gpudirect:1"}, False),  # a gres whose name only starts with gpu
        ({"gpu": 1}, True),
        ({"gpu": 0}, False),
        ({"gpus": "2"}, True),
        ({"gpus": "h100:1"}, True),
    ],
)
def test_a_job_asks_for_a_gpu_through_its_resources(resources, gpu):
    assert asks_for_gpu(resources) is gpu


def test_the_setting_and_the_resources_resolve_the_device():
    cpu = torch.device("cpu")
    assert resolve_device("cpu") == cpu
    assert resolve_device("auto") == (cpu if NO_GPU else torch.device("cuda"))
    with pytest.raises(ValueError, match="train.device must be one of auto, cpu, cuda; got 'gpu'"):
        resolve_device("gpu")
    with pytest.raises(ValueError, match="resources ask for a GPU but train.device is cpu"):
        resolve_device("cpu", {"gres": "gpu:1"})


@pytest.mark.skipif(not NO_GPU, reason="checks the refusal where torch sees no GPU")
def test_cuda_where_torch_sees_none_is_refused_naming_the_key_or_the_resources():
    with pytest.raises(RuntimeError, match="train.device is cuda, but torch sees no GPU"):
        check_setting("cuda")
    with pytest.raises(RuntimeError, match=r"resources ask for a GPU \(gres=gpu:1\) but torch"):
        resolve_device("auto", {"gres": "gpu:1"})
    cfg = physgs.config.load_workflow_config(physgs.config.read_yaml(ROOT / "config/trees.yaml"))
    assert list(device_is_available(cfg)) == []  # the shipped setting (auto) plans anywhere
    cfg["train"]["device"] = "cuda"
    [(key, msg)] = list(device_is_available(cfg))
    assert key == ("train", "device") and "torch sees no GPU" in msg


def test_the_schema_refuses_an_unknown_device():
    raw = physgs.config.read_yaml(ROOT / "config/trees.yaml")
    raw["train"]["device"] = "tpu"
    with pytest.raises(physgs.config.ConfigError, match="device"):
        physgs.config.load_workflow_config(raw)


def test_training_on_the_cpu_by_name_is_the_training_as_it_was(swaying):
    """device='cpu' (what train.device resolves to here) changes nothing: the same weights and
    losses as the loop called without a device, bit for bit."""
    cfg = quick_train_cfg(8, 2)

    def run(**kw):
        torch.manual_seed(0)
        m = build_model("ours", swaying, cfg["models"], seed=0)
        res = train_model(m, swaying, cfg["train"], conditions=[0], seed=0, progress=False, **kw)
        return res.model.state_dict(), [r["loss"] for r in res.log], res.stats

    a, la, sa = run()
    b, lb, sb = run(device="cpu")
    assert la == lb and all(torch.equal(a[k], b[k]) for k in a)
    assert sa["device"] == sb["device"] == "cpu"


def test_a_held_out_evaluator_on_another_device_is_refused(swaying):
    cfg = quick_train_cfg(8, 2)
    _, held = heldout_split(swaying.n_train, 5)
    ev = HoldoutEval.build(swaying, held, [0], cfg["train"], device="meta")
    assert ev.targets.device.type == "meta" and ev.winds.device.type == "meta"
    m = build_model("static", swaying, cfg["models"], seed=0)
    with pytest.raises(ValueError, match=r"targets are on meta, the training on cpu"):
        train_model(m, swaying, cfg["train"], conditions=[0], seed=0, progress=False, holdout=ev)


class _OnGpu:
    """A stand-in for a CUDA tensor (none here): where it lives, and its copy to the CPU."""

    def __init__(self, value: torch.Tensor):
        self.value, self.device = value, torch.device("cuda", 0)

    def cpu(self) -> torch.Tensor:
        return self.value.clone()


def test_checkpoints_are_saved_device_free(tmp_path, swaying):
    """A CPU state is saved as it is (the file unchanged); a state elsewhere comes to the CPU,
    in its order and with its modules' versions, which load_state_dict reads."""
    cfg = quick_train_cfg(4, 1)
    m = build_model("ours", swaying, cfg["models"], seed=0)
    sd = m.state_dict()
    assert _device_free(sd) is sd
    away = type(sd)((k, _OnGpu(v)) for k, v in sd.items())
    away._metadata = sd._metadata
    out = _device_free(away)
    assert list(out) == list(sd) and all(torch.equal(out[k], sd[k]) for k in sd)
    assert out._metadata == sd._metadata
    m2 = build_model("ours", swaying, cfg["models"], seed=1)
    m2.load_state_dict(out, strict=True)
    ck, lg = tmp_path / "ours.pt", tmp_path / "ours.csv"
    job = job_spec(cfg, "ours", "single")
    train_and_save(swaying, job, checkpoint_path=ck, loss_path=lg, progress=False, resources={})
    assert load_checkpoint(ck).checkpoint_info["stats"]["device"] == "cpu"


def test_the_gpu_check_runs_on_the_cpu_and_holds_the_reference_to_the_numba_kernels():
    """The GPU check's three parts on tiny sizes: (a) the PyTorch reference in float64 agrees
    with the numba kernels to rounding (images and gradients, turned and stretched Gaussians);
    (b) two CPU trainings from one seed agree bit for bit; (c) every rate is positive and its
    parts add up to the iteration."""
    gc = _script("gpu_check.py")
    cfg = physgs.config.load_workflow_config(
        physgs.config.read_yaml(ROOT / "config/trees.yaml"), "quick"
    )
    cpu = torch.device("cpu")
    par = gc.parity(cfg, "sparse", [24], cpu)
    ref64 = par[(par.backend == "reference") & (par.dtype == "float64")].iloc[0]
    assert ref64.image_max_abs < 1e-12
    assert max(ref64[f"grad_{k}"] for k in gc.FIELDS) < 1e-10
    assert (par[par.dtype == "float32"].image_max_abs < 1e-5).all()
    data = geometry_stand_in(cfg, "sparse", 24)
    _, summary = gc.curves(cfg, _observed_like(data), ["static"], 6, cpu, points=3)
    assert bool(summary.identical.iloc[0]) and np.isfinite(summary.heldout_psnr_cpu.iloc[0])
    r = gc.rates(cfg, ["sparse"], [24], [("ours", "single")], 2, cpu)
    parts = r[[f"ms_{p}" for p in gc.PARTS]].sum(axis=1)
    assert (r.wall_s_per_iter > 0).all() and (parts > 0).all()
    assert (r[[f"ms_{p}" for p in gc.PARTS if p != "other"]] >= 0).all().all()


def _observed_like(data):
    """The stand-in with varying frames (a flat target trains nothing) for the curves."""
    rng = np.random.default_rng(0)
    frames = rng.integers(0, 255, size=data.frames.shape, dtype=np.uint8)
    data.frames = frames
    return data


def test_paper_estimate_prices_a_plan_on_one_gpu_from_the_checks_rates(tmp_path):
    """The GPU paragraph: each planned training at its rate at the profile's resolution,
    warm-up at the static pose's; unrated jobs named, never guessed; other resolutions
    refused."""
    pe = _script("paper_estimate.py")
    rates = tmp_path / "rates.csv"
    rates.write_text(
        "tree,model,config,resolution,wall_s_per_iter,device,device_name,date,commit\n"
        "medium,static,single,512,0.005,cuda,H200,2026-11-28,abc1234\n"
        "medium,ours,single,512,0.010,cuda,H200,2026-11-28,abc1234\n"
        "medium,ours,single,128,0.001,cuda,H200,2026-11-28,abc1234\n"
    )
    planned = [
        ("train", "results/benchmarks/train/medium/seed0/ours_single.tsv"),
        ("train", "results/benchmarks/train/medium/seed1/ours_single.tsv"),
        ("train", "results/benchmarks/train/medium/seed0/mlp_single.tsv"),
        ("evaluate", "results/benchmarks/evaluate/medium/seed0/ours_single.tsv"),
    ]
    cfg = {"testbed": {"resolution": 512}, "train": {"iterations": 100_000, "warmup": 10_000}}
    [text, _] = pe.gpu_paragraph(rates, planned, cfg, ["single"], "paper")
    hours = 2 * (10_000 * 0.005 + 90_000 * 0.010) / 3600  # two rated trainings: 0.53 h
    assert f"**{hours:,.1f} GPU-hours**" in text and "the 2 rated trainings" in text
    assert "H200" in text and "Not priced: 1 trainings (`mlp` single 1)" in text
    cfg["testbed"]["resolution"] = 256
    with pytest.raises(SystemExit, match=r"rates at \[128, 512\] px, none at the paper"):
        pe.gpu_paragraph(rates, planned, cfg, ["single"], "paper")


def test_the_gpu_extra_is_optional_and_ci_stays_cpu_only():
    text = (ROOT / "pyproject.toml").read_text()
    assert 'gpu = ["gsplat' in text
    assert "[gpu]" not in (ROOT / ".ci/run").read_text()
    assert io.StringIO((ROOT / ".ci/run").read_text()).read().count('pip install -e ".[test]"') == 1
