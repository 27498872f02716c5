"""Riccati equations, LQ design and norms with time-varying dimensions.

Periodic Riccati equation (``A_k``: ``n_{k+1} x n_k``, ``B_k``:
``n_{k+1} x m_k``, ``Q_k``: ``n_k x n_k``, ``R_k``: ``m_k x m_k``, ``S_k``:
``n_k x m_k``)::

    X_k = A_kᵀX_{k+1}A_k − (A_kᵀX_{k+1}B_k + S_k)(R_k + B_kᵀX_{k+1}B_k)⁻¹
          (B_kᵀX_{k+1}A_k + S_kᵀ) + Q_k.

Its stabilizing solution at the step j of smallest dimension is that of the
LTI problem lifted over one period from j (the LQ cost over one period is a
quadratic form in the state at j and the N stacked inputs, and the state a
period later is ``Φ x_j + Γ U``): ``X_j`` solves the DARE of ``(Φ, Γ)`` with
the lifted weights; the other ``X_k`` follow from one backward sweep of the
recursion from ``X_{j+N} = X_j`` (one period of a contractive map, exact to
rounding).  The Kalman predictor is the dual problem on the transposed,
time-reversed system (step j of the dual is step ``N-1-j``), as in
`ltpcontrol.dlqe`.

Norms: the H2 norm is the per-step average ``(1/N) Σ_k tr(C_kP_kC_kᵀ +
D_kD_kᵀ)`` of the controllability gramians ``P_k`` (`tv_dlyap`), the
library's convention; the ℓ∞ (ℓ2-induced) norm is that of the time-lifted
LTI system, on which the time lifting is an isometry.
"""

import numpy as np
import scipy.linalg as la
import control as ct
from control.exception import ControlArgument, ControlDimension

from .._core.subperiods import common_steps
from .._core.tvsystem import DiscreteLTPSystem, as_tv, check_chain, cyclic_multipliers, _sequence
from .._core.lifting_forms import tv_time_lift
from .tvlyap import tv_dlyap

__all__ = ['tv_dare']


def tv_dare(A, B, Q, R, S=None):
    """Stabilizing solution of the periodic Riccati equation, dimensions varying.

    Parameters
    ----------
    A, B, Q, R, S : list of array_like
        The matrices of one period (module notes for the shapes); lists of
        different lengths are combined on their least common multiple.  S
        is zero by default.

    Returns
    -------
    X : list of ndarray
        ``X_k`` (``n_k x n_k``).
    L : ndarray of complex
        Closed-loop core multipliers of ``Π_k (A_k − B_kG_k)`` (zero-padded
        to ``n_0``, see `DiscreteLTPSystem.floquet_multipliers`).
    G : list of ndarray
        Gains ``G_k = (R_k + B_kᵀX_{k+1}B_k)⁻¹(B_kᵀX_{k+1}A_k + S_kᵀ)``.

    Examples
    --------
    >>> A = [np.array([[1.0, 2.0]]), np.array([[7.0], [8.0]])]
    >>> B = [np.array([[3.0]]), np.array([[9.0], [10.0]])]
    >>> X, L, G = ltp.dare(A, B, [np.eye(2), np.eye(1)], [np.eye(1), np.eye(1)])
    >>> [x.shape for x in X], bool(np.all(np.abs(L) < 1))
    ([(2, 2), (1, 1)], True)
    """
    seqs = {'A': _sequence(A, 'A'), 'B': _sequence(B, 'B'), 'Q': _sequence(Q, 'Q'),
            'R': _sequence(R, 'R')}
    if S is not None:
        seqs['S'] = _sequence(S, 'S')
    N = common_steps([len(s) for s in seqs.values()], list(seqs))
    A, B, Q, R = ([s[k % len(s)] for k in range(N)] for s in
                  (seqs['A'], seqs['B'], seqs['Q'], seqs['R']))
    n = check_chain(A)
    m = [b.shape[1] for b in B]
    S = [np.zeros((n[k], m[k])) for k in range(N)] if S is None else \
        [seqs['S'][k % len(seqs['S'])] for k in range(N)]
    for k in range(N):
        for M, name, shape in ((B[k], 'B', (n[(k + 1) % N], m[k])), (Q[k], 'Q', (n[k],) * 2),
                               (R[k], 'R', (m[k],) * 2), (S[k], 'S', (n[k], m[k]))):
            if M.shape != shape:
                raise ControlDimension(f"{name}[{k}] must have shape {shape}, got {M.shape}")
        for M, name in ((Q[k], 'Q'), (R[k], 'R')):
            if np.abs(M - M.T).max(initial=0.0) > 1e-10 * max(1.0, np.abs(M).max(initial=0)):
                raise ValueError(f"{name}[{k}] must be symmetric")
        if m[k] and np.linalg.eigvalsh(R[k]).min() <= 0:
            raise ValueError(f"R[{k}] must be positive definite")
    j = int(np.argmin(n))
    order = [(j + i) % N for i in range(N)]
    Xj = _lifted_dare([A[i] for i in order], [B[i] for i in order], [Q[i] for i in order],
                      [R[i] for i in order], [S[i] for i in order])
    X = [None] * N
    X[j] = Xj
    Xn = Xj
    for i in range(N - 1, 0, -1):        # backward sweep over one period
        k = order[i]
        Xn = _riccati_step(A[k], B[k], Q[k], R[k], S[k], Xn)
        X[k] = Xn
    G = [_gain(A[k], B[k], R[k], S[k], X[(k + 1) % N]) for k in range(N)]
    L = cyclic_multipliers([A[k] - B[k] @ G[k] for k in range(N)])
    return X, L, G


