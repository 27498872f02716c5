"""Eigenvalues of a product of matrices without forming the product.

For factors ``F_0, F_1, ..., F_{K-1}`` (applied first to last) the product
``Π = F_{K-1} ... F_1 F_0`` is brought to a periodic (block) Schur form by
the QR iteration on the factor sequence (the product QR or discrete QR
method): starting from ``Q_0``, ``F_k Q_k = Q_{k+1} R_k`` (QR of each
factor in turn), so that

    Π = Q_K R_{K-1} ... R_0 Q_0ᵀ,   Q_0ᵀ Π Q_0 = W R_{K-1} ... R_0,  W = Q_0ᵀ Q_K,

and the sweep is repeated with ``Q_0 ← Q_K``.  Sweeps converge to the
Schur vectors of ``Π`` at the rate of the ratios of successive eigenvalue
moduli per sweep, so eigenvalues of very different size separate after a
few sweeps: W becomes block upper triangular and each eigenvalue of a
1x1 block is a product of diagonal entries, evaluated as a sum of logarithms

    log|μ_i| = log|w_ii| + Σ_k log|(R_k)_ii|.

Eigenvalues of similar size (complex pairs, clusters) that do not separate
stay in one diagonal block, whose product is formed with a normalisation
at every factor.  No entry of ``Π`` is formed, each QR step is backward
stable for its factor, and so eigenvalues far below machine precision
relative to the largest one (stiff flows, long orbits) keep their relative
accuracy; moduli below the smallest float are still returned as finite
log-moduli.
"""

import math
import warnings

import numpy as np
from control.exception import ControlDimension

from .threads import small_blas

__all__ = ['product_eigenvalues']


def product_eigenvalues(factors, *, error=False, rank_tol=None):
    """Eigenvalues of ``F_{K-1} ... F_1 F_0`` in log form, by periodic Schur.

    Parameters
    ----------
    factors : sequence of array_like, or array_like of shape (K, n, n)
        Real square factors of the same size, applied first to last (the
        first factor acts first, as the transition matrices of successive
        steps).  At least one factor.
    error : bool, optional
        Also return the estimated error (keyword only, default False).
    rank_tol : float, optional
        Singular values of a factor below ``rank_tol σ_max`` count as zero:
        the product then has as many exact zero eigenvalues (``-inf``
        log-moduli), which are not left as rounding noise.  Use it when
        factors are well conditioned unless genuinely singular (a reset
        that removes a dimension); by default (None) no factor is rank
        reduced, and tiny singular values of graded factors are kept.

    Returns
    -------
    logmod : ndarray, shape (n,)
        ``log|μ_i|`` (``-inf`` for a zero eigenvalue), sorted by decreasing
        value.
    arg : ndarray, shape (n,)
        ``arg μ_i`` in ``(-π, π]``: 0 or π for real eigenvalues; complex
        conjugate pairs are adjacent with the positive argument first.
    err : float
        Only with ``error=True``: estimated error of ``log|μ_i|`` relative
        to ``1 + |log|μ_i||`` (so ``err (1 + |log|μ||)`` bounds the relative
        error of μ), from the changes over the last QR sweeps: rounding
        noise of an ill-conditioned product, or convergence not yet
        complete.

    Raises
    ------
    ControlDimension
        If the factors are not square matrices of one size.
    ValueError
        If there is no factor or an entry is not finite.

    Warns
    -----
    UserWarning
        When the estimated relative error of a μ exceeds 1e-6.

    Notes
    -----
    Each QR step is backward stable for its factor, so each eigenvalue is
    as accurate as the factors allow relative to its own size, not to the
    largest eigenvalue.  Sweeps stop when the eigenvalues settle to 1e-13
    or stop improving (at most 60 sweeps); eigenvalues of equal modulus
    (complex pairs) share one diagonal block.

    Examples
    --------
    Two factors whose product has the eigenvalues 1 and 1e-300 (the product
    formed in floating point loses the small one):

    >>> from ltpcontrol._core.periodic_schur import product_eigenvalues
    >>> F0 = np.array([[1.0, 1.0], [0.0, 1e-150]])
    >>> F1 = np.array([[1.0, 0.0], [1.0, 1e-150]])
    >>> logmod, arg = product_eigenvalues([F0, F1])
    >>> np.round(logmod / np.log(10), 10) + 0.0, arg
    (array([   0., -300.]), array([0., 0.]))

    A rotation by 0.3 applied twice has the eigenvalues ``e^{±0.6j}``:

    >>> c, s = np.cos(0.3), np.sin(0.3)
    >>> logmod, arg = product_eigenvalues([[[c, -s], [s, c]]] * 2)
    >>> np.round(logmod, 12) + 0.0, np.round(arg, 12)
    (array([0., 0.]), array([ 0.6, -0.6]))
    """
    H = np.asarray(factors, dtype=float)
    if H.ndim == 2:
        H = H[None]
    if H.ndim != 3 or H.shape[1] != H.shape[2]:
        raise ControlDimension(f"factors must be square matrices of one size, got an array "
                               f"of shape {H.shape}")
    if H.shape[0] == 0:
        raise ValueError("factors must contain at least one matrix")
    if not np.all(np.isfinite(H)):
        raise ValueError("factors must be finite")
    n = H.shape[1]
    zeros = 0 if rank_tol is None or n == 0 else _rank_deficiency(H, float(rank_tol))
    # eigenvalues left by factors singular to working precision are rounding noise:
    # they are kept, but their (undetermined) moduli do not enter the error estimate
    noise = 0 if n == 0 else max(0, _rank_deficiency(H, n * np.finfo(float).eps) - zeros)
    with small_blas(n):
        logmod, arg, err = (np.zeros(0), np.zeros(0), 0.0) if n == 0 else \
            _product_qr(H, zeros, noise)
    return (logmod, arg, err) if error else (logmod, arg)


