"""Output-only modal analysis as a method of the pipeline: flow channels against a
known image shift, the mode-to-part rule against constructed shapes, bad settings refused at
config load naming the key, and the identification reading the frames only (never the wind)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from physgs.oma.channels import FlowSettings, flow_channels, principal_channels
from physgs.oma.parts import assign_modes
from test_config import _refused
from workflow_helpers import ROOT


def _textured_video(shifts_px: np.ndarray, size: int = 64) -> np.ndarray:
    """[T, H, W, 3] uint8: a smooth random texture on a white ground, moved by shifts [T, 2] px."""
    import cv2

    rng = np.random.default_rng(0)
    tex = cv2.GaussianBlur(rng.uniform(0, 200, (size, size)), (0, 0), 2.0)
    img = np.full((size, size), 255.0)
    img[16:48, 16:48] = tex[16:48, 16:48]
    frames = []
    for dx, dy in shifts_px:
        m = np.float32([[1, 0, dx], [0, 1, dy]])
        f = cv2.warpAffine(img, m, (size, size), borderValue=255.0, flags=cv2.INTER_CUBIC)
        frames.append(np.repeat(np.clip(f, 0, 255).astype(np.uint8)[..., None], 3, axis=-1))
    return np.stack(frames)


def test_flow_channels_measure_a_known_shift():
    """Every cell inside the square follows the applied sub-pixel shift (Farneback, oracle: the
    warp itself): correlation above 0.98 per cell, and the median error over cells and frames
    under 0.1 px of a 0.8 px swing (polynomial expansion of a blurred texture, 9 px windows)."""
    t = np.arange(12)
    shifts = np.stack([0.8 * np.sin(t / 2.0), 0.5 * np.cos(t / 3.0) - 0.5], axis=1)  # [T, 2]
    ch = flow_channels(_textured_video(shifts), [1, 1, 1], FlowSettings(cell_px=8, min_fg=0.9))
    inner = np.all((ch.cell_xy > 24) & (ch.cell_xy < 40), axis=1)  # away from the square's edge
    assert inner.sum() >= 2
    n = ch.n_cells
    truth = shifts - shifts[0]  # [T, 2] since the first frame
    for axis, off in ((0, 0), (1, n)):
        got = ch.y[:, off + np.flatnonzero(inner)]  # [T, cells]
        for c in range(got.shape[1]):
            assert np.corrcoef(got[:, c], truth[:, axis])[0, 1] > 0.98
        assert np.median(np.abs(got - truth[:, axis : axis + 1])) < 0.1


def test_principal_channels_map_shapes_back():
    rng = np.random.default_rng(1)
    y = rng.normal(size=(200, 3)) @ rng.normal(size=(3, 10))  # rank 3
    z, load = principal_channels(y, 3)
    np.testing.assert_allclose(z @ load, y - y.mean(0), atol=1e-9)
    with pytest.raises(ValueError, match="oma/flow/components"):
        principal_channels(y, 11)


def test_each_part_takes_the_mode_concentrated_on_its_cells():
    """Mode 0 moves cells 0-1 only, mode 1 cells 2-3 (and a little of cell 1): parts {0, 1} and
    {2, 3} take modes 0 and 1; a part with no cell gives no estimate."""
    channel_cell = np.tile(np.arange(4), 2)  # x then y of 4 cells
    shape = np.zeros((2, 8))
    shape[0, [0, 1, 4, 5]] = 1.0
    shape[1, [2, 3, 6, 7]] = 1.0
    shape[1, 1] = 0.2
    pm = assign_modes(
        np.array([0.5, 1.2]), np.array([0.05, 0.08]), shape, channel_cell, np.array([0, 0, 1, 1]), 3
    )
    assert pm.mode_of_part.tolist() == [0, 1, -1]
    np.testing.assert_allclose(pm.omega[:2], 2 * np.pi * np.array([0.5, 1.2]))
    np.testing.assert_allclose(pm.zeta[:2], [0.05, 0.08])
    assert pm.estimated.tolist() == [True, True, False]
    assert pm.mode_part.tolist() == [0, 1]


def test_a_window_too_short_for_the_block_rows_is_refused_at_load():
    msg = _refused(lambda c: c["oma"]["ssi"].update(block_rows=80))
    assert "oma/ssi/block_rows" in msg and "300" in msg


def test_an_order_above_the_components_is_refused_at_load():
    msg = _refused(
        lambda c: c["oma"].update(components=1, ssi={**c["oma"]["ssi"], "order_max": 70})
    )
    assert "oma/ssi/order_max" in msg


def test_identification_reads_the_frames_only():
    """The identifying rule's one input is observed.npz, and its script reads frames, background,
    frame rate and window length from it: never the wind (the rule reads no truth either)."""
    smk = (ROOT / "workflow/rules/oma.smk").read_text()
    rule = smk.split("rule oma_identify:")[1].split("\nrule ")[0]
    inputs = rule.split("input:")[1].split("output:")[0]
    assert re.findall(r"(\w+)=", inputs) == ["observed"]
    script = (ROOT / "workflow/scripts/oma_identify.py").read_text()
    used = set(re.findall(r"obs\.(\w+)", script))
    assert used == {"frames", "n_train", "background", "fps"}, used


def test_more_parts_than_cells_stops_naming_the_key():
    from physgs.oma.parts import cell_parts

    with pytest.raises(ValueError, match="oma/flow/cell_px"):
        cell_parts(np.arange(8.0).reshape(4, 2), 5, seed=0, n_init=1)
    assert cell_parts(np.arange(8.0).reshape(4, 2), 2, seed=0, n_init=1).tolist().count(0) == 2
