"""Tests of Floquet analysis and the Floquet transform.

Truths: transition matrices from `scipy.integrate.solve_ivp` (rtol 1e-12)
or products of matrix exponentials (piecewise-constant A), eigenvalues
from `numpy.linalg.eigvals` / `control.ss(...).poles()`, `scipy.linalg.logm`,
closed-form exponents of published examples, and time simulations of the
original system.
"""

import warnings

import control as ct
import numpy as np
import pytest
import scipy.linalg as la
from control.exception import ControlArgument
from scipy.integrate import solve_ivp

from ltpcontrol import (floquet_exponents, floquet_multipliers, floquet_transform, is_stable,
                        monodromy)
from ltpcontrol import ltpss
from ltpcontrol import PeriodicMatrix
from ltpcontrol import forced_response


def _vectorised(entries):
    """Callable A(t) accepting scalar or 1D t from a nested list of expressions."""
    def A(t):
        t = np.asarray(t, float)
        arr = np.array([[np.broadcast_to(e, t.shape) for e in row] for row in entries(t)])
        return np.moveaxis(arr, (0, 1), (-2, -1))
    return A


def _smooth_A(rng, n, period, shift=-1.0, scale=1.0):
    A0, A1, A2 = scale * rng.standard_normal((3, n, n))
    A0 = A0 + shift * np.eye(n)
    w = 2 * np.pi / period

    def A(t):
        t = np.asarray(t, float)
        return A0 + np.multiply.outer(np.cos(w * t), A1) + np.multiply.outer(np.sin(w * t), A2)
    return A


def _ivp_monodromy(A, period):
    """Φ(T, 0) by solve_ivp on Φ̇ = A(t) Φ."""
    n = A(0.0).shape[0]
    sol = solve_ivp(lambda t, y: (A(t) @ y.reshape(n, n)).ravel(), (0, period),
                    np.eye(n).ravel(), method='DOP853', rtol=1e-12, atol=1e-14)
    return sol.y[:, -1].reshape(n, n)


def _sorted(z):
    return z[np.lexsort((np.round(z.imag, 8), np.round(z.real, 8)))]


_STIFF_A = _vectorised(lambda t: [[0.0, 1.0], [-10 * np.cos(t), -24 - 10 * np.sin(t)]])


def _stiff():
    A = _STIFF_A
    return ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi)


def _zhou_hagiwara(period):
    A = _vectorised(lambda t: [[-1 - np.sin(2 * t) ** 2, 2 - 0.5 * np.sin(4 * t)],
                               [-2 - 0.5 * np.sin(4 * t), -1 - np.cos(2 * t) ** 2]])
    return ltpss(A, [[1.0], [0.5]], [[1.0, -1.0]], 0, period=period)


def _switching_sys():
    T = 1.0
    A1 = np.array([[0.0, 1.0], [-4.0, -0.3]])
    A2 = np.array([[0.0, 1.0], [-1.0, -2.0]])
    A3 = np.array([[-0.5, 0.2], [0.1, -1.0]])
    times = [0.0, 0.3, 0.55]
    A = PeriodicMatrix.switching([A1, A2, A3], times, T)
    B = PeriodicMatrix.switching([[[0.0], [1.0]], [[1.0], [0.5]]], [0.0, 0.5], T)
    sys = ltpss(A, B, [[1.0, 0.0], [0.3, 1.0]], 0, period=T)
    truth = la.expm(A3 * 0.45) @ la.expm(A2 * 0.25) @ la.expm(A1 * 0.3)
    return sys, truth


def _mathieu_4_24(zeta=0.3, beta=0.1, wn=2 * np.pi, wp=4 * np.pi):
    A = _vectorised(lambda t: [[0.0, 1.0],
                               [-(1 + 2 * beta * np.cos(wp * t)) * wn ** 2, -2 * zeta * wn]])
    return ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi / wp), A


def _io_check(sys, sysF, P, tfinal, x0, npts=241, tol=1e-8):
    """Outputs (and states x = P z) of sys and sysF agree for the same input."""
    t = np.linspace(0, tfinal, npts)
    u = np.stack([np.sin(2.3 * t + j) + 0.5 * np.cos(5.1 * t) for j in range(sys.ninputs)])
    r1 = forced_response(sys, t, u, x0)
    z0 = np.linalg.solve(P(0.0), x0)
    r2 = forced_response(sysF, t, u, z0)
    scale = max(1.0, np.abs(r1.outputs).max())
    assert np.abs(r1.outputs - r2.outputs).max() <= tol * scale
    xz = np.einsum('kij,jk->ik', P(t), np.atleast_2d(r2.states))
    assert np.abs(np.atleast_2d(r1.states) - xz).max() <= tol * max(1.0, np.abs(r1.states).max())


