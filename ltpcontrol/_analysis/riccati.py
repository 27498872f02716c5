"""Stabilizing periodic solutions of periodic Riccati equations.

Continuous time, ``-Ẋ = AᵀX + XA - (XB + S) R⁻¹ (BᵀX + Sᵀ) + Q`` with
T-periodic data.  With ``Ā = A - BR⁻¹Sᵀ`` and ``Q̄ = Q - SR⁻¹Sᵀ`` the
state/costate ``z = [x; λ]`` of the optimal control problem obeys
``ż = H(t) z``, ``H = [[Ā, -BR⁻¹Bᵀ], [-Q̄, -Āᵀ]]``, and the stabilizing
solution is ``X(t) = V(t) U(t)⁻¹`` where ``[U; V]`` spans the stable
invariant subspace of the Hamiltonian flow.  The period is split into short
steps ``t_0 = 0 < ... < t_M = T`` (switching instants are step boundaries);
the step factors ``Ψ_k = Φ_H(t_{k+1}, t_k)`` come from the library's Magnus
integrator.

Discrete time, ``X_k = A_kᵀX_{k+1}A_k - (A_kᵀX_{k+1}B_k + S_k)(R_k +
B_kᵀX_{k+1}B_k)⁻¹(B_kᵀX_{k+1}A_k + S_kᵀ) + Q_k``: step k is the symplectic
pencil ``L_k [x_{k+1}; λ_{k+1}] = M_k [x_k; λ_k]`` with
``L_k = [[I, B_kR_k⁻¹B_kᵀ], [0, Ā_kᵀ]]``, ``M_k = [[Ā_k, 0], [-Q̄_k, I]]``
(continuous time: ``L_k = I``, ``M_k = Ψ_k``).

Both cases then share one algorithm:

1. collapse the cyclic product ``L_{M-1}⁻¹M_{M-1} ... L_0⁻¹M_0`` into one
   2n x 2n pencil ``(L, M)`` with orthogonal transformations only: for two
   neighbouring factors, a QR factorisation of ``[L_k; -M_{k+1}]`` gives
   ``[Z1 Z2]`` with ``Z1 L_k = Z2 M_{k+1}``, so ``M_{k+1} L_k⁻¹ = Z2⁻¹ Z1``
   and the pair becomes ``(Z2 L_{k+1}, Z1 M_k)``; pairs are merged in a
   balanced tree.  No product, inverse or exponential of a stiff flow is
   formed;
2. the stable deflating subspace ``[U; V]`` of ``(M, L)`` by ordered QZ
   gives ``X_0 = V U⁻¹`` (exactly n multipliers inside the unit circle
   are required: otherwise no stabilizing solution exists);
3. the other samples by the backward recursion (the Riccati map, which is
   contractive towards the stabilizing solution), ``X_M = X_0``; the
   mismatch between the recursion's ``X_0`` and the pencil's is the
   periodicity residual, removed by Newton steps on the periodicity
   condition (one Stein equation each) and checked;
4. the closed-loop step factors (``U`` of ``Ψ_k [I; X_k]``, or
   ``A_k - B_k G_k``) give the closed-loop multipliers through the
   periodic Schur form (`ltpcontrol._core.floquet`).

Values inside a step ``[t_k, t_{k+1}]`` are ``X(t) = V U⁻¹`` with
``[U; V] = Φ_H(t_{k+1}, t)⁻¹ [I; X_{k+1}]`` (the backward flow, which
contracts onto the stabilizing solution), computed at Chebyshev points of
every step when X is first evaluated between the step boundaries and
interpolated (checked against the exact value inside every step).
"""

import bisect
import math
import warnings

import numpy as np
import scipy.linalg as la
from control.exception import ControlArgument, ControlDimension

from .._core.floquet import (PiecewiseChebyshev, _log_multipliers, chebyshev_nodes,
                             lti_representatives, piecewise_chebyshev)
