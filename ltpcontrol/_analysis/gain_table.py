"""Verified piecewise Chebyshev tables of periodic gains.

A periodic Riccati gain ``G(t)`` (`ltpcontrol.care`, `ltpcontrol.lqr`,
`ltpcontrol.lqe`) is smooth between the switching instants of the data.
When designed, it is sampled at the Chebyshev points of every piece of a
partition of the period and interpolated; the interpolant is checked
against the exact gain at other points and pieces that miss the accuracy
are bisected.  The table is data-backed (picklable, saved by
`ltpcontrol.save`) and evaluates one time with a handful of flops, which is
what a simulation of the closed loop calls at every solver step.
"""

import bisect
import math
import warnings

import numpy as np

from .._core.pm_ops import register_func

# uniform pieces a verified table (gain, X) starts from before bisection;
# step grids up to _GRID_STEPS steps are used directly (cheaper short flows),
# longer (stiff) ones give way to these coarse pieces and exact values
_TABLE_PIECES = 32
_GRID_STEPS = 256
# tabulated gain: degree on every piece, verified relative accuracy (to
# 1 + max |G| on the piece), finest bisection of a step
_GAIN_DEG = 16
_GAIN_TOL = 1e-9
_GAIN_DEPTH = 12


def _tabulated(G, grid):
    """``(edges, coefs)`` of G as a verified piecewise Chebyshev table, or None.

    On every step ``[t_k, t_{k+1}]`` (where the data and the interpolant of X
    are smooth) G is sampled at the Chebyshev points of the first kind and
    the degree-`_GAIN_DEG` interpolant is compared with G at other points;
    steps that miss `_GAIN_TOL` are bisected, at most `_GAIN_DEPTH` times.
    """
    m, n = G.shape
    nodes = np.polynomial.chebyshev.chebpts1(_GAIN_DEG + 1)
    checks = 0.5 * (nodes[:-1] + nodes[1:])[::3]
    vander = np.polynomial.chebyshev.chebvander(nodes, _GAIN_DEG)
    at_checks = np.polynomial.chebyshev.chebvander(checks, _GAIN_DEG)
    lo, hi = grid[:-1], grid[1:]
    starts, coefs = [], []
    for _ in range(_GAIN_DEPTH + 1):
        mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        values = G((mid[:, None] + half[:, None] * nodes).ravel()).reshape(len(lo), -1, m * n)
        exact = G((mid[:, None] + half[:, None] * checks).ravel()).reshape(len(lo), -1, m * n)
        coef = np.linalg.solve(vander, values)
        err = np.abs(at_checks @ coef - exact).max(axis=(1, 2))
        scale = 1 + np.maximum(np.abs(values).max(axis=(1, 2)), np.abs(exact).max(axis=(1, 2)))
        ok = (err <= _GAIN_TOL * scale) & np.all(np.isfinite(coef), axis=(1, 2))
        starts.append(lo[ok])
        coefs.append(coef[ok])
        lo, hi = np.concatenate([lo[~ok], mid[~ok]]), np.concatenate([mid[~ok], hi[~ok]])
        if not len(lo):
            break
    else:
        return None                  # not verified at the finest subdivision
    starts, coefs = np.concatenate(starts), np.concatenate(coefs)
    order = np.argsort(starts)
    return (np.append(starts[order], grid[-1]),
            coefs[order].reshape(len(order), _GAIN_DEG + 1, m, n))


