"""Model components: rotations, canonical pose at init, wind window, parts, ours, checkpoints."""

import math

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from physgs.models import MODEL_NAMES, build_model, load_checkpoint, save_checkpoint
from physgs.models.encoding import fourier
from physgs.models.gaussians import quat_to_rotmat, rotate_about_pivot
from physgs.models.oscillator import integrate
from physgs.models.parts import kmeans_parts
from physgs.models.windwindow import wind_window, window_columns, window_step
from oracles import model_context, quick_models_cfg

LEAD_IN = 160
FPS = 24


def _ctx(n=200, seed=0):
    return model_context(n, seed, LEAD_IN)


def _cov(q, s):
    R = quat_to_rotmat(q)
    return R @ torch.diag_embed(s**2) @ R.transpose(-1, -2)


def test_rotating_an_elongated_gaussian_keeps_it_on_its_axis():
    # A needle along the branch direction d, centred 1 unit from the pivot along d.
    d = torch.tensor([[0.6, 0.0, 0.8]], dtype=torch.float64)
    pivot = torch.tensor([[0.1, -0.2, 0.3]], dtype=torch.float64)
    q0 = torch.tensor(
        Rotation.align_vectors([d[0].numpy()], [[1.0, 0, 0]])[0].as_quat(scalar_first=True)
    )[None]
    scales = torch.tensor([[1.0, 0.05, 0.05]], dtype=torch.float64)
    axis = torch.tensor([[0.0, 1.0, 0.0]], dtype=torch.float64)
    angle = torch.tensor([0.7], dtype=torch.float64)
    means, quats = rotate_about_pivot(pivot + d, q0, axis, angle, pivot)
    R = torch.tensor(Rotation.from_rotvec(0.7 * axis[0].numpy()).as_matrix())  # scipy oracle
    d_rot = R @ d[0]
    assert torch.allclose(means[0], pivot[0] + d_rot, atol=1e-12)
    # Long axis of the new covariance is the rotated branch direction (position and orientation
    # moved together), and the covariance is R Sigma R^T.
    cov = _cov(quats, scales)[0]
    assert torch.allclose(cov, R @ _cov(q0, scales)[0] @ R.T, atol=1e-12)
    evals, evecs = torch.linalg.eigh(cov)
    assert abs(abs(float(evecs[:, -1] @ d_rot)) - 1) < 1e-10


def test_fourier_features_match_explicit_formula():
    x = torch.tensor([[0.3, -0.5, 0.9]])
    f = fourier(x, 2)
    expected = [0.3, -0.5, 0.9]
    for k in range(2):
        a = [(2**k) * math.pi * v for v in (0.3, -0.5, 0.9)]
        expected += [math.sin(v) for v in a] + [math.cos(v) for v in a]
    assert torch.allclose(f[0], torch.tensor(expected), atol=1e-6)


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_every_model_starts_exactly_at_the_canonical_pose(name):
    ctx, w = _ctx()
    model = build_model(name, ctx, quick_models_cfg(), seed=0)
    c = model.canonical_state()
    for j in (0, 150, 349):
        g = model.gaussians_at(j, torch.tensor(w))
        for a, b in (
            (g.means, c.means),
            (g.scales, c.scales),
            (g.opacities, c.opacities),
            (g.colors, c.colors),
        ):
            assert torch.equal(a, b)
        # Identity rotation composed with a zero-angle swing stays exactly identity.
        assert torch.equal(g.quats, c.quats)


