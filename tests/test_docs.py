"""The documentation site builds with `mkdocs build --strict` (a broken link, a missing page or
an API page whose module is gone fails), and every physgs subpackage has an API page."""

import os
import re
import shutil
import subprocess
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def test_docs_build_strict(tmp_path):
    assert shutil.which("mkdocs"), "mkdocs is in the test extra: pip install -e '.[test]'"
    r = subprocess.run(
        ["mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
    )
    assert r.returncode == 0, f"mkdocs build --strict failed:\n{r.stdout}\n{r.stderr}"
    assert (tmp_path / "site" / "api" / "report" / "index.html").is_file()


def test_every_subpackage_and_top_level_module_has_an_api_page():
    documented = set()
    for page in (ROOT / "docs" / "api").glob("*.md"):
        documented |= set(re.findall(r"^::: (physgs\.\w+)\s*$", page.read_text(), re.M))
    src = ROOT / "src" / "physgs"
    wanted = {
        f"physgs.{p.stem if p.is_file() else p.name}"
        for p in src.iterdir()
        if (p.is_dir() and (p / "__init__.py").is_file())
        or (p.suffix == ".py" and p.name != "__init__.py")
    }
    assert not wanted - documented, f"no API page for {sorted(wanted - documented)} (docs/api/)"
    cfg = yaml.load((ROOT / "mkdocs.yml").read_text(), Loader=yaml.BaseLoader)
    nav = str(cfg["nav"])
    for page in (ROOT / "docs" / "api").glob("*.md"):
        assert f"api/{page.name}" in nav, f"docs/api/{page.name} is not in mkdocs.yml's nav"
