"""Periodic Lyapunov equations and gramians.

Continuous time, on the step grid ``0 = t_0 < ... < t_M = T`` (`_steps`):

    forward  Ẋ = A X + X Aᵀ + Q:     X_{k+1} = Φ_k X_k Φ_kᵀ + W_k,
    adjoint −Ẋ = Aᵀ X + X A + Q:     X_k = Φ_kᵀ X_{k+1} Φ_k + V_k,

with the per-step factors ``Φ_k`` and Van Loan integrals ``W_k, V_k``.
Discrete time the same recursions hold with ``Φ_k = A[k]`` and
``W_k = V_k = Q[k]``.  The M unknowns ``X_0..X_{M-1}`` (``X_M = X_0``)
are coupled cyclically; the cyclic system

    vec X_{k+1} − (Φ_k ⊗ Φ_k) vec X_k = vec W_k,   k = 0..M−1,

is solved at once by a sparse LU factorisation (block bidiagonal plus the
corner block), never by iterating the period map, so the solve is exact
also for stiff or unstable A.  It is nonsingular iff no two Floquet
multipliers satisfy ``μ_i μ_j = 1``, which is checked first from the
periodic Schur form of the factors.  Values between grid points come from
the step formula over the partial step.
"""

import math
import warnings
from fractions import Fraction

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from control.exception import ControlArgument, ControlDimension

from .._core.floquet import _log_multipliers
from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .._core.steps import step_grid, step_integrals
from .._core.coerce import as_ltp
from .._core.validation import real_array
from .._core.subperiods import on_common_period, tile_steps
from .tvlyap import is_varying, tv_dlyap
from .._core.tvsystem import DiscreteLTPSystem
from .tvdesign import tv_gram
from .sylvester import dsylvester

__all__ = ['lyap', 'dlyap', 'gram']

# |μ_i μ_j − 1| below which the periodic solution is taken as not unique,
# and below which it is reported as ill-conditioned
_SINGULAR = 1e-10
_ILLCOND = 1e-6
# M n⁴ above which `cyclic_lyap` leaves the sparse Kronecker solve (about 100 MB)
_SPARSE_LIMIT = 4e6


def lyap(A, Q, *, adjoint=False, period=None, nsteps=None):
    """Periodic solution of a continuous-time periodic Lyapunov equation.

    Forward (default) ``dX/dt = A(t) X + X A(t)ᵀ + Q(t)``; adjoint
    ``−dX/dt = A(t)ᵀ X + X A(t) + Q(t)``.  An LTI ``A, Q`` gives the
    solution of ``A X + X Aᵀ + Q = 0`` (`control.lyap`).

    Parameters
    ----------
    A : PeriodicMatrix, callable or array_like, shape (n, n)
        Periodic state matrix (a callable or constant array needs `period`).
    Q : PeriodicMatrix, callable or array_like, shape (n, n)
        Symmetric periodic weight.  A `PeriodicMatrix` A and Q of
        commensurate periods (3 and 2) are combined on the common period (6);
        otherwise the period of Q must divide that of `A`.
    adjoint : bool, optional
        Solve the adjoint (backward) equation.
    period : float, optional
        Period T when `A` is not a `PeriodicMatrix`.
    nsteps : int, optional
        Uniform steps of the period grid (switching instants are added);
        default ``ceil(T max‖A‖)`` clipped to [16, 4096].

    Returns
    -------
    X : PeriodicMatrix
        The unique T-periodic solution; evaluating it between grid points
        propagates the nearest grid value exactly.

    Raises
    ------
    ValueError
        If there is no unique periodic solution (Floquet multipliers with
        ``μ_i μ_j = 1``), Q is not symmetric, or the periods do not match.
    ControlDimension
        If A is not square or Q does not have the shape of A.

    Examples
    --------
    An LTI equation gives `control.lyap`:

    >>> A, Q = np.array([[-1.0, 2.0], [0.0, -3.0]]), np.eye(2)
    >>> X = ltp.lyap(A, Q, period=1.0)
    >>> np.allclose(X(0.3), ct.lyap(A, Q))
    True
    """
    if period is None:                  # sub-periods: A and Q on their common period
        A, Q = on_common_period({'A': A, 'Q': Q}).values()
    A, Q = _pair(A, Q, period, 'lyap')
    _check_bool(adjoint, 'adjoint')
    grid = step_grid(A, [Q], nsteps)
    weights = {'Qa': Q} if adjoint else {'Qf': Q}
    Phi, W, V, _ = step_integrals(A, grid[:-1], np.diff(grid), **weights)
    X = cyclic_lyap(Phi, V if adjoint else W, adjoint)
    return periodic_solution(A, Q, grid, X, adjoint)


