"""A search over each part's natural frequency before the descent (the topology variants' start).

Gradient descent on omega from one common start finds few parts' frequencies: an oscillator's
response to the wind dephases with omega, so the photometric loss has a valley about every
resonance only ~zeta wide. The search replaces omega by something the loss is smooth in:

1. **Bank phase** (from the end of the warm-up to ``until`` x iterations): each part's own angle
   is a linear combination of the responses of a fixed bank of M oscillators, log-spaced over
   the prior's omega bounds at one damping ratio ``bank_zeta``, driven by the observed wind,
       theta_p(t) = s sum_m W[p, m] r_m(t),   r_m = response at unit gain x omega_m^2 / std(force),
   (r_m in radians of quasi-static swing per unit gain, s = ``bank_scale``), so the angle is
   linear in the weights W [K, M] and every part can take whatever
   mixture of frequencies fits the video. The axis and pivot are learned as usual.
2. **Projection** (once, at ``until``): each part's bank angle over the trained frames is fitted
   by a single oscillator, the one of an (omega, zeta) grid over the prior's bounds whose
   least-squares gain (closed form) leaves the smallest residual. That sets omega, zeta and gain.
3. **Descent**: the oscillators take over from there; the physics rate is multiplied by
   ``physics_lr_after`` (from the true physics a rate of 5e-2 dephases the response, 1e-3 keeps
   it: docs/parts.md).

Pure functions over arrays here; the prior ([`physgs.models.ours`][]) holds the bank and calls
``project_to_oscillators``; ``SearchHook`` is the training loop's hook. torch loads only
when a response is integrated: the workflow imports this module to plan (the config checks'
``search_problem``, the recipe's ``search_iteration``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Relative inset of the projection's grid from the prior's bounds: omega and zeta are sigmoids
#: of raw parameters, so a grid point on a bound would need an infinite raw value.
GRID_INSET = 1e-3


@dataclass(frozen=True)
class OmegaSearch:
    """Settings of the search (config ``models.omega_search``).

    until: fraction of train.iterations at which the bank phase ends (after the warm-up, before
    freezing); bank_size: M oscillators in the bank; bank_zeta: their damping ratio; grid:
    (omegas, zetas) of the projection's grid; physics_lr_after: factor on the physics rate after
    the projection; bank_scale: radians of quasi-static swing per unit of a bank weight (Adam
    steps the weights at the physics rate, so this sets the bank's step in radians).
    """

    until: float
    bank_size: int
    bank_zeta: float
    bank_scale: float
    grid: tuple[int, int]
    physics_lr_after: float

    @staticmethod
    def from_config(section: dict) -> OmegaSearch:
        """The search's settings from config ``models.omega_search``.

        Args:
            section: the config section (``until``, ``bank_size``, ``bank_zeta``, ``bank_scale``,
                ``grid``, ``physics_lr_after``).

        Returns:
            The settings.
        """
        return OmegaSearch(
            float(section["until"]),
            int(section["bank_size"]),
            float(section["bank_zeta"]),
            float(section["bank_scale"]),
            (int(section["grid"][0]), int(section["grid"][1])),
            float(section["physics_lr_after"]),
        )


def log_grid(lo: float, hi: float, n: int) -> np.ndarray:
    """n values log-spaced over [lo, hi] (both > 0), float64; for n = 1 their geometric mean.

    Args:
        lo: the lower end (> 0).
        hi: the upper end (> 0).
        n: number of values.

    Returns:
        [n] values.
    """
    if n == 1:
        return np.array([np.sqrt(lo * hi)])
    return np.exp(np.linspace(np.log(lo), np.log(hi), n))


def unit_responses(omega, zeta, wind, vbar: float, dt: float, substeps: int) -> np.ndarray:
    """Responses at unit gain of G oscillators to the forcing v^2 - vbar^2 of a wind.

    Integrated by [`integrate`][physgs.models.oscillator.integrate], from rest at sample 0.

    Args:
        omega (ArrayLike): [G] natural frequencies, rad/s.
        zeta (ArrayLike): [G] damping ratios.
        wind (ArrayLike): [T] wind speed, m/s.
        vbar: the mean speed subtracted, m/s.
        dt: the sample interval, s.
        substeps: RK4 substeps per sample.

    Returns:
        [G, T] responses, rad per unit of m^2/s^2 forcing.
    """
    # here: torch loads only to integrate; the config checks import this module to plan jobs
    import torch

    from physgs.models.oscillator import integrate

    om = torch.as_tensor(np.asarray(omega, dtype=np.float64))
    ze = torch.as_tensor(np.asarray(zeta, dtype=np.float64))
    with torch.no_grad():
        r = integrate(om, ze, torch.ones_like(om), wind, vbar, dt, substeps)
    return r.numpy()


def project_to_oscillators(
    theta: np.ndarray, responses: np.ndarray, omega: np.ndarray, zeta: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The single oscillator that best fits each part's angle, by least squares over a grid.

    For every part and grid point the gain is the least-squares one, <theta, r> / <r, r>; the grid
    point left with the smallest residual wins.

    Args:
        theta: [K, S] each part's angle, rad, at S samples.
        responses: [G, S] the grid's unit-gain responses at the same samples.
        omega: [G] the grid's natural frequencies, rad/s.
        zeta: [G] the grid's damping ratios.

    Returns:
        ``(omega [K], zeta [K], gain [K] in rad per m^2/s^2, explained [K])``, explained = 1 -
            residual / |theta|^2, 0 for a part whose angle is zero.

    Raises:
        ValueError: when the shapes do not share S, or a grid response is identically zero.
    """
    theta = np.asarray(theta, dtype=np.float64)
    responses = np.asarray(responses, dtype=np.float64)
    if theta.ndim != 2 or responses.ndim != 2 or theta.shape[1] != responses.shape[1]:
        raise ValueError(
            f"project_to_oscillators: theta [K, S] and responses [G, S] must share S; got "
            f"{theta.shape} and {responses.shape}"
        )
    rr = np.einsum("gs,gs->g", responses, responses)  # [G]
    if not (rr > 0).all():
        raise ValueError("project_to_oscillators: a grid response is identically zero")
    cross = theta @ responses.T  # [K, G]
    gain_all = cross / rr  # [K, G]
    # residual = |theta|^2 - <theta, r>^2 / <r, r>: the largest explained energy wins
    explained_energy = cross * gain_all  # [K, G]
    best = np.argmax(explained_energy, axis=1)  # [K]
    k = np.arange(theta.shape[0])
    tt = np.einsum("ks,ks->k", theta, theta)
    explained = np.where(tt > 0, explained_energy[k, best] / np.where(tt > 0, tt, 1.0), 0.0)
    return omega[best], zeta[best], gain_all[k, best], explained


def search_problem(until: float, iterations: int, warmup: int, freeze_at: int | None) -> str | None:
    """Why ``until`` cannot end the bank phase in a run of ``iterations`` with ``warmup``
    (iterations) and freezing at iteration ``freeze_at`` (None: off), or None if it can: the
    phase must end after the warm-up and before freezing (freezing reads the oscillators).

    Args:
        until: fraction of ``iterations`` at which the bank phase ends.
        iterations: training iterations.
        warmup: static warm-up iterations.
        freeze_at: the freezing iteration, or None when freezing is off.

    Returns:
        The reason, or None.
    """
    it = int(round(until * iterations))
    end = iterations if freeze_at is None else freeze_at
    if warmup < it < end:
        return None
    return (
        f"{until:g} ends the bank phase at iteration {it} of {iterations}, outside "
        f"({warmup}, {end}): after the warm-up and before "
        + ("freezing (models/ours/freeze_at)" if freeze_at is not None else "the last iteration")
    )


def search_iteration(search: OmegaSearch, train_cfg: dict, freeze_at: int | None) -> int:
    """The iteration at which the bank phase ends, round(until x train.iterations); raises
    ValueError naming ``models.omega_search.until`` where ``search_problem`` finds one.

    Args:
        search: the search settings.
        train_cfg: the ``train`` config section (iterations, warmup).
        freeze_at: the freezing iteration, or None.

    Returns:
        The iteration.

    Raises:
        ValueError: where [`search_problem`][physgs.models.omega_search.search_problem] finds one.
    """
    iterations, warmup = int(train_cfg["iterations"]), int(train_cfg["warmup"])
    why = search_problem(search.until, iterations, warmup, freeze_at)
    if why is not None:
        raise ValueError(f"models.omega_search.until = {why}")
    return int(round(search.until * iterations))


def omega_search_callback(observed, models_cfg: dict, train_cfg: dict, conditions: list[int]):
    """The ``SearchHook`` of one training run: it ends the prior's bank phase once, fitting the
    trained conditions' winds over the training window (recorded frames 0 .. n_train - 1; the
    held-out training frames lie inside it, and their images are never read).

    Args:
        observed (Observed): the dataset (winds [C, L+F] m/s, lead-in, n_train).
        models_cfg: the ``models`` config section.
        train_cfg: the ``train`` config section.
        conditions: the trained conditions' indices.

    Returns:
        (SearchHook): The hook, firing at the iteration of
            [`search_iteration`][physgs.models.omega_search.search_iteration].

    Raises:
        ValueError: when the phase cannot end between the warm-up and freezing.
    """
    from physgs.models.visibility import freeze_schedule  # here: loads torch (module docstring)

    search = OmegaSearch.from_config(models_cfg["omega_search"])
    at = search_iteration(search, train_cfg, freeze_schedule(models_cfg, train_cfg))
    lead, n = int(observed.lead_in_frames), int(observed.n_train)
    winds = np.asarray(observed.wind, dtype=np.float64)  # [C, L+F]
    return SearchHook(at, [(winds[c], slice(lead, lead + n)) for c in conditions])


@dataclass(frozen=True)
class SearchHook:
    """``on_iteration`` hook for ``train_model``: at iteration ``at`` it ends the prior's bank
    phase (``OscillatorPrior.end_bank_phase``) on the trained winds and frames ``windows``
    [(wind [L+F] m/s, the samples of the trained frames)], scales the physics group's rate by
    the model's ``physics_lr_after`` and drops that group's Adam moments (built under the bank:
    the axis' too). Returns the statistics it adds."""

    at: int
    windows: list

    def __call__(self, it, model, optimizer) -> dict | None:
        """End the bank phase at iteration ``at`` (see the class docstring); a no-op at the others.

        Args:
            it (int): the training iteration.
            model (OscillatorPrior): the prior being trained.
            optimizer (physgs.train.adam.FusedAdam): its optimiser (groups named as in ``param_groups``).

        Returns:
            The statistics to log at ``at``, else None.
        """
        if it != self.at:
            return None
        stats = model.end_bank_phase(self.windows)
        factor = model.search.physics_lr_after
        for g in optimizer.param_groups:
            if g["name"] == "physics":
                g["base_lr"] *= factor
                for p in g["params"]:
                    optimizer.state.pop(p, None)
        return {"omega_search_at": it, **stats}
