"""Choose the number of parts K of the oscillator prior from the data, beside fixed K.

Config ``models.kselect``: candidates (K values), method (``heldout`` or ``bic``), every (hold
out every k-th training frame), iterations and warmup (a short training run per candidate),
tie_db (dB), conditions (which wind conditions the chosen model then trains on). Ours' K is
always chosen (trained as ``ours_auto``); each prior under ``priors`` (prior -> its own
candidates, iterations and warmup, the rest shared) is chosen the same way and trained as
``<prior>_auto``: the chained prior's search over omega needs its bank phase after the
warm-up, so its short runs are longer than ours' (``settings_for``).

Both criteria come from the same runs: ours is trained per candidate by the one recipe
([`physgs.experiments.recipe.fit`][]: seeding, loop, schedule and freezing as the full run, only
shorter) on the training frames minus every k-th (frames k-1, 2k-1, ...), and scored through
the evaluation's render callback.
- ``heldout``: mean PSNR (dB) over the held-out frames at the training camera and wind; the
  smallest K within ``tie_db`` of the best wins (ties go to the smaller model).
- ``bic``: n log(MSE) + p log n over the training frames scored (n = pixel values, MSE on
  [0, 1] images), p = 8 K (per part omega, zeta, gain, 2 axis angles, 3 pivot coordinates; the
  canonical Gaussians are the same for every K and cancel). Pixels are strongly correlated, so
  n overstates the evidence and BIC leans to large K; held-out frames are the default.
Both choices are recorded whichever ``method`` picks the K used.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from physgs.experiments.recipe import Job, fit, heldout_split  # noqa: F401 (re-exported)
from physgs.models.registry import AUTO_CONFIG, PAPER_MODEL
from physgs.records import JsonRecord

METHODS = ("heldout", "bic")
PARAMS_PER_PART = 8  # omega, zeta, gain, swing axis (2), pivot (3)
#: the prior whose K the section's own keys choose (an entry of its own under ``priors`` is refused)
BASE_MODEL = PAPER_MODEL
#: what a prior's entry under ``models.kselect.priors`` may set: its candidates and its short
#: runs' schedule (the criterion, held-out frames and conditions stay shared, so the choices
#: compare)
OWN_KEYS = ("candidates", "iterations", "warmup")


def selected_models(kselect: dict) -> tuple[str, ...]:
    """The priors whose K is chosen from the data: ours, then those under ``priors``.

    Args:
        kselect: the ``models.kselect`` config section.

    Returns:
        Their registry ids, ours first, then in the section's order.
    """
    return (BASE_MODEL, *(kselect.get("priors") or {}))


def section_key(model: str) -> str:
    """The config key holding a model's own K-selection settings (for messages).

    Args:
        model: a registry id among ``selected_models``.

    Returns:
        ``models/kselect`` for ours, ``models/kselect/priors/<model>`` for another prior.
    """
    return "models/kselect" if model == BASE_MODEL else f"models/kselect/priors/{model}"


def settings_for(kselect: dict, model: str) -> dict:
    """The K-selection settings of ``model``: the section's keys, with the model's own entry
    under ``priors`` over them (ours: the section's keys alone, exactly as before priors had
    entries, so ours' selection reruns on its own keys only).

    Args:
        kselect: the ``models.kselect`` config section.
        model: a registry id among ``selected_models(kselect)``.

    Returns:
        candidates, method, every, iterations, warmup, tie_db, conditions of its selection.

    Raises:
        ValueError: ``model`` has no K selection, naming the ones that have.
    """
    shared = {k: v for k, v in kselect.items() if k != "priors"}
    if model == BASE_MODEL:
        return shared
    own = (kselect.get("priors") or {}).get(model)
    if own is None:
        raise ValueError(
            f"{model!r} has no K selection; models/kselect/priors lists "
            f"{list(selected_models(kselect)[1:])} (ours is always chosen)"
        )
    return {**shared, **own}


def bic(mse: float, n: int, k_parts: int) -> float:
    """n log(MSE) + p log n with p = 8 K (see module docstring); lower is better.

    Args:
        mse: mean squared error of the scored pixels (> 0).
        n: number of scored values (> 0).
        k_parts: K.

    Returns:
        The BIC.

    Raises:
        ValueError: unless mse > 0 and n > 0.
    """
    if not (mse > 0 and n > 0):
        raise ValueError(f"bic needs mse > 0 and n > 0, got {mse}, {n}")
    return float(n * np.log(mse) + PARAMS_PER_PART * k_parts * np.log(n))


def choose_heldout(candidates, heldout_psnr, tie_db: float) -> int:
    """Smallest K whose held-out PSNR (dB) is within ``tie_db`` of the best.

    Args:
        candidates (ArrayLike): [n] K values.
        heldout_psnr (ArrayLike): [n] held-out PSNR per candidate, dB.
        tie_db: the tolerance, dB.

    Returns:
        The chosen K.

    Raises:
        ValueError: when every PSNR is non-finite.
    """
    ks, p = np.asarray(candidates), np.asarray(heldout_psnr, dtype=np.float64)
    if not np.isfinite(p).any():
        raise ValueError("every K candidate gave a non-finite held-out PSNR; training diverged")
    ok = p >= np.nanmax(p) - tie_db
    return int(ks[ok].min())


def choose_bic(candidates, bics) -> int:
    """K with the lowest BIC (ties: the smaller K).

    Args:
        candidates (ArrayLike): [n] K values.
        bics (ArrayLike): [n] BIC per candidate.

    Returns:
        The chosen K.
    """
    ks, b = np.asarray(candidates), np.asarray(bics, dtype=np.float64)
    best = np.nanmin(b)
    return int(ks[b == best].min())


@dataclass(frozen=True)
class KSelection(JsonRecord):
    """Scores per candidate K (lists aligned with ``candidates``) and the choices.

    heldout_psnr dB; train_mse on [0, 1] images; bic dimensionless; frozen parts per run;
    wall_s seconds of training per candidate; chosen_k is k_heldout or k_bic per ``method``.
    """

    RECORD_NAME = "K selection"

    candidates: list
    method: str
    every: int
    iterations: int
    heldout_psnr: list
    train_mse: list
    n_pixels: int
    bic: list
    frozen: list
    wall_s: list
    k_heldout: int
    k_bic: int
    chosen_k: int


def save_selection(path, sel: KSelection) -> None:
    """Write the K selection to ``path`` as JSON, atomically.

    Args:
        path (str | os.PathLike): the ``.json`` file to write.
        sel: the selection.
    """
    sel.save(path)


def load_selection(path) -> KSelection:
    """Read the K selection that [save_selection][physgs.experiments.kselect.save_selection] wrote.

    Args:
        path (str | os.PathLike): the ``.json`` file.

    Returns:
        The selection.

    Raises:
        IntermediateFileError: the file is missing or not a K selection (it is removed, so rule
            ``kselect`` rebuilds it).
    """
    return KSelection.load(path, rule="kselect")


def _check_cfg(ks: dict, n_gaussians: int, where: str = "models/kselect") -> list[int]:
    cands = sorted({int(k) for k in ks["candidates"]})
    if not cands or cands[0] < 1:
        raise ValueError(f"{where}/candidates must be positive integers, got {ks['candidates']}")
    if cands[-1] > n_gaussians:
        raise ValueError(
            f"{where}/candidates: K = {cands[-1]} exceeds the {n_gaussians} "
            "Gaussians of this tree; drop it from the candidates"
        )
    if ks["method"] not in METHODS:
        raise ValueError(f"models/kselect/method must be one of {METHODS}, got {ks['method']!r}")
    return cands


def select_k(observed, job: Job | dict, kselect: dict, *, progress: bool = False) -> KSelection:
    """Train a prior once per candidate K on the non-held-out frames and score both criteria.

    Each candidate is trained by [`fit`][physgs.experiments.recipe.fit] (freezing and the search
    over omega included) with the shorter schedule. Deterministic for the job's seed.

    Args:
        observed (Observed): the dataset.
        job: the prior's training job ([`job_spec`][physgs.experiments.recipe.job_spec]: model,
            settings, train, seed; its K and configuration are replaced per candidate).
        kselect: its K-selection settings ([`settings_for`][physgs.experiments.kselect.settings_for]).
        progress: show progress bars.

    Returns:
        The [`KSelection`][physgs.experiments.kselect.KSelection]: every candidate's scores and
            the K each criterion chooses.

    Raises:
        ValueError: for candidates above the Gaussian count or an unknown method, or when every
            held-out PSNR is non-finite.
    """
    from physgs.evaluate.run import training_camera_scores  # torch: only when training

    job = Job.from_dict(job) if isinstance(job, dict) else job
    ks = kselect
    cands = _check_cfg(ks, int(np.asarray(observed.canonical_xyz).shape[0]), section_key(job.model))
    train_idx, held = heldout_split(int(observed.n_train), int(ks["every"]))
    tcfg = dict(job.train, iterations=int(ks["iterations"]), warmup=int(ks["warmup"]))
    scored_train = train_idx[:: max(1, train_idx.size // held.size)][: held.size]
    backend = tcfg.get("backend", "auto")
    rows = {k: [] for k in ("heldout_psnr", "train_mse", "bic", "frozen", "wall_s")}
    n_pix = int(scored_train.size * np.prod(np.asarray(observed.frames).shape[2:]))
    for K in cands:
        t0 = time.perf_counter()
        cand = job.replace(K=int(K), config=AUTO_CONFIG, conditions="train", train=tcfg)
        res = fit(observed, cand, frame_pool=train_idx, progress=progress, name=f"{job.model}_K{K}")
        _, p_held = training_camera_scores(res.model, observed, held, backend=backend)
        mse_tr, _ = training_camera_scores(res.model, observed, scored_train, backend=backend)
        rows["heldout_psnr"].append(float(np.mean(p_held)))
        rows["train_mse"].append(float(np.mean(mse_tr)))
        rows["bic"].append(bic(float(np.mean(mse_tr)), n_pix, K))
        rows["frozen"].append(int(res.model.frozen.sum()))
        rows["wall_s"].append(time.perf_counter() - t0)
    k_h = choose_heldout(cands, rows["heldout_psnr"], float(ks["tie_db"]))
    k_b = choose_bic(cands, rows["bic"])
    return KSelection(
        candidates=cands,
        method=ks["method"],
        every=int(ks["every"]),
        iterations=int(ks["iterations"]),
        n_pixels=n_pix,
        k_heldout=k_h,
        k_bic=k_b,
        chosen_k=k_h if ks["method"] == "heldout" else k_b,
        **rows,
    )


def auto_job(job: Job | dict, sel: KSelection, conditions: str) -> dict:
    """A prior's training job with the chosen K (configuration 'auto'), as ``recipe.job_spec``.

    Args:
        job: the prior's training job.
        sel: the selection.
        conditions: the configuration's conditions (``'train'`` or ``'all'``).

    Returns:
        The job's dict with K, configuration and conditions replaced.
    """
    job = Job.from_dict(job) if isinstance(job, dict) else job
    return job.replace(K=int(sel.chosen_k), config=AUTO_CONFIG, conditions=conditions).to_dict()