from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .._core.pm_ops import register_op, register_func
from .._core.steps import step_grid
from .._core.transition import step_transitions
from .._core.validation import check_period, real_array
from .._core.subperiods import common_period, tile_steps
from .tvlyap import is_varying
from .tvdesign import tv_dare

__all__ = ['care', 'dare']

# relative periodicity residual above which a warning is issued
_RESIDUAL_WARN = 1e-8
# degree of the Chebyshev interpolant of X(t) on every step
_CHEB_DEG = 16
# steps per call of the integrator (bounded memory)
_FLOW_CHUNK = 512
# uniform pieces a verified table (gain, X) starts from before bisection;
# step grids up to _GRID_STEPS steps are used directly (cheaper short flows),
# longer (stiff) ones give way to these coarse pieces and exact values
_TABLE_PIECES = 32
_GRID_STEPS = 256
# multipliers within this distance of the unit circle count as on it
_CIRCLE_TOL = 1e-10
# tabulated gain: degree on every piece, verified relative accuracy (to
# 1 + max |G| on the piece), finest bisection of a step
_GAIN_DEG = 16
_GAIN_TOL = 1e-9
_GAIN_DEPTH = 12
# closed-loop log|μ| above -first: not stabilizing; above -second: doubtful
# (a defective unit-circle pair splits by about sqrt(eps))
_CLOSED_LOOP_TOL = (1e-9, 1e-6)


def care(A, B, Q, R, S=None, period=None, nsteps=None):
    """Stabilizing periodic solution of the periodic Riccati differential equation.

    ``-Ẋ = AᵀX + XA - (XB + S) R⁻¹ (BᵀX + Sᵀ) + Q`` with T-periodic data,
    the periodic counterpart of `control.care`.

    Parameters
    ----------
    A, B : PeriodicMatrix, callable or array_like
        Plant matrices, shapes (n, n) and (n, m).
    Q, R : PeriodicMatrix, callable or array_like
        Symmetric weights, (n, n) and (m, m); R(t) positive definite.
    S : PeriodicMatrix, callable or array_like, optional
        Cross weight (n, m); zero by default.
    period : float, optional
        Period T; taken from the first `PeriodicMatrix` argument when omitted.
    nsteps : int, optional
        Uniform steps per period (switching instants are added).  By default
        ``ceil(T max_t ‖H(t)‖₂)`` clipped to [16, 4096].

    Returns
    -------
    X : PeriodicMatrix
        The stabilizing solution, ``X(t + T) = X(t)``.
    L : ndarray of complex
        Closed-loop Floquet exponents of ``A - BG`` (see
        `ltpcontrol.floquet_exponents`).
    G : PeriodicMatrix
        Gain ``G(t) = R⁻¹(BᵀX + Sᵀ)``.

    Raises
    ------
    ValueError
        If R is not positive definite, Q or R is not symmetric, or no
        stabilizing solution exists ((A, B) not stabilizable, or a mode of
        (A, Q) unobservable on the stability boundary).
    ControlDimension
        If the shapes do not match.

    Examples
    --------
    An LTI plant written as periodic gives `control.care`'s solution:

    >>> A, B = np.array([[0.0, 1.0], [2.0, -1.0]]), np.array([[0.0], [1.0]])
    >>> X, L, G = ltp.care(A, B, np.eye(2), [[1.0]], period=1.0)
    >>> np.allclose(X(0.3), ct.care(A, B, np.eye(2), [[1.0]])[0])
    True
    """
    X, L, G, _ = _care_solution(A, B, Q, R, S, period, nsteps)
    if isinstance(G.function, _GainTable):
        G.function._build()                      # tabulated now, bounded (module notes)
    return X, L, G


