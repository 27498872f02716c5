"""Nyquist criterion and margins of loops with measured (sampled) HTFs.

The impedance-based criterion multiplies a converter admittance — a model,
or an HTF estimated from measurements (`estimate_htf`, an `HTFData`) — by
a network impedance (`rlc_impedance`): ``L = Z Y``.  With models only, the
product is realized exactly (`harmonic_product`) and `nyquist_htf` /
`harmonic_margins` count it as any loop.  With a measured factor only the
samples ``L̂_N(jω)`` at the strip frequencies ω for which every ``ω + nω_p``
(``|n| <= N``) lies on the data grid are known, and the count is that of
the sampled curve:

* ``det(I + L̂_N(jω))`` is followed from sample to sample and closed from
  ``ω_p/2`` back to ``-ω_p/2`` by periodicity; a turn between samples
  larger than the grid resolves is not seen (the largest phase step is
  reported, and a step over π/2 warns);
* the strip's horizontal edges cannot be integrated (the data live on the
  axis only), so for a truncated biproper loop the count is right only
  once N is large enough for the closure gap to be small (reported);
* the open-loop exponents P of the measured factor cannot be computed
  from frequency samples: ``open_loop_unstable=`` states them (0 for the
  admittance of a converter that is stable on an ideal grid); without it
  the encirclements are given but no verdict;
* no Floquet cross-check is possible; the components the data leave
  undetermined (NaN) drop the frequencies that need them.

A real data factor is mirrored to negative frequencies by
``G_k(-jω) = conj(G_{-k}(jω))``.
"""

from dataclasses import dataclass
import warnings

import numpy as np

from .htf import HTF, HTFData
from .impedance import LTIHTF
from .margins import HarmonicMargins, MarginPoint, harmonic_margins
from .nyquist import HarmonicNyquistResponse, nyquist_htf, track
from .products import harmonic_product
from .._core.floquet import floquet_exponents
from .._core.ltpsys import LTPStateSpace
from .._core.registry import override
from .._core.coerce import as_ltp
from .._core.validation import check_positive_int, commensurate, real_array

__all__ = ['impedance_nyquist', 'impedance_margins', 'SampledNyquistResponse']

# a phase step of det(I + L̂) between neighbouring samples beyond this warns
_MAX_STEP = np.pi / 2
# grid frequencies match to this fraction of ω_p
_GRID_RTOL = 1e-9


