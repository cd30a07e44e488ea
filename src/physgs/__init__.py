"""physgs: does a dynamic 3D Gaussian Splatting reconstruction of a wind-driven tree recover
physics, or replay an animation?

Subpackages: ``testbed`` (procedural trees, physics, wind, ground-truth frames), ``render``
(differentiable Gaussian rasterizer), ``models`` (canonical Gaussians, deformation fields, the
oscillator prior), ``train``, ``evaluate``, ``recovery`` (part-to-bone matching, null control),
``report`` (tables and figures); modules ``camera``, ``config``, ``speed_accuracy``.
"""
