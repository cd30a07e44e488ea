"""The one training recipe: what a job needs to know, and fit = seed, build, train (freezing
included), in that order, for every model and every caller.

The workflow imports ``job_spec`` and ``canonical`` to plan jobs; the training machinery (torch)
loads inside ``fit`` and ``train_and_save``, so a dry run does not pay its start-up."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from physgs.mappings import deep_merge
from physgs.provenance import bf16_flags
from physgs.models.checkpoint import save_checkpoint
from physgs.testbed.variant import parse_id
from physgs.models.families import searches_omega
from physgs.models.omega_search import OmegaSearch, omega_search_callback, search_iteration
from physgs.models.registry import (
    FIELD_FAMILIES,
    build_model,
    condition_indices,
    configs_for,
    is_prior,
    model_settings,
    spec_of,
)

if TYPE_CHECKING:  # the training machinery loads torch (module docstring)
    from physgs.train.loop import TrainResult


def canonical(x):
    """``x`` with every dict's keys sorted (recursively): a stable repr, so Snakemake's params
    check sees a job as changed only when a value changes, never when keys are reordered.

    Args:
        x (Any): a dict, list, tuple or leaf.

    Returns:
        (Any): The same structure (tuples as lists).
    """
    if isinstance(x, dict):
        return {k: canonical(x[k]) for k in sorted(x)}
    if isinstance(x, (list, tuple)):
        return [canonical(v) for v in x]
    return x


@dataclass(frozen=True)
class Job:
    """Everything one training job reads, and nothing more.

    model: a registry id (a method, or a reference such as truth_motion); config: configuration
    name (labels the run); K: ours' parts (None for the rest); conditions: 'train' or 'all';
    seed: every random source of the job (model initialisation, k-means, frame draws);
    settings: ``model_settings`` of the models section; train: the ``train`` section.
    """

    model: str
    config: str
    conditions: str
    seed: int
    settings: dict = field(repr=False)
    train: dict = field(repr=False)
    K: int | None = None

    @property
    def name(self) -> str:
        """The job's run name, ``<model>_<config>``."""
        return f"{self.model}_{self.config}"

    def to_dict(self) -> dict:
        """The job as a plain dict, keys sorted at every level.

        See [canonical][physgs.experiments.recipe.canonical].

        Returns:
            The job's fields as nested plain values.
        """
        return canonical(asdict(self))

    @staticmethod
    def from_dict(d: dict) -> "Job":
        """The job that [to_dict][physgs.experiments.recipe.Job.to_dict] wrote.

        Args:
            d: field name -> value (extra keys are ignored).

        Returns:
            The job.
        """
        return Job(**{k: d[k] for k in Job.__dataclass_fields__})

    def replace(self, **kw) -> "Job":
        """A copy of the job with the fields in ``kw`` changed.

        Args:
            **kw (Any): field name -> new value.

        Returns:
            The new job.
        """
        return Job.from_dict({**asdict(self), **kw})


def job_spec(
    cfg: dict, model: str, config: str, seed: int | None = None, tree: str | None = None
) -> dict:
    """The narrow settings of one (model, configuration) training job, as a sorted plain dict.

    What the workflow passes as the train rule's params: editing a key outside it (another model's
    architecture, a table's format, the sweep) leaves the job up to date. References
    (``truth_motion``) are trained in ``single`` only. A tree's recipe (``recipes.<tree>.<model>``:
    the settings a search on that tree's held-out window frames chose, [`tree_recipe`][physgs.
    experiments.recipe.tree_recipe]) is merged over the shared ``train`` and ``models`` sections.

    Args:
        cfg: the resolved config.
        model: a registry id.
        config: a configuration name (``models.configs``).
        seed: the job's seed; None: the config's.
        tree: the tree the job trains on (its recipe applies); None: the shared settings only.

    Returns:
        The job's fields ([`Job`][physgs.experiments.recipe.Job]) as a canonical dict.

    Raises:
        ValueError: the model is not trained in that configuration.
    """
    configs = cfg["models"]["configs"]
    if config not in configs_for(model, configs):
        raise ValueError(
            f"model {model!r} is not trained in configuration {config!r}; valid: "
            f"{configs_for(model, configs)} (joint configurations are ours only)"
        )
    spec = configs[config]
    recipe = tree_recipe(cfg, tree, model)
    return Job(
        model=model,
        config=config,
        conditions=spec["conditions"],
        seed=int(cfg["seed"] if seed is None else seed),
        settings=deep_merge(model_settings(cfg["models"], model), recipe.get("settings", {})),
        train=deep_merge(cfg["train"], recipe.get("train", {})),
        K=int(spec["K"]) if is_prior(model) else None,
    ).to_dict()