@dataclass(frozen=True, repr=False)
class SampledNyquistResponse(HarmonicNyquistResponse):
    """`impedance_nyquist` of a loop with a measured (sampled) factor.

    The attributes of `HarmonicNyquistResponse`, with ``open_loop_unstable``
    (and so ``closed_loop_unstable`` and ``stable``) None when the open-loop
    exponents of the measured factors were not given, and:

    Attributes
    ----------
    encirclements, closure_gap, min_distance, nharmonics, omega_p, sysname
        As in `HarmonicNyquistResponse`.
    open_loop_unstable : int or None
        P of the whole loop: the given exponents of the measured factors
        plus those computed for the model factors (None when not given).
    omega : ndarray
        The strip frequencies sampled (sorted).
    contour : ndarray of complex
        ``jω`` at those frequencies.
    det : ndarray of complex
        ``det(I + L̂_N(jω))`` at the samples.
    eigenloci : ndarray of complex
        Eigenvalues of ``L̂_N(jω)``, tracked from sample to sample.
    edge_turns : float
        0: the strip's horizontal edges are not integrated.
    floquet_unstable : None
        No Floquet check is possible.
    max_phase_step : float
        Largest phase change of ``det(I + L̂_N)`` between neighbouring
        samples (radians): below π/2 the samples resolve the curve.  The
        step that closes the curve, from ``ω_p/2`` to ``-ω_p/2``, is
        measured by ``closure_gap``.
    caveats : tuple of str
        What the count rests on (module notes).

    Examples
    --------
    >>> w = np.arange(1, 400) * 0.25                     # a grid of ω_p/4 steps
    >>> G = np.zeros((3, 1, 1, w.size), complex)
    >>> G[1, 0, 0] = 2 / (1j * w + 1)                    # a measured 2/(s + 1)
    >>> Y = ltp.HTFData(G, w, period=2 * np.pi)
    >>> resp = ltp.impedance_nyquist([Y], 5, open_loop_unstable=0)
    >>> resp.encirclements, resp.stable, len(resp.caveats) > 0
    (0, True, True)
    """

    max_phase_step: float = 0.0
    caveats: tuple = ()

    @property
    def closed_loop_unstable(self):
        """Verdict Z = P - encirclements (None when P was not given)."""
        P = self.open_loop_unstable
        return None if P is None else P - self.encirclements

    @property
    def stable(self):
        """True when Z is 0 (None when P was not given)."""
        Z = self.closed_loop_unstable
        return None if Z is None else Z == 0

    def __repr__(self):
        return (f"<SampledNyquistResponse {self.sysname}: N={self.nharmonics}, "
                f"encirclements={self.encirclements}, P={self.open_loop_unstable}, "
                f"Z={self.closed_loop_unstable}, {len(self.omega)} samples, "
                f"max phase step {self.max_phase_step:.2g} rad>")

    def report(self, Hz=False):
        """The count, its samples and its caveats as text.

        Parameters
        ----------
        Hz : bool
            Frequencies in Hz instead of rad/s (python-control's keyword).

        Returns
        -------
        str

        Examples
        --------
        >>> w = np.arange(1, 400) * 0.25
        >>> G = np.zeros((1, 1, 1, w.size), complex)
        >>> G[0, 0, 0] = 2 / (1j * w + 1)
        >>> resp = ltp.impedance_nyquist([ltp.HTFData(G, w, period=2 * np.pi)], 2)
        >>> print(resp.report(Hz=True).splitlines()[1])
        samples: 3 in the strip [-0.07958, 0.07958] Hz (spacing 0.03979 Hz) of harmonics -2..2
        """
        unit, f = ('Hz', 1 / (2 * np.pi)) if Hz else ('rad/s', 1.0)
        w = self.omega
        step = np.min(np.diff(w)) if len(w) > 1 else np.nan
        P = self.open_loop_unstable
        verdict = ('no verdict' if P is None
                   else 'stable' if self.stable else 'unstable')
        lines = [f"encirclements {self.encirclements}, P = {P}, Z = "
                 f"{self.closed_loop_unstable} ({verdict})",
                 f"samples: {len(w)} in the strip [{-self.omega_p / 2 * f:.4g}, "
                 f"{self.omega_p / 2 * f:.4g}] {unit} (spacing {step * f:.4g} {unit}) of "
                 f"harmonics -{self.nharmonics}..{self.nharmonics}",
                 f"largest phase step {self.max_phase_step:.3g} rad, closure gap "
                 f"{self.closure_gap:.3g}, min singular value of I + L̂ "
                 f"{self.min_distance:.3g}"]
        lines += [f"- {c}" for c in self.caveats]
        return "\n".join(lines)


