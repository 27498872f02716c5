"""Exact simulation on any grid by a march over the cells of a phase table.

A phase table (``_core/gridmarch.py``) cuts one period into N cells
``[e_j, e_{j+1}]`` placed so that every cell holds at most one sample of
the grid, and tabulates for every cell the data (``Φ, W, Z``, module notes
of ``gridmarch``) of the whole cell and of its first and last parts
``[e_j, e_j + ℓ]``, ``[e_{j+1} - ℓ, e_{j+1}]`` at D + 1 lengths
(interpolated in ℓ).

Instead of assembling the transition data of every step (products of
augmented matrices per sample), the state is marched over the cells of
the record, a uniform grid whose data repeat every N cells:

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

The data of a part are polynomials in its length ℓ (degree D, from the
table's D + 1 lengths): as Chebyshev coefficients in ξ = ℓ / h_c, a
sample's data are ``Σ_k T_k(2ξ - 1) data_k`` (the last part's, at
``1 - ξ``, take the signs ``(-1)^k``).

Layout: the cells of the record are an N × P grid (phase × period), every
signal stored as (phase, rows, periods × traces).  Every (cell, period)
gets the Chebyshev polynomials of its sample (zero without one), so that
the samples' data, the kinks' forcing and the states at the samples are
batched products over the N phases, with all periods and traces at once;
the samples are gathered from and into that grid by rows.  The march over
the cells is blocked over the period (`PhaseMarch`).  No step's transition
matrix is formed; the work is O(N P R n² + N n³) per march, and the
record is taken in chunks of periods within a fixed budget.
"""

import math

import numpy as np

__all__ = []

_CHUNK_ENTRIES = 2 ** 21       # entries of a chunk's per-cell arrays


