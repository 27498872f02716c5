"""Exact simulation on time grids whose steps do not divide the period.

On a uniform grid whose step divides the period the step data repeat and
one period of them is computed (``_march``).  On any other grid every step
``[t_k, t_k + h_k]`` has its own phase, and computing every step's
transition data afresh costs as many sixth-order Magnus integrations as
there are samples.  Instead:

* **Repeating phases.**  When ``q h = p T`` for small integers (a uniform
  grid commensurate with the period), the step data repeat every q steps:
  q steps are computed and the periodic march runs with period q.
* **Phase table.**  Otherwise one period is cut into N cells
  ``[e_j, e_{j+1}]`` shorter than the shortest step (pieces of a few
  cells, split at the switching instants), and a step is split into a
  head piece ``[t_k, e_{j+1}]``, c whole cells and a tail piece
  ``[e_J, t_k + h_k]``.  The data of every cell, and of its first and last
  parts at the D + 1 Chebyshev-Lobatto lengths ℓ, are integrated once
  (``_core/celldata.py``: A and B sampled once per piece, sixth-order
  Magnus steps on the interpolated values);
  a step's head and tail come from the first and last parts
  ``[e_j, e_j + ℓ]``, ``[e_{j+1} - ℓ, e_{j+1}]`` interpolated in ℓ.  The
  samples per piece, the degree D and the sub-steps are the cheapest that
  agree with the adaptive integrator at probe lengths to 1e-13; cells are
  halved otherwise, or the steps are integrated one by one.
* **Cell march.**  On a grid whose phases never repeat (non-uniform,
  jittered, a few irregular steps, long records) no step's data are
  formed: the state is marched over the cells of the record and read at
  the samples from the cells' first parts (``_core/cellmarch.py``).  A
  repeating pattern spanning several periods takes its q steps' data from
  the table (head, runs of cells, tail, as below).

The data of an interval ``I = [a, b]`` with a linear input
``u(τ) = u_k + (τ - t_k)/h_k Δu`` are

    Φ_I = Φ(b, a),   W_I = ∫_I Φ(b, s) B(s) ds,   Z_I = ∫_I Φ(b, s) B(s) (s - a) ds,

and the input enters as ``W_I (u_k + (a - t_k)/h_k Δu) + Z_I Δu / h_k``.  They
compose exactly: for ``I1 = [a, c]`` followed by ``I2 = [c, b]``

    Φ = Φ2 Φ1,   W = Φ2 W1 + W2,   Z = Φ2 Z1 + Z2 + (c - a) W2,

so a run of c cells is assembled from precomputed runs of 2^i cells
(binary lifting, ⌈log2 c⌉ products), and the step data are
``Γ0 = W``, ``Γ1 = Z / h_k`` (``_transition``).  The answer is exact to the
integrator's tolerance, like the aligned path; only the number of
integrations changes.  The march itself runs on chunks of steps with the
block kernel of ``_march``, a chunk being one "period" of step data.
"""

import math
from fractions import Fraction

import numpy as np

from .celldata import _ENTRYWISE_STATES, CellSamples, CellTable, interpolate, lobatto
from .cellmarch import cell_march
from .march import periodic_march
from .memory import available_memory
from .threads import small_blas
from .transition import _entries_product, step_transitions

__all__ = []

_CHUNK_STEPS = 4000          # steps of step data held at a time ...
_CHUNK_BYTES = 2 ** 26       # ... with at most this many bytes in one array of them
_TABLE_SHARE = 0.5           # most of the available memory a cell table may take
_TABLE_COPIES = 4            # arrays of a cell table's size alive while it is made and used
_FEW_TRACES = 16             # up to this many traces: march state by state
_SEQ_BLOCK = 32              # block length of that march
_MAX_CELLS = 2 ** 15         # cells of the phase table
_FEW_CELLS = 16              # runs of fewer cells than this are tabulated
_MAX_REPEAT = 4096           # longest repeating phase pattern used as a period
_TABLE_TOL = 1e-13           # accepted interpolation error (relative to a cell's data)
_PIECE_CELLS = 8             # cells per piece on which A and B are interpolated
_SAMPLES = (12, 20, 32)      # Chebyshev samples of A and B per piece, tried in turn
# (degree D of the partial-cell interpolants, Magnus steps per sub-interval), by cost
_LADDER = ((4, 1), (5, 1), (6, 1), (8, 1), (8, 2), (10, 2), (12, 4))
_LAYOUT_STEPS = 16384        # steps of a long record from which cells are laid out first
_PHASE_MAX = 1024            # most phases of the interpolated step data of a uniform grid
_PHASE_COPIES = 6            # arrays of 2M phases' size alive while they are interpolated



