"""Minimal realizations and balanced truncation of discrete periodic systems.

Minimal realization by orthogonal projections on the periodic reachable and
observable subspaces (a periodic staircase in the sense of Varga's
``psminreal``; the order may change with k):

* reachable subspaces: the smallest family ``R_k`` with ``range B_k ⊂
  R_{k+1}`` and ``A_k R_k ⊂ R_{k+1}``, found by sweeping around the period
  and appending to the orthonormal basis of ``R_{k+1}`` the directions of
  ``[A_k R_k, B_k]`` outside it (a staircase step) until no dimension grows
  (at most ``Σ n_k`` sweeps).  With orthonormal bases ``T_k`` the restriction
  ``(T_{k+1}ᵀA_kT_k, T_{k+1}ᵀB_k, C_kT_k, D_k)`` has the same input-output
  map and is reachable;
* observable subspaces: the smallest family ``O_k`` with ``range C_kᵀ ⊂
  O_k`` and ``A_kᵀ O_{k+1} ⊂ O_k`` (backward sweeps); the projection
  ``(Z_{k+1}ᵀA_kZ_k, Z_{k+1}ᵀB_k, C_kZ_k, D_k)`` keeps the map and is
  observable.

Reachable then observable gives a minimal periodic realization (Kalman's
decomposition, step by step; stability is not needed).  Ranks are decided
by singular values above ``tol`` times the norm of the step's data.

Default tolerance.  python-control cancels a pole p against a zero z of a
transfer function when ``|z - p| < 1000 sqrt(eps) |z|``
(``TransferFunction.minreal``, the path of its near-cancellation test
``(s+1)(s+2.00000000001)/((s+2)(s²+s+1))``).  A pole-zero pair at a
relative distance δ leaves a staircase singular value of order δ relative
to the step's data, so the same relative tolerance ``MINREAL_TOL = 1000
sqrt(eps)`` (about 1.5e-5) is the default here: in the LTI limit the pairs
python-control cancels are removed, and a pair 1e-3 apart is kept.

Balanced truncation with time-varying dimensions: the periodic gramians of
`tv_dlyap`, per-step square-root balancing ``W_k = Σ_r^{-1/2}U_rᵀR_kᵀ``,
``V_k = S_kV_rΣ_r^{-1/2}`` (Cholesky-free square roots from eigenvalue
decompositions, so that singular gramians are accepted), and the reduced
``(W_{k+1}A_kV_k, W_{k+1}B_k, C_kV_k, D_k)`` of constant order r with the
bound ``2 Σ_{j>r} max_k σ_j(k)`` (values beyond ``n_k`` count as zero).
"""

import numpy as np

from .._core.tvsystem import DiscreteLTPSystem
from .tvdesign import tv_gram

__all__ = []

#: Default relative rank tolerance (module notes).
MINREAL_TOL = 1000 * np.sqrt(np.finfo(float).eps)


def periodic_minreal(sys, tol=None):
    """Minimal realization of a `DiscreteLTPSystem` (module notes).

    `tol` is the relative rank tolerance (default `MINREAL_TOL`).

    Examples
    --------
    >>> from ltpcontrol._analysis.minimal import periodic_minreal
    >>> sys = ltp.dltpss([np.diag([0.5, 0.3]), np.diag([0.2, -0.4])],
    ...                  [[[1.0], [0.0]]], [[[1.0, 1.0]]], 0)
    >>> periodic_minreal(sys, 1e-10).nstates
    (1, 1)
    """
    tol = MINREAL_TOL if tol is None else tol
    red = _observable_part(_reachable_part(sys, tol), tol)
    red.name = sys.name + '$minreal'
    return red


def _reachable_part(sys, tol):
    N = sys.nsteps
    return _smallest_family(sys, tol, [((k + 1) % N, k, sys.A[k], sys.B[k])
                                       for k in range(N)])


def _observable_part(sys, tol):
    # the reachable part of the dual: A_kᵀ maps O_(k+1) into O_k, C_kᵀ spans into O_k
    N = sys.nsteps
    return _smallest_family(sys, tol, [(k, (k + 1) % N, sys.A[k].T, sys.C[k].T)
                                       for k in range(N - 1, -1, -1)])


def _smallest_family(sys, tol, steps):
    """Orthonormal bases of the smallest subspaces with ``range G ⊂ S_to`` and
    ``M S_from ⊂ S_to`` for every ``(to, from, M, G)`` of `steps` (swept in that
    order until no dimension grows), and the projection of `sys` on them."""
    T = [np.zeros((nk, 0)) for nk in sys.nstates]
    scale = [max(np.linalg.norm(np.hstack([M, G]), 2), 1e-300) if M.size + G.size else 1.0
             for _, _, M, G in steps]
    for _ in range(sum(sys.nstates) + 2):
        grown = False
        for (to, frm, M, G), sc in zip(steps, scale):
            T[to], added = _extend(T[to], np.hstack([M @ T[frm], G]), tol * sc)
            grown = grown or added
        if not grown:
            break
    return _project(sys, T, T)


