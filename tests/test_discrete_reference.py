"""The reference toolbox's published cases with time-varying dimensions.

The periodic systems toolbox of Varga (PeriodicSystems.jl, PeriodicMatrices.jl,
PeriodicMatrixEquations.jl) states these systems and the values its tests
assert: the poles of a system with factors 1x2, 2x1, 2x2 (pole 2, padded with
0), the core multiplier 1 of factors 1x2, 2x1, the zeros of the lifted
systems, and periodic Lyapunov equations with dimensions [5, 3, 3, 4, 1]
(residual below 1e-7 and agreement with a Kronecker-product solution).  The
matrices are the toolbox's; the truths are its asserted numbers and, where it
compares two of its solvers, an independent solver written here (the
Kronecker expansion of the periodic equations, the lifted LTI system).
"""

import numpy as np
import control as ct
import pytest

import ltpcontrol as ltp

NA, MA = [5, 3, 3, 4, 1], [3, 3, 4, 1, 5]       # n_k and n_(k+1) of the toolbox's test


def _m(*rows):
    return np.array(rows, dtype=float)


def _pole_two():
    """Factors 1x2, 2x1, 2x2 (states 2, 1, 2), D = 1; the toolbox's poles [2, 0]."""
    A = [_m([4, 0]), _m([1], [1]), _m([2, 0], [0, 1])]
    B = [_m([1]), _m([1], [1]), _m([1], [2])]
    C = [_m([1, 1]), _m([1]), _m([1, 0])]
    return ltp.dltpss(A, B, C, [[1.0]])


def _core_one():
    """Factors 1x2, 2x1 (states 2, 1), D = 1: core multiplier [1 0][1; 1] = 1."""
    return ltp.dltpss([_m([1, 0]), _m([1], [1])], [_m([1]), _m([1], [1])],
                      [_m([1, 1]), _m([1])], [[1.0]])


def _zeros_case():
    """Factors 1x2, 2x1 with D = 0 (the toolbox's zeros case)."""
    return ltp.dltpss([_m([1, 2]), _m([7], [8])], [_m([3]), _m([9], [10])],
                      [_m([4, 5]), _m([11])], [[0.0]])


def _zeros_and_lifted(sys, start):
    """The toolbox's check (``pszero`` against ``gzero(ps2ls(psys, start))``): the
    finite zeros raised to N, and the lifted system's finite zeros, both sorted."""
    z = ltp.zeros(sys.shifted(start))
    zl = ct.zeros(ltp.lift(sys, method='time', start=start))
    z, zl = z[np.isfinite(z)], zl[np.isfinite(zl)]
    return np.sort_complex(z ** sys.nsteps), np.sort_complex(zl)


def test_factors_1x2_2x1_2x2_poles_and_zeros():
    sys = _pole_two()
    assert sys.nstates == (2, 1, 2)
    # pspole(psys) ≈ [2, 0]; from the second step ≈ [2] ≈ lifted poles^(1/3)
    np.testing.assert_allclose(np.sort(sys.poles().real), [0.0, 2.0], atol=1e-14)
    np.testing.assert_allclose(sys.shifted(1).poles(), [2.0], rtol=1e-14)
    lifted = ct.poles(ltp.lift(sys, method='time', start=1))
    np.testing.assert_allclose(lifted ** (1 / 3), [2.0], rtol=1e-14)
    np.testing.assert_allclose(ltp.floquet_multipliers(sys), [8.0, 0.0], atol=1e-13)
    assert not ltp.is_stable(sys)
    zN, zl = _zeros_and_lifted(sys, 0)
    assert zN.size == zl.size
    np.testing.assert_allclose(zN, zl, atol=1e-8)


