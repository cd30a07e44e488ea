"""Learned deformation fields: Deformation MLP and Deformable-3DGS, each with or without wind.

Input per Gaussian: Fourier features of its canonical position (normalised to about [-1, 1] by
the canonical bounding box, detached as in Deformable-3DGS) and of time, plus, for the + wind
variants, the standardised 48-value wind history (shared by all Gaussians of a frame).
Time enters the encoding as ``time_scale * t_norm`` (t_norm 0..1 over the training window):
``time_top_hz`` puts the top time band at a frequency in Hz (the paper fixes the band counts, not
the unit of time), or ``"window"`` keeps Deformable-3DGS's window-normalised time, whose 4 bands
top out at 0.32 Hz over a 12.5 s window, below every bone's natural frequency.
Output heads start at zero, so at initialisation every field returns the canonical pose.

``precision: bfloat16`` runs the hidden layers' matmuls under CPU/CUDA autocast in bfloat16 (the
weights, their gradients and Adam stay float32; the inputs and the heads stay float32, so the
offsets keep float32 resolution). On a CPU with native bf16 dot products (AVX-512 BF16 / AMX) the
Deformable-3DGS field's forward + backward runs ~2.4x faster (``benchmarks/field_precision.py``).
"""

from __future__ import annotations

import numpy as np
import torch
from torch import nn

from physgs.models.base import BaseModel, ModelContext
from physgs.models.encoding import fourier, fourier_dim
from physgs.models.timescale import WINDOW_TIME, time_scale_for
from physgs.models.gaussians import GaussianState
from physgs.models.windwindow import wind_window, window_step

HEAD_DIMS = {"dx": 3, "dq": 4, "ds": 3}
PRECISIONS = ("float32", "bfloat16")  # models.<mlp|d3dgs>.precision


def native_bf16() -> bool:
    """Whether this CPU runs bf16 matmuls natively (oneDNN's own probe: AVX-512 BF16 or AMX
    class hardware). Without it autocast emulates them, ~48x slower than float32.

    Returns:
        True where oneDNN reports native bf16 support.
    """
    return bool(
        torch.backends.mkldnn.is_available() and torch.ops.mkldnn._is_mkldnn_bf16_supported()
    )


class DeformationField(nn.Module):
    """ReLU MLP with an optional input skip and zero-initialised linear heads.

    depth hidden layers of ``width``; if ``skip`` is set the network input is concatenated to
    the activations after hidden layer ``skip`` (0-based), as in Deformable-3DGS.
    """

    def __init__(
        self,
        in_dim: int,
        depth: int,
        width: int,
        skip: int | None,
        heads: tuple[str, ...],
        precision: str = "float32",
    ):
        """An MLP with ``depth`` hidden layers of ``width`` ReLU units and the named output heads.

        Args:
            in_dim: input features per Gaussian.
            depth: hidden layers.
            width: units per hidden layer.
            skip: hidden layer (0-based, in [0, depth - 1)) after which the input is
                concatenated, or None.
            heads: output heads among ``dx`` [3], ``dq`` [4], ``ds`` [3].
            precision: ``float32`` or ``bfloat16`` (the hidden layers under autocast).

        Raises:
            ValueError: an unknown precision or a skip layer out of range.
        """
        super().__init__()
        if precision not in PRECISIONS:
            raise ValueError(f"field precision {precision!r}: use one of {PRECISIONS}")
        self.precision = precision
        if skip is not None and not 0 <= skip < depth - 1:
            raise ValueError(f"skip layer {skip} must lie in [0, depth - 1) = [0, {depth - 1})")
        self.skip = skip
        layers = []
        for i in range(depth):
            d_in = (
                in_dim if i == 0 else width + (in_dim if skip is not None and i == skip + 1 else 0)
            )
            layers.append(nn.Linear(d_in, width))
        self.layers = nn.ModuleList(layers)
        self.heads = nn.ModuleDict({h: nn.Linear(width, HEAD_DIMS[h]) for h in heads})
        for h in self.heads.values():
            nn.init.zeros_(h.weight)
            nn.init.zeros_(h.bias)

    def forward(self, x: torch.Tensor) -> dict[str, torch.Tensor]:  # x [N, in_dim] float32
        """The heads' outputs for the inputs ``x``.

        Args:
            x: [N, in_dim] float32 features.

        Returns:
            head name -> [N, dim] float32 (``dx`` [N, 3] scene units, ``dq`` [N, 4], ``ds`` [N, 3]).
        """
        h = x
        with torch.autocast(
            x.device.type, dtype=torch.bfloat16, enabled=self.precision == "bfloat16"
        ):
            for i, layer in enumerate(self.layers):
                h = torch.relu(layer(h))
                if self.skip is not None and i == self.skip:
                    h = torch.cat([x.to(h.dtype), h], dim=-1)
        h = h.to(x.dtype)  # the heads (offsets in scene units) run in the input's float32
        return {name: head(h) for name, head in self.heads.items()}


