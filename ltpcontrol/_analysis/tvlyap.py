"""Periodic Lyapunov equations with time-varying dimensions.

With ``A_k`` of shape ``n_{k+1} x n_k`` (indices modulo N), the forward
equation ``X_{k+1} = A_k X_k A_kᵀ + Q_k`` has ``X_k`` of shape
``n_k x n_k`` and ``Q_k`` of shape ``n_{k+1} x n_{k+1}``; the adjoint
equation ``X_k = A_kᵀ X_{k+1} A_k + Q_k`` has ``Q_k`` of shape
``n_k x n_k`` (the conventions of the reference toolbox's ``pfdlyap`` and
``prdlyap``).  The N unknowns are coupled cyclically; with row-major
vectorisation ``vec(A X Aᵀ) = (A ⊗ A) vec X`` the cyclic system

    vec X_{k+1} − (A_k ⊗ A_k) vec X_k = vec Q_k     (forward)

(and its adjoint) is one sparse block system with blocks of the sizes
``n_k²``, solved at once by a sparse LU factorisation.  It is nonsingular
iff no two core multipliers of the cyclic product satisfy
``μ_i μ_j = 1`` (the zero multipliers padding the smaller steps never do),
which is checked first.  Matrices of different periods (A of 3 steps, Q of
2) are combined on the least common multiple of their step counts.
"""

import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from control.exception import ControlArgument, ControlDimension

from .._core.subperiods import common_steps
from .._core.tvsystem import check_chain, cyclic_multipliers, _sequence

__all__ = ['tv_dlyap']

_SINGULAR = 1e-10
_ILLCOND = 1e-6


def is_varying(M):
    """True for a list of 2D matrices whose shapes differ (time-varying dimensions).

    Examples
    --------
    >>> from ltpcontrol._analysis.tvlyap import is_varying
    >>> is_varying([np.ones((1, 2)), np.ones((2, 1))]), is_varying(np.ones((2, 3, 3)))
    (True, False)
    """
    if not isinstance(M, (list, tuple)) or not M:
        return False
    try:
        shapes = {np.shape(m) for m in M}
    except (TypeError, ValueError):
        return False
    return len(shapes) > 1 and all(len(s) == 2 for s in shapes)


def tv_dlyap(A, Q, *, adjoint=False):
    """Periodic discrete Lyapunov equation with time-varying dimensions.

    Forward ``X_{k+1} = A_k X_k A_kᵀ + Q_k``; adjoint
    ``X_k = A_kᵀ X_{k+1} A_k + Q_k`` (module notes for the shapes).
    `ltpcontrol.dlyap` passes lists of matrices of varying shapes here.

    Parameters
    ----------
    A : list of array_like, or array_like
        ``A_k`` of shape ``n_{k+1} x n_k``, k = 0..N_A−1.
    Q : list of array_like, or array_like
        Symmetric ``Q_k``: ``n_{k+1} x n_{k+1}`` (forward) or ``n_k x n_k``
        (adjoint), k = 0..N_Q−1.  The equation has period ``lcm(N_A, N_Q)``.
    adjoint : bool, optional
        Solve the adjoint (backward) equation.

    Returns
    -------
    X : list of ndarray
        ``X_k`` (``n_k x n_k``) for k = 0..N−1.

    Raises
    ------
    ControlDimension
        If the dimension chain of A does not close or a ``Q_k`` has the
        wrong shape (the message names the step).
    ValueError
        If the solution is not unique (``μ_i μ_j = 1``) or a ``Q_k`` is not
        symmetric.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> na, ma = [5, 3, 3, 4, 1], [3, 3, 4, 1, 5]
    >>> A = [rng.random((m, n)) for n, m in zip(na, ma)]
    >>> Q = [np.eye(n) for n in na]
    >>> X = ltp.dlyap(A, Q, adjoint=True)
    >>> [x.shape[0] for x in X]
    [5, 3, 3, 4, 1]
    >>> res = max(np.abs(A[k].T @ X[(k + 1) % 5] @ A[k] + Q[k] - X[k]).max()
    ...           for k in range(5))
    >>> bool(res < 1e-12 * max(np.abs(x).max() for x in X))
    True
    """
    if not isinstance(adjoint, (bool, np.bool_)):
        raise ControlArgument(f"adjoint must be True or False, got {adjoint!r}")
    A = _sequence(A, 'A')
    Q = _sequence(Q, 'Q')
    N = common_steps([len(A), len(Q)], ['A', 'Q'])
    A = [A[k % len(A)] for k in range(N)]
    Q = [Q[k % len(Q)] for k in range(N)]
    n = check_chain(A, 'A')
    for k in range(N):
        size = n[k] if adjoint else n[(k + 1) % N]
        if Q[k].shape != (size, size):
            raise ControlDimension(f"Q[{k}] must be {size}x{size} (n_{k if adjoint else k + 1})"
                                   f", got shape {Q[k].shape}")
        scale = max(1.0, np.abs(Q[k]).max(initial=0.0))
        if np.abs(Q[k] - Q[k].T).max(initial=0.0) > 1e-10 * scale:
            raise ValueError(f"Q[{k}] must be symmetric")
    _check_unique(A)
    return _solve_cyclic(A, Q, n, adjoint)