def impedance_nyquist(factors, nharmonics, omega=None, *, open_loop_unstable=None,
                      period=None, indent_radius=None, closure_tol=0.05,
                      internal_harmonics=None, check='auto', floquet_steps=None):
    """Generalized Nyquist criterion of a product of harmonic objects.

    Parameters
    ----------
    factors : sequence
        ``(F_1, ..., F_k)``: the loop ``F_1 F_2 ... F_k`` (``F_k`` acts
        first), closed by negative feedback, e.g. ``(Z_g, Y)``.  Models
        (`LTPStateSpace`, `HTFModel`, `LTIHTF` impedances, LTI systems) and
        measured HTFs (`HTFData`, e.g. from `estimate_htf`).
    nharmonics : int
        Truncation N of the loop HTF.
    omega : array_like, optional
        Strip frequencies (models only: see `nyquist_htf`; with measured
        factors: a subset of the strip frequencies the data provide).
    open_loop_unstable : int, optional
        With measured factors: their open-loop exponents in the right half
        plane (those of the model factors are computed and added).
        Without it no verdict is given.  Ignored for models only.
    period : float, optional
        Period, when no factor has one.
    indent_radius, closure_tol, internal_harmonics, check, floquet_steps
        Models only: see `nyquist_htf`.

    Returns
    -------
    HarmonicNyquistResponse or SampledNyquistResponse
        The exact count of `nyquist_htf` for models; the count of the
        sampled curve (with its caveats) when a factor is measured.

    Raises
    ------
    ValueError
        When the data provide no strip frequency for N harmonics (the
        grid must reach ``(N + 1/2) ω_p`` on a spacing dividing ω_p), for
        unknown keywords with measured factors, or a negative
        `open_loop_unstable`.

    Warns
    -----
    UserWarning
        When a phase step between samples exceeds π/2 (the grid may
        miss turns), when a model factor has exponents on the imaginary
        axis (sampled data cannot pass them), or the truncation edge of
        the sampled loop is not small.

    Examples
    --------
    Grid inductance times a model admittance (exact), and the same
    admittance as frequency samples (count of the sampled curve):

    >>> T = 0.02
    >>> Y = ltp.ltpss(ct.tf([1], [2e-3, 0.1]), period=T)
    >>> Zg = ltp.rlc_impedance(L=5e-3, period=T, nharmonics=4)
    >>> ltp.impedance_nyquist((Zg, Y), 4).stable
    True
    >>> w = np.arange(1, 2000) * 2 * np.pi / T / 16
    >>> Yd = ltp.HTFData(ltp.htf(Y, 0).components(w)[1], w, period=T)
    >>> resp = ltp.impedance_nyquist((Zg, Yd), 4, open_loop_unstable=0)
    >>> resp.stable, resp.encirclements
    (True, 0)
    """
    factors = _factors(factors)
    if not any(isinstance(f, HTFData) for f in factors):
        L = harmonic_product(*factors, period=period)
        return nyquist_htf(L, nharmonics, omega, indent_radius=indent_radius,
                           closure_tol=closure_tol, internal_harmonics=internal_harmonics,
                           check=check, floquet_steps=floquet_steps)
    loop = _SampledLoop(factors, nharmonics, period, omega)
    P = _unstable(open_loop_unstable, loop)
    Lh = loop.values
    I = np.eye(Lh.shape[1])
    sign, logabs = np.linalg.slogdet(I + Lh)
    phase = np.angle(sign)
    steps = _wrap(np.diff(phase))
    closing = float(_wrap(phase[0] - phase[-1]))       # from ω_p/2 back to -ω_p/2
    enc = int(np.round((float(steps.sum()) + closing) / (2 * np.pi)))
    max_step = float(np.max(np.abs(steps), initial=0.0))
    with np.errstate(over='ignore', under='ignore'):
        det = np.exp(logabs + 1j * phase)
        gap = float(abs(np.exp(logabs[0] - logabs[-1] + 1j * (phase[0] - phase[-1])) - 1))
    dist = float(np.linalg.svd(I + Lh, compute_uv=False)[:, -1].min())
    caveats = list(loop.caveats)
    if max_step > _MAX_STEP:
        msg = (f"the phase of det(I + L̂) turns by up to {max_step:.2g} rad between "
               "neighbouring samples: the grid may miss encirclements (measure on a "
               "finer grid)")
        caveats.append(msg)
        warnings.warn(f"impedance_nyquist: {msg}", UserWarning, stacklevel=2)
    if abs(closing) > _MAX_STEP:
        caveats.append(f"the curve closes by a phase step of {closing:.2g} rad from ω_p/2 "
                       "to -ω_p/2 (truncation): raise nharmonics until it is small")
    if dist < 1e-8:
        caveats.append("a sample lies on a closed-loop exponent (stability boundary)")
    caveats.append("the count is that of the sampled curve closed by periodicity: the "
                   "strip's horizontal edges are not integrated (closure gap "
                   f"{gap:.2g}) and no Floquet check is possible")
    if P is None:
        caveats.append("no verdict: give open_loop_unstable, the open-loop exponents of "
                       "the measured factors in the right half plane")
    return SampledNyquistResponse(
        encirclements=enc, open_loop_unstable=P, closure_gap=gap, min_distance=dist,
        omega=loop.omega, contour=1j * loop.omega, det=det,
        eigenloci=track(np.linalg.eigvals(Lh)), nharmonics=loop.N,
        omega_p=loop.omega_p, sysname=loop.name, edge_turns=0.0, floquet_unstable=None,
        max_phase_step=max_step, caveats=tuple(caveats))


