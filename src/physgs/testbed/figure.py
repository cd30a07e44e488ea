"""The testbed figure: skeleton coloured by natural frequency, the frequency histogram, and a few
ground-truth frames (training camera, three conditions, and held-out views)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

from physgs.atomic import atomic_path  # noqa: E402
from physgs.testbed.dataset import Observed, Truth  # noqa: E402


def draw(obs: Observed, truth: Truth, tree: str, stats: dict | None = None):
    """The testbed figure of one tree, drawn at the documentation's content width so its text
    reads at ``FONT_PT`` px there (``physgs.report.figures``); see
    [`testbed_figure`][physgs.testbed.figure.testbed_figure].

    Args:
        obs: the tree's observed dataset.
        truth: its ground truth.
        tree: the tree's name (in the title).
        stats: [`testbed_stats`][physgs.testbed.stats.testbed_stats] of the tree, or None.

    Returns:
        (matplotlib.figure.Figure): the figure, open.
    """
    from physgs.report.figures import FONT_PT, PAGE_WIDTH_IN

    fs = FONT_PT
    f_hz = truth.omega / (2 * np.pi)
    # the strip of frames' row no taller than its square frames and their titles
    fig = plt.figure(figsize=(PAGE_WIDTH_IN, 5.9))
    gs = fig.add_gridspec(2, 6, height_ratios=[2.0, 1])
    ax = fig.add_subplot(gs[0, 0:2])
    # side view perpendicular to the swing axis (the plane the bones swing in)
    a = truth.swing_axis
    w = np.cross(a, [0.0, 0.0, 1.0]) * -1  # downwind horizontal direction
    seg = np.stack([truth.bone_head, truth.bone_tail], 1)  # [B, 2, 3]
    xy = np.stack([seg @ w, seg[..., 2]], -1)
    lc = LineCollection(xy, array=f_hz, cmap="viridis", linewidths=1.0 + 60 * truth.bone_radius)
    ax.add_collection(lc)
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_xlabel("downwind (m)", fontsize=fs)
    ax.set_ylabel("height (m)", fontsize=fs)
    ax.set_title(f"{tree}: {len(f_hz)} bones,\n{len(truth.rest_vertices)} vertices", fontsize=fs)
    cb = fig.colorbar(lc, ax=ax, shrink=0.8)
    cb.set_label("natural frequency (Hz)", fontsize=fs)
    cb.ax.tick_params(labelsize=fs)

    ax = fig.add_subplot(gs[0, 2:4])
    bins = np.linspace(0.3, 1.55, 26)
    ax.hist(f_hz, bins=bins, color="tab:green", edgecolor="k")
    title = f"f: min {f_hz.min():.2f}, median {np.median(f_hz):.2f},\nmax {f_hz.max():.2f} Hz"
    title += f"; clamped {int(truth.omega_clamped.sum())}"
    if stats is not None:  # the key is the title: a legend would sit on the bars
        ax.hist(
            f_hz[np.asarray(stats["visible"], bool)],
            bins=bins,
            color="tab:orange",
            edgecolor="k",
            alpha=0.8,
        )
        title += f"\ngreen: all; orange: own motion >= {stats['visible_threshold_px']:g} px"
    ax.set_xlabel("natural frequency f (Hz)", fontsize=fs)
    ax.set_ylabel("bones", fontsize=fs)
    ax.set_title(title, fontsize=fs)

    ax = fig.add_subplot(gs[0, 4:6])
    L = truth.lead_in_frames
    t = (np.arange(truth.theta.shape[1]) - L) / truth.fps
    tips = truth.tip_vertices[:3]
    names = []
    for p, colour in zip(tips, ("tab:blue", "tab:orange", "tab:green")):
        b = truth.vertex_bone[p]
        ax.plot(t, np.degrees(truth.theta[0, :, b]), lw=0.8, color=colour)
        names.append(f"{colour[4:]}: bone {b} ({f_hz[b]:.2f} Hz)")
    ax.axvline(0, color="k", ls="--", lw=0.8)
    ax.axvline(obs.n_train / obs.fps, color="r", ls=":", lw=0.8)
    ax.set_xlabel("time (s); lead-in < 0,\ntail after the red line", fontsize=fs)
    ax.set_ylabel("theta (deg)", fontsize=fs)
    # the key is the title: a legend would sit on the curves
    ax.set_title("bone angles, training wind\n" + "\n".join(names), fontsize=fs)
    for ax in fig.axes:
        ax.tick_params(labelsize=fs)

    panels = [
        (obs.frames[0, 0], "train cam,\nframe 0"),
        (obs.frames[0, obs.n_train - 1], f"frame {obs.n_train - 1}"),
        (obs.frames[-1, obs.n_train - 1], f"frame {obs.n_train - 1},\n{obs.conditions[-1]:.2f} v0"),
        (obs.frames[0, -1], f"tail frame\n{obs.n_train + obs.n_tail - 1}"),
    ]
    for k in (0, len(obs.heldout_cameras) - 1):
        panels.append(
            (obs.heldout_frames[k, 0], f"azimuth\n{obs.heldout_azimuths_deg[k]:+.0f} deg")
        )
    for i, (img, title) in enumerate(panels[:6]):
        ax = fig.add_subplot(gs[1, i])
        ax.imshow(img)
        ax.set_title(title, fontsize=fs)
        ax.axis("off")
    if stats is not None:
        fig.suptitle(
            f"{stats['distinct_frequencies']} distinct frequencies, span "
            f"{stats['f_span']:.2f}x; median nearest-bone gap {100 * stats['nearest_bone_gap']:.2f}%;\n"
            f"median own-motion visibility {stats['visible_px_median']:.2f} px, "
            f"{100 * stats['visible_below_px_fraction']:.0f}% of bones under "
            f"{stats['visible_threshold_px']:g} px; tree spans {100 * stats['height_fill']:.0f}% "
            "of the image height",
            fontsize=fs,
        )
    fig.tight_layout()
    return fig


def testbed_figure(
    obs: Observed, truth: Truth, tree: str, path: Path | str, stats: dict | None = None
) -> Path:
    """Write the figure to ``path`` (PNG, via a temporary file) and return the path.

    Args:
        obs: the tree's observed dataset.
        truth: its ground truth.
        tree: the tree's name (in the title).
        path: the PNG to write.
        stats: [`testbed_stats`][physgs.testbed.stats.testbed_stats] of the tree; when given, the
            skeleton is coloured by how visible each bone's own motion is (pixels) beside its
            frequency, and the headline statistics are printed under the title.

    Returns:
        ``path`` as a ``Path``.
    """
    fig = draw(obs, truth, tree, stats)
    path = Path(path)
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=150, bbox_inches="tight")
    finally:
        plt.close(fig)
    return path
