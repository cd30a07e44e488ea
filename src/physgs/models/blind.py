"""Ours with a forcing learned from the video instead of the measured wind.

Every part keeps ours' oscillator (omega_p, zeta_p, gain_p, axis, pivot, rigid rotation); the
drive gain_p * (v(t)^2 - vbar^2) of the observed wind is replaced by gain_p * f(t), one series
shared by every part and learned with them from the training video:

    f(t) = normalise( sum_{j=1..J} a_j cos(2 pi j t / S) + b_j sin(2 pi j t / S) )

over the S seconds of the lead-in and the training window (L + n_train samples), band-limited
to j / S <= ``forcing_hz``, centred and divided by its RMS over those samples: its scale is
fixed, so a gain and the forcing cannot trade (doubling f would just be undone), and the gain's
raw value stays, as in ours, roughly the quasi-static swing in radians (gain = raw x
omega_init^2). The lead-in is kept so the window starts from the oscillators' steady response,
as ours' does; the lead-in's part of f is only constrained through that state.

The response is linear and time-invariant in the forcing samples (RK4 from rest, the forcing
linear between samples), so theta_p = h_p * f, a causal convolution with the part's response
h_p to a unit sample at sample 0, computed by ours' integrator (``integrate_forcing``,
differentiable in omega, zeta, gain) and convolved by FFT (differentiable in f).

The model never reads the wind: ``part_theta(wind)`` and ``deform`` ignore it (a NaN series gives
the same result), and it has no forcing beyond the training window or under another wind:
asking for a frame past the window raises ``ForcingNotDefined``, which an evaluation must report
as "not defined", never as a score.
"""

from __future__ import annotations

import math

import numpy as np
import torch
from torch import nn

from physgs.models.undefined import NotDefined
from physgs.models.oscillator import integrate_forcing
from physgs.models.ours import OscillatorPrior


class ForcingNotDefined(NotDefined, ValueError):
    """The learned forcing covers the training window of the training condition only."""


def harmonics(n_samples: int, fps: float, forcing_hz: float) -> np.ndarray:
    """[J] frequencies (Hz) j / S, j = 1..J, up to ``forcing_hz`` (S = n_samples / fps).

    Args:
        n_samples: samples of the span (lead-in plus training window).
        fps: frame rate, frames/s.
        forcing_hz: the highest harmonic allowed, Hz.

    Returns:
        [J] frequencies, Hz.

    Raises:
        ValueError: when ``forcing_hz`` is below the lowest harmonic 1 / S.
    """
    span = n_samples / float(fps)
    J = int(math.floor(forcing_hz * span))
    if J < 1:
        raise ValueError(
            f"models/blind/forcing_hz = {forcing_hz} Hz is below 1 / {span:.2f} s, the lowest "
            "harmonic of the lead-in and training window"
        )
    return np.arange(1, J + 1) / span


def forcing_series(coef: torch.Tensor, basis: torch.Tensor) -> torch.Tensor:
    """Unit-RMS, zero-mean f [N] from coefficients [2J] over the basis [2J, N].

    Args:
        coef: [2J] coefficients.
        basis: [2J, N] the cosine and sine basis.

    Returns:
        [N] the forcing, zero mean and unit RMS.
    """
    f = coef @ basis  # [N]
    f = f - f.mean()
    return f / torch.sqrt((f * f).mean() + 1e-24)


def causal_convolve(r0: torch.Tensor, h: torch.Tensor, f: torch.Tensor) -> torch.Tensor:
    """theta [K, N] = f[0] r0 + sum_{1 <= s <= t} h[k, t - s] f[s] (FFT).

    The integrator's forcing is linear between samples, so a unit sample s >= 1 is a hat over
    [s - 1, s + 1] whose response is h [K, N] shifted by s (h[t] = the response to a unit
    sample 1, read at t + 1), while sample 0 is half a hat, with response r0 [K, N].

    Args:
        r0: [K, N] the response to a unit sample 0, rad.
        h: [K, N] the response to a unit sample 1, read one step later, rad.
        f: [N] the forcing samples.

    Returns:
        [K, N] theta, rad.
    """
    N = f.shape[-1]
    n = 2 * N
    f1 = torch.cat([f.new_zeros(1), f[1:]])
    rest = torch.fft.irfft(torch.fft.rfft(h, n=n) * torch.fft.rfft(f1, n=n), n=n)[..., :N]
    return f[0] * r0 + rest


