"""The stabilisation diagram of one tree's training window, the bones' true frequencies beside it."""

from __future__ import annotations

import numpy as np

from physgs.atomic import atomic_path


def stabilisation_figure(path, ident, omega_bones, title: str = "") -> None:
    """Poles (frequency Hz against model order; filled: stable) with the identified modes as
    vertical lines, each with its 95% frequency interval (+-1.96 sigma) as an error bar above
    the highest order, and the true bone frequencies as ticks in a strip below.

    The truth is drawn, never used to select anything.

    Args:
        path (str | Path): the PNG to write.
        ident (Identification): the identification
            ([`Identification`][physgs.oma.run.Identification]), its stabilisation diagram included.
        omega_bones (ArrayLike): [B] true bone frequencies, rad/s.
        title: the figure's title.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    st = ident.modes.stab
    fig, (ax, ax2) = plt.subplots(
        2, 1, figsize=(6, 4), sharex=True, gridspec_kw={"height_ratios": [4, 1]}
    )
    orders = np.broadcast_to(st.orders[None, :], st.freq_hz.shape)
    ok = np.isfinite(st.freq_hz)
    ax.scatter(st.freq_hz[ok & ~st.stable], orders[ok & ~st.stable], s=4, c="0.75", label="pole")
    ax.scatter(st.freq_hz[st.stable & ok], orders[st.stable & ok], s=6, c="C0", label="stable")
    m = ident.modes
    for f in m.freq_hz:
        ax.axvline(f, c="C3", lw=0.8)
    if m.n_modes:
        top = np.full(m.n_modes, float(st.orders.max()) + 2 * float(np.diff(st.orders[:2])[0]))
        ax.errorbar(
            m.freq_hz,
            top,
            xerr=1.96 * np.nan_to_num(m.freq_std),
            fmt="v",
            c="C3",
            ms=4,
            capsize=3,
            lw=1.0,
            label="mode, 95% interval",
        )
    ax.set_ylabel("model order")
    ax.set_title(f"{title}: SSI-cov of the training window ({ident.modes.n_modes} modes, red)")
    ax.legend(loc="lower right", fontsize=7)  # the error bars run along the top
    fb = np.asarray(omega_bones, float) / (2 * np.pi)
    ax2.vlines(fb, 0, 1, colors="k", lw=0.8)
    ax2.set_yticks([])
    ax2.set_ylabel("bones", fontsize=8)
    ax2.set_xlabel("frequency (Hz)")
    hi = max(3.0, float(fb.max()) * 1.2)
    ax2.set_xlim(0, hi)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120)
    plt.close(fig)
