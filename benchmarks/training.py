"""Training cost: seconds per iteration of every model on every tree, by part, and RK4 cost.

    python benchmarks/training.py [--profile default] [--iters 8] [--threads 1]
        [--configfile config/float32.yaml] [--trees medium] [--models static,ours]

For each tree the testbed's own geometry and cameras are generated (no frame rendering: the
per-iteration cost does not depend on the target image's content), every model is built at the
profile's settings and timed over ``--iters`` deformation iterations of the real training loop
(after one untimed iteration that compiles kernels). Prints a table of s/iter, then, per tree and
model, where the CPU time of one iteration goes (:class:`Parts`: rasterizer forward and backward,
the field (deformation forward + its backward), loss forward + backward, optimiser, divergence
guard, the rest of the loop), then the total
wall time the profile's training jobs imply (3 trees x 5 baselines `single` + ours
single/joint32/joint96; the static warm-up iterations are charged at the static model's rate),
and the RK4 forward+backward cost for K = 96 over the whole recording (lead-in + 350 frames).
``--csv FILE`` also writes the rates (tree, model, configuration, CPU and wall s/iter, with the
profile, date, commit and CPU): the input of ``physgs.experiments.cost.training_estimate``, which
prices a profile's planned trainings (``tools/paper_estimate.py``).
"""

from __future__ import annotations

import argparse
import contextlib
import time
from collections import defaultdict

import numba
import numpy as np
import torch

import physgs.config
from physgs.allocator import retain_freed_memory
import physgs.render.fast
import physgs.train.loop
from physgs.models import build_model, training_jobs
from physgs.models.registry import BASE_CONFIG, PRIOR_VARIANT_NAMES
from physgs.models.oscillator import integrate
from physgs.testbed.standin import geometry_stand_in
from physgs.train import train_model
from physgs.train.divergence import DivergenceGuard

PARTS = ("raster_fwd", "raster_bwd", "field", "loss", "optimiser", "guard", "other")


class Parts:
    """CPU seconds (this process, all threads) spent in each part of the real training loop,
    accumulated by wrapping the names ``physgs.train.loop`` calls; nothing in the loop changes.

    raster_fwd: ``rasterization`` (input checks, projection, compositing); raster_bwd: the fast
    path's explicit backward; loss: ``photometric_loss`` plus the backward from the loss down to
    the rendered image; field: the model's deformation (``gaussians_at`` / ``canonical_state``)
    plus the rest of ``loss.backward()`` (the field's and the activations' backward); optimiser:
    Adam's ``zero_grad`` and ``step``; guard: the divergence guard's checks and the finiteness
    tests; other: the rest of the loop (target frame, learning-rate schedule, log).
    """

    def __init__(self):
        self.sec = defaultdict(float)
        self._bwd_mark = None  # CPU time at which the loss's backward reached the image

    @contextlib.contextmanager
    def timed(self, part: str):
        c0 = time.process_time()
        try:
            yield
        finally:
            self.sec[part] += time.process_time() - c0

    def wrap(self, part: str, fn):
        def wrapped(*a, **k):
            with self.timed(part):
                return fn(*a, **k)

        return wrapped

    @contextlib.contextmanager
    def patched(self, model):
        loop, fast = physgs.train.loop, physgs.render.fast._FastRasterize
        saved = []

        def patch(obj, name, value):
            saved.append((obj, name, obj.__dict__.get(name, _MISSING)))
            setattr(obj, name, value)

        raster = loop.render_state

        def render_state(*a, **k):
            with self.timed("raster_fwd"):
                out = raster(*a, **k)
            if out.rgb.requires_grad:  # the loss's backward reaches the image here
                out.rgb.register_hook(self._reached_image)
            return out

        backward = torch.Tensor.backward

        def tensor_backward(t, *a, **k):
            c0 = time.process_time()
            self._bwd_mark = None
            r0 = self.sec["raster_bwd"]
            backward(t, *a, **k)
            c1 = time.process_time()
            mark = c0 if self._bwd_mark is None else self._bwd_mark
            self.sec["loss"] += mark - c0
            self.sec["field"] += (c1 - mark) - (self.sec["raster_bwd"] - r0)
            return None

        patch(loop, "render_state", render_state)
        patch(loop, "photometric_loss", self.wrap("loss", loop.photometric_loss))
        patch(loop, "_abs_maxes", self.wrap("guard", loop._abs_maxes))
        patch(loop, "_finite", self.wrap("guard", loop._finite))
        for name in ("check_means", "check_loss", "check_params", "suspects"):
            patch(DivergenceGuard, name, self.wrap("guard", getattr(DivergenceGuard, name)))
        patch(fast, "backward", staticmethod(self.wrap("raster_bwd", fast.backward)))
        patch(torch.Tensor, "backward", tensor_backward)
        patch(torch.optim.Adam, "step", self.wrap("optimiser", torch.optim.Adam.step))
        patch(torch.optim.Adam, "zero_grad", self.wrap("optimiser", torch.optim.Adam.zero_grad))
        patch(model, "gaussians_at", self.wrap("field", model.gaussians_at))
        patch(model, "canonical_state", self.wrap("field", model.canonical_state))
        try:
            yield self
        finally:
            for obj, name, old in reversed(saved):
                if old is _MISSING:
                    delattr(obj, name)
                else:
                    setattr(obj, name, old)

    def _reached_image(self, grad):
        self._bwd_mark = time.process_time()
        return grad