def _care_solution(A, B, Q, R, S, period, nsteps):
    """``(X, L, G, exact)`` of `care`; G's table not built yet (``exact`` is the
    pointwise gain ``R⁻¹(BᵀX + Sᵀ)``)."""
    period = _period_of((A, B, Q, R, S), period)
    A = as_periodic(A, period, 'A')
    n = A.shape[0]
    if A.shape != (n, n):
        raise ControlDimension(f"A must be square, got shape {A.shape}")
    B = as_periodic(B, period, 'B')
    if B.shape[0] != n:
        raise ControlDimension(f"B must have {n} rows, got shape {B.shape}")
    m = B.shape[1]
    Q = as_periodic(Q, period, 'Q', shape=(n, n))
    R = as_periodic(R, period, 'R', shape=(m, m))
    S = as_periodic(np.zeros((n, m)) if S is None else S, period, 'S', shape=(n, m))
    ops = (A, B, Q, R, S)
    breaks = np.unique(np.concatenate([M.breakpoints for M in ops]))
    probe = np.union1d(np.arange(16) * period / 16, breaks)
    _check_weights(Q(probe), R(probe), 'Q', 'R')

    H = _hamiltonian(ops, breaks)
    grid = _grid(H, period, breaks, nsteps)
    Psi = _flow(H, grid[:-1], np.diff(grid))
    ident = np.broadcast_to(np.eye(2 * n), Psi.shape)
    X0 = _stable_solution(ident, Psi, n)
    Psi_inv = np.linalg.inv(Psi)

    def sweep(X0):
        # backward flow from X(T) = X(0): [U; V] = Ψ_k⁻¹ [I; X_{k+1}]
        Xg = np.empty((len(grid), n, n))
        Xg[-1] = X0
        for k in range(len(grid) - 2, -1, -1):
            UV = Psi_inv[k, :, :n] + Psi_inv[k, :, n:] @ Xg[k + 1]
            Xg[k] = _graph(UV, n)
        # closed-loop step factors: x(t_{k+1}) = [Ψ_k [I; X_k]]_top x(t_k)
        return Xg, (Psi @ _stack(Xg[:-1]))[:, :n]
    Xg, factors = _refine(X0, sweep)
    L = _exponents(factors, period=period)
    if all(M.is_constant for M in ops):
        # LTI data: constant X and gain (flagged constant), the eigenvalues of A - BG
        X = PeriodicMatrix.constant(Xg[0], period)
        G0 = _gain(B(0.0)[None], R(0.0)[None], S(0.0)[None], Xg[:1])[0]
        L = lti_representatives(L, A(0.0) - B(0.0) @ G0, period=period)
        G = PeriodicMatrix.constant(G0, period)
        return X, L, G, G
    solution = _RiccatiSolution(H, grid, Xg, breaks=breaks)
    X = PeriodicMatrix.from_function(solution, period, (n, n), breakpoints=breaks,
                                     check=False)
    exact = PeriodicMatrix.pointwise(_gain, [B, R, S, X], (m, n), breakpoints=breaks)
    G = PeriodicMatrix.from_function(
        _GainTable(exact=exact, grid=_table_edges(grid, exact.breakpoints)), period,
        (m, n), breakpoints=exact.breakpoints, check=False)
    return X, L, G, exact


def _gain(b, r, s, x):
    # G = R⁻¹(BᵀX + Sᵀ), pointwise
    return np.linalg.solve(r, np.swapaxes(b, 1, 2) @ x + np.swapaxes(s, 1, 2))


register_op('riccati_gain', _gain)


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


