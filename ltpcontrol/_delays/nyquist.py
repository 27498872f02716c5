"""Generalized Nyquist criterion of periodic loops with delays.

`ltpcontrol.nyquist_htf` hands a loop with delays (an
`LTPDelayStateSpace` or a sequence holding one or a `delay` element) to
the function here.  The count is that of `nyquist_htf` for loops without
delays, on the truncated HTF with the exact ``e^{-sτ}`` (no Padé
approximation):

* f(s) = det(I + L̂_N(s)) is meromorphic, with finitely many zeros and
  poles in the half strip ``0 < Re s < σ`` and none beyond σ
  (`ltpcontrol._delays.loop`); the phase of f is accumulated up the
  imaginary axis ``s = jω``, ``ω ∈ [-ω_p/2, ω_p/2]`` (semicircles to the
  right of open-loop exponents on the axis), out along ``Im s = ω_p/2 +
  ε``, down ``Re s = σ`` and back along ``Im s = -ω_p/2 + ε``, each piece
  refined until the phase turns less than π/4 between points;
* the encirclements (counter-clockwise, of the origin by f) equal
  ``P_N - Z_N``, the poles less the zeros of f in the half strip: exact
  for the truncated loop;
* the verdict is ``Z = P - encirclements`` with P the open loop's
  characteristic exponents with positive real part, counted from its
  multipliers (the spectral-element monodromy of `delay_monodromy` when
  it has state delays, else the Floquet multipliers of the ODE): the
  truncated loop's P_N converges to P as N grows;
* with ``check`` the verdict is compared with the multipliers of the
  closed delayed loop ``feedback(L, I)`` (a warning on disagreement).
"""

import numpy as np

from .._core.registry import override
from .._core.validation import check_positive, real_array
from .._frequency.contour import EDGE_OFFSET, path_phase, strip_closure
from .._frequency.nyquist import contour_points, counted_response
from .connect import Delay
from .loop import DelayLoop, as_delayed_loop, check_steps, closed_loop_unstable, open_loop
from .ltpdsys import LTPDelayStateSpace

__all__ = []

_MAX_TURN = np.pi / 4
_MAX_POINTS = 50_000
_CHECK_STATES = 60