def dlyap(A, Q, C=None, E=None, *, adjoint=False):
    """Periodic solution of a discrete-time periodic Lyapunov equation.

    Forward (default) ``X[k+1] = A[k] X[k] A[k]ᵀ + Q[k]``; adjoint
    ``X[k] = A[k]ᵀ X[k+1] A[k] + Q[k]``, indices modulo N.  An LTI
    ``A, Q`` gives `control.dlyap`, and the arguments follow its order:
    ``dlyap(A, Q, C)`` solves the periodic Sylvester equation
    ``X[k+1] = A[k] X[k] Q[k]ᵀ + C[k]`` (`control.dlyap`'s
    ``A X Qᵀ − X + C = 0``), and ``dlyap(A, Q, None, E)`` the generalized
    equation ``E[k] X[k+1] E[k]ᵀ = A[k] X[k] A[k]ᵀ + Q[k]``
    (``A X Aᵀ − E X Eᵀ + Q = 0``) for invertible ``E[k]``.

    Parameters
    ----------
    A : array_like, shape (N, n, n) or (n, n), or PeriodicMatrix
        The N matrices of one period (a 2D array: N = 1, or N from `Q`).  A
        `PeriodicMatrix` held piecewise constant on N equal steps (the ``A``
        of a discrete-time `LTPStateSpace`) gives its N step matrices; a
        constant one counts as one step.
    Q : array_like, shape (N, n, n) or (n, n), or PeriodicMatrix
        Symmetric weights (a 2D array is the same at every step).  `A` and
        `Q` may repeat with different numbers of steps: the equation is then
        solved on the least common multiple (A of 3 steps, Q of 2: N = 6).
        Lists of matrices whose dimensions vary with k (``A[k]`` of shape
        ``n_{k+1} x n_k``) are accepted (time-varying dimensions).  With `C`:
        the second factor of the Sylvester equation, shape (N, m, m).
    C : array_like, shape (N, n, m) or (n, m), or PeriodicMatrix, optional
        Right-hand side of the Sylvester equation (`ltpcontrol.dsylvester`).
    E : array_like, shape (N, n, n) or (n, n), or PeriodicMatrix, optional
        Invertible descriptor matrices of the generalized equation.
    adjoint : bool, optional
        Solve the adjoint (backward) equation (not with `C` or `E`).

    Returns
    -------
    X : ndarray, shape (N, n, n), or PeriodicMatrix
        ``X[k]`` for k = 0..N−1 (a list for time-varying dimensions).  When
        `A` or `Q` is a `PeriodicMatrix` of period T: the solution held on
        the steps, ``X(k T/N) = X[k]`` (``X.sample(N)`` gives the stack).

    Raises
    ------
    ValueError
        If there is no unique periodic solution (``μ_i μ_j = 1``) or Q is
        not symmetric.
    ControlDimension
        For inconsistent shapes or numbers of steps.

    Examples
    --------
    >>> A = np.array([[[0.5, 1.0], [0.0, 0.2]], [[0.1, 0.0], [1.0, -0.3]]])
    >>> X = ltp.dlyap(A, np.eye(2))
    >>> np.allclose(X[1], A[0] @ X[0] @ A[0].T + np.eye(2))
    True

    The matrices of a discrete-time system are taken as they are stored:

    >>> sysd = ltp.ltpss(A, [[1.0], [0.5]], [[1.0, 0.0]], 0, period=2.0, dt=1.0)
    >>> P = ltp.dlyap(sysd.A, sysd.B @ sysd.B.T)
    >>> bool(np.allclose(P.sample(2), ltp.gram(sysd, 'c').sample(2)))
    True
    """
    _check_bool(adjoint, 'adjoint')
    period = _held_period(A, Q, C, E)
    if period is not None:
        A, Q, C, E = _held_steps([A, Q, C, E], ['A', 'Q', 'C', 'E'], period)
        X = dlyap(A, Q, C, E, adjoint=adjoint)
        return PeriodicMatrix.from_samples(X, period, kind='hold')
    if C is not None:
        if E is not None:
            raise ControlArgument("dlyap: give C (Sylvester equation) or E (generalized "
                                  "Lyapunov equation), not both")
        if adjoint:
            raise ControlArgument("dlyap: adjoint=True is not defined for the Sylvester "
                                  "equation (C given)")
        Q = real_array(Q, 'Q', ndim=(2, 3))
        return dsylvester(A, np.swapaxes(Q, -1, -2), C)
    if E is not None:
        return _generalized_dlyap(A, Q, E, adjoint)
    # time-varying dimensions and sub-periods (ltpcontrol._analysis.tvlyap)
    if is_varying(A) or is_varying(Q):
        return tv_dlyap(A, Q, adjoint=adjoint)
    A = real_array(A, 'A', ndim=(2, 3))
    Q = real_array(Q, 'Q', ndim=(2, 3))
    A, Q = tile_steps([A, Q], ['A', 'Q'])
    if A.shape[-1] != A.shape[-2]:
        raise ControlDimension(f"A must hold square matrices, got shape {A.shape}")
    n = A.shape[-1]
    if Q.shape[-2:] != (n, n):
        raise ControlDimension(f"Q must hold {n}x{n} matrices like A, got shape {Q.shape}")
    N = max(A.shape[0] if A.ndim == 3 else 1, Q.shape[0] if Q.ndim == 3 else 1)
    for M, name in ((A, 'A'), (Q, 'Q')):
        if M.ndim == 3 and M.shape[0] != N:
            raise ControlDimension(f"{name} has {M.shape[0]} steps but the period has {N}")
    A = np.broadcast_to(A, (N, n, n))
    Q = np.broadcast_to(Q, (N, n, n))
    _check_symmetric(Q, 'Q')
    return cyclic_lyap(A, Q, adjoint)