def dare(A, B, Q, R, S=None):
    """Stabilizing periodic solution of the periodic Riccati difference equation.

    ``X_k = A_kᵀX_{k+1}A_k - (A_kᵀX_{k+1}B_k + S_k)(R_k + B_kᵀX_{k+1}B_k)⁻¹
    (B_kᵀX_{k+1}A_k + S_kᵀ) + Q_k`` with ``X_{k+N} = X_k``, the periodic
    counterpart of `control.dare`.

    Parameters
    ----------
    A, B, Q, R, S : array_like
        The N matrices of one period, shapes (N, n, n), (N, n, m), (N, n, n),
        (N, m, m) and (N, n, m); a 2D array is the same matrix at every step.
        S is zero by default.  R_k + B_kᵀX_{k+1}B_k must be positive
        definite; R_k is required to be.  Stacks of different lengths are
        combined on their least common multiple; lists of matrices whose
        shapes vary with k (time-varying dimensions) give lists.

    Returns
    -------
    X : ndarray, shape (N, n, n)
        The stabilizing solution.
    L : ndarray of complex
        Closed-loop per-step exponents ``ρ = μ^{1/N}`` of the multipliers μ
        of ``Π_k (A_k - B_k G_k)`` (see `ltpcontrol.floquet_exponents`).
    G : ndarray, shape (N, m, n)
        Gains ``G_k = (R_k + B_kᵀX_{k+1}B_k)⁻¹(B_kᵀX_{k+1}A_k + S_kᵀ)``.

    Raises
    ------
    ValueError
        If R is not positive definite, Q or R is not symmetric, or no
        stabilizing solution exists.
    ControlDimension
        If the shapes or the numbers of steps do not match.

    Examples
    --------
    >>> A = np.array([[[1.2, 0.3], [0.0, 0.5]], [[0.8, 0.0], [0.4, 1.1]]])
    >>> B = np.array([[[0.0], [1.0]], [[1.0], [0.0]]])
    >>> X, L, G = ltp.dare(A, B, np.eye(2), [[1.0]])
    >>> X.shape, G.shape, bool(np.all(np.abs(L) < 1))
    ((2, 2, 2), (2, 1, 2), True)
    """
    if any(is_varying(M) for M in (A, B, Q, R, S)):     # time-varying dimensions
        return tv_dare(A, B, Q, R, S)
    A, B, Q, R, S = tile_steps([A, B, Q, R, S], ['A', 'B', 'Q', 'R', 'S'])   # sub-periods
    A, B, Q, R, S = _step_arrays(A, B, Q, R, S)
    N, n, m = B.shape
    _check_weights(Q, R, 'Q', 'R')
    Abar = A - B @ np.linalg.solve(R, np.swapaxes(S, 1, 2))
    Qbar = Q - S @ np.linalg.solve(R, np.swapaxes(S, 1, 2))
    Lk = np.zeros((N, 2 * n, 2 * n))
    Mk = np.zeros((N, 2 * n, 2 * n))
    Lk[:, :n, :n] = np.eye(n)
    Lk[:, :n, n:] = B @ np.linalg.solve(R, np.swapaxes(B, 1, 2))
    Lk[:, n:, n:] = np.swapaxes(Abar, 1, 2)
    Mk[:, :n, :n] = Abar
    Mk[:, n:, :n] = -Qbar
    Mk[:, n:, n:] = np.eye(n)
    X0 = _stable_solution(Lk, Mk, n)
    Bt = np.swapaxes(B, 1, 2)

    def sweep(X0):
        X = np.empty((N + 1, n, n))
        X[N] = X0
        for k in range(N - 1, -1, -1):
            X[k] = _riccati_step(A[k], B[k], Q[k], R[k], S[k], X[k + 1])
        Xn = X[1:]
        G = np.linalg.solve(R + Bt @ Xn @ B, Bt @ Xn @ A + np.swapaxes(S, 1, 2))
        return X, A - B @ G
    X, factors = _refine(X0, sweep)
    X = X[:N]
    Xn = np.roll(X, -1, axis=0)
    G = np.linalg.solve(R + Bt @ Xn @ B, Bt @ Xn @ A + np.swapaxes(S, 1, 2))
    L = _exponents(factors, nper=N)
    if all(np.all(M == M[0]) for M in (A, B, Q, R, S)):   # LTI data
        L = lti_representatives(L, A[0] - B[0] @ G[0], nper=N)
    return X, L, G


#
# Shared steps
#

