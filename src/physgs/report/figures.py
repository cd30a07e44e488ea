"""Figures (the protocol, section 4-5): fig_temporal, fig_teaser, fig_results, fig_damping, and
the studies' fig_speed_accuracy and fig_fit_curve; what each shows is its caption
(``captions.yaml``), written once.

Each ``fig_*`` takes collected results and a list of output paths; a path's suffix picks its
format (.pdf, .png), each written atomically. Matplotlib's Agg backend: no display needed.
"""

from __future__ import annotations

import textwrap
from itertools import product
from pathlib import Path
from typing import Mapping, Sequence

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter  # noqa: E402

from physgs.atomic import atomic_path  # noqa: E402
from physgs.models.registry import MODEL_NAMES as MODELS  # noqa: E402
from physgs.models.registry import PAPER_MODEL, REFERENCE_NAMES, label, spec_of  # noqa: E402
from physgs.report.tables import condition_label  # noqa: E402

COLORS = {
    "static": "0.55",
    "mlp": "tab:orange",
    "mlp_wind": "tab:red",
    "d3dgs": "tab:purple",
    "d3dgs_wind": "tab:brown",
    "ours": "tab:blue",
    "ours_chain": "tab:green",
    "gt": "k",
}
GOOD, BAD = "#1a9850", "#f46d43"  # green where ours is best, orange where a baseline beats it
WINDOW, TAIL = "0.6", "tab:blue"
#: The documentation's content column, px: MkDocs Material in Chromium shows 688 px at 1280-1440
#: px windows (the contents sidebar shown), 911 px at 1200 px; a figure must read at the narrower.
PAGE_WIDTH_PX = 688
#: A figure this wide (inches) shows one point as one pixel on the page: ``FONT_PT`` reads as px.
PAGE_WIDTH_IN = PAGE_WIDTH_PX / 72
FONT_PT = 9.0


