"""The 2D-track control: point tracks from the training video (``track``, no truth),
the tracker scored against truth-projected vertices (``score``, evaluation only), and the same
wind-driven oscillators as ours fitted to the tracks (``fit``)."""
