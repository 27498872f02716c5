"""Gain, phase, stability and disk margins of periodic feedback loops.

The closed loop ``u = r - k L y`` of a periodic loop has an exponent at
``jω`` exactly when ``-1/k`` is an eigenvalue of ``L̂(jω)`` (module
`nyquist`).  So, on the eigenloci of the truncated HTF ``L̂_N(jω)`` over
the strip:

* a crossing of the negative real axis at ``λ = -|λ|`` is a gain
  crossover: the gain ``k = 1/|λ|`` (the *gain margin* of that crossing)
  puts a closed-loop exponent on the axis (multiplier ``e^{jωT}``; at the
  strip edge ``ω = ω_p/2`` the multiplier -1);
* a crossing of the unit circle at ``λ = e^{ja}`` is a phase crossover:
  the uniform phase rotation ``e^{-jφ}`` of the loop with
  ``φ = a + π`` (the *phase margin*, in degrees, wrapped to (-180, 180])
  puts an exponent on the axis.

The *stability margin* is ``min_ω σ_min(I + L̂(jω))`` (the inverse of the
peak of the sensitivity HTF) and the *disk margin* with skew σ is
``α = 1 / max_ω σ_max(Ŝ(jω) + (σ - 1)/2 I)``, ``Ŝ = (I + L̂)^{-1}``: the
largest disk of complex gains, acting on every channel and harmonic,
that the loop tolerates.  As the harmonic blocks of such a perturbation
may differ, the disk margin of a periodic SISO loop is conservative for
time-invariant gains; for an LTI loop written as periodic every margin
is python-control's.

Each margin is reached at a strip frequency ω; the *harmonic* n is the
block carrying most of the eigen- (or singular) vector, and the physical
frequency is ``|ω + nω_p|`` (a real loop's crossings come in mirrored
pairs ``(ω, n)``, ``(-ω, -n)``).
"""

from dataclasses import dataclass
from typing import NamedTuple
import warnings

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from .loop import LoopHTF, as_loop, fold, loop_exponents, open_loop_exponents
from .nyquist import track
from .._core.ltpsys import feedback, series
from .._core.registry import overridden
from .._core.validation import check_positive_int
from .._core.wellposed import ill_posed_gains

__all__ = ['harmonic_margins', 'stability_margins', 'HarmonicMargins', 'MarginPoint']

# gains beyond this (or below its inverse) are not reported as gain margins
_GAIN_LIMIT = 1e8
# an eigenvalue is taken as on the negative real axis when |Im λ| <= this |λ|
_REAL_RTOL = 1e-6


class MarginPoint(NamedTuple):
    """A margin and where it is reached.

    Attributes
    ----------
    value : float
        The margin (inf when there is no crossing).
    omega : float
        Strip frequency ω in ``(-ω_p/2, ω_p/2]`` (nan without crossing).
    harmonic : int
        Dominant harmonic n of the eigen- or singular vector (0 without
        crossing).
    frequency : float
        Physical frequency ``|ω + nω_p|`` in rad/s (nan without crossing).

    Examples
    --------
    The fields of `HarmonicMargins`; a named tuple:

    >>> m = ltp.harmonic_margins(ltp.ltpss(ct.tf([4], [1, 3, 3, 1]), period=1.0), 5)
    >>> value, omega, harmonic, frequency = m.gain_upper
    >>> round(value, 6), round(frequency, 6)              # python-control: 2 at √3
    (2.0, 1.732051)
    """

    value: float
    omega: float
    harmonic: int
    frequency: float


_NONE = MarginPoint(float('inf'), float('nan'), 0, float('nan'))