_MISSING = object()


def time_model(
    data, cfg: dict, model: str, config: str, iters: int
) -> tuple[float, float, dict[str, float]]:
    """(CPU seconds, wall seconds, CPU seconds by part of :data:`PARTS`) per deformation
    iteration of the training loop: totals the best of three runs, parts from the run with the
    least CPU time. CPU time (all threads of this process) is what a dedicated core would spend;
    on a shared machine it is far steadier than wall time."""
    tcfg = dict(cfg["train"], iterations=iters, warmup=0)
    conds = [0] if config == "single" else [0, 1, 2]
    m = build_model(model, data, cfg["models"], config=config, seed=cfg["seed"])
    train_model(m, data, dict(tcfg, iterations=1), conditions=conds, seed=0, progress=False)
    cpu, wall, parts = [], [], []
    for s in range(3):
        with Parts().patched(m) as p:
            c0, t0 = time.process_time(), time.perf_counter()
            train_model(m, data, tcfg, conditions=conds, seed=s, progress=False)
            cpu.append((time.process_time() - c0) / iters)
            wall.append((time.perf_counter() - t0) / iters)
        by_part = {k: p.sec[k] / iters for k in PARTS if k != "other"}
        by_part["other"] = cpu[-1] - sum(by_part.values())
        parts.append(by_part)
    best = int(np.argmin(cpu))
    return cpu[best], float(np.min(wall)), parts[best]


def rk4_cost(T: int, K: int = 96, reps: int = 20) -> tuple[float, float]:
    """(fast, reference) seconds (best of ``reps`` / 1) for theta [K, T] forward + backward,
    substeps 2."""
    rng = np.random.default_rng(0)
    wind = 6.0 + 1.5 * rng.standard_normal(T)
    p = [
        torch.tensor(a, requires_grad=True)
        for a in (np.linspace(2.0, 10.0, K), np.full(K, 0.1), np.full(K, 0.01))
    ]
    out = []
    for backend, n in (("fast", reps), ("reference", 1)):
        integrate(*p, wind, 6.0, 1 / 24, 2, backend=backend).sum().backward()  # compile / warm
        best = np.inf
        for _ in range(n):
            t0 = time.perf_counter()
            integrate(*p, wind, 6.0, 1 / 24, 2, backend=backend).square().sum().backward()
            best = min(best, time.perf_counter() - t0)
        out.append(best)
    return out[0], out[1]


