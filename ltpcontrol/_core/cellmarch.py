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

Layout: the cells of the record are an N × P grid (phase × period).  The
cells' signals (the held input a, σ, the samples' T_k(2ξ - 1) and kinks;
zero without a sample) are formed in time order and transposed once to
(phase, rows, periods × traces); the products with the cells' data run by
phase over all periods and traces, on blocks of phases that fit a cache;
the states at the samples go back to time order with one transpose and a
gather.  The march over the cells is blocked over the period
(`PhaseMarch`).  No step's transition matrix is formed; the work is
O(N P R n² + N n³) per march, and the record is taken in chunks of periods
within a fixed budget.  Long records of a few states take instead the
compiled loop of `cellkernel` when numba is installed.
"""

import math

import numpy as np

from ..config import _get
from . import cellkernel
from .celldata import _chebyshev_basis

__all__ = []

_CHUNK_ENTRIES = 2 ** 18       # entries of a chunk's arrays (fresh memory pages cost)
_FEW_COLUMNS = 8              # constant output matrices with fewer columns: rows summed
_FEW_HARMONICS = 16           # Fourier output matrices with at most these harmonics: as series
_CELL_ENTRIES = 2 ** 19        # entries of a block of phases of the cell march (cache-sized)


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
    N, n, R, m = len(table.lens), x0.shape[0], x0.shape[1], u.shape[0]
    # the held input's q rows in the cells' forcing: a (and σ, first-order hold)
    q = 2 * m if hold == 'foh' else m
    # the table's data: whole cells' [W Z]; Chebyshev coefficients in the
    # first part's ξ = ℓ / h_c of the kink's part [t_k, e_{c+1}] (W or Z of
    # the last parts, whose lengths' weights are those of the first part,
    # reversed) and of the first part's [Φ W Z], applied to (x(e_c), a, σ)
    # for the state at the sample
    WZ = np.concatenate([table.fwd[1][:, -1], table.fwd[2][:, -1]], axis=2)[:, :, :q]
    kpart = table.bwd[2] if hold == 'foh' else table.bwd[1]                 # (N, D1, n, m)
    D1 = len(table.frac)
    first = np.empty((N, D1, n, n + q))
    for part, cols in enumerate((slice(0, n), slice(n, n + m), slice(n + m, n + q))):
        if cols.stop > cols.start:
            table.coefficients(table.fwd[part], out=first[..., cols])
    kcoef = table.coefficients(kpart, reverse=True)
    # the first sample: its cell's last part carries x0 to the next cell,
    # entered as the forcing of the cell after it (earlier cells force nothing)
    g0, xi0, base = _cells_of_samples(table, t[:1])
    j0 = g0 % N
    Pb, Wb, Zb = table.last(j0, table.lens[j0] * (1 - xi0))
    x1 = Pb[0] @ x0 + Wb[0] @ u[:, :, 0]
    if hold == 'foh':
        x1 += Zb[0] @ (u[:, :, 1] - u[:, :, 0]) / (t[1] - t[0])
    x = np.empty((n, R, len(t)))
    x[:, :, 0] = x0
    # output matrices as real Fourier series (constant: H = 0) are applied in the loop
    series = _real_series(C, D)
    kernel = _kernel(n, m, q, D1, C.shape[0] if series else 0,
                     series[0].shape[1] - 1 if series else 0, len(t))
    if kernel is not None:
        marched = _compiled_march(kernel, table, WZ, first, kcoef, C, D, series, t, u, x1, x,
                                  base)
        if marched is not _UNAVAILABLE:
            return marched if marched is None else ((x if states else None), marched)
    # the NumPy march
    g, xi, base = _cells_of_samples(table, t)
    if np.any(g[1:] == g[:-1]):
        return None                     # two samples in one cell: not this table
    _numpy_march(table, WZ, first, kcoef, t, u, x1, x, g, xi, base, hold)
    return (x if states else None), outputs(C, D, t, x, u)


#: the compiled march could not run (numba failed): the NumPy march takes over
_UNAVAILABLE = object()


def _compiled_march(kernel, table, WZ, first, kcoef, C, D, series, t, u, x1, x, base):
    """States (into `x`) and outputs by the compiled loop (`cellkernel`).

    Returns the outputs, None when two samples share a cell, or
    `_UNAVAILABLE` when the loop could not be compiled.
    """
    (n, R, L), m = x.shape, u.shape[0]
    # equal cells: the loop locates the samples itself; else they are located here
    w = _equal_width(table)
    if w:
        g, xi = np.zeros(1, np.int64), np.zeros(1)
    else:
        g, xi, _ = _cells_of_samples(table, t)
    # output matrices as Fourier series: the outputs in the loop too (but at t[0])
    Cs, Ds = series if series else (np.zeros((2, 1, 0, n)), np.zeros((2, 1, 0, m)))
    y = np.empty((Cs.shape[2], R, L))
    ok = kernel(np.ascontiguousarray(table.fwd[0][:, -1]), np.ascontiguousarray(WZ),
                np.ascontiguousarray(first), np.ascontiguousarray(kcoef), table.edges,
                float(table.edges[-1]), table.offset, float(base), w, g, xi, t,
                np.ascontiguousarray(u), x1, x, Cs, Ds, float(C.omega_p), y)
    if ok is None:
        return _UNAVAILABLE
    if not ok:
        return None                     # two samples in one cell: not this table
    if not series:
        return outputs(C, D, t, x, u)
    y[:, :, 0] = C(t[0]) @ x[:, :, 0] + D(t[0]) @ u[:, :, 0]
    return y


def _numpy_march(table, WZ, first, kcoef, t, u, x1, x, g, xi, base, hold):
    """States at the samples 1 .. L-1 (into `x`) by the NumPy march (module notes)."""
    edges, T = table.edges, table.edges[-1]
    (n, R, L), m = x.shape, u.shape[0]
    N, D1, q = WZ.shape[0], first.shape[1], WZ.shape[2]
    g0, P = int(g[0]), int(g[-1]) // N + 1
    # the first part's data applied to (x, a, σ) as entries when those are
    # fewer numbers (n + q <= D1) than their products with (x, a, σ) at the
    # D1 orders, which are formed otherwise
    E1 = n * (n + q) if n + q <= D1 else 0
    tab = np.concatenate([first.reshape(N, D1, -1)[:, :, :E1], kcoef.reshape(N, D1, n * m)],
                         axis=2)
    tab = np.ascontiguousarray(tab.transpose(0, 2, 1))                      # (N, E, D1)
    first = first.reshape(N, D1 * n, n + q)
    march = PhaseMarch(table.fwd[0][:, -1])
    start = np.zeros((n, R))
    # periods [p0, p1) at a time; inside, phases [j0, j1) at a time (the
    # products per cell run over all the chunk's periods, on cache-sized blocks)
    per = max(1, min(P, _CHUNK_ENTRIES // (N * R * (3 * n + q + m) + N * D1)))
    per = -(-P // -(-P // per))                                 # equal chunks
    nph = max(1, min(N, _CELL_ENTRIES // (per * (R * (3 * n + q + m) + D1 + tab.shape[1]))))
    blocks = [slice(j0, min(N, j0 + nph)) for j0 in range(0, N, nph)]
    for p0 in range(0, P, per):
        # the periods [p0, p1): cells c0 .. c1 - 1, samples in ks.  The cells'
        # signals are formed in time order (Pc, N) and transposed once to the
        # phase order (N, rows, Pc, R) of the products per cell; z = [x | a σ]
        p1 = min(P, p0 + per)
        Pc, c0, c1 = p1 - p0, p0 * N, p1 * N
        k0, k1 = np.searchsorted(g, [c0, c1])
        ks = slice(max(k0, 1), k1)
        cs = g[ks] - c0                                     # the samples' cells
        # the samples s0 = ks.start - 1 .. k1 - 1 (the one before the chunk's
        # cells on): the slopes of the held input on [t_k, t_{k+1}) (zero
        # after the last sample) and the kinks at ks, the jumps (zero-order
        # hold) or the changes of slope (first order: the input is continuous)
        s0 = ks.start - 1
        us, ts = u[:, :, s0:k1], t[s0:k1]
        sigma = np.zeros_like(us)
        if hold == 'foh':
            e = min(k1 + 1, L)
            np.divide(np.diff(u[:, :, s0:e], axis=2), np.diff(t[s0:e]),
                      out=sigma[:, :, :e - s0 - 1])
        kink = np.diff(sigma if hold == 'foh' else us, axis=2)
        # the last sample before every cell, counted from s0 (a sample at a
        # cell's start is counted in the cell: its kink makes up the
        # difference; cells up to sample 0's take no input, below)
        kc = np.empty(Pc * N, np.int64)
        kc[0] = 0
        np.cumsum(np.bincount(cs, minlength=Pc * N)[:-1], out=kc[1:])
        z = np.empty((N, n + q, Pc, R))
        held = us[:, :, kc]
        if hold == 'foh':
            # the held input at the cells' starts τ: a = u_k + σ_k (τ - t_k)
            tau = ((base + p0 + np.arange(Pc)) * T + table.offset)[:, None] + edges[:-1]
            tau = tau.reshape(-1)
            tau -= ts[kc]
            sk = sigma[:, :, kc]
            held += sk * tau
            z[:, n + m:] = sk.reshape(m, R, Pc, N).transpose(3, 0, 2, 1)
        z[:, n:n + m] = held.reshape(m, R, Pc, N).transpose(3, 0, 2, 1)
        if c0 <= g0:
            z[:g0 + 1, n:, 0] = 0.0                 # up to sample 0's cell: no input
        # T_d(2ξ - 1) of every cell (ξ = 0 without a sample) and the kinks
        # (zero without a sample), by phase
        sgrid = np.full(Pc * N, -1.0)
        sgrid[cs] = 2 * xi[ks] - 1
        sgrid = np.ascontiguousarray(sgrid.reshape(Pc, N).T)
        kgrid = np.zeros((m, R, Pc * N))
        kgrid[:, :, cs] = kink
        kgrid = np.ascontiguousarray(kgrid.reshape(m, R, Pc, N).transpose(0, 3, 2, 1))
        f = np.empty((N, n, Pc, R))
        Tk = np.empty((D1, N, Pc))                     # by order: contiguous rows
        Tb = Tk.transpose(1, 0, 2)                      # (N, D1, Pc) for the products
        for ph in blocks:
            # forcing f_c = [W Z] (a, σ) + Σ_d T_d(ξ) K_d kink
            nb = ph.stop - ph.start
            _chebyshev_basis(sgrid[ph], D1, out=Tk[:, ph])
            np.matmul(WZ[ph], z[ph, n:].reshape(nb, q, Pc * R),
                      out=f[ph].reshape(nb, n, Pc * R))
            data = np.matmul(tab[ph, E1:], Tb[ph])                          # (nph, n m, Pc)
            for i in range(n):
                for r in range(m):
                    f[ph, i] += data[:, i * m + r, :, None] * kgrid[r, ph]
        if c0 <= g0:
            f[g0, :, 0] = x1
        _, start = march(f.reshape(N, n, Pc * R), R, start,
                         out=z[:, :n].reshape(N, n, Pc * R))
        if not len(cs):
            continue
        # states at the samples from the first part [e_c, t_k] of their cell,
        # applied to (x(e_c), a, σ), (N, n, Pc, R); back in time order at the
        # samples' cells
        xp = np.empty((N, n, Pc, R))
        for ph in blocks:
            if E1:
                data = np.matmul(tab[ph, :E1], Tb[ph])                      # (nph, n(n+q), Pc)
                for i in range(n):
                    e0 = i * (n + q)
                    np.multiply(data[:, e0, :, None], z[ph, 0], out=xp[ph, i])
                    for e in range(1, n + q):
                        xp[ph, i] += data[:, e0 + e, :, None] * z[ph, e]
            else:
                V = np.matmul(first[ph], z[ph].reshape(ph.stop - ph.start, n + q, Pc * R))
                V = V.reshape(-1, D1, n, Pc, R)
                np.multiply(Tk[0, ph, None, :, None], V[:, 0], out=xp[ph])
                for d in range(1, D1):
                    xp[ph] += Tk[d, ph, None, :, None] * V[:, d]
        xt = np.ascontiguousarray(xp.transpose(1, 3, 2, 0)).reshape(n, R, Pc * N)
        for i in range(n):
            for r in range(R):
                np.take(xt[i, r], cs, out=x[i, r, ks], mode='clip')


def _kernel(n, m, q, D1, p, H, L):
    """The compiled cell march when enabled, installed and worthwhile (`cellkernel`), else None."""
    if not (_get('timeresp.compiled') and L >= cellkernel.MIN_SAMPLES
            and n <= cellkernel.MAX_STATES):
        return None
    return cellkernel.compiled_kernel(n, m, q, D1, p, H)


def _real_series(C, D):
    """``(Cs, Ds)``: C and D as real Fourier series of H harmonics (2, H + 1, rows, cols),
    ``M(t) = Σ_h Ms[0, h] cos hωt + Ms[1, h] sin hωt``; None unless both are
    Fourier series (or constant) of at most `_FEW_HARMONICS` harmonics.

    Examples
    --------
    >>> from ltpcontrol._core.cellmarch import _real_series
    >>> C = ltp.PeriodicMatrix([[[0.5j]], [[1.0]], [[-0.5j]]], 1.0)       # 1 + sin ωt
    >>> Cs, Ds = _real_series(C, ltp.PeriodicMatrix.constant([[0.0]], 1.0))
    >>> Cs[:, :, 0, 0]
    array([[1., 0.],
           [0., 1.]])
    """
    Hs = [M.nharmonics for M in (C, D)]
    if None in Hs or max(Hs) > _FEW_HARMONICS:
        return None
    H = max(Hs)
    out = []
    for M in (C, D):
        c = M.fourier(H)                                   # M_k, k = -H..H
        s = np.zeros((2, H + 1) + M.shape)
        s[0, 0] = c[H].real
        s[0, 1:] = 2 * c[H + 1:].real                      # 2 Re M_k e^{jkωt}
        s[1, 1:] = -2 * c[H + 1:].imag
        out.append(s)
    return tuple(out)


def _equal_width(table):
    """The cells' width when they are equal (to rounding), else 0."""
    lens, T = table.lens, table.edges[-1]
    w = float(lens[0])
    equal = np.ptp(lens) <= 1e-13 * w and abs(len(lens) * w - T) <= 1e-13 * T
    return w if equal else 0.0


