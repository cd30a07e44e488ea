"""Branch-tip trajectories: ground truth taken at the right wind column, projected by the camera,
and the prediction read from each tip vertex's own Gaussian (Gaussians are stored permuted)."""

from types import SimpleNamespace

import numpy as np

from physgs.camera import look_at
from physgs.evaluate import tip_trajectories


def test_tip_trajectories_known_motion():
    # camera on -y looking at +y; world x -> pixel x, world z -> pixel -y
    cam = look_at((0, -10, 0), (0, 0, 0), fov_deg=40, width=64, height=64)
    L, n_train, n_tail, C, B = 3, 4, 2, 2, 1
    F = n_train + n_tail
    theta = np.zeros((C, L + F, B))
    theta[1, :, 0] = np.arange(L + F) * 0.01  # condition 1: sample s has angle 0.01 s
    rest = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.0, 1.0]])
    gaussian_vertex = np.array([2, 0, 1])  # Gaussian i is mesh vertex gaussian_vertex[i]

    def pose_fn(truth, th):  # rotate about the y axis (in the image plane) by th[0]
        a = th[0]
        R = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
        return truth.rest_vertices @ R.T

    truth = SimpleNamespace(
        theta=theta,
        rest_vertices=rest,
        tip_vertices=np.array([1, 2]),
        vertex_gaussian=np.argsort(gaussian_vertex),
    )
    obs = SimpleNamespace(n_train=n_train, n_tail=n_tail, lead_in_frames=L, train_camera=cam)
    f = cam.fx

    def means(j, c):  # the model: true motion lifted by 0.1, in Gaussian order
        return (pose_fn(truth, [0.01 * (L + j)]) + [0.0, 0.0, 0.1])[gaussian_vertex]

    tr = tip_trajectories(means, truth, obs, condition=1, pose_fn=pose_fn)
    assert tr.gt_px.shape == (2, F, 2)
    np.testing.assert_array_equal(tr.tips, [1, 2])
    # tip 1 at (sin a, 0, cos a) with a = 0.01 (L + j): pixel x = cx + f sin(a) / 10
    a = 0.01 * (L + np.arange(F))
    np.testing.assert_allclose(tr.gt_px[0, :, 0], 32 + f * np.sin(a) / 10, atol=1e-9)
    np.testing.assert_allclose(tr.gt_px[0, :, 1], 32 - f * np.cos(a) / 10, atol=1e-9)
    # prediction lifted by 0.1 world units = 0.1 f / 10 pixels up the image, for both tips: the
    # right Gaussians were read (mesh-order indexing would pair tip 1 with vertex 0's path)
    np.testing.assert_allclose(tr.error_px(), f * 0.01, atol=1e-9)
    # control: means in mesh order (the permutation forgotten) put the tips on the wrong paths
    forgot = tip_trajectories(
        lambda j, c: pose_fn(truth, [0.01 * (L + j)]) + [0.0, 0.0, 0.1],
        truth,
        obs,
        condition=1,
        pose_fn=pose_fn,
    )
    assert forgot.error_px().min() > 1.0