def _extend(T, M, threshold):
    """Append to the orthonormal basis T the directions of M outside its span.

    Only the part of M orthogonal to T is examined (a staircase step), so
    the directions already found are never recomputed: rounding errors
    along unreachable (unobservable) unstable modes are not amplified from
    one sweep to the next.
    """
    if M.shape[1] == 0 or T.shape[0] == T.shape[1]:
        return T, False
    R = M - T @ (T.T @ M)
    R = R - T @ (T.T @ R)
    U, sv, _ = np.linalg.svd(R, full_matrices=False)
    r = int(np.count_nonzero(sv > threshold))
    if r == 0:
        return T, False
    new = U[:, :r]
    new = new - T @ (T.T @ new)
    new, _ = np.linalg.qr(new)
    return np.hstack([T, new]), True


def _project(sys, W, V):
    """``(W_{k+1}ᵀA_kV_k, W_{k+1}ᵀB_k, C_kV_k, D_k)`` with per-step bases."""
    N = sys.nsteps
    A = [W[(k + 1) % N].T @ sys.A[k] @ V[k] for k in range(N)]
    B = [W[(k + 1) % N].T @ sys.B[k] for k in range(N)]
    C = [sys.C[k] @ V[k] for k in range(N)]
    return DiscreteLTPSystem(A, B, C, list(sys.D), sys.dt, name=sys.name + '$minreal')


def _sqrt_factor(X):
    """``F`` with ``X = F Fᵀ`` for a symmetric positive semidefinite X."""
    w, U = np.linalg.eigh(0.5 * (X + X.T))
    return U * np.sqrt(np.clip(w, 0.0, None))


def tv_hsvd(sys):
    """Hankel singular values per step (list of arrays, decreasing; ``n_k`` at step k).

    Examples
    --------
    >>> from ltpcontrol._analysis.minimal import tv_hsvd
    >>> sys = ltp.dltpss([[[0.5, 0.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                  [[[1.0, 1.0]], [[1.0]]], 0)
    >>> [len(s) for s in tv_hsvd(sys)]
    [2, 1]
    """
    P = tv_gram(sys, 'c')
    Q = tv_gram(sys, 'o')
    return [np.linalg.svd(_sqrt_factor(Qk).T @ _sqrt_factor(Pk), compute_uv=False)
            for Pk, Qk in zip(P, Q)]


def tv_balred(sys, r):
    """Balanced truncation of a stable `DiscreteLTPSystem` to constant order r.

    Returns the reduced system and the a-priori bound on the ℓ2 gain of the
    error (module notes).

    Examples
    --------
    A weakly coupled second mode (Hankel singular value 4.7e-6):

    >>> from ltpcontrol._analysis.minimal import tv_balred
    >>> sys = ltp.dltpss([np.diag([0.5, 0.1]), 0.3 * np.eye(2)], [[[1.0], [0.01]]],
    ...                  [[[1.0, 0.01]]], 0)
    >>> red, bound = tv_balred(sys, 1)
    >>> red.nstates, float(np.round(bound, 8))       # 2 * 4.7e-6
    ((1, 1), 9.45e-06)
    """
    P = tv_gram(sys, 'c')
    Q = tv_gram(sys, 'o')
    N = sys.nsteps
    W, V, hsv = [], [], []
    for k in range(N):
        S, R = _sqrt_factor(P[k]), _sqrt_factor(Q[k])
        U, s, Vt = np.linalg.svd(R.T @ S)
        hsv.append(s)
        if r > len(s) or s[r - 1] <= 1e-13 * max(1.0, s[0]):
            raise ValueError(f"the Hankel singular value {r} vanishes at step {k}: no "
                             f"balanced truncation of constant order {r} exists (use a "
                             "smaller order, or minreal first)")
        scale = 1 / np.sqrt(s[:r])
        W.append((scale[:, None] * (U[:, :r].T @ R.T)).T)     # stored transposed
        V.append(S @ Vt[:r].T * scale[None, :])
    red = _project(sys, W, V)
    red.name = sys.name + '$reduced'
    width = max(len(s) for s in hsv)
    table = np.zeros((N, width))
    for k, s in enumerate(hsv):
        table[k, :len(s)] = s
    bound = 2 * float(np.sum(np.max(table[:, r:], axis=0))) if width > r else 0.0
    return red, bound
