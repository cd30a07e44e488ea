"""The stopping rule: the plateau detector on curves worked by hand, the schedule's final anneal,
and a tiny real training that stops on its held-out window frames and records it."""

import numpy as np
import pandas as pd
import pytest

from physgs.experiments import job_spec, train_and_save
from physgs.experiments.recipe import Job, fit, heldout_split
from physgs.train.holdout import HoldoutEval
from physgs.models import build_model, load_checkpoint
from physgs.train import train_model
from physgs.train.schedule import DECAYING, lr_factor
from physgs.train.stopping import STOP_CAP, STOP_PLATEAU, plateau_iteration
from oracles import quick_train_cfg

EVERY = 100
ITS = np.arange(EVERY, 3001, EVERY)


def test_rule_stops_on_a_plateau_at_the_iteration_worked_by_hand():
    # 1 / (1 + it / 200) falls >= 8% per evaluation up to 1000, then stays flat: the score at
    # 1000 is the last improvement; 1100, 1200, 1300 are three without one
    loss = np.where(ITS <= 1000, 1 / (1 + ITS / 200), 1 / 6)
    assert plateau_iteration(ITS, loss, patience=3, tol=0.01) == 1300
    # noise below the tolerance does not reset the count
    noisy = loss * np.where(ITS > 1000, 1 - 0.004 * (ITS % 200 == 0), 1.0)
    assert plateau_iteration(ITS, noisy, patience=3, tol=0.01) == 1300
    # the recipe's last change at 1500: nothing counts before it (best = 1500's, then 3 more)
    assert plateau_iteration(ITS, loss, patience=3, tol=0.01, earliest=1500) == 1800


def test_rule_does_not_stop_a_curve_still_improving():
    fast = np.exp(-ITS / 500)  # 18% per evaluation
    assert plateau_iteration(ITS, fast, patience=3, tol=0.01) is None
    # 0.6% per evaluation: each single step is under tol = 1%, but two are over it, inside the
    # patience of 3, so the best moves every second evaluation and the rule never triggers
    slow = 0.994 ** (ITS / EVERY)
    assert plateau_iteration(ITS, slow, patience=3, tol=0.01) is None
    # ... while 0.3% per evaluation (0.9% over three) is a plateau: best at 100, stop at 400
    slower = 0.997 ** (ITS / EVERY)
    assert plateau_iteration(ITS, slower, patience=3, tol=0.01) == 400


@pytest.mark.parametrize("group", DECAYING)
def test_schedule_stopped_early_ends_at_its_final_factor(group):
    its, warm, final, s, A = 3000, 50, 0.1, 1200, 300
    f = [lr_factor(group, i, its, warm, final, s, s + A) for i in range(s + A + 1)]
    assert f[s + A] == pytest.approx(final, rel=1e-12)  # the end of the stopped run
    # the last trained iteration: one anneal step short of it, as the full schedule's last is
    assert f[s + A - 1] == pytest.approx(final ** (1 - (1 - _progress(group, s, its, warm)) / A))
    # continuous at the trigger, and never increasing
    assert f[s] == pytest.approx(lr_factor(group, s, its, warm, final))
    assert np.all(np.diff(f) <= 1e-15)


def _progress(group, it, its, warm):
    start = 0 if group == "means" else warm
    return (it - start) / (its - start)


@pytest.mark.parametrize("group", [*DECAYING, "colors"])
def test_anneal_at_the_budgets_tail_is_the_schedule_without_a_stop(group):
    its, warm, final, A = 3000, 50, 0.1, 300
    for i in (0, 49, 50, 1000, its - A, its - A + 1, 2999, 3000):
        base = lr_factor(group, i, its, warm, final)
        assert lr_factor(group, i, its, warm, final, its - A, its) == pytest.approx(base, rel=1e-12)
        if group in DECAYING:  # the closed form: final ** ((it - start) / span)
            start = 0 if group == "means" else warm
            assert base == pytest.approx(final ** min(max((i - start) / (its - start), 0), 1))


def _stop_cfg(**stopping):
    cfg = quick_train_cfg(200, 5)
    cfg["train"]["stopping"] = {
        "enabled": True,
        "every": 5,
        "patience": 2,
        "tol": 0.9,  # an improvement would be a 10x lower loss: none comes, the count is exact
        "anneal": 10,
        "start": 0.0,
        **stopping,
    }
    return cfg


def test_tiny_training_stops_on_its_held_out_frames_and_records_it(tmp_path, swaying):
    cfg = _stop_cfg()
    ck, lg = tmp_path / "static_single.pt", tmp_path / "static_single.loss.csv"
    train_and_save(
        swaying, job_spec(cfg, "static", "single"), checkpoint_path=ck, loss_path=lg, progress=False
    )
    st = load_checkpoint(ck).checkpoint_info["stats"]
    # scored at 5 (the first deformation iteration: the best), 10, 15: two without an
    # improvement trigger at 15; the anneal's 10 iterations end the run at 25 of the 200
    assert (st["stopped"], st["stop_trigger"], st["iterations"], st["budget"]) == (
        STOP_PLATEAU,
        15,
        25,
        200,
    )
    assert st["holdout_evals"] == 3 and st["holdout_s"] > 0
    log = pd.read_csv(lg)
    assert len(log) == 25 and log["iteration"].iloc[-1] == 24
    assert list(log.loc[log["holdout"].notna(), "iteration"]) == [5, 10, 15]
    assert (log["phase"].iloc[15:] == "anneal").all() and (
        log["phase"].iloc[5:15] == "deform"
    ).all()


