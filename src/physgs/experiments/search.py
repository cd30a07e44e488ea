"""Recipe search: a model's learning rates, size and time encoding chosen per tree on the frames
its training window holds out, as its authors would tune it (issue "Opponents that fit").

Optuna's TPE sampler (a fixed seed) proposes a recipe, the recipe's training reports its held-out
window loss every ``every`` iterations and a median pruner stops a trial that falls behind the
trials before it at the same iteration. The objective is the held-out window loss (L1 + D-SSIM,
the training loss) at the end of the trial's training: never the held-out views, the tail beyond
the window, another wind or the true physics, which are the test. Every trial trains from the
same seed, so two trials differ by their settings only.

The space per model family (``SPACES``) is what the family's authors would tune: a field's
deformation learning rate, width, depth and top time band; a prior's physics and pivot learning
rates. A trial's recipe has the shape of ``recipes.<tree>.<model>``
in the config (``{"train": {...}, "settings": {...}}``), so the best one is pasted there.
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from physgs.experiments.recipe import Job, fit, window_scorer
from physgs.mappings import deep_merge
from physgs.models.registry import spec_of
from physgs.models.timescale import WINDOW_TIME

#: the columns of a search's steps file: every held-out score a trial reported
STEP_FIELDS = ("trial", "iteration", "holdout_loss", "holdout_psnr")


@dataclass(frozen=True)
class FieldSpace:
    """A learned field's space: its deformation learning rate, width, depth and top time band.

    Attributes:
        family: the field's settings section (``mlp``, ``d3dgs``).
        depths: the depths tried.
    """

    family: str
    depths: tuple[int, ...]

    def suggest(self, trial, model: str) -> dict:
        """The trial's recipe.

        Args:
            trial (optuna.trial.Trial): the trial that draws the parameters.
            model: the model's id.

        Returns:
            ``{"train": {...}, "settings": {...}}`` (``recipes.<tree>.<model>``'s shape).
        """
        top = trial.suggest_categorical("time_top_hz", list(TIME_TOPS))
        return {
            "train": {"lr": {"deform": trial.suggest_float("lr_deform", 2e-4, 4e-3, log=True)}},
            "settings": {
                self.family: {
                    "width": trial.suggest_categorical("width", [64, 128, 256]),
                    "depth": trial.suggest_categorical("depth", list(self.depths)),
                    "time_top_hz": {model: top if top == WINDOW_TIME else float(top)},
                }
            },
        }

    def params(self, job: Job) -> dict:
        """The parameters of ``job``'s own recipe (the search's first trial).

        Args:
            job: the model's job on the tree.

        Returns:
            Parameter name -> value, as ``suggest`` draws them.
        """
        s = job.settings[self.family]
        top = s["time_top_hz"][job.model]
        return {
            "time_top_hz": top if top == WINDOW_TIME else f"{float(top):g}",
            "lr_deform": float(job.train["lr"]["deform"]),
            "width": int(s["width"]),
            "depth": int(s["depth"]),
        }


class PriorSpace:
    """A physical prior's space: its physics and pivot learning rates (freezing stays the
    config's: where it acts is tied to the schedule, so a trial turning it on could clash with
    the search over omega, config_checks)."""

    def suggest(self, trial, model: str) -> dict:
        """The trial's recipe.

        Args:
            trial (optuna.trial.Trial): the trial that draws the parameters.
            model: the model's id.

        Returns:
            ``{"train": {...}, "settings": {...}}`` (``recipes.<tree>.<model>``'s shape).
        """
        return {
            "train": {
                "lr": {
                    "physics": trial.suggest_float("lr_physics", 1e-2, 2e-1, log=True),
                    "pivot": trial.suggest_float("lr_pivot", 5e-5, 5e-4, log=True),
                }
            }
        }

    def params(self, job: Job) -> dict:
        """The parameters of ``job``'s own recipe (the search's first trial).

        Args:
            job: the model's job on the tree.

        Returns:
            Parameter name -> value, as ``suggest`` draws them.
        """
        return {
            "lr_physics": float(job.train["lr"]["physics"]),
            "lr_pivot": float(job.train["lr"]["pivot"]),
        }


#: a field's top time bands tried (Hz, or the window-normalised time): the grid the defaults
#: were chosen from (docs/models.md, Time encoding); strings, so Optuna stores one type
TIME_TOPS = (WINDOW_TIME, "0.75", "1.5", "3")

#: model family -> its space (Deformable-3DGS keeps its skip connection at layer 4, so its depth
#: stays above it)
SPACES = {
    "mlp": FieldSpace("mlp", (2, 4, 6)),
    "d3dgs": FieldSpace("d3dgs", (6, 8)),
    "ours": PriorSpace(),
}


@dataclass(frozen=True)
class SearchSettings:
    """One search's budget.

    Attributes:
        trials: trials run (pruned ones included).
        every: iterations between a trial's held-out scores (what the pruner reads).
        startup: trials never pruned (the median needs them) and sampled at random before TPE.
        seed: the sampler's seed (the trainings use the job's seed).
        prune_after: the fraction of a trial's budget before which it is never pruned (early
            scores rank recipes by how fast they start, not where they end).
    """

    trials: int
    every: int
    startup: int
    seed: int
    prune_after: float = 0.0

    @staticmethod
    def from_config(search: dict) -> "SearchSettings":
        """The settings of the config's ``search`` section.

        Args:
            search: ``{trials, every, startup, seed, ...}``.

        Returns:
            The settings.
        """
        return SearchSettings(
            *(int(search[k]) for k in ("trials", "every", "startup", "seed")),
            prune_after=float(search.get("prune_after", 0.0)),
        )


def space_of(model: str) -> FieldSpace | PriorSpace:
    """The search space of ``model``'s family.

    Args:
        model: a registry id.

    Returns:
        Its space.

    Raises:
        ValueError: a model whose family has no space (the static pose, the references).
    """
    family = spec_of(model).family
    if family not in SPACES:
        raise ValueError(
            f"{model!r} ({family}) has no recipe to search; searched: {sorted(SPACES)}"
        )
    return SPACES[family]


def trial_job(base: dict, recipe: dict) -> Job:
    """The job ``base`` with a trial's ``recipe`` merged over it.

    Args:
        base: the model's single-configuration job on the tree
            ([`job_spec`][physgs.experiments.recipe.job_spec] with its tree: the tree's recipe,
            ``recipes``, is the base).
        recipe: ``{"train": {...}, "settings": {...}}``, partial sections.

    Returns:
        The job.
    """
    return Job.from_dict(
        dict(
            base,
            train=deep_merge(base["train"], recipe.get("train", {})),
            settings=deep_merge(base["settings"], recipe.get("settings", {})),
        )
    )


def run_search(
    observed,
    base: dict,
    settings: SearchSettings,
    *,
    tree: str = "",
    log: Callable[[str], None] = print,
    journal: str | Path | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    """Search a model's recipe on a tree's held-out window frames.

    With ``journal``, the study lives in that Optuna journal file as it runs, so a search cut
    short (a session's or a cluster job's end) resumes where it stopped: its finished trials are
    kept, not trained again; the trial it was training is kept as ``FAIL`` (no value) and its
    recipe trained again as a new trial; the sampler is seeded with ``seed`` plus the trials
    already held, so a resumed search proposes its later trials as a search run in one go would
    not. A search cut short before its first trial (the config's own recipe) ended starts afresh.
    The file is removed once the search has finished. Its study is named by the job and budget, so
    a job whose settings changed since starts its own study.

    Args:
        observed (Observed): the tree's observed dataset (the training camera's video).
        base: the model's single-configuration job on the tree (``job_spec`` with its tree), a
            registry id with a space (``SPACES``): every trial is this job with its recipe over it.
        settings: the budget.
        tree: the tree's name (the rows' and the log lines' label).
        log: where the progress goes: a line per held-out score and per trial.
        journal: the journal file that makes the search resumable; None: in memory only.

    Returns:
        ``(trials, steps, best)``: one row per trial (number, state, the objective, held-out
        PSNR, the parameters, wall and CPU seconds; trial 0 is the config's own recipe), every
        reported score (``STEP_FIELDS``), and the best complete trial's recipe.

    Raises:
        ValueError: no space for the model, or no trial completed.
    """
    import optuna

    model = base["model"]
    space = space_of(model)
    own = space.params(trial_job(base, {}))

    def objective(trial) -> float:
        job = trial_job(base, space.suggest(trial, model))
        scorer = window_scorer(observed, job)
        warmup = int(job.train["warmup"])
        steps: list[list] = []  # [iteration, loss, psnr], kept in the study as they come

        def score(it, mdl) -> float:
            loss, psnr = scorer.evaluate(mdl)
            steps.append([it, loss, psnr])
            trial.set_user_attr("steps", steps)
            return loss

        def report(it, mdl, opt):
            if it <= warmup or it % settings.every:
                return None
            loss = score(it, mdl)
            # a trial runs minutes to an hour: each held-out score is the search's progress
            log(f"{tree} {model}: trial {trial.number}, iteration {it}: {steps[-1][2]:.2f} dB")
            trial.report(loss, it)
            if trial.should_prune():
                raise optuna.TrialPruned(f"held-out window loss {loss:.4f} at iteration {it}")
            return None

        cpu0 = time.process_time()
        try:
            res = fit(observed, job, progress=False, hooks=(report,))
            loss = score(len(res.log), res.model)
        finally:
            # the process's CPU time: a trial's cost even where a busy neighbour stretched its
            # wall time (the trial's duration)
            trial.set_user_attr("cpu_seconds", time.process_time() - cpu0)
        trial.set_user_attr("holdout_psnr", steps[-1][2])
        return loss

    finished = (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)

    def progress(study, trial) -> None:
        value = "pruned" if trial.value is None else f"{trial.value:.4f}"
        n = sum(t.state in finished for t in study.trials)
        # what is left at this run's pace so far (pruned trials end early: a rough guide)
        pace = (time.perf_counter() - t0) / max(n - n0, 1)
        eta = f"about {pace * (settings.trials - n) / 60:.0f} min left"
        log(f"{tree} {model}: trial {n}/{settings.trials} {value} {trial.params} ({eta})")

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = _study(base, settings, journal, log=log, label=f"{tree} {model}")
    if not study.trials:
        # the first trial is the recipe the config holds: the search is measured against it
        study.enqueue_trial(own)
    t0 = time.perf_counter()
    n0 = sum(t.state in finished for t in study.trials)  # held from an earlier run: not timed
    left = settings.trials - n0
    study.optimize(objective, n_trials=max(left, 0), callbacks=[progress])
    done = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    if not done:
        raise ValueError(f"{tree} {model}: no trial of {settings.trials} completed")
    trials = study.trials_dataframe(attrs=("number", "state", "value", "params", "duration"))
    trials = trials.rename(columns={"value": "holdout_loss"})
    trials["holdout_psnr"] = [t.user_attrs.get("holdout_psnr") for t in study.trials]
    trials.insert(0, "model", model)
    trials.insert(0, "tree", tree)
    # an interrupted trial's duration would span the pause: not its cost
    seconds = trials.pop("duration").dt.total_seconds()
    trials["seconds"] = seconds.where(trials["state"] != "FAIL")
    cpu = pd.Series([t.user_attrs.get("cpu_seconds") for t in study.trials], dtype=float)
    trials["cpu_seconds"] = cpu.where(trials["state"] != "FAIL")
    steps = pd.DataFrame(
        [[t.number, *row] for t in study.trials for row in t.user_attrs.get("steps", [])],
        columns=list(STEP_FIELDS),
    )
    log(
        f"{tree} {model}: {len(done)} of {settings.trials} trials complete, {time.perf_counter() - t0:.0f} s"
    )
    best = space.suggest(optuna.trial.FixedTrial(study.best_trial.params), model)
    if journal is not None:
        Path(journal).unlink(missing_ok=True)
    return trials, steps, best


def _study(base: dict, settings: SearchSettings, journal, *, log, label: str):
    """The search's Optuna study: new, or resumed from ``journal`` (``run_search``).

    Args:
        base: the model's job on the tree (names the study, with ``settings``).
        settings: the budget.
        journal: the journal file, or None (in memory).
        log: where the line saying what was resumed goes.
        label: the search's name in that line.

    Returns:
        The study, its interrupted trial (``RUNNING`` if killed, ``FAIL`` if stopped by Ctrl-C)
        marked ``FAIL`` and its recipe queued again.
    """
    import optuna

    running, failed = optuna.trial.TrialState.RUNNING, optuna.trial.TrialState.FAIL
    storage, name, held = None, None, 0
    if journal is not None:
        from optuna.storages.journal import JournalFileBackend

        storage = optuna.storages.JournalStorage(JournalFileBackend(str(journal)))
        key = json.dumps([base, asdict(settings)], sort_keys=True, default=str)
        name = f"{label}/{hashlib.sha256(key.encode()).hexdigest()[:12]}"
        try:
            kept = optuna.load_study(study_name=name, storage=storage).trials
        except KeyError:  # no such study yet
            kept = []
        if kept and kept[0].state in (running, failed):
            # cut short before the config's own recipe (its first trial) ended: nothing to keep
            optuna.delete_study(study_name=name, storage=storage)
            kept = []
        held = len(kept)
    study = optuna.create_study(
        study_name=name,
        storage=storage,
        load_if_exists=True,
        direction="minimize",
        sampler=optuna.samplers.TPESampler(
            seed=settings.seed + held, n_startup_trials=settings.startup
        ),
        pruner=optuna.pruners.MedianPruner(
            n_startup_trials=settings.startup,
            n_warmup_steps=int(settings.prune_after * int(base["train"]["iterations"])),
        ),
    )
    # a trial killed stays RUNNING, one stopped by Ctrl-C is FAIL: either way it trains again
    retried = {t.user_attrs.get("retry_of") for t in study.trials}
    for t in study.trials:
        if t.state in (running, failed) and t.number not in retried:
            if t.state == running:
                study.tell(t.number, state=failed)
            study.enqueue_trial(t.params, user_attrs={"retry_of": t.number})
            log(f"{label}: trial {t.number} was cut short: kept as FAIL, its recipe queued again")
    if held:
        done = sum(
            t.state in (optuna.trial.TrialState.COMPLETE, optuna.trial.TrialState.PRUNED)
            for t in study.trials
        )
        log(f"{label}: resumed from {journal}: {done} of {settings.trials} trials finished")
    return study


#: the columns of a search summary (``summary``), one row per tree and model
SUMMARY_FIELDS = (
    "tree",
    "model",
    "trials",
    "complete",
    "cut",
    "own_psnr",
    "best_psnr",
    "best_trial",
    "gain_db",
    "recipe",
)


def summary(trials: pd.DataFrame, adopt_above_db: float) -> pd.DataFrame:
    """What each search found: its config's own recipe against its best, and which one stays.

    Args:
        trials: ``run_search``'s trials of one or more searches (``tree``, ``model`` columns;
            trial 0 of each is the config's own recipe).
        adopt_above_db: the gain on the held-out window frames (dB) a best trial must exceed to
            replace the config's recipe (``search.adopt_above_db``).

    Returns:
        One row per (tree, model) in ``trials``' order (``SUMMARY_FIELDS``): the trials scored
        (the budget's: complete or pruned) and complete, those cut short (``FAIL``: a search
        resumed trains their recipes again, as later trials), the own and the best complete
        trial's held-out PSNR (dB), the best trial's number, the gain (dB), and ``recipe``:
        ``"searched"`` where the gain exceeds ``adopt_above_db``, else ``"config's"``.
    """
    rows = []
    for (tree, model), t in trials.groupby(["tree", "model"], sort=False):
        own, best, done = _own_and_best(t)
        gain = float(best["holdout_psnr"]) - own
        rows.append(
            dict(
                tree=tree, model=model, trials=_scored(t), complete=len(done),
                cut=len(t) - _scored(t), own_psnr=own,
                best_psnr=float(best["holdout_psnr"]), best_trial=int(best["number"]),
                gain_db=gain, recipe="searched" if gain > adopt_above_db else "config's",
            )
        )  # fmt: skip
    return pd.DataFrame(rows, columns=list(SUMMARY_FIELDS))


#: the columns of ``trade``: a search's complete trials that no cheaper trial scores above
TRADE_FIELDS = (
    "tree", "model", "number", "clock", "seconds", "holdout_psnr", "cost_x", "delta_db", "own",
)  # fmt: skip


def trade(trials: pd.DataFrame) -> pd.DataFrame:
    """Each search's cost-accuracy front: the complete trials no cheaper one scores above.

    A search ranks recipes by their held-out window loss alone; this is what each costs: a
    trial's CPU seconds (``cpu_seconds``) where its search recorded them for every trial, else
    its wall time (``seconds``), which a busy neighbour stretches. Either compares within a
    search (one machine), not across machines.

    Args:
        trials: ``run_search``'s trials of one or more searches (trial 0: the config's recipe).

    Returns:
        One row per trial on a front (``TRADE_FIELDS``), cheapest first within each search:
        the ``clock`` (``"cpu"`` or ``"wall"``) and its seconds on it, the held-out window PSNR
        (dB), ``cost_x`` (its seconds over the config's recipe's), ``delta_db`` (its PSNR minus
        the config's recipe's) and ``own`` (it is the config's recipe). Pruned trials are not on
        a front: their seconds and scores are partial.
    """
    rows = []
    for (tree, model), t in trials.groupby(["tree", "model"], sort=False):
        own, _, done = _own_and_best(t)
        cpu = "cpu_seconds" in t and t.loc[t["state"] != "FAIL", "cpu_seconds"].notna().all()
        done = done.assign(cost=done["cpu_seconds" if cpu else "seconds"])
        own_s = float(done.loc[done["number"] == 0, "cost"].iloc[0])
        best = -np.inf
        for r in done.sort_values(["cost", "holdout_psnr"], ascending=[True, False]).itertuples():
            if r.holdout_psnr > best:
                best = r.holdout_psnr
                rows.append((tree, model, int(r.number), "cpu" if cpu else "wall", float(r.cost),
                             float(r.holdout_psnr), r.cost / own_s, r.holdout_psnr - own,
                             r.number == 0))  # fmt: skip
    return pd.DataFrame(rows, columns=list(TRADE_FIELDS))


def _scored(trials: pd.DataFrame) -> int:
    """The trials the budget counts: every one but those cut short (``FAIL``)."""
    return int((trials["state"] != "FAIL").sum())


def _own_and_best(trials: pd.DataFrame) -> tuple[float, pd.Series, pd.DataFrame]:
    """One search's own recipe's held-out PSNR (dB, trial 0), its best complete trial (the
    objective's lowest, as Optuna's ``best_trial``) and its complete trials."""
    done = trials[trials["state"] == "COMPLETE"]
    own = float(trials.loc[trials["number"] == 0, "holdout_psnr"].iloc[0])
    return own, done.loc[done["holdout_loss"].idxmin()], done


def recipe_yaml(tree: str, model: str, trials: pd.DataFrame, recipe: dict) -> str:
    """The best recipe as a ``recipes`` block for config/trees.yaml, its evidence in a comment.

    Args:
        tree: the tree's name.
        model: the model's id.
        trials: ``run_search``'s trials (trial 0: the config's own recipe).
        recipe: the best complete trial's recipe.

    Returns:
        YAML text: ``{tree: {model: recipe}}`` under a comment with the best trial's and the
        config's own held-out window PSNR (dB) and the trials run.
    """
    import yaml

    own, best, done = _own_and_best(trials)
    head = (
        f"# {tree} {model}: trial {int(best['number'])} of {_scored(trials)} "
        f"({len(done)} complete), "
        f"held-out window frames {best['holdout_psnr']:.2f} dB against the config's "
        f"{own:.2f} dB (trial 0)\n"
    )
    return head + yaml.safe_dump({tree: {model: recipe}}, sort_keys=True)


def recipes_block(texts: list[str], found: pd.DataFrame) -> str:
    """The searched recipes that replace the config's, as one ``recipes:`` block.

    Args:
        texts: ``recipe_yaml`` texts (``{tree: {model: recipe}}`` under their comment).
        found: ``summary`` of the same searches: a recipe is kept where its ``recipe`` is
            ``"searched"``.

    Returns:
        YAML text for config/trees.yaml: ``recipes:`` and the kept texts indented under it,
        their comments included.
    """
    import yaml

    kept = {(r.tree, r.model) for r in found.itertuples() if r.recipe == "searched"}
    lines = [
        f"  {line}\n"
        for text in texts
        if {(t, m) for t, by in yaml.safe_load(text).items() for m in by} <= kept
        for line in text.splitlines()
    ]
    return "recipes:\n" + "".join(lines)
