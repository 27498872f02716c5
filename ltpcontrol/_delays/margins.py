"""Delay margin of a periodic feedback loop.

The loop ``u = r + sign L(y)`` is closed through an extra delay d on every
loop channel, ``feedback(delay(d) * L, sign=...)`` in block-diagram terms;
the delay margin is the smallest d > 0 for which the closed loop is
unstable.  For a periodic loop the delay does not act as a phase shift of
one frequency response (``e^{-(s + jkω_p)d}`` differs on every harmonic),
so the margin is decided on the closed loop's characteristic multipliers:
a scan of d on a grid, then bisection of the first change of verdict.
"""

import warnings
from dataclasses import dataclass

import numpy as np
from control.exception import ControlArgument
from scipy.optimize import brentq, minimize_scalar

from .._core.floquet import floquet_multipliers, is_stable
from .._core.registry import override
from .._core.validation import check_positive_int
from .._frequency.margins import (HarmonicMargins, MarginPoint, _disk_gain_phase as _disk,
                                  _point, _refine, _sign_changes as _changes, _unique)
from .._frequency.nyquist import track
from .._core.ltpsys import LTPStateSpace
from .connect import Delay, feedback, series
from .loop import DelayLoop, as_delayed_loop, check_steps, open_loop
from .ltpdsys import LTPDelayStateSpace, as_delayed
from .monodromy import _Problem

__all__ = ['delay_margin']

_NONE = MarginPoint(float('inf'), float('nan'), 0, float('nan'))


def delay_margin(L, *, sign=-1, max_delay=None, num=40, tol=1e-6):
    """Delay margin of the periodic loop ``u = r + sign L(y)``: the smallest destabilizing delay.

    Parameters
    ----------
    L : LTPStateSpace or LTPDelayStateSpace
        Loop transfer (continuous time, square), possibly with delays of
        its own.
    sign : {-1, 1}, optional
        Feedback sign (default negative).
    max_delay : float, optional
        Largest delay scanned (default: two periods).
    num : int, optional
        Grid points of the scan (default 40); an unstable interval shorter
        than ``max_delay/num`` can be missed.
    tol : float, optional
        Relative tolerance of the bisection (default 1e-6).

    Returns
    -------
    float
        The margin; 0 if the loop is unstable without extra delay, inf if no
        delay up to `max_delay` destabilizes it.

    Examples
    --------
    ``L = 2/(s + 1)`` written as periodic: crossover ``ω_c = √3``, phase
    margin ``π - atan(√3)``, so the delay margin is ``(2π/3)/√3``:

    >>> L = ltp.ltpss(ct.tf([2.0], [1.0, 1.0]), 1.0)
    >>> dm = ltp.delay_margin(L, max_delay=3.0, num=6)
    >>> bool(abs(dm - 2 * np.pi / 3 / np.sqrt(3)) < 1e-5)
    True
    """
    if not isinstance(L, (LTPStateSpace, LTPDelayStateSpace)):
        raise ControlArgument(f"L must be an LTPStateSpace or LTPDelayStateSpace, got "
                              f"{type(L).__name__}")
    if isinstance(L, LTPStateSpace) and L.isdtime(strict=True):
        raise ValueError("L must be a continuous-time loop")
    if L.ninputs != L.noutputs:
        raise ValueError(f"L must be square, got {L.noutputs} outputs and {L.ninputs} inputs")
    if sign not in (-1, 1):
        raise ValueError(f"sign must be -1 or 1, got {sign!r}")
    max_delay = 2 * L.period if max_delay is None else float(max_delay)
    if not np.isfinite(max_delay) or max_delay <= 0:
        raise ValueError(f"max_delay must be a finite positive number, got {max_delay!r}")
    if isinstance(num, bool) or not isinstance(num, (int, np.integer)) or num < 2:
        raise ValueError(f"num must be an integer >= 2, got {num!r}")
    if not 0 < tol < 0.1:
        raise ValueError(f"tol must be in (0, 0.1), got {tol!r}")

    base = as_delayed(L)

    def radius(d):
        # the extra delay d on every loop input: the B and D terms delayed by d more
        t = base.terms
        if d > 0:
            t['B'] = {a + d: M for a, M in t['B'].items()}
            t['D'] = {a + d: M for a, M in t['D'].items()}
        loop = feedback(LTPDelayStateSpace(t, base.period), 1.0, sign=sign)
        if loop.state_delays:
            mu = _Problem(loop).multipliers(16)
        else:
            mu = floquet_multipliers(loop.undelayed())
        return float(np.max(np.abs(mu), initial=0.0))

    if radius(0.0) >= 1:
        return 0.0
    grid = np.linspace(0, max_delay, num + 1)[1:]
    lo = 0.0
    for d in grid:
        if radius(d) >= 1:
            return float(brentq(lambda x: np.log(max(radius(x), 1e-300)), lo, d,
                                xtol=0.25 * tol * d, rtol=4 * np.finfo(float).eps))
        lo = d
    return np.inf