def test_a_rule_that_never_triggers_trains_the_whole_budget(swaying):
    cfg = _stop_cfg(tol=0.0, patience=50)  # any decrease counts
    cfg["train"]["iterations"] = 40
    res = fit(swaying, Job.from_dict(job_spec(cfg, "static", "single")), progress=False)
    assert (res.stats["stopped"], res.stats["iterations"], res.stats["holdout_evals"]) == (
        STOP_CAP,
        40,
        5,  # 5 .. 25: from 30 on, an anneal of 10 could not end before the cap
    )


def test_scoring_the_held_out_frames_leaves_the_training_unchanged(swaying):
    """The rule off but scoring: bitwise the training without scores (no side effect)."""
    losses = []
    for every in (0, 5):
        cfg = _stop_cfg(enabled=False, every=every)
        cfg["train"]["iterations"] = 30
        res = fit(swaying, Job.from_dict(job_spec(cfg, "mlp", "single")), progress=False)
        losses.append([r["loss"] for r in res.log])
        assert res.stats["stopped"] == STOP_CAP and res.stats["holdout_evals"] == (
            0 if every == 0 else 5
        )
    assert losses[0] == losses[1]


def test_a_fit_curve_hook_sees_every_iteration_and_changes_nothing(swaying):
    """``fit(hooks=...)``, as benchmarks/stopping.py curves records its curves: the hook runs at
    every iteration after the recipe's, and scoring the held-out frames in it leaves the
    training bitwise as it is without."""
    cfg = _stop_cfg(enabled=False, every=0)
    cfg["train"]["iterations"] = 30
    job = Job.from_dict(job_spec(cfg, "mlp", "single"))
    held = heldout_split(int(swaying.n_train), int(job.train["holdout_every"]))[1]
    ev = HoldoutEval.build(swaying, held, [0], job.train)
    seen, scores = [], []

    def record(it, model, opt):
        seen.append(it)
        if it % 10 == 0:
            scores.append(ev.evaluate(model, warm=it < int(job.train["warmup"]))[0])

    hooked = fit(swaying, job, progress=False, hooks=(record,))
    plain = fit(swaying, job, progress=False)
    assert seen == list(range(30)) and len(scores) == 3 and all(np.isfinite(scores))
    assert [r["loss"] for r in hooked.log] == [r["loss"] for r in plain.log]


def test_enabled_rule_without_held_out_frames_is_refused(swaying):
    cfg = _stop_cfg()
    cfg["train"]["holdout_every"] = 0
    with pytest.raises(ValueError, match="holdout_every > 0"):
        fit(swaying, Job.from_dict(job_spec(cfg, "static", "single")), progress=False)


def test_the_loop_without_held_out_frames_trains_its_budget(swaying):
    cfg = _stop_cfg()
    model = build_model("static", swaying, cfg["models"], seed=0)
    res = train_model(model, swaying, cfg["train"], conditions=[0], seed=0, progress=False)
    assert (res.stats["iterations"], res.stats["stopped"]) == (200, STOP_CAP)


def test_plateau_counts_relative_improvements():
    # by hand: best 1.0; 0.995 is 0.5% (< 1%: no); 0.989 is 1.1% (yes: best 0.989)
    assert plateau_iteration([1, 2, 3, 4], [1.0, 0.995, 0.989, 0.988], 2, 0.01) is None
    assert plateau_iteration([1, 2, 3, 4, 5], [1.0, 0.995, 0.989, 0.988, 0.985], 2, 0.01) == 5


def test_scores_only_where_a_trigger_could_still_stop_the_run():
    from physgs.train.stopping import StopRule

    r = StopRule(enabled=True, every=300, patience=2, tol=0.01, anneal=300, start=0.5)
    # from max(earliest, 0.5 x 3000) = 1500, every 300, while it + 300 < 3000
    assert [i for i in range(3001) if r.scores_at(i, 3000, 50)] == [1500, 1800, 2100, 2400]
    assert [i for i in range(3001) if r.scores_at(i, 3000, 1600)] == [1800, 2100, 2400]
    off = StopRule(enabled=False, every=300, patience=2, tol=0.01, anneal=300, start=0.5)
    assert [i for i in range(3001) if off.scores_at(i, 3000, 50)] == [
        1500,
        1800,
        2100,
        2400,
        2700,
        3000,
    ]