@dataclass(frozen=True, repr=False)
class HarmonicMargins:
    """Result of `harmonic_margins`.

    Attributes
    ----------
    gain_upper : MarginPoint
        Smallest gain margin above 1 (the loop gain may grow by this factor).
        A gain that makes ``I + k D(t)`` singular at some instant ends the
        range: the margin is then that gain, with ``frequency = inf`` (the
        closed loop is ill-posed there).
    gain_lower : MarginPoint
        Largest gain margin below 1 (the loop gain may shrink to this
        factor); its value is 0 when no crossing lies below 1.
    phase : MarginPoint
        Phase margin of smallest magnitude (degrees).
    stability : MarginPoint
        ``min σ_min(I + L̂(jω))``.
    disk : MarginPoint
        Disk margin α for the skew `skew`.
    disk_gain : tuple of float
        Gain interval ``(γ_min, γ_max)`` guaranteed by the disk margin.
    disk_phase : float
        Phase (degrees) guaranteed by the disk margin.
    gain_crossings : list of MarginPoint
        Every gain margin found (value ``1/|λ|``), by frequency.
    phase_crossings : list of MarginPoint
        Every phase margin found, by frequency.
    nharmonics : int
        Truncation N.
    skew : float
        Skew of the disk margin.

    Examples
    --------
    >>> L = ltp.ltpss(ct.tf([4], [1, 3, 3, 1]), period=1.0)
    >>> m = ltp.harmonic_margins(L, 5)
    >>> round(m.gain_upper.value, 6), m.gain_upper.harmonic
    (2.0, 0)
    """

    gain_upper: MarginPoint
    gain_lower: MarginPoint
    phase: MarginPoint
    stability: MarginPoint
    disk: MarginPoint
    disk_gain: tuple
    disk_phase: float
    gain_crossings: list
    phase_crossings: list
    nharmonics: int
    skew: float

    def report(self, Hz=False, *, hz=None):
        """The margins as a table, frequencies in rad/s or (``Hz=True``) Hz.

        Parameters
        ----------
        Hz : bool
            Physical frequencies in Hz instead of rad/s (python-control's
            keyword, as in ``ct.bode_plot(Hz=True)``).
        hz : bool, optional
            Former spelling of `Hz`, still accepted.

        Returns
        -------
        str

        Examples
        --------
        >>> m = ltp.harmonic_margins(ltp.ltpss(ct.tf([4], [1, 3, 3, 1]), period=1.0), 5)
        >>> print(m.report(Hz=True))          # doctest: +NORMALIZE_WHITESPACE
        margin       value  harmonic  frequency [Hz]
        gain upper       2         0         0.27566
        gain lower       0         0             nan
        phase [deg]  27.14         0         0.19621
        stability   0.3333         0         0.22508
        disk        0.3777         0         0.22117
        """
        Hz = Hz if hz is None else hz
        unit = 'Hz' if Hz else 'rad/s'
        rows = [f"margin       value  harmonic  frequency [{unit}]"]
        for name, p in (('gain upper', self.gain_upper), ('gain lower', self.gain_lower),
                        ('phase [deg]', self.phase), ('stability', self.stability),
                        ('disk', self.disk)):
            f = p.frequency / (2 * np.pi) if Hz else p.frequency
            rows.append(f"{name:<11} {p.value:6.4g} {p.harmonic:9d} {f:15.5g}")
        return "\n".join(rows)

    def __repr__(self):
        return (f"<HarmonicMargins N={self.nharmonics}: gain ({self.gain_lower.value:.4g}, "
                f"{self.gain_upper.value:.4g}), phase {self.phase.value:.4g} deg, "
                f"stability {self.stability.value:.4g}, disk {self.disk.value:.4g}>")


