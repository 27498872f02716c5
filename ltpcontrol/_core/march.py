"""Exact march of a periodic recurrence by blocks of steps (BLAS-3 kernel).

The exact discretization of an LTP system on a uniform grid whose step
divides the period (see ``_transition``), or a discrete-time LTP system, is
the recurrence with N-periodic step data

    x[k+1] = Φ_k x[k] + E_k u[k] + F_k u[k+1],     y[k] = C_k x[k] + D_k u[k],

(phase k mod N; first-order hold: ``E = Γ0 - Γ1``, ``F = Γ1``; zero-order
hold and discrete time: ``F = 0``).  A scalar loop over the samples does
O(n² + nm + pn) work per sample and trace, which NumPy cannot do at compiled
speed.  Instead the samples are grouped in blocks of b steps.  Inside a
block that starts at sample s with phase c, unrolling the recurrence gives

    x[s+k] = Φ(k, 0) x[s] + Σ_{j=0..b} V_kj u[s+j],   k = 0..b,

    Φ(k, j) = Φ_{k-1} ⋯ Φ_j,   V_kj = Φ(k, j+1) E_j [j < k] + Φ(k, j) F_{j-1} [0 < j ≤ k],

(step data of phase c + j), and ``y[s+k] = C_k x[s+k] + D_k u[s+k]``.  So
all samples of all blocks of one phase, for every trace, are one matrix
product: the rows are (trace, block), the columns are (signal, k) and the
inner dimension is the b + 1 input samples of the block window plus the n
block-start states.  Block-start states come from two short recurrences:

1. period starts, ``x[(q+1)N] = Ψ x[qN] + z_q`` (loop over periods, all
   traces at once; Ψ the monodromy matrix, ``z_q`` one product per phase);
2. block starts inside every period (loop over the N/b phases, all periods
   and traces at once).

A block is either a divisor of the period or a whole number of periods
(the step data are then repeated), chosen near `_TARGET_BLOCK` steps: long
enough for efficient matrix products, short enough that the triangular
block operator does not waste work (cost ∝ b per sample).  Memory is
linear in traces × samples: one padded copy of the input, the result, and
a bounded work array (`_CHUNK_BYTES`).
"""

import math

import numpy as np
from numpy.lib.stride_tricks import as_strided

__all__ = []

_TARGET_BLOCK = 20
_CHUNK_BYTES = 32 * 2 ** 20