def _held_period(*mats):
    """Period of the `PeriodicMatrix` among `mats` (None if there is none)."""
    periods = [M.period for M in mats if isinstance(M, PeriodicMatrix)]
    if not periods:
        return None
    if any(abs(p - periods[0]) > 1e-12 * periods[0] for p in periods):
        raise ValueError(f"dlyap: the periodic matrices have different periods {periods}")
    return periods[0]


def _held_steps(mats, names, period):
    """The step matrices ``(N, r, c)`` of held (discrete-time) periodic matrices.

    Examples
    --------
    >>> from ltpcontrol._analysis.lyapunov import _held_steps
    >>> P = ltp.PeriodicMatrix.from_samples(np.arange(3.0).reshape(3, 1, 1), 3.0, kind='hold')
    >>> _held_steps([P, None], ['A', 'C'], 3.0)[0][:, 0, 0]
    array([0., 1., 2.])
    """
    out = []
    for M, name in zip(mats, names):
        if isinstance(M, PeriodicMatrix):
            if not M._piecewise_constant:
                raise ControlArgument(
                    f"dlyap: {name} is a PeriodicMatrix that is not held piecewise constant "
                    f"on steps (the form of a discrete-time system's matrices); give its "
                    f"step matrices, e.g. {name}.sample(N)")
            # the fewest equal steps whose instants hold every switching instant
            frac = [Fraction(float(t) / period).limit_denominator(1 << 20)
                    for t in np.unique(M.breakpoints)]
            N = math.lcm(*[f.denominator for f in frac]) if frac else 1
            if any(abs(float(f) - t / period) > 1e-9 for f, t in
                   zip(frac, np.unique(M.breakpoints))) or N > 1 << 20:
                raise ControlArgument(
                    f"dlyap: {name} switches at {np.unique(M.breakpoints)}, not on equal "
                    f"steps of the period {period}")
            M = M.sample(N)
        out.append(M)
    return out


