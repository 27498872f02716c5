"""Eigenvectors of a cyclic product from its periodic (block) Schur form.

For factors ``F_0, ..., F_{M-1}`` (applied first to last, e.g. the step
transition matrices of a period, or their graded forms of `graded.py`) the
Floquet vectors are the periodic solutions of

    F_k y_k = c_k y_{k+1},   y_M = y_0,   Π_k c_k = μ,

one per eigenvalue μ of ``Π = F_{M-1} ... F_0``.  The QR sweeps of
`periodic_schur` give orthogonal ``Q_k`` with ``F_k Q_k = Q_{k+1} R_k``
(R_k upper triangular) and ``W = Q_0ᵀ Q_M``; in the coordinates ``y_k =
Q_kᵀ x_k`` the factors ``R_0, ..., R_{M-2}, W R_{M-1}`` are block upper
triangular once W is, to working precision relative to each row (graded
rows are compared with their own size), with blocks of eigenvalues whose
moduli the sweeps did not separate.  Then, with no product formed across
blocks:

* each diagonal block's product is formed with a normalisation at every
  factor (its eigenvalues have moduli within ``e^8`` of each other, so
  nothing is lost) and diagonalised: its part of the vectors is the block
  eigenvector propagated through the block's factors;
* the rows of every earlier block follow by back-substitution, a cyclic
  affine recurrence per step solved in the direction in which it
  contracts (backwards in time when the earlier block's multipliers are
  the larger ones, as in the ordered form of a stiff system), closed by
  one small Stein equation through the Schur form of the earlier block's
  product.

The cost is O(M n³) for all n vectors (the same order as the sweeps) and
the memory O(M n w) for w vectors at a time, chunked.  A multiplier far
below the others (a stiff mode, ``e^{-6e4}``) is never formed: its
vector's rows are scaled per step by its own block, so they keep their
relative accuracy.
"""

import numpy as np
import scipy.linalg as la

from .threads import small_blas

__all__ = []

#: row-relative couplings of W below this are always neglected (block triangular)
_SPLIT_TOL = 1e-14
#: largest spread of log-moduli inside a block whose product is formed
_BLOCK_SPREAD = 8.0
#: entries of the working array of one chunk of vectors (complex)
_CHUNK_ENTRIES = 2 ** 22


def schur_sweeps(F, keep=(), max_sweeps=None):
    """QR sweeps until the cyclic factors are block triangular to working precision.

    Returns ``(R, Q, blocks)``: the factors in Schur coordinates (R[k]
    upper triangular for ``k < M-1``, ``R[M-1] = W R_{M-1}`` block upper
    triangular), the orthogonal bases ``Q_k`` at the indices `keep` (dict)
    and the diagonal blocks ``(start, stop)``.

    Examples
    --------
    Multipliers about 1 and 1e-12 are split into two blocks:

    >>> from ltpcontrol._core.periodic_vectors import schur_sweeps
    >>> F = np.array([[[1.0, 1.0], [1e-6, 1e-4]]] * 3)
    >>> R, Q, blocks = schur_sweeps(F, keep=[0])
    >>> blocks
    [(0, 1), (1, 2)]
    >>> P = np.linalg.multi_dot(F[::-1])
    >>> bool(np.allclose(Q[0].T @ P @ Q[0], np.linalg.multi_dot(R[::-1])))
    True
    """
    M, n = F.shape[0], F.shape[1]
    if max_sweeps is None:
        max_sweeps = 60 if n <= 48 else 12
    keep = set(int(k) for k in keep) | {0}
    R = np.empty_like(F)
    Q0 = np.eye(n)
    with small_blas(n):
        for sweep in range(max_sweeps):
            Q, saved = Q0, {}
            for k in range(M):
                if k in keep:
                    saved[k] = Q
                Q, R[k] = np.linalg.qr(F[k] @ Q)
            W = Q0.T @ Q
            with np.errstate(divide='ignore'):
                d = np.sum(np.log(np.abs(np.diagonal(R, axis1=1, axis2=2))), axis=0) \
                    + np.log(np.abs(np.diag(W)))
            last = W @ R[-1]
            blocks = _partition(last, d)
            spread = max(float(np.ptp(d[a:b])) if np.all(np.isfinite(d[a:b])) else np.inf
                         for a, b in blocks)
            if spread <= _BLOCK_SPREAD or sweep + 1 == max_sweeps:
                break
            Q0 = Q
    R[-1] = last
    return R, saved, blocks


