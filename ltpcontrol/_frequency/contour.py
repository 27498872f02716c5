"""Closing the Nyquist contour of a truncated periodic loop exactly.

The truncated return difference ``f(s) = det(I + L̂_N(s))`` is a rational
function: with the harmonic state space ``L̂_N(s) = H (sI - F)^{-1} G + J``
of the loop,

    f(s) = det(I + J) det(sI - F_cl) / det(sI - F),   F_cl = F - G (I + J)^{-1} H,

so its zeros (the truncated closed loop's exponents) and poles (the open
loop's) are finite in number.  The argument principle on the boundary of
the half strip ``{0 < Re s < σ_max, -ω_p/2 + ε < Im s <= ω_p/2 + ε}``
counts exactly the zeros minus the poles inside it.  For the untruncated
HTF the two horizontal edges cancel (``L̂(s + jω_p)`` is ``L̂(s)`` with its
blocks shifted); for the truncated one they do not, and for a biproper
loop (``L(∞) ≠ 0``) their contribution is a whole number of turns at small
N.  So the edges are integrated: up the imaginary axis (the Nyquist
curve), out along ``Im s = ω_p/2 + ε``, down ``Re s = σ_max`` and back
along ``Im s = -ω_p/2 + ε``.  σ_max exceeds a bound on the real parts of
the eigenvalues of F and F_cl (their numerical abscissa), so the contour
encloses every zero and pole of f in the strip; ε (``10^-3 ω_p``) keeps
the horizontal edges off the exponents with real multipliers, whose
imaginary part is exactly ``±ω_p/2``.

On every piece the phase of f is accumulated between points close enough
that it turns by less than π/4 (points are bisected until it does).
"""

import numpy as np

__all__ = []

# offset of the strip's horizontal edges from ±ω_p/2, in units of ω_p
EDGE_OFFSET = 1e-3
# refine an interval while the phase of f turns more than this
_MAX_TURN = np.pi / 4
# bound on the number of points of one piece
_MAX_POINTS = 20_000


def path_phase(logdet, s0, s1, t, *, resolution=1e-13):
    """Phase change of f along the path ``s(t)`` sampled at parameters `t`.

    `logdet(s)` returns ``(log|f|, arg f)`` at the points `s`; `s0`, `s1`
    map the parameters `t` in [0, 1] to points (vectorised); the piece is
    refined where the phase turns more than π/4 or ``log|f|`` changes by
    more than 0.5 between neighbours.

    Returns
    -------
    turn : float
        Accumulated phase change (radians).
    resolved : bool
        False when the refinement stopped at `resolution` or the point
        bound with a turn still above π/4 (f has a zero or pole on or at
        rounding distance from the path).
    minabs : float
        Smallest ``log|f|`` on the path.

    Examples
    --------
    The unit circle winds once around the origin:

    >>> from ltpcontrol._frequency.contour import path_phase
    >>> def logdet(s):
    ...     return np.log(np.abs(s)), np.angle(s)
    >>> circle = lambda t: np.exp(2j * np.pi * t)
    >>> turn, ok, _ = path_phase(logdet, circle, None, np.linspace(0, 1, 5))
    >>> round(turn / (2 * np.pi), 12), ok
    (1.0, True)
    """
    path = s0 if s1 is None else (lambda x: s0 + (s1 - s0) * x)
    t = np.asarray(t, float)
    la, ph = logdet(path(t))
    resolved = True
    while True:
        dphi = _wrap(np.diff(ph))
        bad = (np.abs(dphi) > _MAX_TURN) | (np.abs(np.diff(la)) > 0.5)
        small = np.diff(t) <= resolution
        if np.any(bad & small & (np.abs(dphi) > _MAX_TURN)):
            resolved = False
        bad &= ~small
        if not bad.any():
            break
        if len(t) + bad.sum() > _MAX_POINTS:
            resolved = not np.any(np.abs(dphi[bad]) > _MAX_TURN)
            break
        tn = 0.5 * (t[:-1][bad] + t[1:][bad])
        ln, pn = logdet(path(tn))
        order = np.argsort(np.concatenate([t, tn]), kind='stable')
        t = np.concatenate([t, tn])[order]
        la = np.concatenate([la, ln])[order]
        ph = np.concatenate([ph, pn])[order]
    if np.any(np.isinf(la)):
        resolved = False
    return float(_wrap(np.diff(ph)).sum()), resolved, float(np.min(la))