#: couplings of W above this size keep eigenvalues in one Schur block
_SPLIT_TOL = 1e-6
#: sweeps end when no log-modulus or argument changes by more than this
_SETTLE_TOL = 1e-13
#: QR sweeps: at least, at most; sweeps compared to detect a noise floor
_MIN_SWEEPS, _MAX_SWEEPS, _FLOOR_SWEEPS = 3, 60, 3
#: estimated errors of log|μ| above this are announced by a warning
_WARN_ERROR = 1e-6


def _rank_deficiency(F, tol):
    """Largest numerical rank deficiency of a factor (singular values <= tol σ_max).

    The product then has at least that many zero eigenvalues.
    """
    sv = np.linalg.svd(F, compute_uv=False)
    small = sv <= tol * sv[:, :1]
    return int(np.max(np.count_nonzero(small, axis=1)))


def _product_qr(F, zeros=0, noise=0, warn=True, min_sweeps=None):
    """Block periodic Schur form by QR sweeps: sorted (log|μ|, arg μ, error).

    The `zeros` smallest eigenvalues are exact zeros (singular factors); the
    `noise` smallest of the others are rounding noise of factors singular to
    working precision, left out of the error estimate.
    """
    n = F.shape[1]
    Q0, previous, changes = np.eye(n), None, []
    for sweep in range(_MAX_SWEEPS):
        Q, R = Q0, np.empty_like(F)
        for k, Fk in enumerate(F):
            Q, R[k] = np.linalg.qr(Fk @ Q)
        W = Q0.T @ Q
        blocks = _block_partition(W, R)
        logmod, arg = np.empty(n), np.empty(n)
        with np.errstate(divide='ignore', invalid='ignore', over='ignore', under='ignore'):
            for a, b in blocks:
                logmod[a:b], arg[a:b] = _block_eigenvalues(W[a:b, a:b], R[:, a:b, a:b])
        if zeros:
            smallest = np.lexsort((-arg, -logmod))[n - zeros:]
            logmod[smallest], arg[smallest] = -np.inf, 0.0
        changes.append(_change(previous, blocks, logmod, arg, zeros + noise))
        previous, Q0 = (blocks, logmod, arg), Q
        if sweep + 1 >= (min_sweeps or _MIN_SWEEPS) and (changes[-1] <= _SETTLE_TOL or _at_floor(changes)):
            break
    # the last changes estimate the error: rounding noise at the floor, or
    # the remaining (geometric) convergence
    recent = [c for c in changes[-_FLOOR_SWEEPS:] if np.isfinite(c)]
    error = 2 * (changes[-1] if changes[-1] <= _SETTLE_TOL else max(recent, default=np.inf))
    determined = np.sort(logmod)[zeros + noise:]
    worst = error * (1 + np.abs(determined[np.isfinite(determined)]).max(initial=0.0))
    if warn and worst > _WARN_ERROR:
        warnings.warn(f"product_eigenvalues: eigenvalue moduli are accurate only to about "
                      f"{worst:.1g} relative (ill-conditioned product or eigenvalues of close "
                      "but different moduli)", UserWarning, stacklevel=3)
    order = np.lexsort((-arg, -logmod))
    return logmod[order], arg[order], error


