"""Ours' wind-driven oscillators fitted to 2D point tracks instead of to pixels (no renderer).

Tracks ([`physgs.tracks.track`][]) are grouped into K parts by k-means on their seed positions (px).
Part p swings by theta_p(t), the response of the *same* oscillator as ours: omega_p and zeta_p
through [`physgs.models.oscillator_params`][] (ours' bounds, initialisation and raw maps), driven by
v(t)^2 - vbar^2 of each condition's observed wind with its lead-in, integrated from rest by
[`physgs.models.oscillator.integrate`][] (RK4, ours' substeps), vbar = vbar_ratio * mean(wind).

Image of the motion: track i of part p sits at

    x_i(t) = c_i + d_i theta_p(t)        c_i, d_i in px (2D each)

A small rigid rotation about a pivot moves a point by theta (a x (X - pivot)), whose image is a
fixed 2D vector per point times theta to first order; that vector depends on the point's depth
and lever arm, which one camera does not see. So the direction d_i is per track (the tightest 2D
model of a linearised rigid rotation that needs no depth), not per part (a shared d_p would force
points near the pivot to move as far as points at the tip). The offset c_i is per track too.

Fitting: for given (omega, zeta) the best (c_i, d_i) of every track is a weighted linear least
squares over its valid frames, solved in closed form inside the loss (variable projection), so
Adam (ours' optimiser family, ours' physics learning rate) moves only the 2K raw oscillator
parameters and the loss is the mean squared track residual (px^2). The gain is fixed at ours'
initial scale (raw 1: theta is about the quasi-static swing in radians) because any other gain
is absorbed by d_i. Joint configurations fit one (omega_p, zeta_p) to the tracks of every trained
condition (each condition's tracks keep their own c_i, d_i: different videos, different tracks).

A part with fewer than ``min_tracks`` tracks gives no estimate (``estimated[p]`` False: its theta
is reported as 0 so the matcher leaves it untrusted, and the count is recorded).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import torch

from physgs.models.oscillator import STABILITY_GUARD, integrate
from physgs.models.oscillator_params import OscillatorBounds, condition_vbar
from physgs.models.ours import settings_substeps
from physgs.tracks.track import Tracks
from physgs.train.adam import FusedAdam
from physgs.train.divergence import pinned

#: tracks shorter than this many frames (1 s at 24 fps: a third of the slowest 0.35 Hz period,
#: a whole period at 1 Hz) do not enter the fit: a shorter track fixes its own c_i, d_i and
#: leaves almost nothing for (omega, zeta)
MIN_TRACK_FRAMES = 24
#: fewest fitted tracks for a part to give an estimate (each track costs 4 free numbers; with 3
#: tracks of >= 24 frames a part has >= 144 coordinates for its 4 x 3 + 2 unknowns)
MIN_TRACKS_PER_PART = 3


@dataclass(frozen=True)
class FitSettings:
    """K parts; iterations and lr (Adam on the raw omega/zeta, ours' ``train.lr.physics``);
    min_track_frames, min_tracks: see the module constants; kmeans_n_init and seed: k-means."""

    K: int
    iterations: int = 300
    lr: float = 5e-2
    min_track_frames: int = MIN_TRACK_FRAMES
    min_tracks: int = MIN_TRACKS_PER_PART
    kmeans_n_init: int = 4
    seed: int = 0


@dataclass(frozen=True)
class Oscillators:
    """What the fit needs of ours' config and of the observed record.

    bounds: ours' omega/zeta parameterisation; substeps: RK4 steps per frame (ours' rule,
    ``prior_substeps``); fps; lead_in L frames; vbar_ratio (training condition's nominal mean speed
    over its record's mean); gain: rad/m^2 per unit (ours' gain_scale, omega_init^2 /
    std(v^2 - mean(v)^2) of the training wind); guard: RK4 guard.
    """

    bounds: OscillatorBounds
    substeps: int
    fps: int
    lead_in: int
    vbar_ratio: float
    gain: float
    guard: float = STABILITY_GUARD

    @staticmethod
    def from_config(ours_cfg: dict, observed) -> Oscillators:
        """From ``models.ours`` (omega_hz, zeta, omega_init_hz, zeta_init, substeps, rk4_guard)
        and an ``Observed`` (training condition = index 0).

        Args:
            ours_cfg: the ``models.ours`` section.
            observed (Observed): the dataset (fps, lead-in, training wind and vbar).

        Returns:
            The oscillators' settings, substeps raised as ours raises them
                ([`prior_substeps`][physgs.models.ours.prior_substeps]).

        Raises:
            ValueError: for inconsistent bounds.
        """
        b = OscillatorBounds.from_config(
            ours_cfg["omega_hz"], ours_cfg["zeta"], ours_cfg["omega_init_hz"], ours_cfg["zeta_init"]
        )
        guard = float(ours_cfg.get("rk4_guard", STABILITY_GUARD))
        dt = 1.0 / observed.fps
        w = np.asarray(observed.wind[0], np.float64)
        return Oscillators(
            b,
            settings_substeps(ours_cfg, dt),
            int(observed.fps),
            int(observed.lead_in_frames),
            float(np.asarray(observed.vbar)[0] / w.mean()),
            float(b.omega_init**2 / (w**2 - w.mean() ** 2).std()),
            guard,
        )

    def theta(self, omega, zeta, wind) -> torch.Tensor:
        """[K, L+F] rad under one condition's wind [L+F] m/s (lead-in first), from rest.

        Args:
            omega (torch.Tensor): [K] natural frequencies, rad/s.
            zeta (torch.Tensor): [K] damping ratios.
            wind (ArrayLike): [L+F] the condition's wind, m/s.

        Returns:
            [K, L+F] angles, rad, in the dtype of omega, at the shared gain.
        """
        g = torch.full_like(omega, self.gain)
        vbar = condition_vbar(self.vbar_ratio, wind)
        return integrate(
            omega, zeta, g, wind, vbar, 1.0 / self.fps, self.substeps, guard=self.guard
        )


def track_parts(seed_xy: np.ndarray, K: int, seed: int, n_init: int = 4) -> np.ndarray:
    """[P] int labels in [0, K): k-means on the tracks' seed positions seed_xy [P, 2] px.
    Deterministic for ``seed``; parts numbered bottom of the image first (largest y), then x.

    Args:
        seed_xy: [P, 2] the tracks' seed positions, px.
        K: number of parts.
        seed: the k-means seed.
        n_init: k-means restarts.

    Returns:
        [P] int64 labels.

    Raises:
        ValueError: for K < 1 or K above the number of tracks.
    """
    seed_xy = np.asarray(seed_xy, np.float64)
    if K < 1:
        raise ValueError(f"models.configs K must be >= 1 for the tracks control, got {K}")
    if K > len(seed_xy):
        raise ValueError(
            f"models.configs K = {K} parts exceeds the {len(seed_xy)} tracks long enough to fit "
            f"(>= {MIN_TRACK_FRAMES} frames); lower K for the tracks control"
        )
    from sklearn.cluster import KMeans  # here: ~1 s that the jobs loading a fit never need

    km = KMeans(n_clusters=K, random_state=seed, n_init=n_init).fit(seed_xy)
    c = km.cluster_centers_
    order = np.lexsort((c[:, 0], -c[:, 1]))
    rank = np.empty(K, np.int64)
    rank[order] = np.arange(K)
    return rank[km.labels_]


def _project(theta, xy, w) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Closed-form weighted least squares of xy [P, T, 2] on c + d theta [P, T] with weights
    w [P, T] (0/1). Returns (c [P, 2], d [P, 2], residual sum of squares, px^2)."""
    sw = w.sum(1, keepdim=True)  # [P, 1]
    tm = (w * theta).sum(1, keepdim=True) / sw  # [P, 1]
    xm = (w[..., None] * xy).sum(1) / sw  # [P, 2]
    tc = (theta - tm) * w  # [P, T] centred, zero where not valid
    stt = (tc * tc).sum(1, keepdim=True)  # [P, 1]
    # ridge at round-off level: a part whose theta is flat over a track leaves d_i at 0
    d = (tc[..., None] * (xy - xm[:, None])).sum(1) / (stt + 1e-12 * (1.0 + stt.detach()))
    c = xm - d * tm
    r = (c[:, None] + d[:, None] * theta[..., None] - xy) * w[..., None]
    return c, d, (r * r).sum()


