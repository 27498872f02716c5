"""The two solvers of the cyclic periodic Lyapunov equation agree."""

import numpy as np
import pytest
import control as ct

from ltpcontrol._analysis.lyapunov import cyclic_lyap, stein


@pytest.mark.parametrize('N', [1, 7, 8])
@pytest.mark.parametrize('adjoint', [False, True])
def test_monodromy_equals_sparse(N, adjoint):
    rng = np.random.default_rng(N + 10 * adjoint)
    n = 5
    Phi = 0.9 * rng.normal(size=(N, n, n)) / np.sqrt(n)
    Phi[0] *= 3.0                       # steps that expand, a period that may not
    W = rng.normal(size=(N, n, n))
    W = W + np.swapaxes(W, 1, 2)        # indefinite weights
    a = cyclic_lyap(Phi, W, adjoint, method='sparse')
    b = cyclic_lyap(Phi, W, adjoint, method='monodromy')
    assert np.abs(a - b).max() <= 1e-11 * np.abs(a).max()


def test_monodromy_lti_equals_python_control():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(6, 6)) / 3
    Q = np.eye(6)
    X = cyclic_lyap(np.stack([A] * 4), np.stack([Q] * 4), method='monodromy')
    assert np.allclose(X, ct.dlyap(A, Q), rtol=1e-12, atol=1e-13)
    Xa = cyclic_lyap(np.stack([A] * 4), np.stack([Q] * 4), True, method='monodromy')
    assert np.allclose(Xa, ct.dlyap(A.T, Q), rtol=1e-12, atol=1e-13)
    assert np.allclose(stein(A, Q), ct.dlyap(A, Q), rtol=1e-12, atol=1e-13)


def test_monodromy_refuses_nonunique():
    Phi = np.array([[[2.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [0.0, 0.5]]])
    with pytest.raises(ValueError, match='no unique periodic solution'):
        cyclic_lyap(Phi, np.stack([np.eye(2)] * 2), method='monodromy')
    with pytest.raises(ValueError, match='method must be'):
        cyclic_lyap(Phi, np.stack([np.eye(2)] * 2), method='dense')