def harmonic_margins(L, nharmonics=10, *, period=None, omega_num=801, skew=0.0,
                     internal_harmonics=None, edge_tol=0.05, check=True,
                     floquet_steps=None):
    """Gain, phase, stability and disk margins of a periodic loop.

    Parameters
    ----------
    L : LTPStateSpace, control.StateSpace or sequence of systems
        The continuous-time square loop, closed by negative feedback
        (see `nyquist_htf`).  MIMO loops: the gain margins are for a
        common real gain ``kI`` on every channel, the phase margin for a
        common rotation ``e^{-jφ}I`` (module notes).  A sequence holding
        measured HTFs (`HTFData`) gives the margins of the sampled loop
        (`impedance_margins`).
    nharmonics : int
        Truncation N of the loop HTF.
    period : float, optional
        Period of an LTI loop.
    omega_num : int
        Grid points over the strip (crossings are then refined to
        machine precision).
    skew : float
        Skew σ of the disk margin (0: balanced, as `control.disk_margins`).
    internal_harmonics : int, optional
        See `htf`.
    edge_tol : float
        Warn when the outermost harmonic blocks of ``L̂_N`` reach this
        magnitude: crossings beyond the truncation may be missed.
    check : bool
        Verify the gain margins by the Floquet exponents of the closed
        loops with the gains 0.1 % beyond them (one Floquet computation
        per finite margin): the exponents in the right half plane must be
        those that crossed the axis at the margin's frequency; otherwise,
        if the closed loop itself is stable (one more computation), warn
        (a crossing between grid points missed: raise `omega_num`).
    floquet_steps : int, optional
        Steps per period of every Floquet computation (`monodromy`'s
        `nsteps`; default: its own choice).

    Returns
    -------
    HarmonicMargins

    Raises
    ------
    ControlDimension
        If the loop is not square.
    ValueError
        For a discrete-time loop or incommensurate periods.

    Warns
    -----
    UserWarning
        When the truncation edge of ``L̂_N`` is not small (increase
        `nharmonics`), or when the Floquet check of the gain margins fails.

    Examples
    --------
    ``L = 4/(s+1)^3`` written as periodic has python-control's margins:

    >>> G = ct.tf([4], [1, 3, 3, 1])
    >>> m = ltp.harmonic_margins(ltp.ltpss(G, period=1.0), 5)
    >>> gm, pm, sm, wpc, wgc, wms = ct.stability_margins(G)
    >>> bool(np.isclose(m.gain_upper.value, gm)), bool(np.isclose(m.phase.value, pm))
    (True, True)
    >>> bool(np.isclose(m.gain_upper.frequency, wpc))
    True
    """
    # -- loops with delays: their own margins and delay margin (ltpcontrol._delays.margins) --
    if (own := overridden('harmonic_margins', *(L if isinstance(L, (list, tuple)) else [L]))):
        return own(L, nharmonics, period=period, omega_num=omega_num, skew=skew,
                   internal_harmonics=internal_harmonics, edge_tol=edge_tol, check=check,
                   floquet_steps=floquet_steps)
    # --
    L = as_loop(L, 'L', period, 'harmonic_margins')
    loop = LoopHTF(L, nharmonics, internal_harmonics)
    num = check_positive_int(omega_num, 'omega_num', minimum=16)
    skew = float(skew)
    wp = loop.omega_p
    nsteps = None if floquet_steps is None else check_positive_int(floquet_steps,
                                                                   'floquet_steps')
    _, axis_w = open_loop_exponents(L, nsteps=nsteps)
    # the strip, extended by ω_p/8 on both sides so that crossings at its edges
    # (multiplier -1) are seen from both sides
    w = np.linspace(-5 * wp / 8, 5 * wp / 8, num)
    poles = np.concatenate([axis_w + k * wp for k in (-1, 0, 1)]) if axis_w.size else axis_w
    if poles.size:
        # the grid steps over each pole of L̂ closely (asymmetrically, so that no
        # bisection lands on it): other branches may cross right there
        w = w[np.min(np.abs(w[:, None] - poles[None, :]), axis=1) > 1e-6 * wp]
        near = np.concatenate([poles - 1e-7 * wp, poles + 1.37e-7 * wp])
        w = np.sort(np.concatenate([w, near[np.abs(near) < 5 * wp / 8]]))
    Lh = loop(1j * w)
    # near a pole on the axis every harmonic row is large: not a truncation effect
    far = (np.min(np.abs(w[:, None] - poles[None, :]), axis=1) > wp / 20 if poles.size
           else np.ones(len(w), bool))
    edge = _edge_size(loop, Lh[far] - loop.hss.J)     # the feedthrough is exact
    eig = _tracked(Lh)

    gains, phases = [], []
    for b in range(eig.shape[1]):
        lam = eig[:, b]
        for i in _sign_changes(lam.imag):
            if min(lam[i].real, lam[i + 1].real) < 0:
                hit = _refine(loop, w[i], w[i + 1], lam[i], lam[i + 1], np.imag)
                if hit and hit[1].real < 0 and abs(hit[1].imag) <= _REAL_RTOL * abs(hit[1]):
                    gm = 1 / abs(hit[1])
                    if 1 / _GAIN_LIMIT < gm < _GAIN_LIMIT:
                        gains.append(_point(loop, gm, hit))
        logmag = _logabs(lam)
        for i in _sign_changes(logmag):
            hit = _refine(loop, w[i], w[i + 1], lam[i], lam[i + 1], _logabs)
            if hit and abs(abs(hit[1]) - 1) <= _REAL_RTOL:
                pm = float(np.remainder(np.angle(hit[1], deg=True), 360.0) - 180.0)
                phases.append(_point(loop, pm, hit, odd=True))
    gains, phases = _unique(gains, wp), _unique(phases, wp)
    # gains k that make I + k D(t) singular end the range of the gain margins:
    # the closed loop is ill-posed there (its exponents run off to infinity)
    k_lo, k_hi = ill_posed_gains(L.D)
    gains = [g for g in gains if k_lo < g.value < k_hi]

    above = [g for g in gains if g.value > 1]
    below = [g for g in gains if g.value < 1]
    upper = min(above, key=lambda g: g.value) if above else _NONE
    lower = (max(below, key=lambda g: g.value) if below
             else MarginPoint(0.0, float('nan'), 0, float('nan')))
    if k_hi < upper.value:
        upper = MarginPoint(k_hi, float('nan'), 0, float('inf'))
    if k_lo > lower.value:
        lower = MarginPoint(k_lo, float('nan'), 0, float('inf'))
    phase = min(phases, key=lambda p: abs(p.value)) if phases else _NONE
    eye = np.eye(loop.size)
    stability = _extremum(loop, w, Lh, lambda M: np.linalg.svd(
        eye + M, compute_uv=False)[..., -1], 'min')
    offset = 0.5 * (skew - 1)

    def balanced(M):
        # σ_max of S + (σ - 1)/2 I with S = (I + L̂)^{-1}, at a stack of points
        S = np.linalg.inv(eye + M)
        return np.linalg.svd(S + offset * eye, compute_uv=False)[..., 0]

    peak = _extremum(loop, w, Lh, balanced, 'max')
    alpha = 1 / peak.value
    disk = peak._replace(value=alpha)
    dgain, dphase = _disk_gain_phase(alpha, skew)
    confirmed = check and _verify(L, loop, upper, lower, k_lo, k_hi, nsteps=nsteps)
    _check_edge(loop, edge, edge_tol, confirmed)
    return HarmonicMargins(gain_upper=upper, gain_lower=lower, phase=phase,
                           stability=stability, disk=disk, disk_gain=dgain,
                           disk_phase=dphase, gain_crossings=gains,
                           phase_crossings=phases, nharmonics=loop.N, skew=skew)


