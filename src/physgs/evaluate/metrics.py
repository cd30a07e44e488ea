"""Image metrics: PSNR per frame and silhouette centroids (pixels)."""

from __future__ import annotations

import numpy as np


def to_float_image(img: np.ndarray) -> np.ndarray:
    """Images as float64 in [0, 1].

    Args:
        img: [..., H, W, C] uint8 (divided by 255) or float already in [0, 1] (round-off beyond
            the range by up to 1e-6 is clipped).

    Returns:
        The images, float64 in [0, 1], same shape.

    Raises:
        TypeError: a dtype other than uint8 or float.
        ValueError: NaN/inf, or float values outside [0, 1].
    """
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
    """PSNR with data range 1 over whole images (background included).

    Args:
        pred: [..., H, W, 3] uint8 or float in [0, 1]; leading axes are frames.
        gt: the ground truth, same shape and conventions.

    Returns:
        [...] PSNR, dB (a 0-d array for one image); identical images give +inf.

    Raises:
        ValueError: the shapes differ, or an image is invalid (see
            [`to_float_image`][physgs.evaluate.metrics.to_float_image]).
    """
    p, g = to_float_image(pred), to_float_image(gt)
    if p.shape != g.shape:
        raise ValueError(f"psnr: prediction shape {p.shape} != ground-truth shape {g.shape}")
    mse = np.mean((p - g) ** 2, axis=(-3, -2, -1))
    with np.errstate(divide="ignore"):
        return -10.0 * np.log10(mse)


def silhouette_centroid(weight: np.ndarray) -> np.ndarray:
    """Centroid of a silhouette, px.

    Pixel (row i, col j) has its centre at (j + 0.5, i + 0.5) (camera.py convention). A soft
    alpha is used as weights, so a faded canopy still has a defined centroid.

    Args:
        weight: [H, W] bool mask or soft alpha in [0, 1].

    Returns:
        [2] (x, y), px (x right, y down).

    Raises:
        ValueError: not [H, W], or an empty silhouette (nothing rendered: the centroid is
            undefined).
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
    """Canopy-centroid error: |centroid(rendered alpha) - centroid(ground-truth mask)|.

    Args:
        alpha_pred: [H, W] float in [0, 1], the render's accumulated alpha.
        mask_gt: [H, W] bool, the ground-truth silhouette.

    Returns:
        The distance, px.

    Raises:
        ValueError: the shapes differ, or either silhouette is empty.
    """
    if np.shape(alpha_pred) != np.shape(mask_gt):
        raise ValueError(f"alpha shape {np.shape(alpha_pred)} != mask shape {np.shape(mask_gt)}")
    return float(np.linalg.norm(silhouette_centroid(alpha_pred) - silhouette_centroid(mask_gt)))


def ceiling_fraction(fit, static, ceiling):
    """The share of the true-motion ceiling's PSNR gain over the static pose a model reaches.

    (fit - static) / (ceiling - static); arrays broadcast.

    Args:
        fit (np.ndarray | float): the model's PSNR, dB.
        static (np.ndarray | float): the static pose's PSNR, dB.
        ceiling (np.ndarray | float): the true-motion ceiling's PSNR, dB.

    Returns:
        (np.ndarray): The fraction (unitless, float64); NaN where the ceiling does not beat the
            static pose (no gain to measure against).
    """
    fit, static, ceiling = (np.asarray(x, dtype=np.float64) for x in (fit, static, ceiling))
    gain = ceiling - static
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(gain > 0, (fit - static) / gain, np.nan)