def _change(previous, blocks, logmod, arg, skip=0):
    """Largest change of the eigenvalues since the previous sweep (inf if the blocks changed).

    The `skip` smallest eigenvalues (zeros and rounding noise) are not compared.
    """
    if previous is None or previous[0] != blocks:
        return np.inf
    if skip:
        keep = np.zeros(len(logmod), bool)
        keep[np.argsort(logmod)[skip:]] = True
        logmod, arg = logmod[keep], arg[keep]
        previous = (previous[0], previous[1][keep], previous[2][keep])
    finite = np.isfinite(logmod) & np.isfinite(previous[1])
    if np.any(np.isfinite(logmod) != np.isfinite(previous[1])):
        return np.inf
    dlog = np.abs(logmod[finite] - previous[1][finite]) / (1 + np.abs(logmod[finite]))
    darg = np.abs(np.angle(np.exp(1j * (arg - previous[2]))))
    return float(max(dlog.max(initial=0.0), darg.max(initial=0.0)))


def _at_floor(changes):
    """The changes stopped shrinking over the last sweeps (noise floor)."""
    last = changes[-_FLOOR_SWEEPS - 1:]
    return len(last) > _FLOOR_SWEEPS and np.isfinite(last[0]) and min(last[1:]) > 0.25 * last[0]


def _block_partition(W, R):
    """Block upper triangular partition of W for the eigenvalue evaluation.

    Two groups of indices are split when the coupling ``c`` of W below
    them is negligible for what a split gains: a merged block forms its
    product and loses about ``eps e^{gap}`` relative accuracy on its
    smaller eigenvalues (gap: difference of the log-moduli of the groups),
    a split one loses about ``c`` times the non-normality of the product.
    So split when ``c <= max(1e-14, min(_SPLIT_TOL, 1e-15 e^{gap}))``.
    """
    n = len(W)
    lower = np.abs(np.tril(W, -1))
    with np.errstate(divide='ignore'):
        d = np.sum(np.log(np.abs(np.diagonal(R, axis1=1, axis2=2))), axis=0) \
            + np.log(np.abs(np.diag(W)))
    # below[i, j] = max_{r >= i} |W_rj| (lower part), top[i] = max d[i:] (NaN spreads)
    below = np.maximum.accumulate(lower[::-1], axis=0)[::-1]
    top = np.maximum.accumulate(d[::-1])[::-1]
    blocks, start = [], 0
    for split in range(1, n + 1):
        if split < n:
            # a block ends at `split` when nothing below it couples to columns before it
            coupling = float(below[split, start:split].max())
            gap = float(d[start:split].min()) - float(top[split])
            gap = 0.0 if gap != gap else gap                   # NaN: no gap
            limit = max(1e-14, min(_SPLIT_TOL, 1e-15 * math.exp(min(gap, 700.0))))
            if coupling > limit:
                continue
        blocks.append((start, split))
        start = split
    return blocks


def _block_eigenvalues(W, R):
    """Eigenvalues of ``W R_{K-1} ... R_0`` (small blocks) in log form."""
    m = len(W)
    if m == 1:
        # μ = w Π_k r_k: log|μ| = log|w| + Σ_k log|r_k|
        d = np.append(R[:, 0, 0], W[0, 0])
        negative = np.count_nonzero(d < 0) % 2
        return np.array([np.sum(np.log(np.abs(d)))]), np.array([np.pi if negative else 0.0])
    # pairwise products normalised at every level: e^{logscale} prod
    mats, logscale = np.concatenate([R, W[None]]), 0.0
    while len(mats) > 1:
        odd = mats[-1:] if len(mats) % 2 else mats[:0]
        pairs = mats[1:len(mats) - len(odd):2] @ mats[0:len(mats) - len(odd):2]
        s = np.abs(pairs).max(axis=(1, 2))
        if np.any(s == 0):
            return np.full(m, -np.inf), np.zeros(m)
        pairs /= s[:, None, None]
        logscale += float(np.sum(np.log(s)))
        mats = np.concatenate([pairs, odd])
    prod = mats[0]
    mu = np.linalg.eigvals(prod)
    arg = np.angle(mu)
    arg[(mu.imag == 0) & (mu.real < 0)] = np.pi
    logmod = np.log(np.abs(mu)) + logscale
    # a fixed order, so that successive sweeps compare
    order = np.lexsort((-arg, -logmod))
    return logmod[order], arg[order]
