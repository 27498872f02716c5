"""Per-step transition factors and Van Loan integrals over a period grid.

The period is split into steps ``0 = t_0 < t_1 < ... < t_M = T`` that
contain every switching instant (`step_grid`).  Periodic matrix equations
(Lyapunov, Riccati, norms) reduce to recursions over these steps whose
data are, per step ``[t_k, t_k + h]`` with ``Φ = Φ(t_k + h, t_k)``,

    W = ∫ Φ(t_k + h, s) Qf(s) Φ(t_k + h, s)ᵀ ds      (forward integral),
    V = ∫ Φ(s, t_k)ᵀ Qa(s) Φ(s, t_k) ds               (adjoint integral),
    S = ∫ tr(Qa(r) P(r)) dr,  P(r) = ∫_{t_k}^r Φ(r, s) Qf(s) Φ(r, s)ᵀ ds,

so that ``X(t_k + h) = Φ X(t_k) Φᵀ + W`` solves ``Ẋ = AX + XAᵀ + Qf`` and
``Y(t_k) = Φᵀ Y(t_k + h) Φ + V`` solves ``-Ẏ = AᵀY + YA + Qa`` (S is the
within-step part of ``∫ tr(Qa X)``, used by the H2 norm).  All of them are
blocks of the transition matrix Ψ of the block upper-triangular generator
(Van Loan)

    M(t) = [[-Aᵀ, Qa, 0], [0, A, Qf], [0, 0, -Aᵀ]]:
    Φ = Ψ22,  W = Ψ23 Φᵀ,  V = Φᵀ Ψ12,  S = tr(Φᵀ Ψ13),

computed by the library's integrator (`_transition.step_transitions`: one
exponential per segment when A and the weights are piecewise constant,
Magnus otherwise) for every step at once, with M evaluated block by block
at the integrator's nodes.  Only the blocks that are asked for are built.
The steps are short (``h ‖A‖ <= 1`` by default), so the growing blocks
``e^{-Aᵀh}`` stay moderate even for stiff A.
"""

import warnings

import numpy as np
import scipy.linalg as la

from .periodic_matrix import PeriodicMatrix
from .memory import check_allocation
from .transition import step_transitions
from .validation import check_positive_int

__all__ = []


def step_grid(A, others=(), nsteps=None):
    """Grid ``t_0 = 0 < ... < t_M = T`` of one period of `A`.

    Uniform steps refined at every switching instant of `A` and `others`.
    By default ``nsteps = ceil(T max_t ‖A(t)‖₂)`` clipped to [16, 4096], so
    that every step factor is well conditioned.

    Examples
    --------
    >>> from ltpcontrol._core.steps import step_grid
    >>> A = ltp.PeriodicMatrix.switching([[[-1.0]], [[-2.0]]], [0, 0.3], 1.0)
    >>> step_grid(A, nsteps=2)
    array([0. , 0.3, 0.5, 1. ])
    """
    T = A.period
    breaks = np.unique(np.mod(np.concatenate(
        [A.breakpoints] + [M.breakpoints for M in others]), T))
    if nsteps is None:
        # a piecewise-constant A takes all its values at 0 and the breakpoints
        probe = np.concatenate([[0.0] if A._piecewise_constant else np.arange(256) * T / 256,
                                breaks])
        norm = np.max(np.linalg.norm(A(probe), ord=2, axis=(1, 2)), initial=0.0)
        nsteps = int(np.clip(np.ceil(T * norm), 16, 4096))
    else:
        nsteps = check_positive_int(nsteps, 'nsteps')
    grid = np.union1d(np.linspace(0, T, nsteps + 1), breaks)
    # drop grid points that nearly coincide with a switching instant
    keep = np.concatenate([[True], np.diff(grid) > 1e-9 * T / nsteps])
    keep[-1] = True
    grid = grid[keep]
    grid = grid[np.concatenate([np.diff(grid) > 0, [True]])]
    grid[-1] = T
    return grid