def tree_recipe(cfg: dict, tree: str | None, model: str) -> dict:
    """The settings chosen for ``model`` on ``tree`` (``recipes``), over the shared ones.

    A damping testbed (``<tree>_damping``) takes its tree's recipe: the same tree, another
    damping. A forcing-free variant (``ours_blind``) takes its prior's recipe where it has none
    of its own: the claims compare the two, so one budget trains both.

    Args:
        cfg: the resolved config.
        tree: a tree name, or None (no recipe).
        model: a registry id.

    Returns:
        ``{"train": {...}, "settings": {...}}``, each a partial section (empty: none chosen).
    """
    if tree is None:
        return {}
    recipes = cfg.get("recipes") or {}
    own = recipes.get(tree) or recipes.get(parse_id(tree)[0]) or {}
    parent = spec_of(model).blind_of
    return own.get(model) or (own.get(parent) if parent else None) or {}


def heldout_split(n_train: int, every: int) -> tuple[np.ndarray, np.ndarray]:
    """(training frames, held-out frames): indices in [0, n_train), every ``every``-th held out
    (frames every-1, 2 every-1, ...), so frame 0 and the window's start stay in training.

    Args:
        n_train: training-window length, frames.
        every: the holdout period, in [2, n_train].

    Returns:
        ``(trained, held)`` frame indices, int arrays.

    Raises:
        ValueError: for ``every`` outside [2, n_train].
    """
    if not 2 <= every <= n_train:
        raise ValueError(
            f"every (train.holdout_every, models.kselect.every) must lie in "
            f"[2, n_train = {n_train}], got {every}"
        )
    idx = np.arange(n_train)
    held = (idx % every) == every - 1
    return idx[~held], idx[held]


def fit(
    observed,
    job: Job | dict,
    *,
    truth=None,
    frame_pool=None,
    progress: bool = True,
    name: str | None = None,
    hooks: tuple = (),
    device=None,
) -> TrainResult:
    """Seed, build and train one model.

    Every random source is seeded from ``job.seed`` before the model is built, so the same job
    gives bitwise-equal weights in any process. Ours freezes parts whose swing stays under
    ``models.ours.freeze_below_px`` pixels (``freeze_at``); by default every
    ``train.holdout_every``-th training frame is held out (0 = none), so the fit and the
    interpolation to unseen in-window frames can be told apart.

    Args:
        observed (Observed): the testbed's observed dataset.
        job: the job, or its dict.
        truth (Truth | None): the dataset's ground truth (truth.npz), required by a reference
            (truth_motion) and refused for a method.
        frame_pool (np.ndarray | None): recorded-frame indices (< n_train) to draw from; None:
            every training frame not held out.
        progress: show a progress bar.
        name: the name the progress and errors use; None: the job's.
        hooks: ``on_iteration`` callbacks ``(iteration, model, optimiser)`` run after the
            recipe's own (a benchmark's recorder of the fit curve); they must not change the model.
        device (str | torch.device | None): where to train; None: ``train.device`` of the job
            resolved on this machine ([`resolve_device`][physgs.device.resolve_device]:
            auto takes CUDA where torch sees a GPU).

    Returns:
        The [`TrainResult`][physgs.train.loop.TrainResult] (model in eval mode, on the device).

    Raises:
        ValueError: an unknown model, or a truth given to a method.
        TrainingError: the fit diverged or the model failed (no result).
    """
    # here: the training machinery loads torch (module docstring)
    from physgs.device import resolve_device
    from physgs.train.loop import train_model
    from physgs.train.seeding import seed_everything

    job = Job.from_dict(job) if isinstance(job, dict) else job
    spec = spec_of(job.model)  # the job's one look-up: an unknown id raises, naming the valid ones
    check_precision_supported(job.settings, families=(spec.family,))
    dev = resolve_device(job.train.get("device", "auto")) if device is None else device
    seed_everything(job.seed)
    # build_model checks the rest: the configuration, a truth given to a method (refused) or
    # missing for a reference (it says it needs truth.npz)
    model = build_model(
        job.model,
        observed,
        job.settings,
        config=job.config,
        K=job.K,
        seed=job.seed,
        truth=truth,
    )
    conds = condition_indices(job.conditions, len(observed.conditions))
    every = int(job.train.get("holdout_every", 0))
    held = None
    if every:
        trained, held = heldout_split(int(observed.n_train), every)
        frame_pool = trained if frame_pool is None else frame_pool
    result = train_model(
        model,
        observed,
        job.train,
        conditions=conds,
        seed=job.seed,
        name=name or job.name,
        progress=progress,
        frame_pool=frame_pool,
        on_iteration=[*training_hooks(observed, job, conds), *hooks],
        holdout=holdout_eval(observed, job, held, conds, device=dev),
        earliest_stop=earliest_stop(job),
        device=dev,
    )
    if spec.role == "prior":
        result.stats["frozen_parts"] = int(result.model.frozen.sum())
    return result


