"""fig_fit_vs_extrapolation's numbers: each fit-curve point's gain over static beyond the window."""

import numpy as np
import pandas as pd
import pytest

from physgs.experiments.fit_curve import fit_vs_extrapolation, trade_summary
from physgs.report.trade import draw_fit_vs_extrapolation


def _curve() -> pd.DataFrame:
    rows = []
    # two trees, two seeds; static's time-split PSNR differs per tree and seed
    static_time = {("medium", 0): 20.0, ("medium", 1): 21.0, ("dense", 0): 18.0, ("dense", 1): 18.5}
    for (tree, seed), st in static_time.items():
        rows.append(
            dict(
                tree=tree,
                seed=seed,
                model="static",
                iterations=3000,
                is_profile=True,
                fit=22.0,
                time=st,
                of_ceiling=0.0,
            )
        )
        rows.append(
            dict(
                tree=tree,
                seed=seed,
                model="truth_motion",
                iterations=3000,
                is_profile=True,
                fit=32.0,
                time=30.0,
                of_ceiling=1.0,
            )
        )
        for it, (fit_frac, t) in {
            1500: (0.3, st + 1.0),
            3000: (0.5, st + 0.5),
            6000: (0.8, st - 0.25),
        }.items():
            rows.append(
                dict(
                    tree=tree,
                    seed=seed,
                    model="d3dgs_wind",
                    iterations=it,
                    is_profile=it == 3000,
                    fit=0.0,
                    time=t,
                    of_ceiling=fit_frac,
                )
            )
    rows.append(
        dict(
            tree="dense",
            seed=2,
            model="mlp",
            iterations=3000,
            is_profile=True,
            fit=0.0,
            time=19.0,
            of_ceiling=np.nan,
        )
    )  # no ceiling for that seed: no point
    return pd.DataFrame(rows)


def test_each_point_is_scored_against_its_own_trees_and_seeds_static_pose():
    out = fit_vs_extrapolation(_curve())
    assert set(out["model"]) == {"d3dgs_wind", "truth_motion"}
    d = out[out["model"] == "d3dgs_wind"].set_index(["tree", "seed", "iterations"])["beyond_gain"]
    assert d[("medium", 1, 1500)] == pytest.approx(1.0)
    assert d[("dense", 0, 6000)] == pytest.approx(-0.25)
    assert (
        d.groupby(level="iterations").mean() == pd.Series({1500: 1.0, 3000: 0.5, 6000: -0.25})
    ).all()
    ceiling = out[out["model"] == "truth_motion"].set_index(["tree", "seed"])["beyond_gain"]
    assert ceiling[("medium", 1)] == pytest.approx(9.0) and ceiling[("dense", 1)] == pytest.approx(
        11.5
    )


def test_the_figure_draws_one_panel_per_tree(tmp_path):
    png = tmp_path / "fig.png"
    draw_fit_vs_extrapolation(fit_vs_extrapolation(_curve()), [png])
    import matplotlib.image as mpimg

    img = mpimg.imread(png)
    assert img.shape[1] > 1.8 * img.shape[0]  # two panels side by side


def test_the_trade_summary_gives_each_curves_means_and_their_change():
    """Per tree and model: the budgets (the profile's starred), the means over seeds at each, and
    largest-budget minus smallest; the ceiling left out. By hand from the fixture: the fit
    fraction 0.3 / 0.5 / 0.8, the gain +1.0 / +0.5 / -0.25 dB on both trees."""
    s = trade_summary(fit_vs_extrapolation(_curve())).set_index(["tree", "model"])
    assert list(s.index) == [("medium", "d3dgs_wind"), ("dense", "d3dgs_wind")]
    row = s.loc[("dense", "d3dgs_wind")]
    assert row["budgets"] == "1500 / 3000* / 6000" and row["seeds"] == 2
    assert row["of_ceiling"] == "0.30 / 0.50 / 0.80"
    assert row["beyond_gain_db"] == "+1.00 / +0.50 / -0.25"
    assert row["d_of_ceiling"] == pytest.approx(0.5)
    assert row["d_beyond_db"] == pytest.approx(-1.25)


def test_the_tool_writes_the_summary_as_markdown(tmp_path):
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    _curve().to_csv(tmp_path / "fit_curve.csv", index=False)
    tool = [sys.executable, root / "tools" / "fit_trade.py", tmp_path / "fit_curve.csv"]
    bare = subprocess.run(tool, capture_output=True, text=True, timeout=60)
    assert bare.returncode != 0 and "no provenance record" in bare.stderr  # made by what?
    from physgs.provenance import write_provenance

    write_provenance([tmp_path / "fit_curve.csv"], "fit_curve", {"seeds": [0, 1]}, commit="abc1234")
    page, png, small = tmp_path / "fit_trade.md", tmp_path / "fig.png", tmp_path / "small.png"
    draw_fit_vs_extrapolation(fit_vs_extrapolation(_curve()), [png])
    out = subprocess.run(
        [*tool, "--markdown", page, "--figure", png, small],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    origin, lines = page.read_text().splitlines()[0], page.read_text().splitlines()[2:]
    assert "commit abc1234" in origin and "seeds [0, 1]" in origin
    assert lines[0].split("|")[1].strip() == "tree" and len(lines) == 4  # head, rule, 2 rows
    assert "| dense  | d3dgs_wind | 1500 / 3000* / 6000 |" in page.read_text()
    assert lines[-1].rstrip("| ").endswith("-1.25")
    from PIL import Image

    from physgs.report.record import FIGURE_WIDTH_PX

    with Image.open(png) as big, Image.open(small) as im:
        assert big.width > FIGURE_WIDTH_PX and im.width == FIGURE_WIDTH_PX