def _generalized_dlyap(A, Q, E, adjoint):
    """``E[k] X[k+1] E[k]ᵀ = A[k] X[k] A[k]ᵀ + Q[k]`` through ``E⁻¹A``, ``E⁻¹QE⁻ᵀ``."""
    if adjoint:
        raise ControlArgument("dlyap: adjoint=True is not defined for the generalized "
                              "equation (E given)")
    A = real_array(A, 'A', ndim=(2, 3))
    Q = real_array(Q, 'Q', ndim=(2, 3))
    E = real_array(E, 'E', ndim=(2, 3))
    A, Q, E = tile_steps([A, Q, E], ['A', 'Q', 'E'])
    if E.shape[-2:] != A.shape[-2:]:
        raise ControlDimension(f"E must hold matrices of the shape {A.shape[-2:]} of A, "
                               f"got shape {E.shape}")
    if np.any(np.linalg.svd(E, compute_uv=False).min(axis=-1)
              <= 1e-13 * np.linalg.norm(E, 2, axis=(-2, -1))):
        raise ValueError("dlyap: E must be invertible at every step")
    Ei = np.linalg.inv(E)
    return dlyap(Ei @ A, Ei @ Q @ np.swapaxes(Ei, -1, -2))


def gram(sys, type):
    """Periodic controllability or observability gramian.

    Controllability (``'c'``): the forward solution with ``Q = B Bᵀ``;
    observability (``'o'``): the adjoint solution with ``Q = Cᵀ C``
    (`lyap`, `dlyap`).  ``P(t)`` is the gramian of the input on
    ``(−∞, t]`` and ``Q(t)`` that of the output on ``[t, ∞)``.  An LTI
    system gives `control.gram`.

    Parameters
    ----------
    sys : LTPStateSpace
        Stable continuous- or discrete-time LTP system.
    type : {'c', 'o'}
        Which gramian.

    Returns
    -------
    PeriodicMatrix
        Continuous time: the gramian as a function of t.  Discrete time:
        a piecewise-constant matrix with value ``X[k]`` on ``[k dt, (k+1) dt)``
        (``.sample(N)`` returns the stack).

    Raises
    ------
    ValueError
        If the system is unstable or `type` is unknown.

    Examples
    --------
    >>> G = ct.ss([[-1.0, 0.0, 0.0], [1.0, -2.0, 0.0], [0.0, 1.0, -3.0]],
    ...           [[1.0], [0.0], [0.5]], [[0.0, 1.0, 1.0]], 0)
    >>> P = ltp.gram(ltp.ltpss(G, period=2.0), 'c')
    >>> np.allclose(P(0.7), ct.gram(G, 'c'))
    True
    """
    if isinstance(sys, DiscreteLTPSystem):          # time-varying dimensions: lists
        return tv_gram(sys, type)
    sys = as_ltp(sys)
    if type not in ('c', 'o'):
        raise ValueError(f"type must be 'c' or 'o', got {type!r}")
    if not sys.is_stable():
        raise ValueError("gram: the system is unstable; gramians exist for stable "
                         "systems only")
    adjoint = type == 'o'
    Q = sys.C.T @ sys.C if adjoint else sys.B @ sys.B.T
    if sys.isdtime():
        N = sys.nsteps
        X = dlyap(sys.A.sample(N), Q.sample(N), adjoint=adjoint)
        return PeriodicMatrix.from_samples(X, sys.period, kind='hold')
    return lyap(sys.A, Q, adjoint=adjoint)


#
# Shared solvers (also used by the norms)
#

