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


def periodic_march(Phi, E, F, C, D, u, x0):
    """States and outputs of the N-periodic recurrence (module docstring).

    Parameters
    ----------
    Phi : ndarray, shape (N, n, n)
    E : ndarray, shape (N, n, m)
    F : ndarray, shape (N, n, m) or None
        Coefficient of ``u[k+1]`` (None: zero).
    C : ndarray, shape (N, p, n)
    D : ndarray, shape (N, p, m)
    u : ndarray, shape (m, R, L)
        Inputs of R traces at L samples; sample 0 has phase 0.
    x0 : ndarray, shape (n, R)

    Returns
    -------
    x : ndarray, shape (n, R, L)
    y : ndarray, shape (p, R, L)

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
    R, L = u.shape[1], u.shape[2]
    b = block_length(N, L)
    if b > N:                                   # a block of b/N whole periods
        reps = b // N
        Phi, E, C, D = (np.tile(a, (reps, 1, 1)) for a in (Phi, E, C, D))
        F = None if F is None else np.tile(F, (reps, 1, 1))
        N = b
    ops = [_block_operators(Phi, E, F, C, D, c * b, b) for c in range(N // b)]
    P = max(1, -(-(L - 1) // N))                # periods covering the record
    rows = R * (P + 1)                          # (trace, period) pairs, one spare period

    # input laid out as rows of one period, padded with the last sample; the
    # window of b + 1 samples of block c in row r starts at r N + c b
    buf = np.empty((m, rows * N + N))
    padded = buf[:, :rows * N].reshape(m, R, (P + 1) * N)
    padded[:, :, :L] = u
    padded[:, :, L:] = u[:, :, -1:]
    buf[:, rows * N:] = 0.0

    def windows(c, r0, r1):
        return as_strided(buf[:, r0 * N + c * b:], shape=(m, r1 - r0, b + 1),
                          strides=(buf.strides[0], N * buf.strides[1], buf.strides[1]),
                          writeable=False)

    # forcing over each block from a zero start, z_c = Σ_j V_bj u[s+j]: (rows, n)
    z = []
    for c, op in enumerate(ops):
        w = windows(c, 0, rows)
        z.append(sum(w[i] @ op.last[i] for i in range(m)))
    # 1. period starts: x[(q+1)N] = Ψ x[qN] + z_q (row vectors: x Ψᵀ)
    zper = np.zeros((rows, n))
    for c, op in enumerate(ops):
        zper = zper @ op.Phi_b.T + z[c]
    zper = zper.reshape(R, P + 1, n)
    Psi = np.eye(n)
    for op in ops:
        Psi = op.Phi_b @ Psi
    starts = np.empty((R, P + 1, n))
    xq = x0.T
    for q in range(P + 1):
        starts[:, q] = xq
        xq = xq @ Psi.T + zper[:, q]
    # 2.-3. block starts and all samples of each phase, in row chunks: the rows
    # [u window of every input, x[s]] times the phase operator, written in place
    out = np.empty((n + p, rows, N))
    xb = starts.reshape(rows, n)
    K = m * (b + 1) + n
    step = max(1, _CHUNK_BYTES // (8 * K))
    for c, op in enumerate(ops):
        for r0 in range(0, rows, step):
            r1 = min(rows, r0 + step)
            lhs = np.empty((r1 - r0, K))
            w = windows(c, r0, r1)
            for i in range(m):
                lhs[:, i * (b + 1):(i + 1) * (b + 1)] = w[i]
            lhs[:, m * (b + 1):] = xb[r0:r1]
            np.matmul(lhs[None], op.operator, out=out[:, r0:r1, c * b:(c + 1) * b])
        xb = xb @ op.Phi_b.T + z[c]
    out = out.reshape(n + p, R, (P + 1) * N)
    return out[:n, :, :L], out[n:, :, :L]


class _BlockOperators:
    """Matrices of one block phase (see the module docstring)."""

    __slots__ = ('operator', 'last', 'Phi_b')

    def __init__(self, operator, last, Phi_b):
        # operator (signal, K, k): coefficients of [u windows, x[s]] in x[s+k], y[s+k]
        # last (input, j, state): coefficients of the window in x[s+b]; Phi_b = Φ(b, 0)
        self.operator, self.last, self.Phi_b = operator, last, Phi_b


def _block_operators(Phi, E, F, C, D, s, b):
    n, m = E.shape[1], E.shape[2]
    p = C.shape[1]
    ks = s + np.arange(b)
    # O[k] = Φ(k, 0), k = 0..b
    O = np.empty((b + 1, n, n))
    O[0] = np.eye(n)
    for k in range(b):
        O[k + 1] = Phi[ks[k]] @ O[k]
    # V[k, j]: coefficient of u[s+j] in x[s+k]
    V = np.zeros((b + 1, b + 1, n, m))
    for j in range(b):
        M = np.eye(n)                               # Φ(k, j+1), built up over k
        for k in range(j + 1, b + 1):
            if k > j + 1:
                M = Phi[ks[k - 1]] @ M
            V[k, j] += M @ E[ks[j]]
            if F is not None:
                V[k, j + 1] += M @ F[ks[j]]
    Ck, Dk = C[ks], D[ks]
    Vy = np.einsum('kps,kjsi->kjpi', Ck, V[:b])     # y[s+k] = C_k x[s+k] + D_k u[s+k]
    Vy[np.arange(b), np.arange(b)] += Dk
    Vxy = np.concatenate([V[:b], Vy], axis=2)      # (k, j, signal, i)
    Oxy = np.concatenate([O[:b], np.einsum('kps,ksq->kpq', Ck, O[:b])], axis=1)  # (k, signal, q)
    window = Vxy.transpose(2, 3, 1, 0).reshape(n + p, m * (b + 1), b)
    start = Oxy.transpose(1, 2, 0)
    operator = np.ascontiguousarray(np.concatenate([window, start], axis=1))
    last = np.ascontiguousarray(V[b].transpose(2, 0, 1))      # (i, j, n)
    return _BlockOperators(operator, last, O[b])
