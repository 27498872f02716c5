"""Periodic balanced truncation, Hankel singular values and minimal realization.

Truths: python-control in the LTI limit (continuous time), the gramians of
scipy's discrete Lyapunov solver for N = 1, and the ℓ2 gain of the error
system measured on its time-lifted LTI equivalent (SLICOT through
python-control) and by `ltp.norm`.
"""

import numpy as np
import control as ct
import pytest
import scipy.linalg as sla
from control.exception import ControlArgument
from hypothesis import given, settings, strategies as st

import ltpcontrol as ltp


def _stable_plant(seed, N, n, m, p):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((N, n, n))
    # scale the steps so that the monodromy has spectral radius 0.8
    mono = np.eye(n)
    for k in range(N):
        mono = A[k] @ mono
    A *= (0.8 / max(np.max(np.abs(np.linalg.eigvals(mono))), 1e-3)) ** (1 / N)
    B = rng.standard_normal((N, n, m))
    C = rng.standard_normal((N, p, n))
    D = rng.standard_normal((N, p, m))
    return ltp.ltpss(A, B, C, D, period=N * 0.1, dt=0.1)


def _lifted_hinf(sys):
    return ct.norm(ltp.lift(sys, method='time'), 'inf')


def test_balred_lti_embedding_equals_python_control():
    G = ct.ss([[-1.0, 0.5, 0.0, 0.1], [0.0, -2.0, 1.0, 0.0], [0.0, 0.0, -3.0, 0.4],
               [0.2, 0.0, 0.0, -5.0]], [[1.0, 0.0], [0.5, 1.0], [0.0, 0.3], [0.1, 0.1]],
              [[1.0, 0.2, 0.0, 0.3], [0.0, 1.0, 0.5, 0.0]], [[0.0, 0.1], [0.0, 0.0]])
    sys = ltp.ltpss(G, period=0.7)
    np.testing.assert_allclose(ltp.hsvd(sys)[0],
                               np.sort(ct.hankel_singular_values(G))[::-1], rtol=1e-10)
    for r in (1, 2, 3):
        rsys, bound = ltp.balred(sys, r, return_bound=True)
        ref = ct.balred(G, r)
        w = np.logspace(-2, 2, 9)
        got = rsys.to_ss().frequency_response(w).complex
        want = ref.frequency_response(w).complex
        assert np.abs(got - want).max() < 1e-8 * np.abs(want).max()
        hsv = ltp.hsvd(sys)[0]
        assert abs(bound - 2 * hsv[r:].sum()) < 1e-12
    G2 = ct.append(G, ct.ss([[-1.0]], [[0.0]], [[1.0]], 0))[:, :2]   # uncontrollable mode
    red = ltp.minreal(ltp.ltpss(G2, period=0.7))
    assert red.nstates == ct.minreal(G2, verbose=False).nstates == 4


def test_hsvd_discrete_lti_matches_scipy_gramians():
    rng = np.random.default_rng(1)
    A = 0.5 * rng.standard_normal((3, 3))
    B, C = rng.standard_normal((3, 1)), rng.standard_normal((1, 3))
    P = sla.solve_discrete_lyapunov(A, B @ B.T)
    Q = sla.solve_discrete_lyapunov(A.T, C.T @ C)
    hsv = np.sort(np.sqrt(np.abs(np.linalg.eigvals(P @ Q))))[::-1]
    sysd = ltp.ltpss(A, B, C, 0, period=0.3, dt=0.1)     # N = 3, LTI
    got = ltp.hsvd(sysd)
    assert got.shape == (3, 3)
    np.testing.assert_allclose(got, np.broadcast_to(hsv, (3, 3)), rtol=1e-10)


@settings(max_examples=8, deadline=None)
@given(seed=st.integers(0, 10_000), N=st.integers(2, 5), r=st.integers(1, 3))
def test_balred_error_below_the_a_priori_bound(seed, N, r):
    sys = _stable_plant(seed, N, 4, 2, 2)
    rsys, bound = ltp.balred(sys, r, return_bound=True)
    assert rsys.nstates == r and rsys.nsteps == N
    err = _lifted_hinf(sys - rsys)
    assert err <= bound * (1 + 1e-8) + 1e-10
    assert ltp.norm(sys - rsys, 'inf') <= bound * (1 + 1e-6) + 1e-9


