"""Transition data of the sub-intervals of a partition of the period, from few samples.

A partition of one period into pieces (split at the switching instants,
so that A and B are smooth inside every piece), of every piece into k
equal cells ``[e_c, e_{c+1}]`` and of every cell into sub-intervals at the same fractions ``x_0 = 0 < x_1 < … <
x_D = 1`` of its length needs the transition data

    Φ_I = Φ(b, a),   W_I = ∫_I Φ(b, s) B(s) ds,   Z_I = ∫_I Φ(b, s) B(s) (s - a) ds

of every sub-interval ``I = [a, b]``.  Integrating each sub-interval on
its own calls A and B at two Gauss points of every Magnus sub-step, over
and over (``_core/transition.py``).  Here A and B are sampled once per
piece of k cells, at G Chebyshev points of the first kind (interior
points, so a switching instant at a piece's edge is never sampled), and
their values at the three Gauss points of sixth-order Magnus steps of the augmented matrix

    M = [[A, B, σB], [0, 0, 0], [0, 0, 0]]

(``σ = (τ - a)/(b - a)``, `_magnus6`) come from the piece's polynomial interpolant:
one matrix product per cell position, since the Gauss points sit at the
same fractions of every piece.  The number of calls of A and B is G per
piece, whatever the cells, degrees and steps.  The exponentials of the short
steps are Taylor series (no linear solves).

`CellSamples.tail` measures how well the interpolant resolves A and B on
every piece (the last Chebyshev coefficients, relative to the largest
value); the caller checks the resulting data against the adaptive
integrator of ``_core/transition.py`` at probe intervals.
"""

import numpy as np

from .memory import check_allocation
from .threads import small_blas
from .transition import (_balancing, _entries_product, _magnus6,
                         _tree_product, expm_batch)

__all__ = []

#: Gauss-Legendre points of [0, 1] with three nodes
_GAUSS3 = np.array([0.5 - np.sqrt(15) / 10, 0.5, 0.5 + np.sqrt(15) / 10])
#: largest 1-norm of the exponents taken by Taylor series (else scaling and squaring)
_TAYLOR_NORM = 0.25
#: entries of the working arrays of one chunk of cells
_CHUNK_ENTRIES = 2 ** 19


def chebyshev_first_kind(G):
    """Chebyshev points of the first kind on [0, 1] and their barycentric weights.

    Examples
    --------
    >>> from ltpcontrol._core.celldata import chebyshev_first_kind
    >>> x, w = chebyshev_first_kind(3)
    >>> bool(np.all((x > 0) & (x < 1))), bool(np.isclose(x[1], 0.5))
    (True, True)
    """
    theta = np.pi * (2 * np.arange(G) + 1) / (2 * G)
    return 0.5 - 0.5 * np.cos(theta), (-1.0) ** np.arange(G) * np.sin(theta)


#: up to this many states, the short steps' products are taken entry by entry
_ENTRYWISE_STATES = 4


def _expm_small(X, entrywise=False):
    """e^X of a stack of first rows (S, n, d) (zero rows below); the same first rows.

    With `entrywise` the stack is stored entry by entry, (n, d, S).  Taylor
    series when every 1-norm is at most 0.25 (Horner on the first rows:
    ``X E = [X11 E11, X11 E12 + X12]`` since E's last rows are ``[0, I]``),
    else scaling and squaring of the whole matrices.
    """
    if entrywise:
        n, d, S = X.shape
        norms = np.abs(X).sum(axis=0).max(axis=0)
    else:
        S, n, d = X.shape
        norms = np.abs(X).sum(axis=-2).max(axis=-1)
    top = float(norms.max()) if len(norms) else 0.0
    if top > _TAYLOR_NORM:
        full = np.zeros((S, d, d))
        full[:, :n] = np.moveaxis(X, -1, 0) if entrywise else X
        E = expm_batch(full)[:, :n]
        return np.ascontiguousarray(np.moveaxis(E, 0, -1)) if entrywise else E
    # the truncation error top^(K+1)/(K+1)! below 2^-54
    K, term = 1, top
    while term > 2.0 ** -54 and K < 30:
        K += 1
        term *= top / K
    eye = np.eye(n, d)[:, :, None] if entrywise else np.eye(n, d)
    tail = np.zeros_like(X)
    if entrywise:
        X11 = X[:, :n]
        tail[:, n:] = X[:, n:]
    else:
        X11 = X[:, :, :n]
        tail[:, :, n:] = X[:, :, n:]
    product = _entries_product if entrywise else np.matmul
    E = eye + X / K
    for j in range(K - 1, 0, -1):
        E = product(X11, E)
        E += tail
        E /= j
        E += eye
    return E


