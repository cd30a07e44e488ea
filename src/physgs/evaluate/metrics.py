"""Image metrics: PSNR per frame and silhouette centroids (pixels)."""

from __future__ import annotations

import numpy as np


def to_float_image(img: np.ndarray) -> np.ndarray:
    """uint8 images -> float64 in [0, 1]; float images are checked to lie in [0, 1]."""
    img = np.asarray(img)
    if img.dtype == np.uint8:
        return img.astype(np.float64) / 255.0
    if not np.issubdtype(img.dtype, np.floating):
        raise TypeError(f"image dtype {img.dtype} is neither uint8 nor float; convert it first")
    out = img.astype(np.float64)
    if not np.all(np.isfinite(out)):
        raise ValueError("image contains NaN/inf; the renderer produced invalid pixels")
    if out.min() < -1e-6 or out.max() > 1 + 1e-6:
        raise ValueError(
            f"float image outside [0, 1] (min {out.min():.4g}, max {out.max():.4g}); "
            "clip or rescale the render before scoring"
        )
    return np.clip(out, 0.0, 1.0)


def psnr(pred: np.ndarray, gt: np.ndarray) -> np.ndarray:
    """PSNR in dB with data range 1 over whole images (background included).

    pred, gt: [..., H, W, 3] uint8 or float in [0, 1]; leading axes are frames.
    Returns [...] (a 0-d array for one image). Identical images give +inf.
    """
    p, g = to_float_image(pred), to_float_image(gt)
    if p.shape != g.shape:
        raise ValueError(f"psnr: prediction shape {p.shape} != ground-truth shape {g.shape}")
    mse = np.mean((p - g) ** 2, axis=(-3, -2, -1))
    with np.errstate(divide="ignore"):
        return -10.0 * np.log10(mse)


def silhouette_centroid(weight: np.ndarray) -> np.ndarray:
    """Centroid (x, y) in pixels of a silhouette: bool mask or soft alpha [H, W] in [0, 1].

    Pixel (row i, col j) has its centre at (j + 0.5, i + 0.5) (camera.py convention). A soft
    alpha is used as weights, so a faded canopy still has a defined centroid.
    Raises ValueError on an empty silhouette (nothing rendered: the centroid is undefined).
    """
    w = np.asarray(weight, dtype=np.float64)
    if w.ndim != 2:
        raise ValueError(f"silhouette must be [H, W], got shape {w.shape}")
    total = w.sum()
    if not total > 0:
        raise ValueError(
            "empty silhouette: nothing covers the image, so its centroid is undefined; "
            "check the render (all Gaussians transparent or off-screen?)"
        )
    ys, xs = np.indices(w.shape, dtype=np.float64)
    return np.array([(w * (xs + 0.5)).sum() / total, (w * (ys + 0.5)).sum() / total])


def centroid_error(alpha_pred: np.ndarray, mask_gt: np.ndarray) -> float:
    """Canopy-centroid error in pixels: |centroid(rendered alpha) - centroid(ground-truth mask)|.

    alpha_pred: [H, W] float in [0, 1] (accumulated alpha of the render); mask_gt: [H, W] bool.
    """
    if np.shape(alpha_pred) != np.shape(mask_gt):
        raise ValueError(f"alpha shape {np.shape(alpha_pred)} != mask shape {np.shape(mask_gt)}")
    return float(np.linalg.norm(silhouette_centroid(alpha_pred) - silhouette_centroid(mask_gt)))


def ceiling_fraction(fit, static, ceiling):
    """(fit - static) / (ceiling - static): the fraction of the true-motion ceiling's PSNR gain
    over the static pose that a model reaches (dB in, unitless out; arrays broadcast). NaN where
    the ceiling does not beat the static pose (no gain to measure against)."""
    fit, static, ceiling = (np.asarray(x, dtype=np.float64) for x in (fit, static, ceiling))
    gain = ceiling - static
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(gain > 0, (fit - static) / gain, np.nan)
