"""Periodic Lyapunov equations and gramians against independent truth."""

import numpy as np
import pytest
import control as ct
from control.exception import ControlDimension

import ltpcontrol as ltp
from analysis_systems import stable_rss, transformed

RNG = np.random.default_rng(2024)


def _scalar_ok(f):
    # callables of the tests are vectorised; a scalar t gives one matrix
    def g(t):
        out = f(np.atleast_1d(t))
        return out[0] if np.ndim(t) == 0 else out
    return g


@_scalar_ok
def _stiff_A(t):
    # exponents -0.5 and -24.5 (the stiff example of floquet_exponents, shifted)
    t = np.atleast_1d(t)
    out = np.zeros((len(t), 2, 2))
    out[:, 0, 0], out[:, 0, 1] = -0.5, 1.0
    out[:, 1, 0], out[:, 1, 1] = -10 * np.cos(t), -24.5 - 10 * np.sin(t)
    return out


@_scalar_ok
def _X(t):
    t = np.atleast_1d(t)
    out = np.empty((len(t), 2, 2))
    out[:, 0, 0], out[:, 1, 1] = 2 + np.sin(t), 1 + 0.5 * np.cos(t)
    out[:, 0, 1] = out[:, 1, 0] = 0.3 * np.cos(2 * t)
    return out


@_scalar_ok
def _dX(t):
    t = np.atleast_1d(t)
    out = np.empty((len(t), 2, 2))
    out[:, 0, 0], out[:, 1, 1] = np.cos(t), -0.5 * np.sin(t)
    out[:, 0, 1] = out[:, 1, 0] = -0.6 * np.sin(2 * t)
    return out


@pytest.mark.parametrize('T', [0.7, 2.0, 5.3])
@pytest.mark.parametrize('kind', ['c', 'o'])
def test_gram_lti_continuous(T, kind):
    G = stable_rss(4, 2, 3, seed=int(10 * T))
    P = ltp.gram(ltp.ltpss(G, period=T), kind)
    ref = ct.gram(G, kind)
    ts = RNG.uniform(0, 2 * T, 5)
    assert np.abs(P(ts) - ref).max() <= 1e-9 * np.abs(ref).max()


@pytest.mark.parametrize('N', [1, 4, 5])
@pytest.mark.parametrize('kind', ['c', 'o'])
def test_gram_lti_discrete(N, kind):
    G = stable_rss(3, 2, 2, seed=N, dt=0.1)
    P = ltp.gram(ltp.ltpss(G, period=0.1 * N), kind).sample(N)
    ref = ct.dlyap(G.A, G.B @ G.B.T) if kind == 'c' else ct.dlyap(G.A.T, G.C.T @ G.C)
    assert np.abs(P - ref).max() <= 1e-9 * np.abs(ref).max()


def test_lyap_dlyap_lti_equal_python_control():
    A = np.array([[-1.0, 2.0, 0.0], [0.0, -3.0, 1.0], [0.5, 0.0, -2.0]])
    Q = np.array([[2.0, 0.5, 0.0], [0.5, 1.0, 0.2], [0.0, 0.2, 3.0]])
    for adjoint, ref in ((False, ct.lyap(A, Q)), (True, ct.lyap(A.T, Q))):
        X = ltp.lyap(A, Q, adjoint=adjoint, period=1.3)
        assert np.abs(X(np.array([0.0, 0.41, 1.0])) - ref).max() <= 1e-9 * np.abs(ref).max()
    Ad = 0.4 * A
    for N in (2, 3):
        for adjoint, ref in ((False, ct.dlyap(Ad, Q)), (True, ct.dlyap(Ad.T, Q))):
            X = ltp.dlyap(np.stack([Ad] * N), Q, adjoint=adjoint)
            assert np.abs(X - ref).max() <= 1e-9 * np.abs(ref).max()


@pytest.mark.parametrize('T, seed', [(1.0, 7), (3.0, 8), (0.4, 9)])
def test_gram_lyapunov_transformed(T, seed):
    G = stable_rss(3, 1, 2, seed=seed, strictly_proper=True)
    sys, P = transformed(G, T)
    ts = RNG.uniform(0, T, 4)
    Pc, Po = ltp.gram(sys, 'c'), ltp.gram(sys, 'o')
    Xc, Xo = ct.gram(G, 'c'), ct.gram(G, 'o')
    Pt = P(ts)
    Pinv = np.swapaxes(Pt, 1, 2)
    assert np.abs(Pc(ts) - Pt @ Xc @ np.swapaxes(Pt, 1, 2)).max() <= 1e-9 * np.abs(Xc).max()
    assert np.abs(Po(ts) - np.swapaxes(Pinv, 1, 2) @ Xo @ Pinv).max() \
        <= 1e-9 * np.abs(Xo).max()


