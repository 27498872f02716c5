"""Three-phase frames and closed-loop frequency functions against independent truths."""

import numpy as np
import control as ct
import pytest
from control.exception import ControlDimension
from hypothesis import given, settings, strategies as st

import ltpcontrol as ltp

W = 100 * np.pi


@settings(max_examples=15, deadline=None)
@given(p=st.floats(-50, -1), m=st.floats(-10, 10), w=st.floats(1, 400),
       theta0=st.floats(-3, 3))
def test_park_of_a_balanced_system_is_lti(p, m, w, theta0):
    # symmetric circulant (balanced) abc dynamics: self term p, mutual term m
    A = m * np.ones((3, 3)) + (p - m) * np.eye(3)
    sys = ct.ss(A, np.eye(3), np.eye(3), 0)
    dq = ltp.park(sys, w, theta0)
    assert dq.is_lti
    # closed form: (p - m) on d, q; p + 2m on 0; rotation ω couples d and q
    want = np.diag([p - m, p - m, p + 2 * m]) + w * np.array([[0, 1, 0], [-1, 0, 0],
                                                               [0, 0, 0]])
    np.testing.assert_allclose(dq.A(0.0), want, atol=1e-9 * max(1, w))
    np.testing.assert_allclose(dq.B(0.3), np.eye(3), atol=1e-12)


def test_frame_change_satisfies_the_state_equation():
    # unbalanced line: not LTI in dq; check z = T x solves z' = A' z pointwise,
    # with Ṫ by central differences (independent of the Fourier derivative)
    A = -np.diag([100.0, 120.0, 90.0])
    sys = ct.ss(A, np.eye(3), np.eye(3), 0)
    dq = ltp.park(sys, W)
    assert not dq.is_lti
    T = ltp.park_matrix(W)
    rng = np.random.default_rng(1)
    for t in rng.uniform(0, 0.02, 4):
        x = rng.standard_normal(3)
        h = 1e-7
        Tdot = (T(t + h) - T(t - h)) / (2 * h)
        np.testing.assert_allclose(dq.A(t) @ (T(t) @ x), T(t) @ A @ x + Tdot @ x,
                                   rtol=1e-6, atol=1e-6 * W)


def test_park_inverse_and_clarke():
    T, Ti = ltp.park_matrix(-W, 0.4), ltp.park_matrix(-W, 0.4, inverse=True)
    for t in (0.0, 0.0031, 0.017):
        np.testing.assert_allclose(T(t) @ Ti(t), np.eye(3), atol=1e-12)
    # the Park frame at angle 0 is the Clarke frame
    np.testing.assert_allclose(ltp.park_matrix(W)(0.0), ltp.clarke_matrix(), atol=1e-14)
    assert ltp.clarke_matrix(zero_sequence=False).shape == (2, 3)


def test_sequence_components():
    a = np.exp(2j * np.pi / 3)
    rng = np.random.default_rng(2)
    X0, Xp, Xn = rng.standard_normal(3) + 1j * rng.standard_normal(3)
    abc = X0 * np.ones(3) + Xp * np.array([1, a * a, a]) + Xn * np.array([1, a, a * a])
    np.testing.assert_allclose(ltp.sequence_components(abc), [X0, Xp, Xn], atol=1e-12)
    with pytest.raises(ControlDimension):
        ltp.sequence_components([1, 2])


def test_frame_errors():
    sys = ct.ss(-np.eye(3), np.eye(3), np.eye(3), 0)
    with pytest.raises(ValueError, match="nonzero"):
        ltp.park_matrix(0.0)
    with pytest.raises(ControlDimension, match="triples"):
        ltp.park(ct.ss(-np.eye(2), np.eye(2), np.eye(2), 0), W)
    P = ltp.ltpss(ct.ss(-np.eye(3), np.eye(3), np.eye(3), 0), period=np.sqrt(2))
    with pytest.raises(ValueError, match="incommensurate"):
        ltp.park(P, W)
    with pytest.raises(ControlDimension, match="3x3"):
        ltp.frame_transform(sys, states=np.eye(2), outputs=ltp.park_matrix(W))


def _mathieu_loop(k=0.55):
    A = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-(0.2 + 0.8 * np.cos(t)), -0.05]]), 2 * np.pi)
    return (ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi), k)


