"""What the committed recipe searches found: one row per tree and model, from their trials files.

    python tools/search_summary.py docs/studies/search/*.trials.csv \
        --markdown docs/studies/search_summary.md [--trade docs/studies/search_trade.md] \
        [--figure docs/img/search_trade.png] [--check]

Each row (`physgs.experiments.search.summary`): trials scored and complete, those cut short
(trained again on resuming), the config's own recipe's held-out window PSNR (trial 0) and the
best complete trial's, the gain, and which recipe the config keeps by `search.adopt_above_db`
(read from config/trees.yaml). `--trade`: each search's cost-accuracy front
(`physgs.experiments.search.trade`), and `--figure` draws every complete trial's seconds against
its held-out window PSNR. `--check` writes nothing and exits 1 when a page is out of date.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

import physgs.config
from physgs.experiments.search import summary, trade
from physgs.models.registry import MODEL_NAMES, label

#: the page's column headers
HEADERS = {
    "trials": "trials scored",
    "cut": "cut, trained again",
    "own_psnr": "own (dB)",
    "best_psnr": "best (dB)",
    "best_trial": "best trial",
    "gain_db": "gain (dB)",
    "recipe": "recipe kept",
    "number": "trial",
    "holdout_psnr": "held-out window (dB)",
    "cost_x": "seconds / own",
    "delta_db": "against own (dB)",
    "own": "config's recipe",
}


def _markdown(df: pd.DataFrame, order: dict) -> str:
    """``df`` with the config's order of the trees, the models' labels and the pages' headers."""
    df = df.sort_values("tree", key=lambda t: t.map(order), kind="stable")
    df = df.assign(model=df["model"].map(label)).rename(columns=HEADERS)
    return df.to_markdown(index=False, floatfmt=".2f") + "\n"


def _figure(trials: pd.DataFrame, front: pd.DataFrame, trees: list[str], path: Path) -> None:
    """A panel per model: every complete trial's seconds against its held-out window PSNR, a
    colour per tree, its front as a line and the config's recipe as a star; at the docs' page
    width and font size (``physgs.report.figures``)."""
    import matplotlib.pyplot as plt
    from physgs.report.figures import FONT_PT, PAGE_WIDTH_IN, plain_log, save_figure

    done = trials[trials["state"] == "COMPLETE"]
    models = [m for m in MODEL_NAMES if m in set(done["model"])]
    cols = -(-len(models) // 2)
    fig, axes = plt.subplots(2, cols, figsize=(PAGE_WIDTH_IN, 6.0), squeeze=False)
    for ax, model in zip(axes.flat, models):
        for i, tree in enumerate(trees):
            t, f = (d[(d["model"] == model) & (d["tree"] == tree)] for d in (done, front))
            x = "cpu_seconds" if (f["clock"] == "cpu").all() and len(f) else "seconds"
            c = f"C{i}"
            ax.scatter(t[x], t["holdout_psnr"], s=10, color=c, alpha=0.4)
            ax.plot(f["seconds"], f["holdout_psnr"], "-o", ms=2.5, lw=1, color=c, label=tree)
            own = t[t["number"] == 0]
            ax.scatter(own[x], own["holdout_psnr"], marker="*", s=90, color=c, ec="k", lw=0.5)
        ax.set_xscale("log")
        # 1-2-5 ticks, plain numbers: a panel's trials often span less than a decade
        plain_log(ax.xaxis)
        ax.set_title(label(model), fontsize=FONT_PT)
        ax.tick_params(labelsize=FONT_PT - 1)
    for ax in axes[-1]:
        ax.set_xlabel("training seconds", fontsize=FONT_PT)
    for ax in axes[:, 0]:
        ax.set_ylabel("held-out window (dB)", fontsize=FONT_PT)
    for ax in list(axes.flat)[len(models) :]:
        ax.set_visible(False)
    axes.flat[0].legend(fontsize=FONT_PT - 1, frameon=False)
    fig.tight_layout()
    save_figure(fig, [path], dpi=150)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trials", nargs="+", help="searches' trials CSVs")
    ap.add_argument("--markdown", required=True, help="the page to write")
    ap.add_argument("--trade", help="the page of the searches' cost-accuracy fronts")
    ap.add_argument("--figure", help="the PNG of every complete trial's cost and score")
    ap.add_argument("--config", default="config/trees.yaml")
    ap.add_argument("--check", action="store_true", help="exit 1 if a page is out of date")
    args = ap.parse_args(argv)
    cfg = physgs.config.load(args.config)
    trials = pd.concat([pd.read_csv(p) for p in sorted(args.trials)], ignore_index=True)
    order = {t: i for i, t in enumerate(cfg["trees"])}  # the config's order of the trees
    pages = {
        args.markdown: _markdown(summary(trials, float(cfg["search"]["adopt_above_db"])), order)
    }
    front = trade(trials) if args.trade or args.figure else None
    if args.trade:
        pages[args.trade] = _markdown(
            front.assign(own=front["own"].map({True: "yes", False: ""})), order
        )
    if args.check:
        stale = [
            p for p, text in pages.items() if not Path(p).exists() or Path(p).read_text() != text
        ]
        for p in stale:
            print(f"{p} is out of date: rerun without --check", file=sys.stderr)
        return int(bool(stale))
    for p, text in pages.items():
        Path(p).write_text(text)
        print(f"{p}: {text.count(chr(10)) - 2} rows")
    if args.figure:
        _figure(trials, front, list(cfg["trees"]), Path(args.figure))
        print(args.figure)
    return 0


if __name__ == "__main__":
    sys.exit(main())