def _hamiltonian(ops, breaks):
    """``H = [[Ā, -BR⁻¹Bᵀ], [-Q̄, -Āᵀ]]`` of the data ``(A, B, Q, R, S)``.

    With B, R and S constant, H is affine in (A, Q): when these are Fourier
    series, so is H (its harmonics are those of A and Q), and evaluating it
    costs one series sum instead of a batch of solves.
    """
    A, B, Q, R, S = ops
    n, period = A.shape[0], A.period

    def hamiltonian(a, b, q, r, s):
        # R⁻¹ [Bᵀ, Sᵀ]
        rinv = np.linalg.solve(r, np.swapaxes(np.concatenate([b, s], axis=1), 1, 2))
        out = np.empty((len(a), 2 * n, 2 * n))
        out[:, :n, :n] = a - b @ rinv[:, :, n:]        # Ā = A - B R⁻¹ Sᵀ
        out[:, :n, n:] = -(b @ rinv[:, :, :n])         # -B R⁻¹ Bᵀ
        out[:, n:, :n] = s @ rinv[:, :, n:] - q        # -Q̄ = S R⁻¹ Sᵀ - Q
        out[:, n:, n:] = -np.swapaxes(out[:, :n, :n], 1, 2)
        return out

    if (all(M.is_constant for M in (B, R, S))
            and A.nharmonics is not None and Q.nharmonics is not None):
        K = max(A.nharmonics, Q.nharmonics)
        a, q = A.fourier(K), Q.fourier(K)
        coeffs = np.zeros((2 * K + 1, 2 * n, 2 * n), complex)
        coeffs[:, :n, :n] = a
        coeffs[:, n:, :n] = -q
        coeffs[:, n:, n:] = -np.swapaxes(a, 1, 2)
        coeffs[K] = hamiltonian(*(M.fourier(0).real for M in ops))[0]
        return PeriodicMatrix(coeffs, period)
    return PeriodicMatrix.pointwise(hamiltonian, ops, (2 * n, 2 * n), breakpoints=breaks)


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
    `_GAIN_DEPTH` times, until the interpolant matches the exact values at
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
    for depth in range(_GAIN_DEPTH + 1):
        h = (hi - lo)[:, None]
        vals = _exact_values(H, grid, Xg, (lo[:, None] + h * nodes).ravel())
        vals = vals.reshape(len(lo), _CHEB_DEG + 1, n, n)
        exact = _exact_values(H, grid, Xg, (lo[:, None] + h * probe).ravel())
        approx = np.einsum('pj,kjab->kpab', weights, vals)
        dev = np.abs(approx - exact.reshape(approx.shape)).max(axis=(1, 2, 3)) / scale
        ok = dev <= 1e-10
        if depth == _GAIN_DEPTH:
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


def _stable_solution(Lk, Mk, n):
    """``X_0 = V U⁻¹`` from the stable deflating subspace of the collapsed pencil."""
    Lc, Mc = _collapse(np.asarray(Lk, float), np.asarray(Mk, float))
    # QZ of the pencil M - μ L, stable eigenvalues first
    _, _, alpha, beta, _, Zq = la.ordqz(Mc, Lc, sort='iuc', output='real')
    with np.errstate(divide='ignore', invalid='ignore'):
        mod = np.where(beta != 0, np.abs(alpha) / np.abs(beta), np.inf)
    nstable = int(np.count_nonzero(mod < 1 - _CIRCLE_TOL))
    if nstable != n or np.any(np.abs(mod - 1) <= _CIRCLE_TOL):
        raise ValueError(
            "no stabilizing periodic solution exists: the Hamiltonian has "
            f"{int(np.count_nonzero(np.abs(mod - 1) <= _CIRCLE_TOL))} multipliers on "
            "the unit circle (check that (A, B) is stabilizable and that Q penalizes "
            "every mode on the stability boundary)")
    U, V = Zq[:n, :n], Zq[n:, :n]
    if np.linalg.cond(U) > 1e12:
        raise ValueError("no stabilizing periodic solution exists: the stable subspace "
                         "is not a graph over the state space (check that (A, B) is "
                         "stabilizable)")
    X0 = np.linalg.solve(U.T, V.T).T
    return 0.5 * (X0 + X0.T)


