"""Exact simulation on any grid by a march over the cells of a phase table.

A phase table (``_core/gridmarch.py``) cuts one period into N cells
``[e_j, e_{j+1}]`` shorter than the shortest step of the grid, so that a
cell holds at most one sample, and tabulates for every cell the data
(``Φ, W, Z``, module notes of ``gridmarch``) of the whole cell and of its
first and last parts ``[e_j, e_j + ℓ]``, ``[e_{j+1} - ℓ, e_{j+1}]`` at
D + 1 lengths (interpolated in ℓ).

Instead of assembling the transition data of every step (products of
augmented matrices per sample), the state is marched over the cells of
the record, a uniform grid whose data repeat every N cells (the periodic
march of ``_core/march.py``, BLAS-3 over the periods):

    x(e_{c+1}) = Φ_c x(e_c) + f_c.

The input is held (zero order) or linear (first order) between samples,
``u(s) = u_k + σ_k (s - t_k)`` on ``[t_k, t_{k+1})`` (σ_k = 0 or the
slope), so on a cell without a sample it is ``a_c + σ (s - e_c)`` with
``a_c = u(e_c)``, and

    f_c = W_c a_c + Z_c σ.

A sample ``t_k`` inside the cell adds a jump J (zero-order hold) and a
change of slope Δσ from ``t_k`` on: ``W_b J + Z_b Δσ`` with the data of
the last part ``[t_k, e_{c+1}]``.  The state at the sample comes from the
first part ``[e_c, t_k]``:

    x(t_k) = Φ_f x(e_c) + W_f a_c + Z_f σ_{k-1}.

Both are linear in the data at the table's D + 1 lengths, so the
products are taken with those data for every cell of the record, laid out
by phase (one batched product over the N phases, no gathered copies of
the table), and only the results (n numbers per length) are interpolated
in ℓ at the samples.  No step's transition matrix is formed; memory is
linear in the record (the cell states) and bounded per chunk of periods.
"""

import numpy as np

from .celldata import barycentric_matrix, lobatto


__all__ = []

_CHUNK_ENTRIES = 2 ** 21       # entries of the interpolated data of a chunk of samples
_BLOCK = 64                    # longest block of the forced march (about)


