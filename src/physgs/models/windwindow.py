"""The wind-history input of the wind-conditioned fields: the preceding seconds of observed wind.

Wind series are indexed by column: column ``lead_in + j`` holds recorded frame j (0-based), so a
window near the start of the recording reads back into the lead-in.
"""

from __future__ import annotations

import numpy as np
import torch


def window_step(seconds: float, n_values: int, fps: int) -> int:
    """Frames between window samples, e.g. 6 s at 24 fps in 48 values -> 3. Must be a whole number.

    Args:
        seconds: the window's length, s.
        n_values: samples in the window.
        fps: frame rate, frames/s.

    Returns:
        The step, frames.

    Raises:
        ValueError: unless seconds * fps / n_values is a positive integer.
    """
    frames = seconds * fps
    step = frames / n_values
    if n_values < 1 or abs(step - round(step)) > 1e-9 or round(step) < 1:
        raise ValueError(
            f"wind window of {seconds} s at {fps} fps is {frames:g} frames, which {n_values} values "
            "do not subsample evenly; choose models.wind_window seconds/values so that "
            "seconds * fps / values is a positive integer"
        )
    return int(round(step))


def window_columns(frame_idx: int, lead_in: int, n_values: int, step: int) -> np.ndarray:
    """Wind columns [n_values] of the window ending at recorded frame ``frame_idx`` (oldest first).

    The last column is lead_in + frame_idx (the wind at t itself); earlier ones go back ``step``
    frames each.

    Args:
        frame_idx: recorded frame, 0-based.
        lead_in: lead-in frames L before recorded frame 0.
        n_values: samples in the window.
        step: frames between samples.

    Returns:
        [n_values] int column indices into a wind [L+F].

    Raises:
        ValueError: if the window reaches before the first recorded wind sample.
    """
    end = lead_in + int(frame_idx)
    cols = end - step * np.arange(n_values - 1, -1, -1)
    if cols[0] < 0:
        raise ValueError(
            f"wind window for frame {frame_idx} needs {step * (n_values - 1)} frames of history but "
            f"only {end} precede it (lead-in {lead_in}); regenerate the testbed with a longer "
            "lead-in (testbed.lead_in_tau) or shorten models.wind_window.seconds"
        )
    return cols


def wind_window(
    wind: torch.Tensor,
    frame_idx: int,
    lead_in: int,
    mean: float,
    std: float,
    n_values: int,
    step: int,
) -> torch.Tensor:
    """Standardised raw-speed history [n_values] ending at frame ``frame_idx``.

    Args:
        wind: [L+F] one condition's observed wind, m/s.
        frame_idx: recorded frame, 0-based.
        lead_in: lead-in frames L.
        mean: the TRAINING condition's mean speed, m/s (so a weaker wind stays weaker after
            standardisation).
        std: the training condition's speed std, m/s.
        n_values: samples in the window.
        step: frames between samples.

    Returns:
        [n_values] (wind - mean) / std, oldest first.

    Raises:
        ValueError: when the window reaches before the series or beyond it.
    """
    cols = window_columns(frame_idx, lead_in, n_values, step)
    if cols[-1] >= wind.shape[-1]:
        raise ValueError(
            f"frame {frame_idx} lies beyond the wind series ({wind.shape[-1]} columns incl. "
            f"lead-in {lead_in}); pass the condition's full observed wind [L+F]"
        )
    return (wind[..., torch.as_tensor(cols)] - mean) / std
