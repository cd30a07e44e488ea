"""Every script in benchmarks/ and tools/ still runs: `--help` exits 0 and prints its usage.

A script that imports a module since moved, or builds its parser from a name since renamed, fails
here rather than when someone next needs it. The scripts run as ``__main__`` one after another in
one fresh interpreter (each with its own folder first on ``sys.path``, as ``python script.py``
has it): they share torch's and physgs' import, ~2 CPU-s, where a process per script would pay
it ~10 times (~20 CPU-s in all). Scripts that cannot run here are excluded by name, each with the
reason.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("benchmarks", "tools")
#: script (relative to the repository) -> why it is not run
EXCLUDED = {
    "tools/slurm_up.sh": "installs and boots SLURM as root (tests/test_slurm.py runs it)",
    "tools/slurm_down.sh": "stops the SLURM daemons slurm_up.sh started (tests/test_slurm.py)",
}

DRIVER = r"""
import contextlib, io, json, runpy, sys, traceback
out = {}
for path in sys.argv[1:]:
    sys.argv = [path, "--help"]
    sys.path[0] = path.rsplit("/", 1)[0]
    buf = io.StringIO()
    try:
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
            runpy.run_path(path, run_name="__main__")
        code = "returned without exiting"
    except SystemExit as e:
        code = e.code or 0
    except BaseException:
        code = traceback.format_exc(limit=-3)
    out[path] = [code, buf.getvalue()[-2000:]]
print(json.dumps(out))
"""


def scripts() -> list[str]:
    """Every file of the folders, relative to the repository, the excluded ones left out."""
    found = sorted(
        str(p.relative_to(ROOT)) for f in FOLDERS for p in (ROOT / f).iterdir() if p.is_file()
    )
    return [s for s in found if s not in EXCLUDED]


def test_every_non_python_script_is_excluded_by_name():
    """A script in another language would escape the --help run: it must be named in EXCLUDED."""
    assert [s for s in scripts() if not s.endswith(".py")] == []
    assert all((ROOT / s).is_file() for s in EXCLUDED), "an excluded script no longer exists"


def test_every_script_answers_help():
    paths = scripts()
    assert len(paths) >= 10, paths
    run = subprocess.run(
        [sys.executable, "-c", DRIVER, *paths],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    results = json.loads(run.stdout.strip().splitlines()[-1])
    broken = {
        p: f"{code}\n{text}"
        for p, (code, text) in results.items()
        if code != 0 or "usage:" not in text
    }
    assert not broken, "\n\n".join(f"{p}: {why}" for p, why in broken.items())