def stability_margins(L, returnall=False, *, nharmonics=10, period=None, omega_num=801,
                      internal_harmonics=None):
    """Stability margins of a periodic loop, in python-control's convention.

    The periodic counterpart of `control.stability_margins`: the same
    return values, computed by `harmonic_margins` on the loop HTF; the
    frequencies are physical frequencies ``|ω + nω_p|``.

    Parameters
    ----------
    L : LTPStateSpace, control.StateSpace or sequence of systems
        The continuous-time loop (see `harmonic_margins`).
    returnall : bool
        Return every gain and phase crossing (arrays) instead of the
        smallest margins.
    nharmonics : int
        Truncation N of the loop HTF.
    period : float, optional
        Period of an LTI loop.
    omega_num : int
        Grid points over the strip.
    internal_harmonics : int, optional
        See `htf`.

    Returns
    -------
    gm : float
        Gain margin: of all crossings, the one with the smallest
        ``|log gm|`` (upper or lower), as python-control.
    pm : float
        Phase margin in degrees (smallest magnitude).
    sm : float
        Stability margin ``min σ_min(I + L̂(jω))``.
    wpc, wgc, wms : float
        Frequencies (rad/s) of gm, pm and sm.

    Notes
    -----
    python-control's ``sm`` is the smallest *interior* local minimum of
    ``|1 + L(jω)|`` over ω > 0; ours is the minimum over all frequencies,
    so for an LTI loop whose minimum distance is reached at ω = 0 ours is
    the smaller (and correct) one.

    Examples
    --------
    >>> G = ct.tf([4], [1, 3, 3, 1])
    >>> ours = ltp.stability_margins(ltp.ltpss(G, period=1.0), nharmonics=5)
    >>> bool(np.allclose(ours, ct.stability_margins(G)))
    True
    """
    m = harmonic_margins(L, nharmonics, period=period, omega_num=omega_num,
                         internal_harmonics=internal_harmonics)
    if returnall:
        g, p = m.gain_crossings, m.phase_crossings
        return (np.array([x.value for x in g]), np.array([x.value for x in p]),
                np.array([m.stability.value]), np.array([x.frequency for x in g]),
                np.array([x.frequency for x in p]), np.array([m.stability.frequency]))
    g = (min(m.gain_crossings, key=lambda x: abs(np.log(x.value)))
         if m.gain_crossings else _NONE)
    return (g.value, m.phase.value, m.stability.value, g.frequency, m.phase.frequency,
            m.stability.frequency)