def cyclic_lyap(Phi, W, adjoint=False, check=True, method='auto'):
    """Solve the cyclic periodic discrete Lyapunov equation (module notes).

    ``X_{k+1} = Φ_k X_k Φ_kᵀ + W_k`` (forward) or ``X_k = Φ_kᵀ X_{k+1}
    Φ_k + W_k`` (adjoint), k = 0..M−1 cyclic; returns ``X_0..X_{M−1}``.
    ``check=False`` skips the uniqueness test (for callers that know the
    factors are stable).

    ``method='sparse'`` solves the M n² x M n² cyclic Kronecker system by a
    sparse LU (exact also for unstable factors, but O(M n⁴) memory);
    ``'monodromy'`` solves the one-period Stein equation ``X_0 = ΨX_0Ψᵀ +
    W̄`` of the monodromy Ψ by a Schur method and propagates the steps,
    O(M n³) time and O(M n²) memory (`_monodromy_lyap`).  ``'auto'`` takes
    the sparse LU while its Kronecker blocks stay small (M n⁴ <= 4e6).

    Examples
    --------
    >>> from ltpcontrol._analysis.lyapunov import cyclic_lyap
    >>> X = cyclic_lyap(np.array([[[0.5]], [[3.0]]]), np.ones((2, 1, 1)))
    >>> X[:, 0, 0]          # X1 = X0/4 + 1, X0 = 9 X1 + 1
    array([-8., -1.])
    >>> cyclic_lyap(np.array([[[0.5]], [[3.0]]]), np.ones((2, 1, 1)),
    ...             method='monodromy')[:, 0, 0]
    array([-8., -1.])
    """
    M, n = Phi.shape[0], Phi.shape[1]
    if n == 0:
        return np.zeros((M, 0, 0))
    if method not in ('auto', 'sparse', 'monodromy'):
        raise ValueError(f"method must be 'auto', 'sparse' or 'monodromy', got {method!r}")
    if method == 'monodromy' or (method == 'auto' and M * n ** 4 > _SPARSE_LIMIT):
        return _monodromy_lyap(Phi, W, adjoint, check)
    if check:
        check_unique(Phi)
    nn = n * n
    K = np.einsum('kia,kjb->kijab', Phi, Phi).reshape(M, nn, nn)   # Φ ⊗ Φ
    if adjoint:
        K = np.swapaxes(K, 1, 2)                   # Φᵀ ⊗ Φᵀ
    # column j = (c, b) of the block matrix holds 1 at row (c, b) (equation
    # with unknown c as output) and column b of −K_k at row block r: the
    # equation k with c as input, k = c, r = c + 1 (forward), or k = r = c − 1
    blocks = np.arange(M)
    k = blocks if not adjoint else (blocks - 1) % M
    r = (blocks + 1) % M if not adjoint else k
    i = np.arange(nn)
    rows = np.empty((M, nn, nn + 1), int)
    rows[:, :, 0] = blocks[:, None] * nn + i
    rows[:, :, 1:] = (r[:, None] * nn + i)[:, None, :]
    vals = np.empty((M, nn, nn + 1))
    vals[:, :, 0] = 1.0
    vals[:, :, 1:] = -np.swapaxes(K[k], 1, 2)
    L = sp.csc_matrix((vals.ravel(), rows.ravel(), np.arange(M * nn + 1) * (nn + 1)),
                      shape=(M * nn, M * nn))
    L.sum_duplicates()                           # M = 1: the two blocks overlap
    # equation k sits in the rows of its output block (k + 1, or k adjoint)
    rhs = np.roll(W.reshape(M, nn), 0 if adjoint else 1, axis=0).ravel()
    X = spla.splu(L).solve(rhs).reshape(M, n, n)
    return 0.5 * (X + np.swapaxes(X, 1, 2))


def _monodromy_lyap(Phi, W, adjoint, check=True):
    """The cyclic equation through the monodromy's Stein equation, O(M n³).

    Forward: ``Ψ = Φ_{M−1}…Φ_0`` and ``W̄ = Σ_k Φ(M, k+1) W_k Φ(M, k+1)ᵀ``
    accumulated over one period, ``X_0 = ΨX_0Ψᵀ + W̄`` (`stein`), then
    ``X_{k+1} = Φ_kX_kΦ_kᵀ + W_k``; adjoint the same backwards with the
    transposed factors.  Propagating amplifies the error of X_0 along
    unstable directions: the last step, which returns to X_0, measures it,
    and a mismatch above 1e-8 warns.  ``check`` tests uniqueness on the
    Schur form of Ψ (``1 − μ_i conj(μ_j)``, the same set as ``1 − μ_iμ_j``
    for a real Ψ).

    Examples
    --------
    >>> from ltpcontrol._analysis.lyapunov import _monodromy_lyap
    >>> X = _monodromy_lyap(np.array([[[0.5]], [[3.0]]]), np.ones((2, 1, 1)), False)
    >>> X[:, 0, 0]
    array([-8., -1.])
    """
    M, n = Phi.shape[0], Phi.shape[1]
    PhiT = np.swapaxes(Phi, 1, 2)
    order = range(M - 1, -1, -1) if adjoint else range(M)
    Psi, Wbar = np.eye(n), np.zeros((n, n))
    for k in order:
        if adjoint:
            Wbar = PhiT[k] @ Wbar @ Phi[k] + W[k]
            Psi = Psi @ Phi[k]
        else:
            Wbar = Phi[k] @ Wbar @ PhiT[k] + W[k]
            Psi = Phi[k] @ Psi
    X = np.empty((M, n, n))
    X[0] = stein(Psi.T if adjoint else Psi, Wbar, check=check)
    prev = X[0]
    for k in (range(M - 1, 0, -1) if adjoint else range(M - 1)):
        nxt = k if adjoint else k + 1
        prev = (PhiT[k] @ prev @ Phi[k] if adjoint else Phi[k] @ prev @ PhiT[k]) + W[k]
        X[nxt] = prev = 0.5 * (prev + prev.T)
    last = PhiT[0] @ X[1 % M] @ Phi[0] + W[0] if adjoint else \
        Phi[M - 1] @ X[M - 1] @ PhiT[M - 1] + W[M - 1]
    scale = max(np.abs(X[0]).max(), np.abs(last).max(), 1e-300)
    mismatch = np.abs(last - X[0]).max() / scale
    if mismatch > 1e-8:
        warnings.warn(f"the periodic Lyapunov solution lost accuracy over the period "
                      f"(relative mismatch {mismatch:.1e} after one period; unstable "
                      f"Floquet multipliers amplify the error)", UserWarning, stacklevel=3)
    return X


