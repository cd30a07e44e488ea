"""Training loop on a tiny synthetic dataset rendered by the rasterizer (analytic wiggle)."""

import random

import numpy as np
import pytest
import torch

from physgs.experiments import job_spec, train_and_save
from physgs.models import MODEL_NAMES, build_model, load_checkpoint
from physgs.render import render_state
from physgs.train import TrainingError, photometric_loss, ssim, train_model
from physgs.train.seeding import seed_everything
from oracles import quick_train_cfg


@pytest.fixture(scope="module")
def data(swaying):
    return swaying


def _cfg(iterations=24, warmup=6):
    return quick_train_cfg(iterations, warmup)


def _eval_loss(model, data):
    with torch.no_grad():
        tot = 0.0
        for j in range(0, data.n_train, 4):
            s = model.gaussians_at(j, torch.tensor(data.wind[0]))
            out = render_state(s, data.train_camera, data.background)
            tgt = torch.from_numpy(data.frames[0, j]).float() / 255
            tot += float(photometric_loss(out.rgb, tgt)[0])
    return tot


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_short_training_lowers_the_loss(name, data):
    cfg = _cfg()
    model = build_model(name, data, cfg["models"], seed=0)
    before = _eval_loss(model, data)
    res = train_model(model, data, cfg["train"], conditions=[0], seed=0, progress=False)
    after = _eval_loss(res.model, data)
    assert after < 0.9 * before, (name, before, after)
    assert (
        len(res.log) == 24 and res.log[0]["phase"] == "warmup" and res.log[-1]["phase"] == "deform"
    )


def test_train_and_save_writes_checkpoint_and_log(tmp_path, data):
    cfg = _cfg(iterations=6, warmup=2)
    ck, lg = tmp_path / "ours_joint32.pt", tmp_path / "ours_joint32.loss.csv"
    train_and_save(
        data, job_spec(cfg, "ours", "joint32"), checkpoint_path=ck, loss_path=lg, progress=False
    )
    m = load_checkpoint(ck)
    st = m.checkpoint_info["stats"]
    assert st["iterations"] == 6 and st["conditions"] == [0, 1, 2]
    assert st["wind_mean"] == pytest.approx(float(np.mean(data.wind[0].astype(np.float64))))
    assert m.K == 32 and lg.read_text().splitlines()[0].startswith("iteration,phase")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([ck.name, lg.name])  # no temp files


def test_divergence_stops_with_a_named_error_and_no_checkpoint(tmp_path, data):
    cfg = _cfg(iterations=5, warmup=1)
    cfg["train"]["lr"] = {k: 1e30 for k in cfg["train"]["lr"]}
    # the first (warm-up) update sends the canonical set to 1e30: named at once
    with pytest.raises(
        TrainingError,
        match=r"model 'mlp_single'.*update of iteration 0.*"
        r"likely setting: train\.lr\.\w+ \(now 1e\+30\)",
    ):
        train_and_save(
            data,
            job_spec(cfg, "mlp", "single"),
            checkpoint_path=tmp_path / "m.pt",
            loss_path=tmp_path / "m.csv",
            progress=False,
        )
    assert list(tmp_path.iterdir()) == []


# -- reproducibility ---------------------------------------------------------------------------


def _draws(seed):
    seed_everything(seed)
    lin = torch.nn.Linear(16, 8)  # weights from torch's global generator
    w, b = lin.weight.detach().clone(), lin.bias.detach().clone()
    return w, b, np.random.rand(3), random.random()


def test_seed_everything_pins_every_global_source():
    torch.rand(5)  # whatever ran before in the process must not matter
    w1, b1, n1, r1 = _draws(7)
    np.random.rand(11), random.random(), torch.randn(3)
    w2, b2, n2, r2 = _draws(7)
    assert torch.equal(w1, w2) and torch.equal(b1, b2)  # bitwise
    assert np.array_equal(n1, n2) and r1 == r2
    w3, b3, n3, r3 = _draws(8)
    assert not torch.equal(w1, w3) and not np.array_equal(n1, n3) and r1 != r3


def test_seed_everything_rejects_non_integers():
    for bad in (-1, 1.5, "3", True):
        with pytest.raises(ValueError, match="non-negative integer"):
            seed_everything(bad)
    seed_everything(2**40)  # numpy's legacy seed takes it modulo 2**32


def test_same_seed_same_checkpoint_weights(data):
    # the field's first layers come from torch's global generator (nn.Linear's init), the parts
    # from seeded k-means, the frame draws from the loop's own generator
    def run(name, seed, junk):
        torch.randn(junk)  # a different history of the global generator
        seed_everything(seed)
        m = build_model(name, data, _cfg()["models"], seed=seed)
        res = train_model(
            m,
            data,
            _cfg(iterations=8, warmup=2)["train"],
            conditions=[0],
            seed=seed,
            progress=False,
        )
        return {k: v.clone() for k, v in res.model.state_dict().items()}, res.log

    for name in ("mlp", "ours"):
        (a, la), (b, lb) = run(name, 3, 1), run(name, 3, 17)
        assert a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a), name
        assert [r["loss"] for r in la] == [r["loss"] for r in lb], name
    c, _ = run("mlp", 4, 1)
    a, _ = run("mlp", 3, 1)
    assert not torch.equal(a["field.layers.0.weight"], c["field.layers.0.weight"])


