"""A job Snakemake runs ends its process when ``with job(snakemake)`` ends, without Python's
finalisation (physgs.jobs.end_process): its outputs and its log are whole, what logging buffered
is written, and no atexit handler runs. Every workflow script does all its work inside that
block, since nothing after it runs."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from types import SimpleNamespace

from physgs.jobs import job, run_by_snakemake
from workflow_helpers import ROOT

SNAKEFILE = """
rule made:
    output: "x.txt"
    log: "x.log"
    threads: 1
    script: "body.py"
"""

BODY = """
import atexit, logging, logging.handlers, os, sys
from pathlib import Path
from physgs.jobs import job

sm = snakemake  # noqa: F821
with job(sm) as log:
    atexit.register(lambda: Path("atexit_ran").touch())
    # records held until the handler is flushed or closed (logging.shutdown does both)
    held = logging.handlers.MemoryHandler(100, target=logging.FileHandler("logged.txt"))
    logger = logging.getLogger("body")
    logger.addHandler(held)
    logger.warning("a line logging holds in its buffer")
    print("a line in the job's log", file=log)
    print("a console line held in a pipe's buffer", file=sys.__stdout__)
    Path("x.tmp").write_text("made")
    os.replace("x.tmp", sm.output[0])
"""


def test_a_snakemake_job_ends_without_finalisation_and_loses_nothing(tmp_path):
    (tmp_path / "Snakefile").write_text(SNAKEFILE)
    (tmp_path / "body.py").write_text(BODY)
    # buffered stdout, as on most machines (this one may set PYTHONUNBUFFERED)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    env["PYTHONPATH"] = str(ROOT / "src")
    run = subprocess.run(
        [sys.executable, "-m", "snakemake", "--cores", "1", "x.txt"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert (tmp_path / "x.txt").read_text() == "made"
    assert (tmp_path / "x.log").read_text() == "a line in the job's log\n"
    assert (tmp_path / "logged.txt").read_text() == "a line logging holds in its buffer\n"
    assert "a console line held in a pipe's buffer" in run.stdout
    assert not (tmp_path / "atexit_ran").exists()  # the process ended before atexit


def test_a_stand_in_snakemake_object_keeps_the_process(tmp_path):
    # a test or a notebook passes its own object: job() must return to it
    sm = SimpleNamespace(
        threads=1,
        rule="r",
        input=[],
        output=[str(tmp_path / "o")],
        params=[],
        log=[str(tmp_path / "o.log")],
    )
    assert not run_by_snakemake(sm)
    cwd = os.getcwd()
    os.chdir(tmp_path)  # the output locks live under the working directory
    try:
        with job(sm) as log:
            print("body", file=log)
    finally:
        os.chdir(cwd)
    assert (tmp_path / "o.log").read_text() == "body\n"


def test_every_workflow_script_works_inside_its_job_block():
    for path in sorted((ROOT / "workflow" / "scripts").glob("*.py")):
        body = ast.parse(path.read_text()).body
        blocks = [
            i
            for i, node in enumerate(body)
            if isinstance(node, ast.With)
            and any(
                isinstance(item.context_expr, ast.Call)
                and getattr(item.context_expr.func, "id", None) == "job"
                for item in node.items
            )
        ]
        assert len(blocks) == 1, f"{path.name}: one `with job(sm)` block, found {len(blocks)}"
        assert blocks[0] == len(body) - 1, (
            f"{path.name}: statements after `with job(sm)` never run (the job's process ends "
            "there); move them into the block"
        )