def strip_closure(logdet, s_top, s_bottom, omega_p, sigma_max, points=32):
    """Phase change of f along the three other sides of the half strip.

    From `s_top` (the end of the Nyquist curve, continued to
    ``Im s = ω_p/2 + ε``) out to ``σ_max``, down to ``Im s = -ω_p/2 + ε``
    and back to `s_bottom`.

    Returns
    -------
    turn : float
        Phase change (radians) over the three sides.
    resolved : bool
        False when a side passes through (or at rounding distance from) a
        zero or pole of f.

    Examples
    --------
    ``f(s) = (s - 1)/(s + 2)`` has one zero in the half strip of ω_p = 1:
    the three sides turn by 2π less the (nearly zero) turn on the axis.

    >>> from ltpcontrol._frequency.contour import path_phase, strip_closure
    >>> def logdet(s):
    ...     f = (s - 1) / (s + 2)
    ...     return np.log(np.abs(f)), np.angle(f)
    >>> turn, ok = strip_closure(logdet, 0.5001j, -0.4999j, 1.0, 100.0)
    >>> axis, _, _ = path_phase(logdet, -0.4999j, 0.5001j, np.linspace(0, 1, 50))
    >>> round((turn + axis) / (2 * np.pi), 9), ok
    (-1.0, True)
    """
    sigma_max = float(max(sigma_max, 2 * abs(s_top.real), 2 * abs(s_bottom.real), omega_p))
    # dense near the axis, geometric towards σ_max
    x = np.concatenate([[0.0], np.geomspace(1e-7, 1.0, points)])
    top_far = complex(sigma_max, s_top.imag)
    bottom_far = complex(sigma_max, s_bottom.imag)
    # beyond every exponent f barely moves on the far side: few points, refined
    pieces = [(s_top, top_far, x),
              (top_far, bottom_far, np.linspace(0.0, 1.0, 9)),
              (bottom_far, s_bottom, 1.0 - x[::-1])]
    total, ok = 0.0, True
    for a, b, t in pieces:
        turn, res, _ = path_phase(logdet, a, b, t)
        total += turn
        ok &= res
    return total, ok


def abscissa_bound(hss):
    """Bound on the real parts of the eigenvalues of F and of F_cl.

    ``Re λ(M) <= λ_max((M + M^H)/2) <= ||(M + M^H)/2||``; 𝒩 is
    skew-Hermitian, and the feedback term is bounded by Frobenius norms.

    Examples
    --------
    >>> from ltpcontrol._frequency.contour import abscissa_bound
    >>> from ltpcontrol._frequency.harmonic_ss import build
    >>> sys = ltp.ltpss(ct.tf([3], [1, -2]), period=1.0)
    >>> hss = build(sys, 1, None, 'auto', 'test', warn_unstable=False)
    >>> bool(abscissa_bound(hss) >= 2.0)          # the pole 2 of 3/(s - 2)
    True
    """
    F = hss.F
    herm = 0.5 * (F + F.conj().T)
    # ||M||_2 <= sqrt(||M||_1 ||M||_inf)
    a = np.sqrt(np.abs(herm).sum(axis=0).max(initial=0.0)
                * np.abs(herm).sum(axis=1).max(initial=0.0))
    J = hss.J
    if J.size:
        smin = np.linalg.svd(np.eye(len(J)) + J, compute_uv=False)[-1]
        fb = (np.linalg.norm(hss.G) * np.linalg.norm(hss.Hc) / smin if smin > 0
              else np.inf)
    else:
        fb = 0.0
    return float(a + fb)


def _wrap(x):
    """Angles wrapped into [-π, π)."""
    return np.remainder(x + np.pi, 2 * np.pi) - np.pi
