"""Where a training runs: ``train.device`` (auto | cpu | cuda) and the job's own resources.

One rule for every job: a job whose resources ask for a GPU (a SLURM ``gres`` naming a gpu, or a
``gpu``/``gpus`` count above 0, as ``--set-resources train:gres=gpu:1`` gives the cluster
profile's GPU partition) trains on CUDA and fails if its node shows none; otherwise the setting
decides, ``auto`` taking CUDA where torch sees a GPU and the CPU elsewhere. The device is never
guessed from the machine the plan was made on: a cluster plans on a login node without a GPU.

torch is imported only where a device is resolved or CUDA is asked for, so the Snakefile can
check the setting while it plans without loading torch.
"""

from __future__ import annotations

import re
from typing import Mapping

#: the values of ``train.device``
DEVICES = ("auto", "cpu", "cuda")


def asks_for_gpu(resources: Mapping | None) -> bool:
    """Whether a job's resources ask for a GPU.

    Args:
        resources: the job's resources by name (``snakemake.resources``), or None.

    Returns:
        True for a ``gres`` naming a gpu (``gpu:1``, ``gpu:h100:2``) or a ``gpu``/``gpus``
            count above 0.
    """
    if not resources:
        return False
    gres = str(resources.get("gres") or "")
    if re.search(r"(^|,)\s*gpu(:|$|,)", gres):
        return True
    for key in ("gpu", "gpus"):
        value = resources.get(key)
        try:
            if value is not None and int(value) > 0:
                return True
        except (TypeError, ValueError):  # e.g. gpus="h100:1" (a model and a count): a GPU ask
            return bool(str(value).strip())
    return False


def check_setting(setting: str) -> None:
    """Refuse an unknown ``train.device`` value, or ``cuda`` where torch sees no GPU.

    Called while the workflow plans, before any job: a run that asks for CUDA on a machine
    without one stops here, naming the key, instead of failing in its first training.

    Args:
        setting: the ``train.device`` value.

    Raises:
        ValueError: for a value outside ``DEVICES``.
        RuntimeError: for ``cuda`` where ``torch.cuda.is_available()`` is False.
    """
    if setting not in DEVICES:
        raise ValueError(f"train.device must be one of {', '.join(DEVICES)}; got {setting!r}")
    if setting == "cuda":
        import torch  # here: only when CUDA is asked for, so planning a CPU run stays light

        if not torch.cuda.is_available():
            raise RuntimeError(
                "train.device is cuda, but torch sees no GPU here (torch "
                f"{torch.__version__}, CUDA build {torch.version.cuda}): set train.device: auto "
                "(or cpu), or on a cluster ask for the GPU through the rule's resources "
                "(--set-resources train:gres=gpu:1, docs/cluster.md) and leave the setting auto"
            )


def resolve_device(setting: str = "auto", resources: Mapping | None = None):
    """The torch device a job trains and renders on.

    Args:
        setting: ``train.device`` (auto | cpu | cuda).
        resources: the job's resources (``snakemake.resources``); a GPU asked for there wins
            over the setting.

    Returns:
        (torch.device): ``cuda`` or ``cpu``.

    Raises:
        ValueError: an unknown setting, or ``cpu`` set while the resources ask for a GPU.
        RuntimeError: CUDA asked for (by the setting or the resources) where torch sees no GPU.
    """
    import torch  # here: resolved in the job, never while planning

    if setting not in DEVICES:
        raise ValueError(f"train.device must be one of {', '.join(DEVICES)}; got {setting!r}")
    if asks_for_gpu(resources):
        if setting == "cpu":
            raise ValueError(
                "the job's resources ask for a GPU but train.device is cpu: drop the GPU "
                "resources or set train.device: auto"
            )
        if not torch.cuda.is_available():
            raise RuntimeError(
                f"the job's resources ask for a GPU ({_gpu_ask(resources)}) but torch sees none "
                f"on this node (torch {torch.__version__}, CUDA build {torch.version.cuda}); "
                "check the partition and that a CUDA build of torch is installed there"
            )
        return torch.device("cuda")
    if setting == "cuda" or (setting == "auto" and torch.cuda.is_available()):
        check_setting("cuda")
        return torch.device("cuda")
    return torch.device("cpu")


def _gpu_ask(resources: Mapping) -> str:
    return ", ".join(
        f"{k}={resources[k]}" for k in ("gres", "gpu", "gpus") if resources.get(k) is not None
    )
