"""SLURM requests checked against the partitions before any job is submitted.

A job whose threads, memory or run time no node of its partition can give waits PENDING for ever
(reason PartitionConfig or Resources), and Snakemake waits with it without a word. The Snakefile's
``onstart`` hook (run after the DAG is built, before the first submission, only with the SLURM
executor) calls [`check_jobs`][physgs.cluster.check_jobs] with what ``sinfo`` reports, and stops
with every offending rule and request named.
"""

from __future__ import annotations

import re
import subprocess
from dataclasses import dataclass

#: sinfo's format: partition (default marked '*'), CPUs per node, memory per node (MB), time limit
SINFO_FORMAT = "%P|%c|%m|%l"


class ClusterRequestError(RuntimeError):
    """A job asks for more than any node of its partition has; the message names the rule."""


@dataclass(frozen=True)
class Partition:
    """The largest node of one Slurm partition, as ``sinfo`` reports it."""

    name: str
    default: bool
    cpus: int  # most CPUs on one node
    mem_mb: int  # most memory on one node
    max_minutes: float  # the partition's time limit (inf: none)


def parse_time_limit(text: str) -> float:
    """A Slurm time limit in minutes.

    Args:
        text: sinfo's %l (``infinite``, ``MM``, ``MM:SS``, ``HH:MM:SS``, ``D-HH:MM:SS``).

    Returns:
        Minutes (inf: no limit).
    """
    text = text.strip()
    if text in ("infinite", "UNLIMITED", "n/a", ""):
        return float("inf")
    days = 0
    if "-" in text:
        d, text = text.split("-", 1)
        days = int(d)
    parts = [int(p) for p in text.split(":")]
    if len(parts) == 1:  # minutes
        h, m, s = 0, parts[0], 0
    elif len(parts) == 2:  # minutes:seconds
        h, m, s = 0, parts[0], parts[1]
    else:
        h, m, s = parts
    return days * 1440 + h * 60 + m + s / 60


def parse_sinfo(text: str) -> dict[str, Partition]:
    """Partitions from the output of ``sinfo -h -o '%P|%c|%m|%l'``.

    One line per partition and node kind: the largest node counts (a job needs one node that fits).

    Args:
        text: sinfo's output.

    Returns:
        Partition name -> [`Partition`][physgs.cluster.Partition] (the default one marked).
    """
    out: dict[str, Partition] = {}
    for line in text.splitlines():
        if not line.strip():
            continue
        name, cpus, mem, limit = (f.strip() for f in line.split("|"))
        default = name.endswith("*")
        name = name.rstrip("*")
        cpus_n = int(re.sub(r"\D.*", "", cpus) or 0)
        mem_n = int(re.sub(r"\D.*", "", mem) or 0)
        prev = out.get(name)
        out[name] = Partition(
            name,
            default or (prev.default if prev else False),
            max(cpus_n, prev.cpus if prev else 0),
            max(mem_n, prev.mem_mb if prev else 0),
            parse_time_limit(limit),
        )
    return out


def sinfo() -> dict[str, Partition]:
    """The partitions of the cluster this machine submits to.

    Returns:
        Partition name -> [`Partition`][physgs.cluster.Partition], from ``sinfo -h -o
            SINFO_FORMAT``.

    Raises:
        ClusterRequestError: when ``sinfo`` fails.
    """
    proc = subprocess.run(
        ["sinfo", "-h", "-o", SINFO_FORMAT], capture_output=True, text=True, check=False
    )
    if proc.returncode != 0:
        raise ClusterRequestError(
            f"sinfo failed ({proc.returncode}): {proc.stderr.strip()}; cannot check the jobs' "
            "requests against the partitions"
        )
    return parse_sinfo(proc.stdout)


@dataclass(frozen=True)
class Request:
    """What one rule's jobs ask the cluster for (threads, memory in MB, runtime in minutes)."""

    rule: str
    threads: int
    mem_mb: float | None
    runtime: float | None  # minutes
    partition: str | None  # None: the cluster's default


def problems(requests: list[Request], partitions: dict[str, Partition]) -> list[str]:
    """What no node of each job's partition can give.

    Args:
        requests: the rules' requests.
        partitions: name -> partition.

    Returns:
        One line per (rule, what), sorted.
    """
    default = next((p for p in partitions.values() if p.default), None)
    out: set[str] = set()
    for r in requests:
        if r.partition is not None and r.partition not in partitions:
            out.add(
                f"rule {r.rule}: slurm_partition={r.partition} does not exist "
                f"(partitions: {', '.join(sorted(partitions))})"
            )
            continue
        p = partitions[r.partition] if r.partition is not None else default
        if p is None:
            out.add(f"rule {r.rule}: no slurm_partition given and the cluster has no default")
            continue
        if r.threads > p.cpus:
            out.add(
                f"rule {r.rule}: threads={r.threads} but partition {p.name}'s nodes have at "
                f"most {p.cpus} CPUs (--set-threads {r.rule}=N)"
            )
        if r.mem_mb is not None and r.mem_mb > p.mem_mb:
            out.add(
                f"rule {r.rule}: mem_mb={r.mem_mb:g} but partition {p.name}'s nodes have at "
                f"most {p.mem_mb} MB (--set-resources {r.rule}:mem_mb=N)"
            )
        if r.runtime is not None and r.runtime > p.max_minutes:
            out.add(
                f"rule {r.rule}: runtime={r.runtime:g} min but partition {p.name} allows at "
                f"most {p.max_minutes:g} min (--set-resources {r.rule}:slurm_partition=...)"
            )
    return sorted(out)


def _num(v):
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None


def check_jobs(jobs, partitions: dict[str, Partition] | None = None) -> None:
    """Stop before submission if any rule asks for more than a node of its partition has.

    Args:
        jobs (Iterable): Snakemake jobs (``rule.name``, ``threads``, ``resources``).
        partitions: name -> partition; None: read from ``sinfo``.

    Raises:
        ClusterRequestError: naming every rule whose request no node can meet.
    """
    requests = []
    for job in jobs:
        res = job.resources
        part = res.get("slurm_partition")
        requests.append(
            Request(
                rule=job.rule.name,
                threads=int(job.threads),
                mem_mb=_num(res.get("mem_mb")),
                runtime=_num(res.get("runtime")),
                partition=str(part) if part else None,
            )
        )
    lines = problems(requests, partitions if partitions is not None else sinfo())
    if lines:
        raise ClusterRequestError(
            "requests no node can meet; nothing was submitted:\n  - " + "\n  - ".join(lines)
        )