def test_a_curves_plateau_and_heading_are_read_as_worked_by_hand():
    """benchmarks/stopping.py plateau: the rule's trigger on a recorded curve, the PSNR there and
    at 3000, the last quarter's slope and the end's fraction of the ceiling's held-out gain."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "stopping.py"
    spec = importlib.util.spec_from_file_location("stopping_bench", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    its = np.arange(300, 6001, 300)  # 20 scores
    # improving 10% a score up to 2400, then flat: P = 2 flat scores trigger at 3000
    loss = np.where(its <= 2400, 0.1 * 0.9 ** (its / 300), 0.1 * 0.9**8)
    psnr = 20.0 + its / 1000.0  # rising 1 dB per 1000 iterations throughout
    curve = pd.DataFrame(
        {
            "tree": "medium",
            "model": "mlp",
            "iteration": its,
            "holdout_loss": loss,
            "holdout_psnr": psnr,
        }
    )
    refs = pd.DataFrame(
        {
            "tree": "medium",
            "model": ["static", "truth_motion"],
            "iteration": [3000, 3000],
            "holdout_loss": [0.2, 0.01],
            "holdout_psnr": [18.0, 38.0],
        }
    )
    r = bench.plateaus(curve, patience=2, tol=0.005, refs=refs).iloc[0]
    assert r["plateau_at"] == 3000 and r["psnr_plateau"] == pytest.approx(23.0)
    assert r["psnr_3000"] == pytest.approx(23.0) and r["psnr_end"] == pytest.approx(26.0)
    assert r["slope_db_per_1000"] == pytest.approx(1.0)
    assert r["enough_at"] == 5700  # 26.0 - 0.5 = 25.5 dB: 25.4 at 5400, 25.7 at 5700
    assert r["heldout_of_ceiling_end"] == pytest.approx((26.0 - 18.0) / 20.0)

    # the shortfall at a cap: best 26.0 - the last score at or before 4500 (24.5)
    short = bench.shortfalls(curve, [4500, 9000]).iloc[0]
    assert short["below_best_4500"] == pytest.approx(1.5) and short["below_best_9000"] == 0.0
    # a training at its own budget of 3000 that ends at 24.0, against the long curve at 3000
    own = curve[curve["iteration"] <= 3000].assign(
        budget=3000, holdout_psnr=lambda d: d.holdout_psnr + 1
    )
    o = bench.own_budgets(curve, own).iloc[0]
    assert o["own_end"] == pytest.approx(24.0) and o["long_at"] == pytest.approx(23.0)
    assert o["own_below_best"] == pytest.approx(2.0)


def test_the_fit_bars_shortfalls_name_their_curve_and_where_it_heads():
    """benchmarks/stopping.py fits: each fits_window row that does not hold, beside the curve of
    its model at the budget it trained (else the longest): last score, best, heading."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "stopping.py"
    spec = importlib.util.spec_from_file_location("stopping_bench", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.heading(0.55) == "rising (+0.55 dB/1000)"
    assert bench.heading(-0.05).startswith("flat") and bench.heading(-0.2).startswith("falling")
    assert bench.heading(float("nan")) == "--"

    def curve(model, budget, rise):  # PSNR 20 + rise * it / 1000, scored every 300
        its = np.arange(300, budget + 1, 300)
        return pd.DataFrame({"tree": "dense", "model": model, "iteration": its, "budget": budget,
                             "holdout_loss": 0.1 / its, "holdout_psnr": 20.0 + rise * its / 1000})  # fmt: skip

    df = pd.concat([curve("mlp", 12000, 0.5), curve("ours", 12000, 0.0), curve("ours", 6000, 1.0)])
    # ours trained 6000 in the run: its own 6000 curve, not the 12000 one's checkpoints
    picked = bench.curves_at(df, {("dense", "ours"): 6000, ("dense", "mlp"): 3000})
    assert set(zip(picked["model"], picked["budget"])) == {("mlp", 12000), ("ours", 6000)}
    p = bench.plateaus(picked, patience=2, tol=0.005)
    claims = pd.DataFrame({
        "id": ["fits_window/dense/mlp", "fits_window/dense/ours", "fits_window/dense/d3dgs",
               "fits_window/sparse/mlp", "null_factor/dense"],
        "verdict": ["fails", "undecided", "fails", "holds", "fails"],
        "measured": [0.13, 0.45, 0.4, 0.9, 1.0], "ci_low": [0.08, 0.3, 0.3, 0.8, 0.5],
        "ci_high": [0.17, 0.6, 0.5, 1.0, 1.5],
    })  # fmt: skip
    r = bench.fit_shortfalls(claims, p).set_index("model")
    assert list(r.index) == ["mlp", "ours", "d3dgs"]  # the rows that do not hold, in order
    assert r.loc["mlp", "last_psnr"] == "26.00" and r.loc["mlp", "heading"].startswith("rising")
    assert r.loc["ours", "curve"] == "6000 it" and r.loc["ours", "best"] == "26.00 at 6000"
    assert r.loc["ours", "ceiling_frac"] == "0.45 [0.30, 0.60]"
    assert r.loc["d3dgs", "curve"] == "no curve measured"