def _partition(last, d):
    """Blocks of the last factor, split where the couplings below are negligible per row.

    A coupling c of W (relative to its row of the last factor, whose rows
    are graded) perturbs one factor by c; a merged block forms its product
    and loses about ``1e-16 e^{gap}`` on its smaller multipliers (gap: the
    difference of log-moduli ``d`` across the split).  Split when ``c <=
    max(1e-14, min(1e-8, 1e-15 e^{gap}))``.
    """
    n = len(last)
    rowscale = np.abs(last).max(axis=1)
    rel = np.abs(np.tril(last, -1)) / np.where(rowscale > 0, rowscale, 1.0)[:, None]
    # below[i, j] = max_{r >= i} rel[r, j];  top[i] = max d[i:]
    below = np.maximum.accumulate(rel[::-1], axis=0)[::-1]
    top = np.maximum.accumulate(d[::-1])[::-1]
    blocks, start = [], 0
    for split in range(1, n + 1):
        if split < n:
            gap = float(d[start:split].min()) - float(top[split])
            gap = 0.0 if gap != gap else gap
            limit = max(_SPLIT_TOL, min(1e-8, 1e-15 * np.exp(min(gap, 700.0))))
            if float(below[split, start:split].max()) > limit:
                continue
        blocks.append((start, split))
        start = split
    return blocks


class _Block:
    """One diagonal block: step scales, normalised product, its eigen and Schur forms."""

    def __init__(self, R, a, b, keep=()):
        self.a, self.b = a, b
        M, m = R.shape[0], b - a
        logsig = np.empty(M)
        P = np.eye(m)
        #: normalised running products at the kept indices (``y_k = P_k s``)
        self.kept = {}
        for k in range(M):
            if k in keep:
                self.kept[k] = P.copy()
            P = R[k, a:b, a:b] @ P
            s = float(np.abs(P).max())
            if not s > 0 or not np.isfinite(s):
                raise np.linalg.LinAlgError("singular factor: no periodic vectors")
            P /= s
            logsig[k] = np.log(s)
        self.logsig, self.logscale = logsig, float(logsig.sum())
        self.cumlog = np.concatenate([[0.0], np.cumsum(logsig)[:-1]])
        mu, S = la.eig(P)
        self.mu, self.S = mu, S / np.linalg.norm(S, axis=0)
        self.T, self.Z = la.schur(P.astype(complex), output='complex')
        with np.errstate(divide='ignore'):
            self.logmod = np.log(np.abs(mu)) + self.logscale
        self.arg = np.angle(mu)
        self.arg[(mu.imag == 0) & (mu.real < 0)] = np.pi

    def solve(self, R, k, rhs):
        """``F^k_bb⁻¹ rhs`` (triangular but for the last factor)."""
        a, b = self.a, self.b
        if b - a == 1:
            return rhs / R[k, a, a]
        if k < len(R) - 1:
            solve = lambda x: la.solve_triangular(R[k, a:b, a:b], x, check_finite=False)
        else:
            solve = lambda x: np.linalg.solve(R[k, a:b, a:b], x)
        # real factor, complex right-hand side: two real solves
        return solve(rhs.real) + 1j * solve(rhs.imag)