#
# Monodromy, multipliers, exponents
#

def test_monodromy_and_multipliers_random_smooth():
    rng = np.random.default_rng(0)
    A = _smooth_A(rng, 4, 1.5)
    sys = ltpss(A, np.ones((4, 1)), np.ones((1, 4)), 0, period=1.5)
    truth = _ivp_monodromy(A, 1.5)
    assert np.allclose(monodromy(sys), truth, rtol=1e-9, atol=1e-11)
    mu = floquet_multipliers(sys)
    assert np.allclose(_sorted(mu), _sorted(np.linalg.eigvals(truth)), rtol=1e-9, atol=1e-12)
    # documented order: decreasing modulus, conjugate pairs positive imaginary first
    assert np.all(np.diff(np.abs(mu)) <= 1e-12)
    lam = floquet_exponents(sys)
    assert np.allclose(np.exp(lam * 1.5), mu, rtol=1e-12)
    assert np.all(np.abs(lam.imag) <= np.pi / 1.5 + 1e-12)


def test_multipliers_switching_exact():
    sys, truth = _switching_sys()
    assert np.allclose(monodromy(sys), truth, rtol=1e-11, atol=1e-13)
    assert np.allclose(_sorted(floquet_multipliers(sys)), _sorted(np.linalg.eigvals(truth)),
                       rtol=1e-10)
    # a coarse grid still contains the switching instants
    assert np.allclose(monodromy(sys, nsteps=1), truth, rtol=1e-11, atol=1e-13)


def test_lti_limit_continuous():
    rng = np.random.default_rng(3)
    A = rng.standard_normal((5, 5)) - np.eye(5)
    period = 0.2            # keeps Im eig(A) inside (-ω_p/2, ω_p/2]
    sys = ltpss(A, np.ones((5, 1)), np.ones((1, 5)), 0, period=period)
    poles = ct.ss(A, np.ones((5, 1)), np.ones((1, 5)), 0).poles()
    assert np.allclose(_sorted(floquet_exponents(sys)), _sorted(poles), atol=1e-10)
    assert np.allclose(_sorted(floquet_exponents(sys)), _sorted(np.linalg.eigvals(A)),
                       atol=1e-10)
    sysF, P = floquet_transform(sys)
    assert np.allclose(sysF.A(0.0), A, atol=1e-9)
    assert np.allclose(P(np.linspace(0, period, 5)), np.eye(5), atol=1e-9)


def test_lti_limit_discrete():
    rng = np.random.default_rng(4)
    S = rng.standard_normal((3, 3)) + 2 * np.eye(3)
    A = S @ np.array([[0.7, 0.2, 0.0], [-0.2, 0.7, 0.0], [0.0, 0.0, 0.4]]) @ np.linalg.inv(S)
    sys = ltpss(A, np.ones((3, 1)), np.ones((1, 3)), 0, period=0.4, dt=0.1)
    ev = np.linalg.eigvals(A)
    assert np.allclose(_sorted(floquet_multipliers(sys)), _sorted(ev ** 4), atol=1e-12)
    assert np.all(np.abs(np.angle(ev)) < np.pi / 4)     # inside the principal sector
    assert np.allclose(_sorted(floquet_exponents(sys)), _sorted(ev), atol=1e-12)


def test_stiff_example_exponents():
    sys = _stiff()
    lam = floquet_exponents(sys)
    assert abs(lam[0]) < 1e-8
    assert abs(lam[1] + 24) < 1e-8
    # the small multiplier e^{-48π} keeps its relative accuracy
    mu = floquet_multipliers(sys)
    assert abs(mu[1] / np.exp(-48 * np.pi) - 1) < 1e-6
    assert abs(mu[0] - 1) < 1e-8
    assert not is_stable(sys)


def test_zhou_hagiwara_exponents():
    lam = floquet_exponents(_zhou_hagiwara(np.pi / 2))
    assert np.allclose(lam, [-1 + 2j, -2 + 2j], atol=1e-10)
    mu = floquet_multipliers(_zhou_hagiwara(np.pi / 2))
    assert np.allclose(mu, [-np.exp(-np.pi / 2), -np.exp(-np.pi)], rtol=1e-10)
    assert np.all(mu.imag == 0)
    assert np.allclose(floquet_exponents(_zhou_hagiwara(np.pi)), [-1, -2], atol=1e-10)


