"""The stopping rule: a training ends when its held-out window frames stop improving.

Every ``train.stopping.every`` iterations the loop scores the frames the training window holds
out (``train.holdout_every``; [`physgs.train.holdout`][]). Once the model's recipe has run its
course (the warm-up, the search over omega, freezing: ``earliest``), the rule counts the
evaluations since the held-out loss last fell below ``(1 - tol)`` times its best; after
``patience`` such evaluations it triggers, the learning-rate schedule runs its final anneal of
``anneal`` iterations ([`physgs.train.schedule`][]) and the training ends, a finished schedule.
A rule that never triggers leaves the training at ``train.iterations`` with today's schedule
(the anneal then starts at ``iterations - anneal`` and is the schedule's own tail).
"""

from __future__ import annotations

from dataclasses import dataclass, field

#: Why a training ended, as the checkpoint's statistics and the training log record it.
STOP_CAP = "cap"  # train.iterations reached (the rule off, or never triggered)
STOP_PLATEAU = "plateau"  # the held-out window frames stopped improving


@dataclass(frozen=True)
class StopRule:
    """The settings of ``train.stopping``.

    enabled: off = train ``train.iterations`` (the held-out frames are still scored and logged
    when ``every`` > 0); every: evaluation period N, iterations; patience: P, evaluations without
    an improvement; tol: the relative improvement that counts (a fraction of the best loss);
    anneal: iterations of the final decay after the trigger; start: the fraction of the budget
    before which nothing is scored (no trigger came earlier on any curve it was chosen on).
    """

    enabled: bool
    every: int
    patience: int
    tol: float
    anneal: int
    start: float = 0.0

    @staticmethod
    def from_config(train_cfg: dict) -> "StopRule":
        """The rule of a ``train`` section (a section without ``stopping``: off, unlogged).

        Args:
            train_cfg: the ``train`` config section.

        Returns:
            The rule.
        """
        s = train_cfg.get("stopping") or {}
        return StopRule(
            enabled=bool(s.get("enabled", False)),
            every=int(s.get("every", 0)),
            patience=int(s.get("patience", 1)),
            tol=float(s.get("tol", 0.0)),
            anneal=int(s.get("anneal", 0)),
            start=float(s.get("start", 0.0)),
        )

    def scores_at(self, it: int, iterations: int, earliest: int) -> bool:
        """Whether iteration ``it`` of a ``iterations`` budget scores the held-out frames: every
        ``every``-th from ``max(earliest, start x iterations)``, and, with the rule enabled,
        only while a trigger could still stop the run early (``it + anneal < iterations``).

        Args:
            it: the iteration.
            iterations: the budget (the cap).
            earliest: the recipe's last change to the model (the first iteration that counts).

        Returns:
            True when the loop scores before iteration ``it``.
        """
        if self.every <= 0 or it % self.every or it < max(earliest, self.start * iterations):
            return False
        return not self.enabled or it + self.anneal < iterations

    def check(self) -> None:
        """Raise ValueError when the rule cannot run (a rule whose anneal does not fit in the
        budget can: it never stops a training early).

        Raises:
            ValueError: naming the key and the fix.
        """
        if self.enabled and self.every <= 0:
            raise ValueError("train.stopping.every must be > 0 when train.stopping.enabled")
        if self.enabled and self.anneal < 1:
            raise ValueError(f"train.stopping.anneal must be >= 1, got {self.anneal}")
        if not 0.0 <= self.start < 1.0:
            raise ValueError(f"train.stopping.start must lie in [0, 1), got {self.start}")


@dataclass
class Plateau:
    """The plateau detector: fed the held-out loss at each evaluation, says when to stop.

    Evaluations before ``earliest`` (an iteration) are not counted: the recipe still changes
    the model there.
    """

    patience: int
    tol: float
    earliest: int = 0
    best: float = float("inf")
    since: int = 0  # evaluations since the last improvement
    history: list = field(default_factory=list)  # (iteration, loss)

    def update(self, it: int, loss: float) -> bool:
        """Record the held-out loss at iteration ``it``; True when the rule triggers.

        An evaluation improves when ``loss < (1 - tol) * best``; the rule triggers after
        ``patience`` evaluations in a row that do not.

        Args:
            it: the iteration evaluated.
            loss: the held-out window frames' mean loss.

        Returns:
            Whether the rule triggers now.
        """
        self.history.append((int(it), float(loss)))
        if it < self.earliest:
            return False
        if loss < (1.0 - self.tol) * self.best:
            self.best, self.since = float(loss), 0
            return False
        self.since += 1
        return self.since >= self.patience


def plateau_iteration(
    iterations, losses, patience: int, tol: float, earliest: int = 0
) -> int | None:
    """The iteration at which the rule triggers on a recorded curve, or None if it never does.

    Args:
        iterations (Sequence[int]): evaluated iterations, ascending.
        losses (Sequence[float]): the held-out loss at each.
        patience: P.
        tol: the relative improvement that counts.
        earliest: evaluations before this iteration are not counted.

    Returns:
        The trigger iteration, or None.
    """
    p = Plateau(patience=patience, tol=tol, earliest=earliest)
    for it, v in zip(iterations, losses):
        if p.update(int(it), float(v)):
            return int(it)
    return None