class FieldModel(BaseModel):
    """Canonical Gaussians deformed by a learned field of (position, time[, wind history]).

    arch "mlp": position offset only; arch "d3dgs": position, rotation (added to the quaternion)
    and scale (added to the log-scale) offsets.
    """

    def __init__(
        self,
        ctx: ModelContext,
        canonical_cfg: dict,
        *,
        arch: str,
        pos_bands: int,
        time_bands: int,
        depth: int,
        width: int,
        skip: int | None,
        wind: bool,
        window_seconds: float | None,
        window_values: int | None,
        name: str,
        precision: str = "float32",
        time_top_hz: float | str = WINDOW_TIME,
    ):
        """A deformation field over the canonical set.

        Args:
            ctx: the observed-dataset facts (canonical positions, fps, n_train, wind statistics).
            canonical_cfg: keyword arguments of the canonical set (config ``models.canonical``).
            arch: ``mlp`` (position offset) or ``d3dgs`` (position, rotation and scale offsets).
            pos_bands: Fourier bands of the normalised position.
            time_bands: Fourier bands of time.
            depth: hidden layers of the MLP.
            width: units per hidden layer.
            skip: hidden layer after which the input is concatenated, or None.
            wind: whether the 48-value wind history is an input.
            window_seconds: the wind history's span, s (wind-conditioned fields only).
            window_values: the wind history's values (wind-conditioned fields only).
            name: the registry id the model reports.
            precision: ``float32`` or ``bfloat16`` hidden layers.
            time_top_hz: the top time band's frequency, Hz, or ``"window"`` (normalised time).

        Raises:
            ValueError: an unknown architecture, or a wind-conditioned field without a window.
        """
        super().__init__(ctx, canonical_cfg)
        if arch not in ("mlp", "d3dgs"):
            raise ValueError(f"unknown field architecture {arch!r}; use 'mlp' or 'd3dgs'")
        self.name = name
        self.arch = arch
        self.pos_bands, self.time_bands = pos_bands, time_bands
        # t_norm runs 0..1 over frames 0..n_train-1, i.e. over (n_train - 1) / fps seconds
        self.time_top_hz = time_top_hz
        self.time_scale = time_scale_for(time_top_hz, time_bands, (ctx.n_train - 1) / ctx.fps)
        self.use_wind = wind
        if wind and (window_seconds is None or window_values is None):
            raise ValueError(f"{name}: a wind-conditioned field needs models.wind_window")
        # a wind-blind field has no window (its settings do not carry one)
        self.window_values = int(window_values) if wind else 0
        self.window_step = window_step(window_seconds, window_values, ctx.fps) if wind else 0
        xyz = np.asarray(ctx.canonical_xyz, dtype=np.float64)
        lo, hi = xyz.min(0), xyz.max(0)
        self.register_buffer("xyz_center", torch.tensor(0.5 * (lo + hi), dtype=torch.float32))
        half = np.maximum(0.5 * (hi - lo).max(), 1e-6)
        self.register_buffer("xyz_half", torch.tensor(half, dtype=torch.float32))
        # Frozen training-condition statistics: weaker winds stay weaker after standardising.
        self.register_buffer("wind_mean", torch.tensor(ctx.wind_mean, dtype=torch.float32))
        self.register_buffer("wind_std", torch.tensor(ctx.wind_std, dtype=torch.float32))
        in_dim = fourier_dim(3, pos_bands) + fourier_dim(1, time_bands) + self.window_values
        heads = ("dx",) if arch == "mlp" else ("dx", "dq", "ds")
        self.field = DeformationField(in_dim, depth, width, skip, heads, precision)

    def features(self, frame_idx: int, wind: torch.Tensor) -> torch.Tensor:
        """Field input [N, in_dim] at recorded frame ``frame_idx``.

        Args:
            frame_idx: recorded frame, 0-based.
            wind: [L+F] the condition's observed wind, m/s (read by wind-driven fields only).

        Returns:
            [N, in_dim]: Fourier features of the normalised position, of the scaled normalised time,
                and (wind-driven fields) the standardised wind window.

        Raises:
            ValueError: when the wind window reaches outside the wind series.
        """
        xn = (self.canonical.means.detach() - self.xyz_center) / self.xyz_half  # [N, 3]
        n = xn.shape[0]
        t = torch.tensor(
            [self.time_scale * self.t_norm(frame_idx)], dtype=xn.dtype, device=xn.device
        )
        parts = [fourier(xn, self.pos_bands), fourier(t, self.time_bands).expand(n, -1)]
        if self.use_wind:
            w = wind_window(
                wind,
                frame_idx,
                self.lead_in,
                self.wind_mean,
                self.wind_std,
                self.window_values,
                self.window_step,
            )  # [48]
            parts.append(w.to(xn.dtype).expand(n, -1))
        return torch.cat(parts, dim=-1)

    def deform(self, frame_idx: int, wind: torch.Tensor) -> GaussianState:
        """The canonical set moved by the field's offsets at recorded frame ``frame_idx``.

        Args:
            frame_idx: recorded frame, 0-based.
            wind: the condition's observed wind [L+F], m/s (read only by wind-conditioned fields).

        Returns:
            The deformed Gaussians.
        """
        c = self.canonical
        out = self.field(self.features(frame_idx, wind))
        means = c.means + out["dx"]
        quats, log_s = c.quats, c.log_scales
        if "dq" in out:
            quats = quats + out["dq"]
            log_s = log_s + out["ds"]
        return GaussianState(
            means,
            quats,
            torch.exp(log_s),
            torch.sigmoid(c.opacity_logits),
            torch.sigmoid(c.color_logits),
        )

    def deformation_param_groups(self, lr: dict) -> list[dict]:
        """One group, ``deform``, holding the field's weights at rate ``lr["deform"]``.

        Args:
            lr: config ``train.lr``.

        Returns:
            The parameter groups.
        """
        return [{"name": "deform", "params": list(self.field.parameters()), "lr": lr["deform"]}]