def test_joint_configurations_are_for_ours_only(data):
    with pytest.raises(ValueError, match="not trained in configuration"):
        build_model("mlp", data, _cfg()["models"], config="joint96")


def test_ssim_against_direct_float64_formula():
    # Oracle: the SSIM formula evaluated directly in float64 with explicit loops over pixels,
    # using the same zero-padded Gaussian window.
    rng = np.random.default_rng(1)
    a = rng.random((9, 8, 1))
    b = np.clip(a + 0.1 * rng.standard_normal(a.shape), 0, 1)
    x = np.arange(11) - 5.0
    g = np.exp(-(x**2) / (2 * 1.5**2))
    g /= g.sum()
    w = np.outer(g, g)
    pa, pb = (np.pad(z[..., 0], 5) for z in (a, b))
    vals = []
    for i in range(9):
        for j in range(8):
            A, B = pa[i : i + 11, j : j + 11], pb[i : i + 11, j : j + 11]
            ma, mb = (w * A).sum(), (w * B).sum()
            va, vb = (w * A * A).sum() - ma**2, (w * B * B).sum() - mb**2
            cov = (w * A * B).sum() - ma * mb
            vals.append(
                (2 * ma * mb + 1e-4)
                * (2 * cov + 9e-4)
                / ((ma**2 + mb**2 + 1e-4) * (va + vb + 9e-4))
            )
    got = ssim(torch.tensor(a), torch.tensor(b))
    assert float(got) == pytest.approx(np.mean(vals), abs=1e-10)
    assert float(ssim(torch.tensor(a), torch.tensor(a))) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("target_grad", [False, True])
def test_ssim_gradients_against_finite_differences(target_grad):
    # Oracle: central finite differences (torch.autograd.gradcheck, float64). ssim blurs a
    # target that needs no gradient apart, under no_grad; both branches must differentiate.
    rng = np.random.default_rng(2)
    a = torch.tensor(rng.random((13, 12, 2)), requires_grad=True)
    b = torch.tensor(rng.random((13, 12, 2)), requires_grad=target_grad)
    assert torch.autograd.gradcheck(lambda u, v: ssim(u, v), (a, b), eps=1e-6, atol=1e-8)


@pytest.mark.parametrize("tiled", [False, True])
def test_blur_equals_scipys_zero_padded_correlation(tiled):
    # Oracle: scipy.ndimage.correlate1d along each axis, float64, zeros outside the image (the
    # 3DGS SSIM's padding), on a side that is not a multiple of the tile.
    from scipy.ndimage import correlate1d

    from physgs.train.losses import blur

    rng = np.random.default_rng(3)
    z = rng.random((2, 45, 70))
    x = np.arange(11) - 5.0
    g = np.exp(-(x**2) / (2 * 1.5**2))
    g /= g.sum()
    want = correlate1d(correlate1d(z, g, axis=1, mode="constant"), g, axis=2, mode="constant")
    got = blur(torch.tensor(z), 11, 1.5, tiled=tiled).numpy()
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-14)


def test_tiled_blur_gradients_against_finite_differences():
    from physgs.train.losses import blur

    z = torch.tensor(np.random.default_rng(4).random((1, 37, 33)), requires_grad=True)
    assert torch.autograd.gradcheck(lambda u: blur(u, 11, 1.5, tiled=True), (z,), eps=1e-6)


def test_ssim_on_large_images_takes_the_tiles_with_the_same_value(monkeypatch):
    import physgs.train.losses as losses

    rng = np.random.default_rng(5)
    a = torch.tensor(rng.random((330, 341, 1)))
    b = torch.tensor(np.clip(a.numpy() + 0.1 * rng.standard_normal(a.shape), 0, 1))
    calls = []
    tiled_rows = losses._blur_rows_tiled
    monkeypatch.setattr(losses, "_blur_rows_tiled", lambda *x: calls.append(1) or tiled_rows(*x))
    tiled = float(losses.ssim(a, b))
    assert calls and min(a.shape[:2]) >= losses.TILED_BLUR_MIN_SIDE
    monkeypatch.setattr(losses, "TILED_BLUR_MIN_SIDE", 10**6)
    assert tiled == pytest.approx(float(losses.ssim(a, b)), abs=1e-13)


def test_a_training_job_never_imports_torch_dynamo(tmp_path):
    # torch.optim's optimisers import torch._dynamo (and sympy) when built: ~1 CPU-s of every
    # job's start-up. A fresh process trains ours and an MLP field as a job does and must not.
    import subprocess
    import sys
    from pathlib import Path

    code = f"""
import sys
sys.path.insert(0, {str(Path(__file__).parent)!r})
from conftest import swaying_dataset
from oracles import quick_train_cfg
from physgs.experiments import job_spec, train_and_save
data = swaying_dataset()
cfg = quick_train_cfg(4, 1)
for name in ("ours", "mlp"):
    train_and_save(data, job_spec(cfg, name, "single"), checkpoint_path={str(tmp_path)!r} + f"/{{name}}.pt",
                   loss_path={str(tmp_path)!r} + f"/{{name}}.csv", progress=False)
print("dynamo" if "torch._dynamo" in sys.modules else "clean")
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "clean"