@override('nyquist_htf', Delay)
@override('nyquist_htf', LTPDelayStateSpace)
def nyquist_htf(L, nharmonics, omega=None, *, period=None, indent_radius=None,
                closure_tol=0.05, internal_harmonics=None, check='auto', floquet_steps=None):
    """`ltpcontrol.nyquist_htf` of a loop with delays (module notes).

    ``check='auto'`` compares the verdict with the closed loop's
    multipliers for loops of at most 60 states; `floquet_steps` does not
    apply (TypeError).

    Examples
    --------
    ``L = k e^{-sτ}/(s - 1)`` (one unstable open-loop exponent): k = 2
    stabilizes it for ``τ < atan(√3)/√3 = 0.6046``:

    >>> P = ltp.ltpss(ct.tf([2.0], [1.0, -1.0]), period=1.0)
    >>> r = ltp.nyquist_htf((P, ltp.delay(0.4)), 4)
    >>> r.open_loop_unstable, r.encirclements, r.stable, r.floquet_unstable
    (1, 1, True, 0)
    >>> ltp.nyquist_htf((P, ltp.delay(0.8)), 4).closed_loop_unstable
    2
    """
    check_steps(floquet_steps)
    L, cl = as_delayed_loop(L, 'L', period, 'nyquist_htf')
    loop = DelayLoop(L, nharmonics, internal_harmonics)
    wp = loop.omega_p
    r = 1e-4 * wp if indent_radius is None else check_positive(
        indent_radius, 'indent_radius', below=wp / 4)
    closure_tol = check_positive(closure_tol, 'closure_tol')
    if check == 'auto':
        do_check = L.nstates <= _CHECK_STATES
    elif isinstance(check, (bool, np.bool_)):
        do_check = bool(check)
    else:
        raise ValueError(f"check must be True, False or 'auto', got {check!r}")
    P, axis_w = open_loop(L)
    w = _initial_grid(omega, wp, axis_w, r)
    w, s, logabs, phase, eig, edge = _axis(loop, w, axis_w, r)
    edge_turn, resolved = _close(loop, axis_w, r)
    sv = np.linalg.svd(np.eye(loop.size) + loop(s[::max(1, len(s) // 2000)]),
                       compute_uv=False)
    Zf = closed_loop_unstable(cl) if do_check else None
    return counted_response(L.name, loop.N, wp, w, s, logabs, phase, eig, edge, edge_turn,
                            resolved, P, float(sv[:, -1].min()), Zf, closure_tol,
                            "closed delayed loop's multipliers", "check", stacklevel=4)


def _initial_grid(omega, wp, axis_w, r):
    if omega is None:
        w = np.linspace(-wp / 2, wp / 2, 401)
    else:
        w = np.unique(real_array(omega, 'omega', ndim=1))
        if w.size < 2 or w[0] < -wp / 2 * (1 + 1e-12) or w[-1] > wp / 2 * (1 + 1e-12):
            raise ValueError("omega must hold at least two frequencies in the strip "
                             f"[-ω_p/2, ω_p/2] = [{-wp / 2:g}, {wp / 2:g}]")
        w = np.unique(np.concatenate([[-wp / 2], w, [wp / 2]]))
    theta = np.sin(np.linspace(-np.pi / 2, np.pi / 2, 41))
    extra = [c + r * theta for wk in axis_w for c in (wk - wp, wk, wk + wp)]
    if extra:
        w = np.concatenate([w] + extra)
        w = np.unique(w[(w >= -wp / 2) & (w <= wp / 2)])
    return w


def _evaluate(loop, s):
    Lh = loop(s)
    sign, logabs = np.linalg.slogdet(np.eye(loop.size) + Lh)
    dyn = Lh - loop.feedthrough(s)
    m = loop.m
    edge = float(max(np.abs(dyn[:, :m, :]).max(), np.abs(dyn[:, -m:, :]).max(),
                     np.abs(dyn[:, :, :m]).max(), np.abs(dyn[:, :, -m:]).max()))
    return logabs, np.angle(sign), np.linalg.eigvals(Lh), edge


def _axis(loop, w, axis_w, r):
    """The Nyquist curve on the axis, refined where the phase or modulus moves fast."""
    wp = loop.omega_p
    s = contour_points(w, axis_w, r, wp)
    logabs, phase, eig, edge = _evaluate(loop, s)
    while True:
        bad = (np.abs(_wrap(np.diff(phase))) > _MAX_TURN) | (np.abs(np.diff(logabs)) > 0.5)
        bad &= np.diff(w) > 1e-13 * wp
        if not bad.any() or len(w) + bad.sum() > _MAX_POINTS:
            break
        wn = 0.5 * (w[:-1][bad] + w[1:][bad])
        sn = contour_points(wn, axis_w, r, wp)
        la, ph, ev, _ = _evaluate(loop, sn)
        order = np.argsort(np.concatenate([w, wn]), kind='stable')
        w = np.concatenate([w, wn])[order]
        s = np.concatenate([s, sn])[order]
        logabs = np.concatenate([logabs, la])[order]
        phase = np.concatenate([phase, ph])[order]
        eig = np.concatenate([eig, ev])[order]
    return w, s, logabs, phase, eig, edge


def _close(loop, axis_w, r):
    """Phase change of f over the other sides of the half strip (out to σ)."""
    wp = loop.omega_p
    eps = EDGE_OFFSET * wp
    grid = np.linspace(0.0, 1.0, 9)

    def along_axis(w0, w1):
        return lambda t: contour_points(w0 + (w1 - w0) * np.asarray(t), axis_w, r, wp)
    up, ok1, _ = path_phase(loop.logdet, along_axis(wp / 2, wp / 2 + eps), None, grid)
    down, ok2, _ = path_phase(loop.logdet, along_axis(-wp / 2 + eps, -wp / 2), None, grid)
    s_top = complex(contour_points(np.array([wp / 2 + eps]), axis_w, r, wp)[0])
    s_bot = complex(contour_points(np.array([-wp / 2 + eps]), axis_w, r, wp)[0])
    edges, ok3 = strip_closure(loop.logdet, s_top, s_bot, wp, loop.sigma_bound())
    return up + edges + down, ok1 and ok2 and ok3


def _wrap(x):
    return np.remainder(x + np.pi, 2 * np.pi) - np.pi