@dataclass(frozen=True)
class TrackFit:
    """The fitted oscillators and track maps.

    omega [K] rad/s, zeta [K]; estimated [K] bool (part had >= min_tracks tracks);
    n_tracks [K] tracks per part (all conditions); labels: per condition, [P_c] part of each
    track or -1 (too short to fit); c, d: per condition, [P_c, 2] px offsets and directions
    (NaN for unfitted tracks); conditions: the condition index of each entry;
    loss_px2 [iterations] mean squared residual per coordinate; seconds: wall time of the whole
    call; loop_seconds: of the Adam loop alone (k-means and first imports excluded);
    rms_px: final root mean squared residual per coordinate (px).
    """

    omega: np.ndarray
    zeta: np.ndarray
    estimated: np.ndarray
    n_tracks: np.ndarray
    labels: list
    c: list
    d: list
    conditions: list
    loss_px2: np.ndarray
    seconds: float
    loop_seconds: float
    rms_px: float


def _largest_min_frames(tracks: list[Tracks], s: FitSettings) -> int | None:
    """The largest min_track_frames below ``s.min_track_frames`` at which some part of the same
    k-means gets ``s.min_tracks`` tracks (None: none does). Tried from the longest track length
    down; run only to word a refusal."""
    lengths = np.concatenate([tr.length() for tr in tracks])
    for n in sorted({int(x) for x in lengths if 0 < x < s.min_track_frames}, reverse=True):
        seed_xy = np.concatenate([tr.first_xy()[tr.length() >= n] for tr in tracks])
        if len(seed_xy) < s.K:
            continue
        counts = np.bincount(track_parts(seed_xy, s.K, s.seed, s.kmeans_n_init), minlength=s.K)
        if counts.max() >= s.min_tracks:
            return n
    return None


