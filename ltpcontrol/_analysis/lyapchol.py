"""Factored (square-root) solutions of periodic Lyapunov equations.

For a stable periodic A the periodic solution of the forward equation
``X_{k+1} = A_kX_kA_kᵀ + B_kB_kᵀ`` (continuous time ``Ẋ = AX + XAᵀ + BBᵀ``
on the step grid of `ltpcontrol.lyap`, with ``A_k = Φ_k`` and
``B_kB_kᵀ = W_k`` the Van Loan integral of the step) is positive
semidefinite and is computed as ``X_k = R_kᵀR_k`` with R_k upper
triangular, never forming X:

1. one period from zero in factored form: ``R ← triu(qr([R A_kᵀ; B_kᵀ]))``
   gives the factor of the period's input ``W_T`` and the monodromy ``Ψ``;
2. the Stein equation ``X_0 = ΨX_0Ψᵀ + W_T`` by the factored Smith
   doubling ``R ← triu(qr([R; RΨᵀ]))``, ``Ψ ← Ψ²`` (``X_0 = Σ_j Ψʲ W_T
   Ψʲᵀ``), until ``Ψ`` has decayed;
3. the other samples by the same factored step.

Only orthogonal transformations act on the factors, as in Hammarling's
method, so the factor keeps its accuracy where X is ill conditioned (the
square-root balancing of `ltpcontrol.hsvd` needs the factors, not X).  The
adjoint equation ``X_k = A_kᵀX_{k+1}A_k + C_kᵀC_k`` is the forward
equation of the reversed, transposed steps.
"""

import numpy as np
from control.exception import ControlDimension

from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .._core.steps import gram_weight, step_grid, step_integrals
from .._core.validation import real_array
from .lyapunov import _check_bool

__all__ = ['lyapchol', 'dlyapchol']

# doublings of the Smith iteration at most (Ψ^(2^60))
_MAX_DOUBLINGS = 60


def dlyapchol(A, B, *, adjoint=False):
    """Cholesky factor of the periodic solution of a discrete Lyapunov equation.

    Forward (default) ``X[k+1] = A[k] X[k] A[k]ᵀ + B[k] B[k]ᵀ``; adjoint
    ``X[k] = A[k]ᵀ X[k+1] A[k] + B[k]ᵀ B[k]`` (B then plays the part of C),
    indices modulo N.  Returns R with ``X[k] = R[k]ᵀ R[k]``, computed
    without forming X (module notes); `ltpcontrol.dlyap` gives X.

    Parameters
    ----------
    A : array_like, shape (N, n, n) or (n, n)
        The N matrices of one period; all closed-loop multipliers (the
        eigenvalues of ``A[N-1] ... A[0]``) inside the unit circle.
    B : array_like, shape (N, n, m) (forward) or (N, p, n) (adjoint)
        Input (or output) matrices; a 2D array is the same at every step.
    adjoint : bool, optional
        Solve the adjoint equation.

    Returns
    -------
    R : ndarray, shape (N, n, n)
        Upper triangular factors with non-negative diagonals.

    Raises
    ------
    ValueError
        If a multiplier is not inside the unit circle (X is then not
        positive semidefinite, or not unique).
    ControlDimension
        For inconsistent shapes or numbers of steps.

    Examples
    --------
    >>> A = np.array([[[0.5, 1.0], [0.0, 0.2]], [[0.1, 0.0], [1.0, -0.3]]])
    >>> B = np.array([[1.0], [0.5]])
    >>> R = ltp.dlyapchol(A, B)
    >>> X = ltp.dlyap(A, B @ B.T)
    >>> bool(np.allclose(np.swapaxes(R, 1, 2) @ R, X, rtol=1e-12, atol=0))
    True
    """
    _check_bool(adjoint, 'adjoint')
    A = real_array(A, 'A', ndim=(2, 3))
    B = real_array(B, 'B', ndim=(2, 3))
    if A.shape[-1] != A.shape[-2]:
        raise ControlDimension(f"A must hold square matrices, got shape {A.shape}")
    n = A.shape[-1]
    if (B.shape[-1] if adjoint else B.shape[-2]) != n:
        raise ControlDimension(f"B must have {n} {'columns' if adjoint else 'rows'} "
                               f"(per step), got shape {B.shape}")
    steps = {M.shape[0] for M in (A, B) if M.ndim == 3}
    if len(steps) > 1:
        raise ControlDimension(f"A and B must have the same number of steps, got "
                               f"{sorted(steps)}")
    N = steps.pop() if steps else 1
    A = np.broadcast_to(A, (N, n, n)) if A.ndim == 2 else A
    B = np.broadcast_to(B, (N,) + B.shape) if B.ndim == 2 else B
    if adjoint:
        # X_k = A_kᵀX_{k+1}A_k + C_kᵀC_k is forward in j = N - k for Ã_j = A_{N-1-j}ᵀ
        Ar, Lr = np.swapaxes(A[::-1], 1, 2), np.swapaxes(B[::-1], 1, 2)
        R = _forward_factor(Ar, Lr)
        return np.roll(R[::-1], 1, axis=0)         # X_k = X̃_{N-k}
    return _forward_factor(A, B)


