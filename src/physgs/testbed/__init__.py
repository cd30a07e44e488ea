"""Synthetic testbed: Weber-Penn trees with known per-bone physics, wind, ground-truth frames."""
