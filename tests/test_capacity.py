"""The capacity of rigid parts and of one oscillator per part, against motions built by hand
(scipy's rotations: an oracle independent of the module's own turn)."""

import numpy as np
import pytest
import torch
from scipy.spatial.transform import Rotation

from physgs.models.capacity import (
    PartsAtAngles,
    chain_turns,
    oscillator_angles,
    plane_basis,
    refine_oscillators,
    rigid_part_angles,
    turned,
)
from physgs.models.base import ModelContext

AXIS = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])


def _turn(x, angle, pivot, axis=AXIS):
    """[n, 3] points turned by ``angle`` rad about ``axis`` through ``pivot`` (scipy)."""
    return Rotation.from_rotvec(angle * axis).apply(x - pivot) + pivot


def test_fixed_pivot_turns_are_recovered_exactly():
    rng = np.random.default_rng(0)
    T, pivots = 24, np.array([[0.5, 0.2, 0.1], [-1.0, 0.4, 2.0]])
    t = np.arange(T) / 24.0
    angles = np.stack([0.3 * np.sin(2 * np.pi * 0.8 * t), -0.2 * np.sin(2 * np.pi * 1.3 * t + 1)])
    x0 = [pivots[p] + rng.normal(size=(30, 3)) * 0.3 + [0.0, 0.0, 1.0] for p in range(2)]
    labels = np.repeat([0, 1], 30)
    pts = np.stack(
        [
            np.concatenate([_turn(x0[p], angles[p, j], pivots[p]) for p in range(2)])
            for j in range(T)
        ]
    )
    fit = rigid_part_angles(pts, labels, 2, AXIS)
    np.testing.assert_allclose(fit.theta, angles - angles[:, :1], atol=1e-6)
    np.testing.assert_allclose(fit.fitted, pts, atol=1e-6)
    np.testing.assert_allclose(turned(pts[0], labels, AXIS, fit.pivot, fit.theta), pts, atol=1e-6)
    e1, e2, _ = plane_basis(AXIS)  # a pivot is defined up to its place along the axis
    for p in range(2):
        np.testing.assert_allclose(
            [fit.pivot[p] @ e1, fit.pivot[p] @ e2], [pivots[p] @ e1, pivots[p] @ e2], atol=1e-5
        )


def test_a_part_carried_by_its_parent_out_of_phase_is_not_one_fixed_pivot_turn():
    rng = np.random.default_rng(1)
    T = 48
    t = np.arange(T) / 24.0
    parent, child = np.zeros(3), np.array([0.0, 0.0, 2.0])  # the child's head on the parent
    x = child + rng.normal(size=(40, 3)) * 0.2
    phi_a = 0.2 * np.sin(2 * np.pi * 0.5 * t)  # the parent's turn
    for phi_b, leaves in ((0.3 * np.sin(2 * np.pi * 1.7 * t), True), (np.zeros(T), False)):
        pts = np.stack([_turn(_turn(x, phi_b[j], child), phi_a[j], parent) for j in range(T)])
        err = np.linalg.norm(
            rigid_part_angles(pts, np.zeros(40, int), 1, AXIS).fitted - pts, axis=-1
        )
        # carried rigidly (phi_b = 0) it is a turn about the parent's pivot: nothing is left
        assert (err.mean() > 0.01) == leaves, err.mean()


def test_one_oscillator_is_recovered_from_its_own_response():
    rng = np.random.default_rng(2)
    G, T = 6, 50
    responses = rng.normal(size=(G, T))
    responses -= responses[:, :1]
    omega, zeta = np.linspace(1.0, 6.0, G), np.linspace(0.05, 0.3, G)
    theta = np.stack([2.5 * responses[3], -0.7 * responses[1]])
    om, ze, gain, fitted = oscillator_angles(theta, responses, omega, zeta)
    np.testing.assert_allclose(
        [om, ze, gain], [[omega[3], omega[1]], [zeta[3], zeta[1]], [2.5, -0.7]]
    )
    np.testing.assert_allclose(fitted, theta, atol=1e-12)