def lyapchol(A, B, *, adjoint=False, period=None, nsteps=None):
    """Cholesky factor of the periodic solution of a continuous Lyapunov equation.

    Forward (default) ``Ẋ = A X + X Aᵀ + B Bᵀ``; adjoint ``−Ẋ = Aᵀ X + X A
    + Bᵀ B`` (B then plays the part of C).  Returns R(t) with ``X(t) =
    R(t)ᵀ R(t)``, computed without forming X (module notes); `ltpcontrol.lyap`
    gives X.

    Parameters
    ----------
    A : PeriodicMatrix, callable or array_like, shape (n, n)
        Periodic state matrix with all Floquet multipliers inside the unit
        circle.
    B : PeriodicMatrix, callable or array_like, shape (n, m) or (p, n)
        Input matrix (forward) or output matrix (adjoint).
    adjoint : bool, optional
        Solve the adjoint equation.
    period : float, optional
        Period T when `A` is not a `PeriodicMatrix`.
    nsteps : int, optional
        Uniform steps of the period grid (as `lyap`).

    Returns
    -------
    R : PeriodicMatrix, shape (n, n)
        Upper triangular factor; between grid points the nearest grid factor
        is propagated over the partial step in factored form.

    Raises
    ------
    ValueError
        If a Floquet multiplier is not inside the unit circle.
    ControlDimension
        If the shapes do not match.

    Examples
    --------
    An LTI equation: ``RᵀR`` is `control.lyap`'s solution:

    >>> A, B = np.array([[-1.0, 2.0], [0.0, -3.0]]), np.array([[1.0], [1.0]])
    >>> R = ltp.lyapchol(A, B, period=1.0)
    >>> bool(np.allclose(R(0.3).T @ R(0.3), ct.lyap(A, B @ B.T), rtol=1e-12, atol=0))
    True
    """
    _check_bool(adjoint, 'adjoint')
    if period is None:
        period = next((M.period for M in (A, B) if isinstance(M, PeriodicMatrix)), None)
    if period is None:
        raise ValueError("period must be given when neither A nor B is a PeriodicMatrix")
    A = as_periodic(A, period, 'A')
    n = A.shape[0]
    if A.shape != (n, n):
        raise ControlDimension(f"A must be square, got shape {A.shape}")
    B = as_periodic(B, period, 'B')
    if (B.shape[1] if adjoint else B.shape[0]) != n:
        raise ControlDimension(f"B must have {n} {'columns' if adjoint else 'rows'}, "
                               f"got shape {B.shape}")
    T = A.period
    Q = gram_weight(B, adjoint)
    grid = step_grid(A, [Q], nsteps)
    weights = {'Qa': Q} if adjoint else {'Qf': Q}
    Phi, W, V, _ = step_integrals(A, grid[:-1], np.diff(grid), **weights)
    if adjoint:
        # −Ẋ = AᵀX + XA + CᵀC: X_k = Φ_kᵀX_{k+1}Φ_k + V_k
        Rg = dlyapchol(Phi, _psd_factor(V, transpose=True), adjoint=True)
    else:
        Rg = dlyapchol(Phi, _psd_factor(W))
    starts, ends = grid[:-1], grid[1:]
    Rn = np.concatenate([Rg, Rg[:1]])

    def evaluate(t):
        tau = np.mod(np.asarray(t, float), T)
        k = np.clip(np.searchsorted(starts, tau, side='right') - 1, 0, len(starts) - 1)
        if adjoint:
            # X(τ) = Φ(t_{k+1}, τ)ᵀ X_{k+1} Φ(t_{k+1}, τ) + V(τ, t_{k+1})
            P, _, Vt, _ = step_integrals(A, tau, ends[k] - tau, Qa=Q)
            stacked = np.concatenate([Rn[k + 1] @ P, _psd_factor(Vt, transpose=True)], axis=1)
        else:
            # X(τ) = Φ(τ, t_k) X_k Φ(τ, t_k)ᵀ + W(t_k, τ)
            P, Wt, _, _ = step_integrals(A, starts[k], tau - starts[k], Qf=Q)
            stacked = np.concatenate([Rg[k] @ np.swapaxes(P, 1, 2),
                                      np.swapaxes(_psd_factor(Wt), 1, 2)], axis=1)
        return _triangular(stacked)

    return PeriodicMatrix.from_function(evaluate, T, (n, n),
                                        breakpoints=np.concatenate([A.breakpoints,
                                                                    B.breakpoints]),
                                        check=False)