@pytest.mark.parametrize('adjoint', [False, True])
def test_lyap_manufactured_stiff(adjoint):
    T = 2 * np.pi
    A = ltp.PeriodicMatrix.from_function(_stiff_A, T)
    At = lambda t: np.swapaxes(_stiff_A(t), -1, -2)
    if adjoint:
        Q = lambda t: -_dX(t) - At(t) @ _X(t) - _X(t) @ _stiff_A(t)
    else:
        Q = lambda t: _dX(t) - _stiff_A(t) @ _X(t) - _X(t) @ At(t)
    X = ltp.lyap(A, Q, adjoint=adjoint)
    ts = RNG.uniform(-T, 2 * T, 8)
    assert np.abs(X(ts) - _X(ts)).max() <= 1e-9


@pytest.mark.parametrize('adjoint', [False, True])
def test_lyap_manufactured_switching(adjoint):
    # A jumps at 0.4 (and Q with it): X smooth, Q = ±Ẋ - A X - X Aᵀ piecewise
    T = 2 * np.pi
    A1, A2 = np.array([[-1.0, 2.0], [0.0, -3.0]]), np.array([[-2.0, 0.0], [1.0, 0.5]])
    S = ltp.PeriodicMatrix.switching([A1, A2], [0, 0.4 * T], T)

    def Q(t):
        a = S(t)
        if adjoint:
            return -_dX(t) - np.swapaxes(a, -1, -2) @ _X(t) - _X(t) @ a
        return _dX(t) - a @ _X(t) - _X(t) @ np.swapaxes(a, -1, -2)
    Qp = ltp.PeriodicMatrix.from_function(Q, T, (2, 2), breakpoints=[0.0, 0.4 * T])
    X = ltp.lyap(S, Qp, adjoint=adjoint)
    ts = np.concatenate([RNG.uniform(0, T, 6), [0.4 * T, 0.4 * T + 1e-9]])
    assert np.abs(X(ts) - _X(ts)).max() <= 1e-9


@pytest.mark.parametrize('N', [3, 4])
@pytest.mark.parametrize('adjoint', [False, True])
def test_dlyap_manufactured_unstable_factor(N, adjoint):
    # one factor is expanding: the cyclic solve must not iterate the map
    A = RNG.standard_normal((N, 3, 3))
    A[0] *= 3.0
    L = RNG.standard_normal((N, 3, 3))
    X = L @ np.swapaxes(L, 1, 2) + np.eye(3)
    Xn = np.roll(X, -1, axis=0)
    if adjoint:
        Q = X - np.swapaxes(A, 1, 2) @ Xn @ A
    else:
        Q = Xn - A @ X @ np.swapaxes(A, 1, 2)
    assert np.abs(ltp.dlyap(A, Q, adjoint=adjoint) - X).max() <= 1e-9 * np.abs(X).max()


