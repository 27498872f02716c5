"""The plant's HTF from closed-loop records by the joint input-output method."""

import numpy as np
import pytest
from control.exception import ControlArgument

import ltpcontrol as ltp

T = 1.0


def b(t):
    return np.array([[1 + 0.5 * np.cos(2 * np.pi * t)]])


PLANT = ltp.ltpss([[-2.0]], b, [[1.0]], 0, period=T)
# the loop u = r - (y + v) around the plant: inputs [r, v], outputs [y + v, u]
LOOP = ltp.ltpss(lambda t: -2 - b(t), lambda t: np.hstack([b(t), -b(t)]),
                 [[1.0], [-1.0]], [[0.0, 1.0], [1.0, -1.0]], period=T)
LOOP_R = ltp.ltpss(lambda t: -2 - b(t), b, [[1.0], [-1.0]], [[0.0], [1.0]], period=T)


@pytest.fixture(scope='module')
def chirps():
    return ltp.chirp_replicas(T, 12, 8.0, 0.0, 12.0, dt=0.02, gap=4.0)


def closed_loop(exc, noise):
    v = noise * np.random.default_rng(3).standard_normal(exc.time.size)
    return ltp.forced_response(LOOP, exc.time, np.vstack([exc.inputs, v])).outputs


def test_exact_loop_htf_gives_the_plant():
    omega = np.arange(1, 60) * np.pi / 8
    _, comps = ltp.htf(LOOP_R, 4).components(omega)
    plant = ltp.joint_io_htf(ltp.HTFData(comps, omega, T), inputs=[1])
    assert plant.nharmonics == 2 and plant.input_labels == ['y[1]']
    known = np.all(np.isfinite(plant.components()[1]), axis=(0, 1, 2))
    assert known.sum() > 20                      # ω + 2ω_p on the grid
    _, truth = ltp.htf(PLANT, 2).components(plant.omega[known])
    np.testing.assert_allclose(plant.components()[1][..., known], truth, atol=1e-12)


def test_closed_loop_records_with_noise_in_the_loop(chirps):
    exc = chirps
    K = 2
    bias = {}
    for noise in (0.0, 0.5):                      # measurement noise fed back through u
        z = closed_loop(exc, noise)
        H = ltp.estimate_htf((exc.time, exc.inputs, z), T, segments=exc.segments)
        plant = ltp.joint_io_htf(H, inputs=1)
        assert plant.nharmonics == K
        known = np.all(np.isfinite(plant.components()[1]), axis=(0, 1, 2))
        band = known & (plant.omega < 2 * np.pi * 8)
        _, truth = ltp.htf(PLANT, K).components(plant.omega[band])
        joint = plant.components()[1][..., band] - truth
        # the open-loop estimate from (u, y) sees the noise fed back through u
        direct = ltp.estimate_htf((exc.time, z[1], z[0]), T, K, segments=exc.segments)
        naive = direct.components(plant.omega[band])[1] - truth
        bias[noise] = abs(np.median(joint[K].real) + 1j * np.median(joint[K].imag)), \
            abs(np.median(naive[K].real) + 1j * np.median(naive[K].imag))
        if noise == 0:
            scale = np.abs(truth[K]).max()
            assert np.max(np.abs(joint)) < 5e-3 * scale and np.median(np.abs(joint)) < 1e-3 * scale
    # the joint estimate stays centred on the plant, the direct one is biased
    joint_bias, naive_bias = bias[0.5]
    assert joint_bias < 0.1 * np.abs(truth[K]).max()
    assert naive_bias > 2.5 * joint_bias


def test_bad_input():
    omega = np.arange(1, 20) * np.pi / 8
    H = ltp.HTFData(np.ones((5, 2, 1, omega.size)), omega, T)
    with pytest.raises(ControlArgument, match='HTFData'):
        ltp.joint_io_htf(ltp.htf(PLANT, 1), inputs=0)
    for bad in (2, [0, 1], [0, 0], 0.5):
        with pytest.raises(ValueError, match='inputs'):
            ltp.joint_io_htf(H, inputs=bad)
    with pytest.raises(ValueError, match='nharmonics'):
        ltp.joint_io_htf(H, inputs=1, nharmonics=3)


def test_joint_io_std_equals_monte_carlo_spread():
    # exact closed-loop HTF components plus complex noise of known std: the
    # propagated std equals the spread of the plant estimates over 200 draws
    T = 1.0
    loop = ltp.ltpss(lambda t: -2 - b(t), b, [[1.0], [-1.0]], [[0.0], [1.0]], period=T)
    K, L = 2, 8
    omega = 2 * np.pi / L * np.arange(1, 3 * L)
    _, comps = ltp.htf(loop, K).components(omega)
    std = np.broadcast_to(0.01 * np.abs(comps).max() * (1 + np.arange(omega.size) / omega.size),
                          comps.shape).copy()
    P0 = ltp.joint_io_htf(ltp.HTFData(comps, omega, T, std=std), inputs=1)
    assert ltp.joint_io_htf(ltp.HTFData(comps, omega, T), inputs=1).std is None
    known = np.isfinite(P0.std)
    assert known.sum() >= 30
    rng = np.random.default_rng(0)
    draws = np.array([ltp.joint_io_htf(ltp.HTFData(
        comps + std * (rng.normal(size=comps.shape) + 1j * rng.normal(size=comps.shape))
        / np.sqrt(2), omega, T), inputs=1).components()[1] for _ in range(200)])
    spread = np.sqrt(np.mean(np.abs(draws - P0.components()[1]) ** 2, axis=0))
    ratio = spread[known] / P0.std[known]
    assert 0.8 < ratio.min() and ratio.max() < 1.2