def _collapse(L, M):
    """One pencil ``(L, M)`` with ``L⁻¹M = L_{K-1}⁻¹M_{K-1} ... L_0⁻¹M_0``.

    Neighbours are merged pairwise (a balanced tree, batched): for factors
    k, k+1 the QR factorisation of ``[L_k; -M_{k+1}]`` gives ``[Z1 Z2]``
    with ``Z1 L_k = Z2 M_{k+1}``, and the pair becomes ``(Z2 L_{k+1}, Z1 M_k)``.
    """
    d = L.shape[1]
    while len(L) > 1:
        even = len(L) - len(L) % 2
        q, _ = np.linalg.qr(np.concatenate([L[0:even:2], -M[1:even:2]], axis=1),
                            mode='complete')
        Z = np.swapaxes(q, 1, 2)[:, d:]
        Lnew, Mnew = Z[:, :, d:] @ L[1:even:2], Z[:, :, :d] @ M[0:even:2]
        if even < len(L):
            Lnew, Mnew = np.concatenate([Lnew, L[-1:]]), np.concatenate([Mnew, M[-1:]])
        L, M = Lnew, Mnew
    return L[0], M[0]


def _riccati_step(a, b, q, r, s, xn):
    """One backward step of the discrete Riccati map."""
    axb = a.T @ xn @ b + s
    X = a.T @ xn @ a - axb @ np.linalg.solve(r + b.T @ xn @ b, axb.T) + q
    return 0.5 * (X + X.T)


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


def _exponents(factors, period=None, nper=None):
    """Floquet exponents (continuous) or per-step exponents (discrete) of the
    closed-loop factors; raises unless every multiplier is inside the unit
    circle (a Hamiltonian multiplier pair on the circle, split by round-off,
    can pass the count of stable multipliers and give a non-stabilizing X)."""
    logmod, arg = _log_multipliers(None, None, grid=None, factors=factors)
    worst = logmod.max() if logmod.size else -np.inf
    if not worst < -_CLOSED_LOOP_TOL[0]:
        raise ValueError(
            "no stabilizing periodic solution exists: the closed loop keeps a Floquet "
            f"multiplier on the unit circle (log|mu| = {worst:.1e}); check that (A, B) "
            "is stabilizable and that Q penalizes every mode on the stability boundary")
    if worst >= -_CLOSED_LOOP_TOL[1]:
        warnings.warn(
            f"the closed loop has a Floquet multiplier with log|mu| = {worst:.1e}: at "
            "this precision a Hamiltonian multiplier pair on the unit circle looks the "
            "same, so the solution may not be stabilizing", UserWarning, stacklevel=3)
    if nper is not None:
        with np.errstate(under='ignore', over='ignore'):
            return np.exp(logmod / nper) * np.exp(1j * arg / nper)   # log|μ| may be -inf
    return logmod / period + 1j * (arg / period)


def _refine(X0, sweep, passes=2):
    """Newton refinement of the pencil's ``X_0`` on the periodicity condition.

    ``sweep(X_0)`` runs the backward recursion over one period and returns
    the samples (first: the period map ``F(X_0)``) and the closed-loop step
    factors.  ``F(X_0 + Δ) ≈ F(X_0) + ΦᵀΔΦ`` with the closed-loop monodromy
    Φ, so the Newton step solves the Stein equation ``Δ = ΦᵀΔΦ + F(X_0) -
    X_0``.  The pencil's ``X_0`` is backward stable but its error is
    amplified by the conditioning of the stable subspace; one or two steps
    restore full accuracy.  Returns the samples with ``X[0] = X[-1]``.
    """
    scale = max(1.0, np.abs(X0).max())
    for attempt in range(passes + 1):
        Xs, factors = sweep(X0)
        res = Xs[0] - X0
        if attempt == passes or np.abs(res).max() <= 1e-13 * scale:
            break
        mono = np.eye(X0.shape[0])
        for f in factors:
            mono = f @ mono
        if not np.all(np.isfinite(mono)) or np.max(np.abs(la.eigvals(mono))) >= 1:
            break
        delta = la.solve_discrete_lyapunov(mono.T, res)
        X0 = X0 + 0.5 * (delta + delta.T)
    err = np.abs(res).max() / scale
    if not np.isfinite(err) or err > _RESIDUAL_WARN:
        warnings.warn(f"the periodic Riccati solution has a periodicity residual of "
                      f"{err:.1e}: the problem is ill-conditioned (closed-loop "
                      "multipliers close to the unit circle or a badly scaled plant)",
                      UserWarning, stacklevel=3)
    Xs[0] = X0
    return Xs, factors