def grid_march(A, B, C, D, t, u, x0, hold, rtol, states=True):
    """States and outputs of ``ẋ = Ax + Bu, y = Cx + Du`` on an arbitrary grid.

    Parameters
    ----------
    A, B, C, D : PeriodicMatrix
    t : ndarray, shape (L,)
        Strictly increasing time points, L >= 2.
    u : ndarray, shape (m, R, L)
    x0 : ndarray, shape (n, R)
    hold : {'foh', 'zoh'}
    rtol : float
    states : bool
        Return the states (False: None, outputs only).

    Returns
    -------
    x : ndarray, shape (n, R, L), or None
    y : ndarray, shape (p, R, L)

    Examples
    --------
    A grid whose step (0.3) does not divide the period (1):

    >>> from ltpcontrol._core.gridmarch import grid_march
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> t = 0.3 * np.arange(11)
    >>> x, y = grid_march(sys.A, sys.B, sys.C, sys.D, t, np.ones((1, 1, 11)),
    ...                   np.zeros((1, 1)), 'foh', 1e-12)
    >>> bool(np.allclose(y[0, 0], 1 - np.exp(-t)))
    True
    """
    # the small products of every path run on one BLAS thread, entered once
    with small_blas(A.shape[0] + 2 * B.shape[1]):
        return _grid_march(A, B, C, D, t, u, x0, hold, rtol, states)


