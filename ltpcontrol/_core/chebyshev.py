"""Piecewise Chebyshev interpolation of matrix values given on every step of a grid.

Periodic quantities computed exactly at Chebyshev points inside every step
of a period grid (the Floquet transformation P(t), periodic Riccati and
Lyapunov solutions) are stored as their values there and evaluated by the
barycentric formula on the step that contains t.
"""

import numpy as np

from .pm_ops import register_func

__all__ = []


def chebyshev_nodes(degree):
    """Chebyshev points ``(1 - cos(jπ/D))/2``, j = 0..D, on [0, 1].

    Examples
    --------
    >>> from ltpcontrol._core.chebyshev import chebyshev_nodes
    >>> chebyshev_nodes(2)
    array([0. , 0.5, 1. ])
    >>> c = chebyshev_nodes(5)
    >>> bool(np.allclose(c + c[::-1], 1.0))          # symmetric about 1/2
    True
    """
    return 0.5 * (1 - np.cos(np.pi * np.arange(degree + 1) / degree))


def piecewise_chebyshev(grid, values):
    """Callable interpolating matrix values given on every grid interval.

    ``values[k, j]`` is the value at ``t_k + h_k c_j`` (`chebyshev_nodes`);
    evaluation (at times taken modulo ``grid[-1]``) is by the barycentric
    formula on the interval that contains t.

    Examples
    --------
    Degree-3 nodes reproduce ``t³`` exactly on each interval, and t is taken
    modulo the period ``grid[-1] = 3``:

    >>> from ltpcontrol._core.chebyshev import chebyshev_nodes, piecewise_chebyshev
    >>> grid = np.array([0.0, 1.0, 3.0])
    >>> t = grid[:-1, None] + np.diff(grid)[:, None] * chebyshev_nodes(3)
    >>> f = piecewise_chebyshev(grid, t ** 3)
    >>> bool(np.allclose(f([0.4, 2.5, 3.4]), [0.4 ** 3, 2.5 ** 3, 0.4 ** 3]))
    True
    """
    return PiecewiseChebyshev(grid, values)


class PiecewiseChebyshev:
    """Data-backed callable of `piecewise_chebyshev` (picklable, storable)."""

    def __init__(self, grid, values):
        self.grid, self.values = np.asarray(grid, float), np.asarray(values)

    def __call__(self, t):
        grid, values = self.grid, self.values
        period, starts, h = grid[-1], grid[:-1], np.diff(grid)
        degree = values.shape[1] - 1
        cheb = chebyshev_nodes(degree)
        bary = (-1.0) ** np.arange(degree + 1)
        bary[[0, -1]] *= 0.5
        tau = np.mod(np.atleast_1d(np.asarray(t, float)), period)
        k = np.clip(np.searchsorted(starts, tau, side='right') - 1, 0, len(starts) - 1)
        xi = np.clip((tau - starts[k]) / h[k], 0.0, 1.0)
        diff = xi[:, None] - cheb[None, :]
        hit = diff == 0
        with np.errstate(divide='ignore'):
            weights = np.where(hit.any(axis=1, keepdims=True), hit.astype(float), bary / diff)
        weights /= weights.sum(axis=1, keepdims=True)
        return np.einsum('sj,sj...->s...', weights, values[k])

    def _portable(self):
        return 'chebyshev', {}, {'grid': self.grid, 'values': self.values}

    @classmethod
    def _from_portable(cls, params, arrays):
        return cls(arrays['grid'], arrays['values'])


register_func('chebyshev', PiecewiseChebyshev)
