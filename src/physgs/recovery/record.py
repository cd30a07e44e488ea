"""Score one trained model's recovery against the truth file, and store results as JSON."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from physgs.atomic import write_json
from physgs.intermediate import read_json
from physgs.recovery.damping import DampingResult, damping_summary
from physgs.recovery.damping_scores import DampingNull, DampingScores, damping_null, score_match
from physgs.recovery.matcher import MatchResult, match_parts, restricted, training_window
from physgs.recovery.null import N_DRAWS, NullResult, null_control


@dataclass(frozen=True)
class RecoveryRecord:
    """Frequency match and damping summary of one (tree, config) model.

    n_frozen: parts frozen as invisible (physgs.models.visibility); their theta is 0, so the
    matcher leaves them untrusted. n_trusted_visible / median_rel_err_visible: the same scores
    restricted to parts matched to bones whose own motion is visible (>= 1 px in the training
    camera; -1 / NaN when no visibility was given).
    """

    match: MatchResult
    damping: DampingResult
    n_frozen: int = 0
    n_trusted_visible: int = -1
    median_rel_err_visible: float = float("nan")
    #: per-part damping against the per-bone truth and its untrained null (tab_damping); None
    #: when the recovery was not asked for them
    damping_scores: DampingScores | None = None
    damping_null: DampingNull | None = None
    #: a method's own uncertainty of its estimates (the output-only analysis': each part's
    #: standard deviations, its 95% intervals' coverage, the parts its sigma rule keeps:
    #: ``physgs.oma.run.interval_block``); None for a method without one
    intervals: dict | None = None

    def with_visibility(self, bone_visible: np.ndarray) -> "RecoveryRecord":
        """This record with the scores restricted to visible bones (``bone_visible`` [B] bool).

        Args:
            bone_visible: [B] bool, True for a visible bone.

        Returns:
            A copy with ``n_trusted_visible`` and ``median_rel_err_visible`` set.
        """
        n, med = restricted(self.match, bone_visible)
        return dataclasses.replace(self, n_trusted_visible=n, median_rel_err_visible=med)


def bone_window(truth, lead_in_frames: int, n_train: int) -> np.ndarray:
    """[B, n_train] ground-truth bone angles (rad) over the training window at the training wind.

    Args:
        truth (Truth): the dataset's ground truth.
        lead_in_frames: lead-in frames L.
        n_train: training-window length, frames.

    Returns:
        [B, n_train] angles, rad.
    """
    theta = np.asarray(truth.theta)[0]  # [L+F, B]
    return training_window(theta.T, lead_in_frames, n_train)


def score_recovery(
    part_theta: np.ndarray,
    omega_hat: np.ndarray,
    zeta_hat: np.ndarray,
    truth,
    lead_in_frames: int,
    n_train: int,
) -> RecoveryRecord:
    """Match parts to bones and summarise damping.

    Damping is summarised over all parts (the paper's median zeta_hat is over all parts).

    Args:
        part_theta: [K, L+F] the model's part angles (rad) under the training wind, lead-in first
            (``model.part_theta(wind)``).
        omega_hat: [K] estimated natural frequencies, rad/s.
        zeta_hat: [K] estimated damping ratios.
        truth (Truth): the dataset's ground truth.
        lead_in_frames: lead-in frames L.
        n_train: training-window length, frames.

    Returns:
        The [`RecoveryRecord`][physgs.recovery.record.RecoveryRecord]: the match over the training
            window and the damping summary.
    """
    part = training_window(part_theta, lead_in_frames, n_train)
    m = match_parts(part, bone_window(truth, lead_in_frames, n_train), omega_hat, truth.omega)
    zeta_true = float(np.median(truth.zeta))
    return RecoveryRecord(m, damping_summary(omega_hat, zeta_hat, zeta_true))


def with_damping_scores(rec: RecoveryRecord, zeta_hat, truth, damping: dict) -> RecoveryRecord:
    """``rec`` with each trusted part's zeta scored against its bone's true zeta and against
    the untrained null drawn log-uniformly from ``damping['zeta_range']`` with seed
    ``damping['seed']`` ([`physgs.recovery.damping_scores`][physgs.recovery.damping_scores];
    tab_damping).

    Args:
        rec: the record (its match is used).
        zeta_hat (ArrayLike): [K] estimated damping ratios.
        truth (Truth): the dataset's ground truth (``zeta``, ``omega``).
        damping: ``zeta_range`` and ``seed`` of the null.

    Returns:
        A copy with ``damping_scores`` and ``damping_null`` set.
    """
    zb, ob = np.asarray(truth.zeta, np.float64), np.asarray(truth.omega, np.float64)
    m = rec.match
    return dataclasses.replace(
        rec,
        damping_scores=score_match(m, np.asarray(zeta_hat, np.float64), zb, ob),
        damping_null=damping_null(
            m.bone, m.trusted, m.omega_hat, zb, ob, damping["zeta_range"], seed=int(damping["seed"])
        ),
    )


def recovery_dict(rec: RecoveryRecord) -> dict:
    """The JSON object ``save_recovery`` writes (``load_recovery`` ignores any other key, so a
    method may add its own block beside these).

    Args:
        rec: the record.

    Returns:
        ``match``, ``damping``, ``n_frozen``, ``n_trusted_visible``, ``median_rel_err_visible``,
            ``damping_scores`` and ``damping_null`` (None where not scored), ``intervals`` (None
            for a method without its own uncertainty).
    """
    return {
        "match": rec.match.to_dict(),
        "damping": rec.damping.to_dict(),
        "n_frozen": int(rec.n_frozen),
        "n_trusted_visible": int(rec.n_trusted_visible),
        "median_rel_err_visible": rec.median_rel_err_visible,
        "damping_scores": (
            rec.damping_scores.to_dict() if rec.damping_scores is not None else None
        ),
        "damping_null": (rec.damping_null.to_dict() if rec.damping_null is not None else None),
        "intervals": rec.intervals,
    }


def save_recovery(path, rec: RecoveryRecord) -> None:
    """Write the recovery record to ``path`` as JSON, atomically.

    Args:
        path (str | os.PathLike): the ``.json`` file to write.
        rec: the record.
    """
    write_json(path, recovery_dict(rec))


def load_recovery(path) -> RecoveryRecord:
    """Read the recovery record that [save_recovery][physgs.recovery.record.save_recovery] wrote.

    Keys a record from before freezing, visibility or the damping scores lacks take their
    defaults (none frozen, -1 / NaN, None).

    Args:
        path (str | os.PathLike): the ``.json`` file.

    Returns:
        The record.

    Raises:
        IntermediateFileError: the file is missing or unreadable (it names the rule to rerun).
    """
    d = read_json(path, rule="recovery (tracks_evaluate for the tracks control's)")
    return RecoveryRecord(
        MatchResult.from_dict(d["match"]),
        DampingResult.from_dict(d["damping"]),
        int(d.get("n_frozen", 0)),  # records from before freezing: none frozen
        int(d.get("n_trusted_visible", -1)),
        float(d.get("median_rel_err_visible", float("nan"))),
        DampingScores.from_dict(d["damping_scores"]) if d.get("damping_scores") else None,
        DampingNull.from_dict(d["damping_null"]) if d.get("damping_null") else None,
        d.get("intervals"),
    )


def save_null(path, res: NullResult) -> None:
    """Write the null control's result to ``path`` as JSON, atomically.

    Args:
        path (str | os.PathLike): the ``.json`` file to write.
        res: the result.
    """
    res.save(path)


def load_null(path) -> NullResult:
    """Read the null control's result that [save_null][physgs.recovery.record.save_null] wrote.

    Args:
        path (str | os.PathLike): the ``.json`` file.

    Returns:
        The result.

    Raises:
        IntermediateFileError: the file is missing or unreadable (rule ``null_control``).
    """
    return NullResult.load(path, rule="null_control")


def run_null(
    truth,
    observed,
    *,
    n_parts: int,
    zeta_init: float,
    substeps: int,
    seed: int,
    n_draws: int | None = None,
    bone_visible: np.ndarray | None = None,
) -> NullResult:
    """The null control for one tree and one K, wired exactly like the trained model.

    Uses the training condition's observed wind (lead-in first), dt = 1 / fps, and the
    condition's mean speed ``observed.vbar[0]``, as the oscillator prior does; bones over the
    training window at the training wind.

    Args:
        truth (Truth): the dataset's ground truth.
        observed (Observed): the dataset.
        n_parts: K, parts per draw.
        zeta_init: the model's initial damping ratio (config value).
        substeps: RK4 substeps per wind sample (the model's).
        seed: the null's seed.
        n_draws: draws (default ``N_DRAWS``).
        bone_visible: [B] bool; also score the draws on visible bones.

    Returns:
        The [`NullResult`][physgs.recovery.null.NullResult].
    """
    wind = np.asarray(observed.wind[0], dtype=np.float64)  # [L+F]
    L, n_train = int(observed.lead_in_frames), int(observed.n_train)
    return null_control(
        truth.omega,
        bone_window(truth, L, n_train),
        wind,
        n_parts=n_parts,
        zeta_init=zeta_init,
        vbar=float(np.asarray(observed.vbar)[0]),
        dt=1.0 / observed.fps,
        substeps=substeps,
        lead_in_frames=L,
        n_train=n_train,
        seed=seed,
        n_draws=N_DRAWS if n_draws is None else n_draws,
        bone_visible=bone_visible,
    )
