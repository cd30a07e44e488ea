"""fig_fit_vs_extrapolation's numbers: each fit-curve point's gain over static beyond the window."""

import numpy as np
import pandas as pd
import pytest

from physgs.report.trade import draw_fit_vs_extrapolation, fit_vs_extrapolation


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