def impedance_margins(factors, nharmonics=10, *, period=None, skew=0.0, omega_num=801,
                      internal_harmonics=None, edge_tol=0.05, check=True,
                      floquet_steps=None):
    """Gain, phase, stability and disk margins of a product of harmonic objects.

    Parameters
    ----------
    factors : sequence
        The loop ``F_1 ... F_k`` (see `impedance_nyquist`).
    nharmonics : int
        Truncation N of the loop HTF.
    period : float, optional
        Period, when no factor has one.
    skew : float
        Skew σ of the disk margin (see `harmonic_margins`).
    omega_num, internal_harmonics, edge_tol, check, floquet_steps
        Models only: see `harmonic_margins`.

    Returns
    -------
    HarmonicMargins
        For models, exactly `harmonic_margins` of the realized product.
        With measured factors the crossings of the tracked eigenloci are
        interpolated linearly between samples (no refinement, no Floquet
        check: the accuracy is the grid's), and the stability and disk
        margins are the extrema over the samples.

    Raises
    ------
    ValueError
        As `impedance_nyquist`.

    Examples
    --------
    ``4/(s+1)^3`` (python-control: gain margin 2) as measured samples:

    >>> w = np.arange(1, 4000) * 0.01
    >>> G = np.zeros((1, 1, 1, w.size), complex)
    >>> G[0, 0, 0] = 4 / (1j * w + 1) ** 3
    >>> m = ltp.impedance_margins([ltp.HTFData(G, w, period=2 * np.pi)], 3)
    >>> round(m.gain_upper.value, 3), round(m.gain_upper.frequency, 2)
    (2.0, 1.73)
    """
    factors = _factors(factors)
    if not any(isinstance(f, HTFData) for f in factors):
        return harmonic_margins(harmonic_product(*factors, period=period), nharmonics,
                                omega_num=omega_num, skew=skew,
                                internal_harmonics=internal_harmonics, edge_tol=edge_tol,
                                check=check, floquet_steps=floquet_steps)
    skew = float(real_array(skew, 'skew', ndim=0))
    # the strip widened by ω_p/8 on both sides: crossings at its edges are seen
    # from both sides (and counted once, by physical frequency)
    loop = _SampledLoop(factors, nharmonics, period, None, extend=0.125)
    Lh, w, wp = loop.values, loop.omega, loop.omega_p
    eig = track(np.linalg.eigvals(Lh))
    _, V = np.linalg.eig(Lh)
    gains, phases = [], []
    for b in range(eig.shape[1]):
        lam = eig[:, b]
        for i in np.nonzero(np.sign(lam.imag[:-1]) * np.sign(lam.imag[1:]) < 0)[0]:
            t = lam.imag[i] / (lam.imag[i] - lam.imag[i + 1])
            z = lam[i] + t * (lam[i + 1] - lam[i])
            if z.real < 0:
                gains.append(_point(loop, 1 / abs(z.real), w[i] + t * (w[i + 1] - w[i]),
                                    Lh[i], lam[i]))
        la = np.log(np.abs(lam))
        for i in np.nonzero(np.sign(la[:-1]) * np.sign(la[1:]) < 0)[0]:
            t = la[i] / (la[i] - la[i + 1])
            ang = np.angle(lam[i]) + t * _wrap(np.angle(lam[i + 1]) - np.angle(lam[i]))
            pm = float(np.remainder(np.degrees(ang), 360.0) - 180.0)
            phases.append(_point(loop, pm, w[i] + t * (w[i + 1] - w[i]), Lh[i], lam[i],
                                 odd=True))
    gains, phases = _unique(gains, wp), _unique(phases, wp)
    above = [g for g in gains if g.value > 1]
    below = [g for g in gains if g.value < 1]
    inf = MarginPoint(float('inf'), float('nan'), 0, float('nan'))
    upper = min(above, key=lambda g: g.value) if above else inf
    lower = (max(below, key=lambda g: g.value) if below
             else MarginPoint(0.0, float('nan'), 0, float('nan')))
    phase = min(phases, key=lambda p: abs(p.value)) if phases else inf
    I = np.eye(Lh.shape[1])
    smin = np.linalg.svd(I + Lh, compute_uv=False)[:, -1]
    i = int(np.argmin(smin))
    stability = _point(loop, float(smin[i]), w[i], None, None,
                       v=np.linalg.svd(I + Lh[i])[2][-1].conj())
    S = np.linalg.inv(I + Lh) + 0.5 * (skew - 1) * I
    smax = np.linalg.svd(S, compute_uv=False)[:, 0]
    j = int(np.argmax(smax))
    alpha = 1 / float(smax[j])
    disk = _point(loop, alpha, w[j], None, None, v=np.linalg.svd(S[j])[2][0].conj())
    dgain, dphase = _disk(alpha, skew)
    return HarmonicMargins(gain_upper=upper, gain_lower=lower, phase=phase,
                           stability=stability, disk=disk, disk_gain=dgain,
                           disk_phase=dphase, gain_crossings=gains,
                           phase_crossings=phases, nharmonics=loop.N, skew=skew)