def test_mathieu_4_115_constant_A():
    wn, zeta = 2 * np.pi, 0.3
    A = np.array([[0, 1], [-wn ** 2, -2 * zeta * wn]])
    B = PeriodicMatrix.from_function(
        lambda t: np.array([[0.0], [1 + 0.4 * np.cos(4 * np.pi * t)]]), 0.5)
    C = lambda t: np.array([[1 + 0.2 * np.cos(4 * np.pi * t), 0.0]])
    sys = ltpss(A, B, C, 0, period=0.5)
    expected = -zeta * wn + 1j * wn * np.sqrt(1 - zeta ** 2) * np.array([1, -1])
    assert np.allclose(floquet_exponents(sys), expected, atol=1e-10)
    sysF, P = floquet_transform(sys)
    assert np.allclose(sysF.A(0.0), A, atol=1e-10)          # already in Floquet form
    assert np.allclose(P(np.linspace(0, 0.5, 7)), np.eye(2), atol=1e-10)


@pytest.mark.parametrize("zeta, beta, stable", [(0.3, 0.1, True), (0.1, 0.2, True),
                                                (0.0, 0.2, False)])
def test_damped_mathieu_4_24(zeta, beta, stable):
    sys, A = _mathieu_4_24(zeta, beta)
    truth = np.linalg.eigvals(_ivp_monodromy(A, sys.period))
    mu = floquet_multipliers(sys)
    assert np.allclose(_sorted(mu), _sorted(truth), rtol=1e-9, atol=1e-12)
    assert is_stable(sys) is stable
    if (zeta, beta) == (0.1, 0.2):
        # principal parametric resonance: largest |μ| ≈ 0.9993
        assert abs(np.abs(mu[0]) - 0.9993) < 5e-4


def test_switching_damped_mathieu_table_4_1():
    wn, wp, T = 2 * np.pi, 4 * np.pi, 0.5

    def piece(zeta, beta):
        return _vectorised(lambda t: [[0.0, 1.0], [-(1 + 2 * beta * np.cos(wp * t)) * wn ** 2,
                                                   -2 * zeta * wn]])
    pieces = [piece(0.3, 0.1), piece(0.1, 0.2)]
    A = PeriodicMatrix.switching(pieces, [0.0, T / 2], T)
    sys = ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T)
    # truth: solve_ivp on each smooth half
    n = 2
    Phi = np.eye(n)
    for f, (a, b) in zip(pieces, [(0, T / 2), (T / 2, T)]):
        sol = solve_ivp(lambda t, y: (f(t) @ y.reshape(n, n)).ravel(), (a, b), np.eye(n).ravel(),
                        method='DOP853', rtol=1e-12, atol=1e-14)
        Phi = sol.y[:, -1].reshape(n, n) @ Phi
    assert np.allclose(monodromy(sys), Phi, rtol=1e-9, atol=1e-12)
    assert np.allclose(_sorted(floquet_multipliers(sys)), _sorted(np.linalg.eigvals(Phi)),
                       rtol=1e-9)


def test_discrete_multipliers_and_singular_factor():
    rng = np.random.default_rng(5)
    Ak = rng.standard_normal((5, 3, 3))
    sys = ltpss(Ak, np.ones((5, 3, 1)), np.ones((5, 1, 3)), 0, period=1.0, dt=0.2)
    prod = Ak[4] @ Ak[3] @ Ak[2] @ Ak[1] @ Ak[0]
    assert np.allclose(monodromy(sys), prod)
    assert np.allclose(_sorted(floquet_multipliers(sys)), _sorted(np.linalg.eigvals(prod)))
    assert np.allclose(floquet_exponents(sys) ** 5, floquet_multipliers(sys))
    Ak[2, :, 0] = 0.0                                     # singular factor
    sing = ltpss(Ak, np.ones((5, 3, 1)), np.ones((5, 1, 3)), 0, period=1.0, dt=0.2)
    assert np.min(np.abs(floquet_multipliers(sing))) < 1e-12
    with pytest.raises(ValueError, match=r"A\[2\] is singular"):
        floquet_transform(sing)


#
# Floquet transform
#