#
# Margins of a loop with delays (`ltpcontrol.harmonic_margins` hands it here)
#

# gains beyond this (or below its inverse) are not reported as gain margins
_GAIN_LIMIT = 1e8
# an eigenvalue is taken as on the negative real axis (or unit circle) within this
_REAL_RTOL = 1e-6


@dataclass(frozen=True, repr=False)
class DelayHarmonicMargins(HarmonicMargins):
    """Result of `harmonic_margins` for a loop with delays: `HarmonicMargins` and its delay margin.

    Attributes
    ----------
    delay_margin : float
        Smallest extra delay on every loop channel that destabilizes the
        closed loop (`delay_margin`); 0 when it is unstable, inf when no
        delay up to the scanned range does.

    Examples
    --------
    ``10 e^{-0.05 s}/(s + 1)``: crossover at ``√99``, delay margin
    ``(π - atan √99)/√99 - 0.05``:

    >>> P = ltp.ltpss(ct.tf([10.0], [1.0, 1.0]), period=1.0)
    >>> m = ltp.harmonic_margins((P, ltp.delay(0.05)), 3, check=False, edge_tol=2.0)
    >>> w = np.sqrt(99.0)
    >>> bool(abs(m.delay_margin - ((np.pi - np.arctan(w)) / w - 0.05)) < 1e-6)
    True
    """

    delay_margin: float = float('inf')

    def report(self, Hz=False, *, hz=None):
        """The margins as a table, with the delay margin in seconds.

        Parameters
        ----------
        Hz : bool
            Physical frequencies in Hz instead of rad/s (python-control's
            keyword).
        hz : bool, optional
            Former spelling of `Hz`, still accepted.

        Returns
        -------
        str

        Examples
        --------
        >>> P = ltp.ltpss(ct.tf([10.0], [1.0, 1.0]), period=1.0)
        >>> print(ltp.harmonic_margins((P, ltp.delay(0.05)), 3, check=False,
        ...                             edge_tol=2.0).report().splitlines()[-1])
        delay [s]   0.1179
        """
        return (super().report(Hz, hz=hz)
                + f"\n{'delay [s]':<11} {self.delay_margin:6.4g}")

    def __repr__(self):
        return super().__repr__()[:-1] + f", delay {self.delay_margin:.4g}>"