def barycentric_matrix(x, nodes, weights):
    """Matrix ``P`` with ``P @ f(nodes) = p(x)``, p the interpolant of f at `nodes`.

    Examples
    --------
    >>> from ltpcontrol._core.celldata import barycentric_matrix
    >>> nodes = np.array([0.0, 0.5, 1.0])
    >>> P = barycentric_matrix(np.array([0.25, 1.0]), nodes, np.array([0.5, -1.0, 0.5]))
    >>> P @ nodes ** 2
    array([0.0625, 1.    ])
    """
    diff = np.asarray(x, float)[:, None] - nodes[None, :]
    hit = diff == 0
    with np.errstate(divide='ignore'):
        w = np.where(hit.any(axis=1, keepdims=True), hit.astype(float), weights / diff)
    return w / w.sum(axis=1, keepdims=True)


class CellSamples:
    """A and B sampled at G Chebyshev points of every piece of `pieces`.

    Every piece ``[p_s, p_{s+1}]`` is cut into k equal cells; the cells are
    numbered piece by piece (cell ``c`` is cell ``c % k`` of piece ``c // k``).
    A and B are interpolated over a whole piece, so a piece spanning many
    cells costs G calls of A and B.  The pieces are phases counted from
    `offset` (A and B are sampled at ``offset + τ``).

    Examples
    --------
    >>> from ltpcontrol._core.celldata import CellSamples
    >>> A = ltp.PeriodicMatrix.constant([[-1.0]], 1.0)
    >>> B = ltp.PeriodicMatrix.constant([[1.0]], 1.0)
    >>> cells = CellSamples(A, B, np.array([0.0, 0.5, 1.0]), 2, 4)
    >>> Phi, W, Z = cells.interval_data(np.array([0.0, 0.5, 1.0]), 1)
    >>> Phi.shape, bool(np.isclose(Phi[:, :, 0, 0].prod(), np.exp(-1.0)))
    ((4, 2, 1, 1), True)
    """

    def __init__(self, A, B, pieces, k, G, offset=0.0):
        pieces = np.asarray(pieces, float)
        self.A, self.B, self.G, self.pieces = A, B, int(G), pieces
        self.offset = float(offset)
        self.n, self.m = A.shape[0], B.shape[1]
        plen = np.diff(pieces)
        self.refine(k)
        self.nodes, self.weights = chebyshev_first_kind(self.G)
        tau = (pieces[:-1, None] + plen[:, None] * self.nodes).ravel() + self.offset
        Ns, n, m = len(plen), self.n, self.m
        check_allocation((Ns * self.G, n, n + m), f"A and B at {Ns * self.G} points")
        vals = np.empty((Ns * self.G, n, n + m))
        vals[:, :, :n] = A._eval(tau)
        vals[:, :, n:] = B._eval(tau)
        self.values = vals.reshape(Ns, self.G, n * (n + m))
        self.scale = _balancing(A, n, n + 2 * m)

    def refine(self, k):
        """Cut every piece into k equal cells (the samples are kept)."""
        pieces, plen = self.pieces, np.diff(self.pieces)
        self.k = int(k)
        self.edges = (pieces[:-1, None] + plen[:, None] * np.arange(self.k) / self.k).ravel()
        self.edges = np.append(self.edges, pieces[-1])
        self.lens = np.repeat(plen / self.k, self.k)

    def _coefficients(self, orders):
        # c_j = (2/G) Σ_g f(x_g) cos(j θ_g), θ_g = π (2g + 1)/(2G): (pieces, orders, entries)
        G = self.G
        basis = (2.0 / G) * np.cos(np.outer(orders, np.pi * (2 * np.arange(G) + 1) / (2 * G)))
        return np.einsum('jg,sge->sje', basis, self.values)

    def tail(self):
        """Largest of the last two Chebyshev coefficients of A and B over the pieces.

        Relative to the largest |A| (A's entries) and |B| (B's entries); the
        interpolation error of A and B is about this size.
        """
        n = self.n
        coef = np.abs(self._coefficients(np.arange(self.G - 2, self.G))).max(axis=1)
        coef = coef.reshape(len(coef), n, -1)
        vals = np.abs(self.values).reshape(-1, n, coef.shape[2])
        out = 0.0
        for part in (slice(0, n), slice(n, None)):
            size = vals[:, :, part].max(initial=0.0)
            if size > 0:
                out = max(out, float(coef[:, :, part].max() / size))
        return out

    def cell_tails(self):
        """Per cell: its piece's largest last Chebyshev coefficient (absolute), shape (N,)."""
        tails = np.abs(self._coefficients([self.G - 1])[:, 0]).max(axis=1)
        return np.repeat(tails, self.k)

    def cell_norms(self):
        """Per cell: the largest |entry| of A on its piece, shape (N,)."""
        n = self.n
        vals = self.values.reshape(len(self.values), self.G, n, n + self.m)[..., :n]
        return np.repeat(np.abs(vals).max(axis=(1, 2, 3)), self.k)

    def interval_data(self, fractions, nsub, cells=None):
        """(Φ, W, Z) of the sub-intervals ``[x_k, x_{k+1}]`` of the cells.

        Sixth-order Magnus steps (module notes), `nsub` per sub-interval.

        Parameters
        ----------
        fractions : ndarray, shape (D + 1,)
            Increasing fractions of the cell length, from 0 to 1.
        nsub : int
            Magnus steps per sub-interval.
        cells : ndarray of int, optional
            The cells (default: all).

        Returns
        -------
        Phi : ndarray, shape (N, D, n, n)
        W, Z : ndarray, shape (N, D, n, m)
        """
        n, m = self.n, self.m
        d = n + 2 * m
        cells = np.arange(len(self.lens)) if cells is None else np.asarray(cells)
        D = len(fractions) - 1
        # Gauss points of every step of every sub-interval, as cell fractions
        width = np.diff(fractions)                                      # (D,)
        sub = (np.arange(nsub)[:, None] + _GAUSS3) / nsub               # (nsub, 3)
        frac = fractions[:-1, None, None] + width[:, None, None] * sub  # (D, nsub, 3)
        # as fractions of the pieces, for the k positions of a cell in its piece
        Q = D * nsub * 3
        at = (np.arange(self.k)[:, None] + frac.ravel()) / self.k      # (k, Q)
        P = barycentric_matrix(at.ravel(), self.nodes, self.weights).reshape(self.k, Q, -1)
        sigma = np.broadcast_to(sub, frac.shape).ravel()
        ratio = None if self.scale is None else self.scale[None, :] / self.scale[:, None]
        Nc = len(cells)
        Phi = np.empty((Nc, D, n, n))
        W, Z = np.empty((Nc, D, n, m)), np.empty((Nc, D, n, m))
        chunk = max(1, _CHUNK_ENTRIES // (Q * d * d))
        with small_blas(d):
            for c0 in range(0, Nc, chunk):
                sel = cells[c0:c0 + chunk]
                k = len(sel)
                vals = (P[sel % self.k] @ self.values[sel // self.k]).reshape(k, Q, n, n + m)
                M = np.empty((k, Q, n, d))
                M[..., :n + m] = vals
                M[..., n + m:] = sigma[:, None, None] * vals[..., n:]
                if ratio is not None:
                    M *= ratio[:n]
                delta = self.lens[sel, None, None] * width[:, None] / nsub      # (k, D, 1)
                if n <= _ENTRYWISE_STATES:
                    # entry by entry: (3, n, d, steps)
                    M = np.ascontiguousarray(M.reshape(-1, 3, n, d).transpose(1, 2, 3, 0))
                    delta = np.broadcast_to(delta, (k, D, nsub)).ravel()
                    Omega = _magnus6(M[0], M[1], M[2], delta, entrywise=True)
                    E = np.moveaxis(_expm_small(Omega, entrywise=True), -1, 0)
                else:
                    M = M.reshape(k, D, nsub, 3, n, d)
                    Omega = _magnus6(M[:, :, :, 0], M[:, :, :, 1], M[:, :, :, 2],
                                     delta[..., None, None])
                    E = _expm_small(Omega.reshape(-1, n, d))
                if nsub > 1:
                    full = np.zeros((len(E), d, d))
                    full[:, :n] = E
                    full[:, n:, n:] = np.eye(d - n)
                    E = _tree_product(full.reshape(k * D, nsub, d, d))[:, :n]
                E = E.reshape(k, D, n, d)
                if ratio is not None:
                    E *= self.scale[:n, None] / self.scale[None, :]
                Phi[c0:c0 + k] = E[..., :n, :n]
                W[c0:c0 + k] = E[..., :n, n:n + m]
                # Z = δ Γ1 (δ the sub-interval's length)
                Z[c0:c0 + k] = E[..., :n, n + m:] * (self.lens[sel, None] * width)[..., None,
                                                                                   None]
        return Phi, W, Z


def lobatto(D):
    """Chebyshev-Lobatto fractions of [0, 1] (symmetric) and their barycentric weights.

    Examples
    --------
    >>> from ltpcontrol._core.celldata import lobatto
    >>> x, w = lobatto(2)
    >>> x, w
    (array([0. , 0.5, 1. ]), array([ 0.5, -1. ,  0.5]))
    """
    k = np.arange(D + 1)
    return 0.5 - 0.5 * np.cos(np.pi * k / D), (-1.0) ** k * np.where(k % D == 0, 0.5, 1.0)


def interpolate(table, frac, cells, xi):
    """Values at the fractions `xi` of cells `cells` of a table (cells, D+1, ...).

    Barycentric interpolation at the Chebyshev-Lobatto fractions `frac`;
    `table` is an array or a tuple of arrays with the same two leading axes.

    Examples
    --------
    >>> from ltpcontrol._core.celldata import interpolate, lobatto
    >>> frac, _ = lobatto(4)
    >>> table = (frac ** 3)[None, :]                 # one cell, values of x³
    >>> interpolate(table, frac, np.array([0, 0]), np.array([0.5, 0.1]))
    array([0.125, 0.001])
    """
    single = not isinstance(table, tuple)
    parts = (table,) if single else table
    D = len(frac) - 1
    _, weights = lobatto(D)
    w = barycentric_matrix(np.clip(xi, 0.0, 1.0), frac, weights)          # (S, D+1)
    sizes = [int(np.prod(v.shape[2:])) for v in parts]
    flat = np.concatenate([v.reshape(v.shape[0], D + 1, -1) for v in parts], axis=2) \
        if len(parts) > 1 else parts[0].reshape(parts[0].shape[0], D + 1, -1)
    out = np.empty((len(xi), flat.shape[2]))
    if len(xi) * (D + 1) * flat.shape[2] <= 2 ** 22:
        # gather the cells' values: one product per sample
        np.matmul(w[:, None, :], flat[cells], out=out[:, None, :])
    else:
        # one matrix product per cell on the sorted samples
        order = np.argsort(cells, kind='stable')
        cs, ws = cells[order], w[order]
        bounds = np.flatnonzero(np.diff(cs)) + 1
        starts, ends = np.concatenate([[0], bounds]), np.concatenate([bounds, [len(cs)]])
        sorted_out = np.empty_like(out)
        for a, b in zip(starts, ends):
            if b > a:
                np.matmul(ws[a:b], flat[cs[a]], out=sorted_out[a:b])
        out[order] = sorted_out
    res = tuple(q.reshape((len(xi),) + v.shape[2:])
                for q, v in zip(np.split(out, np.cumsum(sizes)[:-1], axis=1), parts))
    return res[0] if single else res


class CellTable:
    """Data of the cells of one period and of their first and last parts.

    ``edges`` (N + 1,) and ``lens`` (N,) of the cells, phases counted from
    ``offset`` (cell j is ``[offset + e_j, offset + e_{j+1}]`` modulo the
    period), ``frac`` the Chebyshev-Lobatto fractions of the part lengths,
    ``fwd`` and ``bwd`` the tuples (Φ, W, Z) of ``[e_j, e_j + ℓ_i]`` and
    ``[e_{j+1} - ℓ_i, e_{j+1}]``, ``ℓ_i = frac_i lens_j``, each of shape
    (N, D + 1, ...); ``fwd[q][:, -1]`` are the whole cells.

    Examples
    --------
    >>> from ltpcontrol._core.celldata import CellTable, lobatto
    >>> frac, _ = lobatto(2)
    >>> P = np.exp(-frac)[None, :, None, None]          # ẋ = -x on the cell [0, 1]
    >>> W = Z = np.zeros((1, 3, 1, 1))
    >>> table = CellTable(np.array([0.0, 1.0]), np.array([1.0]), frac, (P, W, Z), (P, W, Z))
    >>> bool(table.first(np.array([0]), np.array([1.0]))[0][0, 0, 0] == np.exp(-1.0))
    True
    >>> C = table.coefficients(P)                       # e^{-ξ} in Chebyshev polynomials
    >>> T = table.basis(np.array([0.25]), np.array([0]))
    >>> bool(abs(np.einsum('ks,k->s', T, C[0, :, 0, 0])[0] - np.exp(-0.25)) < 0.01)
    True
    """

    def __init__(self, edges, lens, frac, fwd, bwd, offset=0.0):
        self.edges, self.lens, self.frac, self.fwd, self.bwd = edges, lens, frac, fwd, bwd
        self.offset = float(offset)
        # node values -> Chebyshev coefficients of the degree-D interpolant
        self._to_coeffs = np.linalg.inv(_chebyshev_basis(2 * frac - 1, len(frac)).T)

    def basis(self, length, j):
        """Chebyshev polynomials ``T_k(2ξ - 1)`` (D + 1, S), ξ = `length` / (cell j's length)."""
        xi = np.clip(length / self.lens[j], 0.0, 1.0)
        return _chebyshev_basis(2 * xi - 1, len(self.frac))

    def coefficients(self, values, reverse=False, out=None):
        """Chebyshev coefficients in ξ of a table (N, D + 1, ...) at the lengths.

        With `reverse` those of the table read at ``1 - ξ`` (the last parts'
        data at the first part's length: ``T_k(-s) = (-1)^k T_k(s)``).  With
        `out` (same shape, any strides) they are written there; a large
        table order by order, with no temporary of its size.
        """
        N, D1 = values.shape[:2]
        M = self._to_coeffs
        if reverse:
            M = M * ((-1.0) ** np.arange(D1))[:, None]
        if out is not None and values.size > _CHUNK_ENTRIES:
            for k in range(D1):
                np.multiply(values[:, 0], M[k, 0], out=out[:, k])
                for i in range(1, D1):
                    out[:, k] += M[k, i] * values[:, i]
            return out
        flat = np.ascontiguousarray(values).reshape(N, D1, -1)
        coeffs = np.matmul(M, flat).reshape(values.shape)                     # (N, D+1, ...)
        if out is None:
            return coeffs
        out[...] = coeffs
        return out

    def first(self, j, length, parts=(0, 1, 2)):
        """(Φ, W, Z) (or the `parts` asked for) of ``[e_j, e_j + length]``."""
        rows = np.arange(len(j))
        return interpolate(tuple(self.fwd[q][j] for q in parts), self.frac, rows,
                           length / self.lens[j])

    def last(self, j, length, parts=(0, 1, 2)):
        """(Φ, W, Z) (or the `parts` asked for) of ``[e_{j+1} - length, e_{j+1}]``."""
        rows = np.arange(len(j))
        return interpolate(tuple(self.bwd[q][j] for q in parts), self.frac, rows,
                           length / self.lens[j])


def _chebyshev_basis(s, K, out=None):
    """``T_k(s)`` for k < K at the points s of [-1, 1] (any shape), shape (K,) + s.shape."""
    if out is None:
        out = np.empty((K,) + np.shape(s))
    out[0] = 1.0
    if K > 1:
        out[1] = s
    two_s = 2 * s
    for k in range(2, K):
        np.multiply(two_s, out[k - 1], out=out[k])
        out[k] -= out[k - 2]
    return out
