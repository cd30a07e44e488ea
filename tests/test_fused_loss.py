"""The fused photometric loss (one numba pass) against independent oracles: a per-window SSIM
in numpy, the torch ops in float64 under autograd, and central finite differences."""

import numpy as np
import pytest
import torch
from scipy.ndimage import correlate1d

from physgs.train.fused_loss import fused_photometric_loss, gauss_window, loss_terms
from physgs.train.losses import photometric_loss, _photometric_loss_torch


def _images(shape, seed):
    rng = np.random.default_rng(seed)
    a = torch.tensor(rng.random(shape), requires_grad=True)
    b = torch.tensor(np.clip(a.detach().numpy() + 0.2 * rng.standard_normal(shape), 0, 1))
    return a, b


def _ssim_scipy(a, b):
    # Oracle: the 3DGS SSIM from scipy's zero-padded correlations, float64, per channel.
    g = gauss_window(11, 1.5)

    def blur(z):
        return correlate1d(correlate1d(z, g, axis=0, mode="constant"), g, axis=1, mode="constant")

    vals = []
    for c in range(a.shape[2]):
        x, y = a[:, :, c], b[:, :, c]
        mx, my = blur(x), blur(y)
        sxx, syy, sxy = blur(x * x) - mx**2, blur(y * y) - my**2, blur(x * y) - mx * my
        vals.append(
            (2 * mx * my + 1e-4) * (2 * sxy + 9e-4) / ((mx**2 + my**2 + 1e-4) * (sxx + syy + 9e-4))
        )
    return float(np.mean(vals))


@pytest.mark.parametrize("shape", [(32, 32, 3), (7, 9, 1), (33, 20, 3), (12, 40, 2)])
def test_values_and_gradients_equal_the_torch_ops_in_float64(shape):
    a, b = _images(shape, 1)
    weights = (1.0, 0.3, -0.7)  # a mix of the three outputs, so each one's backward is checked
    grads = []
    for f in (fused_photometric_loss, _photometric_loss_torch):
        out = f(a, b, 0.2)
        sum(w * o for w, o in zip(weights, out)).backward()
        grads.append(a.grad.clone())
        a.grad = None
        if f is fused_photometric_loss:
            got = [float(o.detach()) for o in out]
        else:
            want = [float(o.detach()) for o in out]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-13)
    scale = float(grads[1].abs().max())
    np.testing.assert_allclose(grads[0].numpy(), grads[1].numpy(), rtol=0, atol=1e-12 * scale)
    dssim = 1.0 - _ssim_scipy(a.detach().numpy(), b.numpy())
    assert got[2] == pytest.approx(dssim, abs=1e-12)


def test_gradients_against_finite_differences():
    a, b = _images((13, 12, 2), 2)
    assert torch.autograd.gradcheck(
        lambda u: fused_photometric_loss(u, b, 0.3), (a,), eps=1e-6, atol=1e-8
    )


def test_float32_images_are_computed_in_float64():
    a, b = _images((24, 24, 3), 3)
    a32 = a.detach().float().requires_grad_(True)
    b32 = b.float()
    loss, l1, dssim = fused_photometric_loss(a32, b32, 0.2)
    loss.backward()
    assert loss.dtype == torch.float32 and a32.grad.dtype == torch.float32
    # the reference on the same (float32-rounded) pixels, in float64
    a64 = a32.detach().double().requires_grad_(True)
    ref = _photometric_loss_torch(a64, b32.double(), 0.2)
    ref[0].backward()
    ref = [r.detach() for r in ref]
    # the kernel's own float64 results, before the one rounding to the render's dtype
    grads = [np.empty(a32.shape, np.float32) for _ in range(3)]
    l1_64, ssim_64 = loss_terms(
        a32.detach().numpy(), b32.numpy(), gauss_window(11, 1.5), 0.2, *grads
    )
    assert l1_64 == pytest.approx(float(ref[1]), abs=1e-14)
    assert 1.0 - ssim_64 == pytest.approx(float(ref[2]), abs=1e-13)
    assert float(dssim.detach()) == pytest.approx(float(ref[2]), rel=1e-7)
    np.testing.assert_allclose(a32.grad.numpy(), a64.grad.numpy(), rtol=1e-6, atol=1e-12)


def test_identical_images():
    a, _ = _images((16, 16, 3), 4)
    loss, l1, dssim = fused_photometric_loss(a, a.detach(), 0.2)
    loss.backward()
    assert float(l1.detach()) == 0.0 and float(dssim.detach()) == pytest.approx(0.0, abs=1e-14)
    # SSIM is at its maximum and the L1's subgradient at zero difference is 0 (as torch's abs)
    assert float(a.grad.abs().max()) < 1e-14


def test_photometric_loss_takes_the_fused_pass_only_for_a_constant_target():
    a, b = _images((16, 16, 3), 5)
    assert type(photometric_loss(a, b)[0].grad_fn).__name__ == "_FusedPhotometricLossBackward"
    b.requires_grad_(True)
    loss = photometric_loss(a, b)[0]
    loss.backward()
    assert b.grad is not None and float(b.grad.abs().sum()) > 0


def test_bad_input_is_refused():
    a, b = _images((16, 16, 3), 6)
    with pytest.raises(ValueError, match="share shape"):
        fused_photometric_loss(a, b[:, :8])
    with pytest.raises(ValueError, match="must not require a gradient"):
        fused_photometric_loss(a, b.requires_grad_(True))


def test_blur_refuses_scratch_without_its_padding():
    # the blur's loops do not check bounds: a scratch plane without the window's padding must be
    # refused, not written past its end
    from physgs.train.fused_loss import _blur_plane

    src = np.ones((8, 8))
    with pytest.raises(ValueError, match="tmp must be"):
        _blur_plane(src, gauss_window(11, 1.5), np.empty((8, 8)), np.empty((8, 8)))