@override('harmonic_margins', Delay)
@override('harmonic_margins', LTPDelayStateSpace)
def harmonic_margins(L, nharmonics=10, *, period=None, omega_num=801, skew=0.0,
                     internal_harmonics=None, edge_tol=0.05, check=True, floquet_steps=None):
    """`ltpcontrol.harmonic_margins` of a loop with delays, with its delay margin.

    The gain, phase, stability and disk margins are read on the eigenloci
    and singular values of the truncated HTF with the exact ``e^{-sτ}``
    (as for loops without delays); `check` verifies the gain margins by
    the multipliers of the closed delayed loops 0.1 % inside and outside
    them; the delay margin is `delay_margin`'s, scanned on 40 to 100
    delays up to twice the largest of two periods and the delay margins
    ``φ/ω`` of the phase crossings (an unstable window of delays narrower
    than the scan step can be missed; `delay_margin` scans finer).  `floquet_steps` does not apply (TypeError).

    Returns
    -------
    HarmonicMargins
        Its subclass with the field ``delay_margin`` (seconds), also in
        ``report()``.

    Examples
    --------
    ``L = 4 e^{-0.1 s}/(s + 1)^3`` written as periodic: python-control's
    margins of the exact frequency response.

    >>> G = ct.tf([4.0], [1.0, 3.0, 3.0, 1.0])
    >>> m = ltp.harmonic_margins((ltp.ltpss(G, period=1.0), ltp.delay(0.1)), 4)
    >>> w = np.linspace(0.01, 10, 2001)
    >>> frd = ct.frd(G(1j * w) * np.exp(-0.1j * w), w)
    >>> gm, pm, _, wpc, wgc, _ = ct.stability_margins(frd)
    >>> bool(abs(m.gain_upper.value - gm) < 1e-8), bool(abs(m.phase.value - pm) < 1e-6)
    (True, True)
    >>> bool(abs(m.delay_margin - np.radians(pm) / wgc) < 1e-6)
    True
    """
    check_steps(floquet_steps)
    L, _ = as_delayed_loop(L, 'L', period, 'harmonic_margins')
    loop = DelayLoop(L, nharmonics, internal_harmonics)
    num = check_positive_int(omega_num, 'omega_num', minimum=16)
    skew = float(skew)
    wp = loop.omega_p
    _, axis_w = open_loop(L)
    w = np.linspace(-5 * wp / 8, 5 * wp / 8, num)
    poles = np.concatenate([axis_w + k * wp for k in (-1, 0, 1)]) if axis_w.size else axis_w
    if poles.size:
        w = w[np.min(np.abs(w[:, None] - poles[None, :]), axis=1) > 1e-6 * wp]
        near = np.concatenate([poles - 1e-7 * wp, poles + 1.37e-7 * wp])
        w = np.sort(np.concatenate([w, near[np.abs(near) < 5 * wp / 8]]))
    Lh = loop(1j * w)
    far = (np.min(np.abs(w[:, None] - poles[None, :]), axis=1) > wp / 20 if poles.size
           else np.ones(len(w), bool))
    _check_edge(loop, (Lh - loop.feedthrough(1j * w))[far], edge_tol)
    eig = track(np.linalg.eigvals(Lh))
    gains, phases = [], []
    for b in range(eig.shape[1]):
        lam = eig[:, b]
        for i in _changes(lam.imag):
            if min(lam[i].real, lam[i + 1].real) < 0:
                hit = _refine(loop, w[i], w[i + 1], lam[i], lam[i + 1], np.imag)
                if hit and hit[1].real < 0 and abs(hit[1].imag) <= _REAL_RTOL * abs(hit[1]):
                    gm = 1 / abs(hit[1])
                    if 1 / _GAIN_LIMIT < gm < _GAIN_LIMIT:
                        gains.append(_point(loop, gm, hit))
        with np.errstate(divide='ignore'):
            logmag = np.log(np.abs(lam))
        for i in _changes(logmag):
            hit = _refine(loop, w[i], w[i + 1], lam[i], lam[i + 1],
                          lambda z: np.log(abs(z)) if z != 0 else -np.inf)
            if hit and abs(abs(hit[1]) - 1) <= _REAL_RTOL:
                pm = float(np.remainder(np.angle(hit[1], deg=True), 360.0) - 180.0)
                phases.append(_point(loop, pm, hit, odd=True))
    gains, phases = _unique(gains, wp), _unique(phases, wp)
    above = [g for g in gains if g.value > 1]
    below = [g for g in gains if g.value < 1]
    upper = min(above, key=lambda g: g.value) if above else _NONE
    lower = (max(below, key=lambda g: g.value) if below
             else MarginPoint(0.0, float('nan'), 0, float('nan')))
    phase = min(phases, key=lambda p: abs(p.value)) if phases else _NONE
    eye = np.eye(loop.size)
    stability = _extremum(loop, w, Lh, lambda M: np.linalg.svd(
        eye + M, compute_uv=False)[-1], 'min')
    offset = 0.5 * (skew - 1)
    peak = _extremum(loop, w, Lh, lambda M: np.linalg.svd(
        np.linalg.inv(eye + M) + offset * eye, compute_uv=False)[0], 'max')
    alpha = 1 / peak.value
    dgain, dphase = _disk(alpha, skew)
    if check:
        _verify(L, upper.value, lower.value)
    # the delay margin: the scan covers the delay margins of the phase crossings
    guesses = [np.radians(abs(p.value)) / p.frequency for p in phases
               if p.value > 0 and p.frequency > 0]
    top = max([2 * L.period] + [2 * g for g in guesses])
    num_d = int(min(100, max(40, np.ceil(40 * top / (2 * L.period)))))
    dm = delay_margin(L, max_delay=top, num=num_d)
    return DelayHarmonicMargins(
        gain_upper=upper, gain_lower=lower, phase=phase, stability=stability,
        disk=peak._replace(value=alpha), disk_gain=dgain, disk_phase=dphase,
        gain_crossings=gains, phase_crossings=phases, nharmonics=loop.N, skew=skew,
        delay_margin=float(dm))


