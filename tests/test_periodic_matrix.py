"""PeriodicMatrix: forms, Fourier convention, algebra and validation."""

import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp


def brute_fourier(P, K, n=200000):
    """Midpoint-rule coefficients (1/T)∫ P(t) e^{-jkω t} dt as an independent check."""
    t = (np.arange(n) + 0.5) / n * P.period
    vals = P(t)
    k = np.arange(-K, K + 1)
    return np.einsum('kt,tij->kij', np.exp(-2j * np.pi * np.outer(k, t) / P.period), vals) / n


def test_fourier_form_evaluates_series():
    coeffs = np.array([[[0.25 - 0.5j]], [[1.0]], [[0.25 + 0.5j]]])
    P = ltp.PeriodicMatrix(coeffs, 2.0)
    t = np.linspace(0, 3, 7)
    expected = 1 + 2 * (0.25 * np.cos(np.pi * t) - 0.5 * np.sin(np.pi * t))
    np.testing.assert_allclose(P(t)[:, 0, 0], expected, atol=1e-14)
    np.testing.assert_allclose(P.fourier(1), coeffs)
    assert P.fourier(3).shape == (7, 1, 1)


def test_from_function_matches_closed_form_coefficients():
    P = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[np.cos(t) ** 2, np.sin(3 * t)]]), 2 * np.pi)
    c = P.fourier(3)
    np.testing.assert_allclose(c[3, 0, 0], 0.5, atol=1e-14)       # cos² = 1/2 + cos(2t)/2
    np.testing.assert_allclose(c[5, 0, 0], 0.25, atol=1e-14)
    np.testing.assert_allclose(c[6, 0, 1], -0.5j, atol=1e-14)     # sin 3t = (e^{3jt}-e^{-3jt})/2j
    np.testing.assert_allclose(c[0, 0, 1], 0.5j, atol=1e-14)


def test_from_samples_interpolates_and_holds():
    N, T = 9, 3.0
    t = np.arange(N) * T / N
    f = np.cos(2 * np.pi * t / T) + 0.3 * np.sin(4 * np.pi * t / T)
    P = ltp.PeriodicMatrix.from_samples(f, T)
    tt = np.linspace(0, T, 13)
    np.testing.assert_allclose(P(tt)[:, 0, 0], np.cos(2 * np.pi * tt / T)
                               + 0.3 * np.sin(4 * np.pi * tt / T), atol=1e-13)
    H = ltp.PeriodicMatrix.from_samples(f, T, kind='hold')
    np.testing.assert_allclose(H(t + 0.4 * T / N)[:, 0, 0], f, atol=0)
    np.testing.assert_allclose(H.fourier(4), brute_fourier(H, 4, n=9 * 20000), atol=1e-9)


def test_switching_keeps_jumps_and_exact_coefficients():
    T = 0.5
    smooth = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[np.cos(4 * np.pi * t), 1.0]]), T)
    S = ltp.PeriodicMatrix.switching([[[2.0, 0.0]], smooth], [0.0, 0.2], T)
    eps = 1e-12
    np.testing.assert_allclose(S(0.2 - eps), [[2.0, 0.0]])
    np.testing.assert_allclose(S(0.2), smooth(0.2))
    np.testing.assert_allclose(S(T + 0.1), [[2.0, 0.0]])
    np.testing.assert_allclose(S.fourier(6), brute_fourier(S, 6), atol=1e-9)
    np.testing.assert_allclose(S.breakpoints, [0.0, 0.2])
    # constant pieces: closed form (e^{-jkωa} - e^{-jkωb}) / (jkωT)
    Q = ltp.PeriodicMatrix.switching([[[1.0]], [[0.0]]], [0.0, 0.5], 1.0)
    k = np.arange(-3, 4)
    with np.errstate(divide='ignore', invalid='ignore'):
        exact = (1 - np.exp(-1j * k * np.pi)) / (2j * np.pi * k)
    exact[3] = 0.5
    np.testing.assert_allclose(Q.fourier(3)[:, 0, 0], exact, atol=1e-15)


def test_algebra_pointwise_and_in_fourier_domain():
    P = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[np.cos(t), 1.0], [0.0, np.sin(t)]]), 2 * np.pi)
    F = ltp.PeriodicMatrix([[[0.5, 0]], [[1.0, 2.0]], [[0.5, 0]]], np.pi)   # period π divides 2π
    t = np.linspace(0, 7, 11)
    np.testing.assert_allclose((P @ P.T)(t), P(t) @ np.swapaxes(P(t), 1, 2), atol=1e-14)
    np.testing.assert_allclose((F @ P)(t), F(t) @ P(t), atol=1e-14)
    np.testing.assert_allclose((P + 2.0 * P - P)(t), 2 * P(t), atol=1e-14)
    G = F.T @ F
    assert G.nharmonics == 2                      # convolution of exact series stays exact
    np.testing.assert_allclose(G(t), np.swapaxes(F(t), 1, 2) @ F(t), atol=1e-13)
    np.testing.assert_allclose(G.fourier(4), brute_fourier(G, 4), atol=1e-10)


