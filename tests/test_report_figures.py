"""Figures are written in both formats, atomically, and bad input names its cause."""

import numpy as np
import pytest

from physgs.evaluate.trajectories import Trajectories
from physgs.recovery import damping_summary
from physgs.report import figures as FG


def test_figures_write_pdf_and_png(tmp_path):
    rng = np.random.default_rng(0)
    F, n = 30, 24
    curves = {("medium", m): 25 + rng.random(F) for m in ("static", "ours")}
    FG.fig_temporal(
        curves, ["medium"], n, [tmp_path / "t.pdf", tmp_path / "t.png"], models=("static", "ours")
    )
    gt = rng.random((2, F, 2)) * 10
    tr = {"ours": Trajectories(gt, gt + 0.1, np.arange(2), 0, n)}
    FG.fig_teaser(tr, {"ours": rng.random((3, F))}, [1.0, 0.84, 0.71], [tmp_path / "s.png"])
    img = np.ones((8, 8, 3))
    FG.fig_results(
        ["r"],
        ["gt", "ours", "mlp"],
        {("r", "gt"): (img, None), ("r", "ours"): (img, 25.0), ("r", "mlp"): (img, 26.0)},
        [tmp_path / "q.png"],
    )
    d = {
        ("medium", "single"): damping_summary(
            np.array([2.0, 4.0, 8.0]), np.array([0.2, 0.1, 0.05]), 0.08
        )
    }
    FG.fig_damping({"ours": d}, ["medium"], ["single"], 0.08, [tmp_path / "d.pdf"])
    chain = {("medium", "single"): d[("medium", "single")]}
    FG.fig_damping(
        {"ours": d, "ours_chain": chain}, ["medium"], ["single"], 0.08, [tmp_path / "c.png"]
    )
    assert (tmp_path / "c.png").stat().st_size > 1000
    (tmp_path / "c.png").unlink()
    with pytest.raises(KeyError, match="of ours_chain for \\(medium, single\\)"):
        FG.fig_damping(
            {"ours": d, "ours_chain": {}}, ["medium"], ["single"], 0.08, [tmp_path / "x.png"]
        )
    for name in ("t.pdf", "t.png", "s.png", "q.png", "d.pdf"):
        assert (tmp_path / name).stat().st_size > 1000
    assert (tmp_path / "t.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "t.pdf").read_bytes()[:4] == b"%PDF"
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "d.pdf",
        "q.png",
        "s.png",
        "t.pdf",
        "t.png",
    ]


def test_figure_bad_input(tmp_path):
    with pytest.raises(ValueError, match="suffix"):
        FG.fig_temporal(
            {("a", "ours"): np.ones(5)}, ["a"], 3, [tmp_path / "x.jpg"], models=("ours",)
        )
    assert not any(tmp_path.iterdir())  # no partial output left behind
    with pytest.raises(KeyError, match="static"):
        FG.fig_temporal(
            {("a", "ours"): np.ones(5)}, ["a"], 3, [tmp_path / "x.png"], models=("static", "ours")
        )


def test_best_baseline():
    s = {
        "static": {"time": 30.0},
        "mlp": {"time": 24.0},
        "d3dgs": {"time": 25.0},
        "ours": {"time": 28.0},
    }
    assert FG.best_baseline(s) == "d3dgs"


def test_fig_results_names_the_panel_without_an_image(tmp_path):
    img = np.ones((8, 8, 3))
    images = {("r", "gt"): (img, None), ("r", "ours"): (img, 25.0)}  # no ("r", "mlp")
    with pytest.raises(KeyError, match="no image for row 'r', column 'mlp'"):
        FG.fig_results(["r"], ["gt", "ours", "mlp"], images, [tmp_path / "q.png"])
    assert not (tmp_path / "q.png").exists()
