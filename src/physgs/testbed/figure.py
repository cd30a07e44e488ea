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
    f_hz = truth.omega / (2 * np.pi)
    fig = plt.figure(figsize=(12, 6.2))
    gs = fig.add_gridspec(2, 6, height_ratios=[1.25, 1])
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
    ax.set_xlabel("downwind (m)")
    ax.set_ylabel("height (m)")
    ax.set_title(f"{tree}: {len(f_hz)} bones, {len(truth.rest_vertices)} vertices")
    fig.colorbar(lc, ax=ax, label="natural frequency (Hz)", shrink=0.8)

    ax = fig.add_subplot(gs[0, 2:4])
    ax.hist(
        f_hz, bins=np.linspace(0.3, 1.55, 26), color="tab:green", edgecolor="k", label="all bones"
    )
    if stats is not None:
        ax.hist(
            f_hz[np.asarray(stats["visible"], bool)],
            bins=np.linspace(0.3, 1.55, 26),
            color="tab:orange",
            edgecolor="k",
            alpha=0.8,
            label=f"own motion >= {stats['visible_threshold_px']:g} px",
        )
        ax.legend(fontsize=7)
    ax.set_xlabel("natural frequency f = omega / 2 pi (Hz)")
    ax.set_ylabel("bones")
    ax.set_title(
        f"min {f_hz.min():.2f}, median {np.median(f_hz):.2f}, max {f_hz.max():.2f} Hz"
        f"; clamped {int(truth.omega_clamped.sum())}"
    )

    ax = fig.add_subplot(gs[0, 4:6])
    L = truth.lead_in_frames
    t = (np.arange(truth.theta.shape[1]) - L) / truth.fps
    tips = truth.tip_vertices[:3]
    for p in tips:
        b = truth.vertex_bone[p]
        ax.plot(t, np.degrees(truth.theta[0, :, b]), lw=0.8, label=f"bone {b} ({f_hz[b]:.2f} Hz)")
    ax.axvline(0, color="k", ls="--", lw=0.8)
    ax.axvline(obs.n_train / obs.fps, color="r", ls=":", lw=0.8)
    ax.set_xlabel("time (s); lead-in < 0, tail after red line")
    ax.set_ylabel("theta (deg)")
    ax.legend(fontsize=7)
    ax.set_title("ground-truth bone angles, training wind")

    panels = [
        (obs.frames[0, 0], "train cam, frame 0"),
        (obs.frames[0, obs.n_train - 1], f"frame {obs.n_train - 1}"),
        (obs.frames[-1, obs.n_train - 1], f"frame {obs.n_train - 1}, {obs.conditions[-1]:.2f} v0"),
        (obs.frames[0, -1], f"tail frame {obs.n_train + obs.n_tail - 1}"),
    ]
    for k in (0, len(obs.heldout_cameras) - 1):
        panels.append((obs.heldout_frames[k, 0], f"azimuth {obs.heldout_azimuths_deg[k]:+.0f} deg"))
    for i, (img, title) in enumerate(panels[:6]):
        ax = fig.add_subplot(gs[1, i])
        ax.imshow(img)
        ax.set_title(title, fontsize=8)
        ax.axis("off")
    if stats is not None:
        fig.suptitle(
            f"{stats['distinct_frequencies']} distinct frequencies, span "
            f"{stats['f_span']:.2f}x; median nearest-bone gap {100 * stats['nearest_bone_gap']:.2f}%; "
            f"median own-motion visibility {stats['visible_px_median']:.2f} px, "
            f"{100 * stats['visible_below_px_fraction']:.0f}% of bones under "
            f"{stats['visible_threshold_px']:g} px; tree spans {100 * stats['height_fill']:.0f}% "
            "of the image height",
            fontsize=9,
            y=0.995,
        )
    fig.tight_layout()
    path = Path(path)
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110)
    finally:
        plt.close(fig)
    return path