def _lifted_dare(A, B, Q, R, S):
    """X at the first step from the DARE of the system lifted over one period."""
    N = len(A)
    n0 = A[0].shape[1]
    m = [b.shape[1] for b in B]
    moff = np.concatenate([[0], np.cumsum(m)]).astype(int)
    M = moff[-1]
    F = np.eye(n0)                       # x_k = F x_0 + G U
    Gm = np.zeros((n0, M))
    W = np.zeros((n0 + M, n0 + M))
    for k in range(N):
        Z = np.zeros((A[k].shape[1] + m[k], n0 + M))
        Z[:A[k].shape[1], :n0] = F
        Z[:A[k].shape[1], n0:] = Gm
        Z[A[k].shape[1]:, n0 + moff[k]:n0 + moff[k + 1]] = np.eye(m[k])
        Wk = np.block([[Q[k], S[k]], [S[k].T, R[k]]])
        W += Z.T @ Wk @ Z
        F = A[k] @ F
        Gm = A[k] @ Gm
        Gm[:, moff[k]:moff[k + 1]] += B[k]
    W = 0.5 * (W + W.T)
    try:
        X = la.solve_discrete_are(F, Gm, W[:n0, :n0], W[n0:, n0:], s=W[:n0, n0:])
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ValueError("the periodic Riccati equation has no stabilizing solution "
                         f"(lifted problem: {exc})") from None
    return 0.5 * (X + X.T)


def _riccati_step(a, b, q, r, s, xn):
    t = a.T @ xn @ b + s
    x = a.T @ xn @ a + q - t @ np.linalg.solve(r + b.T @ xn @ b, t.T)
    return 0.5 * (x + x.T)


def _gain(a, b, r, s, xn):
    return np.linalg.solve(r + b.T @ xn @ b, b.T @ xn @ a + s.T)


def _weights(W, sizes, name):
    """Per-step weights: a list (cycled), a 3D array, or one 2D matrix."""
    seq = _sequence(W, name)
    N = common_steps([len(seq), len(sizes)], [name, 'sys'])
    out = [seq[k % len(seq)] for k in range(N)]
    for k, (w, size) in enumerate(zip(out, [sizes[k % len(sizes)] for k in range(N)])):
        if w.shape != size:
            raise ControlDimension(f"{name}[{k}] must have shape {size}, got {w.shape}")
    return out


def tv_dlqr(sys, Q, R, N=None, *, integral_action=None):
    """Periodic LQR of a `DiscreteLTPSystem` (`ltpcontrol.dlqr` dispatches here).

    Returns
    -------
    K : list of ndarray
        Gains ``K_k`` (``m_k x n_k``), ``u_k = -K_k x_k``.
    X : list of ndarray
        Stabilizing Riccati solution.
    E : ndarray of complex
        Closed-loop core multipliers (zero-padded).

    Examples
    --------
    >>> sys = ltp.dltpss([[[1.0, 2.0]], [[7.0], [8.0]]], [[[3.0]], [[9.0], [10.0]]],
    ...                  [[[4.0, 5.0]], [[11.0]]], [[1.0]])
    >>> K, X, E = ltp.dlqr(sys, [np.eye(2), np.eye(1)], np.eye(1))
    >>> [k.shape for k in K], bool(np.all(np.abs(E) < 1))
    ([(1, 2), (1, 1)], True)
    """
    if integral_action is not None:
        raise ControlArgument("integral_action is not available for time-varying "
                              "dimensions; augment the plant with its integrators")
    sys = as_tv(sys)
    n, m, Nn = sys.nstates, sys.ninputs, sys.nsteps
    Qs = _weights(Q, [(n[k], n[k]) for k in range(Nn)], 'Q')
    Rs = _weights(R, [(m[k], m[k]) for k in range(Nn)], 'R')
    Ss = None if N is None else _weights(N, [(n[k], m[k]) for k in range(Nn)], 'N')
    X, E, K = tv_dare(list(sys.A), list(sys.B), Qs, Rs, Ss)
    return K, X, E