def test_coefficients_are_conjugate_symmetric_for_every_form():
    P = ltp.PeriodicMatrix.switching(
        [lambda t: np.array([[np.sin(2 * np.pi * t)]]), [[3.0]]], [0, 0.3], 1.0)
    c = P.fourier(5)
    np.testing.assert_allclose(c, np.conj(c[::-1]), atol=1e-15)


@pytest.mark.parametrize("call, exc, match", [
    (lambda: ltp.PeriodicMatrix([[[1.0]], [[1.0]]], 1.0), ValueError, "2K\\+1"),
    (lambda: ltp.PeriodicMatrix([[[1j]], [[1.0]], [[1j]]], 1.0), ValueError, "conjugate"),
    (lambda: ltp.PeriodicMatrix([[[1.0]]], 0.0), ValueError, "period"),
    (lambda: ltp.PeriodicMatrix([[[1.0]]], -1.0), ValueError, "period"),
    (lambda: ltp.PeriodicMatrix([[[np.nan]]], 1.0), ValueError, "coeffs"),
    (lambda: ltp.PeriodicMatrix([[[1.0]]], 'a'), ControlArgument, "period"),
    (lambda: ltp.PeriodicMatrix.constant([[1j]], 1.0), ControlArgument, "M"),
    (lambda: ltp.PeriodicMatrix.from_function(lambda t: np.array([[t]]), 1.0),
     ValueError, "not periodic"),
    (lambda: ltp.PeriodicMatrix.from_function(3.0, 1.0), TypeError, "func"),
    (lambda: ltp.PeriodicMatrix.switching([[[1.0]], [[2.0]]], [0.1, 0.5], 1.0),
     ValueError, "times"),
    (lambda: ltp.PeriodicMatrix.switching([[[1.0]], [[2.0]]], [0.0, 1.5], 1.0),
     ValueError, "times"),
    (lambda: ltp.PeriodicMatrix.switching([[[1.0]], [[2.0, 1.0]]], [0.0, 0.5], 1.0),
     ValueError, "pieces"),
    (lambda: ltp.PeriodicMatrix.from_samples(np.ones(4), 1.0, kind='cubic'),
     ValueError, "kind"),
    (lambda: ltp.PeriodicMatrix.constant([[1.0]], 1.0).fourier(-1), ValueError, "nharmonics"),
    (lambda: ltp.PeriodicMatrix.constant([[1.0]], 1.0) + ltp.PeriodicMatrix.constant(
        [[1.0]], np.sqrt(2)), ValueError, "commensurate"),
    (lambda: ltp.PeriodicMatrix.constant([[1.0]], 1.0) @ np.ones((2, 2)), ValueError, "shapes"),
])
def test_bad_input(call, exc, match):
    with pytest.raises(exc, match=match):
        call()


def test_bad_shape_is_control_dimension():
    with pytest.raises(ControlDimension, match="coeffs"):
        ltp.PeriodicMatrix(np.ones((3, 2, 2, 2)), 1.0)


def test_pointwise_and_unchecked_function_constructors():
    P = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[2.0 + np.cos(2 * np.pi * t), 0.0], [np.sin(2 * np.pi * t), 1.0]]),
        period=1.0)
    Q = ltp.PeriodicMatrix.switching([ltp.PeriodicMatrix.constant(np.eye(2), 1.0),
                                      ltp.PeriodicMatrix.constant(2 * np.eye(2), 1.0)],
                                     [0.0, 0.5], 1.0)
    M = ltp.PeriodicMatrix.pointwise(lambda p, q: p @ q, [P, Q], (2, 2), breakpoints=[0.25])
    for t in (0.1, 0.7):
        np.testing.assert_allclose(M(t), P(t) @ Q(t), atol=1e-14)
    assert set(np.round(M.breakpoints, 12)) >= {0.0, 0.25, 0.5}
    with pytest.raises(ValueError, match="same period"):
        ltp.PeriodicMatrix.pointwise(np.add, [P, ltp.PeriodicMatrix.constant(np.eye(2), 2.0)],
                                     (2, 2))
    with pytest.raises(TypeError, match="operands"):
        ltp.PeriodicMatrix.pointwise(np.add, [np.eye(2)], (2, 2))
    # an unchecked function is not probed; a checked one is
    F = ltp.PeriodicMatrix.from_function(lambda t: np.array([[t]]), 1.0, (1, 1), check=False)
    assert F(0.5)[0, 0] == 0.5
    with pytest.raises(ValueError, match="not periodic"):
        ltp.PeriodicMatrix.from_function(lambda t: np.array([[t]]), 1.0)
