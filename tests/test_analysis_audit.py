"""Analysis and design against independent truths: LTI limits outside the
Floquet strip, brute-force periodic solutions, lifted systems, python-control
conventions."""

import warnings

import numpy as np
import pytest
import control as ct
from control.exception import ControlArgument

import ltpcontrol as ltp


def _sorted(z):
    z = np.asarray(z, complex)
    return z[np.lexsort((z.imag.round(8), z.real.round(8)))]


# a lightly damped LTI plant whose poles lie far outside the strip |Im| < ω_p/2 = π
_A = np.array([[0.0, 1.0], [-40.0, -0.2]])
_B = np.array([[0.0], [1.0]])
_C = np.array([[1.0, 0.0]])


def test_lti_limit_poles_and_gains_outside_the_strip():
    G = ct.ss(_A, _B, _C, 0)
    sys = ltp.ltpss(G, period=1.0)
    assert np.allclose(_sorted(ct.poles(sys)), _sorted(G.poles()), rtol=0, atol=1e-12)
    K, X, E = ltp.lqr(sys, np.eye(2), [[1.0]])
    Kc, Xc, _ = ct.lqr(G, np.eye(2), [[1.0]])
    assert np.allclose(K(0.3), Kc, atol=1e-12)
    assert np.allclose(_sorted(E), _sorted(np.linalg.eigvals(_A - _B @ Kc)), atol=1e-12)
    assert np.allclose(_sorted(ct.lqr(sys, np.eye(2), [[1.0]])[2]), _sorted(E))
    X2, L, G2 = ltp.care(_A, _B, np.eye(2), [[1.0]], period=1.0)
    assert np.allclose(_sorted(L), _sorted(E), atol=1e-12)
    Lf, P, EL = ltp.lqe(sys, [[1.0]], [[1.0]])
    Lc, _, _ = ct.lqe(G, [[1.0]], [[1.0]])
    assert np.allclose(Lf(0.7), Lc, atol=1e-10)
    assert np.allclose(_sorted(EL), _sorted(np.linalg.eigvals(_A - Lc @ _C)), atol=1e-10)


def test_lti_limit_zeros_outside_the_strip():
    G = ct.tf([1, 0.1, 50], [1, 2, 3, 4])         # zeros -0.05 ± 7.07j
    sys = ltp.ltpss(G, period=1.0)
    assert np.allclose(_sorted(ltp.zeros(sys)), _sorted(ct.zeros(G)), atol=1e-12)
    Gd = ct.ss(ct.tf([1, -0.2, 0.9], [1, 0.1, 0.2, 0.05], 0.1))  # zeros at arg ±1.47
    sysd = ltp.ltpss(Gd, period=0.4)                            # sector |arg| < π/4
    assert np.allclose(_sorted(ltp.zeros(sysd)), _sorted(ct.zeros(Gd)), atol=1e-12)


def test_lti_limit_discrete_exponents_outside_the_sector():
    Ad = np.array([[0.0, 0.9], [-0.9, 0.3]])      # eigenvalues at arg ±1.4 > π/3
    Bd = np.array([[0.0], [1.0]])
    Gd = ct.ss(Ad, Bd, np.eye(2), 0, 0.5)
    sysd = ltp.ltpss(Gd, period=1.5)              # N = 3
    assert np.allclose(_sorted(ltp.floquet_exponents(sysd)),
                       _sorted(np.linalg.eigvals(Ad)), atol=1e-12)
    K, X, E = ltp.dlqr(sysd, np.eye(2), [[1.0]])
    Kc, _, _ = ct.dlqr(Gd, np.eye(2), [[1.0]])
    assert np.allclose(K(1.0), Kc, atol=1e-12)
    assert np.allclose(_sorted(E), _sorted(np.linalg.eigvals(Ad - Bd @ Kc)), atol=1e-12)
    L, P, EL = ltp.dlqe(sysd, [[1.0]], np.eye(2))
    Lc, _, _ = ct.dlqe(Ad, Bd, np.eye(2), [[1.0]], np.eye(2))
    assert np.allclose(L(0.5), Lc, atol=1e-12)
    assert np.allclose(_sorted(EL), _sorted(np.linalg.eigvals(Ad - Lc)), atol=1e-12)


def test_h2_of_an_unstable_system_is_inf_as_python_control():
    G = ct.ss([[0.3]], [[1.0]], [[1.0]], 0)
    sys = ltp.ltpss(G, period=1.0)
    with pytest.warns(UserWarning, match="unstable"):
        ref = ct.norm(G, 2)
    for f in (ltp.norm, ct.norm):
        with pytest.warns(UserWarning, match="unstable"):
            assert f(sys, 2) == ref == np.inf
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        assert ltp.norm(sys, 2, print_warning=False) == np.inf