def tv_dlqe(sys, QN, RN, NN=None):
    """Periodic Kalman predictor of a `DiscreteLTPSystem` (G = B, as `ltpcontrol.dlqe`).

    Returns
    -------
    L : list of ndarray
        Predictor gains ``L_k`` (``n_{k+1} x p_k``).
    P : list of ndarray
        A priori error covariances ``P_k`` (``n_k x n_k``).
    E : ndarray of complex
        Core multipliers of the error dynamics ``A_k − L_kC_k``.

    Examples
    --------
    >>> sys = ltp.dltpss([[[1.0, 2.0]], [[7.0], [8.0]]], [[[3.0]], [[9.0], [10.0]]],
    ...                  [[[4.0, 5.0]], [[11.0]]], [[1.0]])
    >>> L, P, E = ltp.dlqe(sys, np.eye(1), np.eye(1))
    >>> [l.shape for l in L], bool(np.all(np.abs(E) < 1))
    ([(1, 1), (2, 1)], True)
    """
    sys = as_tv(sys)
    Nn = sys.nsteps
    m, p = sys.ninputs, sys.noutputs
    QN = _weights(QN, [(m[k], m[k]) for k in range(Nn)], 'QN')
    RN = _weights(RN, [(p[k], p[k]) for k in range(Nn)], 'RN')
    NN = [np.zeros((m[k], p[k])) for k in range(Nn)] if NN is None else \
        _weights(NN, [(m[k], p[k]) for k in range(Nn)], 'NN')
    # dual step j is step k = N-1-j of the plant
    ks = [Nn - 1 - j for j in range(Nn)]
    Ad = [sys.A[k].T for k in ks]
    Bd = [sys.C[k].T for k in ks]
    Qd = [sys.B[k] @ QN[k] @ sys.B[k].T for k in ks]
    Rd = [RN[k] for k in ks]
    Sd = [sys.B[k] @ NN[k] for k in ks]
    Xd, _, Gd = tv_dare(Ad, Bd, Qd, Rd, Sd)
    P = [Xd[(Nn - k) % Nn] for k in range(Nn)]          # P_k = X̃_{N-k}
    L = [Gd[Nn - 1 - k].T for k in range(Nn)]            # L_k = G̃_{N-1-k}ᵀ
    E = cyclic_multipliers([sys.A[k] - L[k] @ sys.C[k] for k in range(Nn)])
    return L, P, E


def tv_gram(sys, type):
    """Periodic gramians ``P_k`` ('c') or ``Q_k`` ('o') of a stable `DiscreteLTPSystem`.

    ``P_{k+1} = A_kP_kA_kᵀ + B_kB_kᵀ`` and ``Q_k = A_kᵀQ_{k+1}A_k + C_kᵀC_k``
    (`ltpcontrol.gram` of these systems), ``P_k`` and ``Q_k`` ``n_k x n_k``.

    Examples
    --------
    >>> from ltpcontrol._analysis.tvdesign import tv_gram
    >>> sys = ltp.dltpss([[[0.5, 0.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                  [[[1.0, 1.0]], [[1.0]]], 0)
    >>> P = tv_gram(sys, 'c')
    >>> [p.shape for p in P]
    [(2, 2), (1, 1)]
    >>> bool(np.allclose(sys.A[0] @ P[0] @ sys.A[0].T + sys.B[0] @ sys.B[0].T, P[1]))
    True
    """
    if type not in ('c', 'o'):
        raise ValueError(f"type must be 'c' or 'o', got {type!r}")
    if not sys.is_stable():
        raise ValueError("the system is unstable: its gramians do not exist")
    if type == 'c':
        return tv_dlyap(list(sys.A), [b @ b.T for b in sys.B])
    return tv_dlyap(list(sys.A), [c.T @ c for c in sys.C], adjoint=True)


def tv_norm(sys, p=2, tol=1e-6):
    """H2, ℓ∞ or Hankel norm of a stable `DiscreteLTPSystem` (module notes).

    The Hankel norm is ``max_k sqrt(λ_max(P_k Q_k))`` over the steps.

    Examples
    --------
    >>> sys = ltp.dltpss([[[0.5]]], [[[1.0]]], [[[1.0]]], 0)
    >>> round(ltp.norm(sys, 2), 10), round(ltp.norm(sys, np.inf), 10)
    (1.1547005384, 2.0)
    """
    sys = as_tv(sys)
    if p == 2:
        P = tv_gram(sys, 'c')
        total = sum(np.trace(sys.C[k] @ P[k] @ sys.C[k].T + sys.D[k] @ sys.D[k].T)
                    for k in range(sys.nsteps))
        return float(np.sqrt(max(total, 0.0) / sys.nsteps))
    if p in (np.inf, 'inf'):
        if not sys.is_stable():
            raise ValueError("the system is unstable: its ℓ∞ norm is infinite")
        A, B, C, D = tv_time_lift(sys)
        if A.shape[0] == 0:
            return float(np.linalg.norm(D, 2))
        L = ct.ss(A, B, C, D, sys.period)
        return float(ct.norm(L, 'inf', tol=tol))
    if p == 'hankel':
        P, Q = tv_gram(sys, 'c'), tv_gram(sys, 'o')
        return float(np.sqrt(max(max(np.linalg.eigvals(Pk @ Qk).real.max(initial=0.0), 0.0)
                                 for Pk, Qk in zip(P, Q))))
    raise ControlArgument(f"p must be 2, np.inf or 'hankel', got {p!r}")