def block_length(N, L):
    """Block length b: a divisor or a multiple of the period N near the target.

    Examples
    --------
    >>> from ltpcontrol._core.march import block_length
    >>> block_length(50, 20001), block_length(37, 1000), block_length(2, 1000)
    (25, 37, 20)
    """
    cands = [d for d in range(1, N + 1) if N % d == 0]
    cands += [N * q for q in range(2, _TARGET_BLOCK // N + 2)]
    cands = [b for b in cands if b <= max(L - 1, 1)] or [1]
    return min(cands, key=lambda b: (abs(math.log(b / _TARGET_BLOCK)), -b))


def periodic_march(Phi, E, F, C, D, u, x0, *, states=True, final=False, nsamples=None):
    """States and outputs of the N-periodic recurrence (module docstring).

    Parameters
    ----------
    Phi : ndarray, shape (N, n, n)
    E : ndarray, shape (N, n, m)
    F : ndarray, shape (N, n, m) or None
        Coefficient of ``u[k+1]`` (None: zero).
    C : ndarray, shape (N, p, n)
    D : ndarray, shape (N, p, m)
    u : ndarray, shape (m, R, L) or (m, R, L + 1)
        Inputs of R traces at L samples; sample 0 has phase 0.
    x0 : ndarray, shape (n, R)
    states : bool
        Compute the states (False: outputs only, less work and memory).
    final : bool
        Also return the state at sample ``Q N``, ``Q = ceil(L / N)`` (the
        start of the period after the record; meant for ``L = Q N``).  With
        F given it needs ``u[Q N]``: pass it as an extra sample of `u`
        beyond `nsamples` (otherwise the last sample is held).
    nsamples : int, optional
        Number L of samples to return (default ``u.shape[2]``).

    Returns
    -------
    x : ndarray, shape (n, R, L), or None when not `states`
    y : ndarray, shape (p, R, L)
    xend : ndarray, shape (n, R), only when `final`

    Examples
    --------
    >>> from ltpcontrol._core.march import periodic_march
    >>> Phi = np.array([[[0.5]], [[2.0]]])               # x[k+1] = Φ_k x[k] + u[k]
    >>> E, C, D = np.ones((2, 1, 1)), np.ones((2, 1, 1)), np.zeros((2, 1, 1))
    >>> x, y = periodic_march(Phi, E, None, C, D, np.ones((1, 1, 5)), np.ones((1, 1)))
    >>> x[0, 0]
    array([1. , 1.5, 4. , 3. , 7. ])
    """
    N, n, m = E.shape
    p = C.shape[1]
    R, Lu = u.shape[1], u.shape[2]
    b = block_length(N, Lu)
    if b > N:                                   # a block of b/N whole periods
        reps = b // N
        Phi, E, C, D = (np.tile(a, (reps, 1, 1)) for a in (Phi, E, C, D))
        F = None if F is None else np.tile(F, (reps, 1, 1))
        N = b
    L = Lu if nsamples is None else int(nsamples)
    ops = _block_operators(Phi, E, F, C, D, b, states)
    nph = N // b
    Q = max(1, -(-L // N))                      # periods covering the samples
    rows = R * Q                                # (trace, period) pairs

    # input laid out as rows of one period, padded with the last sample; the
    # window of b + 1 samples of block c in row r starts at r N + c b
    buf = np.empty((m, rows * N + N))
    padded = buf[:, :rows * N].reshape(m, R, Q * N)
    keep = min(Lu, Q * N)
    padded[:, :, :keep] = u[:, :, :keep]
    padded[:, :, keep:] = u[:, :, keep - 1:keep]
    buf[:, rows * N:] = 0.0
    if final and Lu > Q * N:
        # the sample after the last row of each trace is the next row's first
        # one (other traces) or the tail of the buffer (last trace)
        nxt = np.empty((m, R))
        nxt[:] = u[:, :, Q * N]
    else:
        nxt = None

    def windows(c, r0, r1):
        return as_strided(buf[:, r0 * N + c * b:], shape=(m, r1 - r0, b + 1),
                          strides=(buf.strides[0], N * buf.strides[1], buf.strides[1]),
                          writeable=False)

    def forcing(c, r0, r1):
        # forcing over block c from a zero start, Σ_j V_bj u[s+j]: (r1 - r0, n)
        w = windows(c, r0, r1)
        return sum(w[i] @ ops.last[c, i] for i in range(m))
    z = [forcing(c, 0, rows) for c in range(nph)]
    if nxt is not None:
        # the last block of every trace's last row ends at sample Q N
        w_last = np.array(windows(nph - 1, 0, rows))
        w_last.reshape(m, R, Q, b + 1)[:, :, -1, -1] = nxt
        z[-1] = sum(w_last[i] @ ops.last[nph - 1, i] for i in range(m))
    # 1. period starts: x[(q+1)N] = Ψ x[qN] + z_q (row vectors: x Ψᵀ)
    zper = np.zeros((rows, n))
    for c in range(nph):
        zper = zper @ ops.Phi_b[c].T + z[c]
    zper = zper.reshape(R, Q, n)
    Psi = np.eye(n)
    for c in range(nph):
        Psi = ops.Phi_b[c] @ Psi
    starts = np.empty((R, Q, n))
    xq = x0.T
    for q in range(Q):
        starts[:, q] = xq
        xq = xq @ Psi.T + zper[:, q]
    # 2.-3. block starts and all samples of each phase, in row chunks: the rows
    # [u window of every input, x[s]] times the phase operator, written in place
    nsig = ops.operator.shape[1]
    out = np.empty((nsig, rows, N))
    xb = starts.reshape(rows, n)
    K = m * (b + 1) + n
    step = max(1, _CHUNK_BYTES // (8 * K))
    lhs_full = np.empty((min(step, rows), K))
    for c in range(nph):
        for r0 in range(0, rows, step):
            r1 = min(rows, r0 + step)
            lhs = lhs_full[:r1 - r0]
            w = windows(c, r0, r1)
            for i in range(m):
                lhs[:, i * (b + 1):(i + 1) * (b + 1)] = w[i]
            lhs[:, m * (b + 1):] = xb[r0:r1]
            np.matmul(lhs[None], ops.operator[c], out=out[:, r0:r1, c * b:(c + 1) * b])
        xb = xb @ ops.Phi_b[c].T + z[c]
    out = out.reshape(nsig, R, Q * N)
    x = out[:n, :, :L] if states else None
    y = out[nsig - p:, :, :L]
    if final:
        return x, y, xq.T.copy()
    return x, y


class _BlockOperators:
    """Matrices of the block phases (see the module docstring)."""

    __slots__ = ('operator', 'last', 'Phi_b')

    def __init__(self, operator, last, Phi_b):
        # operator (phase, signal, K, k): coefficients of [u windows, x[s]] in
        # x[s+k] (when states are kept) and y[s+k]; last (phase, input, j, state):
        # coefficients of the window in x[s+b]; Phi_b (phase) = Φ(b, 0)
        self.operator, self.last, self.Phi_b = operator, last, Phi_b


def _block_operators(Phi, E, F, C, D, b, states=True):
    """Operators of all N/b block phases at once (loops over k only)."""
    N, n, m = E.shape
    nb = N // b
    Phi, E, C, D = (a.reshape((nb, b) + a.shape[1:]) for a in (Phi, E, C, D))
    F = None if F is None else F.reshape((nb, b) + F.shape[1:])
    # O[:, k] = Φ(k, 0), k = 0..b
    O = np.empty((nb, b + 1, n, n))
    O[:, 0] = np.eye(n)
    # V[:, k, j]: coefficient of u[s+j] in x[s+k], from
    # x[s+k+1] = Φ_k x[s+k] + E_k u[s+k] + F_k u[s+k+1]
    V = np.zeros((nb, b + 1, b + 1, n, m))
    for k in range(b):
        O[:, k + 1] = Phi[:, k] @ O[:, k]
        V[:, k + 1, :k + 1] = Phi[:, k, None] @ V[:, k, :k + 1]
        V[:, k + 1, k] += E[:, k]
        if F is not None:
            V[:, k + 1, k + 1] += F[:, k]
    # y[s+k] = C_k x[s+k] + D_k u[s+k]
    Vy = np.einsum('ckps,ckjsi->ckjpi', C, V[:, :b])
    Vy[:, np.arange(b), np.arange(b)] += D
    Oy = np.einsum('ckps,cksq->ckpq', C, O[:, :b])
    if states:
        Vxy = np.concatenate([V[:, :b], Vy], axis=3)          # (c, k, j, signal, i)
        Oxy = np.concatenate([O[:, :b], Oy], axis=2)          # (c, k, signal, q)
    else:
        Vxy, Oxy = Vy, Oy
    nsig = Vxy.shape[3]
    window = Vxy.transpose(0, 3, 4, 2, 1).reshape(nb, nsig, m * (b + 1), b)
    start = Oxy.transpose(0, 2, 3, 1)
    operator = np.ascontiguousarray(np.concatenate([window, start], axis=2))
    last = np.ascontiguousarray(V[:, b].transpose(0, 3, 1, 2))      # (c, i, j, n)
    return _BlockOperators(operator, last, O[:, b])
