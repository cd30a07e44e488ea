"""Segmentation purity against hand-counted bones."""

import numpy as np
import pytest

from physgs.evaluate.parts import part_purity


def test_purity_by_hand():
    labels = np.array([0, 0, 0, 0, 1, 1, 1, 2])
    bone = np.array([5, 5, 5, 2, 1, 2, 2, 0])
    p = part_purity(labels, bone)
    assert np.allclose(p.per_part, [3 / 4, 2 / 3, 1.0])
    assert list(p.majority_bone) == [5, 2, 0] and list(p.size) == [4, 3, 1]
    assert p.overall == pytest.approx((3 + 2 + 1) / 8)


def test_purity_refuses_empty_parts_and_mismatched_lengths():
    with pytest.raises(ValueError, match="no empty part"):
        part_purity(np.array([0, 2]), np.array([0, 1]))
    with pytest.raises(ValueError, match="one length"):
        part_purity(np.array([0, 1]), np.array([0]))
