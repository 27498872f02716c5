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

The steps live in their own modules: the cyclic pencil, its stable
subspace and the Newton refinement in `periodic_pencil`, X(t) between the
step boundaries in `riccati_solution`, the verified gain tables in
`gain_table`.
"""

import numpy as np
from control.exception import ControlArgument, ControlDimension

from .._core.floquet import lti_representatives
from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .._core.pm_ops import register_op
from .._core.steps import step_grid
from .._core.validation import check_period, real_array
from .._core.subperiods import common_period, tile_steps
from .tvlyap import is_varying
from .tvdesign import tv_dare
from .gain_table import _GainTable, _table_edges
from .periodic_pencil import _exponents, _refine, _stable_solution
from .riccati_solution import _RiccatiSolution, _flow, _graph, _stack

__all__ = ['care', 'dare']


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


def _care_solution(A, B, Q, R, S, period, nsteps, definite=True):
    """``(X, L, G, exact)`` of `care`; G's table not built yet (``exact`` is the
    pointwise gain ``R⁻¹(BᵀX + Sᵀ)``).  ``definite=False`` admits an
    indefinite (invertible) R, as in the H∞ Riccati equation."""
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
    if definite:
        probe = np.union1d(np.arange(16) * period / 16, breaks)
        _check_weights(Q(probe), R(probe), 'Q', 'R')

    H = _hamiltonian(ops, breaks)
    grid = _grid(H, period, breaks, nsteps)
    Psi = _flow(H, grid[:-1], np.diff(grid))
    ident = np.broadcast_to(np.eye(2 * n), Psi.shape)
    X0 = _stable_solution(ident, Psi, n)
    Psi_inv = np.linalg.inv(Psi)

    det_signs = np.ones(len(grid) - 1)

    def sweep(X0):
        # backward flow from X(T) = X(0): [U; V] = Ψ_k⁻¹ [I; X_{k+1}]
        Xg = np.empty((len(grid), n, n))
        Xg[-1] = X0
        for k in range(len(grid) - 2, -1, -1):
            UV = Psi_inv[k, :, :n] + Psi_inv[k, :, n:] @ Xg[k + 1]
            det_signs[k] = np.linalg.slogdet(UV[:n])[0]
            Xg[k] = _graph(UV, n)
        # closed-loop step factors: x(t_{k+1}) = [Ψ_k [I; X_k]]_top x(t_k)
        return Xg, (Psi @ _stack(Xg[:-1]))[:, :n]
    Xg, factors = _refine(X0, sweep)
    if not definite and np.any(det_signs <= 0):
        # U(t) runs from I at t_{k+1} to U_k at t_k: a sign change of det U
        # is a singular U inside the step, where X escapes to infinity
        # (impossible for a definite R)
        raise ValueError("the periodic Riccati solution escapes to infinity inside the "
                         f"period (near t = {grid[np.argmax(det_signs <= 0)]:.6g})")
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
    _check_weights(Q, R, 'Q', 'R')
    return _dare_solution(A, B, Q, R, S)


def _dare_solution(A, B, Q, R, S):
    """``(X, L, G)`` of `dare` for validated step stacks (N, ., .); R may be
    indefinite (invertible), as in the H∞ Riccati equation."""
    N, n, m = B.shape
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


def _riccati_step(a, b, q, r, s, xn):
    """One backward step of the discrete Riccati map."""
    axb = a.T @ xn @ b + s
    X = a.T @ xn @ a - axb @ np.linalg.solve(r + b.T @ xn @ b, axb.T) + q
    return 0.5 * (X + X.T)



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