class _GainTable:
    """Piecewise Chebyshev series of a gain, ``t -> (m, n)`` (data-backed).

    ``edges`` (P + 1) split ``[0, T]``; ``coefs[k, j]`` (P, D + 1, m, n) is
    the coefficient of ``T_j(s)``, ``s = (2t - e_k - e_{k+1}) / (e_{k+1} - e_k)``
    on piece k.  Pieces are closed on the left: at an edge the piece that
    starts there is used (within ``1e-12 T``, as for switching matrices).
    `scalar` evaluates one time with Python floats and one small product.

    Built from the exact gain (a `PeriodicMatrix`) and the step grid, the
    table is tabulated on first use, or when pickled or saved; if it cannot
    be verified, the exact gain is evaluated instead.
    """

    def __init__(self, edges=None, coefs=None, exact=None, grid=None):
        self.exact, self.grid, self.edges, self.coefs = exact, grid, None, None
        self._ready = coefs is not None
        if self._ready:
            self.edges, self.coefs = np.asarray(edges, float), np.asarray(coefs, float)
            self._setup()

    def _setup(self):
        P, D1, m, n = self.coefs.shape
        self._flat = self.coefs.reshape(P, D1, m * n)
        self._list = self.edges.tolist()
        self._degrees = np.arange(D1, dtype=float)
        self._period = float(self.edges[-1])
        self._shape = (m, n)

    def _build(self):
        if not self._ready:
            table = _tabulated(self.exact, self.grid)
            if table is not None:
                self.edges, self.coefs = table
                self.exact = self.grid = None
                self._setup()
            else:
                warnings.warn("the periodic gain could not be verified as a Chebyshev table "
                              f"(relative accuracy {_GAIN_TOL:.0e}); it is evaluated from the "
                              "Riccati solution at every call instead (slower)", UserWarning,
                              stacklevel=5)
            self._ready = True
        return self.coefs is not None

    def __getstate__(self):
        self._build()
        return {'edges': self.edges, 'coefs': self.coefs, 'exact': self.exact}

    def __setstate__(self, state):
        self.__init__(state['edges'], state['coefs'], state['exact'])
        self._ready = True

    def scalar(self, t):
        """Value at one float time t, shape (m, n)."""
        if not self._ready:
            self._build()
        if self.coefs is None:
            return self.exact(t)
        T, edges = self._period, self._list
        eps = 1e-12 * T
        tau = t % T
        if tau >= T - eps:
            tau -= T
        k = bisect.bisect_right(edges, tau + eps) - 1
        last = len(edges) - 2
        k = 0 if k < 0 else (last if k > last else k)
        a, b = edges[k], edges[k + 1]
        s = (2 * tau - a - b) / (b - a)
        s = -1.0 if s < -1.0 else (1.0 if s > 1.0 else s)
        # Σ_j c_j T_j(s), T_j(s) = cos(j arccos s)
        return (np.cos(self._degrees * math.acos(s)) @ self._flat[k]).reshape(self._shape)

    def __call__(self, t):
        if np.ndim(t) == 0:
            return self.scalar(float(t))
        if not self._build():
            return self.exact(t)
        T, edges = self._period, self.edges
        eps = 1e-12 * T
        tau = np.mod(np.asarray(t, float), T)
        tau[tau >= T - eps] -= T
        k = np.clip(np.searchsorted(edges, tau + eps, side='right') - 1, 0, len(edges) - 2)
        a, b = edges[k], edges[k + 1]
        s = np.clip((2 * tau - a - b) / (b - a), -1.0, 1.0)
        basis = np.cos(np.arccos(s)[:, None] * self._degrees)
        return np.einsum('tj,tjs->ts', basis, self._flat[k]).reshape((len(tau),) + self._shape)

    def _portable(self):
        if not self._build():
            raise TypeError("save: the gain could not be tabulated to its verified accuracy; "
                            "save the Riccati solution X and compute the gain from it")
        return 'gain_table', {}, {'edges': self.edges, 'coefs': self.coefs}

    @classmethod
    def _from_portable(cls, params, arrays):
        return cls(arrays['edges'], arrays['coefs'])


register_func('gain_table', _GainTable)


def _table_edges(grid, breaks):
    """Initial pieces of a gain table: the step grid when it is short, else
    `_coarse_edges`."""
    if len(grid) - 1 <= _GRID_STEPS:
        return np.asarray(grid, float)
    return _coarse_edges(grid[-1], breaks)


def _coarse_edges(period, breaks):
    """Initial pieces of a verified table: `_TABLE_PIECES` uniform pieces and
    the switching instants (the solution is smooth in between, whatever the
    step grid of the solver)."""
    edges = np.linspace(0.0, period, _TABLE_PIECES + 1)
    edges = np.union1d(edges, np.mod(np.asarray(breaks, float), period))
    keep = np.concatenate([[True], np.diff(edges) > 1e-12 * period])
    edges = edges[keep]
    edges[-1] = period
    return edges