def _extremum(loop, w, Lh, fun, kind):
    sign = 1.0 if kind == 'min' else -1.0
    vals = np.array([fun(M) for M in Lh])
    i = int(np.argmin(sign * vals))
    lo, hi = w[max(i - 1, 0)], w[min(i + 1, len(w) - 1)]
    res = minimize_scalar(lambda x: sign * fun(loop(1j * x)[0]), bounds=(lo, hi),
                          method='bounded', options={'xatol': 1e-13 * loop.omega_p})
    wbest, vbest = (res.x, sign * res.fun) if res.fun < sign * vals[i] else (w[i], vals[i])
    _, _, Vh = np.linalg.svd(np.eye(loop.size) + loop(1j * wbest)[0])
    return _point(loop, float(vbest), (wbest, None, Vh[-1].conj()))


def _verify(L, upper, lower, delta=1e-3):
    """Check the gain margins by the closed delayed loops' multipliers (warn otherwise)."""
    eye = np.eye(L.ninputs)

    def stable(k):
        with warnings.catch_warnings():
            warnings.filterwarnings('ignore', message='is_stable')
            return is_stable(feedback(series(L, k * eye), eye))
    if not stable(1.0):
        return
    bad = []
    if np.isfinite(upper):
        bad += [k for k, want in ((upper * (1 - delta), True), (upper * (1 + delta), False))
                if stable(k) != want]
    if lower > 0:
        bad += [k for k, want in ((lower * (1 + delta), True), (lower * (1 - delta), False))
                if stable(k) != want]
    if bad:
        warnings.warn(f"harmonic_margins: the multipliers of the closed delayed loop with the "
                      f"gains {bad} contradict the gain margins ({lower:.6g}, {upper:.6g}): "
                      "a crossing was missed between grid points; increase omega_num",
                      UserWarning, stacklevel=3)


def _check_edge(loop, dyn, tol):
    m, N = loop.m, loop.N
    edge = max(np.abs(dyn[:, :m, :]).max(), np.abs(dyn[:, -m:, :]).max(),
               np.abs(dyn[:, :, :m]).max(), np.abs(dyn[:, :, -m:]).max())
    if edge > tol:
        warnings.warn(f"the loop HTF is not small at its truncation edge (|L̂| up to "
                      f"{edge:.2g} in harmonics ±{N}): margins beyond them may be "
                      "missed; increase nharmonics", UserWarning, stacklevel=3)