def test_lyap_no_unique_solution():
    # multipliers e^{±1}: μ1 μ2 = 1
    with pytest.raises(ValueError, match="no unique periodic solution"):
        ltp.lyap([[1.0, 0.0], [0.0, -1.0]], np.eye(2), period=1.0)
    with pytest.raises(ValueError, match="no unique periodic solution"):
        ltp.dlyap(np.array([[[2.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [0.0, 0.5]]]), np.eye(2))


def test_lyap_bad_input():
    A = ltp.PeriodicMatrix.constant(-np.eye(2), 1.0)
    with pytest.raises(ControlDimension, match="Q must have the shape"):
        ltp.lyap(A, np.eye(3))
    with pytest.raises(ControlDimension, match="A must be square"):
        ltp.lyap(np.ones((2, 3)), np.eye(2), period=1.0)
    with pytest.raises(ValueError, match="Q: periods .* are incommensurate"):
        ltp.lyap(A, ltp.PeriodicMatrix(np.zeros((3, 2, 2)), 0.3 * np.sqrt(2)) + np.eye(2))
    with pytest.raises(ValueError, match="Q must be symmetric"):
        ltp.lyap(A, [[1.0, 1.0], [0.0, 1.0]])
    with pytest.raises(TypeError, match="give its period"):
        ltp.lyap(-np.eye(2), np.eye(2))
    with pytest.raises(ValueError, match="A .101 steps., Q .103 steps. have the common"):
        ltp.dlyap(np.zeros((101, 2, 2)), np.zeros((103, 2, 2)))
    with pytest.raises(TypeError, match="adjoint"):
        ltp.dlyap(np.zeros((2, 2)), np.eye(2), adjoint='yes')
    unstable = ltp.ltpss([[0.5]], [[1.0]], [[1.0]], 0, period=1.0)
    with pytest.raises(ValueError, match="unstable"):
        ltp.gram(unstable, 'c')
    with pytest.raises(ValueError, match="type must be"):
        ltp.gram(ltp.ltpss([[-0.5]], [[1.0]], [[1.0]], 0, period=1.0), 'x')


@pytest.mark.parametrize('adjoint', [False, True])
def test_dlyap_single_step_equals_python_control(adjoint):
    # N = 1: the identity and the Kronecker block share the diagonal block
    A = 0.3 * RNG.standard_normal((3, 3))
    Q = np.eye(3) + 0.1 * np.ones((3, 3))
    ref = ct.dlyap(A.T, Q) if adjoint else ct.dlyap(A, Q)
    X = ltp.dlyap(A[None], Q[None], adjoint=adjoint)
    assert np.abs(X[0] - ref).max() <= 1e-12 * np.abs(ref).max()


def _lifted_dlyap(A, Q):
    """Independent solution of X[k+1] = A[k]X[k]A[k]ᵀ + Q[k]: the one-period
    Stein equation of the monodromy (Kronecker form), then the steps."""
    N, n = A.shape[0], A.shape[1]
    Psi, W = np.eye(n), np.zeros((n, n))
    for k in range(N):
        Psi, W = A[k] @ Psi, A[k] @ W @ A[k].T + Q[k]
    X0 = np.linalg.solve(np.eye(n * n) - np.kron(Psi, Psi), W.ravel()).reshape(n, n)
    X = [X0]
    for k in range(N - 1):
        X.append(A[k] @ X[-1] @ A[k].T + Q[k])
    return np.array(X)


@pytest.mark.parametrize('N', [7, 8])
def test_dlyap_of_discrete_system_matrices(N):
    # the PeriodicMatrix A and Q of a discrete-time system (held steps) are
    # taken as they are stored; Q varies on a sub-period (2 of the N steps)
    rng = np.random.default_rng(N)
    n = 3
    A = 0.6 * rng.normal(size=(N, n, n)) / np.sqrt(n)
    B = rng.normal(size=(N, n, 1))
    sysd = ltp.ltpss(A, B, np.ones((1, n)), 0, period=2.0 * N, dt=2.0)
    X = ltp.dlyap(sysd.A, sysd.B @ sysd.B.T)
    assert isinstance(X, ltp.PeriodicMatrix) and X.period == sysd.period
    ref = _lifted_dlyap(A, B @ np.swapaxes(B, 1, 2))
    assert np.abs(X.sample(N) - ref).max() <= 1e-12 * np.abs(ref).max()
    assert np.allclose(X.sample(N), ltp.dlyap(A, B @ np.swapaxes(B, 1, 2)), rtol=1e-14, atol=0)


def test_dlyap_lti_as_periodic_equals_python_control():
    G = ct.drss(4, 2, 2, dt=0.5)
    G.A *= 0.9 / max(1.0, np.abs(np.linalg.eigvals(G.A)).max())
    sysd = ltp.ltpss(G, period=1.5)
    X = ltp.dlyap(sysd.A, sysd.B @ sysd.B.T)
    assert np.allclose(X.sample(3), ct.dlyap(G.A, G.B @ G.B.T), rtol=1e-12, atol=1e-13)
    # python-control's Sylvester and generalized forms, same argument order
    Q, C = np.diag([1.0, 0.5, 0.3, 0.2]), np.arange(16.0).reshape(4, 4)
    E = np.eye(4) + 0.1 * np.ones((4, 4))
    assert np.allclose(ltp.dlyap(G.A, Q, C), ct.dlyap(G.A, Q, C), rtol=1e-12, atol=1e-12)
    assert np.allclose(ltp.dlyap(G.A, Q, None, E), ct.dlyap(G.A, Q, None, E),
                       rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match='E must be invertible'):
        ltp.dlyap(G.A, Q, None, np.zeros((4, 4)))
    smooth = ltp.PeriodicMatrix.from_function(lambda t: 0.5 * np.cos(t) * np.eye(2), 2 * np.pi)
    with pytest.raises(ct.ControlArgument, match='A is a PeriodicMatrix that is not held'):
        ltp.dlyap(smooth, np.eye(2))


@pytest.mark.parametrize('N', [7, 8])
def test_dlyap_memory_scales_as_steps_times_states_squared(N):
    # 30 states: the Kronecker form would hold N·30⁴ entries (≈ 50-200 MB);
    # the solution itself is N·30² numbers
    import tracemalloc
    rng = np.random.default_rng(N)
    n = 30
    A = np.stack([0.95 * np.linalg.qr(rng.normal(size=(n, n)))[0] @ np.diag(
        rng.uniform(0.1, 1.0, n)) for _ in range(N)])
    A[N // 2] *= 1.5                  # one expanding step, the period still contracts
    Q = rng.normal(size=(N, n, 2))
    Q = Q @ np.swapaxes(Q, 1, 2)
    tracemalloc.start()
    X = ltp.dlyap(A, Q)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 5e6
    Xn = np.roll(X, -1, axis=0)
    assert np.abs(Xn - A @ X @ np.swapaxes(A, 1, 2) - Q).max() <= 1e-12 * np.abs(X).max()
    assert np.abs(X - _lifted_dlyap(A, Q)).max() <= 1e-11 * np.abs(X).max()
    Xa = ltp.dlyap(A, Q, adjoint=True)
    At = np.swapaxes(A, 1, 2)
    assert np.abs(Xa - At @ np.roll(Xa, -1, axis=0) @ A - Q).max() <= 1e-12 * np.abs(Xa).max()
