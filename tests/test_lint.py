"""The trade's hygiene, checked in seconds: ruff's lint rules (pyproject.toml), ruff format and
snakefmt over every tracked file, so a commit that skips the pre-commit hook fails CI; and the
Google sections (Args:, Returns:) of the library's public API, which the API reference renders."""

import ast
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def tracked(*patterns: str) -> list[str]:
    """Tracked files matching the patterns (an untracked draft in a shared checkout is not
    checked); the whole tree when this is not a git checkout."""
    try:
        out = subprocess.run(
            ["git", "ls-files", "--", *patterns], cwd=ROOT, capture_output=True, text=True
        )
    except FileNotFoundError:
        return ["."]
    if out.returncode != 0:
        return ["."]
    return [f for f in out.stdout.split() if (ROOT / f).exists()]


@pytest.mark.parametrize(
    "cmd, patterns",
    [
        (["ruff", "check", "--no-cache"], ("*.py",)),
        (["ruff", "format", "--check", "--no-cache"], ("*.py",)),
        (["snakefmt", "--check"], ("Snakefile", "*.smk")),
    ],
    ids=["ruff-check", "ruff-format", "snakefmt"],
)
def test_tree_is_clean(cmd, patterns):
    assert shutil.which(cmd[0]), f"{cmd[0]} is in the test extra: pip install -e '.[test]'"
    files = tracked(*patterns)
    assert files, f"no files match {patterns}"
    r = subprocess.run([*cmd, *files], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, f"{' '.join(cmd)} found problems:\n{r.stdout}\n{r.stderr}"


# -- Google sections on the public API ------------------------------------------------------------
# ruff's D417 names every argument of an ``Args:`` section but does not ask for the section; its
# pydoclint rules (DOC201, DOC402: returns and yields documented) are preview-only in the ruff the
# test extra installs. So: every public function or method of ``src/physgs`` that takes arguments
# has ``Args:``, and one that returns or yields a value has ``Returns:`` or ``Yields:``.
# Public: a name without a leading underscore, in a module and class whose names have none, not
# nested in a function; properties are left out (their one line is the whole story).

SRC = ROOT / "src" / "physgs"


def _own_nodes(fn):
    """The nodes of ``fn``'s body, not descending into nested functions, lambdas or classes."""
    todo = list(fn.body)
    while todo:
        node = todo.pop()
        yield node
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            todo.extend(ast.iter_child_nodes(node))


def _returns_value(fn) -> bool:
    """Whether ``fn`` hands a value back: an annotation other than None / NoReturn, or, without
    one, a ``return <value>``, ``yield`` or ``yield from`` of its own."""
    r = fn.returns
    if r is not None:
        none = isinstance(r, ast.Constant) and r.value is None
        return not (none or (isinstance(r, ast.Name) and r.id == "NoReturn"))
    return any(
        isinstance(n, (ast.Yield, ast.YieldFrom)) or (isinstance(n, ast.Return) and n.value)
        for n in _own_nodes(fn)
    )


def missing_sections(root: Path) -> list[str]:
    """``path:line: name lacks Args:/Returns:`` for every public function of the package under
    ``root`` whose docstring lacks a section it needs."""
    out = []
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root)
        if any(p.startswith("_") and p != "__init__.py" for p in rel.parts):
            continue
        stack = [(ast.parse(path.read_text()).body, "")]
        while stack:
            body, prefix = stack.pop()
            for node in body:
                if node.__class__ is ast.ClassDef and not node.name.startswith("_"):
                    stack.append((node.body, f"{prefix}{node.name}."))
                if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    continue
                decorators = {getattr(d, "id", getattr(d, "attr", "")) for d in node.decorator_list}
                if node.name.startswith("_") or decorators & {"property", "setter", "overload"}:
                    continue
                a = node.args
                params = [p.arg for p in (*a.posonlyargs, *a.args, *a.kwonlyargs)]
                params = params[1:] if params[:1] in (["self"], ["cls"]) else params
                params += [p.arg for p in (a.vararg, a.kwarg) if p is not None]
                doc = ast.get_docstring(node) or ""
                lacks = [
                    s
                    for s, need, has in (
                        ("Args:", bool(params), "Args:" in doc),
                        ("Returns:", _returns_value(node), "Returns:" in doc or "Yields:" in doc),
                    )
                    if need and not has
                ]
                if lacks:
                    where = f"{path.relative_to(ROOT) if path.is_relative_to(ROOT) else path}"
                    out.append(
                        f"{where}:{node.lineno}: {prefix}{node.name} lacks {'/'.join(lacks)}"
                    )
    return out


def test_public_functions_have_google_sections():
    missing = missing_sections(SRC)
    assert not missing, (
        f"{len(missing)} public function(s) of the API reference lack a Google section "
        "(Args: with each argument's units and shape; Returns: or Yields:):\n" + "\n".join(missing)
    )


def test_missing_sections_names_each_gap(tmp_path):
    """The check finds what it is for, and leaves alone what it should (a check that cannot
    fail checks nothing)."""
    (tmp_path / "mod.py").write_text(
        '''
def bare(x):
    """No sections."""
    return x


def args_only(x) -> int:
    """Args but no Returns.

    Args:
        x: a value.
    """
    return 1


def fine(x) -> None:
    """Nothing returned.

    Args:
        x: a value.
    """


def gen():
    """A generator.

    Yields:
        Ones.
    """
    yield 1


def nested_return():
    """Only a nested function returns a value."""

    def inner():
        return 1

    inner()


def _private(x):
    return x


class Thing:
    """A class."""

    @property
    def size(self) -> int:
        """Its size."""
        return 1

    def method(self, y):
        """Takes y, returns it."""
        return y
'''
    )
    (tmp_path / "_hidden.py").write_text("def f(x):\n    return x\n")
    found = [line.split(":", 2)[2].strip() for line in missing_sections(tmp_path)]
    assert sorted(found) == [
        "Thing.method lacks Args:/Returns:",
        "args_only lacks Returns:",
        "bare lacks Args:/Returns:",
    ]


def test_every_rule_runs_on_one_thread():
    """On two cores a job of two threads starts only when both are free, which never happens
    while one-thread jobs are ready: it waits for the end of the run (the K selections did).
    Every ``threads:`` of the workflow is therefore 1 (a cluster gives a rule more with
    ``--set-threads``)."""
    found = []
    for smk in sorted((ROOT / "workflow" / "rules").glob("*.smk")) + [ROOT / "Snakefile"]:
        for i, line in enumerate(smk.read_text().splitlines(), 1):
            key, _, value = line.strip().partition(":")
            if key == "threads":
                found.append((f"{smk.name}:{i}", value.split("#")[0].strip()))
    assert found, "no threads: directive found; the rules declare threads (docs/development.md)"
    wider = [f"{where} threads: {v}" for where, v in found if v != "1"]
    assert not wider, "rules with more than one thread wait for the end of a 2-core run:\n" + (
        "\n".join(wider)
    )
