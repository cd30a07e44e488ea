"""Which settings made a result.

Two records, both travelling with the files (a results folder copied without Snakemake's
``.snakemake/`` metadata keeps them):

- the stamp (profile, resolved-config hash, package version) written into every table's CSV and
  the report, so copied tables say which config they came from;
- beside every output of every job, ``<output>.provenance`` (JSON): the job's settings (its rule
  and the params Snakemake tracks: the slice of the config the job reads), their hash, the
  commit, and the settings hash of each input it read. [`write_provenance`][physgs.provenance.write_provenance]
  writes it when a job ends well ([`physgs.jobs.job`][physgs.jobs.job]).

Snakemake remakes a file whose rule's params changed only when its metadata says so; a results
folder without that metadata (copied, or made before) is taken as up to date whatever config
made it. [`check_plan`][physgs.provenance.check_plan], run on every plan before any job starts
([`install`][physgs.provenance.install]), reads the record of every file the plan reads and does
not remake, and refuses a file made with other settings than the plan's (or from an input that
has since been made with other settings, or with no record at all), naming the file, the key
that differs and the command that remakes it.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import subprocess
import shlex
import sys
import time
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from physgs.atomic import write_json


def package_version() -> str:
    """physgs' installed version ('unknown' when run from a tree that is not installed).

    Returns:
        The version string of the installed distribution, or ``'unknown'``.
    """
    try:
        return version("physgs")
    except PackageNotFoundError:
        return "unknown"


def config_hash(cfg: dict) -> str:
    """Hash of the resolved config, unchanged by key order and changed by any value.

    Args:
        cfg: the resolved config.

    Returns:
        12 hex digits of the SHA-256 of the config as canonical JSON (sorted keys).
    """
    blob = json.dumps(cfg, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:12]


@dataclass(frozen=True)
class Stamp:
    """Provenance of one result.

    A class rather than a dict on purpose: Snakemake does not track params it cannot represent,
    so passing a Stamp as a rule's param records it without making every table out of date
    whenever any key of the config changes (the narrow settings and the inputs decide that).
    """

    profile: str
    config_hash: str
    physgs_version: str

    def to_dict(self) -> dict:
        """The stamp as a plain dict (profile, config_hash, physgs_version).

        Returns:
            A new dict of the dataclass fields.
        """
        return asdict(self)


def stamp(cfg: dict) -> Stamp:
    """The stamp of a resolved config.

    Args:
        cfg: the resolved config (its ``profile`` key names the profile).

    Returns:
        The [`Stamp`][physgs.provenance.Stamp]: profile, config hash and physgs' version.
    """
    return Stamp(str(cfg.get("profile", "unknown")), config_hash(cfg), package_version())


def read_stamped(path) -> "pandas.DataFrame":  # noqa: F821 (pandas: imported when called)
    """A CSV whose rows carry a [`Stamp`][physgs.provenance.Stamp] (a run's table, its claims),
    the config hash read as text: a hash of digits stays one.

    Args:
        path (str | Path): the CSV.

    Returns:
        Its rows.
    """
    import pandas as pd  # not at the top: the Snakefile imports this module to plan

    return pd.read_csv(path, dtype={"config_hash": str})


#: The CPU flags of native bf16 dot products (AVX-512 BF16, AMX), as Linux names them.
BF16_FLAGS = ("avx512_bf16", "amx_bf16")


def _cpuinfo(cpuinfo: str | Path) -> str:
    return Path(cpuinfo).read_text() if Path(cpuinfo).is_file() else ""


def _flags_in(info: str) -> list[str]:
    words = info.split()
    return [f for f in BF16_FLAGS if f in words]


def bf16_flags(cpuinfo: str | Path = "/proc/cpuinfo") -> list[str]:
    """The flags among ``BF16_FLAGS`` that the kernel reports for this CPU.

    Args:
        cpuinfo: the kernel's CPU description (Linux).

    Returns:
        Those flags; empty where it reports none or there is no such file (not Linux).
    """
    return _flags_in(_cpuinfo(cpuinfo))


def machine_cpu(cpuinfo: str | Path = "/proc/cpuinfo") -> str:
    """The CPU's model and whether it computes bf16 natively (AVX-512 BF16, AMX): what a
    timing depends on (the fields run in bf16).

    Args:
        cpuinfo: the kernel's CPU description (Linux); elsewhere ``platform.processor()``.

    Returns:
        ``'<model> (<flags>)'``, the flags among ``avx512_bf16`` and ``amx_bf16`` or ``no bf16``.
    """
    info = _cpuinfo(cpuinfo)
    model = next(
        (ln.split(":", 1)[1].strip() for ln in info.splitlines() if "model name" in ln), ""
    )
    flags = _flags_in(info)  # the text read once
    return f"{model or platform.processor() or 'unknown CPU'} ({', '.join(flags) or 'no bf16'})"


def git_commit(cwd: str | Path = ".") -> str:
    """The abbreviated hash of ``cwd``'s HEAD, or ``unknown`` outside a checkout.

    A plain hash, never ``git describe``'s ``tag-N-gHASH`` (a clone without the tag cannot
    resolve it) nor a ``-dirty`` suffix ([`git_dirty`][physgs.provenance.git_dirty] says that).

    Args:
        cwd: the directory git runs in.

    Returns:
        The hash (e.g. ``77c3389``), or ``'unknown'`` when git prints nothing.
    """
    out = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=cwd
    )
    return out.stdout.strip() or "unknown"


def git_dirty(cwd: str | Path = ".") -> bool:
    """Whether ``cwd``'s tracked files differ from its HEAD.

    Args:
        cwd: the directory git runs in.

    Returns:
        True when a tracked file is changed (False outside a checkout).
    """
    out = subprocess.run(
        ["git", "status", "--porcelain", "--untracked-files=no"],
        capture_output=True,
        text=True,
        cwd=cwd,
    )
    return bool(out.stdout.strip())


# ---- the provenance of every output ---------------------------------------------------------

#: the file beside each output that says which settings made it: ``<output>`` + this
SIDECAR_SUFFIX = ".provenance"
#: the param values Snakemake tracks (its persistence's ``_serialize_param_builtin``): a param of
#: another type (a [`Stamp`][physgs.provenance.Stamp]) is no setting of the job
TRACKED = (type(None), bool, int, float, str, complex, range, list, tuple, dict)
#: keys that differ named in a refusal, per file
KEYS_SHOWN = 3
#: files named in a refusal; the rest counted
FILES_SHOWN = 12
#: set (to anything but "" or "0") in Snakemake's environment, the plan's check reads the record
#: of every file of the plan that is there, of the jobs Snakemake would run again as well (what
#: ``tools/record.py`` asks: a finished run, every file made with the plan's settings)
EVERY_JOB_ENV = "PHYSGS_PROVENANCE_EVERY_JOB"
#: Snakemake's dry-run flags, left out of the command a refusal gives
DRY_RUN_FLAGS = ("-n", "--dry-run", "--dryrun")


class ProvenanceError(RuntimeError):
    """Files a plan would read that were made with other settings; the message names each."""


def sidecar(path: str | Path) -> Path:
    """The provenance record of ``path`` (a file or a folder).

    Args:
        path: an output.

    Returns:
        ``<path>.provenance``.
    """
    return Path(str(path) + SIDECAR_SUFFIX)


def job_settings(rule: str, params) -> dict:
    """What makes a job's output what it is, apart from its inputs: the rule and its params.

    The params Snakemake tracks (values of ``TRACKED`` types, by name), as JSON would read them
    back (tuples as lists), so a record read from disk compares equal to the settings computed
    again.

    Args:
        rule: the rule's name.
        params (snakemake.io.Namedlist | Mapping): the job's params (named ones are read).

    Returns:
        ``{"rule": rule, "params": {name: value}}``.
    """
    items = params.items() if hasattr(params, "items") else ()
    tracked = {k: v for k, v in items if isinstance(v, TRACKED)}
    return {"rule": rule, "params": json.loads(json.dumps(tracked, sort_keys=True, default=str))}


def settings_hash(settings: Mapping) -> str:
    """The hash of a job's settings ([`job_settings`][physgs.provenance.job_settings]).

    Args:
        settings: the settings.

    Returns:
        12 hex digits ([`config_hash`][physgs.provenance.config_hash] of them).
    """
    return config_hash(dict(settings))


def read_provenance(path: str | Path) -> dict | None:
    """The provenance record of ``path``.

    Args:
        path: an output.

    Returns:
        The record, or None when there is none.

    Raises:
        ProvenanceError: the record is there but unreadable, naming it and how to remake it.
    """
    side = sidecar(path)
    try:
        text = side.read_text()
    except FileNotFoundError:
        return None
    try:
        rec = json.loads(text)
        if not isinstance(rec, dict) or "settings_hash" not in rec:
            raise ValueError("not a provenance record")
    except ValueError as e:
        raise ProvenanceError(
            f"{side}: unreadable ({e}); remake {path} (`--forcerun {path}` added to the command)"
        ) from None
    return rec


def write_provenance(
    outputs: Iterable[str | Path],
    rule: str,
    params,
    inputs: Iterable[str | Path] = (),
    commit: str | None = None,
    previous: Mapping | None = None,
    known: Mapping[str, str] | None = None,
) -> dict:
    """Write the provenance record beside each of a job's outputs.

    Args:
        outputs: the job's outputs (each gets ``<output>.provenance``, written atomically).
        rule: the job's rule.
        params (snakemake.io.Namedlist | Mapping): the job's params.
        inputs: the files the job read; the settings hash each one's record holds is kept
            (None for a file with no record: a source file, a config).
        commit: the commit of the code that made them (default: the commit of the checkout
            physgs is imported from, [`git_commit`][physgs.provenance.git_commit]; the
            workflow's own checkout in a run).
        previous: the record the outputs had before this job (read before it cleared it):
            when its settings were others, they are kept (``replaced``), so a file made from
            the old outputs can name the key that changed.
        known: input -> settings hash, for inputs whose records are being written in the same
            pass (taken before their records on disk).

    Returns:
        The record written.
    """
    settings = job_settings(rule, params)
    read = {}
    for i in dict.fromkeys(str(i) for i in inputs):
        if known and i in known:
            read[i] = known[i]
            continue
        rec = read_provenance(i)
        read[i] = rec["settings_hash"] if rec else None
    record = {
        "settings_hash": settings_hash(settings),
        "settings": settings,
        "commit": commit or git_commit(Path(__file__).parent),
        "inputs": read,  # no time: two runs of one job write the same record (its mtime says when)
    }
    if previous and previous.get("settings_hash") != record["settings_hash"]:
        record["replaced"] = {k: previous.get(k) for k in ("settings_hash", "settings")}
    for out in outputs:
        write_json(sidecar(out), record)
    return record


def take_provenance(outputs: Iterable[str | Path]) -> dict | None:
    """Remove the records of ``outputs`` (a job about to make them: an output it leaves
    half-made never pairs with the record of the job that made it before), returning the
    first one's, for [`write_provenance`][physgs.provenance.write_provenance]'s ``previous``.

    Args:
        outputs: the job's outputs.

    Returns:
        The record the first output had (None: none, or unreadable).
    """
    outputs = list(outputs)
    try:
        previous = read_provenance(outputs[0]) if outputs else None
    except ProvenanceError:
        previous = None
    clear_provenance(outputs)
    return previous


def clear_provenance(outputs: Iterable[str | Path]) -> None:
    """Remove the records of ``outputs`` (a job about to make them: an output it leaves
    half-made never pairs with the record of the job that made it before).

    Args:
        outputs: the job's outputs.
    """
    for out in outputs:
        sidecar(out).unlink(missing_ok=True)


def _differences(
    made, now, key: str = "", was: str = "when it was made", is_: str = "in this plan"
) -> list[str]:
    """The dotted keys at which two settings differ, each with both values."""
    if isinstance(made, dict) and isinstance(now, dict):
        out = []
        for k in sorted(set(made) | set(now), key=str):
            sub = f"{key}.{k}" if key else str(k)
            if k not in made:
                out.append(f"`{sub}` absent {was}, {now[k]!r} {is_}")
            elif k not in now:
                out.append(f"`{sub}` {made[k]!r} {was}, absent {is_}")
            else:
                out += _differences(made[k], now[k], sub, was, is_)
        return out
    if made != now:
        return [f"`{key}` {made!r} {was}, {now!r} {is_}"]
    return []


def disagreement(output: str | Path, rule: str, params, inputs: Iterable[str | Path]) -> str | None:
    """Why ``output``, as a job with these settings would make it, is not the file on disk.

    Args:
        output: an output of the job (present on disk).
        rule: the job's rule.
        params (snakemake.io.Namedlist | Mapping): the job's params in this plan.
        inputs: the job's inputs in this plan.

    Returns:
        None when the file's record holds these settings and the settings each input's record
            holds now; otherwise what differs (the keys, with both values), in a phrase.
    """
    try:
        rec = read_provenance(output)
    except ProvenanceError as e:
        return str(e)
    if rec is None:
        return "carries no provenance record (made before records were kept, or copied without it)"
    now = job_settings(rule, params)
    if rec["settings_hash"] != settings_hash(now):
        diff = _differences(rec.get("settings", {}), now) or ["its settings hash"]
        more = f" and {len(diff) - KEYS_SHOWN} more" if len(diff) > KEYS_SHOWN else ""
        return "made with other settings: " + "; ".join(diff[:KEYS_SHOWN]) + more
    made_from = rec.get("inputs", {})
    for i in (str(i) for i in inputs):
        if i not in made_from:
            continue  # an input the plan adds (a new need): Snakemake remakes the job
        try:
            irec = read_provenance(i)
        except ProvenanceError:
            continue  # that input is named on its own
        h = irec["settings_hash"] if irec else None
        if h != made_from[i]:
            old = (irec or {}).get("replaced") or {}
            keys = ""
            if old.get("settings_hash") and old["settings_hash"] == made_from[i]:
                diff = _differences(old.get("settings", {}), irec["settings"], "", "then", "now")
                keys = " (" + "; ".join(diff[:KEYS_SHOWN]) + ")"
            return f"made from {i} before that was made again with other settings{keys}"
    return None


@dataclass
class PlanCheck:
    """What [`check_plan`][physgs.provenance.check_plan] found in a plan that agrees.

    Attributes:
        checked: the files whose records were read.
        adopted: the jobs (rule, params, outputs, inputs) whose outputs carry no record but
            whose params Snakemake's metadata records as this plan's: made before records were
            kept, by the settings the plan has ([`adopt`][physgs.provenance.adopt] writes them).
    """

    checked: int = 0
    adopted: list = field(default_factory=list)


def check_plan(jobs: Iterable, command: str) -> PlanCheck:
    """Refuse a plan that would read files made with other settings than its own.

    Args:
        jobs (Iterable[tuple]): the plan's jobs whose outputs it takes as made: rule, params,
            outputs, inputs and, optionally, whether Snakemake's metadata vouches for the
            outputs (it records them with this plan's params, and the job will not run). A job
            with an output missing is left out (Snakemake makes it).
        command: the command that planned it (named in the refusal, with ``{forcerun}`` where
            ``--forcerun`` and the files go).

    Returns:
        The [`PlanCheck`][physgs.provenance.PlanCheck].

    Raises:
        ProvenanceError: naming each file that disagrees (its rule and what differs) and the
            command that remakes them.
    """
    bad: list[tuple[str, str, str]] = []
    found = PlanCheck()
    for rule, params, outputs, inputs, *vouched in jobs:
        outputs = [str(o) for o in outputs]
        if not outputs or not all(Path(o).exists() for o in outputs):
            continue
        if vouched and vouched[0] and not any(sidecar(o).exists() for o in outputs):
            found.adopted.append((rule, params, outputs, inputs))
            continue
        for out in outputs:
            found.checked += 1
            why = disagreement(out, rule, params, inputs)
            if why:
                bad.append((out, rule, why))
                break  # one output of a job says it: the job's outputs are remade together
    if bad:
        lines = [f"- {out} (rule `{rule}`): {why}" for out, rule, why in bad[:FILES_SHOWN]]
        if len(bad) > FILES_SHOWN:
            lines.append(f"- and {len(bad) - FILES_SHOWN} more")
        rules = sorted({r for _, r, _ in bad})
        targets = [o for o, _, _ in bad] if len(bad) <= FILES_SHOWN else rules
        raise ProvenanceError(
            f"{len(bad)} file(s) this plan would read as made do not carry its settings "
            "(Snakemake takes a file as made when no metadata of its own says otherwise: a "
            "results folder copied without .snakemake/, or made before provenance records "
            "were kept):\n"
            + "\n".join(lines)
            + "\nremake them (and what is made from them) with: "
            + _with_forcerun(command, targets)
        )
    return found


def adopt(jobs: Iterable) -> int:
    """Write the records of outputs made before records were kept, with the settings that
    Snakemake's metadata says made them (``PlanCheck.adopted``).

    Args:
        jobs (Iterable[tuple]): rule, params, outputs, inputs of each job.

    Returns:
        The number of outputs given a record.
    """
    jobs = list(jobs)
    # each job's inputs may be another's outputs given records in this pass: take their hashes
    known = {
        str(o): settings_hash(job_settings(rule, params))
        for rule, params, outputs, _ in jobs
        for o in outputs
    }
    n = 0
    for rule, params, outputs, inputs in jobs:
        write_provenance(outputs, rule, params, inputs, known=known)
        n += len(outputs)
    return n


def _with_forcerun(command: str, targets: list[str]) -> str:
    """``command`` with ``--forcerun targets`` where its ``{forcerun}`` is (else at its end)."""
    flag = "--forcerun " + " ".join(shlex.quote(t) for t in targets)
    if "{forcerun}" in command:
        return command.replace("{forcerun}", flag)
    return f"{command} {flag}"


def plan_jobs(dag, every: bool = False) -> Iterable[tuple]:
    """The jobs of a Snakemake DAG whose outputs a run takes as made, as
    [`check_plan`][physgs.provenance.check_plan] reads them.

    Args:
        dag (snakemake.dag.DAG): the built DAG.
        every: the jobs Snakemake would run again too (their outputs, where present, are
            checked all the same).

    Yields:
        (tuple[str, Namedlist, list[str], list[str], bool]): rule, params, outputs, inputs, and
            whether Snakemake's metadata vouches for the outputs (it records this plan's params
            for each, and the job will not run).
    """
    persistence = dag.workflow.persistence
    for job in dag.jobs:
        needrun = dag.needrun(job)
        if (needrun and not every) or not job.output:
            continue
        # metadata that records these params vouches for outputs made before records were kept
        # (Snakemake stores params reliably from its record format 6 on)
        vouched = (
            not needrun
            and all((persistence.record_format_version(o) or 0) >= 6 for o in job.output)
            and all(persistence.params(o) is not None for o in job.output)
            and not persistence.params_changed(job)
        )
        yield job.rule.name, job.params, list(job.output), list(job.input), vouched


def install(workflow) -> None:
    """Check every plan ``workflow`` executes, dry runs included, when its DAG is built and
    before any job runs ([`check_plan`][physgs.provenance.check_plan]).

    Snakemake has no hook there (``onstart`` runs only when a real run has jobs to do), so the
    workflow's ``execute`` and ``_build_dag`` are wrapped on the instance: the DAGs built for
    anything but an execution (``--report``, ``--rulegraph``, ``--delete-all-output``) are not
    checked, nor the single-job plans of jobs Snakemake runs in processes of their own (a
    cluster executor's).

    Args:
        workflow (snakemake.workflow.Workflow): the Snakefile's ``workflow``.

    Raises:
        RuntimeError: the workflow has no ``execute`` or ``_build_dag`` (a Snakemake this was
            not written for).
    """
    build = getattr(workflow, "_build_dag", None)
    execute = getattr(workflow, "execute", None)
    if build is None or execute is None:
        raise RuntimeError(
            "physgs.provenance.install: Snakemake's Workflow has no _build_dag or execute; the "
            "provenance check was written for Snakemake 9.27"
        )
    if getattr(build, "_physgs_provenance", False):
        return
    executing = []

    def execute_checked(*args, **kwargs):
        executing.append(True)
        try:
            return execute(*args, **kwargs)
        finally:
            executing.pop()

    def build_and_check():
        build()
        if not executing or workflow.remote_exec or workflow.subprocess_exec:
            return
        from snakemake.exceptions import WorkflowError

        start = time.perf_counter()
        try:
            every = os.environ.get(EVERY_JOB_ENV, "") not in ("", "0")
            found = check_plan(plan_jobs(workflow.dag, every=every), _command())
        except ProvenanceError as e:
            raise WorkflowError(str(e)) from None  # Snakemake prints its message, no traceback
        if found.checked:
            print(
                f"provenance: the {found.checked} files this plan reads as made agree with its "
                f"settings ({time.perf_counter() - start:.2f} s)",
                file=sys.stderr,
            )
        if found.adopted:
            outs = sum(len(j[2]) for j in found.adopted)
            if workflow.dryrun:
                what = "would be written (a run writes them)"
            else:
                adopt(found.adopted)
                what = "written"
            print(
                f"provenance: {outs} files made before provenance records were kept, with the "
                "params Snakemake's metadata records for them (this plan's): their records "
                f"{what}",
                file=sys.stderr,
            )

    build_and_check._physgs_provenance = True
    workflow._build_dag = build_and_check
    workflow.execute = execute_checked


def _command() -> str:
    """The command line that planned the run, as a person would type it again to run it, with
    ``{forcerun}`` where the files to remake go (before a ``--`` that ends the options)."""
    argv = [a for a in sys.argv if a not in DRY_RUN_FLAGS]
    if argv and Path(argv[0]).name in ("__main__.py", "snakemake"):
        argv[0] = "snakemake"
    words = [shlex.quote(a) for a in argv]
    at = words.index("--") if "--" in words else len(words)
    return " ".join([*words[:at], "{forcerun}", *words[at:]])
