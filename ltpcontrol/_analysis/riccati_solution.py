"""The stabilizing periodic Riccati solution X(t) between the step boundaries.

`ltpcontrol.care` computes X exactly at the boundaries ``t_k`` of its step
grid.  Inside a step ``[t_k, t_{k+1}]``, ``X(t) = V U⁻¹`` with ``[U; V] =
Φ_H(t_{k+1}, t)⁻¹ [I; X_{k+1}]``: the backward Hamiltonian flow, which
contracts onto the stabilizing solution.  It is evaluated exactly, or
through a verified piecewise Chebyshev interpolant (built at Chebyshev
points of every step for short grids, or on coarse pieces bisected until
verified for long, stiff ones) so that the solution is data-backed when
pickled or saved.
"""

import warnings

import numpy as np

from .._core.chebyshev import PiecewiseChebyshev, chebyshev_nodes, piecewise_chebyshev
from .._core.pm_ops import register_func
from .._core.transition import step_transitions
from .gain_table import _GRID_STEPS, _coarse_edges

# degree of the Chebyshev interpolant of X(t) on every step
_CHEB_DEG = 16
# steps per call of the integrator (bounded memory)
_FLOW_CHUNK = 512
# finest bisection of a coarse piece of the interpolant
_INTERP_DEPTH = 12


class _RiccatiSolution:
    """X(t) of `care`: exact at the step boundaries and, between them, by the
    backward Hamiltonian flow over the partial step (exact, bounded cost).

    A verified piecewise Chebyshev interpolant (`_interpolant`) is built
    when the solution is pickled or saved, so that it is data-backed; once
    built (or after loading) it serves the evaluations.
    """

    def __init__(self, H, grid, Xg, interp=None, breaks=()):
        self.H, self.grid, self.Xg, self.interp = H, grid, Xg, interp
        self.breaks = np.asarray(breaks, float)

    def __call__(self, t):
        grid = self.grid
        period = grid[-1]
        tau = np.mod(np.atleast_1d(np.asarray(t, float)), period)
        k = np.searchsorted(grid, tau)
        on = np.abs(grid[np.minimum(k, len(grid) - 1)] - tau) <= 1e-14 * period
        if np.all(on):                      # step boundaries: no interpolant needed
            return self.Xg[k]
        if self.interp is not None or self.H is None or len(grid) - 1 <= _GRID_STEPS:
            return self._interpolant()(t)
        return _exact_values(self.H, grid, self.Xg, tau)

    def _interpolant(self):
        if self.interp is None:
            self.interp = _interpolant(self.H, self.grid, self.Xg, self.breaks)
        return self.interp

    def __getstate__(self):
        self._interpolant()
        return {'H': None, 'grid': self.grid, 'Xg': self.Xg, 'interp': self.interp,
                'breaks': self.breaks}

    def __setstate__(self, state):
        self.__init__(state['H'], state['grid'], state['Xg'], state['interp'],
                      state.get('breaks', ()))

    def _portable(self):
        it = self._interpolant()
        return 'riccati_solution', {}, {'grid': self.grid, 'Xg': self.Xg,
                                        'interp_grid': it.grid, 'interp_values': it.values}

    @classmethod
    def _from_portable(cls, params, arrays):
        return cls(None, arrays['grid'], arrays['Xg'],
                   PiecewiseChebyshev(arrays['interp_grid'], arrays['interp_values']))


register_func('riccati_solution', _RiccatiSolution)


def _grid_interpolant(H, grid, Xg):
    """X(t) inside the steps of a short grid: the backward flow at Chebyshev
    points of every step, interpolated (``16 x len(grid)`` short flows)."""
    n = Xg.shape[1]
    cheb = chebyshev_nodes(_CHEB_DEG)
    nodes = grid[:-1, None] + np.diff(grid)[:, None] * cheb
    sub = _flow(H, nodes[:, :-1].ravel(), np.diff(nodes, axis=1).ravel())
    sub = sub.reshape(len(grid) - 1, _CHEB_DEG, 2 * n, 2 * n)
    # W[k, j] = Φ_H(t_{k+1}, s_j),  [U; V] = W⁻¹ [I; X_{k+1}]
    W = np.empty((len(grid) - 1, _CHEB_DEG + 1, 2 * n, 2 * n))
    W[:, -1] = np.eye(2 * n)
    for j in range(_CHEB_DEG - 1, -1, -1):
        W[:, j] = W[:, j + 1] @ sub[:, j]
    values = _graph(np.linalg.solve(W, _stack(Xg[1:])[:, None]), n)
    values[:, 0] = Xg[:-1]
    interp = piecewise_chebyshev(grid, values)
    probe = grid[:-1] + 0.3717 * np.diff(grid)
    exact = _graph(np.linalg.solve(_flow(H, probe, grid[1:] - probe), _stack(Xg[1:])), n)
    err = np.abs(interp(probe) - exact).max() / max(1.0, np.abs(exact).max())
    if err > 1e-10:
        warnings.warn(f"the interpolated Riccati solution has relative errors up to "
                      f"{err:.1e} inside the steps; increase nsteps", UserWarning,
                      stacklevel=4)
    return interp