class _SampledLoop:
    """``L̂_N(jω)`` of the product at the strip frequencies the data provide."""

    def __init__(self, factors, nharmonics, period, omega, extend=0.0):
        self.N = N = check_positive_int(nharmonics, 'nharmonics', minimum=1)
        data = [f for f in factors if isinstance(f, HTFData)]
        periods = [f.period for f in factors if isinstance(f, (HTF, LTPStateSpace))]
        T = periods[0] if periods else period
        if T is None:
            raise ValueError("impedance_nyquist: no factor has a period; pass period=")
        for p in periods[1:]:
            T = commensurate(T, p)
        wp = 2 * np.pi / T
        self.omega_p, self.name = wp, 'L'
        caveats = []
        w = _strip(data, N, wp, extend) if omega is None else np.unique(
            real_array(omega, 'omega', ndim=1))
        mats, keep = [], np.ones(len(w), bool)
        P_models = 0
        for i, f in enumerate(factors):
            if isinstance(f, HTFData):
                M, ok = _data_blocks(f, w, N, wp, T)
                keep &= ok
                if f.nharmonics < N:
                    caveats.append(f"factor {i + 1} (measured) has components up to "
                                   f"|k| = {f.nharmonics}: those beyond are taken as zero")
            else:
                sys = _model(f, T)
                M = _model_blocks(f, sys, w, N)
                lam = None
                if isinstance(f, LTIHTF):
                    lam = np.atleast_1d(f.sys.poles()).astype(complex)
                elif sys is not None and sys.nstates:
                    lam = (np.linalg.eigvals(sys.A(0.0)) if sys.A.is_constant
                           else np.atleast_1d(floquet_exponents(sys)))
                elif sys is None:
                    caveats.append(f"factor {i + 1} ({type(f).__name__}): its open-loop "
                                   "exponents are not computed; count them in "
                                   "open_loop_unstable")
                if lam is not None and lam.size:
                    atol = 1e-9 * wp
                    P_models += int(np.count_nonzero(lam.real > atol))
                    if np.any(np.abs(lam.real) <= atol):
                        msg = (f"factor {i + 1} has exponents on the imaginary axis: "
                               "sampled data cannot pass them on the right")
                        caveats.append(msg)
                        warnings.warn(f"impedance_nyquist: {msg}", UserWarning,
                                      stacklevel=4)
            mats.append(M)
        if not keep.any():
            raise ValueError("impedance_nyquist: the measured components are undetermined "
                             "(NaN) at every strip frequency needed")
        if not keep.all():
            caveats.append(f"{int((~keep).sum())} strip frequencies dropped: components "
                           "undetermined there (NaN)")
        Lh = mats[0][keep]
        for M in mats[1:]:
            Lh = Lh @ M[keep]
        self.omega, self.values = w[keep], Lh
        self.P_models = P_models
        m = Lh.shape[1] // (2 * N + 1)
        self.m = m
        edge = max(np.abs(Lh[:, :m, :]).max(), np.abs(Lh[:, -m:, :]).max(),
                   np.abs(Lh[:, :, :m]).max(), np.abs(Lh[:, :, -m:]).max())
        if edge > 0.05:
            caveats.append(f"the loop HTF reaches {edge:.2g} in its outermost harmonics "
                           f"±{N}: the truncation may change the count")
        self.caveats = caveats

    def dominant_harmonic(self, v):
        blocks = np.abs(v.reshape(2 * self.N + 1, self.m)) ** 2
        return int(np.argmax(blocks.sum(axis=1))) - self.N


