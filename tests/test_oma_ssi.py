"""SSI-cov through physgs.oma.ssi against multi-degree-of-freedom systems simulated by scipy.

Oracle: each mode is a damped oscillator q'' + 2 zeta omega q' + omega^2 q = w(t) driven by its
own white noise, integrated by ``scipy.signal.lsim``, and seen through a random shape on every
channel. Tolerances come from the record length, not from runs of the code: an output-only
estimate averages about N = T / tau independent stretches of a mode's response (tau =
1 / (zeta omega) its correlation time, T the record), so its relative random error is about
sqrt(2 / N): sigma_zeta / zeta = 1 / sqrt(pi zeta f T), and sigma_f / f = zeta times that =
sqrt(zeta / (pi f T)). The tests allow four sigma.
"""

import numpy as np
import pytest
import scipy.signal as ss

from physgs.oma.ssi import SSISettings, check_record, identify, identify_records

FS = 24.0  # Hz, the testbed's frame rate
N_SIGMA = 4.0


def simulate(freq_hz, zeta, n_channels, seconds, seed, noise=0.02, shape_seed=None):
    """[T, C] channel matrix: modal responses under independent white noise, plus sensor noise
    (the shapes drawn from ``shape_seed`` when given, so several records share one system)."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * FS)) / FS
    srng = rng if shape_seed is None else np.random.default_rng(shape_seed)
    shapes = srng.normal(size=(n_channels, len(freq_hz)))  # [C, M]
    y = np.zeros((t.size, n_channels))
    for k, (f, z) in enumerate(zip(freq_hz, zeta)):
        w = 2 * np.pi * f
        _, q, _ = ss.lsim(ss.lti([1.0], [1.0, 2 * z * w, w * w]), rng.normal(size=t.size), t)
        y += np.outer(q / q.std(), shapes[:, k])
    return y + noise * y.std() * rng.normal(size=y.shape)


def tolerances(f, z, seconds):
    """(relative frequency, relative damping) tolerance: N_SIGMA x the record-length error."""
    n = np.pi * z * f * seconds
    return N_SIGMA * z / np.sqrt(n), N_SIGMA / np.sqrt(n)


@pytest.mark.parametrize("seed", [0, 1])
def test_ssi_recovers_three_modes(seed):
    freq, zeta, seconds = [0.5, 0.9, 1.4], [0.03, 0.05, 0.08], 200.0
    modes = identify(
        simulate(freq, zeta, 6, seconds, seed), FS, SSISettings(block_rows=20, order_max=40)
    )
    assert modes.n_modes == 3, modes.freq_hz  # every mode, nothing spurious
    for f, z, fh, zh in zip(freq, zeta, modes.freq_hz, modes.zeta):
        tf, tz = tolerances(f, z, seconds)
        assert abs(fh - f) / f < tf, (f, fh, tf)
        assert abs(zh - z) / z < tz, (z, zh, tz)
    assert modes.shape.shape == (3, 6)
    np.testing.assert_allclose(np.linalg.norm(modes.shape, axis=1), 1.0)


def test_records_of_one_system_identify_together():
    """Three 70 s records of the same system (the three winds' videos) identified as one: every
    mode within the tolerances of their 210 s together, where some record alone misses a mode."""
    freq, zeta = [0.5, 0.9, 1.4], [0.03, 0.05, 0.08]
    ys = [simulate(freq, zeta, 6, 70.0, seed, shape_seed=9) for seed in (3, 4, 5)]
    modes = identify_records(ys, FS, SSISettings(block_rows=20, order_max=40))
    assert modes.n_modes == 3, modes.freq_hz
    for f, z, fh, zh in zip(freq, zeta, modes.freq_hz, modes.zeta):
        tf, tz = tolerances(f, z, 210.0)
        assert abs(fh - f) / f < tf, (f, fh, tf)
        assert abs(zh - z) / z < tz, (z, zh, tz)
    assert min(identify(y, FS, SSISettings(block_rows=20, order_max=40)).n_modes for y in ys) < 3
    with pytest.raises(ValueError, match="one channel count"):
        identify_records([ys[0], ys[1][:, :5]], FS, SSISettings())


def test_ssi_mode_shapes_match_the_simulated_ones():
    """Each mode's shape is the simulated column (MAC near 1): the shape is what maps it to parts."""
    rng_shapes = np.random.default_rng(5).normal(size=(8, 2))
    t = np.arange(int(150 * FS)) / FS
    rng = np.random.default_rng(6)
    y = np.zeros((t.size, 8))
    for k, f in enumerate([0.6, 1.1]):
        w = 2 * np.pi * f
        _, q, _ = ss.lsim(ss.lti([1.0], [1.0, 0.1 * w, w * w]), rng.normal(size=t.size), t)
        y += np.outer(q / q.std(), rng_shapes[:, k])
    modes = identify(y, FS, SSISettings(block_rows=20, order_max=20))
    assert modes.n_modes == 2
    for k in range(2):
        u = rng_shapes[:, k] / np.linalg.norm(rng_shapes[:, k])
        mac = np.abs(np.vdot(modes.shape[k], u)) ** 2
        assert mac > 0.95, (k, mac)


def test_stabilisation_diagram_covers_every_order():
    modes = identify(
        simulate([0.8], [0.05], 3, 60.0, 2), FS, SSISettings(block_rows=20, order_max=12)
    )
    assert modes.stab.orders.tolist() == list(range(0, 13, 2))
    assert modes.stab.freq_hz.shape == modes.stab.stable.shape
    assert modes.stab.stable.any()


def test_short_record_or_high_order_stops_naming_the_key():
    with pytest.raises(ValueError, match="oma/ssi/block_rows"):
        check_record(100, 10, SSISettings(block_rows=30, order_max=20))
    with pytest.raises(ValueError, match="oma/ssi/order_max") as e:
        check_record(1000, 1, SSISettings(block_rows=10, order_max=20))
    assert (e.value.key, e.value.msg.split()[:2]) == ("oma/ssi/order_max", ["=", "20"])
    with pytest.raises(ValueError, match="oma/ssi has no channels") as e:
        check_record(1000, 0, SSISettings())
    assert e.value.key == "oma/ssi"  # a config check reads the key, not the text
    with pytest.raises(ValueError, match="oma/ssi/block_rows"):
        identify(np.zeros((50, 4)), FS, SSISettings(block_rows=30))
