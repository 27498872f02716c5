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
their values at the Gauss points of the fourth-order Magnus sub-steps

    Ω = δ/2 (M1 + M2) + √3/12 δ² [M2, M1],   M = [[A, B, σB], [0, 0, 0], [0, 0, 0]]

(``σ = (τ - a)/(b - a)``) come from the piece's polynomial interpolant:
one matrix product per cell position, since the Gauss points sit at the
same fractions of every piece.  The number of calls of A and B is G per
piece, whatever the cells, degrees and sub-steps.  Both sub-step counts
m/2 and m are integrated and Richardson-extrapolated, as the adaptive
integrator does.

`CellSamples.tail` measures how well the interpolant resolves A and B on
every piece (the last Chebyshev coefficients, relative to the largest
value); the caller checks the resulting data against the adaptive
integrator of ``_core/transition.py`` at probe intervals.
"""

import numpy as np

from .memory import check_allocation
from .threads import small_blas
from .transition import _balancing, _tree_product, expm_batch

__all__ = []

_C1, _C2 = 0.5 - np.sqrt(3) / 6, 0.5 + np.sqrt(3) / 6
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
    cells costs G calls of A and B.

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

    def __init__(self, A, B, pieces, k, G):
        pieces = np.asarray(pieces, float)
        self.A, self.B, self.G, self.pieces = A, B, int(G), pieces
        self.n, self.m = A.shape[0], B.shape[1]
        plen = np.diff(pieces)
        self.refine(k)
        self.nodes, self.weights = chebyshev_first_kind(self.G)
        tau = (pieces[:-1, None] + plen[:, None] * self.nodes).ravel()
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
            size = vals[:, :, part].max()
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

    def interval_data(self, fractions, nsub, cells=None, extrapolate=True):
        """(Φ, W, Z) of the sub-intervals ``[x_k, x_{k+1}]`` of the cells.

        Parameters
        ----------
        fractions : ndarray, shape (D + 1,)
            Increasing fractions of the cell length, from 0 to 1.
        nsub : int
            Magnus sub-steps per sub-interval.
        cells : ndarray of int, optional
            The cells (default: all).
        extrapolate : bool
            Also integrate with half the sub-steps and return the
            Richardson-extrapolated value ``E + (E - E_half)/15`` (the
            error of a fourth-order step scales as its length to the fifth),
            as the adaptive integrator does; costs no more calls of A or B.

        Returns
        -------
        Phi : ndarray, shape (N, D, n, n)
        W, Z : ndarray, shape (N, D, n, m)
        """
        n, m = self.n, self.m
        d = n + 2 * m
        cells = np.arange(len(self.lens)) if cells is None else np.asarray(cells)
        D = len(fractions) - 1
        # Gauss points of every sub-step of every sub-interval, as cell fractions
        width = np.diff(fractions)                                      # (D,)
        counts = (nsub // 2, nsub) if extrapolate and nsub > 1 else (nsub,)
        # sub-steps of all resolutions side by side: nsub / 2 then nsub
        sub = np.concatenate([(np.arange(c)[:, None] + np.array([_C1, _C2])) / c
                              for c in counts])                          # (S, 2)
        frac = fractions[:-1, None, None] + width[:, None, None] * sub  # (D, S, 2)
        S = len(sub)
        # as fractions of the pieces, for the k positions of a cell in its piece
        Q = D * S * 2
        at = (np.arange(self.k)[:, None] + frac.ravel()) / self.k              # (k, Q)
        P = barycentric_matrix(at.ravel(), self.nodes, self.weights).reshape(self.k, Q, -1)
        sigma = np.broadcast_to(sub, frac.shape).ravel()
        # the step length of every sub-step, relative to its sub-interval
        rel = np.concatenate([np.full(c, 1.0 / c) for c in counts])
        ratio = None if self.scale is None else self.scale[None, :] / self.scale[:, None]
        Nc = len(cells)
        Phi = np.empty((Nc, D, n, n))
        W, Z = np.empty((Nc, D, n, m)), np.empty((Nc, D, n, m))
        chunk = max(1, _CHUNK_ENTRIES // (D * S * 2 * d * d))
        with small_blas(d):
            for c0 in range(0, Nc, chunk):
                sel = cells[c0:c0 + chunk]
                k = len(sel)
                vals = (P[sel % self.k] @ self.values[sel // self.k]).reshape(k, Q, n, n + m)
                M = np.zeros((k, Q, d, d))
                M[..., :n, :n + m] = vals
                M[..., :n, n + m:] = sigma[:, None, None] * vals[..., n:]
                if ratio is not None:
                    M *= ratio
                M = M.reshape(k, D, S, 2, d, d)
                M1, M2 = M[:, :, :, 0], M[:, :, :, 1]
                delta = (self.lens[sel, None, None] * width[:, None] * rel)[..., None, None]
                Omega = 0.5 * delta * (M1 + M2) + (np.sqrt(3) / 12) * delta ** 2 * (
                    M2 @ M1 - M1 @ M2)
                E = expm_batch(Omega.reshape(-1, d, d)).reshape(k * D, S, d, d)
                if len(counts) == 2:
                    half = _tree_product(E[:, :counts[0]])
                    E = _tree_product(E[:, counts[0]:])
                    E += (E - half) / 15
                else:
                    E = _tree_product(E)
                E = E.reshape(k, D, d, d)
                if ratio is not None:
                    E *= self.scale[:, None] / self.scale[None, :]
                Phi[c0:c0 + k] = E[..., :n, :n]
                W[c0:c0 + k] = E[..., :n, n:n + m]
                # Z = δ Γ1 (δ the sub-interval's length)
                Z[c0:c0 + k] = E[..., :n, n + m:] * (self.lens[sel, None] * width)[..., None,
                                                                                   None]
        return Phi, W, Z
