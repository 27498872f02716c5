"""Periodic Sylvester equations, continuous and discrete time.

Discrete ``X_{k+1} = A_kX_kB_k + C_k`` (indices modulo N): with row-major
vectorization ``vec(AXB) = (A ⊗ Bᵀ) vec X`` the N unknowns satisfy the
cyclic block system ``vec X_{k+1} - (A_k ⊗ B_kᵀ) vec X_k = vec C_k``,
solved at once by a sparse LU factorisation (as the periodic Lyapunov
equations of `ltpcontrol.lyap`).  The solution is unique iff no product
``μ_i(A) μ_j(B) = 1`` of the multipliers of ``Π A_k`` and ``Π B_k``.

Continuous ``Ẋ = A(t)X + XB(t) + C(t)``: with ``Ẏ = -BY``, ``Y(t_k) = I``,
``Z = XY`` obeys ``Ż = AZ + CY``, so the transition ``Θ`` of the block
generator ``[[A, C], [0, -B]]`` over a step gives
``X_{k+1} = Θ₁₁X_kΘ₂₂⁻¹ + Θ₁₂Θ₂₂⁻¹`` — a discrete periodic Sylvester
equation on the step grid (steps short, ``h ‖·‖ <= 1``).  Values inside a
step come from the same formula over the partial step.  Unique iff no
``μ_i(A) μ_j(B) = 1`` (B's multipliers those of ``Ẏ = YB``).
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from control.exception import ControlDimension

from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .._core.steps import step_grid
from .._core.transition import step_transitions
from .._core.validation import real_array

__all__ = ['sylvester', 'dsylvester']


def dsylvester(A, B, C):
    """Periodic solution of the discrete periodic Sylvester equation.

    ``X[k+1] = A[k] X[k] B[k] + C[k]``, indices modulo N.

    Parameters
    ----------
    A : array_like, shape (N, n, n) or (n, n)
    B : array_like, shape (N, m, m) or (m, m)
    C : array_like, shape (N, n, m) or (n, m)
        One matrix per step (a 2D array is the same at every step).

    Returns
    -------
    X : ndarray, shape (N, n, m)

    Raises
    ------
    ValueError
        If the solution is not unique (``μ_i(A) μ_j(B) = 1``).
    ControlDimension
        For inconsistent shapes or numbers of steps.

    Examples
    --------
    >>> A = np.array([[[0.5, 1.0], [0.0, 0.2]], [[0.1, 0.0], [1.0, -0.3]]])
    >>> B = np.array([[[0.4]], [[-0.7]]])
    >>> X = ltp.dsylvester(A, B, np.ones((2, 2, 1)))
    >>> bool(np.allclose(X[1], A[0] @ X[0] @ B[0] + 1))
    True
    """
    A = real_array(A, 'A', ndim=(2, 3))
    B = real_array(B, 'B', ndim=(2, 3))
    C = real_array(C, 'C', ndim=(2, 3))
    n, m = A.shape[-1], B.shape[-1]
    if A.shape[-2] != n or B.shape[-2] != m:
        raise ControlDimension(f"A and B must hold square matrices, got {A.shape}, {B.shape}")
    if C.shape[-2:] != (n, m):
        raise ControlDimension(f"C must hold {n}x{m} matrices, got shape {C.shape}")
    sizes = {M.shape[0] for M in (A, B, C) if M.ndim == 3}
    if len(sizes) > 1:
        raise ControlDimension(f"A, B and C must have the same number of steps, got "
                               f"{sorted(sizes)}")
    N = sizes.pop() if sizes else 1
    A, B, C = (np.broadcast_to(M if M.ndim == 3 else M[None], (N,) + M.shape[-2:])
               for M in (A, B, C))
    return _cyclic(A, B, C)


def sylvester(A, B, C, *, period=None, nsteps=None):
    """Periodic solution of the continuous periodic Sylvester equation.

    ``dX/dt = A(t) X + X B(t) + C(t)`` with T-periodic data; an LTI
    ``A, B, C`` gives the solution of ``AX + XB + C = 0``
    (`scipy.linalg.solve_sylvester` with ``-C``).

    Parameters
    ----------
    A, B, C : PeriodicMatrix, callable or array_like
        Shapes (n, n), (m, m), (n, m).
    period : float, optional
        Period when none of the arguments is a `PeriodicMatrix`.
    nsteps : int, optional
        Uniform steps of the period grid (see `lyap`).

    Returns
    -------
    X : PeriodicMatrix, shape (n, m)

    Raises
    ------
    ValueError
        If the periodic solution is not unique.
    ControlDimension
        For inconsistent shapes.

    Examples
    --------
    >>> import scipy.linalg as la
    >>> A, B, C = np.array([[-1.0, 2.0], [0.0, -3.0]]), np.array([[-0.5]]), np.ones((2, 1))
    >>> X = ltp.sylvester(A, B, C, period=1.0)
    >>> bool(np.allclose(X(0.3), la.solve_sylvester(A, B, -C)))
    True
    """
    T = period
    for M in (A, B, C):
        if isinstance(M, PeriodicMatrix):
            T = M.period
            break
    if T is None:
        raise ValueError("period must be given when no argument is a PeriodicMatrix")
    A, B, C = as_periodic(A, T, 'A'), as_periodic(B, T, 'B'), as_periodic(C, T, 'C')
    n, m = A.shape[0], B.shape[0]
    if A.shape != (n, n) or B.shape != (m, m):
        raise ControlDimension(f"A and B must be square, got {A.shape}, {B.shape}")
    if C.shape != (n, m):
        raise ControlDimension(f"C must have shape {(n, m)}, got {C.shape}")
    G = PeriodicMatrix.block([[A, C], [np.zeros((m, n)), -B]])
    grid = step_grid(G, (), nsteps)
    Phi, Psi, W = _step_maps(G, grid[:-1], np.diff(grid), n)
    Xg = _cyclic(Phi, Psi, W)

    def evaluate(t):
        tau = np.mod(np.atleast_1d(np.asarray(t, float)), T)
        k = np.clip(np.searchsorted(grid, tau, side='right') - 1, 0, len(grid) - 2)
        h = tau - grid[k]
        out = Xg[k].copy()
        inside = h > 1e-14 * T
        if np.any(inside):
            P, S, V = _step_maps(G, grid[k[inside]], h[inside], n)
            out[inside] = P @ Xg[k[inside]] @ S + V
        return out
    return PeriodicMatrix.from_function(evaluate, T, (n, m), breakpoints=G.breakpoints,
                                        check=False)


def _step_maps(G, t0, h, n):
    """``(Θ₁₁, Θ₂₂⁻¹, Θ₁₂Θ₂₂⁻¹)`` of the block generator over the given steps."""
    Theta, _, _ = step_transitions(G, None, t0, h)
    inv22 = np.linalg.inv(Theta[:, n:, n:])
    return Theta[:, :n, :n], inv22, Theta[:, :n, n:] @ inv22


def _cyclic(A, B, C):
    """Solve ``X_{k+1} = A_k X_k B_k + C_k`` cyclically (module notes)."""
    N, n, m = C.shape
    nm = n * m
    if nm == 0:
        return np.zeros((N, n, m))
    K = np.einsum('kia,kbj->kijab', A, B).reshape(N, nm, nm)   # A ⊗ Bᵀ (row-major vec)
    rows, cols, vals = [], [], []
    idx = np.arange(nm)
    for k in range(N):
        r = ((k + 1) % N) * nm
        rows.append(r + idx)
        cols.append(r + idx)
        vals.append(np.ones(nm))
        rr, cc = np.meshgrid(idx, idx, indexing='ij')
        rows.append((r + rr).ravel())
        cols.append((k * nm + cc).ravel())
        vals.append(-K[k].ravel())
    L = sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(N * nm, N * nm))
    rhs = np.roll(C.reshape(N, nm), 1, axis=0).ravel()
    try:
        X = spla.splu(L).solve(rhs)
    except RuntimeError:
        raise ValueError("the periodic Sylvester equation has no unique solution: "
                         "multipliers of A and B satisfy mu_i(A) mu_j(B) = 1") from None
    X = X.reshape(N, n, m)
    res = X[(np.arange(N) + 1) % N] - (A @ X @ B + C)
    scale = max(1.0, np.abs(X).max(), np.abs(C).max())
    if not np.all(np.isfinite(X)) or np.abs(res).max() > 1e-8 * scale:
        raise ValueError("the periodic Sylvester equation has no unique solution "
                         f"(residual {np.abs(res).max() / scale:.1e}): multipliers of A and "
                         "B nearly satisfy mu_i(A) mu_j(B) = 1")
    return X