def with_budget(train: dict, iterations: int) -> dict:
    """A ``train`` section trained for ``iterations`` instead, its static warm-up keeping its
    fraction (the sweep's iterations knob, the fit curve's points, the benchmarks' curves).

    Args:
        train: a ``train`` config section.
        iterations: the new budget.

    Returns:
        A new section.
    """
    frac = train["warmup"] / train["iterations"]
    iterations = int(iterations)
    return {**train, "iterations": iterations, "warmup": max(1, int(round(frac * iterations)))}


def window_scorer(observed, job: Job, device=None):
    """The evaluator of the frames ``job``'s training window holds out, of its trained winds:
    what a recipe search and a fit curve read (never the views, the tail or another wind).

    Args:
        observed (Observed): the testbed's observed dataset.
        job: the training job (``train.holdout_every`` > 0).
        device (str | torch.device | None): the training's device (None: ``train.device``
            resolved here, as ``fit`` does).

    Returns:
        (HoldoutEval): the evaluator.

    Raises:
        ValueError: ``train.holdout_every`` is 0 (no frame held out).
    """
    from physgs.device import resolve_device
    from physgs.train.holdout import HoldoutEval  # here: torch (module docstring)

    every = int(job.train.get("holdout_every", 0))
    if not every:
        raise ValueError("train.holdout_every is 0: no held-out window frame to score")
    held = heldout_split(int(observed.n_train), every)[1]
    conds = condition_indices(job.conditions, len(observed.conditions))
    dev = resolve_device(job.train.get("device", "auto")) if device is None else device
    return HoldoutEval.build(observed, held, conds, job.train, device=dev)


def holdout_eval(observed, job: Job, held, conditions: list[int], device=None):
    """The evaluator of the held-out window frames the stopping rule reads, or None when the
    rule neither evaluates (``train.stopping.every`` 0) nor has frames to read.

    Args:
        observed (Observed): the dataset.
        job: the training job.
        held (np.ndarray | None): the held-out frame indices (``heldout_split``), or None.
        conditions: the trained conditions' indices (their winds' held-out frames only).
        device (str | torch.device | None): the training's device (None: the CPU).

    Returns:
        (HoldoutEval | None): the evaluator.

    Raises:
        ValueError: the rule is enabled and no frame is held out.
    """
    from physgs.train.holdout import HoldoutEval  # here: torch (module docstring)
    from physgs.train.stopping import StopRule

    rule = StopRule.from_config(job.train)
    if held is None or held.size == 0:
        if rule.enabled:
            raise ValueError(
                "train.stopping.enabled needs held-out window frames to read: set "
                "train.holdout_every > 0, or train.stopping.enabled: false"
            )
        return None
    if rule.every <= 0:
        return None
    return HoldoutEval.build(observed, held, conditions, job.train, device=device)


def earliest_stop(job: Job) -> int:
    """The first iteration the stopping rule may count: after the recipe's last change to the
    model (freezing of invisible parts, the end of the search over omega), so a stopped
    training has had every step of its recipe.

    Args:
        job: the training job.

    Returns:
        The iteration (0 when the recipe changes nothing after the warm-up).
    """
    from physgs.models.visibility import freeze_schedule  # here: torch (module docstring)

    out = 0
    if is_prior(job.model):
        freeze = freeze_schedule(job.settings, job.train)
        out = freeze or 0
        if searches_omega(job.settings, job.model):
            search = OmegaSearch.from_config(job.settings["omega_search"])
            out = max(out, search_iteration(search, job.train, freeze))
    return out


