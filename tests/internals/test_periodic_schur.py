"""Eigenvalues of matrix products by the periodic Schur form.

Tests of internals: they import private names (see the Developer notes).
"""

import warnings

import numpy as np
import pytest
from control.exception import ControlDimension
from hypothesis import given, settings, strategies as st

from ltpcontrol._core.periodic_schur import product_eigenvalues


def _sorted_complex(logmod, arg):
    mu = np.exp(logmod) * np.exp(1j * arg)
    return mu[np.lexsort((mu.imag, mu.real))]


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 4), st.integers(1, 6), st.integers(0, 2**32 - 1))
def test_matches_eigenvalues_of_the_formed_product(n, k, seed):
    rng = np.random.default_rng(seed)
    factors = rng.standard_normal((k, n, n))
    prod = np.eye(n)
    for F in factors:
        prod = F @ prod
    expected = np.linalg.eigvals(prod)
    logmod, arg = product_eigenvalues(factors)
    assert np.all(np.diff(logmod) <= 0)
    got = _sorted_complex(logmod, arg)
    expected = expected[np.lexsort((expected.imag, expected.real))]
    scale = np.abs(expected).max()
    assert np.allclose(got, expected, atol=1e-8 * scale)


@settings(max_examples=30, deadline=None)
@given(st.integers(2, 4), st.integers(2, 60), st.integers(0, 2**32 - 1))
def test_graded_products_keep_relative_accuracy(n, k, seed):
    # F_j = Q_{j+1} T_j Q_jᵀ with triangular T_j and Q_k = Q_0: the product is
    # Q_0 (T_{k-1}...T_0) Q_0ᵀ, whose eigenvalues are the products of the
    # diagonals, graded over up to hundreds of decades
    rng = np.random.default_rng(seed)
    Q = [np.linalg.qr(rng.standard_normal((n, n)))[0] for _ in range(k + 1)]
    Q[-1] = Q[0]
    rates = np.sort(rng.uniform(-8, 1, n))[::-1]
    T = [np.triu(rng.standard_normal((n, n)), 1)
         + np.diag(rng.choice([-1, 1], n) * np.exp(rates + 0.1 * rng.standard_normal(n)))
         for _ in range(k)]
    # F_j = Q_{j+1} T_j Q_jᵀ: F_{k-1}...F_0 = Q_0 (T_{k-1}...T_0) Q_0ᵀ
    factors = [Q[j + 1] @ T[j] @ Q[j].T for j in range(k)]
    exact = np.sum([np.log(np.abs(np.diag(t))) for t in T], axis=0)
    negative = np.count_nonzero(np.prod([np.sign(np.diag(t)) for t in T], axis=0) < 0)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', UserWarning)   # ill-conditioned draws announce it
        logmod, arg, err = product_eigenvalues(factors, error=True)
    # accurate to the estimated error (an honest estimate), itself small
    exact = np.sort(exact)
    bound = np.maximum(10 * err, 1e-9) * (1 + np.abs(exact))
    assert np.all(np.abs(np.sort(logmod) - exact) <= bound)
    if err < 1e-10:
        assert np.count_nonzero(arg == np.pi) == negative


def test_tiny_eigenvalues_keep_relative_accuracy():
    # exact flows of x' = diag(0, -a) x in a rotating basis: eigenvalue e^{-a k h}
    rng = np.random.default_rng(1)
    k, h, a = 200, 0.5, 8.0
    Q = [np.linalg.qr(rng.standard_normal((3, 3)))[0] for _ in range(k)]
    Q.append(Q[0])
    D = np.diag(np.exp(np.array([0.0, -a, -0.5 * a]) * h))
    factors = [Q[j + 1] @ D @ Q[j].T for j in range(k)]
    logmod, _ = product_eigenvalues(factors)
    assert np.allclose(logmod, np.array([0.0, -0.5 * a, -a]) * h * k, rtol=1e-12, atol=1e-9)


def test_complex_pair_and_negative():
    c, s = np.cos(0.4), np.sin(0.4)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, -0.5]])
    logmod, arg = product_eigenvalues([R, 2 * R])
    assert np.allclose(logmod, [np.log(2), np.log(2), np.log(0.5)])
    assert np.allclose(arg, [0.8, -0.8, 0.0])


def test_zero_eigenvalue_and_sizes():
    logmod, arg = product_eigenvalues([np.diag([1.0, 0.0])])
    assert logmod[0] == 0 and logmod[1] == -np.inf
    assert product_eigenvalues(np.zeros((1, 0, 0)))[0].size == 0
    assert np.allclose(product_eigenvalues([[2.0]])[0], np.log(2))


def test_bad_input():
    with pytest.raises(ControlDimension, match='factors'):
        product_eigenvalues(np.ones((2, 2, 3)))
    with pytest.raises(ValueError, match='at least one'):
        product_eigenvalues(np.zeros((0, 2, 2)))
    with pytest.raises(ValueError, match='finite'):
        product_eigenvalues([[[np.nan]]])


def test_ill_conditioned_product_is_announced():
    # strongly non-normal graded factors: the eigenvalues are sensitive to
    # rounding, and the estimated error says so
    rng = np.random.default_rng(1)
    n, k = 4, 43
    Q = [np.linalg.qr(rng.standard_normal((n, n)))[0] for _ in range(k + 1)]
    Q[-1] = Q[0]
    T = [np.triu(rng.standard_normal((n, n)), 1) + np.diag(np.exp(-8 * np.arange(n) / 3))
         for _ in range(k)]
    exact = k * (-8 * np.arange(n) / 3)
    factors = [Q[j + 1] @ T[j] @ Q[j].T for j in range(k)]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        logmod, _, err = product_eigenvalues(factors, error=True)
    actual = np.abs(logmod - exact).max()
    if err * 400 > 1e-6:
        assert any('accurate only' in str(w.message) for w in caught)
    assert actual <= 10 * err * 400


def test_rounding_noise_of_numerically_singular_factors_is_not_announced():
    # closed-loop factors of a periodic LQR (Hench & Laub 1994, example 2) are each
    # singular to working precision: the product's third eigenvalue is rounding
    # noise (true value 0); the determined ones are exact and nothing is announced
    rng = np.random.default_rng(7)
    factors = []
    for _ in range(3):
        U, _ = np.linalg.qr(rng.standard_normal((3, 3)))
        V, _ = np.linalg.qr(rng.standard_normal((3, 3)))
        factors.append(U @ np.diag([20.0, 5.0, 0.0]) @ V.T)      # rank 2, rounded
    dense = np.linalg.eigvals(factors[2] @ factors[1] @ factors[0])
    big = np.sort_complex(dense[np.abs(dense) > 1e-6])
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        logmod, arg = product_eigenvalues(factors)
    mu = np.exp(logmod) * np.exp(1j * arg)
    assert np.allclose(np.sort_complex(mu[:2]), big, rtol=1e-10)
    assert abs(mu[2]) <= 1e-12 * abs(mu[0])