def cyclic_eigenvectors(F, keep, bases=None):
    """All eigenvalues and periodic-form eigenvectors of a cyclic product.

    Parameters
    ----------
    F : ndarray, shape (M, n, n)
        Real factors applied first to last.
    keep : sequence of int
        Step indices (``0 <= k < M``) at which the vectors are wanted.
    bases : dict, optional
        ``{k: B_k}``: the vectors are ``B_k x_k`` at the kept indices (the
        change of coordinates of graded factors), default the identity.

    Returns
    -------
    logmod, arg : ndarray, shape (n,)
        ``log|μ|`` and ``arg μ`` of every eigenvalue, in block order.
    vectors : ndarray of complex, shape (n, len(keep), n)
        ``vectors[i, s]`` is ``x_{keep[s]}`` of eigenvalue i, scaled so
        that ``F_k x_k = e^{ℓ_k} x_{k+1}``; NaN for an eigenvalue repeated
        across blocks of the Schur form (a defective multiplier).
    logscales : ndarray, shape (n, len(keep))
        ``Σ_{j < keep[s]} ℓ_j`` of each vector: ``x_k e^{logscales}`` is the
        vector propagated by the factors from ``x_0``.

    Examples
    --------
    >>> from ltpcontrol._core.periodic_vectors import cyclic_eigenvectors
    >>> F = np.array([[[2.0, 1.0], [0.5, 1.0]], [[1.0, 0.0], [1.0, 3.0]]])
    >>> logmod, arg, V, _ = cyclic_eigenvectors(F, [0])
    >>> P = F[1] @ F[0]
    >>> mu = np.exp(logmod) * np.exp(1j * arg)
    >>> bool(np.allclose(P @ V[:, 0].T, V[:, 0].T * mu))
    True
    """
    F = np.asarray(F, float)
    M, n = F.shape[0], F.shape[1]
    keep = [int(k) for k in keep]
    R, Q, blocks = schur_sweeps(F, keep)
    # the first block's vectors are needed at the kept indices only
    blk = [_Block(R, a, b, set(keep) if i == 0 else ()) for i, (a, b) in enumerate(blocks)]
    owner = np.concatenate([[i] * (b - a) for i, (a, b) in enumerate(blocks)]).astype(int)
    logmod = np.concatenate([B.logmod for B in blk])
    arg = np.concatenate([B.arg for B in blk])
    vectors = np.empty((n, len(keep), n), complex)
    logscales = np.empty((n, len(keep)))
    C = {k: Q[k] if bases is None else bases[k] @ Q[k] for k in keep}
    width = max(1, _CHUNK_ENTRIES // (M * n))
    with small_blas(n):
        for c0 in range(0, n, width):
            cols = np.arange(c0, min(n, c0 + width))
            Y = _chunk(R, blk, owner, cols, logmod, arg)
            rows = blk[owner[cols[-1]]].b
            for s, k in enumerate(keep):
                vectors[cols, s] = _rmul(C[k][:, :rows], Y[k, :rows]).T
            for j in cols:
                logscales[j] = blk[owner[j]].cumlog[keep]
    return logmod, arg, vectors, logscales


def _chunk(R, blk, owner, cols, logmod, arg):
    """Vectors of the columns `cols` at every step, Schur coordinates (M, rows, w)."""
    M = R.shape[0]
    rows = blk[owner[cols[-1]]].b
    Y = np.zeros((M, rows, len(cols)), complex)
    # the own block's part: block eigenvector propagated through the block
    for bi in np.unique(owner[cols]):
        B = blk[bi]
        sel = np.flatnonzero(owner[cols] == bi)
        y = B.S[:, cols[sel] - B.a].astype(complex)
        if bi == 0:
            # no earlier block needs them at every step
            for k, P in B.kept.items():
                Y[k, B.a:B.b][:, sel] = _rmul(P, y)
            continue
        for k in range(M):
            Y[k, B.a:B.b][:, sel] = y
            y = _rmul(R[k, B.a:B.b, B.a:B.b], y) / np.exp(B.logsig[k])
    # earlier blocks, last to first
    for ai in range(owner[cols[-1]] - 1, -1, -1):
        A_ = blk[ai]
        sel = np.flatnonzero(owner[cols] > ai)
        if sel.size == 0:
            continue
        a, b = A_.a, A_.b
        top = blk[owner[cols[sel[-1]]]].b
        f = _rmul(R[:, a:b, b:top], Y[:, b:top][:, :, sel])              # (M, m, w)
        sig = np.exp(np.array([blk[owner[cols[j]]].logsig for j in sel]).T)   # (M, w)
        lm, ag = logmod[cols[sel]], arg[cols[sel]]
        amin, amax = A_.logmod.min(), A_.logmod.max()
        backward = (lm < amin) | ((lm <= amax) & (lm < 0.5 * (amin + amax)))
        for direction in (True, False):
            part = np.flatnonzero(backward == direction)
            if part.size == 0:
                continue
            Y[:, a:b, sel[part]] = _earlier(R, A_, f[:, :, part], sig[:, part], lm[part],
                                            ag[part], [blk[owner[cols[j]]].logscale
                                                       for j in sel[part]], direction)
    return Y


def _rmul(F, Y):
    """``F @ Y`` for real F and complex Y as two real products (half the flops)."""
    return np.matmul(F, Y.real) + 1j * np.matmul(F, Y.imag)


def _tri_solve(T, rhs):
    """Upper triangular solve; NaN when singular (a multiplier repeated across blocks)."""
    try:
        return la.solve_triangular(T, rhs, check_finite=False)
    except np.linalg.LinAlgError:
        return np.full(len(rhs), np.nan, complex)


def _earlier(R, A_, f, sig, lm, ag, scale_b, backward):
    """Rows of an earlier block: the cyclic affine recurrence, in its contracting direction.

    ``F^k_aa y_k + f_k = σ_k y_{k+1}``, ``y_M = d y_0`` with d the column's
    normalised multiplier ``μ / Π σ``.
    """
    M = R.shape[0]
    m, w = f.shape[1], f.shape[2]
    d = np.exp(lm - np.asarray(scale_b)) * np.exp(1j * ag)
    out = np.empty((M, m, w), complex)
    y = np.zeros((m, w), complex)
    if backward:
        # y_k = F_aa⁻¹ (σ_k y_{k+1} - f_k): the particular solution from y_M = 0
        for k in range(M - 1, -1, -1):
            y = A_.solve(R, k, y * sig[k] - f[k])
        # (I - d Λ) y_0 = α_0, Λ = Π σ / P_a  ⇔  (P̃_a - e I) y_0 = P̃_a α_0
        with np.errstate(under='ignore'):
            e = np.exp(np.minimum(lm - A_.logscale, 700.0)) * np.exp(1j * ag)
        rhs = A_.Z.conj().T @ y
        y0 = np.empty_like(y)
        for j in range(w):
            y0[:, j] = A_.Z @ _tri_solve(A_.T - e[j] * np.eye(m), A_.T @ rhs[:, j])
        y = y0 * d
        for k in range(M - 1, -1, -1):
            y = A_.solve(R, k, y * sig[k] - f[k])
            out[k] = y
        return out
    # forward: y_{k+1} = (F_aa y_k + f_k) / σ_k, from y_0 = 0 to β_M
    a, b = A_.a, A_.b
    for k in range(M):
        y = (_rmul(R[k, a:b, a:b], y) + f[k]) / sig[k]
    # d y_0 = c P̃_a y_0 + β_M, c = Π σ_a / Π σ_b  ⇔  (I - P̃_a / e) y_0 = β_M / d
    with np.errstate(under='ignore', over='ignore'):
        inv_e = np.exp(np.minimum(A_.logscale - lm, 700.0)) * np.exp(-1j * ag)
    rhs = A_.Z.conj().T @ (y / d)
    y = np.empty_like(rhs)
    for j in range(w):
        y[:, j] = A_.Z @ _tri_solve(np.eye(m) - A_.T * inv_e[j], rhs[:, j])
    for k in range(M):
        out[k] = y
        y = (_rmul(R[k, a:b, a:b], y) + f[k]) / sig[k]
    return out