def test_sensitivity_is_the_inverse_return_difference():
    loop = _mathieu_loop()
    S = ltp.sensitivity_htf(loop, 3)
    T = ltp.complementary_sensitivity_htf(loop, 3)
    with pytest.warns(UserWarning, match='unstable'):     # P = 1
        Lbig = ltp.htf(ltp.series(0.55, loop[0]), 20)
    for w in (0.1, -0.37, 0.5):
        s = 1j * w
        np.testing.assert_allclose(S(s) + T(s), np.eye(7), atol=1e-10)
        inv = np.linalg.inv(np.eye(41) + Lbig(s))[17:24, 17:24]
        np.testing.assert_allclose(S(s), inv, atol=1e-8)


def test_siso_equivalent_is_the_central_sensitivity():
    loop = _mathieu_loop()
    w = np.array([0.05, 0.21, 0.44])
    Leq = ltp.siso_equivalent(loop, 12, w).frdata[0, 0]
    S = ltp.sensitivity_htf(loop, 1)
    S00 = np.array([S(1j * x)[1, 1] for x in w])
    np.testing.assert_allclose(1 / (1 + Leq), S00, rtol=1e-8)
    G = ct.tf([3], [1, 2, 1])
    Leq_lti = ltp.siso_equivalent(ltp.ltpss(G, period=1.0), 3, w).frdata[0, 0]
    np.testing.assert_allclose(Leq_lti, G(1j * w), rtol=1e-12)


def test_impedance_inverts_the_admittance():
    A = ltp.PeriodicMatrix.from_function(lambda t: np.array([[-3.0 + np.cos(t)]]), 2 * np.pi)
    D = ltp.PeriodicMatrix.from_function(lambda t: np.array([[2.0 + 0.5 * np.sin(t)]]),
                                         2 * np.pi)
    conv = ltp.ltpss(A, [[1.0]], [[0.7]], D, period=2 * np.pi, name='conv',
                     inputs='v', outputs='i')
    Y = ltp.harmonic_admittance(conv, 12)
    Z = ltp.harmonic_impedance(conv, 12)
    s = 0.3j
    prod = (Z(s) @ Y(s))[10:15, 10:15]        # central harmonics -2..2
    np.testing.assert_allclose(prod, np.eye(5), atol=1e-6)
    with pytest.raises(ValueError, match="improper"):
        ltp.harmonic_impedance(ltp.ltpss(ct.tf([1], [1e-3, 0.1]), period=0.02), 2)
    with pytest.raises(ControlDimension, match="as many voltages"):
        ltp.harmonic_admittance(ltp.ltpss(ct.ss(-np.eye(2), np.eye(2), [[1, 1]], 0),
                                          period=1.0), 2)
    # the port's channels by name or index: the same admittance; bad ones refused
    np.testing.assert_array_equal(ltp.harmonic_admittance(conv, 2, voltage='v', current=0)(s),
                                  ltp.harmonic_admittance(conv, 2)(s))
    with pytest.raises(ValueError, match="unknown voltage name 'u'"):
        ltp.harmonic_admittance(conv, 2, voltage='u')
    with pytest.raises(ValueError, match="current index 3 out of range"):
        ltp.harmonic_admittance(conv, 2, current=3)


def test_sequence_components_of_a_periodic_matrix():
    # unbalanced currents: amplitudes (1, 0.8, 0.6) at 120°; their harmonic +1
    # phasors, computed directly, give the same sequences
    amp = np.array([1.0, 0.8, 0.6])
    phi = np.array([0, 2 * np.pi / 3, -2 * np.pi / 3])
    i_abc = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[amp[i] * np.cos(t - phi[i])] for i in range(3)]), 2 * np.pi)
    X = ltp.sequence_components(i_abc, nharmonics=1)
    direct = ltp.sequence_components(amp * np.exp(-1j * phi) / 2)
    np.testing.assert_allclose(X[2, :, 0], direct, atol=1e-12)
    # harmonic -1 holds the conjugates, with the positive and negative sequences swapped
    np.testing.assert_allclose(X[0, :, 0], np.conj(direct)[[0, 2, 1]], atol=1e-12)
    with pytest.raises(ct.ControlArgument, match="nharmonics"):
        ltp.sequence_components(i_abc)
    with pytest.raises(ControlDimension, match="3 rows"):
        ltp.sequence_components(i_abc[:2, :], nharmonics=1)