def test_minreal_removes_planted_modes():
    base = _stable_plant(3, 3, 2, 1, 1)
    A, B, C, D = (M.sample(3) for M in (base.A, base.B, base.C, base.D))
    # add an uncontrollable periodic mode and an unobservable one
    a_u = np.array([0.5, -0.7, 0.9])[:, None, None]
    a_o = np.array([0.3, 0.8, -0.4])[:, None, None]
    Z = np.zeros
    Abig = np.zeros((3, 4, 4))
    Abig[:, :2, :2], Abig[:, 2:3, 2:3], Abig[:, 3:, 3:] = A, a_u, a_o
    Abig[:, 0, 2] = 0.3                    # the unreachable mode drives the plant
    Abig[:, 3, 0] = 0.2                    # the plant drives the unobservable mode
    Bbig = np.concatenate([B, Z((3, 1, 1)), np.ones((3, 1, 1))], axis=1)
    Cbig = np.concatenate([C, np.ones((3, 1, 1)), Z((3, 1, 1))], axis=2)
    big = ltp.ltpss(Abig, Bbig, Cbig, D, period=0.3, dt=0.1)
    red = ltp.minreal(big)
    assert red.nstates == 2
    assert _lifted_hinf(big - red) < 1e-8
    assert ltp.minreal(base).nstates == 2


def test_reduction_bad_input():
    sys = _stable_plant(4, 2, 3, 1, 1)
    with pytest.raises(ValueError, match="orders must be at most"):
        ltp.balred(sys, 4)
    with pytest.raises(ValueError, match="orders must be >= 1"):
        ltp.balred(sys, 0)
    with pytest.raises(ValueError, match="method"):
        ltp.balred(sys, 1, method='matchdc')
    unstable = ltp.ltpss(np.eye(2) * 1.2, np.ones((2, 1)), np.ones((1, 2)), 0,
                         period=0.2, dt=0.1)
    with pytest.raises(ValueError, match="sys must be stable"):
        ltp.balred(unstable, 1)
    with pytest.raises(ValueError, match="tol"):
        ltp.minreal(sys, tol=2.0)


#
# Continuous time with periodic matrices
#

_T = 1.0
_W = 2 * np.pi / _T


def _rotation():
    """Periodic rotation R(t) (planes (0,1) and (2,3)) and its derivative, Fourier form."""
    R = np.zeros((3, 4, 4), complex)
    for i in range(4):
        R[0, i, i] = R[2, i, i] = 0.5
    for i, j, sign in ((0, 1, -1), (1, 0, 1), (2, 3, -1), (3, 2, 1)):
        R[2, i, j], R[0, i, j] = -0.5j * sign, 0.5j * sign
    dR = R * (1j * _W * np.arange(-1, 2))[:, None, None]
    return ltp.PeriodicMatrix(R, _T), ltp.PeriodicMatrix(dR, _T)


def _transformed(A, B, C):
    """``x = R(t) z``: ``(R A Rᵀ + Ṙ Rᵀ, R B, C Rᵀ)``, the same input-output map."""
    R, dR = _rotation()
    return ltp.ltpss(R @ A @ R.T + dR @ R.T, R @ B, C @ R.T, 0, period=_T)


_G4 = ct.ss([[-1.0, 0.5, 0.0, 0.1], [0.0, -2.0, 1.0, 0.0], [0.0, 0.0, -3.0, 0.4],
             [0.2, 0.0, 0.0, -5.0]], [[1.0], [0.5], [0.0], [0.1]],
            [[1.0, 0.2, 0.0, 0.3]], 0)


def _fourier(coeff0, coeff1):
    """Fourier PeriodicMatrix ``M0 + 2 Re(M1 e^{jωt})``."""
    c = np.zeros((3,) + coeff0.shape, complex)
    c[1], c[2] = coeff0, coeff1
    c[0] = np.conj(coeff1)
    return ltp.PeriodicMatrix(c, _T)


def _random_periodic(seed, n=4):
    rng = np.random.default_rng(seed)
    A0 = rng.standard_normal((n, n))
    A0 -= (np.max(np.linalg.eigvals(A0).real) + 1.0) * np.eye(n)
    A1 = 0.25 * (rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n)))
    B1 = 0.15 * (rng.standard_normal((n, 1)) + 1j * rng.standard_normal((n, 1)))
    sys = ltp.ltpss(_fourier(A0, A1), _fourier(rng.standard_normal((n, 1)), B1),
                    rng.standard_normal((1, n)), 0, period=_T)
    assert sys.is_stable()
    return sys


def _htf_gain(sys, K=2):
    """sup over a frequency grid of σ_max of the central HTF blocks (a lower
    estimate of the L2 gain)."""
    H = ltp.htf(sys, K, internal_harmonics=K + 12)
    w = np.linspace(0.0, _W / 2, 41)
    return max(np.linalg.norm(H(1j * x), 2) for x in w)