#: bytes of the step factors of a Floquet grid (with their QR copies)
FACTOR_BUDGET = 512e6
#: largest log-spread ``h ‖A‖`` of a factor whose small multipliers stay above rounding
_LOG_SPREAD = 36.0


def floquet_grid(A, nsteps=None, budget=FACTOR_BUDGET):
    """Grid of the Floquet factors ``Φ_k`` of one period of `A`.

    As `step_grid`, with ``nsteps = ceil(T max_t ‖A(t)‖)`` by default, where
    the norm is that of A after the exact diagonal balancing of the
    integrator when it pays (states in mixed units), and the count is
    clipped to [16, min(4096, budget / (24 n²))], so that the factors and
    their periodic Schur copies fit `budget` bytes (512 MB) whatever the
    size.  Each factor is integrated with as many sub-steps as its error
    estimate asks (`step_transitions`).  A factor holds its multipliers
    down to about ``e^{-36}`` of its largest to working precision, so when
    the budget caps the grid below ``T max‖A‖ / 36`` steps the most stiff
    exponents may be lost to rounding (as in a formed product), which is
    announced by a warning; the others keep full accuracy.

    Examples
    --------
    >>> from ltpcontrol._core.steps import floquet_grid
    >>> A = ltp.PeriodicMatrix.constant(np.diag([-1.0, -1e4]), 1.0)
    >>> len(floquet_grid(A)) - 1
    4096
    >>> len(floquet_grid(ltp.PeriodicMatrix.constant(-np.eye(300), 1.0))) - 1
    16
    """
    T, n = A.period, A.shape[0]
    if nsteps is not None:
        nsteps = check_positive_int(nsteps, 'nsteps')
        check_allocation((nsteps, n, n), f"{nsteps} Floquet factors of {n} states", copies=2)
        return step_grid(A, nsteps=nsteps)
    norm = floquet_norm(A)
    cap = int(min(4096, max(16, budget // (24 * max(n, 1) ** 2))))
    nsteps = int(np.clip(np.ceil(T * norm), 16, cap))
    if T * norm > _LOG_SPREAD * nsteps:
        warnings.warn(f"the Floquet factors of {n} states are capped at {nsteps} steps "
                      f"(memory budget {budget / 1e6:.0f} MB) while T max‖A(t)‖ = "
                      f"{T * norm:.3g}: exponents below about {-_LOG_SPREAD * nsteps / T:.3g} "
                      "fall under the rounding of the factors and may be inaccurate",
                      UserWarning, stacklevel=3)
    return step_grid(A, nsteps=nsteps)


def floquet_norm(A):
    """``max_t ‖A(t)‖`` on probe instants, A balanced when its states are badly scaled.

    Examples
    --------
    >>> from ltpcontrol._core.steps import floquet_norm
    >>> floquet_norm(ltp.PeriodicMatrix.constant(np.diag([-1.0, -1e4]), 1.0))
    10000.0
    """
    T, n = A.period, A.shape[0]
    breaks = np.unique(np.mod(A.breakpoints, T))
    few = n <= 64
    probe = np.concatenate([[0.0] if A._piecewise_constant
                            else np.arange(256 if few else 32) * T / (256 if few else 32),
                            breaks])
    At = A._eval(probe)
    if n >= 2 and np.all(np.isfinite(At)):
        big = np.abs(At).max(axis=0)
        _, (s, _) = la.matrix_balance(big, permute=False, separate=True)
        if (big * (s[None, :] / s[:, None])).sum(axis=0).max() * 8 < big.sum(axis=0).max():
            At = At * (s[None, :] / s[:, None])
    if few:
        norm = np.max(np.linalg.norm(At, ord=2, axis=(1, 2)), initial=0.0)
    else:
        # sqrt(‖·‖₁ ‖·‖∞) bounds the 2-norm without an SVD per probe
        norm = np.sqrt(np.abs(At).sum(axis=1).max(initial=0.0)
                       * np.abs(At).sum(axis=2).max(initial=0.0))
    return float(norm)


def gram_weight(F, adjoint=False):
    """``F Fᵀ`` (``Fᵀ F`` when `adjoint`) of a periodic matrix, pointwise.

    Examples
    --------
    >>> from ltpcontrol._core.steps import gram_weight
    >>> C = ltp.PeriodicMatrix.constant([[1.0, 2.0]], 1.0)
    >>> gram_weight(C, adjoint=True)(0.0)
    array([[1., 2.],
           [2., 4.]])
    """
    if adjoint:
        n, op = F.shape[1], lambda f: np.swapaxes(f, 1, 2) @ f
    else:
        n, op = F.shape[0], lambda f: f @ np.swapaxes(f, 1, 2)
    return PeriodicMatrix.pointwise(op, [F], (n, n))


def step_integrals(A, t0, h, Qf=None, Qa=None):
    """Transition factors and Van Loan integrals of many steps (module notes).

    Parameters
    ----------
    A : PeriodicMatrix, shape (n, n)
    t0, h : ndarray
        Step starts and lengths (1D, same length; h > 0).
    Qf, Qa : PeriodicMatrix, shape (n, n), optional
        Forward and adjoint weights.

    Returns
    -------
    Phi : ndarray, shape (S, n, n)
    W, V : ndarray, shape (S, n, n), or None when `Qf` (`Qa`) is None
    S : ndarray, shape (S,), or None unless both weights are given

    Examples
    --------
    Scalar ``ẋ = -x``: ``W = ∫_0^h e^{-2(h-s)} ds = (1 - e^{-2h})/2``.

    >>> from ltpcontrol._core.steps import step_integrals
    >>> A = ltp.PeriodicMatrix.constant([[-1.0]], 1.0)
    >>> Q = ltp.PeriodicMatrix.constant([[1.0]], 1.0)
    >>> Phi, W, V, S = step_integrals(A, np.array([0.0]), np.array([0.5]), Qf=Q)
    >>> bool(np.isclose(W[0, 0, 0], (1 - np.exp(-1.0)) / 2)), V, S
    (True, None, None)
    """
    n = A.shape[0]
    # blocks of the 3n generator that are needed: [adjoint, state, forward]
    keep = [i for i, Q in enumerate((Qa, A, Qf)) if Q is not None]
    blk = {k: slice(j * n, (j + 1) * n) for j, k in enumerate(keep)}
    weights = [Q.with_period(A.period) for Q in (Qa, Qf) if Q is not None]

    def generator(a, *q):
        # M(t) at the integrator's nodes
        out = np.zeros((len(a), len(keep) * n, len(keep) * n))
        out[:, blk[1], blk[1]] = a
        q = iter(q)
        if Qa is not None:
            out[:, blk[0], blk[0]] = -np.swapaxes(a, 1, 2)
            out[:, blk[0], blk[1]] = next(q)
        if Qf is not None:
            out[:, blk[2], blk[2]] = -np.swapaxes(a, 1, 2)
            out[:, blk[1], blk[2]] = next(q)
        return out
    M = PeriodicMatrix.pointwise(generator, [A] + weights, (len(keep) * n,) * 2)
    Psi, _, _ = step_transitions(M, None, np.asarray(t0, float), np.asarray(h, float))
    Phi = Psi[:, blk[1], blk[1]]
    W = V = S = None
    if Qf is not None:
        W = Psi[:, blk[1], blk[2]] @ np.swapaxes(Phi, 1, 2)
        W = 0.5 * (W + np.swapaxes(W, 1, 2))
    if Qa is not None:
        V = np.swapaxes(Phi, 1, 2) @ Psi[:, blk[0], blk[1]]
        V = 0.5 * (V + np.swapaxes(V, 1, 2))
    if Qf is not None and Qa is not None:
        S = np.einsum('kji,kji->k', Phi, Psi[:, blk[0], blk[2]])
    return Phi, W, V, S