@pytest.mark.parametrize('call', [
    lambda A, B: ct.lyap(A, np.eye(2)), lambda A, B: ct.care(A, B, np.eye(2)),
    lambda A, B: ct.lqr(A, B, np.eye(2), 1), lambda A, B: ct.ctrb(A, B),
    lambda A, B: ct.obsv(A, B.T), lambda A, B: ct.acker(A, B, [-1, -2]),
    lambda A, B: ct.place(A, B, [-1, -2]), lambda A, B: ct.dlyap(A, np.eye(2)),
])
def test_matrix_functions_name_the_ltp_way_for_periodic_matrices(call):
    sys = ltp.ltpss(lambda t: _A + 0.1 * np.cos(2 * np.pi * t) * np.eye(2), _B, _C, 0,
                    period=1.0)
    with pytest.raises(ControlArgument, match=r"PeriodicMatrix.*use ltp\."):
        call(sys.A, sys.B)
    # the same functions on plain arrays are python-control's
    assert np.allclose(ct.ctrb(_A, _B), np.hstack([_B, _A @ _B]))


def test_riccati_refuses_a_closed_loop_left_on_the_unit_circle():
    # (A, B) = (0, ones) is not stabilizable: two Hamiltonian multiplier pairs
    # sit on the unit circle, split by round-off; python-control refuses too
    A, B = np.zeros((3, 3)), np.ones((3, 1))
    with pytest.raises(Exception):
        ct.care(A, B, np.eye(3), [[1.0]])
    with pytest.raises(ValueError, match="stabilizing"):
        ltp.care(A, B, np.eye(3), [[1.0]], period=1.0)
    sys = ltp.ltpss(A, B, np.eye(3), 0, period=1.0)
    with pytest.raises(ValueError, match="stabilizing"):
        ltp.lqr(sys, np.eye(3), [[1.0]])
    # a defective pair on the circle (A = -1, B = R = 1, Q = -1: X = -1 double)
    # is indistinguishable from a slow closed loop: a warning, never silence
    with pytest.warns(UserWarning, match="may not be stabilizing"):
        ltp.care(-np.eye(2), np.eye(2), -np.eye(2), np.eye(2), period=1.0)
    # a genuinely slow, well-posed closed loop passes silently
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        X, L, _ = ltp.care([[-1e-5]], [[0.0]], [[1.0]], [[1.0]], period=1.0)
    assert np.isclose(X(0.0)[0, 0], ct.care([[-1e-5]], [[0.0]], [[1.0]], [[1.0]])[0][0, 0])


def test_singular_monodromy_gives_zero_exponents_without_warnings():
    # A_0 singular: a multiplier exactly 0 (log|μ| = -inf) is the exponent 0
    A = np.array([[[0.5, 0.0], [0.0, 0.0]], [[1.0, 0.3], [0.0, 1.0]]])
    sys = ltp.ltpss(A, np.eye(2), np.eye(2), 0, period=2.0, dt=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        rho = ltp.floquet_exponents(sys)
        X, L, G = ltp.dare(A, np.eye(2), np.eye(2), np.eye(2))
    assert np.allclose(np.sort(np.abs(rho)), [0.0, np.sqrt(0.5)], atol=1e-15)
    assert np.count_nonzero(L == 0) == 1 and np.all(np.isfinite(L))


def test_python_control_keywords_are_accepted():
    # ct.norm(sys, 2.0, method=...) and ct.lqr(..., method=...) are valid
    # python-control calls; on an LTP system they give the periodic answer
    G = ct.ss(_A, _B, _C, 0)
    sys = ltp.ltpss(G, period=1.0)
    assert np.isclose(ct.norm(sys, 2.0, method='scipy'), ct.norm(G, 2.0, method='scipy'))
    K, _, _ = ct.lqr(sys, np.eye(2), [[1.0]], method='scipy')
    assert np.allclose(K(0.0), ct.lqr(G, np.eye(2), [[1.0]], method='scipy')[0])
    L, _, _ = ct.lqe(sys, [[1.0]], [[1.0]], method='scipy')
    assert np.allclose(L(0.0), ct.lqe(G, [[1.0]], [[1.0]], method='scipy')[0])
    sysd = ltp.sample_system(sys, 0.25)
    Gd = ct.c2d(G, 0.25)
    assert np.allclose(ct.dlqr(sysd, np.eye(2), 1.0, method='slycot')[0](0.0),
                       ct.dlqr(Gd, np.eye(2), 1.0)[0])
    assert np.allclose(ct.dlqe(sysd, 1.0, 1.0, method='slycot')[0](0.0),
                       ct.dlqe(Gd, 1.0, 1.0)[0])
    with pytest.raises(ControlArgument, match="method"):
        ltp.lqr(sys, np.eye(2), [[1.0]], method='fast')
    with pytest.raises(ControlArgument, match="method"):
        ltp.norm(sys, 2, method='fast')
    with pytest.raises(ValueError, match="p must be"):
        ltp.norm(sys, 2.5)