def test_factors_1x2_2x1_core_multiplier_one():
    sys = _core_one()
    np.testing.assert_allclose(ltp.floquet_multipliers(sys), [1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(sys.shifted(1).floquet_multipliers(), [1.0], atol=1e-15)
    assert not ltp.is_stable(sys)                  # on the unit circle
    # the toolbox: the sparse stacked and cyclic forms equal the dense ones exactly
    for method in ('stacked', 'cyclic'):
        dense = ltp.lift(sys, method=method)
        dense = dense if isinstance(dense, tuple) else (dense.A, dense.B, dense.C, dense.D)
        sparse = ltp.lift(sys, method=method, sparse=True)
        for S, M in zip(sparse, dense):
            assert np.array_equal(S.toarray(), M)
    # psys + psys - 2 psys is zero, psinv(psys) * psys is the identity (lifted)
    zero = ltp.lift(sys + sys - 2 * sys, method='time')
    Dinv = 1.0 / sys.D[0]
    inv = ltp.dltpss([a - b @ Dinv @ c for a, b, c in zip(sys.A, sys.B, sys.C)],
                     [b @ Dinv for b in sys.B], [-Dinv @ c for c in sys.C], [Dinv])
    ident = ltp.lift(inv * sys, method='time')
    for z in (0.4 + 0.3j, 2.0, np.exp(1j)):
        assert np.abs(zero(z)).max() < 1e-13
        np.testing.assert_allclose(ident(z), np.eye(2), atol=1e-13)


@pytest.mark.parametrize('start', [0, 1])
def test_factors_1x2_2x1_zeros_equal_lifted(start):
    zN, zl = _zeros_and_lifted(_zeros_case(), start)
    assert zN.size == zl.size
    np.testing.assert_allclose(zN, zl, atol=1e-8)


def _kronecker_dlyap(A, Q, adjoint):
    """Independent solution of the cyclic Lyapunov equations by the Kronecker
    expansion (the toolbox's ``pslyapdkr``): one linear system in all vec(X_k)."""
    N = len(A)
    n = [a.shape[1] for a in A]
    size = [nk * nk for nk in n]
    off = np.concatenate([[0], np.cumsum(size)])
    M = -np.eye(off[-1])
    rhs = np.zeros(off[-1])
    for k in range(N):
        k1 = (k + 1) % N
        if adjoint:      # X_k = A_kᵀ X_(k+1) A_k + Q_k
            M[off[k]:off[k + 1], off[k1]:off[k1 + 1]] += np.kron(A[k].T, A[k].T)
            rhs[off[k]:off[k + 1]] -= Q[k].ravel()
        else:            # X_(k+1) = A_k X_k A_kᵀ + Q_k
            M[off[k1]:off[k1 + 1], off[k]:off[k + 1]] += np.kron(A[k], A[k])
            rhs[off[k1]:off[k1 + 1]] -= Q[k].ravel()
    x = np.linalg.solve(M, rhs)
    return [x[off[k]:off[k + 1]].reshape(n[k], n[k]) for k in range(N)]


@pytest.mark.parametrize('adjoint', [True, False])
def test_dlyap_dims_53341_as_the_toolbox(adjoint):
    # prdlyap / pfdlyap: uniform random factors m_k x n_k, Q_k = x + xᵀ
    rng = np.random.default_rng(7)
    A = [rng.random((m, n)) for n, m in zip(NA, MA)]
    x = [rng.random((s, s)) for s in (NA if adjoint else MA)]
    Q = [xk + xk.T for xk in x]
    X = ltp.dlyap(A, Q, adjoint=adjoint)
    assert [xk.shape for xk in X] == [(n, n) for n in NA]
    if adjoint:
        res = [A[k].T @ X[(k + 1) % 5] @ A[k] - X[k] + Q[k] for k in range(5)]
    else:
        res = [A[k] @ X[k] @ A[k].T - X[(k + 1) % 5] + Q[k] for k in range(5)]
    scale = max(np.linalg.norm(xk) for xk in X)
    residual = np.sqrt(sum(np.linalg.norm(r) ** 2 for r in res))
    assert residual < 1e-7                        # the toolbox's bound
    assert residual <= 1e-12 * max(scale, 1.0)
    Xk = _kronecker_dlyap(A, Q, adjoint)
    for a, b in zip(X, Xk):
        assert np.abs(a - b).max() <= 1e-10 * max(scale, 1.0)


def test_dlyap_dims_53341_positive_form():
    # pdplyap: A = 0.1 rand, X = A X Aᵀ + B Bᵀ (forward) and X = Aᵀ X A + CᵀC
    # (adjoint) are positive semidefinite, residual below the toolbox's 1e-7
    rng = np.random.default_rng(8)
    A = [0.1 * rng.random((m, n)) for n, m in zip(NA, MA)]
    B = [rng.random((m, 2)) for m in MA]
    C = [rng.random((2, n)) for n in NA]
    P = ltp.dlyap(A, [b @ b.T for b in B])
    Qo = ltp.dlyap(A, [c.T @ c for c in C], adjoint=True)
    for k in range(5):
        k1 = (k + 1) % 5
        assert np.linalg.norm(A[k] @ P[k] @ A[k].T - P[k1] + B[k] @ B[k].T) < 1e-12
        assert np.linalg.norm(A[k].T @ Qo[k1] @ A[k] - Qo[k] + C[k].T @ C[k]) < 1e-12
        assert np.linalg.eigvalsh(P[k]).min() > -1e-12
        assert np.linalg.eigvalsh(Qo[k]).min() > -1e-12


def test_public_floquet_functions_take_time_varying_dimensions():
    # the same dispatch as every other system class: monodromy, exponents, stability
    sys = _pole_two()
    np.testing.assert_array_equal(ltp.monodromy(sys), sys.A[2] @ sys.A[1] @ sys.A[0])
    np.testing.assert_allclose(ltp.floquet_exponents(sys), [2.0, 0.0], atol=1e-14)
    verdicts = []
    for scale in (0.4, 0.6):                       # core multipliers 0.512 and 1.728
        scaled = ltp.dltpss([scale * a for a in sys.A], sys.B, sys.C, sys.D)
        lifted = ct.poles(ltp.lift(scaled, method='time'))
        verdicts.append(ltp.is_stable(scaled))
        assert verdicts[-1] is bool(np.all(np.abs(lifted) < 1))
    assert verdicts == [True, False]
    with pytest.raises(ValueError, match='tol'):
        ltp.is_stable(sys, tol=2.0)
    with pytest.raises(ct.ControlArgument, match='nsteps'):
        ltp.floquet_multipliers(sys, nsteps=4)