def test_wind_window_ends_at_t_steps_three_frames_and_reads_the_lead_in():
    step = window_step(6.0, 48, 24)
    assert step == 3
    cols = window_columns(0, LEAD_IN, 48, step)
    assert cols[-1] == LEAD_IN and np.all(np.diff(cols) == 3) and cols.size == 48
    assert cols[0] == LEAD_IN - 141 and cols[0] >= 0  # frame 1 reads 141 frames into the lead-in
    wind = torch.arange(LEAD_IN + 350, dtype=torch.float32)  # value = column index
    w = wind_window(wind, 10, LEAD_IN, 2.0, 4.0, 48, step)
    assert torch.equal(
        w * 4.0 + 2.0, torch.tensor(window_columns(10, LEAD_IN, 48, 3), dtype=torch.float32)
    )
    with pytest.raises(ValueError, match="lead-in"):
        window_columns(0, 100, 48, step)
    with pytest.raises(ValueError, match="subsample evenly"):
        window_step(6.0, 50, 24)


def test_wind_models_see_the_wind_and_use_frozen_training_statistics():
    ctx, w = _ctx()
    model = build_model("mlp_wind", ctx, quick_models_cfg())
    f_train = model.features(5, torch.tensor(w, dtype=torch.float32))
    f_weak = model.features(5, torch.tensor(0.71 * w, dtype=torch.float32))
    win = f_train[0, -48:]
    assert abs(float(win.mean())) < 1.0  # standardised
    # Scaling the wind shifts the standardised history (not re-standardised per condition).
    expected = (0.71 * w[window_columns(5, LEAD_IN, 48, 3)] - ctx.wind_mean) / ctx.wind_std
    assert np.allclose(f_weak[0, -48:].numpy(), expected, atol=1e-5)


def test_kmeans_parts_deterministic_and_checked():
    ctx, _ = _ctx(300)
    a = kmeans_parts(ctx.canonical_xyz, 12, seed=3)
    b = kmeans_parts(ctx.canonical_xyz, 12, seed=3)
    assert np.array_equal(a, b) and set(a) == set(range(12))
    with pytest.raises(ValueError, match="exceeds"):
        kmeans_parts(ctx.canonical_xyz[:10], 11, seed=0)


def test_ours_bounds_guard_and_theta():
    ctx, w = _ctx()
    cfg = quick_models_cfg()
    model = build_model("ours", ctx, cfg, config="joint96")
    assert model.K == 96 and model.part_labels.shape == (200,)
    lo, hi = (2 * math.pi * f for f in cfg["ours"]["omega_hz"])
    assert hi * model.dt / model.substeps <= cfg["ours"]["rk4_guard"]
    with torch.no_grad():
        model.omega_raw.fill_(50.0)  # saturates at the upper bound: still integrable
        model.zeta_raw.fill_(-50.0)
        model.gain_raw.fill_(0.05)
    assert torch.all(model.omega <= hi + 1e-4) and torch.all(model.zeta >= cfg["ours"]["zeta"][0])
    theta = model.part_theta(torch.tensor(w))
    assert theta.shape == (96, w.size) and torch.isfinite(theta).all()
    # vbar is that condition's mean wind; same numbers as a direct solver call.
    direct = integrate(
        model.omega, model.zeta, model.gain, w, float(w.mean()), 1 / FPS, model.substeps
    )
    assert torch.allclose(theta, direct)


def test_checkpoint_roundtrip(tmp_path):
    ctx, w = _ctx()
    for name in ("ours", "d3dgs_wind"):
        model = build_model(name, ctx, quick_models_cfg())
        with torch.no_grad():
            for p in model.parameters():
                p.add_(0.01 * torch.randn_like(p))
        path = tmp_path / f"{name}.pt"
        save_checkpoint(
            path,
            model,
            name=name,
            config="single",
            seed=0,
            models_cfg=quick_models_cfg(),
            train_cfg={},
            stats={"iterations": 1},
        )
        back = load_checkpoint(path)
        a = model.gaussians_at(200, torch.tensor(w))
        b = back.gaussians_at(200, torch.tensor(w))
        for field in ("means", "quats", "scales", "opacities", "colors"):
            # scales too: a loaded set skips the starting-scale search (knn=None)
            assert torch.equal(getattr(a, field), getattr(b, field)), (name, field)
        assert back.checkpoint_info["models_cfg"]["canonical"]["knn"] is not None
    (tmp_path / "bad.pt").write_bytes(b"not a checkpoint")
    with pytest.raises(ValueError, match="corrupt"):
        load_checkpoint(tmp_path / "bad.pt")
    with pytest.raises(FileNotFoundError, match="snakemake"):
        load_checkpoint(tmp_path / "missing.pt")


