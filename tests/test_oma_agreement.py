"""The agreement count that chooses SSI's frequency tolerance on the training winds."""

import numpy as np

from physgs.oma.agreement import reproduced_modes


def test_a_mode_counts_only_when_every_other_record_holds_it_within_its_bandwidth():
    z = 0.05
    # 1.00 Hz in every record (within 0.05 Hz of each other); 2.0 Hz only in two of three;
    # 3.0 Hz in the third record is 0.2 Hz from 3.2 Hz, beyond its bandwidth (~0.155 Hz).
    recs = [
        (np.array([1.00, 2.0, 3.0]), np.full(3, z)),
        (np.array([1.03, 2.0]), np.full(2, z)),
        (np.array([0.98, 3.2]), np.full(2, z)),
    ]
    hit, found = reproduced_modes(recs)
    assert (hit, found) == (3, 7)


def test_the_bandwidth_uses_the_pairs_mean_damping_and_frequency():
    # |1.0 - 1.1| = 0.1; tolerance (0.1 + 0.1)/2 * 1.05 = 0.105: reproduced; at zeta 0.09: 0.0945, not
    near = [(np.array([1.0]), np.array([0.1])), (np.array([1.1]), np.array([0.1]))]
    far = [(np.array([1.0]), np.array([0.09])), (np.array([1.1]), np.array([0.09]))]
    assert reproduced_modes(near) == (2, 2)
    assert reproduced_modes(far) == (0, 2)


def test_no_modes_no_agreement():
    assert reproduced_modes([(np.zeros(0), np.zeros(0))] * 3) == (0, 0)
