"""Shared test oracles and small builders (as torchdiffeq's tests/problems.py).

One copy of each independent oracle that two or more test files check physgs against, and of the
small builders they share. Each oracle's docstring says what it is independent of. Imported as
``from oracles import ...``: tests/ has no __init__.py, so pytest puts it on sys.path (as for
workflow_helpers).
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import scipy.signal
import torch
from scipy.spatial.transform import Rotation

import physgs.config
from physgs.models import ModelContext
from physgs.testbed.dataset import build_dataset, save_dataset, simulate_tree

ROOT = Path(__file__).resolve().parents[1]


# -- the damped oscillator theta'' + 2 zeta omega theta' + omega^2 theta = f ----------------------


def gusty_wind(T, seed=0):
    """Synthetic gusty wind [T] m/s: 6 + 1.5 N(0, 1), seeded."""
    rng = np.random.default_rng(seed)
    return 6.0 + 1.5 * rng.standard_normal(T)  # [T] m/s


def wind_lsim(omega, zeta, gain, wind, vbar, dt):
    """float64 oracle for theta [T] (rad) under the drag-law forcing gain (v^2 - vbar^2), from rest:
    scipy.signal.lsim's exact first-order-hold LTI solution (matrix exponential) of the state-space
    system. Independent of physgs's RK4 solver (physgs.models.oscillator) and of the testbed's
    simulator (physgs.testbed.physics)."""
    A = [[0.0, 1.0], [-(omega**2), -2 * zeta * omega]]
    sys = scipy.signal.StateSpace(A, [[0.0], [gain]], [[1.0, 0.0]], [[0.0]])
    t = np.arange(len(wind)) * dt
    _, y, _ = scipy.signal.lsim(sys, wind**2 - vbar**2, t, X0=[0.0, 0.0], interp=True)
    return y


def forced_lsim(omega, zeta, forcing, dt):
    """scipy.signal.lsim of theta'' + 2 zeta omega theta' + omega^2 theta = f from rest, f sampled
    every dt and held first-order (linear) between samples: theta [T] in float64. Independent of
    physgs (the testbed's simulator, the RK4 solver, the recovery matcher and null control)."""
    t = np.arange(len(forcing)) * dt
    sys = scipy.signal.lti([1.0], [1.0, 2 * zeta * omega, omega**2])
    return scipy.signal.lsim(sys, forcing, t)[1]


def free_response(omega, zeta, theta0, t):
    """Closed-form unforced (homogeneous) response of an under-damped oscillator (zeta < 1)
    released at rest from theta0: theta0 exp(-zeta omega t) (cos wd t + zeta omega / wd sin wd t),
    wd = omega sqrt(1 - zeta^2). Independent of any integrator, physgs's or scipy's."""
    wd = omega * np.sqrt(1 - zeta**2)
    decay = np.exp(-zeta * omega * t)
    return theta0 * decay * (np.cos(wd * t) + zeta * omega / wd * np.sin(wd * t))


def step_response(omega, zeta, forcing, t):
    """Closed-form response of an under-damped oscillator (zeta < 1) started from rest under a
    constant forcing F: the static deflection F / omega^2 plus the free response released from
    -F / omega^2. Independent of any integrator, physgs's or scipy's."""
    return forcing / omega**2 + free_response(omega, zeta, -forcing / omega**2, t)


def t64(x):
    """x (a number or an array) as a 1-d float64 tensor."""
    return torch.tensor(np.atleast_1d(np.asarray(x, dtype=np.float64)), dtype=torch.float64)


# -- models ---------------------------------------------------------------------------------------


def quick_config():
    """config/trees.yaml resolved under the quick profile."""
    return physgs.config.load(ROOT / "config" / "trees.yaml", "quick")


def quick_models_cfg():
    """The quick profile's models section."""
    return quick_config()["models"]


def quick_train_cfg(iterations, warmup, K=4, **lr):
    """The quick profile shortened for a test: `iterations` (with `warmup`) on the fast backend,
    K parts for the single configuration, learning rates overridden by `lr`."""
    cfg = quick_config()
    cfg["train"].update(iterations=iterations, warmup=warmup, backend="fast")
    cfg["train"]["lr"].update(lr)
    cfg["models"]["configs"]["single"]["K"] = K
    return cfg


def model_context(n, seed, lead_in, wind=None):
    """(ModelContext, wind): n Gaussians in a tree-sized blob around z = 2 m at 24 fps, 300 training
    frames after `lead_in` frames, wind statistics from `wind` ([lead_in + 350] m/s; None draws
    6 + 1.5 N(0, 1) from the same generator as the positions)."""
    rng = np.random.default_rng(seed)
    xyz = rng.normal(size=(n, 3)) * [0.5, 0.5, 1.0] + [0.0, 0.0, 2.0]
    w = 6.0 + 1.5 * rng.standard_normal(lead_in + 350) if wind is None else wind
    return ModelContext(
        xyz.astype(np.float32),
        24,
        300,
        lead_in,
        float(w.mean()),
        float(w.std()),
        float((w**2 - w.mean() ** 2).std()),
        np.array([0.0, 1.0, 0.0]),
    ), w


# -- rendering ------------------------------------------------------------------------------------


def pixel_centres(cam):
    """(x, y) of every pixel centre [H, W], at half-integer pixel coordinates."""
    yy, xx = np.meshgrid(np.arange(cam.height) + 0.5, np.arange(cam.width) + 0.5, indexing="ij")
    return xx, yy


def rotation_wxyz(q):
    """scipy Rotation of quaternions stored (w, x, y, z), as physgs stores them (scipy reads
    (x, y, z, w)). Independent of physgs's quaternion code (quat_to_rotmat)."""
    return Rotation.from_quat(np.asarray(q)[..., [1, 2, 3, 0]])


# -- testbed --------------------------------------------------------------------------------------


def simulate_trees(cfg):
    """{tree: simulation} for every tree of a resolved config (physics only, no frames)."""
    tb = cfg["testbed"]
    return {t: simulate_tree(tb, cfg["presets"][t], seed=cfg["seed"], tree=t) for t in cfg["trees"]}


def tiny_testbed(tmp_dir, resolution, fill_height):
    """The quick profile's sparse tree built end to end at `resolution` px (20 training + 4 tail
    frames, held-out azimuths -30 and 60 degrees, no supersampling), framed to `fill_height`, and
    saved as tmp_dir/observed.npz and tmp_dir/truth.npz. Returns (testbed config, tmp_dir)."""
    cfg = quick_config()
    tb = copy.deepcopy(cfg["testbed"])
    tb.update(
        n_train=20,
        n_tail=4,
        resolution=resolution,
        supersample=1,
        heldout_azimuths_deg=[-30, 60],
        fill_height=fill_height,
    )
    obs, tru = build_dataset(tb, cfg["presets"]["sparse"], seed=0, tree="sparse", progress=False)
    save_dataset(obs, tru, tmp_dir / "observed.npz", tmp_dir / "truth.npz")
    return tb, tmp_dir
