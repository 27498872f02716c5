"""Algebra of delay polynomials of periodic matrices (``ltpcontrol._delays.terms``)."""

import numpy as np
from hypothesis import given, settings, strategies as st

import ltpcontrol as ltp
from ltpcontrol._delays import terms as tm

T = 1.3


def _pm(seed, shape):
    rng = np.random.default_rng(seed)
    c = rng.normal(size=(3,) + shape) + 1j * rng.normal(size=(3,) + shape)
    c[1] = c[1].real
    c[0] = np.conj(c[2])
    return ltp.PeriodicMatrix(c, T)


delays = st.floats(0.01, 3.0)


@settings(max_examples=8, deadline=None)
@given(a=delays, b=delays, seed=st.integers(0, 10_000), t=st.floats(0.0, 5.0))
def test_product_shifts_the_right_factor(a, b, seed, t):
    M, N = _pm(seed, (2, 3)), _pm(seed + 1, (3, 2))
    prod = tm.matmul({a: M}, {b: N})
    (key, P), = prod.items()
    assert abs(key - (a + b)) < 1e-12
    np.testing.assert_allclose(P(t), M(t) @ N(t - a), atol=1e-12)


@settings(max_examples=5, deadline=None)
@given(a=delays, b=delays, c=delays, seed=st.integers(0, 10_000), t=st.floats(0.0, 5.0))
def test_product_is_associative_and_distributes(a, b, c, seed, t):
    X = {0.0: _pm(seed, (2, 2)), a: _pm(seed + 1, (2, 2))}
    Y = {b: _pm(seed + 2, (2, 2))}
    Z = {0.0: _pm(seed + 3, (2, 2)), c: _pm(seed + 4, (2, 2))}
    left = tm.matmul(tm.matmul(X, Y), Z)
    right = tm.matmul(X, tm.matmul(Y, Z))
    assert sorted(left) == sorted(right) or np.allclose(sorted(left), sorted(right))
    for k in left:
        np.testing.assert_allclose(left[k](t), right[tm.key(k, right)](t), atol=1e-10)
    dist = tm.matmul(X, tm.add(Y, Z))
    summed = tm.add(tm.matmul(X, Y), tm.matmul(X, Z))
    for k in dist:
        np.testing.assert_allclose(dist[k](t), summed[tm.key(k, summed)](t), atol=1e-10)


def test_zero_terms_are_dropped_but_the_undelayed_one_is_kept():
    Z = ltp.PeriodicMatrix.constant(np.zeros((1, 1)), T)
    assert set(tm.clean({0.0: Z, 0.5: Z})) == {0.0}