def _grid_march(A, B, C, D, t, u, x0, hold, rtol, states):
    T = A.period
    h = np.diff(t)
    repeat = _repeat_length(t, h, T)
    table = None
    if repeat is None or repeat[1] > 1:
        # steps longer than or not dividing the period: a cell table, when worthwhile
        count = len(h) if repeat is None else repeat[0]
        if count > 2 * math.ceil(T / h.min()) or (repeat is not None and repeat[1] > 1):
            if repeat is None:
                # a grid whose phases never repeat: march over the cells of a
                # phase table, laid out from every k-th step of a long record
                # first (again from all steps when two samples share a cell)
                stride = -(-len(h) // _LAYOUT_STEPS)
                for k in ((stride, 1) if stride > 1 else (1,)):
                    cells = _cell_table(A, B, h, T, rtol, t, stride=k)
                    marched = None if cells is None else cell_march(cells, C, D, t, u, x0,
                                                                    hold, states)
                    if marched is not None:
                        return marched
                if _uniform(t, h):
                    # a uniform grid: the step data are smooth periodic functions
                    # of the phase
                    table = _phase_table(A, B, float(h[0]), T, rtol)
            else:
                table = _table_steps(A, B, h, T, rtol)
    if repeat is not None:
        # the step data repeat every q steps: march with period q
        q = repeat[0]
        tk = t[0] + h[0] * np.arange(q)
        if table is not None:
            Phi, G0, G1 = table(tk, np.full(q, h[0]))
        else:
            Phi, G0, G1 = step_transitions(A, B, tk, h[0], rtol)
        E, F = _hold(G0, G1, hold)
        return periodic_march(Phi, E, F, C(tk), D(tk), u, x0, states=states)
    if table is None:
        def steps(k0, k1):
            return step_transitions(A, B, t[k0:k1], h[k0:k1], rtol)
    else:
        def steps(k0, k1):
            return table(t[k0:k1], h[k0:k1])
    return _chunked_march(steps, C, D, t, u, x0, hold, states)


def _uniform(t, h):
    """Whether the steps h of the grid t are equal, to 1e-10 and to the rounding of t.

    The times of a long record carry rounding errors of ``eps |t|``: a step
    computed as a difference of two of them is known to that absolute
    accuracy only (``np.arange(L) / 400`` has steps that differ by 2e-10
    relative beyond a million samples).

    Examples
    --------
    >>> from ltpcontrol._core.gridmarch import _uniform
    >>> t = np.arange(2_000_000) / 400
    >>> _uniform(t, np.diff(t)), _uniform(t[:3] ** 2, np.diff(t[:3] ** 2))
    (True, False)
    """
    atol = 8 * np.finfo(float).eps * max(abs(float(t[0])), abs(float(t[-1])))
    return bool(np.all(np.abs(h - h[0]) <= 1e-10 * abs(h[0]) + atol))


def _repeat_length(t, h, T):
    """``(q, p)`` when the grid is uniform and ``q h = p T`` (q <= a bound), else None."""
    if not _uniform(t, h):
        return None
    ratio = Fraction(float(h[0] / T)).limit_denominator(_MAX_REPEAT)
    q, p = ratio.denominator, ratio.numerator
    if abs(q * h[0] - p * T) > 1e-9 * p * T or q > len(h):
        return None
    # worthwhile only when the pattern is a few periods' worth of steps
    return (q, p) if q <= 4 * math.ceil(T / h[0]) else None


def _hold(G0, G1, hold):
    # x[k+1] = Φ x[k] + (Γ0 - Γ1) u[k] + Γ1 u[k+1] (first-order hold)
    return (G0, None) if hold == 'zoh' else (G0 - G1, G1)


def _chunked_march(steps, C, D, t, u, x0, hold, states):
    """March chunk after chunk of step data, each chunk as one 'period'."""
    L = len(t)
    n, R = x0.shape
    p, d = C.shape[0], n + 2 * u.shape[0]
    x = np.empty((n, R, L)) if states else None
    y = np.empty((p, R, L))
    xs = x0
    # chunks whose step data (and augmented matrices d x d) stay within _CHUNK_BYTES
    chunk = max(20, min(_CHUNK_STEPS, _CHUNK_BYTES // (8 * d * d)))
    for s0 in range(0, L, chunk):
        s1 = min(L, s0 + chunk)
        S = s1 - s0
        k1 = min(s1, L - 1)                    # step data exist for samples < L - 1
        Phi, G0, G1 = steps(s0, k1)
        E, F = _hold(G0, G1, hold)
        Nc = -(-S // 20) * 20                  # a multiple of the block length
        Phi, E, F = _pad(Phi, Nc, eye=True), _pad(E, Nc), None if F is None else _pad(F, Nc)
        tk = t[s0:s1]
        Cs, Ds = _pad(C(tk), Nc), _pad(D(tk), Nc)
        if R <= _FEW_TRACES:
            xc, yc, xs = _sequence_march(Phi, E, F, Cs, Ds, u[:, :, s0:s1 + 1], xs, S)
            xc = xc if states else None
        elif s1 == L:
            xc, yc = periodic_march(Phi, E, F, Cs, Ds, u[:, :, s0:s1], xs, states=states,
                                    nsamples=S)
        else:
            # one more input sample: the state after the chunk starts the next one
            xc, yc, xs = periodic_march(Phi, E, F, Cs, Ds, u[:, :, s0:s1 + 1], xs,
                                        states=states, final=True, nsamples=S)
        y[:, :, s0:s1] = yc
        if states:
            x[:, :, s0:s1] = xc
    return x, y


def _sequence_march(Phi, E, F, C, D, u, x0, S):
    """States, outputs and final state of one chunk for a few traces.

    With the forcing ``w_k = E_k u[k] + F_k u[k+1]`` computed for all steps
    at once, ``x[k+1] = Φ_k x[k] + w_k`` is unrolled inside blocks of b
    steps (``x[s+j] = Φ(j, 0) x[s] + σ_j``, a loop over j for all blocks at
    once) and the block starts are marched block by block.
    """
    N, n, m = E.shape
    R = u.shape[1]
    Lu = u.shape[2]
    b = _SEQ_BLOCK
    Np = -(-N // b) * b
    uk = np.zeros((m, R, Np + 1))
    uk[:, :, :Lu] = u
    uk[:, :, Lu:] = u[:, :, -1:]
    w = np.einsum('kni,irk->knr', E, uk[:, :, :N])
    if F is not None:
        w += np.einsum('kni,irk->knr', F, uk[:, :, 1:N + 1])
    Phi, w = _pad(Phi, Np, eye=True), _pad(w, Np)
    nb = Np // b
    Phi, w = Phi.reshape(nb, b, n, n), w.reshape(nb, b, n, R)
    P = np.broadcast_to(np.eye(n), (nb, n, n)).copy()
    sig = np.zeros((nb, n, R))
    Ploc, sloc = np.empty((nb, b, n, n)), np.empty((nb, b, n, R))
    for j in range(b):
        Ploc[:, j], sloc[:, j] = P, sig
        P, sig = Phi[:, j] @ P, Phi[:, j] @ sig + w[:, j]
    starts = np.empty((nb + 1, n, R))
    starts[0] = x0
    for i in range(nb):
        starts[i + 1] = P[i] @ starts[i] + sig[i]
    x = (Ploc @ starts[:nb, None] + sloc).reshape(Np, n, R)[:S]
    Ck, Dk = C[:S], D[:S]
    y = np.einsum('kpn,knr->prk', Ck, x) + np.einsum('kpi,irk->prk', Dk, uk[:, :, :S])
    return x.transpose(1, 2, 0), y, starts[nb]


def _pad(a, N, eye=False):
    """Step data padded to N steps (identity transitions, zero inputs and outputs)."""
    if len(a) == N:
        return a
    out = np.zeros((N,) + a.shape[1:])
    out[:len(a)] = a
    if eye:
        out[len(a):] = np.eye(a.shape[1])
    return out


def _phase_table(A, B, h, T, rtol):
    """Step data of a uniform grid (step h) interpolated in the phase, or None.

    The data ``(Φ, Γ0, Γ1)`` of a step ``[τ, τ + h]`` are T-periodic in τ
    and, for A and B without switching, smooth: their trigonometric
    interpolant from M equispaced phases converges spectrally.  M doubles
    from 32 until the interpolant predicts the data at the M midpoints to
    1e-13 (relative), so a uniform grid of any step costs about as many
    integrations as a period of the aligned grid, whatever its length.
    """
    if A.breakpoints.size or B.breakpoints.size:
        return None
    n, m = A.shape[0], B.shape[1]

    def data(phases):
        Phi, G0, G1 = step_transitions(A, B, phases, h, rtol)
        return np.concatenate([Phi, G0, G1], axis=2)

    # the samples at 2M phases, (n, n + 2m) each, and their transforms (complex):
    # no doubling beyond what the memory holds (the step by step march instead)
    avail = available_memory()

    def fits(M):
        need = _PHASE_COPIES * 8.0 * 2 * M * n * (n + 2 * m)
        return avail is None or need <= _TABLE_SHARE * avail

    M = 32
    if not fits(M):
        return None
    X = data(T * np.arange(M) / M)
    while M <= _PHASE_MAX and fits(M):
        mid = data(T * (np.arange(M) + 0.5) / M)
        scale = max(1.0, np.abs(X).max())
        ks = np.fft.fftfreq(M, 1.0 / M)
        ks[M // 2] = 0                      # the Nyquist term vanishes at midpoints
        coeffs = np.fft.fft(X, axis=0) / M
        coeffs[M // 2] = 0
        E = np.exp(2j * np.pi * np.outer(np.arange(M) + 0.5, ks) / M)
        pred = np.tensordot(E, coeffs, axes=1).real
        both = np.empty((2 * M,) + X.shape[1:])
        both[0::2], both[1::2] = X, mid
        if np.abs(pred - mid).max() <= _TABLE_TOL * scale:
            return _PhaseInterpolant(both, T, n, m)
        X, M = both, 2 * M
    return None


class _PhaseInterpolant:
    """``table(tk, hk) -> (Φ, Γ0, Γ1)`` from equispaced phase samples (real data)."""

    def __init__(self, samples, T, n, m):
        M = len(samples)
        C = np.fft.rfft(samples, axis=0)[:M // 2] / M        # harmonics 0..M/2-1
        C[1:] *= 2                                          # X = Re Σ_{k>=0} C_k e^{jkθ}
        self.coeffs = C.reshape(len(C), -1)
        self.shape, self.T, self.n, self.m = samples.shape[1:], T, n, m

    def __call__(self, tk, hk):
        z = np.exp(2j * np.pi * np.mod(tk, self.T) / self.T)
        Z = np.empty((len(tk), len(self.coeffs)), complex)
        Z[:, 0] = 1.0
        for k in range(1, Z.shape[1]):
            np.multiply(Z[:, k - 1], z, out=Z[:, k])
        X = (Z @ self.coeffs).real.reshape((len(tk),) + self.shape)
        n, m = self.n, self.m
        return X[:, :, :n], X[:, :, n:n + m], X[:, :, n + m:]


def _cell_table(A, B, h, T, rtol, t=None, stride=1):
    """The phase table of the steps `h` (module notes), or None when not exact enough.

    With the samples `t` of a plant without switching, the cells are the
    fewest (offset at will) that hold at most one sample each
    (`_cell_layout`, from every `stride`-th step); otherwise they are
    shorter than the shortest step.
    """
    hmin = float(h.min())
    tol = max(_TABLE_TOL, 0.1 * rtol)
    # pieces of about _PIECE_CELLS cells (split at the switching instants),
    # on which A and B are sampled; cells shorter than the shortest step (so
    # that a step spans a cell boundary), halved when no degree and sub-step
    # count of the ladder meets the tolerance
    N0 = max(16, math.floor(T / hmin) + 1)
    bps = np.mod(np.concatenate([A.breakpoints, B.breakpoints]), T)
    Ns = -(-N0 // _PIECE_CELLS)
    offset = 0.0
    layout = None if (t is None or bps.size) else \
        _cell_layout(t[:-1:stride], h[::stride], T, Ns, (t[-1] - t[0]) / len(h))
    if layout is not None:
        Ns, offset = layout
    pieces = np.union1d(np.linspace(0, T, Ns + 1), bps)
    pieces = pieces[np.concatenate([[True], np.diff(pieces) > 1e-12 * T])]
    pieces[-1] = T
    k0 = _PIECE_CELLS
    if k0 * (len(pieces) - 1) > _MAX_CELLS:
        return None
    # A and B on every piece at the fewest Chebyshev points that resolve them
    for G in _SAMPLES:
        cells = CellSamples(A, B, pieces, k0, G, offset)
        if cells.tail() <= tol:
            break
    else:
        return None
    for refine in (1, 2, 4):
        if refine * k0 * (len(pieces) - 1) > _MAX_CELLS:
            return None
        cells.refine(refine * k0)
        config = _table_config(A, B, cells, rtol, tol)
        if config is not None:
            break
    else:
        return None
    frac, nsub = config
    # the table's parts at the D + 1 lengths of every cell, (n, n + 2m) each:
    # for large models on fine grids more than the memory holds (the step by
    # step march then runs in chunks of bounded size)
    need = _TABLE_COPIES * 8.0 * len(cells.lens) * len(frac) * cells.n * (cells.n + 2 * cells.m)
    avail = available_memory()
    if avail is not None and need > _TABLE_SHARE * avail:
        return None
    fwd, bwd = _partial_table(cells, frac, nsub)
    return CellTable(cells.edges, cells.lens, frac, fwd, bwd, offset)


def _cell_layout(starts, h, T, most, mean=None):
    """``(pieces, offset)``: the fewest pieces of `_PIECE_CELLS` equal cells with one sample each.

    Cells of width w hold at most one sample each when every step shorter
    than w has a cell edge inside it: the offset of the edges (modulo w)
    must lie in the arc ``(t_k, t_{k+1}]`` of every such step (`starts` t_k,
    steps `h`).  The arcs are intersected on 256 bins for piece counts from
    the `mean` step on (a step of at least w covers every bin: its arc is
    cut to w, and every bin must be covered by all the steps); the offset is
    the middle of the widest common run.  None when no count below `most`
    works.
    """
    bins = 256
    hmin = float(h.min())
    mean = float(np.mean(h)) if mean is None else mean
    first = max(1, math.ceil(T / (_PIECE_CELLS * mean) - 1e-9))
    for Ns in sorted({min(most, int(first * 1.06 ** i)) for i in range(8)}):
        if Ns >= most:
            break
        w = T / (Ns * _PIECE_CELLS)
        if hmin >= w:
            return Ns, 0.0
        # bin centres (i + 1/2) w / bins inside (s, s + h]: i0 <= i <= i1, from
        # the steps' starts s in cells (their fractional parts, in bins)
        s0 = starts / w
        s0 -= np.floor(s0)
        s0 *= bins
        s0 -= 0.5
        i0 = np.floor(s0).astype(np.int64)
        s0 += np.minimum(h, w) * (bins / w)
        i1 = np.floor(s0).astype(np.int64)
        cover = np.bincount(i0 + 1, minlength=2 * bins + 2) \
            - np.bincount(i1 + 1, minlength=2 * bins + 2)
        cover = np.cumsum(cover)[:2 * bins]
        ok = cover[:bins] + cover[bins:] == len(h)
        if ok.sum() < 3:
            continue
        if ok.all():
            return Ns, 0.0
        # the middle of the widest run of allowed bins (circular): the widest
        # gap between consecutive forbidden bins
        bad = np.flatnonzero(~ok)
        gaps = np.diff(np.append(bad, bad[0] + bins))
        i = int(np.argmax(gaps))
        at = (bad[i] + gaps[i] / 2 + 0.5) % bins          # a bin centre
        return Ns, at * w / bins
    return None


def _table_steps(A, B, h, T, rtol):
    """Step data ``steps(tk, hk) -> (Φ, Γ0, Γ1)`` from a phase table, or None."""
    table = _cell_table(A, B, h, T, rtol)
    if table is None:
        return None
    hmax = float(h.max())
    n, m = A.shape[0], B.shape[1]
    edges, lens, frac = table.edges, table.lens, table.frac
    N = len(lens)
    partial = table.fwd, table.bwd
    # the composition rule as a product of augmented matrices
    # [[Φ, W, Z], [0, I, ℓI], [0, 0, I]] (ℓ the interval's length)
    nodes = lens[:, None] * frac
    fwd, bwd = (_augment(*v, nodes) for v in partial)
    del partial
    cells = fwd[:, -1]
    # runs of 2^i cells from every cell
    levels = max(1, int(math.ceil(hmax / lens.min()) + 1).bit_length())
    lift = [cells]
    for i in range(1, levels):
        nxt = (np.arange(N) + 2 ** (i - 1)) % N
        lift.append(lift[-1][nxt] @ lift[-1])
    # steps spanning few cells: every run of c < 2^levels cells from every cell
    runs = None
    if 2 ** levels <= _FEW_CELLS:
        runs = np.empty((2 ** levels, N) + cells.shape[1:])
        runs[0] = np.eye(cells.shape[1])
        for c in range(1, 2 ** levels):
            runs[c] = cells[(np.arange(N) + c - 1) % N] @ runs[c - 1]

    def steps(tk, hk):
        theta = tk - T * np.floor(tk / T)
        j = np.clip(np.searchsorted(edges, theta, side='right') - 1, 0, N - 1)
        phi = theta + hk
        wraps = np.floor(phi / T)
        jb = np.clip(np.searchsorted(edges, phi - wraps * T, side='right') - 1, 0, N - 1)
        count = (jb + N * wraps.astype(int)) - j - 1
        # head [θ, e_{j+1}] and tail [e_J, t_k + h_k] from the partial cells
        M = interpolate(bwd, frac, j, (edges[j + 1] - theta) / lens[j])
        # the run of `count` cells after cell j, by the binary digits of count
        pos = (j + 1) % N
        if runs is not None:
            M = runs[count, pos] @ M
        else:
            for i, run in enumerate(lift):
                sel = (count >> i) & 1 == 1
                if np.any(sel):
                    M[sel] = run[pos[sel]] @ M[sel]
                    pos = np.where(sel, (pos + 2 ** i) % N, pos)
        tail = interpolate(fwd, frac, jb, (phi - wraps * T - edges[jb]) / lens[jb])
        M = tail @ M
        return M[:, :n, :n], M[:, :n, n:n + m], M[:, :n, n + m:] / hk[:, None, None]
    return steps


def _table_config(A, B, cells, rtol, tol):
    """``(fractions, sub-steps)`` of the cheapest accurate table, or None.

    Degrees D and Magnus steps are tried in order of cost on probe
    cells (spread over the period, the cell of the largest |A| and the
    least resolved one) until the interpolated head and tail pieces agree
    with the adaptive integrator at probe lengths to `tol`.
    """
    edges = cells.edges
    N = len(edges) - 1
    probe = np.unique(np.concatenate([np.linspace(0, N - 1, min(N, 6)).astype(int),
                                      [np.argmax(cells.cell_norms()),
                                       np.argmax(cells.cell_tails())]]))
    # reference pieces at both ends of the probe cells
    xi = np.tile([0.0731, 0.2917, 0.6180], len(probe))
    j = np.repeat(probe, 3)
    length = xi * (edges[j + 1] - edges[j])
    exact = _pieces(A, B, np.concatenate([edges[j], edges[j + 1] - length]) + cells.offset,
                    np.concatenate([length, length]), rtol, A.shape[0])
    sub = np.repeat(np.arange(len(probe)), 3)
    # the Chebyshev coefficients of e^{Aℓ} on a cell decay as 2 (ρ/4)^k / k!,
    # ρ = |A| h: start from the first degree whose next coefficient is below tol
    rho = np.sqrt(A.shape[0]) * float((cells.cell_norms() * cells.lens).max())
    start = 0
    while start < len(_LADDER) - 1 and \
            2 * (rho / 4) ** (_LADDER[start][0] + 1) / math.factorial(_LADDER[start][0] + 1) > tol:
        start += 1
    for D, nsub in _LADDER[start:]:
        nodes, _ = lobatto(D)
        err = 0.0
        for end, table in enumerate(_partial_table(cells, nodes, nsub, probe)):
            approx = interpolate(table, nodes, sub, xi)
            ref = tuple(v[end * len(j):(end + 1) * len(j)] for v in exact)
            for i, (e, a, whole) in enumerate(zip(ref, approx, table)):
                if not e.size:                       # no inputs
                    continue
                # Φ relative to max(1, |Φ|); W, Z relative to their size over a cell
                scale = np.abs(whole[:, -1]).max()
                scale = max(1.0, scale) if i == 0 else max(scale, 1e-300)
                err = max(err, float(np.abs(e - a).max() / scale))
        if err <= tol:
            return nodes, nsub
    return None


def _augment(P, W, Z, lengths):
    """``[[Φ, W, Z], [0, I, ℓI], [0, 0, I]]`` of a table (cells, nodes)."""
    n, m = W.shape[-2:]
    M = np.zeros(P.shape[:2] + (n + 2 * m, n + 2 * m))
    M[..., :n, :n], M[..., :n, n:n + m], M[..., :n, n + m:] = P, W, Z
    M[..., n:n + m, n:n + m] = M[..., n + m:, n + m:] = np.eye(m)
    M[..., n:n + m, n + m:] = lengths[..., None, None] * np.eye(m)
    return M


def _partial_table(cells, frac, nsub, which=None):
    """(Φ, W, Z) of ``[e_j, e_j + ℓ_i]`` and ``[e_{j+1} - ℓ_i, e_{j+1}]``, ``ℓ_i = x_i h_j``.

    `frac` holds the fractions ``x_i`` (symmetric about 1/2, so that the
    backward pieces have the same lengths); `which` selects cells.
    """
    n, m = cells.n, cells.m
    D = len(frac) - 1
    E = np.concatenate(cells.interval_data(frac, nsub, which), axis=3)   # (Nc, D, n, d)
    d = E.shape[3]
    lens = cells.lens if which is None else cells.lens[which]
    start = lens[:, None] * frac                                         # (Nc, D+1)
    dd = np.diff(start, axis=1)
    # the sub-intervals' data [Φ | W | Z] as stacks S[i] of position i: entry
    # by entry for a few states, (D, n, d, Nc), else (D, Nc, n, d)
    entrywise = n <= _ENTRYWISE_STATES
    if entrywise:
        S = np.ascontiguousarray(E.transpose(1, 2, 3, 0))
        start, dd = start.T[:, None, None, :], dd.T[:, None, None, :]
        eye = np.eye(n, d)[:, :, None]
    else:
        S = E.swapaxes(0, 1)
        start, dd = start.T[..., None, None], dd.T[..., None, None]
        eye = np.eye(n, d)

    def col(X, c):
        return X[:, c] if entrywise else X[..., c]

    def product(X, Y, out):
        if entrywise:
            np.copyto(out, _entries_product(X, Y))
        else:
            np.matmul(X, Y, out=out)
    # data of I1 followed by I2: Φ2 [Φ1 | W1 | Z1] + [0 | W2 | Z2 + |I1| W2]
    Ph, W, Z = slice(0, n), slice(n, n + m), slice(n + m, None)
    fwd = np.empty((D + 1,) + S.shape[1:])
    fwd[0] = eye
    bwd = fwd.copy()
    for i in range(D):
        # forward: [e_j, e_j + ℓ_i] then sub-interval i
        product(col(S[i], Ph), fwd[i], fwd[i + 1])
        col(fwd[i + 1], W)[...] += col(S[i], W)
        col(fwd[i + 1], Z)[...] += col(S[i], Z) + start[i] * col(S[i], W)
        # backward: sub-interval D-1-i then [e_{j+1} - ℓ_i, e_{j+1}]
        k = D - 1 - i
        product(col(bwd[i], Ph), S[k], bwd[i + 1])
        col(bwd[i + 1], W)[...] += col(bwd[i], W)
        col(bwd[i + 1], Z)[...] += col(bwd[i], Z) + dd[k] * col(bwd[i], W)
    # to (cells, D + 1, n, d), one at a time (at most three arrays of the
    # table's size alive)
    del S, E
    order = (3, 0, 1, 2) if entrywise else (1, 0, 2, 3)
    fwd = np.ascontiguousarray(fwd.transpose(order))
    bwd = np.ascontiguousarray(bwd.transpose(order))
    return (fwd[..., :n], fwd[..., W], fwd[..., Z]), (bwd[..., :n], bwd[..., W], bwd[..., Z])


def _pieces(A, B, a, length, rtol, n):
    """(Φ, W, Z) of the pieces [a, a + length]; zero length gives the identity."""
    m = B.shape[1]
    P = np.broadcast_to(np.eye(n), (len(a), n, n)).copy()
    W, Z = np.zeros((len(a), n, m)), np.zeros((len(a), n, m))
    live = length > 1e-14 * A.period
    if np.any(live):
        Pl, G0, G1 = step_transitions(A, B, a[live], length[live], rtol)
        P[live], W[live], Z[live] = Pl, G0, G1 * length[live][:, None, None]
    return P, W, Z