def _write_rates(path: str, profile: str, breakdown: dict) -> None:
    """The measured s/iter per (tree, model, configuration) as a CSV, with where measured."""
    import datetime

    import pandas as pd

    from physgs.provenance import git_commit, machine_cpu

    rows = [
        dict(tree=t, model=m, config=c, cpu_s_per_iter=v[0], wall_s_per_iter=v[1])
        for t, jobs in breakdown.items()
        for (m, c), v in jobs.items()
    ]
    stamp = dict(
        profile=profile,
        date=datetime.date.today().isoformat(),
        commit=git_commit(),
        cpu=machine_cpu(),
    )
    pd.DataFrame([r | stamp for r in rows]).to_csv(path, index=False)
    print(f"{path}: {len(rows)} rates")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", default="default")
    ap.add_argument("--iters", type=int, default=8, help="timed iterations per model")
    ap.add_argument("--threads", type=int, default=1, help="torch and numba threads")
    ap.add_argument("--trees", nargs="*", default=None)
    ap.add_argument("--models", default=None, help="comma-separated model ids (default: all)")
    ap.add_argument(
        "--configfile",
        action="append",
        default=[],
        help="YAML overlay merged into config/trees.yaml before the profile resolves (as "
        "Snakemake's --configfile; config/float32.yaml on a CPU without native bf16)",
    )
    ap.add_argument("--csv", default=None, help="write the measured rates to this CSV")
    ap.add_argument(
        "--variants",
        action="store_true",
        help="also time the prior variants (topology parts, the forcing-free priors) in the base "
        "configuration, as the parts study and the blind recovery train them",
    )
    args = ap.parse_args()
    retain_freed_memory()  # as a workflow job (physgs.jobs)
    torch.set_num_threads(args.threads)
    numba.set_num_threads(args.threads)
    raw = physgs.config.read_yaml("config/trees.yaml")
    # the overlays beat the profile, as Snakemake's --configfile does (physgs.config)
    cfg = physgs.config.load_workflow_config(raw, args.profile, configfiles=args.configfile)
    trees = args.trees or cfg["trees"]
    it_total, warm = cfg["train"]["iterations"], cfg["train"]["warmup"]
    jobs = training_jobs(cfg["models"]["configs"])
    if args.variants:
        jobs += [(m, BASE_CONFIG) for m in PRIOR_VARIANT_NAMES]
    if args.models:
        jobs = [j for j in jobs if j[0] in args.models.split(",")]
    print(
        f"profile {args.profile}: {cfg['testbed']['resolution']} px, {it_total} iterations "
        f"({warm} warm-up), {args.threads} thread(s) per job; CPU s/iter (wall s/iter)"
    )
    print(f"{'tree':<7} {'N':>6} " + " ".join(f"{m + '_' + c:>17}" for m, c in jobs))
    cpu_total = 0.0
    breakdown = {}
    for tree in trees:
        data = geometry_stand_in(cfg, tree)
        t = {job: time_model(data, cfg, *job, args.iters) for job in jobs}
        breakdown[tree] = t
        static = t.get(("static", "single"), (0.0,))[0]
        cpu_total += sum(warm * static + (it_total - warm) * v[0] for v in t.values())
        print(
            f"{tree:<7} {data.canonical_xyz.shape[0]:>6} "
            + " ".join(f"{t[j][0]:>8.3f} ({t[j][1]:>6.3f})" for j in jobs),
            flush=True,
        )
    print("\nCPU ms per iteration by part (the run with the least CPU time of three)")
    print(f"{'tree':<7} {'model':<18} {'total':>7} " + " ".join(f"{p:>10}" for p in PARTS))
    for tree, t in breakdown.items():
        for (model, config), (cpu, _, parts) in t.items():
            print(
                f"{tree:<7} {model + '_' + config:<18} {1e3 * cpu:>7.1f} "
                + " ".join(f"{1e3 * parts[p]:>10.1f}" for p in PARTS)
            )
    print(
        f"implied training CPU time, {len(jobs)} jobs x {len(trees)} trees: "
        f"{cpu_total / 60:.1f} CPU-min -> about {cpu_total / 120:.1f} min wall on 2 idle cores "
        "(2 jobs at once, 1 thread each)"
    )
    if args.csv:
        _write_rates(args.csv, args.profile, breakdown)
    T = data.wind.shape[1]  # whole recording of the last tree: lead-in + 350 frames
    fast, ref = rk4_cost(T)
    print(
        f"RK4 forward+backward, K=96, T={T} samples, 2 substeps: fast {fast * 1e3:.2f} ms, "
        f"torch autograd reference {ref * 1e3:.0f} ms ({ref / fast:.0f}x)"
    )


if __name__ == "__main__":
    main()
