"""The unit of time that enters a field's Fourier time encoding (torch-free: the config checks
and the planner read it).

The paper fixes the band counts (4 for the MLP, 6 for the full field), not the unit of time.
Deformable-3DGS normalises time to [0, 1] over its sequence; over a 12.5 s window the MLP's 4
bands then top out at 0.32 Hz, below every bone's natural frequency (0.35-1.5 Hz). A field's
``time_top_hz`` names the top band's frequency in Hz instead, which reads the same whatever the
frame rate or window.
"""

from __future__ import annotations


#: ``time_top_hz`` value that keeps Deformable-3DGS's convention: time normalised to [0, 1] over
#: the training window, whatever its length (the top band then sits at 2^(bands-2) / window Hz).
WINDOW_TIME = "window"


def top_band_hz(bands: int, time_scale: float, window_s: float) -> float:
    """Frequency (Hz) of the highest time band when ``fourier`` encodes ``time_scale * t_norm``.

    t_norm = t / window_s runs 0..1 over the training window; band k is sin(2^k pi x), i.e.
    2^(k-1) cycles per unit of x.

    Args:
        bands: time bands (>= 1).
        time_scale: the factor on t_norm.
        window_s: the training window's length, s.

    Returns:
        The top band's frequency, Hz.

    Raises:
        ValueError: for ``bands`` < 1.
    """
    if bands < 1:
        raise ValueError(f"top_band_hz: a time encoding with {bands} bands has no top band")
    return 2.0 ** (bands - 2) * time_scale / window_s


def time_scale_for(top_hz: float | str, bands: int, window_s: float) -> float:
    """Factor on t_norm before the encoding that puts the top time band at ``top_hz`` (Hz).

    The top band's frequency reads the same whatever the frame rate or window, which a bare
    factor would not.

    Args:
        top_hz: a positive frequency in Hz, or ``WINDOW_TIME`` (factor 1: Deformable-3DGS's
            window-normalised time).
        bands: time bands (0 bands: factor 1, nothing is encoded).
        window_s: the training window's length t_norm is normalised by, s.

    Returns:
        The factor (dimensionless).

    Raises:
        ValueError: for a ``top_hz`` that is neither positive nor ``WINDOW_TIME``.
    """
    if top_hz == WINDOW_TIME or bands == 0:
        return 1.0
    if isinstance(top_hz, str) or not top_hz > 0:
        raise ValueError(
            f"time_top_hz must be a positive frequency (Hz) or {WINDOW_TIME!r}, got {top_hz!r}"
        )
    return float(top_hz) / top_band_hz(bands, 1.0, window_s)