def fit_tracks(
    tracks: list[Tracks],
    conditions: list[int],
    wind: np.ndarray,
    osc: Oscillators,
    settings: FitSettings,
) -> TrackFit:
    """Fit K oscillators to the tracks of the trained conditions.

    Args:
        tracks: one ``Tracks`` per trained condition, over the training window's T frames.
        conditions: their condition indices (into ``wind``).
        wind: [C, L+F] observed wind, m/s (lead-in first).
        osc: the oscillators' settings (bounds, substeps, parts).
        settings: the fit's settings.

    Returns:
        The [`TrackFit`][physgs.tracks.fit.TrackFit].
    """
    t_start = time.perf_counter()
    if len(tracks) != len(conditions) or not tracks:
        raise ValueError("fit_tracks needs one Tracks per trained condition")
    s = settings
    keep = [tr.length() >= s.min_track_frames for tr in tracks]
    seed_xy = np.concatenate([tr.first_xy()[k] for tr, k in zip(tracks, keep)])  # [P, 2]
    lab_all = track_parts(seed_xy, s.K, s.seed, s.kmeans_n_init)
    labels, xs, ws, off = [], [], [], 0
    for tr, k in zip(tracks, keep):
        lab = np.full(tr.n_tracks, -1, np.int64)
        lab[k] = lab_all[off : off + int(k.sum())]
        off += int(k.sum())
        labels.append(lab)
    n_tracks = np.bincount(lab_all, minlength=s.K)
    estimated = n_tracks >= s.min_tracks
    for tr, lab in zip(tracks, labels):
        use = (lab >= 0) & estimated[np.maximum(lab, 0)]
        xs.append(torch.as_tensor(np.nan_to_num(tr.xy[use]), dtype=torch.float64))
        ws.append(torch.as_tensor(tr.valid[use], dtype=torch.float64))
    T = tracks[0].xy.shape[1]
    L = osc.lead_in
    winds = [torch.as_tensor(np.asarray(wind[c], np.float64)) for c in conditions]
    b = osc.bounds
    om_raw = torch.full((s.K,), b.omega_raw_init(), dtype=torch.float64, requires_grad=True)
    ze_raw = torch.full((s.K,), b.zeta_raw_init(), dtype=torch.float64, requires_grad=True)
    opt = FusedAdam([{"params": [om_raw, ze_raw], "lr": s.lr}])  # no torch.optim: see train.adam
    n_obs = sum(float(w.sum()) for w in ws) * 2
    if n_obs == 0:  # the parts do not depend on min_tracks: their largest count is what works
        frames = _largest_min_frames(tracks, s)
        raise ValueError(
            f"no part has tracks/min_tracks = {s.min_tracks} tracks of >= {s.min_track_frames} "
            f"frames (tracks/min_track_frames): nothing to fit. The {s.K} parts have "
            f"{sorted(n_tracks.tolist(), reverse=True)} tracks: set tracks/min_tracks to at most "
            f"{int(n_tracks.max())}, or lower tracks/min_track_frames"
            + (f" to at most {frames}" if frames is not None else "")
        )
    sel = [
        torch.as_tensor(lab[(lab >= 0) & estimated[np.maximum(lab, 0)]]) for lab in labels
    ]  # part of each fitted track
    losses = []
    t_loop = time.perf_counter()

    def loss_fn():
        om, ze = b.omega(om_raw), b.zeta(ze_raw)
        tot = 0.0
        for wd, x, w, p in zip(winds, xs, ws, sel):
            th = osc.theta(om, ze, wd)[:, L : L + T]  # [K, T]
            tot = tot + _project(th[p], x, w)[2]
        return tot / n_obs

    for _ in range(s.iterations):
        opt.zero_grad()
        loss = loss_fn()
        loss.backward()
        opt.step()
        losses.append(float(loss.detach()))
    loop_seconds = time.perf_counter() - t_loop
    with torch.no_grad():  # every estimated omega and zeta on a bound: a saturated fit
        d = pinned(
            {
                "omega": torch.sigmoid(om_raw).numpy()[estimated],
                "zeta": torch.sigmoid(ze_raw).numpy()[estimated],
            }
        )
    if d is not None:
        raise ValueError(
            f"the tracks fit: {d.what}; likely setting: train.lr.physics (now {s.lr:g}, Adam's "
            "rate on the raw omega and zeta); lower it"
        )
    with torch.no_grad():
        om, ze = b.omega(om_raw), b.zeta(ze_raw)
        final = float(loss_fn())
        cs, ds = [], []
        for wd, x, w, p, tr, lab in zip(winds, xs, ws, sel, tracks, labels):
            th = osc.theta(om, ze, wd)[:, L : L + T]
            c, d, _ = _project(th[p], x, w)
            C = np.full((tr.n_tracks, 2), np.nan)
            D = np.full((tr.n_tracks, 2), np.nan)
            use = (lab >= 0) & estimated[np.maximum(lab, 0)]
            C[use], D[use] = c.numpy(), d.numpy()
            cs.append(C)
            ds.append(D)
    return TrackFit(
        om.numpy().copy(),
        ze.numpy().copy(),
        estimated,
        n_tracks,
        labels,
        cs,
        ds,
        list(conditions),
        np.asarray(losses),
        time.perf_counter() - t_start,
        loop_seconds,
        float(np.sqrt(final)),
    )