#
# Helpers
#

def _logabs(z):
    """log|z|, with -inf for z = 0 and no warning."""
    with np.errstate(divide='ignore'):
        return np.log(np.abs(z))


def _sign_changes(x):
    """Intervals [i, i+1] over which x changes sign strictly; a zero at a grid
    point counts once (as [i-1, i]) when its neighbours have opposite signs,
    and not at all when they agree (a tangency).

    Examples
    --------
    >>> from ltpcontrol._frequency.margins import _sign_changes
    >>> _sign_changes(np.array([1.0, -1.0, 0.0, 2.0, 0.0, 3.0]))
    array([0, 1])
    """
    sg = np.sign(x)
    strict = np.nonzero(sg[:-1] * sg[1:] < 0)[0]
    zero = np.nonzero(sg[1:-1] == 0)[0] + 1
    through = zero[sg[zero - 1] * sg[zero + 1] < 0] - 1
    return np.union1d(strict, through)


def _tracked(Lh):
    return track(np.linalg.eigvals(Lh))


def _refine(loop, w0, w1, ref0, ref1, fun):
    """Root of fun(λ(ω)) on [w0, w1] along the branch from ref0 to ref1."""
    def nearest(w):
        t = (w - w0) / (w1 - w0)
        ref = ref0 + t * (ref1 - ref0)
        try:
            lam, V = np.linalg.eig(loop(1j * w)[0])
        except ValueError:                   # on a pole of L̂: step off it, inwards
            step = 1e-3 * (w1 - w0) * (1 if w < 0.5 * (w0 + w1) else -1)
            lam, V = np.linalg.eig(loop(1j * (w + step))[0])
        i = np.argmin(np.abs(lam - ref))
        return lam[i], V[:, i]

    def g(w):
        return fun(nearest(w)[0])

    g0, g1 = g(w0), g(w1)
    if not (np.isfinite(g0) and np.isfinite(g1)) or g0 * g1 > 0:
        return None
    wr = brentq(g, w0, w1, xtol=1e-15 * loop.omega_p, rtol=1e-15)
    lam, v = nearest(wr)
    return wr, lam, v