#
# Helpers
#

def _factors(factors):
    if isinstance(factors, (HTF, LTPStateSpace)) or not isinstance(factors, (list, tuple)):
        factors = [factors]
    if not factors:
        raise ValueError("factors must hold at least one factor")
    return list(factors)


def _unstable(P, loop):
    if P is None:
        return None
    if isinstance(P, bool) or not isinstance(P, (int, np.integer)) or P < 0:
        raise ValueError(f"open_loop_unstable must be an integer >= 0, got {P!r}")
    return int(P) + loop.P_models


def _strip(data, N, wp, extend=0.0):
    """Strip frequencies ω at which every ``|ω + nω_p|``, |n| <= N, is on every grid
    (the strip widened by `extend` ω_p on both sides)."""
    g = data[0].omega
    half = (0.5 + extend) * wp
    cand = np.concatenate([s * g - n * wp for s in (1, -1) for n in range(-N, N + 1)])
    cand = cand[(cand > -half + 1e-9 * wp) & (cand <= half * (1 + 1e-9))]
    cand = np.unique(np.round(cand / (wp * _GRID_RTOL)) * (wp * _GRID_RTOL))
    ok = np.ones(len(cand), bool)
    for H in data:
        for n in range(-N, N + 1):
            ok &= _on_grid(H.omega, np.abs(cand + n * wp), wp)
    w = cand[ok]
    if len(w) < 3:
        raise ValueError(
            f"impedance_nyquist: the data provide {len(w)} strip frequencies for "
            f"nharmonics={N}: the grid must reach (N + 1/2) ω_p = {(N + 0.5) * wp:.4g} "
            "rad/s on a spacing that divides ω_p (e.g. the grid of estimate_htf)")
    return w


def _on_grid(grid, x, wp):
    pos = np.clip(np.searchsorted(grid, x), 0, len(grid) - 1)
    lo = np.clip(pos - 1, 0, len(grid) - 1)
    return np.minimum(np.abs(grid[pos] - x), np.abs(grid[lo] - x)) <= _GRID_RTOL * wp * 1e3


def _data_blocks(H, w, N, wp, T):
    """Block matrix of an HTFData at strip frequencies w (mirrored), and where defined."""
    K, ny, nu = H.nharmonics, H.noutputs, H.ninputs
    if abs(H.period - T) > 1e-9 * T:
        raise ValueError(f"a measured factor has the period {H.period:g}, the loop "
                         f"{T:g}: HTF data are only combined at their own period")
    grid, comps = H.omega, H._components_on(None, list(H.harmonics))[1]
    never = np.all(np.isnan(comps), axis=(1, 2, 3))          # component never identified
    out = np.zeros((len(w), (2 * N + 1) * ny, (2 * N + 1) * nu), complex)
    ok = np.ones(len(w), bool)
    for a, n in enumerate(range(-N, N + 1)):
        nu_ = w + n * wp
        pos = np.argmin(np.abs(grid[None, :] - np.abs(nu_)[:, None]), axis=1)
        for b, m in enumerate(range(-N, N + 1)):
            k = n - m
            if abs(k) > K:
                continue
            # G_k(jν) for ν >= 0, conj(G_{-k}(j|ν|)) for ν < 0
            G = np.where((nu_ >= 0)[:, None, None],
                         comps[k + K][..., pos].transpose(2, 0, 1),
                         np.conj(comps[-k + K][..., pos].transpose(2, 0, 1)))
            kk = np.where(nu_ >= 0, k, -k) + K
            bad = np.isnan(G).any(axis=(1, 2))
            G = np.where(np.isnan(G), 0, G)
            ok &= ~bad | never[kk]
            out[:, a * ny:(a + 1) * ny, b * nu:(b + 1) * nu] = G
    return out, ok


