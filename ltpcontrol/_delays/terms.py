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
    """`terms` without identically zero delayed terms (the undelayed one is kept)."""
    return {a: P for a, P in terms.items() if a == 0 or not is_zero(P)}


def add(X, Y):
    """Sum of two delay polynomials."""
    out = dict(X)
    for b, N in Y.items():
        k = key(b, out)
        out[k] = out[k] + N if k in out else N
    return clean(out)


def matmul(X, Y):
    """Product ``X Y`` of two delay polynomials (the right factor shifted in time)."""
    out = {}
    for a, M in X.items():
        for b, N in Y.items():
            k = key(a + b, out)
            term = M @ shift(N, a)
            out[k] = out[k] + term if k in out else term
    return clean(out)


def scale(X, c):
    """``c X`` for a scalar or a constant/periodic matrix `c` on the left."""
    if np.ndim(c) == 0 and not isinstance(c, PeriodicMatrix):
        return {a: M * float(c) for a, M in X.items()}
    return {a: c @ M for a, M in X.items()}


def block(rows, period):
    """Block polynomial from a nested list of polynomials (dicts) or matrices."""
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
    """The undelayed term of `X` (zero of `shape` when absent)."""
    return X.get(0.0, PeriodicMatrix.constant(np.zeros(shape), period))


def delayed(X):
    """The delayed terms of `X` as a sorted list of ``(a, M_a)``."""
    return sorted((a, M) for a, M in X.items() if a > 0)