def _forward_factor(A, L):
    """``R_k`` with ``R_kᵀR_k = X_k``, ``X_{k+1} = A_kX_kA_kᵀ + L_kL_kᵀ`` (module notes)."""
    N, n, _ = A.shape
    At, Lt = np.swapaxes(A, 1, 2), np.swapaxes(L, 1, 2)
    # 1. one period from X_0 = 0, and the monodromy
    R = np.zeros((0, n))
    Psi = np.eye(n)
    for k in range(N):
        R = _triangular(np.concatenate([R @ At[k], Lt[k]])[None])[0]
        Psi = A[k] @ Psi
    mu = np.abs(np.linalg.eigvals(Psi)).max(initial=0.0)
    if not mu < 1:
        raise ValueError(f"the periodic Lyapunov equation has no positive semidefinite "
                         f"factored solution: a multiplier is not inside the unit circle "
                         f"(largest |mu| = {mu:.6g})")
    # 2. X_0 = Σ_j Ψʲ W_T Ψʲᵀ by factored doubling
    scale = max(np.abs(R).max(initial=0.0), 1e-300)
    for _ in range(_MAX_DOUBLINGS):
        step = R @ Psi.T
        R = _triangular(np.concatenate([R, step])[None])[0]
        if np.abs(step).max(initial=0.0) <= 1e-17 * scale:
            break
        Psi = Psi @ Psi
    # 3. the samples
    out = np.empty((N, n, n))
    out[0] = R
    for k in range(N - 1):
        out[k + 1] = _triangular(np.concatenate([out[k] @ At[k], Lt[k]])[None])[0]
    return out


def _triangular(M):
    """Upper triangular R (n x n, diagonal ≥ 0) with ``RᵀR = MᵀM`` for a stack M."""
    S, r, n = M.shape
    if r < n:
        M = np.concatenate([M, np.zeros((S, n - r, n))], axis=1)
    R = np.linalg.qr(M, mode='r')[:, :n, :]
    sign = np.where(np.diagonal(R, axis1=1, axis2=2) < 0, -1.0, 1.0)
    return R * sign[:, :, None]


def _psd_factor(W, transpose=False):
    """L with ``LLᵀ = W`` (or ``LᵀL = W``) for a stack of PSD step integrals."""
    W = 0.5 * (W + np.swapaxes(W, 1, 2))
    w, U = np.linalg.eigh(W)
    L = U * np.sqrt(np.clip(w, 0.0, None))[:, None, :]
    return np.swapaxes(L, 1, 2) if transpose else L