def training_hooks(observed, job: Job, conditions: list[int]) -> list:
    """The ``on_iteration`` hooks of ``job``'s training, in order: freezing invisible parts
    (oscillator priors, unless off) and the search over omega (the models it lists).

    Args:
        observed (Observed): the dataset.
        job: the training job.
        conditions: the trained conditions' indices.

    Returns:
        The hooks (none that are off).

    Raises:
        ValueError: for a freezing iteration or a search end outside the deformation phase.
    """
    from physgs.models.visibility import freeze_callback  # here: torch (module docstring)

    hooks = []
    if is_prior(job.model):
        hooks.append(freeze_callback(observed, job.settings, job.train))
    if searches_omega(job.settings, job.model):
        hooks.append(omega_search_callback(observed, job.settings, job.train, conditions))
    return [h for h in hooks if h is not None]


def check_precision_supported(
    settings: dict, families: tuple[str, ...] = FIELD_FAMILIES, *, planning: bool = False
) -> None:
    """Raise RuntimeError if any of ``families`` asks for ``precision: bfloat16`` in the models
    settings ``settings`` and this CPU has no native bf16 (autocast would emulate it, ~48x
    slower than float32: a default run would take days), naming the key and the way out. torch
    is imported only when some family asks for bf16, so planning a float32 run stays light.

    Args:
        settings: the ``models`` settings.
        families: the field families checked.
        planning: the plan's check (the Snakefile, at every Snakemake call): a CPU whose flags
            report native bf16 (``physgs.provenance.bf16_flags``) passes without loading torch
            (~1.5 CPU-s a call); otherwise, and always in a training job, oneDNN's own probe
            decides.

    Raises:
        RuntimeError: naming the key and the way out when bf16 is asked for without native
            support.
    """
    asked = [
        f for f in families if (settings.get(f) or {}).get("precision", "float32") == "bfloat16"
    ]
    if not asked or (planning and bf16_flags()):
        return
    from physgs.models.fields import native_bf16  # here: torch, only when bf16 is asked for

    if not native_bf16():
        import torch

        keys = " and ".join(f"models.{f}.precision" for f in asked)
        raise RuntimeError(
            f"{keys} is bfloat16, but this CPU (torch capability "
            f"{torch.backends.cpu.get_cpu_capability()}) has no native bf16 matmuls: autocast "
            "would emulate them, ~48x slower than float32. Run with `--configfile "
            "config/float32.yaml` (or set precision: float32 in config/trees.yaml), or on a CPU "
            "with AVX-512 BF16 or AMX"
        )


def train_and_save(
    observed,
    job: Job | dict,
    *,
    checkpoint_path,
    loss_path,
    progress: bool = True,
    truth=None,
    resources=None,
) -> TrainResult:
    """[`fit`][physgs.experiments.recipe.fit], then write the loss log and the checkpoint.

    Each is written atomically, the checkpoint last; nothing is written if training fails. The
    checkpoint of a reference carries its motion, so it reloads without truth.npz.

    Args:
        observed (Observed): the testbed's observed dataset.
        job: the job, or its dict.
        checkpoint_path (str | os.PathLike): where the checkpoint goes.
        loss_path (str | os.PathLike): where the per-iteration loss log goes.
        progress: show a progress bar.
        truth (Truth | None): as in ``fit`` (references only).
        resources (Mapping | None): the job's resources (``snakemake.resources``): a GPU asked
            for there trains on CUDA, whatever ``train.device`` says
            ([`resolve_device`][physgs.device.resolve_device]); the checkpoint is saved
            device-free either way.

    Returns:
        The [`TrainResult`][physgs.train.loop.TrainResult].
    """
    # here: torch (module docstring)
    from physgs.device import resolve_device
    from physgs.train.loop import write_loss_log

    job = Job.from_dict(job) if isinstance(job, dict) else job
    device = resolve_device(job.train.get("device", "auto"), resources)
    result = fit(observed, job, truth=truth, progress=progress, device=device)
    write_loss_log(loss_path, result.log)
    save_checkpoint(
        checkpoint_path,
        result.model,
        name=job.model,
        config=job.config,
        seed=job.seed,
        models_cfg=job.settings,
        train_cfg=job.train,
        stats=result.stats,
    )
    return result
