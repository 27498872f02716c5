"""Delay polynomials of periodic matrices: ``M(t, σ) = Σ_a M_a(t) σ^a``.

A term ``M_a(t) σ^a`` acts on a signal as ``v ↦ M_a(t) v(t - a)``.  A
block of a delayed LTP system (its A, B, C or D) is such a polynomial,
stored as a dict ``{a: PeriodicMatrix}`` with ``a = 0`` the undelayed
part.  The product of two terms shifts the right factor in time,

    (M_a σ^a)(N_b σ^b) v = M_a(t) N_b(t - a) v(t - a - b),

so block-diagram algebra on delayed periodic systems is the algebra of
these polynomials.
"""

import numpy as np

from .._core.periodic_matrix import PeriodicMatrix, as_periodic

__all__ = []

# delays closer than this (relative to the largest) are one delay
_KEY_RTOL = 1e-12


def key(a, keys=()):
    """The delay `a`, snapped onto an equal one of `keys` (rounding of sums).

    Examples
    --------
    >>> from ltpcontrol._delays.terms import key
    >>> key(0.1 + 0.2, [0.3]) == 0.3
    True
    """
    a = float(a)
    for k in keys:
        if abs(k - a) <= _KEY_RTOL * max(1.0, abs(a)):
            return k
    return a


def is_zero(P):
    """True when the periodic matrix `P` is identically zero (checked on samples).

    Examples
    --------
    >>> from ltpcontrol._delays.terms import is_zero
    >>> is_zero(ltp.PeriodicMatrix.constant(np.zeros((2, 2)), 1.0))
    True
    """
    if P.is_constant:
        return not np.any(P(0.0))
    t = (np.arange(64) + 0.37) / 64 * P.period
    return not np.any(P(np.concatenate([t, P.breakpoints])))


def shift(P, a):
    """The periodic matrix ``t ↦ P(t - a)``.

    Examples
    --------
    >>> from ltpcontrol._delays.terms import shift
    >>> P = ltp.PeriodicMatrix.from_function(lambda t: np.array([[np.cos(t)]]), 2 * np.pi)
    >>> bool(np.isclose(shift(P, 1.0)(1.0)[0, 0], 1.0))
    True
    """
    if a == 0 or P.is_constant:
        return P
    T = P.period
    a = float(np.mod(a, T))
    if a == 0:
        return P
    return PeriodicMatrix.from_function(lambda t: P(np.asarray(t, float) - a), T, P.shape,
                                        breakpoints=np.mod(P.breakpoints + a, T), check=False)


def clean(terms):
    """`terms` without identically zero delayed terms (the undelayed one is kept).

    Examples
    --------
    >>> from ltpcontrol._delays.terms import clean
    >>> Z = ltp.PeriodicMatrix.constant(np.zeros((1, 1)), 1.0)
    >>> sorted(clean({0.0: Z, 0.5: Z, 1.0: Z + 1}))
    [0.0, 1.0]
    """
    return {a: P for a, P in terms.items() if a == 0 or not is_zero(P)}


def add(X, Y):
    """Sum of two delay polynomials (terms of equal delay added).

    Examples
    --------
    >>> from ltpcontrol._delays.terms import add
    >>> P = lambda v: ltp.PeriodicMatrix.constant(np.array([[v]]), 1.0)
    >>> S = add({0.0: P(1.0), 0.5: P(2.0)}, {0.1 + 0.4: P(3.0)})
    >>> {a: float(M(0.0)[0, 0]) for a, M in S.items()}
    {0.0: 1.0, 0.5: 5.0}
    """
    out = dict(X)
    for b, N in Y.items():
        k = key(b, out)
        out[k] = out[k] + N if k in out else N
    return clean(out)


def matmul(X, Y):
    """Product ``X Y`` of two delay polynomials (the right factor shifted in time).

    Examples
    --------
    ``(σ^a M)(N(t) σ^b) = M N(t - a) σ^{a+b}``:

    >>> from ltpcontrol._delays.terms import matmul
    >>> M = ltp.PeriodicMatrix.constant(np.array([[2.0]]), 2 * np.pi)
    >>> N = ltp.PeriodicMatrix.from_function(lambda t: np.array([[np.cos(t)]]), 2 * np.pi)
    >>> prod = matmul({0.5: M}, {0.25: N})
    >>> list(prod), bool(np.isclose(prod[0.75](1.0)[0, 0], 2 * np.cos(0.5)))
    ([0.75], True)
    """
    out = {}
    for a, M in X.items():
        for b, N in Y.items():
            k = key(a + b, out)
            term = M @ shift(N, a)
            out[k] = out[k] + term if k in out else term
    return clean(out)


def scale(X, c):
    """``c X`` for a scalar or a constant/periodic matrix `c` on the left.

    Examples
    --------
    >>> from ltpcontrol._delays.terms import scale
    >>> X = {0.0: ltp.PeriodicMatrix.constant(np.eye(2), 1.0)}
    >>> scale(X, -2.0)[0.0](0.0).tolist(), scale(X, np.ones((1, 2)))[0.0](0.0).tolist()
    ([[-2.0, -0.0], [-0.0, -2.0]], [[1.0, 1.0]])
    """
    if np.ndim(c) == 0 and not isinstance(c, PeriodicMatrix):
        return {a: M * float(c) for a, M in X.items()}
    return {a: c @ M for a, M in X.items()}


def block(rows, period):
    """Block polynomial from a nested list of polynomials (dicts) or matrices.

    Examples
    --------
    >>> from ltpcontrol._delays.terms import block
    >>> d = {0.3: ltp.PeriodicMatrix.constant(np.array([[4.0]]), 1.0)}
    >>> B = block([[d, np.array([[1.0]])]], 1.0)
    >>> {a: M(0.0).tolist() for a, M in B.items()}
    {0.0: [[0.0, 1.0]], 0.3: [[4.0, 0.0]]}
    """
    rows = [[P if isinstance(P, dict) else {0.0: as_periodic(P, period, 'block')}
             for P in row] for row in rows]
    keys = []
    for row in rows:
        for P in row:
            for a in P:
                if key(a, keys) not in keys:
                    keys.append(float(a))
    heights = [next(iter(r[0].values())).shape[0] for r in rows]
    widths = [next(iter(P.values())).shape[1] for P in rows[0]]
    out = {}
    for k in sorted(keys):
        grid = [[_at(P, k, (h, w), period) for P, w in zip(row, widths)]
                for row, h in zip(rows, heights)]
        out[k] = PeriodicMatrix.block(grid)
    return clean(out)


def _at(P, k, shape, period):
    for a, M in P.items():
        if key(a, [k]) == k:
            return M
    return np.zeros(shape)


def undelayed(X, shape, period):
    """The undelayed term of `X` (zero of `shape` when absent).

    Examples
    --------
    >>> from ltpcontrol._delays.terms import undelayed
    >>> undelayed({0.5: ltp.PeriodicMatrix.constant(np.eye(1), 1.0)}, (1, 2), 1.0)(0.0)
    array([[0., 0.]])
    """
    return X.get(0.0, PeriodicMatrix.constant(np.zeros(shape), period))


def delayed(X):
    """The delayed terms of `X` as a sorted list of ``(a, M_a)``.

    Examples
    --------
    >>> from ltpcontrol._delays.terms import delayed
    >>> P = ltp.PeriodicMatrix.constant(np.eye(1), 1.0)
    >>> [a for a, _ in delayed({0.0: P, 0.7: P, 0.2: P})]
    [0.2, 0.7]
    """
    return sorted((a, M) for a, M in X.items() if a > 0)