def _point(loop, value, hit, odd=False):
    """The margin at a crossing; `odd` for a phase, which the mirror negates."""
    w, _, v = hit
    n = loop.dominant_harmonic(v)
    wp = loop.omega_p
    # the strip (-ω_p/2, ω_p/2]: a crossing seen in its extension is shifted back
    k = int(np.round((w - fold(w, wp)) / wp))
    if abs(w - k * wp + wp / 2) <= 1e-9 * wp:
        k -= 1
    w, n = w - k * wp, n + k
    f = w + n * wp
    if f < 0:                  # the mirrored crossing (-ω, -n) of a real loop
        w, n, f = -w, -n, -f
        value = -value if odd else value
    if abs(w + wp / 2) <= 1e-9 * wp:        # -ω_p/2 is the strip's edge ω_p/2
        w, n = w + wp, n - 1
    return MarginPoint(float(value), float(w), int(n), float(f))


def _unique(points, wp):
    """One point per (frequency, value): the strip extension and mirrors repeat them."""
    out = []
    for p in sorted(points, key=lambda p: p.frequency):
        if not any(abs(p.frequency - q.frequency) <= 1e-5 * wp
                   and abs(p.value - q.value) <= 1e-5 * max(1.0, abs(q.value)) for q in out):
            out.append(p)
    return out


def _extremum(loop, w, Lh, fun, kind):
    """Refined min (or max) of fun(L̂(jω)) over the grid, as a MarginPoint
    (`fun` maps a stack of matrices to their values)."""
    sign = 1.0 if kind == 'min' else -1.0
    vals = fun(Lh)
    i = int(np.argmin(sign * vals))
    lo, hi = w[max(i - 1, 0)], w[min(i + 1, len(w) - 1)]
    res = minimize_scalar(lambda x: sign * fun(loop(1j * x)[0]), bounds=(lo, hi),
                          method='bounded', options={'xatol': 1e-13 * loop.omega_p})
    # res.fun is sign * fun
    wbest, vbest = (res.x, sign * res.fun) if res.fun < sign * vals[i] else (w[i], vals[i])
    # harmonic: the block carrying the right singular vector of I + L̂
    M = np.eye(loop.size) + loop(1j * wbest)[0]
    _, _, Vh = np.linalg.svd(M)
    v = Vh[-1].conj()
    return _point(loop, float(vbest), (wbest, None, v))


def _disk_gain_phase(alpha, skew):
    """Gain interval and phase (deg) of the disk of radius α (control.disk_margins)."""
    alpha, skew = np.float64(alpha), np.float64(skew)        # α = 2: gmax = ∞, not an error
    with np.errstate(divide='ignore', invalid='ignore'):
        gmin = (1 - 0.5 * alpha * (1 - skew)) / (1 + 0.5 * alpha * (1 + skew))
        gmax = (1 + 0.5 * alpha * (1 - skew)) / (1 - 0.5 * alpha * (1 + skew))
        if gmax < 0 or not np.isfinite(gmax):
            gmax = float('inf')
        c = (1 + gmin * gmax) / (gmin + gmax) if np.isfinite(gmax) else None
    if c is None:
        phase = 90.0
    else:
        phase = float(np.degrees(np.arccos(c))) if abs(c) < 1 else float('inf')
    return (float(gmin), float(gmax)), phase


