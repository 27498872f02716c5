"""Well-posedness of periodic feedback loops: ``I + D(t)`` over the period.

A feedback loop whose direct feedthrough makes ``I - sign D_1(t) D_2(t)``
singular at some instant has no solution there (an algebraic loop); a
check at sample points can step over that instant.  Here the whole period
is searched: the smallest singular value is sampled densely, every sign
change of the (real) determinant between samples is located by bisection,
and the smallest sample is refined by a bounded minimisation, so an
isolated singular instant is found to machine precision.

For the margins, the real gains k that make ``I + k D(t)`` singular for
some t (``-1/k`` a real eigenvalue of ``D(t)``) bound the interval of
gains a loop may be given.
"""

import numpy as np
from scipy.optimize import brentq, minimize_scalar

__all__ = []

# a loop matrix with σ_min below this times max(1, ||M||) is singular
SINGULAR_RTOL = 1e-10


def singular_instant(M):
    """Instant t in [0, T) where the square `PeriodicMatrix` M(t) is closest
    to singular, and its smallest singular value there.

    Examples
    --------
    >>> from ltpcontrol._core.wellposed import singular_instant
    >>> M = ltp.PeriodicMatrix.from_function(lambda t: np.array([[1 + np.cos(t)]]),
    ...                                      2 * np.pi)
    >>> t, smin = singular_instant(M)
    >>> round(t, 6), smin < 1e-12
    (3.141593, True)
    """
    T = M.period
    if M.is_constant:
        return 0.0, float(np.linalg.svd(M(0.0), compute_uv=False)[-1])
    K = M.nharmonics
    num = 512 if K is None else max(64, 16 * K)
    t = np.arange(num) * T / num
    t = np.unique(np.concatenate([t, [] if M.switching_times is None else M.switching_times]))
    vals = M(t)

    def smin(x):
        return float(np.linalg.svd(M(float(x)), compute_uv=False)[-1])
    sv = np.linalg.svd(vals, compute_uv=False)[:, -1]
    cand = []
    det = np.linalg.det(vals)
    tt = np.append(t, T)
    dd = np.append(det, det[0])
    for i in np.nonzero(np.sign(dd[:-1]) * np.sign(dd[1:]) < 0)[0]:
        root = brentq(lambda x: float(np.linalg.det(M(float(x)))), tt[i], tt[i + 1],
                      xtol=1e-14 * T)
        cand.append((smin(root), root))
    i = int(np.argmin(sv))
    lo, hi = tt[max(i - 1, 0)] if i else -(T / num), tt[i + 1]
    res = minimize_scalar(smin, bounds=(lo, hi), method='bounded',
                          options={'xatol': 1e-13 * T})
    cand += [(sv[i], t[i]), (float(res.fun), float(res.x) % T)]
    best = min(cand)
    return float(best[1]), float(best[0])


def check_well_posed(M, where, what="I + D(t)"):
    """Raise ValueError naming the instant when `M(t)` is singular for some t.

    Examples
    --------
    >>> from ltpcontrol._core.wellposed import check_well_posed
    >>> M = ltp.PeriodicMatrix.from_function(lambda t: np.array([[1 + np.cos(t)]]),
    ...                                      2 * np.pi)
    >>> check_well_posed(M, 'feedback')
    Traceback (most recent call last):
    ...
    ValueError: feedback: the loop is ill-posed: I + D(t) is singular at t = 3.14159 (smallest singular value ..., entries up to 1); an algebraic loop has no solution there
    """
    t, smin = singular_instant(M)
    scale = max(1.0, float(np.abs(M(t)).max()))
    if smin <= SINGULAR_RTOL * scale:
        at = "" if M.is_constant else f" at t = {t:.6g}"
        raise ValueError(f"{where}: the loop is ill-posed: {what} is singular{at} "
                         f"(smallest singular value {smin:.2g}, entries up to {scale:.3g}); "
                         "an algebraic loop has no solution there")


def ill_posed_gains(D):
    """Nearest real gains below and above 1 that make ``I + k D(t)`` singular.

    ``-1/k`` is then a real eigenvalue of ``D(t)`` for some t; returns
    ``(k_below, k_above)`` with 0 and inf when there is none.

    Examples
    --------
    >>> from ltpcontrol._core.wellposed import ill_posed_gains
    >>> D = ltp.PeriodicMatrix.from_function(lambda t: np.array([[-0.5 - 0.3 * np.cos(t)]]),
    ...                                      2 * np.pi)
    >>> np.round(ill_posed_gains(D), 6)          # -1/k in [-0.8, -0.2]
    array([0.  , 1.25])
    """
    T = D.period
    num = 1 if D.is_constant else (512 if D.nharmonics is None else max(64, 16 * D.nharmonics))
    t = np.arange(num) * T / num

    def gains(x):
        lam = np.linalg.eigvals(D(np.atleast_1d(x)))
        real = np.abs(lam.imag) <= 1e-12 * np.maximum(1.0, np.abs(lam))
        neg = real & (lam.real < 0)
        with np.errstate(divide='ignore'):
            return np.where(neg, -1.0 / np.where(neg, lam.real, -1.0), np.nan)
    k = gains(t)                                   # (num, m)
    above = np.where(k > 1, k, np.inf).min(axis=1)
    below = np.where(k < 1, k, 0.0).max(axis=1)
    out = []
    for vals, sign in ((below, -1.0), (above, 1.0)):
        i = int(np.argmin(sign * vals))
        best = vals[i]
        if num > 1 and np.isfinite(best) and best > 0:
            def f(x, sign=sign):
                g = gains(x)[0]
                g = g[(g > 1) if sign > 0 else (g < 1)]
                return sign * g.min() if sign > 0 and g.size else (
                    sign * g.max() if g.size else np.inf)
            res = minimize_scalar(f, bounds=(t[i] - T / num, t[i] + T / num),
                                  method='bounded', options={'xatol': 1e-13 * T})
            if np.isfinite(res.fun) and sign * res.fun < sign * best:
                best = sign * res.fun
        out.append(float(best))
    return out[0], out[1]
