"""How few parts the chained prior needs: the smallest K at which it matches the paper's prior.

"Model only what a scene requires": the chained prior (``ours_chain``) is trained at each smaller K
of ``parts_study.k_candidates`` by the one recipe ([`physgs.experiments.recipe.fit`][], the
profile's budget, the training frames minus every ``train.holdout_every``-th, as every training job
of the pipeline), and scored on the held-out training-window frames at the training camera and wind.
The smallest K whose held-out PSNR lies within ``models.kselect.tie_db`` of the k-means prior's at
the base configuration's K (``ours`` single, the pipeline's own job, same frames held out) is the
match; at the base K itself the chained prior is the pipeline's own ``ours_chain`` single job. Never
reads the view, time or transfer splits.
"""

from __future__ import annotations

import time
from typing import Mapping

import numpy as np

from physgs.experiments.recipe import Job, fit, heldout_split


def point_job(job: Mapping, K: int) -> dict:
    """The chained prior's training job (``recipe.job_spec`` of ``ours_chain`` single) at K parts.

    Args:
        job: the job's dict.
        K: number of parts.

    Returns:
        The job's dict with ``K`` replaced.
    """
    return Job.from_dict(dict(job)).replace(K=int(K)).to_dict()


def kmatch_point(observed, job: Mapping, *, progress: bool = False) -> dict:
    """Train ``job`` ([`point_job`][physgs.experiments.kmatch.point_job]) on the training frames
    minus every holdout_every-th and score it.

    Args:
        observed (Observed): the dataset.
        job: the job's dict.
        progress: show a progress bar.

    Returns:
        ``model``, ``K``, ``heldout_psnr`` (dB, mean over the held-out frames), ``fit_psnr`` (dB,
            mean over the trained frames), ``frozen`` (parts), ``train_s`` (seconds).
    """
    from physgs.evaluate.run import training_camera_scores  # torch: only when training

    j = Job.from_dict(dict(job))
    every = int(j.train["holdout_every"])
    trained, held = heldout_split(int(observed.n_train), every)
    t0 = time.perf_counter()
    res = fit(observed, j, frame_pool=trained, progress=progress, name=f"{j.model}_K{j.K}")
    secs = time.perf_counter() - t0
    backend = j.train.get("backend", "auto")
    _, p_held = training_camera_scores(res.model, observed, held, backend=backend)
    _, p_fit = training_camera_scores(res.model, observed, trained, backend=backend)
    return {
        "model": j.model,
        "K": int(j.K),
        "heldout_psnr": float(np.mean(p_held)),
        "fit_psnr": float(np.mean(p_fit)),
        "frozen": int(res.model.frozen.sum()),
        "train_s": float(secs),
    }


def matched_k(heldout_by_k: Mapping[int, float], base_heldout: float, tie_db: float) -> int | None:
    """Smallest K whose held-out PSNR (dB) is at least ``base_heldout - tie_db``; None when none
    is (the chained prior does not match at any K tried).

    Args:
        heldout_by_k: K -> held-out PSNR, dB (NaN values never match).
        base_heldout: the reference's held-out PSNR, dB.
        tie_db: the tolerance, dB.

    Returns:
        The K, or None.
    """
    ok = [int(k) for k, p in heldout_by_k.items() if np.isfinite(p) and p >= base_heldout - tie_db]
    return min(ok) if ok else None