def _cells_of_samples(table, t):
    """Cell g of every sample (counted from the start of the period of t[0]),
    the fraction ξ of the cell before it, and the number of that period."""
    edges, lens = table.edges, table.lens
    N, T = len(lens), edges[-1]
    shifted = t - table.offset
    base = np.floor(shifted[0] / T)
    w = _equal_width(table)
    if w:
        # equal cells: r cells from the start of that period, ξ = r - ⌊r⌋ (exact)
        r = shifted
        r /= w
        r -= base * N
        cell = np.floor(r)
        xi = r
        xi -= cell
        return cell.astype(np.int64), xi, base
    wraps = np.floor(shifted / T)
    theta = shifted - wraps * T
    j = _cell_of(edges, theta)
    xi = np.clip((theta - edges[j]) / lens[j], 0.0, 1.0)
    return (wraps - base).astype(np.int64) * N + j, xi, base


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
    y = np.zeros((p, R, L))
    chunk = max(256, _CHUNK_ENTRIES // max(1, p * (n + m)))
    series = None if C.is_constant and D.is_constant else _real_series(C, D)
    for s0 in range(0, L, chunk):
        i = slice(s0, s0 + chunk)
        if series is not None:
            # Fourier series: y = Σ_h cos hωt (Cs_0h x + Ds_0h u) + sin hωt (Cs_1h x + Ds_1h u),
            # the products with x and u in one each, cos and sin by the
            # multiple-angle recurrence
            Cs, Ds = series
            H = Cs.shape[1] - 1
            # (2 (H + 1) p rows) @ (states of trace r): BLAS on the strided rows of x
            Cf, Df = Cs.reshape(-1, n), Ds.reshape(-1, m)
            P = np.stack([Cf @ x[:, r, i] + Df @ u[:, r, i] for r in range(R)], axis=1)
            P = P.reshape(Cs.shape[:3] + P.shape[1:])                          # (2, H+1, p, R, s)
            y[:, :, i] = P[0, 0]
            angle = C.omega_p * t[i]
            cos = [np.ones_like(angle), np.cos(angle)]
            sin = [np.zeros_like(angle), np.sin(angle)]
            for h in range(1, H + 1):
                if h > 1:
                    cos.append(2 * cos[1] * cos[h - 1] - cos[h - 2])
                    sin.append(2 * cos[1] * sin[h - 1] - sin[h - 2])
                y[:, :, i] += P[0, h] * cos[h] + P[1, h] * sin[h]
            continue
        for M, v in ((C, x), (D, u)):
            if not M.is_constant:
                y[:, :, i] += _apply(M(t[i]), v[:, :, i])
                continue
            Mc = M(t[0])
            if Mc.shape[1] > _FEW_COLUMNS:
                y[:, :, i] += np.tensordot(Mc, v[:, :, i], axes=1)
                continue
            # a few columns: a sum of scaled rows (a product would read v
            # column by column); zero columns skipped
            for c in np.flatnonzero(np.any(Mc, axis=0)):
                y[:, :, i] += Mc[:, c:c + 1, None] * v[c, :, i]
    return y


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
    starts follow ``s_{p+1} = Ψ s_p + z_p`` (`_period_starts`).  It returns
    the states at the start of every cell (same layout; written into `out`
    when given) and the state after the last period (`start` and the result
    (n, R); default start 0).

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

    def __call__(self, f, R, start=None, out=None):
        B, b, n, _ = self.Pb.shape
        O, M, Pb, Psi = self.O, self.M, self.Pb, self.M[-1]
        N, _, K = f.shape
        P = K // R
        X = np.empty_like(f) if out is None else out
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
            starts, s = _period_starts(Psi, Y[B].reshape(n, -1, R), s)
            Sb = M[:B] @ starts.reshape(n, k) + Y[:B]                  # (B, n, k)
            Xc = X[:, :, cols].reshape(B, b, n, k)
            np.matmul(O[:, :b], Sb[:, None], out=Xc)
            Xc += Z[:, :b]
        return X, s


def _period_starts(Psi, z, s):
    """Starts ``s_p`` (n, P, R) of ``s_{p+1} = Ψ s_p + z_p`` (z (n, P, R)), and ``s_P``.

    In blocks of q ≈ √P periods: the periods of every block from a zero
    start at once (q steps), the block starts one after the other (P/q
    steps), and ``s = Ψ^i s_block + local_i``.
    """
    n, P, R = z.shape
    q = max(1, math.isqrt(P))
    nb = -(-P // q)
    zp = np.zeros((n, nb * q, R))
    zp[:, :P] = z
    zp = zp.reshape(n, nb, q, R)
    local = np.empty((q + 1, n, nb, R))
    local[0] = 0.0
    powers = np.empty((q + 1, n, n))
    powers[0] = np.eye(n)
    for i in range(q):
        local[i + 1] = np.tensordot(Psi, local[i], axes=1) + zp[:, :, i]
        powers[i + 1] = Psi @ powers[i]
    starts = np.empty((n, nb, R))
    for c in range(nb):
        starts[:, c] = s
        s = powers[q] @ s + local[q, :, c]
    # the state after period P (the padded periods would multiply by Ψ)
    out = np.tensordot(powers[:q], starts, axes=([2], [0])) + local[:q]   # (q, n, nb, R)
    out = out.transpose(1, 2, 0, 3).reshape(n, nb * q, R)
    end = P - (nb - 1) * q                       # periods of the last block
    last = powers[end] @ starts[:, -1] + local[end, :, -1]
    return out[:, :P], last


def _cell_of(edges, theta):
    """Index j of the cell ``[e_j, e_{j+1})`` holding each phase (uniform guess, corrected)."""
    N = len(edges) - 1
    j = np.clip((theta * (N / edges[-1])).astype(np.int64), 0, N - 1)
    wrong = (theta < edges[j]) | (theta >= edges[j + 1])
    if np.any(wrong):
        j[wrong] = np.clip(np.searchsorted(edges, theta[wrong], side='right') - 1, 0, N - 1)
    return j
