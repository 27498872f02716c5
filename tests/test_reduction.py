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
    periodic = ltp.ltpss(lambda t: np.array([[-1.0 - 0.5 * np.cos(t)]]), [[1.0]], [[1.0]], 0,
                         period=2 * np.pi)
    with pytest.raises(ControlArgument, match="sampling"):
        ltp.balred(periodic, 1)
    with pytest.raises(ValueError, match="tol"):
        ltp.minreal(sys, tol=2.0)
