"""Every numerical threshold of the rasterizer, in one place (as gsplat's ``cuda/_constants.py``).

The PyTorch reference ([`physgs.render.project`][physgs.render.project],
[`physgs.render.reference`][physgs.render.reference]), the numba fast path
([`physgs.render.fast`][physgs.render.fast], [`physgs.render.kernels`][physgs.render.kernels]) and
the gsplat dispatch ([`physgs.render.gsplat_backend`][physgs.render.gsplat_backend]) all read these.
The numba kernels freeze them as globals at compile time and cache the machine code keyed on
``kernels.py`` alone: after editing a value here, touch ``kernels.py`` (or delete its
``__pycache__``) so the fast path recompiles; the fast-vs-reference tests catch a stale cache.

Not here: the near plane, which is per camera (``Camera.near``, default 0.01 world units, as
gsplat's ``near_plane``), and the pixel-centre convention (centres at integer + 0.5).
"""

from __future__ import annotations

# --- projection ----------------------------------------------------------------------------
# px^2 added to both diagonal entries of the 2D covariance: the anti-aliasing dilation of 3DGS
# (a Gaussian never gets thinner than ~half a pixel); gsplat's ``eps2d`` default.
EPS2D = 0.3
# The perspective Jacobian is evaluated at x/z, y/z clamped to the image edge plus this fraction
# of tan(half field of view), tan_fov = 0.5 * W / fx (3DGS ``computeCov2D``: 1.3 * tan_fov;
# gsplat ``persp_proj``: (W - cx) / fx + 0.3 * tan_fov), i.e. 1.3 x the half field of view for
# a centred principal point, so a Gaussian far to the side gets no huge, ill-conditioned blob.
FOV_CLAMP_MARGIN = 0.3
# The floor on a quaternion's norm before normalising lives with the rotations
# (``physgs.rotations.QUAT_NORM_EPS``).

# --- compositing (3DGS, Kerbl et al. 2023; gsplat's ALPHA_THRESHOLD, MAX_ALPHA,
# TRANSMITTANCE_THRESHOLD) ----------------------------------------------------------------------
# A Gaussian whose alpha at a pixel is below this is skipped there (3DGS and gsplat: 1/255,
# invisible in an 8-bit image).
ALPHA_MIN = 1.0 / 255.0
# Its inverse, exactly 255.0 in float64: footprints solve o exp(-sigma / 2) = ALPHA_MIN.
INV_ALPHA_MIN = 1.0 / ALPHA_MIN
# Per-Gaussian alpha is clamped to this (3DGS and gsplat), keeping 1 - alpha >= 0.01 so the
# backward's division by (1 - alpha) stays stable.
ALPHA_MAX = 0.99
# Compositing stops before transmittance would fall below this (3DGS and gsplat;
# = (1 - ALPHA_MAX)^2: two maximally opaque Gaussians end a pixel).
T_MIN = 1e-4
# Tile side in pixels (3DGS BLOCK_X = BLOCK_Y = 16; gsplat's default tile_size).
TILE = 16

# --- conservative footprints (this package's binning; no counterpart in gsplat, which cuts at
# 3 sigma) --------------------------------------------------------------------------------------
# Pixels of slack on each side of the analytic 1/255 bounding box (absorbs rounding of the box).
BOX_SLACK_PX = 1
# Relative (and absolute) widening of the 1/255 contour sigma^2 threshold in the fast kernels,
# so rounding can only add pixels (which the exact alpha test then skips), never drop them.
FOOTPRINT_SLACK = 1e-9
# Pixel-column tolerance when a row's span of that contour is rounded to whole pixels.
ROW_SPAN_TOL = 1e-6
