"""The Hamiltonian of `ltp.care` in closed Fourier form equals its pointwise form.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np
import pytest

import ltpcontrol as ltp
from ltpcontrol._core.periodic_matrix import as_periodic
from ltpcontrol._analysis.riccati import _hamiltonian


def _fourier(rng, K, n, m, T, sym=False):
    c = rng.standard_normal((2 * K + 1, n, m)) + 1j * rng.standard_normal((2 * K + 1, n, m))
    c = 0.5 * (c + np.conj(c[::-1]))
    if sym:
        c = 0.5 * (c + np.swapaxes(c, 1, 2))
    return ltp.PeriodicMatrix(c, T)


@pytest.mark.parametrize("seed", range(3))
def test_fourier_form_matches_pointwise(seed):
    rng = np.random.default_rng(seed)
    n, m, T = 3, 2, 0.7
    A = _fourier(rng, 2, n, n, T)
    Q = _fourier(rng, 1, n, n, T, sym=True) + 5 * np.eye(n)
    B, S = rng.standard_normal((n, m)), 0.1 * rng.standard_normal((n, m))
    R = np.eye(m) + 0.1 * np.ones((m, m))
    ops = [as_periodic(M, T, 'M') for M in (A, B, Q, R, S)]
    H = _hamiltonian(ops, np.array([]))
    assert H.nharmonics == 2                       # the closed form was taken
    # pointwise form: A given as a callable has no Fourier form
    ops_fn = [ltp.PeriodicMatrix.from_function(lambda t: A(t), T)] + ops[1:]
    H_fn = _hamiltonian(ops_fn, np.array([]))
    assert H_fn.nharmonics is None
    t = rng.uniform(0, T, 20)
    assert np.abs(H(t) - H_fn(t)).max() <= 1e-13 * np.abs(H_fn(t)).max()
    # explicit formula
    Ri = np.linalg.inv(R)
    Ab = A(t) - B @ Ri @ S.T
    ref = np.block([[Ab, np.broadcast_to(-B @ Ri @ B.T, Ab.shape)],
                    [S @ Ri @ S.T - Q(t), -np.swapaxes(Ab, 1, 2)]])
    assert np.abs(H(t) - ref).max() <= 1e-13 * np.abs(ref).max()
    X1 = ltp.care(A, B, Q, R, S)[0]
    X2 = ltp.care(ops_fn[0], B, Q, R, S)[0]
    assert np.abs(X1(0.0) - X2(0.0)).max() <= 1e-11 * np.abs(X2(0.0)).max()