def save_figure(fig, outputs: Sequence[str | Path], dpi: int = 200) -> None:
    """Save ``fig`` to every path in ``outputs`` (format from the suffix), atomically; closes it.

    Args:
        fig (matplotlib.figure.Figure): the figure (closed afterwards, also on error).
        outputs: the paths, each ``.pdf`` or ``.png``.
        dpi: resolution of a PNG, dots per inch.

    Raises:
        ValueError: for another suffix.
    """
    try:
        for out in outputs:
            suffix = Path(out).suffix.lstrip(".")
            if suffix not in ("pdf", "png"):
                raise ValueError(f"figure output {out!r}: suffix must be .pdf or .png")
            with atomic_path(out) as tmp:
                fig.savefig(tmp, format=suffix, dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(fig)


def best_baseline(
    summaries: Mapping[str, Mapping[str, float]],
    key: str = "time",
    exclude: Sequence[str] = ("static", PAPER_MODEL),
) -> str:
    """The id of the learned baseline with the highest ``summaries[model][key]`` (dB).

    Args:
        summaries: model -> its split means
            ([`EvalResult.summary`][physgs.evaluate.splits.EvalResult.summary]).
        key: the split compared.
        exclude: models that are not candidates.

    Returns:
        The model id.

    Raises:
        ValueError: when no candidate is left.
    """
    cands = {m: s[key] for m, s in summaries.items() if m not in exclude}
    if not cands:
        raise ValueError("best_baseline: no baseline among the given models")
    return max(cands, key=cands.get)


def _axes(rows: int, cols: int, height: float, width: float = PAGE_WIDTH_IN, **kw):
    """A figure of [rows, cols] axes, ``width`` x ``height`` inches (the page's width by default)."""
    return plt.subplots(rows, cols, figsize=(width, height), squeeze=False, **kw)


def _finish(
    fig, outputs, title="", *, title_pt=FONT_PT, key=(), ncol=4, top=0.1, pad=1.08, dpi=200
):
    """Title ``fig``, lay it out and save it (``save_figure``); a ``key``: those handles in one
    legend below the panels (its top at ``top`` < 0.2 in figure fractions), never over the data:
    the panels keep the top 80%."""
    if title:
        fig.suptitle(title, fontsize=title_pt)
    fig.tight_layout(pad=pad, rect=(0, 0.2, 1, 1) if key else None)
    if key:
        where = dict(loc="upper center", bbox_to_anchor=(0.5, top), ncol=ncol)
        fig.legend(handles=list(key), **where, fontsize=FONT_PT, frameon=False)
    save_figure(fig, outputs, dpi=dpi)


def plain_log(axis, ticks: bool = True) -> None:
    """Plain-number labels on a log axis (10^x labels collide on a short one), none on minor ticks.

    Args:
        axis (matplotlib.axis.Axis): a log-scaled axis (``ax.xaxis``, ``ax.yaxis``).
        ticks: major ticks at 1, 2 and 5 per decade (a span under one gets some); False keeps
            the major ticks the caller set.
    """
    if ticks:
        axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(ScalarFormatter())
    axis.set_minor_formatter(NullFormatter())


def _texts(ax, title=None, xlabel=None, ylabel=None, title_pt=FONT_PT) -> None:
    """An axes' title and axis labels (those given) and its tick labels, at the page's font size."""
    if title is not None:
        ax.set_title(title, fontsize=title_pt)
    if xlabel is not None:
        ax.set_xlabel(xlabel, fontsize=FONT_PT)
    if ylabel is not None:
        ax.set_ylabel(ylabel, fontsize=FONT_PT)
    ax.tick_params(labelsize=FONT_PT)


def fig_temporal(
    curves: Mapping[tuple[str, str], np.ndarray],
    trees: Sequence[str],
    n_train: int,
    outputs: Sequence[str | Path],
    models: Sequence[str] = MODELS,
) -> None:
    """fig_temporal: per-frame PSNR (dB) at the training camera and wind, one panel per tree.

    Args:
        curves: ``curves[(tree, model)]``: [S, F] PSNR (dB) over recorded frames 1..F, one row per
            training seed (or [F] for one seed).
        trees: the trees, one panel each.
        n_train: training-window length, frames.
        outputs: the paths to write.
        models: the models drawn.

    Raises:
        KeyError: when a (tree, model) has no curve.
    """
    fig, axes = _axes(1, len(trees), 3.4)
    for ax, t in zip(axes[0], trees):
        for m in (*models, *(r for r in REFERENCE_NAMES if (t, r) in curves)):
            if (t, m) not in curves:
                raise KeyError(f"fig_temporal: no per-frame PSNR for ({t}, {m})")
            Y = np.atleast_2d(np.asarray(curves[(t, m)], dtype=np.float64))  # [S, F]
            x = np.arange(1, Y.shape[1] + 1)
            if m in REFERENCE_NAMES:  # the ceiling: no spread
                ax.plot(x, Y.mean(0), color="k", lw=0.8, ls=":", label=label(m))
                continue
            n_seeds, color = len(Y), COLORS.get(m)
            lw, ls = 1.4 if spec_of(m).role == "prior" else 0.8, "--" if m == "static" else "-"
            ax.plot(x, Y.mean(0), color=color, lw=lw, ls=ls, label=label(m))
            if len(Y) > 1:  # the seeds' spread
                ax.fill_between(x, Y.min(0), Y.max(0), color=color, alpha=0.2, lw=0)
        ax.axvline(n_train + 0.5, color="k", lw=0.8, ls=":")
        ax.axvspan(n_train + 0.5, len(x) + 0.5, color="0.9", zorder=0)
        ax.set_xlim(1, len(x))
        first = ax is axes[0, 0]
        _texts(ax, t.capitalize(), "frame", "PSNR (dB)" if first else None, FONT_PT + 1)
    handles, _ = axes[0, 0].get_legend_handles_labels()
    handles.append(Patch(color="0.9", label=f"beyond the training window (after frame {n_train})"))
    if n_seeds > 1:
        handles.append(Patch(color="0.5", alpha=0.3, label=f"lowest to highest of {n_seeds} seeds"))
    _finish(fig, outputs, key=handles, ncol=3, top=0.16)


def fig_teaser(
    trajectories: Mapping[str, object],
    centroid_err: Mapping[str, np.ndarray],
    conditions: Sequence[float],
    outputs: Sequence[str | Path],
    *,
    tip: int | None = None,
    unseen: int = -1,
    title: str = "",
) -> None:
    """Branch-tip paths through the window (grey) and tail (blue), and canopy-centroid error.

    Args:
        trajectories: [`Trajectories`][physgs.evaluate.trajectories.Trajectories] by model at the
            training wind (e.g. ours and the best baseline; the ground truth: the first's).
        centroid_err: ``centroid_err[model]``: [C, F] canopy-centroid error, px.
        conditions: the mean-speed multipliers of the C conditions.
        outputs: the paths to write.
        tip: which tip to draw (default: the one the ground truth moves most).
        unseen: index of the unseen condition shown in the last panel.
        title: the figure's title.
    """
    models = list(trajectories)
    first = trajectories[models[0]]
    n_train = first.n_train
    if tip is None:
        tip = int(np.argmax(np.ptp(first.gt_px, axis=1).sum(-1)))
    gt = first.gt_px[tip]
    panels = [("Ground truth", gt)] + [(label(m), trajectories[m].pred_px[tip]) for m in models]
    fig = plt.figure(figsize=(PAGE_WIDTH_IN, PAGE_WIDTH_IN / len(panels) + 4.2))
    gs = fig.add_gridspec(2, 2 * len(panels), height_ratios=[1.0, 1.1])
    pad = 0.15 * max(np.ptp(gt[:, 0]), np.ptp(gt[:, 1]), 1.0)
    lo, hi = gt.min(0) - pad, gt.max(0) + pad
    for i, (name, p) in enumerate(panels):
        ax = fig.add_subplot(gs[0, 2 * i : 2 * i + 2])
        if i:
            ax.plot(gt[:, 0], gt[:, 1], color="k", lw=0.5, ls=":", label="ground truth")
        tail = p[n_train - 1 :]
        ax.plot(p[:n_train, 0], p[:n_train, 1], color=WINDOW, lw=0.9, label="training window")
        ax.plot(tail[:, 0], tail[:, 1], color=TAIL, lw=1.4, label="beyond the window")
        ax.set(xlim=(lo[0], hi[0]), ylim=(hi[1], lo[1]), aspect="equal")  # image y points down
        _texts(ax, textwrap.fill(name, 16), "x (px)", "y (px)" if i == 0 else None)
        if i == len(panels) - 1:  # one key for the paths, right of the last panel
            ax.legend(fontsize=FONT_PT, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    half, unseen = len(panels), unseen % len(conditions)
    unseen_wind = f"unseen wind {condition_label(conditions[unseen], tex=False)}"
    for j, (c, lab) in enumerate([(0, "training wind"), (unseen, unseen_wind)]):
        ax = fig.add_subplot(gs[1, j * half : (j + 1) * half])
        for m in models:
            e = np.asarray(centroid_err[m])[c]
            key = f"{label(m)} (mean {e.mean():.1f} px)"
            ax.plot(np.arange(1, len(e) + 1), e, color=COLORS.get(m), lw=1.0, label=key)
        ax.axvline(n_train + 0.5, color="k", lw=0.8, ls=":")
        _texts(ax, f"canopy-centroid error, {lab}", "frame", "error (px)")
        # below its panel, never over the curves
        ax.legend(fontsize=FONT_PT, loc="upper center", bbox_to_anchor=(0.5, -0.22), frameon=False)
    _finish(fig, outputs, title, title_pt=FONT_PT + 1)


def fig_results(
    rows: Sequence[str],
    columns: Sequence[str],
    images: Mapping[tuple[str, str], tuple[np.ndarray, float | None]],
    outputs: Sequence[str | Path],
    ours: str = PAPER_MODEL,
) -> None:
    """fig_results: one row per (tree, split) label, one column per model (or 'gt').

    Args:
        rows: the row labels.
        columns: the column labels (model ids or ``'gt'``).
        images: ``images[(row, column)]`` = (rgb [H, W, 3] in [0, 1] or uint8, PSNR in dB or None
            for the ground truth).
        outputs: the paths to write.
        ours: ours' column.

    Raises:
        KeyError: when a panel has no image.
    """
    for r, c in product(rows, columns):  # before drawing: each row's scores read every column
        if (r, c) not in images:
            raise KeyError(f"fig_results: no image for row {r!r}, column {c!r}")
    side = PAGE_WIDTH_IN / (len(columns) + 0.3)  # one panel, inches; the row labels beside
    fig, axes = _axes(len(rows), len(columns), side * len(rows) + 0.5)
    box = dict(facecolor="white", alpha=0.8, lw=0, pad=1)
    for (i, r), (j, c) in product(enumerate(rows), enumerate(columns)):
        scores = {x: images[(r, x)][1] for x in columns if images[(r, x)][1] is not None}
        img, score = images[(r, c)]
        ax, mine = axes[i, j], scores.get(ours)
        ax.imshow(np.asarray(img), interpolation="nearest")
        ax.set(xticks=[], yticks=[])
        if score is not None:
            best = c == ours and mine is not None and mine >= max(scores.values())
            beats = c != ours and mine is not None and score > mine
            color = GOOD if best else BAD if beats else "k"
            weight = "bold" if color != "k" else "normal"
            kw = dict(fontsize=FONT_PT, color=color, fontweight=weight, bbox=box)
            ax.text(0.03, 0.03, f"{score:.1f} dB", transform=ax.transAxes, **kw)
        if i == 0:
            name = "Ground truth" if c == "gt" else label(c)
            ax.set_title(textwrap.fill(name, 12), fontsize=FONT_PT)
        if j == 0:
            ax.set_ylabel(textwrap.fill(r, 14), fontsize=FONT_PT)
    _finish(fig, outputs, pad=0.3)


def fig_damping(
    damping: Mapping[str, Mapping[tuple[str, str], object]],
    trees: Sequence[str],
    configs: Sequence[str],
    zeta_true: float,
    outputs: Sequence[str | Path],
    zeta_bound: float | None = None,
) -> None:
    """fig_damping: the recovered damping ratios (left) and decay rates (right) per part.

    Args:
        damping: each prior's ``DampingResult`` per ``(tree, config)``, by model id in drawing
            order: ours' (filled markers), then the others' (hollow markers).
        trees: the trees, in column order.
        configs: the configurations, in column order.
        zeta_true: the testbed's damping ratio.
        outputs: the files to write (PDF, PNG).
        zeta_bound: the largest zeta the fit may take (``models.ours.zeta``); None: no bound.

    Raises:
        KeyError: naming a ``(tree, config)`` (and model) without a result.
    """
    fig, ((a0, a1),) = _axes(1, 2, 3.6)
    tree_colors = dict(zip(trees, ["tab:green", "tab:blue", "tab:red", "tab:purple"]))
    markers = dict(zip(configs, ["o", "s", "^", "D"]))
    models = list(damping)
    per_tree, allw = len(configs) * len(models), []
    for (i, t), (j, c), (k, model) in product(*map(enumerate, (trees, configs, models))):
        if (t, c) not in damping[model]:
            who = "" if model == PAPER_MODEL else f" of {model}"
            raise KeyError(f"fig_damping: no damping result{who} for ({t}, {c})")
        d = damping[model][(t, c)]
        pos = i * (per_tree + 1) + j * len(models) + k  # a gap between trees
        jitter = np.random.default_rng(pos).uniform(-0.2, 0.2, len(d.zeta))  # display
        tc = tree_colors[t]  # the first prior filled, the others hollow in the tree's colour
        look = {"color": tc} if k == 0 else {"facecolors": "none", "edgecolors": tc}
        a0.scatter(pos + jitter, d.zeta, s=7, marker=markers[c], alpha=0.5, **look)
        a0.plot([pos - 0.35, pos + 0.35], [d.median_zeta] * 2, color="k", lw=1.5)
        a1.scatter(d.omega, d.gamma, s=9, marker=markers[c], alpha=0.6, **look)
        allw.append(d.omega)
    a0.axhline(zeta_true, color="k", ls="--", lw=0.8)
    if zeta_bound is not None:
        a0.axhline(zeta_bound, color="0.4", ls=":", lw=1.0)
    a0.set_xticks([i * (per_tree + 1) + (per_tree - 1) / 2 for i in range(len(trees))])
    a0.set_xticklabels(trees, fontsize=FONT_PT)
    zeta = r"$\hat\zeta_p$ (damping ratio, no unit)"
    _texts(a0, "damping ratio per part (bar: median)", ylabel=zeta)
    w = np.concatenate(allw)
    grid = np.geomspace(w.min() * 0.9, w.max() * 1.1, 50)
    a1.plot(grid, zeta_true * grid, "k--", lw=1)
    a1.set(xscale="log", yscale="log")
    for axis in (a1.xaxis, a1.yaxis):
        plain_log(axis)
    gamma = r"$\hat\gamma_p = \hat\zeta_p\hat\omega_p$ (1/s)"
    _texts(a1, "decay rate against natural frequency", r"$\hat\omega_p$ (rad/s)", gamma)
    # one key for both panels, below them: colour = tree, marker = configuration, fill = prior
    grey = "0.35"
    handles = [Patch(color=tree_colors[t], label=t) for t in trees]
    handles += [
        Line2D([], [], ls="", marker=markers[c], color=grey, label=c, markersize=5) for c in configs
    ]
    # the prior's key is a swatch, not a marker: a filled circle would also read as a config's
    for m in models:
        filled = m == models[0]
        key = label(m) + (": filled markers" if filled else ": hollow markers")
        handles.append(Patch(facecolor=grey if filled else "none", edgecolor=grey, label=key))
    truth = rf"truth $\zeta$ = {zeta_true} ($\gamma = \zeta\omega$)"
    handles.append(Line2D([], [], color="k", ls="--", label=truth))
    if zeta_bound is not None:
        bound = rf"fitting bound $\zeta$ = {zeta_bound:g}"
        handles.append(Line2D([], [], color="0.4", ls=":", label=bound))
    _finish(fig, outputs, key=handles, top=0.15)


def _seed_mean(df: pd.DataFrame, by: list[str], cols: Sequence[str]) -> pd.DataFrame:
    """Mean and sd (ddof 1; 0 with one seed) of ``cols`` over seeds per ``by`` group, as columns
    <col> and <col>_sd, groups in first-seen order."""
    g = df.groupby(by, sort=False)
    out = g[list(cols)].mean()
    sd = g[list(cols)].std(ddof=1).fillna(0.0).add_suffix("_sd")
    rest = g[[c for c in df.columns if c not in (*by, *cols, "seed")]].first()
    return pd.concat([out, sd, rest], axis=1).reset_index()


def _seed_errorbar(ax, g: pd.DataFrame, x: str, y: str, bars: bool, xbars: bool = True, **style):
    """``y`` against ``x`` of ``_seed_mean``'s rows, the seeds' sd as error bars (``bars``: more
    than one seed; ``xbars``: on ``x`` too)."""
    xerr, yerr = (g[f"{x}_sd"] if bars and xbars else None), (g[f"{y}_sd"] if bars else None)
    ax.errorbar(g[x], g[y], yerr=yerr, xerr=xerr, capsize=2, **style)


def _save_sweep(fig, axes, head: str, n_seeds: int, outputs: Sequence[str | Path]) -> None:
    """Key a sweep's first panel, title it ``head`` and the seeds its points are the mean of
    (closing ``head``'s parenthesis), and save it."""
    axes[0].legend(fontsize=7)
    seeds = f"; mean +- sd over {n_seeds} training seeds" if n_seeds > 1 else "; one seed"
    _finish(fig, outputs, f"{head}{seeds})", title_pt="large")


def fig_speed_accuracy(
    df: pd.DataFrame, outputs: Sequence[str | Path], null: Mapping[str, float] | None = None
) -> None:
    """fig_speed_accuracy: PSNR and recovery error against wall time, a line per knob.

    Args:
        df: [`sweep.collect`][physgs.experiments.sweep.collect] (one row per seed, knob and
            value).
        outputs: the paths to write.
        null: [`null_level`][physgs.experiments.sweep.null_level]: the untrained null's median and
            the central 95% of its draws, drawn on the recovery panel (a point inside: chance).
    """
    n_seeds = df["seed"].nunique()
    pct = df.assign(rel_pct=100 * df["rel_err"])
    m = _seed_mean(pct, ["knob", "value"], ("wall_s", "psnr_time", "rel_pct"))
    fig, (axes,) = _axes(1, 2, 4, width=10)
    colors = {k: f"C{i}" for i, k in enumerate(sorted(m["knob"].unique()))}
    ylabels = ("PSNR, time split (dB)", "median rel. error of omega, trusted parts (%)")
    panels = tuple(zip(axes, ("psnr_time", "rel_pct"), ylabels))
    for knob, g in m.groupby("knob", sort=False):
        g = g.sort_values("value")
        for ax, col, _ in panels:
            style = dict(fmt="-o", ms=3.5, lw=1.0, color=colors[knob], label=knob)
            _seed_errorbar(ax, g, "wall_s", col, n_seeds > 1, **style)
            kw = dict(fontsize=6, xytext=(3, 3), textcoords="offset points", color=colors[knob])
            for v, x, y in zip(g["value"], g["wall_s"], g[col]):
                ax.annotate(str(int(v)), (x, y), **kw)
    base = m[m["is_base"]].iloc[0]
    for ax, col, ylabel in panels:
        ax.plot([base["wall_s"]], [base[col]], "k*", ms=11, label="profile setting")
        ax.set(xscale="log", xlabel="wall time per point (s, log)", ylabel=ylabel)
        ax.grid(alpha=0.3)
    if null is not None and np.isfinite(null.get("median", np.nan)):
        median = f"untrained null, K={null.get('K', '?')} (median)"
        axes[1].axhline(100 * null["median"], color="0.3", ls="--", lw=1.0, label=median)
        band = f"null: central 95% of {null['draws']} draws"
        low, high = 100 * null["low"], 100 * null["high"]
        axes[1].axhspan(low, high, color="0.6", alpha=0.25, lw=0, label=band)
        axes[1].legend(fontsize=7)
    head = f"Speed-accuracy trade, ours on the {df['tree'].iloc[0]} tree (one knob at a time"
    _save_sweep(fig, axes, head, n_seeds, outputs)


def fig_fit_curve(df: pd.DataFrame, outputs: Sequence[str | Path]) -> None:
    """fig_fit_curve ([`physgs.experiments.fit_curve`][physgs.experiments.fit_curve]): a row of
    three panels per tree, one line per model (a ``<field>@window`` series: open diamonds).

    Args:
        df: [`fit_curve.collect`][physgs.experiments.fit_curve.collect] (one row per seed, model
            and budget).
        outputs: the paths to write.
    """
    panels = (
        ("iterations", "fit", "training iterations (log)", "PSNR, trained frames (dB)"),
        ("iterations", "time", "training iterations (log)", "PSNR, time split (dB)"),
        ("train_s", "fit", "training wall time (s, log)", "PSNR, trained frames (dB)"),
    )
    n_seeds = df["seed"].nunique()
    trees = list(dict.fromkeys(df["tree"]))
    fig, grid = _axes(len(trees), len(panels), 3.8 * len(trees), width=13)
    refs = {"static": ("0.55", "--"), **{r: ("k", ":") for r in REFERENCE_NAMES}}
    for tree, axes in zip(trees, grid):
        t = _seed_mean(df[df["tree"] == tree], ["model", "iterations"], ("fit", "time", "train_s"))
        prof = t[t["is_profile"]].set_index("model")
        budgets = sorted(t["iterations"].unique())
        row = f"{tree}: " if len(trees) > 1 else ""
        for ax, (x, y, xlabel, ylabel) in zip(axes, panels):
            for m, g in t[~t["model"].isin(refs)].groupby("model", sort=False):
                g = g.sort_values("iterations")
                base, _, variant = m.partition("@")  # <field>@window: the diagnostic series
                fmt, mfc, ms = ("D", "none", 6) if variant else ("-o", None, 3.5)
                lw = 1.6 if m == PAPER_MODEL else 1.0
                lab = label(base) + (f" ({variant} time)" if variant else "")
                look = dict(fmt=fmt, mfc=mfc, ms=ms, color=COLORS.get(base), lw=lw, label=lab)
                # no x error bars on the budgets themselves (no spread)
                _seed_errorbar(ax, g, x, y, n_seeds > 1, x != "iterations", **look)
                # the profile's star in its line's colour (a @window series: its field's)
                p = g[g["is_profile"]]
                ax.plot(p[x], p[y], "*", ms=10, color=COLORS.get(base))
            for m, (c, ls) in refs.items():
                if m in prof.index:
                    ax.axhline(prof.loc[m, y], color=c, ls=ls, lw=1.0, label=label(m))
            ax.set(xscale="log", xlabel=xlabel, ylabel=row + ylabel)
            if x == "iterations":  # tick the budgets themselves, not powers of ten
                ax.set_xticks(budgets)
            # seconds span under a decade: 1-2-5 ticks as plain numbers, minor labels overlap
            plain_log(ax.xaxis, ticks=x != "iterations")
            ax.grid(alpha=0.3)
    where = f"the {trees[0]} tree" if len(trees) == 1 else "each tree (a row each)"
    _save_sweep(fig, grid[0], f"Fit curve on {where} (star: the profile's budget", n_seeds, outputs)
