"""fig_stabilisation: the output-only analysis' stabilisation diagrams ([`physgs.oma`][],
docs/blind.md), one panel per tree, the bones' true frequencies (drawn, never used to select
anything) in a strip below each."""

from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

from physgs.report.output import Output
from physgs.report.recovery import OMA

#: the panels' frequency axis ends at max(this, 1.2 x the highest bone's), Hz
MIN_FREQ_AXIS_HZ = 3.0


def fig_stabilisation(
    idents: Mapping, omega_bones: Mapping, trees: Sequence, outputs: Sequence, title: str = ""
) -> None:
    """fig_stabilisation: one column per tree, the true frequencies in a strip below.

    Args:
        idents: ``idents[tree]``: its [`Identification`][physgs.oma.run.Identification], the
            stabilisation diagram included.
        omega_bones: ``omega_bones[tree]``: [B] the bones' true natural frequencies, rad/s.
        trees: the trees, one column each.
        outputs: the paths to write (pdf, png).
        title: the figure's title.
    """
    from matplotlib.lines import Line2D

    from physgs.report.figures import _axes, _finish, _texts

    fig, axes = _axes(2, len(trees), 4.6, sharex="col", gridspec_kw={"height_ratios": [4, 1]})
    for j, t in enumerate(trees):
        (ax, strip), st, m = axes[:, j], idents[t].modes.stab, idents[t].modes
        orders = np.broadcast_to(st.orders[None, :], st.freq_hz.shape)
        for poles, size, c in ((~st.stable, 3, "0.75"), (st.stable, 5, "C0")):
            shown = np.isfinite(st.freq_hz) & poles
            ax.scatter(st.freq_hz[shown], orders[shown], s=size, c=c)
        for f in m.freq_hz:
            ax.axvline(f, c="C3", lw=0.8)
        if m.n_modes:
            step = float(np.diff(st.orders[:2])[0]) if st.orders.size > 1 else 1.0
            top = np.full(m.n_modes, float(st.orders.max()) + 2 * step)
            ax.errorbar(
                m.freq_hz, top, xerr=1.96 * np.nan_to_num(m.freq_std), fmt="v", c="C3", ms=4,
                capsize=3, lw=1.0,
            )  # fmt: skip
        _texts(ax, f"{t}: {m.n_modes} modes", ylabel="model order" if j == 0 else None)
        fb = np.asarray(omega_bones[t], float) / (2 * np.pi)
        strip.vlines(fb, 0, 1, colors="k", lw=0.8)
        strip.set(yticks=[], xlim=(0, max(MIN_FREQ_AXIS_HZ, 1.2 * float(fb.max(initial=0.0)))))
        _texts(strip, xlabel="frequency (Hz)", ylabel="bones" if j == 0 else None)
    handles = [
        Line2D([], [], ls="", marker="o", ms=3, c="0.75", label="pole"),
        Line2D([], [], ls="", marker="o", ms=3, c="C0", label="stable pole"),
        Line2D([], [], c="C3", lw=0.8, marker="v", ms=4, label="mode, 95% interval"),
        Line2D([], [], c="k", lw=0.8, label="a bone's true frequency"),
    ]
    _finish(fig, outputs, title, key=handles, dpi=150)


# ---- the declaration -----------------------------------------------------------------------
def _fig_stabilisation_needs(plan, seeds):
    """Per tree, the first seed's identification in the first configuration and the truth of
    that seed's instance."""
    s0, config = int(seeds[0]), next(iter(plan.recovery[OMA]))
    return [need for t in plan.trees for need in (("oma_modes", t, config, s0), ("truth", t, s0))]


def _fig_stabilisation(path, settings, inputs, out):
    from physgs.oma.run import load_identification  # not for the planning imports
    from physgs.testbed.dataset import load_truth

    trees, s0, config = settings["trees"], settings["seeds"][0], settings["configs"][0]
    idents = {t: load_identification(path("oma_modes", t, config, s0)) for t in trees}
    omega = {t: load_truth(path("truth", t, s0)).omega for t in trees}
    title = f"Output-only modal analysis of the training window ({config}, seed {s0})"
    fig_stabilisation(idents, omega, trees, out, title=title)


FIG_STABILISATION = Output(
    "fig_stabilisation",
    "figure",
    _fig_stabilisation_needs,
    _fig_stabilisation,
    settings=lambda cfg: {"configs": list(cfg["oma"]["configs"])},
    seeds="first",
    in_report=lambda plan: bool(plan.recovery.get(OMA)),
)