def _verify(L, loop, upper, lower, k_lo=0.0, k_hi=np.inf, delta=1e-3, nsteps=None):
    """Floquet check of the gain margins (MarginPoints `upper`, `lower`).

    At a margin k the closed loop has an exponent at jω where ``-1/k`` is an
    eigenvalue μ of ``L̂(jω)``; along the branch ``μ'(s) ds = dk / k²``, so
    the gain ``k(1 ± δ)`` just beyond the margin moves it to
    ``jω + ds``, ``ds = ±δ / (k μ'(jω))``.  The closed loop with that gain
    must have its exponents in the right half plane there (within
    ``0.9 |ds|``, modulo jω_p and with the conjugate) and nowhere else: no
    such exponent means no crossing at the margin, another one an exponent
    that crossed at a gain nearer 1 (a crossing missed between grid
    points).  A margin set by an ill-posed gain is checked from inside (no
    exponent in the right half plane).  So each finite margin costs one
    Floquet computation; only when a check fails is the closed loop itself
    computed, and the warning given when it is stable (the margins of an
    unstable closed loop are not margins).  Returns True when at least one
    finite margin was checked and every check agreed.
    """
    eye = np.eye(L.ninputs)
    wp = L.omega_p
    atol = 1e-9 * wp

    def unstable(k):
        with warnings.catch_warnings():
            # only the verdict is used, 0.1 % away from the boundary
            warnings.filterwarnings('ignore', message='product_eigenvalues')
            lam = loop_exponents(feedback(series(L, k * eye), eye), nsteps)
        return lam[lam.real > atol]

    def predicted(m, step):
        # ds = (k' - k) / (k² μ'(jω)), μ' = dμ/ds by central differences
        h = 1e-6 * wp
        mu = -1 / m.value
        ends = []
        for w in (m.omega - h, m.omega + h):
            ev = np.linalg.eigvals(loop(1j * w)[0])
            ends.append(ev[np.argmin(np.abs(ev - mu))])
        dmu = (ends[1] - ends[0]) / (2j * h)
        return 1j * m.omega + (step - 1) / (m.value * dmu)

    def explained(lam, m, target):
        ds = abs(target - 1j * m.omega)
        out = np.zeros(len(lam), bool)
        for c in (target, target.conjugate()):
            gap = lam - c
            out |= np.abs(gap.real + 1j * fold(gap.imag, wp)) <= 0.9 * ds
        return out

    bad, checked = [], 0
    for m, step in ((upper, 1 + delta), (lower, 1 - delta)):
        if not (np.isfinite(m.value) and m.value > 0):
            continue
        checked += 1
        beyond = m.value * step
        if m.frequency == np.inf or not k_lo < beyond < k_hi:
            # a margin set by an ill-posed gain: just inside must be stable
            k = m.value / step
            if unstable(k).size:
                bad.append(k)
            continue
        lam = unstable(beyond)
        if not lam.size or not np.all(explained(lam, m, predicted(m, step))):
            bad.append(beyond)
    if bad and not unstable(1.0).size:
        warnings.warn(f"harmonic_margins: the Floquet exponents of the closed loop with "
                      f"the gains {bad} contradict the gain margins ({lower.value:.6g}, "
                      f"{upper.value:.6g}): a crossing was missed between grid points; "
                      "increase omega_num", UserWarning, stacklevel=3)
    return checked > 0 and not bad


def _edge_size(loop, Lh):
    """Largest |L̂| in the outermost harmonic blocks of the stack `Lh`."""
    m = loop.m
    return max(np.abs(Lh[:, :m, :]).max(), np.abs(Lh[:, -m:, :]).max(),
               np.abs(Lh[:, :, :m]).max(), np.abs(Lh[:, :, -m:]).max())


def _check_edge(loop, Lh, tol, confirmed=False):
    """Warn when the outermost harmonic blocks of L̂_N are not small.

    `Lh` is the stack of L̂_N or the size `_edge_size` found in it.  When the
    Floquet check `confirmed` the gain margins, the warning says so and
    restricts its doubt to the margins that check does not cover.
    """
    N = loop.N
    edge = Lh if np.ndim(Lh) == 0 else _edge_size(loop, Lh)
    if edge <= tol:
        return
    if confirmed:
        warnings.warn(f"the loop HTF is not small at its truncation edge (|L̂| up to "
                      f"{edge:.2g} in harmonics ±{N}); the gain margins are confirmed by "
                      "the Floquet exponents of the closed loop, the phase, stability and "
                      "disk margins are not: increase nharmonics to confirm them",
                      UserWarning, stacklevel=3)
        return
    warnings.warn(f"the loop HTF is not small at its truncation edge (|L̂| up to "
                  f"{edge:.2g} in harmonics ±{N}): margins beyond them may be "
                  "missed; increase nharmonics", UserWarning, stacklevel=3)