def stein(Psi, W, check=True):
    """Solution of the Stein equation ``X = Ψ X Ψᵀ + W`` by a complex Schur form.

    With ``Ψ = U S Uᴴ`` (S upper triangular) and ``Y = UᴴXU``, column j of
    ``Y − S Y Sᴴ = UᴴWU`` is a triangular solve with ``I − conj(S_jj) S``
    once the columns l > j are known: O(n³).  ``check`` raises (or warns)
    as `check_unique` when ``1 − μ_i conj(μ_j)`` (nearly) vanishes.

    Examples
    --------
    >>> from ltpcontrol._analysis.lyapunov import stein
    >>> A = np.array([[0.5, 1.0], [-0.3, 0.2]])
    >>> X = stein(A, np.eye(2))
    >>> bool(np.allclose(X, ct.dlyap(A, np.eye(2))))
    True
    """
    n = Psi.shape[0]
    S, U = scipy.linalg.schur(Psi.astype(complex), output='complex')
    if check:
        mu = np.diag(S)
        _uniqueness_verdict(np.abs(1 - mu[:, None] * np.conj(mu[None, :])).min(), stacklevel=6)
    R = U.conj().T @ W @ U
    Y = np.zeros((n, n), complex)
    acc = np.zeros((n, n), complex)            # column j: Σ_{l>j} Y[:, l] conj(S[j, l])
    for j in range(n - 1, -1, -1):
        rhs = R[:, j] + S @ acc[:, j]
        Y[:, j] = scipy.linalg.solve_triangular(np.eye(n) - np.conj(S[j, j]) * S, rhs)
        acc[:, :j] += np.outer(Y[:, j], np.conj(S[:j, j]))
    X = (U @ Y @ U.conj().T).real
    return 0.5 * (X + X.T)


def check_unique(Phi):
    """Raise if ``μ_i μ_j = 1`` for two multipliers of ``Φ_{M−1} ... Φ_0``.

    Examples
    --------
    >>> from ltpcontrol._analysis.lyapunov import check_unique
    >>> check_unique(np.array([[[2.0, 0.0], [0.0, 0.5]]]))
    Traceback (most recent call last):
    ...
    ValueError: the periodic Lyapunov equation has no unique periodic solution: two Floquet multipliers satisfy mu_i mu_j = 1 (|mu_i mu_j - 1| = 0.0e+00)
    """
    logmod, arg = _log_multipliers(None, None, grid=None, factors=Phi)
    s = logmod[:, None] + logmod[None, :]
    with np.errstate(over='ignore', invalid='ignore'):
        gap = np.abs(np.exp(np.minimum(s, 50.0) + 1j * (arg[:, None] + arg[None, :])) - 1)
    _uniqueness_verdict(np.min(np.where(np.isnan(gap), np.inf, gap)))


