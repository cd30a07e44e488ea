"""A workflow job's start-up: the CPU seconds its script's imports cost before it reads a file.

    python benchmarks/job_startup.py [--scripts train,evaluate,recovery] [--reps 3]

For each script of `workflow/scripts/` (or those named), runs its top-level imports (the
`import` / `from ... import` statements of the file, read with `ast`) in a fresh Python process,
`--reps` times, and prints the least CPU time (user + system of the child). Then the costs a job
pays on first use, beyond its imports, each in a fresh process: the training's first optimiser
step (`physgs.train.adam.FusedAdam`; beside it, what `torch.optim.Adam` would cost: building any
`torch.optim.Optimizer` imports `torch._dynamo`), scikit-learn's k-means (imported where ours
cuts its parts), the renderer's numba kernels (loaded from numba's cache at the first render,
forward and backward; the imports that render needs are timed apart) and the loss's and the
part transform's kernels. A job's start-up is its script's imports plus the first uses it
reaches: a training steps an optimiser, ours' training also runs k-means, and every job that
renders loads the kernels.
Last, what a job's end costs: Python's finalisation of a process that imported torch, numba and
scipy (the difference to ending it with `os._exit`, as `physgs.jobs.end_process` does).
`python -X importtime -c "<imports>"` says which module costs what.
"""

from __future__ import annotations

import argparse
import ast
import resource
import subprocess
import sys
from pathlib import Path

SCRIPTS = Path(__file__).resolve().parents[1] / "workflow" / "scripts"

#: One tiny render, forward and backward: numba loads a kernel from its cache at the first call,
#: not at import.
RENDER_ONCE = """
import numpy as np
from physgs.camera import Camera
from physgs.render import rasterization
def render_once():
    cam = Camera(R=np.eye(3), t=np.array([0.0, 0.0, 3.0]), fx=8.0, fy=8.0, cx=4.0, cy=4.0,
                 width=8, height=8)
    means = torch.zeros(1, 3, requires_grad=True)
    out = rasterization(means, torch.tensor([[1.0, 0, 0, 0]]), torch.full((1, 3), 0.1),
                        torch.full((1,), 0.5), torch.full((1, 3), 0.5), cam, torch.zeros(3),
                        backend="fast")
    out.rgb.sum().backward()
"""


#: First-use costs beyond a script's imports: (name, setup code not timed apart, code).
FIRST_USE = (
    ("torch (import)", "", "import torch"),
    (
        "+ first optimiser step (FusedAdam)",
        "import torch\nfrom physgs.train.adam import FusedAdam",
        "p = torch.zeros(1, requires_grad=True)\np.grad = torch.ones(1)\n"
        "FusedAdam([{'params': [p], 'lr': 0.1}]).step()",
    ),
    (
        "  (torch.optim.Adam: torch._dynamo)",
        "import torch",
        "torch.optim.Adam([torch.zeros(1, requires_grad=True)])",
    ),
    ("+ renderer kernels (numba cache)", "import torch", "render_once()"),
    (
        "+ loss and part-transform kernels",
        # after a render, as in a training: numba's first cache load is the renderer's
        "import torch\n" + RENDER_ONCE + "\nrender_once()\n"
        "from physgs.train.losses import photometric_loss\n"
        "from physgs.models.gaussians import rotate_parts",
        "x = torch.rand(8, 8, 3, requires_grad=True)\n"
        "photometric_loss(x, torch.rand(8, 8, 3))[0].backward()\n"
        "m = torch.zeros(2, 3, requires_grad=True)\n"
        "q = torch.tensor([[1.0, 0, 0, 0]] * 2, requires_grad=True)\n"
        "a = torch.tensor([[0.0, 0, 1]])\n"
        "out = rotate_parts(m, q, torch.zeros(2, dtype=torch.long), a, torch.ones(1), a)\n"
        "(out[0].sum() + out[1].sum()).backward()",
    ),
    ("+ scikit-learn k-means", "import torch", "from sklearn.cluster import KMeans"),
)


def script_imports(path: Path) -> str:
    """The top-level import statements of a script, as source lines."""
    tree = ast.parse(path.read_text())
    return "\n".join(
        ast.unparse(n) for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))
    )


def child_cpu(code: str) -> float:
    """CPU seconds (user + system) of ``python -c code`` in a fresh process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-c", code], check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def least(code: str, reps: int) -> float:
    return min(child_cpu(code) for _ in range(reps))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scripts", default="", help="comma-separated script names (default: all)")
    ap.add_argument("--reps", type=int, default=3, help="fresh processes per row (least kept)")
    args = ap.parse_args()
    names = [s for s in args.scripts.split(",") if s] or sorted(
        p.stem for p in SCRIPTS.glob("*.py")
    )
    bare = least("pass", args.reps)
    print(f"CPU s of a fresh process (least of {args.reps}); python alone: {bare:.2f}")
    print(f"{'script':<24} {'imports':>8}")
    for name in names:
        print(f"{name:<24} {least(script_imports(SCRIPTS / f'{name}.py'), args.reps):>8.2f}")
    print(f"\n{'first use':<36} {'CPU s':>6}")
    base = {"": bare}
    for label, setup, code in FIRST_USE:
        if code == "render_once()":  # the imports it needs are timed apart from the call
            setup = f"{setup}\n{RENDER_ONCE}"
        if setup not in base:
            base[setup] = least(setup, args.reps)
        total = least(f"{setup}\n{code}", args.reps)
        print(f"{label:<36} {total - base[setup]:>6.2f}")
    heavy = "import torch\nimport numba\nimport scipy.spatial"
    ended = least(f"{heavy}\nimport os\nos._exit(0)", args.reps)
    print(
        f"{'exit: finalisation (torch, numba, scipy)':<36} {least(heavy, args.reps) - ended:>6.2f}"
    )


if __name__ == "__main__":
    main()