@pytest.mark.parametrize('period', [0.7, 2.0, 5.0])
def test_lti_embedding_continuous_several_periods(period):
    sys = ltp.ltpss(_G4, period=period)
    hsv = np.sort(ct.hankel_singular_values(_G4))[::-1]
    np.testing.assert_allclose(ltp.hsvd(sys)[0], hsv, rtol=1e-10, atol=1e-9 * hsv[0])
    w = np.logspace(-2, 2, 9)
    for r in (1, 2, 3):
        got = ltp.balred(sys, r).to_ss().frequency_response(w).complex
        want = ct.balred(_G4, r).frequency_response(w).complex
        assert np.abs(got - want).max() < 1e-8 * np.abs(want).max()


def test_lyapunov_transformed_lti_equals_python_control():
    sys = _transformed(_G4.A, _G4.B, _G4.C)
    assert not sys.is_lti
    hsv = np.sort(ct.hankel_singular_values(_G4))[::-1]
    got = ltp.hsvd(sys, t=[0.0, 0.13, 0.5, 0.77])
    np.testing.assert_allclose(got, np.broadcast_to(hsv, got.shape), rtol=1e-8, atol=1e-9 * hsv[0])
    rsys, bound = ltp.balred(sys, 2, return_bound=True)
    assert rsys.nstates == 2 and abs(bound - 2 * hsv[2:].sum()) < 1e-9 * hsv[0]
    # the reduced HTF is diagonal with the LTI reduced model on it
    Gr = ct.balred(_G4, 2)
    H = ltp.htf(rsys, 1, internal_harmonics=12)
    for w in (0.1, 1.0, 3.0):
        Hw = H(1j * w)
        np.testing.assert_allclose(np.diag(Hw), Gr(1j * (w + _W * np.arange(-1, 2))),
                                   atol=1e-8)
        assert np.abs(Hw - np.diag(np.diag(Hw))).max() < 1e-8


@pytest.mark.slow
@pytest.mark.parametrize('seed', [1, 5])
def test_periodic_balred_error_below_the_bound(seed):
    sys = _random_periodic(seed)
    hsv = ltp.hsvd(sys)
    assert np.ptp(hsv[:, 0]) > 1e-3 * hsv[0, 0]          # genuinely time-varying
    for r in (1, 2):
        rsys, bound = ltp.balred(sys, r, return_bound=True)
        assert rsys.nstates == r and rsys.is_stable()
        assert bound >= 2 * hsv[:, r:].max(axis=0).sum() * (1 - 1e-9)
        err = _htf_gain(sys - rsys)
        assert 0 < err <= bound


def test_minreal_removes_planted_periodic_modes():
    # block structure: state 2 is never reached by u, state 3 never seen by y
    rng = np.random.default_rng(7)
    A0 = np.array([[-1.0, 0.3, 0.8, 0.0], [0.2, -2.0, 0.0, 0.0],
                   [0.0, 0.0, -1.5, 0.0], [0.5, 0.1, 0.0, -0.7]])
    mask = (A0 != 0).astype(float)
    A1 = 0.3 * mask * (rng.standard_normal((4, 4)) + 1j * rng.standard_normal((4, 4)))
    B1 = np.array([[0.2j], [0.1], [0.0], [0.3]])
    B0 = np.array([[1.0], [0.5], [0.0], [0.7]])
    C = np.array([[1.0, 0.5, 0.3, 0.0]])
    A, B = _fourier(A0, A1), _fourier(B0, B1)
    core = ltp.ltpss(A[:2, :2], B[:2, :], C[:, :2], 0, period=_T)
    big = _transformed(A, B, C)                          # then a periodic change of state
    red = ltp.minreal(big)
    assert red.nstates == 2
    H, Hc = ltp.htf(red, 1, internal_harmonics=12), ltp.htf(core, 1, internal_harmonics=12)
    for w in (0.2, 2.0):
        assert np.abs(H(1j * w) - Hc(1j * w)).max() < 1e-6
    assert ltp.minreal(core).nstates == 2


def test_periodic_reduction_bad_input():
    # two decoupled channels whose Hankel singular values cross twice a period
    b = lambda t: np.array([[1.0 + 0.5 * np.cos(_W * t), 0.0],
                            [0.0, 1.0 - 0.5 * np.cos(_W * t)]])
    sys = ltp.ltpss(-np.eye(2), b, np.eye(2), 0, period=_T)
    with pytest.raises(ValueError, match="orders=1"):
        ltp.balred(sys, 1)
    with pytest.raises(ValueError, match="orders must be at most"):
        ltp.balred(sys, 3)
    with pytest.raises(ControlArgument, match="t applies"):
        ltp.hsvd(_stable_plant(4, 2, 3, 1, 1), t=[0.0])
    with pytest.raises(ValueError, match="sys must be stable"):
        ltp.hsvd(ltp.ltpss(lambda t: np.array([[0.5 + np.cos(_W * t)]]), [[1.0]], [[1.0]],
                           0, period=_T))
    with pytest.raises(ControlArgument, match="sys must be"):
        ltp.balred(_G4, 1)