def cell_march(table, C, D, t, u, x0, hold, states=True):
    """States and outputs on the grid `t` through the cells of `table`.

    Parameters
    ----------
    table : CellTable
        Phase table whose cells hold at most one sample of `t` each.
    C, D : PeriodicMatrix
    t : ndarray, shape (L,)
    u : ndarray, shape (m, R, L)
    x0 : ndarray, shape (n, R)
    hold : {'foh', 'zoh'}
    states : bool

    Returns
    -------
    (x, y) : x ndarray (n, R, L) or None, y ndarray (p, R, L); None when
        two samples fall in one cell of `table`.

    Examples
    --------
    A first-order lag on a non-uniform grid (constant input: ``1 - e^{-t}``):

    >>> from ltpcontrol._core.cellmarch import cell_march
    >>> from ltpcontrol._core.gridmarch import _cell_table
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> t = np.cumsum(np.r_[0.0, np.random.default_rng(0).uniform(0.2, 0.3, 40)])
    >>> table = _cell_table(sys.A, sys.B, np.diff(t), 1.0, 1e-12, t)
    >>> x, y = cell_march(table, sys.C, sys.D, t, np.ones((1, 1, 41)), np.zeros((1, 1)),
    ...                   'foh')
    >>> bool(np.allclose(y[0, 0], 1 - np.exp(-t), rtol=0, atol=1e-13))
    True
    """
    edges, T, lens = table.edges, table.edges[-1], table.lens
    N = len(lens)
    n, R = x0.shape
    m, L = u.shape[0], len(t)
    D1 = len(table.frac)
    # cell of every sample (phases counted from the table's offset), numbered
    # g = P N + j from the start of the period of t[0]
    shifted = t - table.offset
    base = np.floor(shifted[0] / T)
    wraps = np.floor(shifted / T)
    theta = shifted - wraps * T
    j = _cell_of(edges, theta)
    g = (wraps - base).astype(np.int64) * N + j
    ell = np.clip(theta - edges[j], 0.0, lens[j])                 # first part
    if np.any(np.diff(g) == 0):
        return None                     # two samples in one cell: not this table
    # slopes of the held input on [t_k, t_{k+1}) (zero after the last sample)
    sigma = np.zeros((m, R, L))
    if hold == 'foh':
        sigma[:, :, :-1] = np.diff(u, axis=2) / np.diff(t)
    g0, P = int(g[0]), int(g[-1]) // N + 1
    # the last sample before every cell of the record (a sample at a cell's
    # start is counted in the cell: its jump below makes up the difference)
    last = np.concatenate([[0], np.cumsum(np.bincount(g, minlength=P * N))[:-1]]) - 1
    # the table's data: whole cells' (W, Z); the kink's part, the jump
    # (zero-order hold) or the change of slope (first-order hold: the input is
    # continuous) through the last part [t_k, e_{c+1}]: W or Z of the last
    # parts, whose lengths' weights are those of the first part, reversed (the
    # lengths are symmetric about half a cell); the first parts' [Φ | W | Z];
    # the last two as Chebyshev coefficients in the first part's ξ = ℓ / h_c
    WZ = np.concatenate([table.fwd[1][:, -1], table.fwd[2][:, -1]], axis=2)
    kpart = table.bwd[2] if hold == 'foh' else table.bwd[1]                # (N, D1, n, m)
    # the coefficients of every sample's data: the kink's part, and the first
    # part's [Φ | W | Z] when that is fewer numbers (n + 2m <= D1) than its
    # products with (x, a, σ) at the D1 orders, which are formed otherwise
    firstC = table.coefficients(np.concatenate(table.fwd, axis=3))          # (N, D1, n, n+2m)
    E1 = n * (n + 2 * m) if n + 2 * m <= D1 else 0
    tab = np.concatenate([firstC.reshape(N, D1, -1)[:, :, :E1],
                          table.coefficients(kpart, reverse=True).reshape(N, D1, n * m)],
                         axis=2)
    tabT = np.ascontiguousarray(tab.transpose(0, 2, 1))                     # (N, E, D1)
    firstC = firstC.reshape(N, D1 * n, n + 2 * m)
    march = PhaseMarch(table.fwd[0][:, -1])
    # the first sample: its cell's last part carries x0 to the next cell,
    # entered as the forcing of cell g0 (all earlier cells force nothing)
    Pb, Wb, Zb = table.last(j[:1], lens[j[:1]] - ell[:1])
    x1 = Pb[0] @ x0 + Wb[0] @ u[:, :, 0] + Zb[0] @ sigma[:, :, 0]
    x = np.empty((n, R, L))
    x[:, :, 0] = x0
    start = np.zeros((n, R))
    per = max(1, _CHUNK_ENTRIES // (N * max(tab.shape[2], R * (n + 2 * m), R * D1 * n)))
    for p0 in range(0, P, per):
        # the periods [p0, p1): their cells c0 .. c1 - 1 and samples k0 .. k1 - 1;
        # every signal by phase: (N, rows, Pc R)
        p1 = min(P, p0 + per)
        Pc, c0, c1 = p1 - p0, p0 * N, p1 * N
        k0, k1 = np.searchsorted(g, [c0, c1])
        k0 = max(k0, 1)
        cells = np.arange(c0, c1)
        tau = (base + cells // N) * T + table.offset + edges[cells % N]
        kc = np.maximum(last[c0:c1], 0)
        a = u[:, :, kc] + sigma[:, :, kc] * (tau - t[kc])                  # (m, R, cells)
        sig = sigma[:, :, kc]
        if c0 <= g0:
            a[:, :, :g0 + 1 - c0], sig[:, :, :g0 + 1 - c0] = 0.0, 0.0
        ab = _by_phase(np.concatenate([a, sig]), N, Pc)                 # (N, 2m, Pc R)
        f = np.matmul(WZ, ab)                                           # (N, n, Pc R)
        # every (cell, period)'s data Σ_k T_k(ξ) tab_k, by phase: one product
        # per cell over the periods (zero where the cell holds no sample);
        # row j Pc + period
        ks = np.arange(k0, k1)
        gs = g[ks] - c0
        row = j[ks] * Pc + gs // N
        # rows are gathered, not scattered: every (cell, period) names its
        # sample, or an appended zero row
        which = np.full(N * Pc, len(ks))
        which[row] = np.arange(len(ks))
        Tk = np.concatenate([table.basis(ell[ks], j[ks]).T, np.zeros((1, D1))])
        Tk = np.take(Tk, which, axis=0)
        data = np.matmul(tabT, Tk.reshape(N, Pc, D1).transpose(0, 2, 1))   # (N, E, Pc)
        if m and len(ks):
            kink = sigma[:, :, ks] - sig[:, :, gs] if hold == 'foh' \
                else u[:, :, ks] - a[:, :, gs]                               # (m, R, s)
            Kp = np.concatenate([kink.transpose(2, 0, 1), np.zeros((1, m, R))])
            Kp = np.take(Kp, which, axis=0).reshape(N, Pc, m, R)
            fk = np.empty((N, n, Pc, R))
            for i in range(n):
                fk[:, i] = data[:, E1 + i * m, :, None] * Kp[:, :, 0]
                for q in range(1, m):
                    fk[:, i] += data[:, E1 + i * m + q, :, None] * Kp[:, :, q]
            f += fk.reshape(N, n, Pc * R)
        if c0 <= g0:
            f[g0 - c0, :, :R] = x1
        X, start = march(f, R, start)                                   # (N, n, Pc R)
        if not len(ks):
            continue
        # states at the samples from the first part [e_c, t_k] of their cell,
        # applied to (x(e_c), a_c, σ_c)
        z = np.concatenate([X, ab], axis=1)                             # (N, n+2m, Pc R)
        xp = np.empty((N, Pc, n, R))
        if E1:
            z = z.reshape(N, n + 2 * m, Pc, R)
            for i in range(n):
                e0 = i * (n + 2 * m)
                xp[:, :, i] = data[:, e0, :, None] * z[:, 0]
                for e in range(1, n + 2 * m):
                    xp[:, :, i] += data[:, e0 + e, :, None] * z[:, e]
        else:
            V = np.matmul(firstC, z).reshape(N, D1, n, Pc, R)
            Tp = Tk.reshape(N, Pc, D1)
            out = Tp[:, None, :, 0, None] * V[:, 0]
            for d in range(1, D1):
                out += Tp[:, None, :, d, None] * V[:, d]                  # (N, n, Pc, R)
            xp[...] = out.transpose(0, 2, 1, 3)
        x[:, :, k0:k1] = np.take(xp.reshape(N * Pc, n, R), row, axis=0).transpose(1, 2, 0)
    return (x if states else None), outputs(C, D, t, x, u)


def outputs(C, D, t, x, u):
    """``y = C(t) x + D(t) u`` at the samples: x (n, R, L), u (m, R, L) -> (p, R, L).

    Examples
    --------
    >>> from ltpcontrol._core.cellmarch import outputs
    >>> C = ltp.PeriodicMatrix.constant([[2.0]], 1.0)
    >>> D = ltp.PeriodicMatrix([[[0.5]], [[1.0]], [[0.5]]], 1.0)      # 1 + cos ωt
    >>> outputs(C, D, np.array([0.0, 0.5]), np.ones((1, 1, 2)), np.ones((1, 1, 2)))[0, 0]
    array([4., 2.])
    """
    (n, R, L), m, p = x.shape, u.shape[0], C.shape[0]
    y = np.empty((p, R, L))
    chunk = max(256, _CHUNK_ENTRIES // max(1, p * (n + m)))
    for s0 in range(0, L, chunk):
        i = slice(s0, s0 + chunk)
        for M, v, first in ((C, x, True), (D, u, False)):
            if M.is_constant:
                out = np.tensordot(M(t[0]), v[:, :, i], axes=1)
            else:
                out = _apply(M(t[i]), v[:, :, i])
            if first:
                y[:, :, i] = out
            else:
                y[:, :, i] += out
    return y


def _by_phase(z, N, P):
    """Signal (rows, R, P N) of the cells in time order as (N, rows, P R)."""
    rows, R, _ = z.shape
    return np.ascontiguousarray(z.reshape(rows, R, P, N).transpose(3, 0, 2, 1)) \
        .reshape(N, rows, P * R)


def _apply(M, v):
    """``M[s] @ v[:, :, s]`` for every s: M (S, a, b), v (b, R, S) -> (a, R, S)."""
    return (M @ v.transpose(2, 0, 1)).transpose(1, 2, 0)


class PhaseMarch:
    """States of ``x_{c+1} = Φ_{c mod N} x_c + f_c`` over whole periods, P at a time.

    The period is cut into B blocks of b phases (b a divisor of N near √N);
    the block-local products ``Φ(c, c_0)``, the products from the period
    start to every block start and the period's product Ψ are formed once.
    A call takes the forcing `f` (N, n, P R) of phase c of period p, trace
    r at ``[c, :, p R + r]``: a loop over the b positions marches every
    block of every period from a zero start at once, a loop over the B
    blocks gives the block starts from a zero period start, and the period
    starts follow ``s_{p+1} = Ψ s_p + z_p``.  It returns the states at the
    start of every cell (same layout) and the state after the last period
    (`start` and the result (n, R); default start 0).

    Examples
    --------
    >>> from ltpcontrol._core.cellmarch import PhaseMarch
    >>> march = PhaseMarch(np.array([[[0.5]], [[2.0]]]))
    >>> X, end = march(np.ones((2, 1, 3)), 1)                 # three periods, one trace
    >>> X[:, 0]                                                 # cells 0, 1 of each period
    array([[0. , 3. , 6. ],
           [1. , 2.5, 4. ]])
    >>> end
    array([[9.]])
    """

    def __init__(self, Phi):
        N, n, _ = Phi.shape
        small = [d for d in range(1, math.isqrt(N) + 1) if N % d == 0]
        b = min(small + [N // d for d in small], key=lambda d: abs(np.log(d / np.sqrt(N))))
        B = N // b
        self.Pb = Phi.reshape(B, b, n, n)
        # block-local products Φ(c, c_0)
        self.O = np.empty((B, b + 1, n, n))
        self.O[:, 0] = np.eye(n)
        for i in range(b):
            np.matmul(self.Pb[:, i], self.O[:, i], out=self.O[:, i + 1])
        # products from the period start to every block start, and Ψ
        self.M = np.empty((B + 1, n, n))
        self.M[0] = np.eye(n)
        for i in range(B):
            self.M[i + 1] = self.O[i, b] @ self.M[i]

    def __call__(self, f, R, start=None):
        B, b, n, _ = self.Pb.shape
        O, M, Pb, Psi = self.O, self.M, self.Pb, self.M[-1]
        N, _, K = f.shape
        P = K // R
        X = np.empty_like(f)
        per = max(1, _CHUNK_ENTRIES // max(1, 2 * N * n * R))
        s = np.zeros((n, R)) if start is None else start
        for p0 in range(0, P, per):
            cols = slice(p0 * R, min(P, p0 + per) * R)
            k = cols.stop - cols.start
            fb = f[:, :, cols].reshape(B, b, n, k)
            # forced parts of every block from a zero block start
            Z = np.empty((B, b + 1, n, k))
            Z[:, 0] = 0.0
            for i in range(b):
                np.matmul(Pb[:, i], Z[:, i], out=Z[:, i + 1])
                Z[:, i + 1] += fb[:, i]
            # block starts from a zero period start
            Y = np.empty((B + 1, n, k))
            Y[0] = 0.0
            for i in range(B):
                Y[i + 1] = O[i, b] @ Y[i] + Z[i, b]
            zend = Y[B].reshape(n, -1, R)
            starts = np.empty((n, zend.shape[1], R))
            for i in range(zend.shape[1]):
                starts[:, i] = s
                s = Psi @ s + zend[:, i]
            Sb = M[:B] @ starts.reshape(n, k) + Y[:B]                  # (B, n, k)
            X[:, :, cols] = (O[:, :b] @ Sb[:, None] + Z[:, :b]).reshape(N, n, k)
        return X, s


def _cell_of(edges, theta):
    """Index j of the cell ``[e_j, e_{j+1})`` holding each phase (uniform guess, corrected)."""
    N = len(edges) - 1
    j = np.clip((theta * (N / edges[-1])).astype(np.int64), 0, N - 1)
    wrong = (theta < edges[j]) | (theta >= edges[j + 1])
    if np.any(wrong):
        j[wrong] = np.clip(np.searchsorted(edges, theta[wrong], side='right') - 1, 0, N - 1)
    return j