def test_transform_random_smooth():
    rng = np.random.default_rng(1)
    A = _smooth_A(rng, 3, 1.0)
    B = lambda t: np.array([[1.0], [0.5 * np.cos(2 * np.pi * t)], [0.2]])
    sys = ltpss(A, B, [[1.0, 0, 0], [0, 1, 1]], [[0.0], [0.1]], period=1.0, name='rnd')
    sysF, P = floquet_transform(sys)
    assert sysF.is_floquet_form and sysF.period == 1.0 and sysF.name == 'rnd$floquet'
    F = sysF.A(0.0)
    assert np.allclose(F, la.logm(_ivp_monodromy(A, 1.0)).real, atol=1e-9)
    assert np.allclose(P(0.0), np.eye(3), atol=1e-12) and np.allclose(P(1.0), np.eye(3))
    # Φ(t, 0) = P(t) e^{Ft} at an off-grid time
    t1 = 0.3717
    sol = solve_ivp(lambda t, y: (A(t) @ y.reshape(3, 3)).ravel(), (0, t1), np.eye(3).ravel(),
                    method='DOP853', rtol=1e-12, atol=1e-14)
    assert np.allclose(sol.y[:, -1].reshape(3, 3), P(t1) @ la.expm(F * t1), atol=1e-10)
    _io_check(sys, sysF, P, 2.5, np.array([1.0, -0.5, 0.3]))


def test_transform_stiff():
    sys = _stiff()
    with pytest.warns(UserWarning, match="ill-conditioned"):
        sysF, P = floquet_transform(sys)
    F = sysF.A(0.0)
    assert np.allclose(np.sort(np.linalg.eigvals(F).real), [-24, 0], atol=1e-8)
    t = np.linspace(0, 2 * np.pi, 50)
    assert np.abs(P(t)).max() < 10                                    # bounded P(t)
    # Liouville: det P(t) = exp(∫_0^t tr A - t tr F) = exp(-10 (1 - cos t))
    assert np.allclose(np.linalg.det(P(t)), np.exp(-10 * (1 - np.cos(t))), rtol=1e-7, atol=0)
    # Φ(t, 0) = P(t) e^{Ft}
    A = _STIFF_A
    sol = solve_ivp(lambda t, y: (A(t) @ y.reshape(2, 2)).ravel(), (0, 2.0), np.eye(2).ravel(),
                    method='DOP853', rtol=1e-12, atol=1e-14)
    assert np.allclose(sol.y[:, -1].reshape(2, 2), P(2.0) @ la.expm(F * 2.0), atol=1e-9)
    # away from t = π, where det P(t) = e^{-20}, the Floquet form simulates accurately
    _io_check(sys, sysF, P, 1.0, np.array([1.0, -2.0]), npts=101)


def test_transform_switching():
    sys, truth = _switching_sys()
    sysF, P = floquet_transform(sys, real=False)
    assert sysF.period == 1.0
    assert np.allclose(la.expm(sysF.A(0.0) * 1.0), truth, atol=1e-10)
    assert np.all(np.isin(sys.A.breakpoints, P.breakpoints))
    _io_check(sys, sysF, P, 2.0, np.array([0.5, 1.0]), npts=201)


def test_transform_negative_multipliers_doubles_period():
    sys = _zhou_hagiwara(np.pi / 2)
    with pytest.warns(UserWarning, match="2T"):
        sysF, P = floquet_transform(sys)
    assert sysF.period == pytest.approx(np.pi)
    assert np.allclose(_sorted(np.linalg.eigvals(sysF.A(0.0))), [-2, -1], atol=1e-9)
    assert np.allclose(P(np.pi), np.eye(2), atol=1e-10)
    assert not np.allclose(P(np.pi / 2), np.eye(2), atol=1e-3)    # only 2T-periodic
    _io_check(sys, sysF, P, 4.0, np.array([1.0, 0.5]), npts=161)
    with pytest.raises(ValueError, match="real=True"):
        floquet_transform(sys, real=False)


def test_transform_defective_monodromy_fallback():
    # double integrator: Φ(T, 0) = [[1, T], [0, 1]] is defective
    B = lambda t: np.array([[0.0], [1 + 0.5 * np.cos(2 * np.pi * t)]])
    sys = ltpss([[0.0, 1.0], [0.0, 0.0]], B, [[1.0, 0.0]], 0, period=1.0)
    sysF, P = floquet_transform(sys)
    assert np.allclose(sysF.A(0.0), [[0, 1], [0, 0]], atol=1e-10)
    _io_check(sys, sysF, P, 2.0, np.array([0.2, -0.1]), npts=101)


def _dt_simulate(Ak, Bk, Ck, Dk, u, x0):
    N, x, y = len(Ak), x0.copy(), []
    for k in range(u.shape[1]):
        j = k % N
        y.append(Ck[j] @ x + Dk[j] @ u[:, k])
        x = Ak[j] @ x + Bk[j] @ u[:, k]
    return np.array(y).T


