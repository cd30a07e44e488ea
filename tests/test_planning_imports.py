"""Planning is cheap: what the Snakefile imports to plan jobs loads no torch, matplotlib or scipy,
so a dry run (and every Snakemake call of the suite) does not pay seconds of their start-up."""

from __future__ import annotations

import re
import subprocess
import sys

from workflow_helpers import ROOT

HEAVY = ("torch", "matplotlib", "scipy", "sklearn", "numba", "trimesh")


def _workflow_imports() -> list[str]:
    """The physgs import statements of the Snakefile and every rule file, as written there."""
    files = [ROOT / "Snakefile", *sorted((ROOT / "workflow" / "rules").glob("*.smk"))]
    lines = [ln.strip() for f in files for ln in f.read_text().splitlines()]
    return [ln for ln in lines if re.match(r"(import|from) physgs\b", ln)]


def test_the_workflows_imports_load_no_heavy_library():
    imports = _workflow_imports()
    assert len(imports) >= 5, imports  # the parse found the imports it is about
    # the Snakefile's own first step: validate and check the shipped config (its checks reuse
    # the testbed's formulas, whose modules must not load torch either)
    load = (
        "cfg = physgs.config.load_workflow_config(yaml.safe_load(open('config/trees.yaml')), "
        "'default', source='config/trees.yaml')"
    )
    # then its bf16 check, on a CPU whose flags report native bf16 (the default's fields are
    # bf16): the flags decide, and torch stays unloaded
    check = (
        "physgs.experiments.recipe.bf16_flags = lambda: ['avx512_bf16']\n"
        "physgs.experiments.recipe.check_precision_supported(cfg['models'], planning=True)"
    )
    code = "\n".join(
        [
            *imports,
            "import yaml",
            load,
            check,
            "import sys",
            f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))",
        ]
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    ).stdout
    assert out.strip() == "[]", f"planning imports load {out.strip()}"


def test_the_packages_names_still_resolve():
    """The lazily loaded package names are the same objects as their modules' own."""
    import physgs.evaluate
    import physgs.models
    from physgs.evaluate.splits import load_eval
    from physgs.models.base import ModelContext
    from physgs.models.registry import build_model

    assert physgs.models.build_model is build_model
    assert physgs.models.ModelContext is ModelContext
    assert physgs.evaluate.load_eval is load_eval
    for pkg in (physgs.models, physgs.evaluate):
        for name in pkg.__all__:
            assert getattr(pkg, name) is not None
    try:
        physgs.models.no_such_name  # noqa: B018
    except AttributeError as e:
        assert "no_such_name" in str(e)
    else:
        raise AssertionError("an unknown name must raise AttributeError")