def _uniqueness_verdict(worst, stacklevel=4):
    """Raise or warn for the smallest ``|μ_i μ_j − 1|`` (see `check_unique`)."""
    if worst <= _SINGULAR:
        raise ValueError("the periodic Lyapunov equation has no unique periodic solution: "
                         "two Floquet multipliers satisfy mu_i mu_j = 1 "
                         f"(|mu_i mu_j - 1| = {worst:.1e})")
    if worst <= _ILLCOND:
        warnings.warn("the periodic Lyapunov equation is ill-conditioned: two Floquet "
                      f"multipliers nearly satisfy mu_i mu_j = 1 (|mu_i mu_j - 1| = "
                      f"{worst:.1e})", UserWarning, stacklevel=stacklevel)


def periodic_solution(A, Q, grid, X, adjoint):
    """PeriodicMatrix evaluating the solution from the grid values `X`.

    Examples
    --------
    For ``Ẋ = -2X + 2`` (A = -1, Q = 2) the grid values ``X(0) = 0``,
    ``X(0.5) = 1 - e^{-1}`` are joined by ``X(t) = 1 - e^{-2t}``:

    >>> from ltpcontrol._analysis.lyapunov import periodic_solution
    >>> A = ltp.PeriodicMatrix.constant([[-1.0]], 1.0)
    >>> Q = ltp.PeriodicMatrix.constant([[2.0]], 1.0)
    >>> X = periodic_solution(A, Q, np.array([0.0, 0.5, 1.0]),
    ...                       np.array([[[0.0]], [[1 - np.exp(-1.0)]]]), adjoint=False)
    >>> X.shape, bool(np.isclose(X(0.25)[0, 0], 1 - np.exp(-0.5)))
    ((1, 1), True)
    """
    T, n = A.period, A.shape[0]
    starts, ends = grid[:-1], grid[1:]
    Xn = np.concatenate([X, X[:1]])              # X_M = X_0

    def evaluate(t):
        tau = np.mod(np.asarray(t, float), T)
        k = np.clip(np.searchsorted(starts, tau, side='right') - 1, 0, len(starts) - 1)
        if adjoint:
            # X(τ) = Φ(t_{k+1}, τ)ᵀ X_{k+1} Φ(t_{k+1}, τ) + V(τ, t_{k+1})
            Phi, _, V, _ = step_integrals(A, tau, ends[k] - tau, Qa=Q)
            return np.swapaxes(Phi, 1, 2) @ Xn[k + 1] @ Phi + V
        # X(τ) = Φ(τ, t_k) X_k Φ(τ, t_k)ᵀ + W(t_k, τ)
        Phi, W, _, _ = step_integrals(A, starts[k], tau - starts[k], Qf=Q)
        return Phi @ X[k] @ np.swapaxes(Phi, 1, 2) + W

    breaks = np.concatenate([A.breakpoints, Q.breakpoints])
    return PeriodicMatrix.from_function(evaluate, T, (n, n), breakpoints=breaks, check=False)


#
# Input handling
#

def _pair(A, Q, period, where):
    if isinstance(A, PeriodicMatrix):
        if period is not None and abs(period - A.period) > 1e-12 * period:
            A = as_periodic(A, period, 'A')
    else:
        if period is None:
            raise ControlArgument(f"{where}: A is not a PeriodicMatrix; give its period")
        A = as_periodic(A, period, 'A')
    if A.shape[0] != A.shape[1]:
        raise ControlDimension(f"A must be square, got shape {A.shape}")
    if isinstance(Q, PeriodicMatrix):
        try:
            Q = Q.with_period(A.period)
        except ValueError:
            raise ValueError(f"Q has period {Q.period}, which does not divide the period "
                             f"{A.period} of A") from None
    else:
        Q = as_periodic(Q, A.period, 'Q')
    if Q.shape != A.shape:
        raise ControlDimension(f"Q must have the shape {A.shape} of A, got {Q.shape}")
    probe = np.concatenate([np.linspace(0, A.period, 17)[:-1] + 0.0123 * A.period,
                            Q.breakpoints])
    _check_symmetric(Q(probe), 'Q')
    return A, Q


def _check_symmetric(Q, name):
    scale = max(1.0, np.abs(Q).max(initial=0.0))
    if np.abs(Q - np.swapaxes(Q, -1, -2)).max(initial=0.0) > 1e-10 * scale:
        raise ValueError(f"{name} must be symmetric")


def _check_bool(value, name):
    if not isinstance(value, (bool, np.bool_)):
        raise ControlArgument(f"{name} must be True or False, got {value!r}")