class BlindOscillatorPrior(OscillatorPrior):
    """Ours driven by a learned band-limited forcing shared by every part (module docstring)."""

    name = "ours_blind"  # also ours_chain_blind: the chained prior's options, this forcing
    use_wind = False

    def __init__(self, ctx, canonical_cfg: dict, *, forcing_hz: float, seed: int = 0, **kw):
        """Ours' oscillators and a learned forcing series of the lead-in and training window.

        Args:
            ctx (ModelContext): the observed-dataset facts.
            canonical_cfg: keyword arguments of the canonical set (config ``models.canonical``).
            forcing_hz: the forcing's band limit, Hz (harmonics j / S <= forcing_hz).
            seed: seeds the forcing's starting coefficients and ours' k-means.
            **kw (Any): ours' options ([OscillatorPrior][physgs.models.ours.OscillatorPrior]); the
                search over omega is refused.

        Raises:
            ValueError: a search over omega is asked for.
        """
        super().__init__(ctx, canonical_cfg, seed=seed, **kw)
        if self.search is not None:
            raise ValueError("the blind prior has no search over omega (models/omega_search)")
        self.n_samples = int(self.lead_in + self.n_train)  # lead-in + training window
        freqs = harmonics(self.n_samples, self.fps, forcing_hz)  # [J] Hz
        t = np.arange(self.n_samples) / float(self.fps)
        ph = 2 * np.pi * freqs[:, None] * t[None, :]  # [J, N]
        self.register_buffer(
            "forcing_basis", torch.tensor(np.concatenate([np.cos(ph), np.sin(ph)]))
        )  # [2J, N] float64
        g = torch.Generator().manual_seed(int(seed))
        # a seeded start: a zero series has no direction to normalise
        self.forcing_coef = nn.Parameter(torch.randn(2 * freqs.size, generator=g).double())
        # the forcing has unit RMS: the gain's raw value is the quasi-static swing in rad
        self.gain_scale = torch.tensor(float(self.bounds.omega_init**2))
        unit = np.zeros(self.n_samples + 1)
        unit[1] = 1.0
        self.register_buffer("unit1", torch.tensor(unit), persistent=False)
        self.register_buffer("unit0", torch.tensor(unit[1:]), persistent=False)

    def forcing(self) -> torch.Tensor:
        """f [L + n_train], unit RMS, over the lead-in and the training window.

        Returns:
            [L + n_train] the learned forcing, dimensionless.
        """
        return forcing_series(self.forcing_coef, self.forcing_basis)

    def part_theta(self, wind=None, upto: int | None = None) -> torch.Tensor:
        """theta [K, L + n_train] (rad) under the learned forcing; ``wind`` is ignored.

        Args:
            wind (Any): ignored.
            upto: with autograd, only samples [0, upto) (at most L + n_train): the responses and
                the convolution are causal, so these are the whole series' first ``upto``
                columns to rounding (a training iteration needs one frame). None (and always
                without autograd): the whole window.

        Returns:
            [K, L + n_train] part angles, rad (frozen parts 0); [K, upto] when ``upto`` is given
                with autograd on.
        """
        m = self.n_samples
        if upto is not None and torch.is_grad_enabled():
            m = max(1, min(int(upto), m))
        om, ze, g = self.omega.double(), self.zeta.double(), self.gain.double()
        r0, r1 = (
            integrate_forcing(
                om, ze, g, u, self.dt, self.substeps, guard=self.guard, backend="auto"
            )
            for u in (self.unit0[:m], self.unit1[: m + 1])
        )  # [K, m] the response to a unit sample 0, [K, m + 1] to a unit sample 1
        theta = causal_convolve(r0, r1[:, 1:], self.forcing()[:m]).to(self.omega_raw.dtype)
        if bool(self.frozen.any()):
            theta = torch.where(self.frozen[:, None], torch.zeros_like(theta), theta)
        return theta

    def deform(self, frame_idx: int, wind: torch.Tensor):
        """The Gaussians at frame ``frame_idx`` of the training window (the wind is not read).

        Args:
            frame_idx: recorded frame, 0 .. n_train - 1.
            wind: ignored (any [L+F] series, NaN included).

        Returns:
            (GaussianState): The Gaussians at the frame (the oscillator prior's deformation).

        Raises:
            ForcingNotDefined: the frame lies beyond the training window.
        """
        if frame_idx >= self.n_train:
            raise ForcingNotDefined(
                f"ours_blind: frame {frame_idx} is beyond the training window (frames 0 .. "
                f"{self.n_train - 1}): the learned forcing is not defined there"
            )
        return super().deform(frame_idx, wind)

    def defined(self, frame_idx: int, condition: int) -> bool:
        """Only the training window of the training condition (the forcing's span).

        Args:
            frame_idx: recorded frame, 0-based.
            condition: wind condition index.

        Returns:
            True for condition 0 and 0 <= frame_idx < n_train.
        """
        return int(condition) == 0 and 0 <= int(frame_idx) < self.n_train

    def _check(self, frame_idx: int, wind: torch.Tensor) -> None:  # the wind is not read
        if not 0 <= frame_idx < self.n_train:
            raise ForcingNotDefined(
                f"ours_blind: frame {frame_idx} is outside the training window (0 .. "
                f"{self.n_train - 1}): the learned forcing is not defined there"
            )

    def deformation_param_groups(self, lr: dict) -> list[dict]:
        """Ours' physics and pivot groups, the forcing's coefficients added to the physics group.

        Args:
            lr: config ``train.lr``.

        Returns:
            The parameter groups.
        """
        groups = super().deformation_param_groups(lr)
        groups[0]["params"] = [*groups[0]["params"], self.forcing_coef]
        return groups