def test_ours_drives_each_condition_with_its_nominal_mean_speed():
    """vbar = the condition's nominal mean speed, also for a rescaled (unseen) wind."""
    import dataclasses

    ctx, w = _ctx()
    nominal = 6.3  # the anemometer record's mean differs from the condition's mean speed
    ctx = dataclasses.replace(ctx, vbar_ratio=nominal / float(w.mean()))
    m = build_model("ours", ctx, quick_models_cfg(), config="single", seed=0)
    with torch.no_grad():
        m.gain_raw.fill_(0.3)
        for scale in (1.0, 0.71):
            wind = torch.as_tensor(scale * w, dtype=torch.float64)
            got = m.part_theta(wind)
            want = integrate(
                m.omega.double(),
                m.zeta.double(),
                m.gain.double(),
                wind,
                scale * nominal,
                1.0 / FPS,
                m.substeps,
                backend="reference",
            )
            torch.testing.assert_close(got.double(), want, rtol=1e-5, atol=1e-7)


@pytest.mark.parametrize(
    "name, top_hz", [("mlp", 1.5), ("mlp_wind", 0.75), ("d3dgs", 3.0), ("d3dgs_wind", "window")]
)
def test_field_time_encoding_puts_its_top_band_at_the_named_frequency(name, top_hz):
    """The top time band's sine is sin(2 pi f t) in seconds (t = frame / fps), whatever the
    window; "window" keeps Deformable-3DGS's t_norm = frame / (n_train - 1): f = 2^(L-2) / T."""
    ctx, w = _ctx()
    cfg = quick_models_cfg()
    family = "mlp" if name.startswith("mlp") else "d3dgs"
    cfg[family]["time_top_hz"][name] = top_hz
    bands = int(cfg[family]["time_bands"])
    model = build_model(name, ctx, cfg)
    wind = torch.tensor(w, dtype=torch.float32)
    n_pos = 3 * (1 + 2 * int(cfg[family]["pos_bands"]))
    col = n_pos + 1 + 2 * (bands - 1)  # [t, sin0, cos0, sin1, cos1, ...]: the top band's sine
    frames = np.arange(0, 300, 7)
    got = np.array([float(model.features(int(f), wind)[0, col]) for f in frames])
    window_s = (ctx.n_train - 1) / ctx.fps
    f_hz = 2.0 ** (bands - 2) / window_s if top_hz == "window" else top_hz
    np.testing.assert_allclose(got, np.sin(2 * np.pi * f_hz * frames / FPS), atol=2e-5)


