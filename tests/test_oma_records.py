"""The SSI model a record can carry (issue 58): the order bound is the one pyOMA-2 itself can
take (its ``SSI_fast`` is the oracle), and a video that gives fewer channels than
``oma/components`` stops before SSI, naming the key, the cells and the numbers."""

from __future__ import annotations

import numpy as np
import pytest

from physgs.oma.channels import FlowSettings
from physgs.oma.run import OMASettings, identify_video
from physgs.oma.ssi import RecordError, SSISettings, identify_records
from test_oma import _textured_video

BR = 7


def _records(n_channels: int) -> list[np.ndarray]:
    rng = np.random.default_rng(n_channels)
    return [rng.standard_normal((60, n_channels)).cumsum(axis=0) for _ in range(2)]


@pytest.mark.parametrize("n_channels", [1, 2, 3])
def test_the_order_bound_is_what_pyoma2_can_carry(n_channels):
    from pyoma2.functions import ssi

    bound = (BR - 1) * n_channels  # even for BR = 7: a multiple of order_step
    ys = _records(n_channels)
    ok = SSISettings(block_rows=BR, order_max=bound, order_step=2, min_stable=2)
    assert identify_records(ys, 24.0, ok).stab.orders[-1] == bound
    yt = ys[0].T - ys[0].mean(axis=0)[:, None]  # [C, T]
    H = ssi.build_hank(Y=yt, Yref=yt, br=BR, method="cov")[0]
    with pytest.raises(np.linalg.LinAlgError):  # the oracle: pyOMA-2 one step above the bound
        ssi.SSI_fast(H, BR, bound + 2, step=2)
    high = SSISettings(block_rows=BR, order_max=bound + 2, order_step=2, min_stable=2)
    with pytest.raises(RecordError) as e:
        identify_records(ys, 24.0, high)
    assert e.value.key == "oma/ssi/order_max" and f"= {bound}," in e.value.msg, e.value.msg


def test_a_video_of_one_cell_stops_naming_order_max_cell_px_and_the_numbers():
    t = np.arange(60)
    shifts = np.stack([0.8 * np.sin(t / 2.0), 0.5 * np.cos(t / 3.0)], axis=1)  # [T, 2] px
    video = _textured_video(shifts)  # 64 px: one 64-px cell, a quarter of it foreground
    s = OMASettings(
        FlowSettings(cell_px=64, min_fg=0.2),
        4,
        SSISettings(block_rows=12, order_max=24, order_step=2),
        (0.1, 10.0),
    )
    with pytest.raises(RecordError) as e:
        identify_video([video], [1, 1, 1], 24.0, s)
    msg = str(e.value)
    assert e.value.key == "oma/ssi/order_max", msg
    for part in (
        "= 24 exceeds",
        "11 x 2 = 22",
        "1 cell(s) of oma/flow/cell_px = 64 px",
        "oma/flow/min_fg = 0.2",
        "2 channels",
        "oma/components = 4",
    ):
        assert part in msg, msg