def _exact_values(H, grid, Xg, tau):
    """X at the times tau in [0, T): ``[U; V] = Φ_H(t_{k+1}, τ)⁻¹ [I; X_{k+1}]``
    on the step k that holds τ (the backward flow contracts onto the
    stabilizing solution)."""
    n = Xg.shape[1]
    k = np.clip(np.searchsorted(grid, tau, side='right') - 1, 0, len(grid) - 2)
    Phi = _flow(H, tau, grid[k + 1] - tau)
    return _graph(np.linalg.solve(Phi, _stack(Xg[k + 1])), n)


def _interpolant(H, grid, Xg, breaks):
    """`_grid_interpolant` for a grid of at most `_GRID_STEPS` steps, else
    `_coarse_interpolant`."""
    if len(grid) - 1 <= _GRID_STEPS:
        return _grid_interpolant(H, grid, Xg)
    return _coarse_interpolant(H, grid, Xg, breaks)


def _coarse_interpolant(H, grid, Xg, breaks):
    """Verified piecewise Chebyshev interpolant of X (`PiecewiseChebyshev`).

    Pieces start from `_coarse_edges` (X is smooth between switching
    instants, whatever the solver's step grid) and are bisected, at most
    `_INTERP_DEPTH` times, until the interpolant matches the exact values at
    interior probes to 1e-10 relative.  The cost is set by the smoothness
    of X, not by the stiffness of the data.
    """
    n = Xg.shape[1]
    period = grid[-1]
    scale = max(np.abs(Xg).max(), 1e-300)
    nodes = chebyshev_nodes(_CHEB_DEG)
    probe = np.array([0.1234, 0.3717, 0.6543, 0.8911])
    bary = (-1.0) ** np.arange(_CHEB_DEG + 1)
    bary[[0, -1]] *= 0.5
    weights = bary / (probe[:, None] - nodes[None, :])
    weights /= weights.sum(axis=1, keepdims=True)
    edges = _coarse_edges(period, breaks)
    lo, hi = edges[:-1], edges[1:]
    starts, values, err = [], [], 0.0
    for depth in range(_INTERP_DEPTH + 1):
        h = (hi - lo)[:, None]
        vals = _exact_values(H, grid, Xg, (lo[:, None] + h * nodes).ravel())
        vals = vals.reshape(len(lo), _CHEB_DEG + 1, n, n)
        exact = _exact_values(H, grid, Xg, (lo[:, None] + h * probe).ravel())
        approx = np.einsum('pj,kjab->kpab', weights, vals)
        dev = np.abs(approx - exact.reshape(approx.shape)).max(axis=(1, 2, 3)) / scale
        ok = dev <= 1e-10
        if depth == _INTERP_DEPTH:
            ok[:] = True
            err = float(dev.max(initial=0.0))
        starts.append(lo[ok])
        values.append(vals[ok])
        mid = 0.5 * (lo + hi)
        lo, hi = np.concatenate([lo[~ok], mid[~ok]]), np.concatenate([mid[~ok], hi[~ok]])
        if not len(lo):
            break
    starts, values = np.concatenate(starts), np.concatenate(values)
    order = np.argsort(starts)
    if err > 1e-10:
        warnings.warn(f"the interpolated Riccati solution has relative errors up to "
                      f"{err:.1e} inside the steps; increase nsteps", UserWarning,
                      stacklevel=4)
    return PiecewiseChebyshev(np.append(starts[order], period), values[order])



def _graph(UV, n):
    """``X = V U⁻¹`` for stacked ``[U; V]`` (shape (..., 2n, n)), symmetrized."""
    U, V = UV[..., :n, :], UV[..., n:, :]
    if UV.ndim == 2:
        X = np.linalg.solve(U.T, V.T).T
        return 0.5 * (X + X.T)
    X = np.swapaxes(np.linalg.solve(np.swapaxes(U, -1, -2), np.swapaxes(V, -1, -2)), -1, -2)
    return 0.5 * (X + np.swapaxes(X, -1, -2))


def _stack(X):
    """``[I; X]`` for one or many X."""
    n = X.shape[-1]
    ident = np.broadcast_to(np.eye(n), X.shape)
    return np.concatenate([ident, X], axis=-2)


def _flow(H, t0, h):
    """Transition matrices of many steps, computed in chunks of `_FLOW_CHUNK`
    steps so that the integrator's sub-step stacks stay bounded."""
    t0 = np.atleast_1d(np.asarray(t0, float))
    h = np.broadcast_to(np.asarray(h, float), t0.shape)
    if len(t0) <= _FLOW_CHUNK:
        return step_transitions(H, None, t0, h)[0]
    d = H.shape[0]
    out = np.empty((len(t0), d, d))
    for i in range(0, len(t0), _FLOW_CHUNK):
        out[i:i + _FLOW_CHUNK] = step_transitions(H, None, t0[i:i + _FLOW_CHUNK],
                                                  h[i:i + _FLOW_CHUNK])[0]
    return out