def _model(f, T):
    if isinstance(f, LTIHTF):
        return None
    if isinstance(f, HTF):
        if not hasattr(f, '_source'):
            return None
        return f._source[0]
    if isinstance(f, LTPStateSpace):
        return f
    return as_ltp(f, 'factor', period=T)


def _model_blocks(f, sys, w, N):
    if isinstance(f, LTIHTF):
        H = LTIHTF(f.sys, f.period, N)
    elif sys is not None:
        from .htf import htf
        H = htf(sys, N)
    elif isinstance(f, HTF) and f.nharmonics >= N:
        # another harmonic object (frame change, delays): its central blocks
        M = np.moveaxis(np.asarray(f(1j * w), complex), -1, 0)
        d = f.nharmonics - N
        r = slice(d * f.noutputs, (d + 2 * N + 1) * f.noutputs)
        c = slice(d * f.ninputs, (d + 2 * N + 1) * f.ninputs)
        return M[:, r, c]
    else:
        raise ValueError(f"impedance_nyquist: a factor of type {type(f).__name__} with "
                         f"{f.nharmonics} harmonics cannot be evaluated with N = {N}")
    return np.moveaxis(H(1j * w), -1, 0)


def _point(loop, value, w, Lh, lam, odd=False, v=None):
    """A MarginPoint at strip frequency w (harmonic from the eigen/singular vector)."""
    wp = loop.omega_p
    if v is None:
        ev, V = np.linalg.eig(Lh)
        v = V[:, np.argmin(np.abs(ev - lam))]
    n = loop.dominant_harmonic(v)
    f = w + n * wp
    if f < 0:
        w, n, f = -w, -n, -f
        value = -value if odd else value
    return MarginPoint(float(value), float(w), int(n), float(f))


def _unique(points, wp):
    out = []
    for p in sorted(points, key=lambda p: p.frequency):
        if not any(abs(p.frequency - q.frequency) <= 1e-3 * wp
                   and abs(p.value - q.value) <= 1e-3 * max(1.0, abs(q.value)) for q in out):
            out.append(p)
    return out


def _disk(alpha, skew):
    with np.errstate(divide='ignore', invalid='ignore'):
        gmin = (1 - 0.5 * alpha * (1 - skew)) / (1 + 0.5 * alpha * (1 + skew))
        gmax = (1 + 0.5 * alpha * (1 - skew)) / (1 - 0.5 * alpha * (1 + skew))
    if gmax < 0 or not np.isfinite(gmax):
        return (float(gmin), float('inf')), 90.0
    c = (1 + gmin * gmax) / (gmin + gmax)
    return (float(gmin), float(gmax)), (float(np.degrees(np.arccos(c))) if abs(c) < 1
                                        else float('inf'))


def _wrap(x):
    return np.remainder(x + np.pi, 2 * np.pi) - np.pi


# nyquist_htf and harmonic_margins of loops with measured factors: the sampled count
@override('nyquist_htf', HTFData)
def _nyquist_htf_measured(L, nharmonics, omega=None, **options):
    return impedance_nyquist(L, nharmonics, omega, **options)


@override('harmonic_margins', HTFData)
def _harmonic_margins_measured(L, nharmonics=10, **options):
    return impedance_margins(L, nharmonics, **options)