def _check_unique(A):
    """Raise if two core multipliers of the cyclic product satisfy ``μ_i μ_j = 1``."""
    mu = cyclic_multipliers(A)
    if mu.size == 0:
        return
    gap = np.abs(mu[:, None] * mu[None, :] - 1).min()
    if gap <= _SINGULAR:
        raise ValueError("the periodic Lyapunov equation has no unique periodic solution: "
                         f"two multipliers satisfy mu_i mu_j = 1 (|mu_i mu_j - 1| = "
                         f"{gap:.1e})")
    if gap <= _ILLCOND:
        warnings.warn("the periodic Lyapunov equation is ill-conditioned: two multipliers "
                      f"nearly satisfy mu_i mu_j = 1 (|mu_i mu_j - 1| = {gap:.1e})",
                      UserWarning, stacklevel=3)


def _solve_cyclic(A, Q, n, adjoint):
    """Sparse LU solution of the cyclic block system (module notes)."""
    N = len(A)
    sizes = np.array([m * m for m in n])
    off = np.concatenate([[0], np.cumsum(sizes)])
    total = int(off[-1])
    if total == 0:
        return [np.zeros((m, m)) for m in n]
    rows, cols, vals = [np.arange(total)], [np.arange(total)], [np.ones(total)]
    rhs = np.zeros(total)
    for k in range(N):
        k1 = (k + 1) % N
        K = np.kron(A[k], A[k])                     # (n_{k+1}², n_k²)
        if adjoint:
            # row block k: vec X_k − (A_kᵀ ⊗ A_kᵀ) vec X_{k+1} = vec Q_k
            r, c = np.nonzero(np.ones((sizes[k], sizes[k1]), bool))
            rows.append(off[k] + r)
            cols.append(off[k1] + c)
            vals.append(-K.T.ravel())
            rhs[off[k]:off[k + 1]] += Q[k].ravel()
        else:
            # row block k+1: vec X_{k+1} − (A_k ⊗ A_k) vec X_k = vec Q_k
            r, c = np.nonzero(np.ones((sizes[k1], sizes[k]), bool))
            rows.append(off[k1] + r)
            cols.append(off[k] + c)
            vals.append(-K.ravel())
            rhs[off[k1]:off[k1 + 1]] += Q[k].ravel()
    L = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(total, total))
    x = spla.splu(L).solve(rhs)
    X = [x[off[k]:off[k + 1]].reshape(n[k], n[k]) for k in range(N)]
    return [0.5 * (x + x.T) for x in X]
