"""GPU check: the rasterizer, the training loop and every model's rate on a device, beside the CPU.

    python benchmarks/gpu_check.py [--device cuda] [--tree medium] [--resolutions 128,512]
        [--curve-iters 300] [--models static,ours,d3dgs] [--rate-iters 20] [--rate-models all]
        [--rate-trees sparse,medium,dense] [--rates FILE] [--skip a,b,c] [--profile default]
        [--configfile FILE]

Three parts, each printed as a table; the check needs only what it generates (no committed data):

(a) **Rasterizer parity.** The tree's canonical Gaussians (its real mesh, the testbed's own
    framing) rendered forward and backward by every backend on ``--device`` (``reference`` in
    float64 and float32, ``fast``, and ``gsplat`` where installed on CUDA) at each resolution,
    against the CPU ``fast`` path in float64: the image's largest difference and the gradients'
    relative error (norm of the difference over the norm of the CPU's), per Gaussian field.
(b) **The loop on the device.** The tree's testbed at the profile's resolution (built here:
    Embree frames, a few seconds to a minute), and static, ours (single) and Deformable-3DGS
    (``--models``) trained by the recipe (``physgs.experiments.recipe.fit``) for ``--curve-iters``
    iterations from one seed on the device and on the CPU: their loss curves side by side and the
    held-out window frames' PSNR of both (the frames the stopping rule reads, never the views,
    the tail or another wind).
(c) **Rates.** Milliseconds per iteration of every model and configuration the profile trains
    (``--rate-models``) in the real loop on the device, on each tree (``--rate-trees``) at each
    resolution (the tree's geometry and cameras, a flat target: the cost
    does not depend on the image's content), after one untimed iteration that compiles kernels,
    with a breakdown (rasterizer, field, loss, backward, optimiser, the rest: host copies,
    checks) timed with the device synchronised around each part. ``--rates FILE`` writes them
    (tree, model, configuration, seconds per iteration, device, resolution, date, commit): what
    ``tools/paper_estimate.py --gpu-rates FILE`` prices a profile from.

On the CPU (``--device cpu``) the same code runs (a test runs it on tiny sizes): (a) then checks
the PyTorch reference against the numba kernels, and (b) the loop's determinism (both runs on the
CPU must agree bit for bit).
"""

from __future__ import annotations

import argparse
import contextlib
import datetime
import functools
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from unittest import mock

import numpy as np
import pandas as pd
import torch

import physgs.config
import physgs.train.loop as loop
from physgs.experiments.recipe import fit, heldout_split, job_spec
from physgs.models import build_model
from physgs.models.registry import BASE_CONFIG, PRIOR_VARIANT_NAMES, training_jobs
from physgs.provenance import git_commit, machine_cpu
from physgs.render import BACKENDS, _gsplat_available, rasterization
from physgs.testbed.dataset import build_dataset, load_observed, save_dataset
from physgs.testbed.standin import geometry_stand_in
from physgs.train.holdout import HoldoutEval

FIELDS = ("means", "quats", "scales", "opacities", "colors")
PARTS = ("raster", "field", "loss", "backward", "optimiser", "other")


def sync(device: torch.device) -> None:
    """Wait for the device's queued work, so a wall-clock read covers it."""
    if device.type == "cuda":
        torch.cuda.synchronize(device)


# ---------------------------------------------------------------------------------------------
# (a) rasterizer parity


def _render_grads(state: dict, cam, bg, backend: str, device, dtype, probe: np.ndarray):
    """(image [H, W, 3] float64 numpy, {field: gradient numpy}) of one render's forward and
    backward; the loss is the image against a fixed random probe, so every pixel's gradient
    counts."""
    leaves = {
        k: torch.tensor(v, dtype=dtype, device=device, requires_grad=True) for k, v in state.items()
    }
    out = rasterization(
        *(leaves[k] for k in FIELDS),
        cam,
        torch.as_tensor(bg, dtype=dtype, device=device),
        backend=backend,
    )
    (out.rgb * torch.as_tensor(probe, dtype=dtype, device=device)).sum().backward()
    return (
        out.rgb.detach().double().cpu().numpy(),
        {k: v.grad.double().cpu().numpy() for k, v in leaves.items()},
    )