def _check_weights(Q, R, qname, rname):
    """Symmetric Q, symmetric positive definite R (stacks of samples)."""
    for M, name in ((Q, qname), (R, rname)):
        scale = max(1.0, np.abs(M).max())
        if np.abs(M - np.swapaxes(M, 1, 2)).max() > 1e-10 * scale:
            raise ValueError(f"{name} must be symmetric")
    if R.shape[-1] and np.min(np.linalg.eigvalsh(R)) <= 1e-14 * max(1.0, np.abs(R).max()):
        raise ValueError(f"{rname} must be positive definite")


def _grid(H, period, breaks, nsteps):
    """Step grid of `_steps.step_grid`, by default ``ceil(T max‖H‖)`` steps
    (clipped to [16, 4096]) with the norm estimated from 16 samples."""
    if nsteps is None:
        probe = np.concatenate([np.arange(16) * period / 16, breaks])
        norm = np.max(np.linalg.norm(H(probe), ord=2, axis=(1, 2)), initial=0.0)
        nsteps = int(np.clip(np.ceil(period * norm), 16, 4096))
    return step_grid(H, nsteps=nsteps)


def _period_of(args, period):
    """The common period of `period` and the periodic arguments (sub-periods)."""
    given = [] if period is None else [check_period(period)]
    named = [(M.period, n) for M, n in zip(args, 'ABQRS') if isinstance(M, PeriodicMatrix)]
    if not given and not named:
        raise ControlArgument("period must be given when no argument is a PeriodicMatrix")
    return common_period(given + [p for p, _ in named],
                         ['period'] * len(given) + [n for _, n in named])


def _step_arrays(A, B, Q, R, S):
    """Validate the step matrices of a discrete periodic problem; common N."""
    names = ('A', 'B', 'Q', 'R', 'S')
    arrs = []
    for M, name in zip((A, B, Q, R, S), names):
        if M is None:
            arrs.append(None)
            continue
        arr = real_array(M, name, ndim=(0, 1, 2, 3))
        if arr.ndim < 2:
            arr = np.atleast_2d(arr)
        arrs.append(arr if arr.ndim == 3 else arr[np.newaxis])
    steps = {a.shape[0] for a in arrs if a is not None and a.shape[0] != 1}
    if len(steps) > 1:
        raise ControlDimension("A, B, Q, R and S must have the same number of steps N "
                               f"(or one matrix), got {sorted(steps)}")
    N = steps.pop() if steps else 1
    A, B, Q, R, S = arrs
    n = A.shape[1]
    if A.shape[1:] != (n, n):
        raise ControlDimension(f"A must hold square matrices, got shape {A.shape}")
    if B.shape[1] != n:
        raise ControlDimension(f"B must have {n} rows, got shape {B.shape}")
    m = B.shape[2]
    if S is None:
        S = np.zeros((1, n, m))
    for M, name, shape in ((Q, 'Q', (n, n)), (R, 'R', (m, m)), (S, 'S', (n, m))):
        if M.shape[1:] != shape:
            raise ControlDimension(f"{name} must have shape {shape} (per step), "
                                   f"got {M.shape[1:]}")
    return tuple(np.broadcast_to(M, (N,) + M.shape[1:]).copy() for M in (A, B, Q, R, S))