def test_parts_at_angles_turns_its_canonical_set():
    rng = np.random.default_rng(3)
    xyz = rng.normal(size=(12, 3))
    ctx = ModelContext(
        canonical_xyz=xyz,
        fps=24,
        n_train=4,
        lead_in_frames=2,
        wind_mean=5.0,
        wind_std=1.0,
        wind_force_std=10.0,
        view_dir=np.array([0.0, 1.0, 0.0]),
    )
    labels = np.repeat([0, 1], 6)
    pivot = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    theta = np.array([[0.0, 0.1, 0.2, 0.3], [0.0, -0.4, 0.1, 0.0]])
    m = PartsAtAngles(ctx, {}, labels, AXIS, pivot, theta)
    with torch.no_grad():
        means = m.gaussians_at(2, torch.zeros(2 + 4)).means.numpy()
        c = m.canonical.means.double().numpy()
    want = np.concatenate([_turn(c[labels == p], theta[p, 2], pivot[p]) for p in range(2)])
    np.testing.assert_allclose(means, want, atol=1e-5)
    assert m.defined(3, 0) and not m.defined(4, 0) and not m.defined(0, 1)


def test_shapes_are_checked():
    with pytest.raises(ValueError, match="labels must lie"):
        rigid_part_angles(np.zeros((2, 3, 3)), np.array([0, 1, 2]), 2, AXIS)


def test_a_chain_is_fitted_top_down_and_recomposed():
    """A child turning about its head on top of its parent's turn: the chain's fit recovers both
    own angles and every position; chain_turns recomposes the same shifts from the angles, and
    PartsAtAngles moves its canonical set there."""
    rng = np.random.default_rng(4)
    T = 40
    t = np.arange(T) / 24.0
    phi_a, phi_b = 0.2 * np.sin(2 * np.pi * 0.5 * t), 0.3 * np.sin(2 * np.pi * 1.7 * t)
    parent_pivot, head = np.array([0.1, 0.0, 0.0]), np.array([0.2, -0.3, 2.0])
    xa = rng.normal(size=(30, 3)) * 0.2 + [0.0, 0.0, 1.0]
    xb = head + rng.normal(size=(30, 3)) * 0.2
    pts = np.stack(
        [
            np.concatenate(
                [
                    _turn(xa, phi_a[j], parent_pivot),
                    _turn(_turn(xb, phi_b[j], head), phi_a[j], parent_pivot),
                ]
            )
            for j in range(T)
        ]
    )
    labels, parent = np.repeat([0, 1], 30), np.array([-1, 0])
    fit = rigid_part_angles(pts, labels, 2, AXIS, parent=parent)
    np.testing.assert_allclose(fit.theta, np.stack([phi_a, phi_b]), atol=1e-6)
    np.testing.assert_allclose(fit.fitted, pts, atol=1e-6)
    total, shift = chain_turns(fit.theta, fit.pivot, parent, AXIS)
    np.testing.assert_allclose(total, np.stack([phi_a, phi_a + phi_b]), atol=1e-6)
    np.testing.assert_allclose(shift, fit.shift, atol=1e-9)
    np.testing.assert_allclose(
        turned(pts[0], labels, AXIS, fit.pivot, total, shift), pts, atol=1e-6
    )
    ctx = ModelContext(
        canonical_xyz=pts[0],
        fps=24,
        n_train=T,
        lead_in_frames=0,
        wind_mean=5.0,
        wind_std=1.0,
        wind_force_std=10.0,
        view_dir=np.array([0.0, 1.0, 0.0]),
    )
    m = PartsAtAngles(ctx, {}, labels, AXIS, fit.pivot, total, shift)
    with torch.no_grad():
        m.canonical.means.copy_(torch.as_tensor(pts[0]))
        got = m.gaussians_at(25, torch.zeros(T)).means.double().numpy()
    np.testing.assert_allclose(got, pts[25], atol=1e-5)


def test_an_oscillator_between_grid_points_is_refined_to_its_own_values():
    """An analytic damped sine (the free response's shape) off the grid: the refinement finds its
    frequency, damping and gain from the nearest grid point."""
    t = np.arange(120) / 24.0

    def response(w, z):
        return np.exp(-z * w * t) * np.sin(w * np.sqrt(1 - z * z) * t)

    theta = np.stack([1.7 * response(3.3, 0.12), np.zeros_like(t)])
    om, ze, gain, fitted = refine_oscillators(
        theta, np.array([3.0, 3.0]), np.array([0.1, 0.1]), response, ((0.5, 20.0), (0.01, 0.5))
    )
    np.testing.assert_allclose([om[0], ze[0], gain[0]], [3.3, 0.12, 1.7], rtol=1e-4)
    np.testing.assert_allclose(fitted[0], theta[0], atol=1e-6)
    assert gain[1] == 0 and not fitted[1].any()  # a part that never turns keeps no oscillator
