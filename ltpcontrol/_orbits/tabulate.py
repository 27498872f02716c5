"""Matrices along an orbit, tabulated once as verified piecewise Chebyshev interpolants.

Linearisations about an orbit, ``A(t) = ∂f/∂x (x̄(t))`` and the like, are
costly to evaluate (the orbit's dense output and, without analytic
Jacobians, central differences) and are evaluated very often (transition
matrices, Riccati equations, closed-loop integrations).  On each smooth
interval ``[a, b]`` (a mode interval of the orbit) the matrix is sampled
once at the Chebyshev points of the first kind (interior points, so that
the events at the ends are never sampled) of subintervals, bisected until
the interpolant of degree `DEGREE` reproduces the matrix at other points
to ``tol (1 + max |M|)``.  An interval that does not pass at the finest
subdivision keeps the exact function (correct, only slower).
"""

import numpy as np

__all__ = []

#: degree of the Chebyshev interpolant on each subinterval
DEGREE = 16
#: relative accuracy verified at check points
TOLERANCE = 1e-9
#: finest subdivision: 2**-MAX_DEPTH of the interval
MAX_DEPTH = 12

_NODES = np.polynomial.chebyshev.chebpts1(DEGREE + 1)          # in (-1, 1)
# check points: midpoints between nodes, in (-1, 1) and off the nodes
_CHECKS = 0.5 * (_NODES[:-1] + _NODES[1:])[::3]


def tabulate(func, a, b, shape, tol=TOLERANCE):
    """Vectorised callable interpolating ``func`` on ``[a, b]`` to `tol`, or `func`.

    Parameters
    ----------
    func : callable
        ``func(t)`` for a 1D array t in ``(a, b)`` returns shape
        ``(len(t),) + shape``.
    a, b : float
        The smooth interval.
    shape : tuple
        Matrix shape.
    tol : float, optional
        Verified accuracy relative to ``1 + max |M|`` on each subinterval.

    Returns
    -------
    callable
        ``t -> (len(t),) + shape`` for 1D arrays (t clipped to ``[a, b]``),
        or `func` itself when the interpolant cannot be verified.

    Examples
    --------
    >>> from ltpcontrol._orbits.tabulate import tabulate
    >>> f = lambda t: np.exp(np.asarray(t))[:, None, None] * np.ones((1, 1, 2))
    >>> tab = tabulate(f, 0.0, 3.0, (1, 2))
    >>> t = np.linspace(0, 3, 7)
    >>> bool(np.allclose(tab(t), f(t), rtol=1e-9, atol=0)), tab is f
    (True, False)
    """
    size = int(np.prod(shape))
    pieces, stack = [], [(a, b, 0)]
    while stack:
        lo, hi, depth = stack.pop()
        mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        values = np.asarray(func(mid + half * _NODES), float).reshape(-1, size)
        coef = np.polynomial.chebyshev.chebfit(_NODES, values, DEGREE)
        exact = np.asarray(func(mid + half * _CHECKS), float).reshape(-1, size)
        err = np.max(np.abs(np.polynomial.chebyshev.chebval(_CHECKS, coef).T - exact))
        scale = 1 + max(np.max(np.abs(values)), np.max(np.abs(exact)))
        if err <= tol * scale and np.all(np.isfinite(coef)):
            pieces.append((lo, coef))
        elif depth >= MAX_DEPTH:
            return func
        else:
            stack += [(mid, hi, depth + 1), (lo, mid, depth + 1)]
    pieces.sort(key=lambda p: p[0])
    starts = np.array([p[0] for p in pieces])
    ends = np.append(starts[1:], b)
    coefs = np.array([p[1] for p in pieces])                  # (P, D+1, size)
    degrees = np.arange(DEGREE + 1)

    def evaluate(t):
        scalar = np.ndim(t) == 0
        t = np.clip(np.atleast_1d(np.asarray(t, float)), a, b)
        k = np.clip(np.searchsorted(starts, t, side='right') - 1, 0, len(starts) - 1)
        s = np.clip((2 * t - starts[k] - ends[k]) / (ends[k] - starts[k]), -1.0, 1.0)
        # Σ_j c_j T_j(s), T_j(s) = cos(j arccos s)
        basis = np.cos(np.arccos(s)[:, None] * degrees)
        out = np.einsum('tj,tjs->ts', basis, coefs[k]).reshape((len(t),) + tuple(shape))
        return out[0] if scalar else out
    return evaluate