@pytest.mark.parametrize("nper, negative", [(5, False), (5, True), (4, True)])
def test_transform_discrete(nper, negative):
    rng = np.random.default_rng(7 + nper)
    Ak = 0.6 * rng.standard_normal((nper, 3, 3))
    if negative:
        # make the product have a negative real eigenvalue
        Ak[0] = np.diag([-0.9, 0.5, 0.7]) @ np.eye(3)
        Ak[1:] = np.eye(3) + 0.05 * rng.standard_normal((nper - 1, 3, 3))
    Bk, Ck = rng.standard_normal((nper, 3, 1)), rng.standard_normal((nper, 2, 3))
    Dk = rng.standard_normal((nper, 2, 1))
    sys = ltpss(Ak, Bk, Ck, Dk, period=nper * 0.1, dt=0.1)
    double = negative and nper % 2 == 0
    with warnings.catch_warnings():
        warnings.simplefilter('error' if not double else 'ignore')
        sysF, P = floquet_transform(sys)
    nw = 2 * nper if double else nper
    assert sysF.period == pytest.approx(nw * 0.1) and sysF.dt == 0.1
    AF = sysF.A(0.0)
    assert np.allclose(np.linalg.matrix_power(AF, nper),
                       monodromy(sys), atol=1e-10) or double
    assert np.allclose(np.linalg.matrix_power(AF, nw),
                       np.linalg.matrix_power(monodromy(sys), nw // nper), atol=1e-10)
    u = rng.standard_normal((1, 3 * nw + 2))
    x0 = rng.standard_normal(3)
    y1 = _dt_simulate(Ak, Bk, Ck, Dk, u, x0)
    Pk = P.sample(nw)
    y2 = _dt_simulate(np.broadcast_to(AF, (nw, 3, 3)), sysF.B.sample(nw), sysF.C.sample(nw),
                      sysF.D.sample(nw), u, np.linalg.solve(Pk[0], x0))
    assert np.allclose(y1, y2, atol=1e-10)


#
# Validation
#

def test_validation():
    sys = _zhou_hagiwara(np.pi)
    with pytest.raises(TypeError, match="unexpected keyword argument 'method'"):
        floquet_transform(sys, method='x')
    with pytest.raises(ControlArgument, match="real"):
        floquet_transform(sys, real='yes')
    with pytest.raises(ControlArgument, match="sys"):
        floquet_multipliers(np.eye(2))
    with pytest.raises(ValueError, match="nsteps"):
        monodromy(sys, nsteps=0)
    with pytest.raises(ValueError, match="tol"):
        is_stable(sys, tol=-1)
    dsys = ltpss(np.ones((2, 1, 1)), [[1.0]], [[1.0]], 0, period=0.2, dt=0.1)
    with pytest.raises(ControlArgument, match="nsteps"):
        floquet_exponents(dsys, nsteps=4)
    nostate = ltpss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), 1.0, period=1.0)
    assert floquet_multipliers(nostate).size == 0 and is_stable(nostate)
    with pytest.raises(ValueError, match="no states"):
        floquet_transform(nostate)


def test_stiff_exponents_without_stiff_step_counts():
    # two Mathieu oscillators drive lags at -3e4 that do not feed back: the lag
    # exponents are the lag rates (multipliers e^{-3e4} underflow any product),
    # the others those of the oscillators' own monodromy (DOP853)
    w = 2 * np.pi
    lags = np.array([-3e4, -4.2e4])

    def A(t):
        K = np.array([[1.0 + 0.3 * np.cos(w * t), 0.2], [0.2, 2.3 + 0.2 * np.sin(2 * w * t)]])
        out = np.zeros((6, 6))
        out[:2, 2:4] = np.eye(2)
        out[2:4, :2] = -w ** 2 * K
        out[2:4, 2:4] = -np.diag([0.3, 0.1])
        out[4:, 2:4] = [[1.0, -2.0], [0.5, 3.0]]
        out[4:, 4:] = np.diag(lags)
        return out
    sys = ltpss(A, np.zeros((6, 1)), np.zeros((1, 6)), 0, period=1.0)
    lam = floquet_exponents(sys)
    sol = solve_ivp(lambda t, x: (A(t)[:4, :4] @ x.reshape(4, 4)).ravel(), (0, 1),
                    np.eye(4).ravel(), method='DOP853', rtol=1e-12, atol=1e-14)
    slow = np.log(np.abs(np.linalg.eigvals(sol.y[:, -1].reshape(4, 4))))
    truth = np.concatenate([np.sort(slow), np.sort(lags)])
    got = np.sort(lam.real)[::-1]
    truth = np.sort(truth)[::-1]
    assert np.abs(got - truth).max() <= 1e-8 * np.abs(truth).max()
    assert np.allclose(got[-2:], np.sort(lags)[::-1], rtol=1e-12, atol=0)
    assert np.allclose(got[:4], truth[:4], rtol=1e-8, atol=1e-9)