def parity(cfg: dict, tree: str, resolutions: list[int], device: torch.device) -> pd.DataFrame:
    """Every backend on ``device`` against the CPU fast path in float64, per resolution."""
    rows = []
    for res in resolutions:
        data = geometry_stand_in(cfg, tree, res)
        model = build_model("static", data, cfg["models"], seed=0)
        with torch.no_grad():
            s = model.canonical_state()
        state = {k: getattr(s, k).detach().double().numpy() for k in FIELDS}
        # turned and stretched: the canonical set is isotropic, and an isotropic Gaussian's
        # gradient w.r.t. its orientation is zero, which would compare rounding noise
        rng = np.random.default_rng(1)
        state["quats"] = rng.normal(size=state["quats"].shape)
        state["scales"] = state["scales"] * rng.lognormal(0.0, 0.3, size=state["scales"].shape)
        cam, bg = data.train_camera, np.asarray(cfg["testbed"]["background"], dtype=np.float64)
        probe = np.random.default_rng(0).uniform(size=(res, res, 3))
        ref_img, ref_grad = _render_grads(
            state, cam, bg, "fast", torch.device("cpu"), torch.float64, probe
        )
        paths = [
            ("reference", torch.float64),
            ("reference", torch.float32),
            ("fast", torch.float32),
        ]
        if _gsplat_available(device):
            paths.append(("gsplat", torch.float32))
        for backend, dtype in paths:
            sync(device)
            t0 = time.perf_counter()
            img, grad = _render_grads(state, cam, bg, backend, device, dtype, probe)
            sync(device)
            ms = 1e3 * (time.perf_counter() - t0)
            row = dict(
                resolution=res,
                backend=backend,
                dtype=str(dtype).removeprefix("torch."),
                n_gaussians=len(state["means"]),
                image_max_abs=float(np.abs(img - ref_img).max()),
                ms=ms,
            )
            for k in FIELDS:
                row[f"grad_{k}"] = float(
                    np.linalg.norm(grad[k] - ref_grad[k]) / max(np.linalg.norm(ref_grad[k]), 1e-300)
                )
            rows.append(row)
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------------------------
# (b) the training loop on the device and on the CPU


def testbed(cfg: dict, tree: str, workdir: Path):
    """The tree's observed dataset at the profile's settings, built and read back as the
    workflow's jobs read it."""
    observed, truth = build_dataset(
        cfg["testbed"], cfg["presets"][tree], seed=cfg["seed"], tree=tree, progress=False
    )
    obs_path, truth_path = workdir / "observed.npz", workdir / "truth.npz"
    save_dataset(observed, truth, obs_path, truth_path)
    return load_observed(obs_path)