def cell_march(table, C, D, t, u, x0, hold, states=True):
    """States and outputs on the grid `t` through the cells of `table`.

    Parameters
    ----------
    table : CellTable
        Phase table whose cells are shorter than the shortest step of `t`.
    C, D : PeriodicMatrix
    t : ndarray, shape (L,)
    u : ndarray, shape (m, R, L)
    x0 : ndarray, shape (n, R)
    hold : {'foh', 'zoh'}
    states : bool

    Returns
    -------
    x : ndarray, shape (n, R, L), or None
    y : ndarray, shape (p, R, L)

    Examples
    --------
    A first-order lag on a non-uniform grid (constant input: ``1 - e^{-t}``):

    >>> from ltpcontrol._core.cellmarch import cell_march
    >>> from ltpcontrol._core.gridmarch import _cell_table
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> t = np.cumsum(np.r_[0.0, np.random.default_rng(0).uniform(0.2, 0.3, 40)])
    >>> table = _cell_table(sys.A, sys.B, np.diff(t), 1.0, 1e-12)
    >>> x, y = cell_march(table, sys.C, sys.D, t, np.ones((1, 1, 41)), np.zeros((1, 1)),
    ...                   'foh')
    >>> bool(np.allclose(y[0, 0], 1 - np.exp(-t), rtol=0, atol=1e-13))
    True
    """
    edges, T = table.edges, table.edges[-1]
    N = len(table.lens)
    n, R = x0.shape
    m, L = u.shape[0], len(t)
    p = C.shape[0]
    # cell of every sample, counted from the start of the period of t[0]
    base = np.floor(t[0] / T)
    wraps = np.floor(t / T)
    theta = t - wraps * T
    j = _cell_of(edges, theta)
    g = (wraps - base).astype(np.int64) * N + j
    ell = np.clip(theta - edges[j], 0.0, table.lens[j])           # first part
    # slopes of the held input on [t_k, t_{k+1}) (zero after the last sample)
    sigma = np.zeros((m, R, L))
    if hold == 'foh':
        sigma[:, :, :-1] = np.diff(u, axis=2) / np.diff(t)
    # cell edges e(c) for c = g0 + 1 .. gL (the states marched), their times,
    # the interval [t_k, t_{k+1}) holding each and the input there
    g0, gL = int(g[0]), int(g[-1])
    cells = np.arange(g0 + 1, gL + 1)
    tau = (base + cells // N) * T + edges[cells % N]
    k = np.clip(np.searchsorted(t, tau, side='right') - 1, 0, L - 1)
    a = u[:, :, k] + sigma[:, :, k] * (tau - t[k])                 # (m, R, cells)
    sig = sigma[:, :, k]
    # the cells of the record laid out by phase: cell c (0-based from g0 + 1)
    # has phase (c + o) mod N, and every per-cell product is one batched
    # product over the N phases (no gathered copies of the table)
    o = (g0 + 1) % N
    D1 = len(table.frac)
    # forcing of the cells c = g0 + 1 .. gL - 1 (the last entry is not used):
    # the whole cell's W a + Z σ, plus for a sample inside the cell the jump
    # and the change of slope through the last part [t_k, e_{c+1}], whose data
    # are Σ_i w_i(ℓ) (W_i, Z_i) at the table's lengths
    q = np.zeros((2 * m * (D1 + 1), R, len(cells)))
    q[:2 * m] = np.concatenate([a, sig])
    inner = np.flatnonzero((g > g0) & (g < gL))
    if len(inner):
        c = g[inner] - g0 - 1
        w = _weights(table, j[inner], table.lens[j[inner]] - ell[inner])     # (S, D1)
        sc = sig[:, :, c]
        jump = np.concatenate([u[:, :, inner] - (a[:, :, c] + sc * (t[inner] - tau[c])),
                               sigma[:, :, inner] - sc])                         # (2m, R, S)
        q[2 * m:, :, c] = (w.T[:, None, None, :] * jump[None]).reshape(-1, R, len(c))
    WZb = np.concatenate([table.bwd[1], table.bwd[2]], axis=3)              # (N, D1, n, 2m)
    Fq = np.concatenate([np.concatenate([table.fwd[1][:, -1], table.fwd[2][:, -1]], axis=2),
                         WZb.transpose(0, 2, 1, 3).reshape(N, n, D1 * 2 * m)], axis=2)
    f = _by_phase(Fq, q, o)
    # the first sample: its cell's last part carries x0 to e(g0 + 1)
    Pb, Wb, Zb = table.last(j[:1], table.lens[j[:1]] - ell[:1])
    x1 = Pb[0] @ x0 + Wb[0] @ u[:, :, 0] + Zb[0] @ sigma[:, :, 0]
    # the march over the cells, phase (g0 + 1) mod N first
    Phi = np.roll(table.fwd[0][:, -1], -o, axis=0)
    xe = forced_march(Phi, f, x1)
    # states at the samples from the first part [e_c, t_k] of their cell:
    # the data at the table's lengths applied to (x(e_c), a_c, σ) for every
    # cell, by phase, then interpolated in ℓ at the samples' cells
    x = np.empty((n, R, L))
    x[:, :, 0] = x0
    if L > 1:
        rest = np.arange(1, L)
        c = g[rest] - g0 - 1
        Ff = np.concatenate(table.fwd, axis=3).reshape(N, D1 * n, n + 2 * m)
        V = _by_phase(Ff, np.concatenate([xe, a, sig]), o, pick=c)           # (D1 n, R, S)
        w = _weights(table, j[rest], ell[rest])
        x[:, :, 1:] = np.einsum('sd,dnrs->nrs', w, V.reshape(D1, n, R, len(c)))
    y = np.empty((p, R, L))
    chunk = max(256, _CHUNK_ENTRIES // max(1, p * (n + m)))
    for s0 in range(0, L, chunk):
        i = slice(s0, s0 + chunk)
        y[:, :, i] = _apply(C(t[i]), x[:, :, i]) + _apply(D(t[i]), u[:, :, i])
    return (x if states else None), y


def _weights(table, j, length):
    """Barycentric weights (S, D + 1) of the lengths `length` of cells `j` at the table's nodes."""
    _, wts = lobatto(len(table.frac) - 1)
    return barycentric_matrix(np.clip(length / table.lens[j], 0.0, 1.0), table.frac, wts)


def _by_phase(F, z, o, pick=None):
    """``F[(c + o) % N] @ z[:, :, c]`` for every c, as (a, R, J) (or its columns `pick`).

    F (N, a, b), z (b, R, J): the columns are laid out as periods of N
    phases, so that the products are one batched product over the phases;
    periods are taken in chunks within a fixed budget.
    """
    N, A_, b = F.shape
    _, R, J = z.shape
    P = -(-(J + o) // N)
    per = max(1, _CHUNK_ENTRIES // max(1, N * (A_ + b) * R))
    out = np.empty((A_, R, J if pick is None else len(pick)))
    for p0 in range(0, P, per):
        p1 = min(P, p0 + per)
        lo, hi = max(0, p0 * N - o), min(J, p1 * N - o)
        zp = np.zeros((b, R, (p1 - p0) * N))
        zp[:, :, lo + o - p0 * N:hi + o - p0 * N] = z[:, :, lo:hi]
        zt = np.ascontiguousarray(zp.reshape(b, R, p1 - p0, N).transpose(3, 0, 2, 1))
        res = np.matmul(F, zt.reshape(N, b, (p1 - p0) * R)).reshape(N, A_, p1 - p0, R)
        if pick is None:
            res = res.transpose(1, 3, 2, 0).reshape(A_, R, (p1 - p0) * N)
            out[:, :, lo:hi] = res[:, :, lo + o - p0 * N:hi + o - p0 * N]
        else:
            sel = np.flatnonzero((pick >= lo) & (pick < hi))
            at = pick[sel] + o - p0 * N
            out[:, :, sel] = res[at % N, :, at // N].transpose(1, 2, 0)
    return out


def _apply(M, v):
    """``M[s] @ v[:, :, s]`` for every s: M (S, a, b), v (b, R, S) -> (a, R, S)."""
    return (M @ v.transpose(2, 0, 1)).transpose(1, 2, 0)


def forced_march(Phi, f, x0):
    """States of ``x[c+1] = Φ_{c mod N} x[c] + f[c]``, ``x[0] = x0``, for c < J.

    Blocks of b cells (b a divisor of N near √J, at most about 64): the
    transitions ``Φ(k, 0)`` of the N/b block phases are formed once; inside every block the forced part from a zero start is
    unrolled for all blocks at once (a loop over the b positions), and the
    block starts follow the same recurrence over the blocks (period N/b),
    marched the same way when there are many.  Work O(J n² R + N n³).

    Parameters
    ----------
    Phi : ndarray, shape (N, n, n)
    f : ndarray, shape (n, R, J)
    x0 : ndarray, shape (n, R)

    Returns
    -------
    x : ndarray, shape (n, R, J)

    Examples
    --------
    >>> from ltpcontrol._core.cellmarch import forced_march
    >>> Phi = np.array([[[0.5]], [[2.0]]])
    >>> forced_march(Phi, np.ones((1, 1, 5)), np.ones((1, 1)))[0, 0]
    array([1. , 1.5, 4. , 3. , 7. ])
    """
    N, n, _ = Phi.shape
    R, J = f.shape[1], f.shape[2]
    # b near √J balances the two loops (over the b positions, over the blocks)
    target = min(max(np.sqrt(J), 8.0), _BLOCK)
    divisors = [b for b in range(1, min(N, 2 * _BLOCK) + 1) if N % b == 0]
    b = min(divisors, key=lambda v: (abs(np.log(v / target)), -v))
    nph = N // b
    nb = -(-J // b)
    # phase of every block, and the inputs laid out by block: (nb, b, n, R)
    bph = np.arange(nb) % nph
    fb = np.zeros((nb * b, n, R))
    fb[:J] = f.transpose(2, 0, 1)
    fb = fb.reshape(nb, b, n, R)
    Pb = Phi.reshape(nph, b, n, n)
    # block-local transitions Φ(k, 0) per block phase and forced parts
    O = np.empty((nph, b + 1, n, n))
    O[:, 0] = np.eye(n)
    sig = np.empty((nb, b + 1, n, R))
    sig[:, 0] = 0.0
    for k in range(b):
        O[:, k + 1] = Pb[:, k] @ O[:, k]
        sig[:, k + 1] = Pb[bph, k] @ sig[:, k] + fb[:, k]
    # block starts: the same recurrence over the blocks (period N/b), by the
    # same method when there are many blocks
    if nb > _BLOCK and nph > 1:
        starts = forced_march(O[:, b], sig[:, b].transpose(1, 2, 0), x0).transpose(2, 0, 1)
    else:
        starts = np.empty((nb, n, R))
        xs = x0
        for i in range(nb):
            starts[i] = xs
            xs = O[bph[i], b] @ xs + sig[i, b]
    x = O[bph, :b] @ starts[:, None] + sig[:, :b]                 # (nb, b, n, R)
    return x.reshape(nb * b, n, R)[:J].transpose(1, 2, 0)


def _cell_of(edges, theta):
    """Index j of the cell ``[e_j, e_{j+1})`` holding each phase (uniform guess, corrected)."""
    N = len(edges) - 1
    j = np.clip((theta * (N / edges[-1])).astype(np.int64), 0, N - 1)
    wrong = (theta < edges[j]) | (theta >= edges[j + 1])
    if np.any(wrong):
        j[wrong] = np.clip(np.searchsorted(edges, theta[wrong], side='right') - 1, 0, N - 1)
    return j