@pytest.mark.parametrize(
    "family, edited, kept", [("mlp", "mlp_wind", "mlp"), ("d3dgs", "d3dgs", "d3dgs_wind")]
)
def test_a_fields_time_scale_edit_leaves_its_sibling_field_up_to_date(family, edited, kept):
    import copy

    from physgs.experiments.recipe import job_spec
    from oracles import quick_config

    cfg = quick_config()
    before = {m: job_spec(cfg, m, "single", seed=0) for m in (edited, kept)}
    cfg2 = copy.deepcopy(cfg)
    cfg2["models"][family]["time_top_hz"][edited] = 2.5
    assert job_spec(cfg2, kept, "single", seed=0) == before[kept]
    after = job_spec(cfg2, edited, "single", seed=0)
    assert after != before[edited]
    assert after["settings"][family]["time_top_hz"] == {edited: 2.5}
    # the narrowed settings still build the field with its own time scale
    ctx, _ = model_context(50, seed=0, lead_in=10)
    field = build_model(edited, ctx, after["settings"])
    assert field.time_top_hz == 2.5


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_rotate_parts_equals_the_per_gaussian_rotation_to_rounding(dtype):
    from physgs.models.gaussians import rotate_parts

    g = torch.Generator().manual_seed(0)
    N, K = 500, 7
    means, quats = (
        torch.randn(N, 3, generator=g, dtype=dtype),
        torch.nn.functional.normalize(torch.randn(N, 4, generator=g, dtype=dtype), dim=-1),
    )
    lab = torch.randint(0, K, (N,), generator=g)
    axis = torch.nn.functional.normalize(torch.randn(K, 3, generator=g, dtype=dtype), dim=-1)
    angle = 0.3 * torch.randn(K, generator=g, dtype=dtype)
    pivot = torch.randn(K, 3, generator=g, dtype=dtype)
    m1, q1 = rotate_parts(means, quats, lab, axis, angle, pivot)
    m0, q0 = rotate_about_pivot(means, quats, axis[lab], angle[lab], pivot[lab])
    assert m1.dtype == q1.dtype == dtype
    tol = 4 * torch.finfo(dtype).eps * 8  # |means| < ~8: a few ulps of the largest
    torch.testing.assert_close(m1, m0, rtol=0, atol=tol)
    torch.testing.assert_close(q1, q0, rtol=0, atol=4 * torch.finfo(dtype).eps)
    # and against scipy's rotation of one Gaussian
    p = int(lab[0])
    R = Rotation.from_rotvec((axis[p] * angle[p]).double().numpy()).as_matrix()
    ref = pivot[p].double().numpy() + R @ (means[0] - pivot[p]).double().numpy()
    assert np.allclose(m1[0].double().numpy(), ref, atol=1e-5)


def test_part_theta_without_autograd_reuses_its_series_until_a_parameter_changes():
    ctx, wind = model_context(120, seed=4, lead_in=30)
    model = build_model("ours", ctx, quick_models_cfg(), K=4)
    with torch.no_grad():
        model.gain_raw.copy_(torch.linspace(-0.5, 0.5, 4))
    w = torch.as_tensor(wind)
    with torch.no_grad():
        a = model.part_theta(w)
        assert model.part_theta(w) is a  # same series: not integrated again
        w2 = w.clone()
        w2[5] += 1.0
        assert not torch.equal(model.part_theta(w2), a)  # another wind
        model.gain_raw.mul_(2.0)  # in place: its version moves
        b = model.part_theta(w)
        assert torch.allclose(b, 2 * a, rtol=1e-10, atol=0)
        model.freeze_parts(np.array([True, False, False, False]))
        assert torch.equal(model.part_theta(w)[0], torch.zeros_like(a[0]))
    with torch.enable_grad():
        c = model.part_theta(w)
    assert c.requires_grad and torch.equal(c.detach(), model._integrate_theta(w).detach())


def test_ours_training_frame_integrates_only_up_to_it_bit_for_bit():
    # Oracle: the whole record's theta, computed without autograd (the memo path): the oscillators
    # start from rest and are causal, so the first columns are the same numbers.
    from physgs.models.ours import OscillatorPrior

    ctx, _ = model_context(50, seed=0, lead_in=10)
    m = build_model("ours", ctx, quick_models_cfg(), config="single")
    assert isinstance(m, OscillatorPrior)
    wind = torch.as_tensor(np.random.default_rng(0).uniform(4, 8, 60), dtype=torch.float64)
    with torch.no_grad():
        m.gain_raw.add_(0.5)
        full = m.part_theta(wind).clone()
    for upto in (11, 33, 60):
        part = m.part_theta(wind, upto=upto)
        assert part.shape == (full.shape[0], upto)
        assert torch.equal(part.detach(), full[:, :upto])