def curves(
    cfg: dict, observed, models: list[str], iters: int, device: torch.device, points: int = 8
):
    """Each model trained ``iters`` iterations on ``device`` and on the CPU from seed 0: its loss
    at ``points`` iterations (mean of the iterations since the last point) and the held-out
    window frames' PSNR (dB) after training, for both."""
    warm = max(1, round(iters * cfg["train"]["warmup"] / cfg["train"]["iterations"]))
    train = dict(
        cfg["train"],
        iterations=iters,
        warmup=warm,
        stopping=dict(cfg["train"]["stopping"], enabled=False),
    )
    c2 = dict(cfg, train=train)
    _, held = heldout_split(int(observed.n_train), int(train["holdout_every"]) or 10)
    marks = np.unique(np.linspace(0, iters, points + 1).astype(int))[1:]
    curve_rows, summary = [], []
    for model in models:
        job = job_spec(c2, model, BASE_CONFIG, seed=0)
        runs = []
        for where in (device, torch.device("cpu")):
            t0 = time.perf_counter()
            res = fit(observed, job, progress=False, device=where)
            sync(where)
            wall = time.perf_counter() - t0
            _, psnr = HoldoutEval.build(observed, held, [0], train, device=where).evaluate(
                res.model
            )
            runs.append((np.array([r["loss"] for r in res.log]), psnr, wall))
        (ld, pd_, wd), (lc, pc, wc) = runs
        lo = 0
        for m in marks:
            curve_rows.append(
                dict(
                    model=model,
                    iteration=int(m),
                    loss_device=float(ld[lo:m].mean()),
                    loss_cpu=float(lc[lo:m].mean()),
                )
            )
            lo = m
        summary.append(
            dict(
                model=model,
                iterations=iters,
                heldout_psnr_device=pd_,
                heldout_psnr_cpu=pc,
                final_loss_device=float(ld[-max(1, iters // 10) :].mean()),
                final_loss_cpu=float(lc[-max(1, iters // 10) :].mean()),
                identical=bool(np.array_equal(ld, lc)),
                wall_s_device=wd,
                wall_s_cpu=wc,
            )
        )
    return pd.DataFrame(curve_rows), pd.DataFrame(summary)


# ---------------------------------------------------------------------------------------------
# (c) rates and where each iteration's time goes


class SyncedParts:
    """Wall seconds per part of the real loop, the device synchronised around each part (the
    parts then add up to the iteration; the synchronisation itself costs a little)."""

    def __init__(self, device: torch.device):
        self.device, self.sec = device, defaultdict(float)

    def wrap(self, part: str, fn):
        def wrapped(*a, **k):
            sync(self.device)
            t0 = time.perf_counter()
            try:
                return fn(*a, **k)
            finally:
                sync(self.device)
                self.sec[part] += time.perf_counter() - t0

        return wrapped

    @contextlib.contextmanager
    def patched(self, model, optimiser_cls):
        """The loop's parts wrapped while the block runs (unittest.mock restores each)."""
        parts = (
            (loop, "render_state", "raster"),
            (loop, "photometric_loss", "loss"),
            (torch.Tensor, "backward", "backward"),
            (optimiser_cls, "step", "optimiser"),
            (model, "gaussians_at", "field"),
        )
        with contextlib.ExitStack() as stack:
            for obj, name, part in parts:
                wrapped = self.wrap(part, getattr(obj, name))
                stack.enter_context(mock.patch.object(obj, name, wrapped))
            yield self


def time_model(data, cfg: dict, model: str, config: str, iters: int, device) -> dict:
    """Seconds per deformation iteration of ``model`` in ``config`` in the real loop on
    ``device`` (best of two runs) and its breakdown by part (a third run, synchronised)."""
    from physgs.train.adam import FusedAdam

    tcfg = dict(
        cfg["train"],
        iterations=iters,
        warmup=0,
        stopping=dict(cfg["train"]["stopping"], enabled=False),
    )
    conds = [0] if config == BASE_CONFIG else list(range(len(data.conditions)))
    m = build_model(model, data, cfg["models"], config=config, seed=0)
    run = functools.partial(
        loop.train_model, m, data, conditions=conds, progress=False, device=device
    )
    run(dict(tcfg, iterations=1), seed=0)  # compiles kernels, moves the model
    walls, cpus = [], []
    for s in range(2):
        sync(device)
        c0, t0 = time.process_time(), time.perf_counter()
        run(tcfg, seed=s)
        sync(device)
        walls.append((time.perf_counter() - t0) / iters)
        cpus.append((time.process_time() - c0) / iters)
    with SyncedParts(device).patched(m, FusedAdam) as p:
        sync(device)
        t0 = time.perf_counter()
        run(tcfg, seed=2)
        total = (time.perf_counter() - t0) / iters
    parts = {k: p.sec[k] / iters for k in PARTS if k != "other"}
    parts["other"] = total - sum(parts.values())
    best = int(np.argmin(walls))
    return dict(
        wall_s_per_iter=walls[best],
        cpu_s_per_iter=cpus[best],
        **{f"ms_{k}": 1e3 * v for k, v in parts.items()},
    )


def rates(cfg: dict, trees, resolutions, jobs, iters: int, device) -> pd.DataFrame:
    """(c)'s table: one row per tree, resolution and (model, configuration)."""
    rows = []
    for tree in trees:
        for res in resolutions:
            data = geometry_stand_in(cfg, tree, res)
            for model, config in jobs:
                r = time_model(data, cfg, model, config, iters, device)
                rows.append(dict(tree=tree, model=model, config=config, resolution=res, **r))
                print(
                    f"  {tree} {model} {config} at {res} px: "
                    f"{1e3 * r['wall_s_per_iter']:.1f} ms/iter",
                    flush=True,
                )
    return pd.DataFrame(rows)


def device_name(device: torch.device) -> str:
    return torch.cuda.get_device_name(device) if device.type == "cuda" else machine_cpu()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--device", default="cuda", help="cuda (default) or cpu")
    ap.add_argument("--profile", default="default", help="the settings (models, recipe, testbed)")
    ap.add_argument(
        "--configfile", action="append", default=[], help="YAML overlays, as Snakemake's"
    )
    ap.add_argument("--tree", default="medium", help="(a) and (b): the tree")
    ap.add_argument("--resolutions", default="128,512", help="px, comma-separated, for (a) and (c)")
    ap.add_argument("--curve-iters", type=int, default=300, help="(b): iterations per training")
    ap.add_argument("--models", default="static,ours,d3dgs", help="(b): the models trained")
    ap.add_argument("--rate-iters", type=int, default=20, help="(c): timed iterations per model")
    ap.add_argument(
        "--rate-models",
        default="all",
        help="(c): comma-separated ids in the base configuration, or all (every trained model "
        "in every configuration of models.configs, and the prior variants, as the profile plans)",
    )
    ap.add_argument("--rate-trees", default="sparse,medium,dense", help="(c): the trees timed")
    ap.add_argument("--skip", default="", help="parts to skip, e.g. b or a,b")
    ap.add_argument("--rates", default=None, help="write (c)'s rates to this CSV")
    args = ap.parse_args()
    device = torch.device(args.device)
    if device.type == "cuda" and not torch.cuda.is_available():
        raise SystemExit(
            "--device cuda: torch sees no GPU here (torch "
            f"{torch.__version__}); run with --device cpu, or on a GPU machine"
        )
    cfg = physgs.config.load_workflow_config(
        physgs.config.read_yaml("config/trees.yaml"), args.profile, configfiles=args.configfile
    )
    resolutions = [int(r) for r in args.resolutions.split(",")]
    skip = set(filter(None, args.skip.split(",")))
    t_start = time.perf_counter()
    print(
        f"gpu_check on {device} ({device_name(device)}), torch {torch.__version__}, commit "
        f"{git_commit()}, {datetime.date.today().isoformat()}; profile {args.profile}, tree {args.tree}"
    )
    pd.set_option("display.width", 200)
    pd.set_option("display.max_columns", 30)
    if "a" not in skip:
        print(
            f"\n(a) rasterizer on {device} against the CPU fast path in float64 (backends {BACKENDS[1:]})"
        )
        print(
            parity(cfg, args.tree, resolutions, device).to_string(index=False, float_format="%.3g")
        )
    if "b" not in skip:
        res = cfg["testbed"]["resolution"]
        print(
            f"\n(b) the recipe on {device} and on the CPU, {args.curve_iters} iterations, seed 0, {res} px"
        )
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            observed = testbed(cfg, args.tree, Path(tmp))
            print(f"  testbed built in {time.perf_counter() - t0:.1f} s")
            curve, summary = curves(cfg, observed, args.models.split(","), args.curve_iters, device)
        print(curve.to_string(index=False, float_format="%.4f"))
        print(summary.to_string(index=False, float_format="%.3f"))
    if "c" not in skip:
        if args.rate_models == "all":
            jobs = training_jobs(cfg["models"]["configs"])
            jobs += [(m, BASE_CONFIG) for m in PRIOR_VARIANT_NAMES]
        else:
            jobs = [(m, BASE_CONFIG) for m in args.rate_models.split(",")]
        print(f"\n(c) ms per iteration on {device} (real loop, best of two; parts synchronised)")
        trees = args.rate_trees.split(",")
        r = rates(cfg, trees, resolutions, jobs, args.rate_iters, device)
        shown = r.assign(ms_per_iter=1e3 * r["wall_s_per_iter"]).drop(
            columns=["wall_s_per_iter", "cpu_s_per_iter"]
        )
        print(shown.to_string(index=False, float_format="%.1f"))
        if args.rates:
            stamp = dict(
                device=device.type,
                device_name=device_name(device),
                cpu=machine_cpu(),
                profile=args.profile,
                date=datetime.date.today().isoformat(),
                commit=git_commit(),
            )
            r.assign(**stamp).to_csv(args.rates, index=False)
            print(f"{args.rates}: {len(r)} rates")
    print(f"\ngpu_check done in {time.perf_counter() - t_start:.0f} s")


if __name__ == "__main__":
    main()
