"""Shared fixtures: a small rasterized 'swaying tree' dataset that stands in for the testbed."""

from __future__ import annotations

import math
import os
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from filelock import FileLock

from workflow_helpers import snakemake, workflow_copy

# torch only in the workers: xdist's controller loads this file before it starts them, and runs
# no test (torch's start-up there delayed both workers by ~1.5 s)
if os.environ.get("PYTEST_XDIST_WORKER"):
    import torch

    torch.set_num_threads(1)  # two workers on two cores: one thread each, no oversubscription

FPS, N_TRAIN, N_TAIL, LEAD_IN, RES = 24, 20, 4, 150, 24


def swaying_dataset(seed: int = 0) -> SimpleNamespace:
    """Observed-like dataset: 120 Gaussians (trunk + crown), the crown swaying as
    cond * 0.12 * height^2 * sin(2 pi 0.8 t) in x, rendered by the fast rasterizer at 24 px."""
    import torch

    from physgs.camera import look_at
    from physgs.render import rasterization

    rng = np.random.default_rng(seed)
    trunk = np.stack([np.zeros(30), np.zeros(30), np.linspace(0, 1, 30)], 1)
    crown = rng.normal(size=(90, 3)) * [0.35, 0.35, 0.3] + [0, 0, 1.4]
    xyz = np.concatenate([trunk, crown]).astype(np.float32)  # [N, 3]
    n = xyz.shape[0]
    col = torch.tensor(
        np.where(np.arange(n)[:, None] < 30, [0.4, 0.25, 0.1], [0.2, 0.6, 0.2]), dtype=torch.float32
    )
    cam = look_at((0.0, -4.5, 1.0), (0.0, 0.0, 1.0), fov_deg=40, width=RES, height=RES)
    F = N_TRAIN + N_TAIL
    cond = np.array([1.0, 0.84, 0.71])
    wind = (6.0 + 1.5 * rng.standard_normal(LEAD_IN + F))[None] * cond[:, None]  # [C, L+F]
    frames = np.empty((3, F, RES, RES, 3), np.uint8)
    q = torch.tensor([[1.0, 0, 0, 0]]).repeat(n, 1)
    s, o = torch.full((n, 3), 0.08), torch.full((n,), 0.8)
    for c in range(3):
        for j in range(F):
            m = xyz.copy()
            m[:, 0] += cond[c] * 0.12 * xyz[:, 2] ** 2 * math.sin(2 * math.pi * 0.8 * j / FPS)
            out = rasterization(
                torch.tensor(m),
                q,
                s,
                o,
                col,
                cam,
                [1.0, 1.0, 1.0],
                backend="fast",
                return_depth=False,
            )
            frames[c, j] = np.round(out.rgb.numpy() * 255).astype(np.uint8)
    return SimpleNamespace(
        fps=FPS,
        n_train=N_TRAIN,
        n_tail=N_TAIL,
        lead_in_frames=LEAD_IN,
        conditions=cond,
        wind=wind.astype(np.float32),
        frames=frames,
        train_camera=cam,
        background=np.ones(3),
        canonical_xyz=xyz,
    )


#: A SLURM configuration with no controller, answered at once. tools/slurm_up.sh leaves SLURM's
#: packages installed, and with its daemons down every `snakemake` call (the SLURM executor plugin
#: runs `scontrol show config` whenever it is imported: Snakemake's start, and collecting
#: test_cluster_profile.py) waited 1 s for the controller, about 50 s of the suite's wall time on
#: two workers. Only test_slurm.py talks to a SLURM: its fixture puts ``MACHINE_SLURM_CONF`` back.
NO_CONTROLLER = Path(__file__).with_name("no_slurm_controller.conf")
# xdist's workers inherit the controller's environment: the machine's value is kept beside it
os.environ.setdefault("PHYSGS_MACHINE_SLURM_CONF", os.environ.get("SLURM_CONF", ""))
MACHINE_SLURM_CONF = os.environ["PHYSGS_MACHINE_SLURM_CONF"] or None
os.environ["SLURM_CONF"] = str(NO_CONTROLLER)  # before any test module imports the plugin


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist reads the groups
def pytest_collection_modifyitems(items):
    """Order and group the tests for the suite's two workers (``--dist loadgroup``, order kept).

    One test that reads the quick DAG goes first, so one worker builds the DAG on both cores
    while the other runs the tests that need no DAG and start processes (the long ones); the
    rest of the DAG's readers follow, shared by both workers, and the tests of modules that
    start no process go last: many short tests, so both workers end within seconds of each
    other. A module with a module-scoped fixture stays on one worker, so its fixture is built
    once."""
    dag = [it for it in items if "quick_dag" in it.fixturenames]
    rest = [it for it in items if "quick_dag" not in it.fixturenames]
    spawns = {p: "subprocess" in p.read_text() for p in {it.path for it in rest}}  # each file once
    items[:] = (
        dag[:1] + [it for it in rest if spawns[it.path]] + dag[1:]
        + [it for it in rest if not spawns[it.path]]
    )  # fmt: skip
    for it in items:
        defs = it._fixtureinfo.name2fixturedefs.values()
        if any(d[-1].scope == "module" for d in defs):
            it.add_marker(pytest.mark.xdist_group(it.module.__name__))


@pytest.fixture(scope="session")
def swaying():
    """The swaying-tree dataset, built once per session."""
    return swaying_dataset()


@pytest.fixture(scope="session")
def quick_dag(tmp_path_factory):
    """Every rule of the quick DAG, run once on the sparse tree in a scratch workflow copy.

    Built once per test session: under pytest-xdist (the suite runs on two workers) the first
    worker that asks builds it in the folder the workers share, and the others wait on a file
    lock and read the same copy; a build that failed fails them too, without a second try."""
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent  # the session's folder, shared by its workers
    wd, failed = root / "quick_dag", root / "quick_dag.failed"
    with FileLock(str(root / "quick_dag.lock")):
        if failed.exists():
            pytest.fail(f"the quick DAG failed to build in another worker:\n{failed.read_text()}")
        if not (wd / ".built").exists():
            try:
                snakemake(
                    workflow_copy(wd),
                    "--cores",
                    "2",
                    "all",
                    "studies",
                    "--config",
                    "profile=quick",
                    'trees=["sparse"]',
                    timeout=900,
                )
            except AssertionError as err:
                failed.write_text(str(err))
                raise
            (wd / ".built").touch()
    return wd
