"""A stray pole cannot drag a mode's frequency (issue 58): the stabilisation diagram's stable
poles of one mode, with a chain of stray poles beside them close enough to be clustered with it,
give the mode the frequency most of its poles agree on. Oracle: the poles placed by hand."""

from __future__ import annotations

import numpy as np

from physgs.oma import ssi
from physgs.oma.ssi import SSISettings

#: the function that turns a stabilisation diagram into modes (the behaviour tested, not how
#: it clusters)
modes_of = ssi.group_stable_poles


def test_a_chain_of_stray_poles_does_not_drag_the_mode_frequency():
    orders = 12
    freq = np.full((2, orders), np.nan)  # [P, O] Hz
    freq[0, :9] = 1.0 + 0.001 * np.sin(np.arange(9))  # the mode, at nine orders
    freq[0, 9:] = [1.04, 1.08, 1.12]  # stray poles, each within err_fn of the one before
    xi = np.where(np.isfinite(freq), 0.02, np.nan)
    phi = np.ones((2, orders, 3), np.complex128)
    stable = np.isfinite(freq)
    s = SSISettings(err_fn=0.05, min_stable=5)
    f, *_ = modes_of(freq, xi, phi, stable, s)
    assert f.size >= 1
    near = f[np.argmin(np.abs(f - 1.0))]
    assert abs(near - 1.0) < 0.002, f  # a mean over the chain gives 1.020 Hz
