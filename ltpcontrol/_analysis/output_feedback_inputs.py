"""Input checks and plant-data interpolation of periodic output feedback.

The design weights and the initial-state covariance of `ltpcontrol.oflqr`
(symmetric, Q ⪰ 0, R ≻ 0, X0 ⪰ 0), per-step matrices of discrete plants,
and the Chebyshev surrogate ``t -> [M(t) ...]`` that the continuous
objective's integrator samples instead of the plant's own callables.
"""

import warnings

import numpy as np
from control.exception import ControlArgument, ControlDimension

from .._core.chebyshev import PiecewiseChebyshev, chebyshev_nodes
from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .._core.validation import real_array

__all__ = []

#: Chebyshev degree of the surrogate on each step of the period grid
_CHEB = 16


def _covariance(X0, n):
    if X0 is None:
        return np.eye(n)
    X0 = real_array(X0, 'X0', ndim=2)
    if X0.shape != (n, n):
        raise ControlDimension(f"X0 must have shape {(n, n)}, got {X0.shape}")
    if np.abs(X0 - X0.T).max() > 1e-10 * max(1.0, np.abs(X0).max()) \
            or np.linalg.eigvalsh(0.5 * (X0 + X0.T)).min() < -1e-12 * np.abs(X0).max():
        raise ValueError("X0 must be symmetric positive semidefinite")
    return 0.5 * (X0 + X0.T)


def _per_step(M, sys, name, shape):
    if M is None:
        raise ControlArgument(f"{name} is required")
    if isinstance(M, PeriodicMatrix) or callable(M):
        arr = as_periodic(M, sys.period, name).sample(sys.nsteps)
    else:
        arr = real_array(M, name, ndim=(2, 3))
        if arr.ndim == 3 and arr.shape[0] != sys.nsteps:
            raise ControlDimension(f"{name} has {arr.shape[0]} matrices but the period has "
                                   f"{sys.nsteps} steps")
    if arr.shape[-2:] != shape:
        raise ControlDimension(f"{name} must have shape {shape}, got {arr.shape[-2:]}")
    return np.broadcast_to(arr, (sys.nsteps,) + shape).copy()


def _check_weights(Q, R):
    for M, name in ((Q, 'Q'), (R, 'R')):
        if np.abs(M - np.swapaxes(M, 1, 2)).max() > 1e-10 * max(1.0, np.abs(M).max()):
            raise ValueError(f"{name} must be symmetric")
    if np.linalg.eigvalsh(Q).min() < -1e-12 * max(1.0, np.abs(Q).max()):
        raise ValueError("Q must be positive semidefinite")
    if np.linalg.eigvalsh(R).min() <= 0:
        raise ValueError("R must be positive definite")


class _Surrogate:
    """``t -> [M(t) for M in mats]`` from Chebyshev interpolants on the grid steps."""

    def __init__(self, mats, grid):
        self.parts = []
        nodes = (grid[:-1, None] + np.diff(grid)[:, None] * chebyshev_nodes(_CHEB)).ravel()
        probe = grid[:-1] + 0.3817 * np.diff(grid)
        for M in mats:
            vals = M(nodes).reshape((len(grid) - 1, _CHEB + 1) + M.shape)
            interp = PiecewiseChebyshev(grid, vals)
            exact = M(probe)
            err = np.abs(interp(probe) - exact).max() / max(1.0, np.abs(exact).max())
            if err > 1e-10:
                warnings.warn(f"the plant data vary fast within the steps of the period grid "
                              f"(interpolation error {err:.1e}); increase nsteps", UserWarning,
                              stacklevel=4)
            self.parts.append(interp)

        self.cache = {}

    def __call__(self, t):
        # the integrator asks for the same node sets at every evaluation of
        # the objective: remember them (bounded)
        t = np.atleast_1d(np.asarray(t, float))
        key = t.tobytes()
        if key not in self.cache:
            if len(self.cache) > 64:
                self.cache.clear()
            self.cache[key] = [f(t) for f in self.parts]
        return self.cache[key]


_surrogate = _Surrogate


def _is_zero(D):
    probe = np.concatenate([np.arange(16) * D.period / 16, D.breakpoints])
    return not np.any(D(probe))