def part_theta(fit: TrackFit, osc: Oscillators, wind) -> np.ndarray:
    """The fitted parts' angles under one condition's wind.

    Args:
        fit: the track fit.
        osc: the oscillators' settings the fit used.
        wind (np.ndarray): [L+F] the condition's observed wind, m/s, lead-in first.

    Returns:
        [K, L+F] angles, rad; parts with no estimate are 0 (the matcher leaves a constant row
            untrusted).
    """
    with torch.no_grad():
        th = osc.theta(torch.as_tensor(fit.omega), torch.as_tensor(fit.zeta), torch.as_tensor(wind))
    th = th.numpy().copy()
    th[~fit.estimated] = 0.0
    return th


def predict_tracks(fit: TrackFit, osc: Oscillators, entry: int, wind, frames) -> np.ndarray:
    """[P, F, 2] px: the tracks of fitted condition ``fit.conditions[entry]`` predicted at recorded
    frames [F] under a condition's wind [L+F] (its own, or another for transfer); NaN rows for
    tracks that were not fitted.

    Args:
        fit: the fit.
        osc: its oscillators.
        entry: the index into ``fit.conditions`` whose tracks are predicted.
        wind (ArrayLike): [L+F] the wind to predict under, m/s.
        frames (ArrayLike): [F] recorded-frame indices.

    Returns:
        [P, F, 2] predicted positions, px.
    """
    th = part_theta(fit, osc, wind)[:, osc.lead_in + np.asarray(frames)]  # [K, F]
    lab = fit.labels[entry]
    out = fit.c[entry][:, None, :] + fit.d[entry][:, None, :] * th[np.maximum(lab, 0)][..., None]
    return out
