"""Generalized Nyquist criterion for periodic feedback loops.

The closed loop ``u = r - L y`` of a T-periodic loop ``L`` has the
characteristic exponents where ``det(I + L̂(s)) = 0`` (Hall & Wereley,
ACC 1990; Möllerstedt 2000).  Since ``L̂(s + jω_p)`` is ``L̂(s)`` with its
harmonic blocks shifted, one strip ``-ω_p/2 < Im s <= ω_p/2`` of the right
half plane holds every exponent once.  Its boundary, travelled clockwise —
up the imaginary axis, then out along ``Im s = ω_p/2`` and back along
``Im s = -ω_p/2`` (the two horizontal edges cancel by periodicity) —
gives, by the argument principle,

    encirclements (counter-clockwise, of 0 by det(I + L̂)) = P - Z,

with P the open-loop exponents and Z the closed-loop exponents in the
open right half plane.  With the HTF truncated to N harmonics the two
horizontal edges no longer cancel — for a biproper loop (``L(∞) ≠ 0``)
they carry whole turns at small N — so they are integrated (module
`contour`): the count is then exact for the truncated loop, whose
closed-loop exponents converge to the true ones as N grows.  The verdict
is cross-checked by the closed loop's Floquet exponents when they are
cheap.  The *closure gap* ``|f(-jω_p/2) / f(jω_p/2) - 1|`` of the curve on
the axis alone is kept as information.  Exponents on the imaginary axis
are passed on the right by semicircles of radius ``indent_radius`` (not
counted in P), as in `control.nyquist_response`.

For an LTI loop written as periodic, ``det(I + L̂_N(jω)) = Π_n (1 +
L(jω + jnω_p))``, so the count is that of the ordinary Nyquist plot over
``|ω| <= (N + 1/2) ω_p``; python-control counts *clockwise* encirclements
(``count = -encirclements``).
"""

from dataclasses import dataclass

import warnings

import numpy as np
import control as ct
import matplotlib.pyplot as plt
from scipy.optimize import linear_sum_assignment

from .contour import EDGE_OFFSET, abscissa_bound, path_phase, strip_closure
from .loop import LoopHTF, as_loop, fold, loop_exponents, open_loop_exponents
from .._core.ltpsys import feedback
from .._core.registry import overridden
from .._core.validation import check_positive, check_positive_int, real_array

__all__ = ['nyquist_htf', 'HarmonicNyquistResponse']

# refine an interval of the contour while the phase of det(I + L̂) turns more than this
_MAX_TURN = np.pi / 4
# bound on the number of contour points after refinement
_MAX_POINTS = 50_000
# uniform points of the default initial contour (refined where f turns fast)
_INITIAL_POINTS = 201
# extra points around each exponent near the axis, in units of its distance to it
_NEAR = np.array([-8.0, -4.0, -2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 2.0, 4.0, 8.0])
# check='auto' verifies the count by the closed loop's Floquet exponents up to this size
_CHECK_STATES = 60


@dataclass(frozen=True, repr=False)
class HarmonicNyquistResponse:
    """Result of `nyquist_htf`: the generalized Nyquist criterion of a periodic loop.

    Attributes
    ----------
    encirclements : int
        Counter-clockwise encirclements of the origin by
        ``det(I + L̂_N(s))`` along the contour (equivalently of -1 by the
        eigenloci of ``L̂_N``).
    count : int
        python-control's convention: clockwise encirclements,
        ``-encirclements``.
    open_loop_unstable : int
        P, the open-loop exponents with positive real part (one strip).
    closed_loop_unstable : int
        The verdict ``Z = P - encirclements``: closed-loop exponents with
        positive real part.
    stable : bool
        True when Z is 0 (closed loop asymptotically stable).
    closure_gap : float
        ``|f(-jω_p/2) / f(jω_p/2) - 1|`` of ``f = det(I + L̂_N)``: zero for
        the untruncated HTF.  Information only: the count integrates the
        strip's horizontal edges, so it needs no closed curve.
    edge_turns : float
        Turns of f along the strip's other sides (horizontal edges and the
        far side): zero for the untruncated HTF; whole turns at small N
        for biproper loops.
    floquet_unstable : int or None
        Z from the closed loop's Floquet exponents (None when not
        checked); a contradiction with the count warns.
    min_distance : float
        Smallest singular value of ``I + L̂_N`` on the contour (distance
        to a closed-loop exponent on the axis).
    omega : ndarray
        Contour parameter: frequencies in the strip ``[-ω_p/2, ω_p/2]``.
    contour : ndarray of complex
        The points s of the contour (``jω``, or the indentation).
    det : ndarray of complex
        ``det(I + L̂_N(s))`` on the contour (may over- or underflow for
        large N; the count uses its logarithm).
    eigenloci : ndarray of complex, shape (points, (2N+1) m)
        Eigenvalues of ``L̂_N(s)`` on the contour, tracked along it.
    nharmonics : int
        Truncation N.
    omega_p : float
        Fundamental frequency of the loop.
    sysname : str
        Name of the loop.

    Examples
    --------
    >>> L = ltp.ltpss(ct.tf([2], [1, 1]), period=0.2)
    >>> resp = ltp.nyquist_htf(L, 5)
    >>> resp.encirclements, resp.stable
    (0, True)
    """

    encirclements: int
    open_loop_unstable: int
    closure_gap: float
    min_distance: float
    omega: np.ndarray
    contour: np.ndarray
    det: np.ndarray
    eigenloci: np.ndarray
    nharmonics: int
    omega_p: float
    sysname: str
    edge_turns: float = 0.0
    floquet_unstable: object = None

    @property
    def count(self):
        """Clockwise encirclements (`control.nyquist_response` convention)."""
        return -self.encirclements

    @property
    def closed_loop_unstable(self):
        """Verdict Z = P - encirclements."""
        return self.open_loop_unstable - self.encirclements

    @property
    def stable(self):
        """True when the closed loop has no exponent in the right half plane."""
        return self.closed_loop_unstable == 0

    def __repr__(self):
        return (f"<HarmonicNyquistResponse {self.sysname}: N={self.nharmonics}, "
                f"encirclements={self.encirclements}, P={self.open_loop_unstable}, "
                f"Z={self.closed_loop_unstable}, closure_gap={self.closure_gap:.2g}>")

    def plot(self, kind='eigenloci', *, ax=None, title=None, max_curve_magnitude=20.0,
             **kwargs):
        """Nyquist plot of the eigenloci (critical point -1) or of the determinant.

        Parameters
        ----------
        kind : {'eigenloci', 'det'}
            The eigenvalues of ``L̂_N`` along the contour with the critical
            point -1 (default), or ``det(I + L̂_N)`` with the critical
            point 0.
        ax : matplotlib.axes.Axes, optional
            Axes to draw into.
        title : str, optional
            Figure title.
        max_curve_magnitude : float
            View radius around the origin.
        **kwargs
            Matplotlib line properties.

        Returns
        -------
        control.ControlPlot

        Examples
        --------
        >>> L = ltp.ltpss(ct.tf([2], [1, 1]), period=0.1)
        >>> cplt = ltp.nyquist_htf(L, 2).plot()
        >>> type(cplt).__name__
        'ControlPlot'
        """
        if kind not in ('eigenloci', 'det'):
            raise ValueError(f"kind must be 'eigenloci' or 'det', got {kind!r}")
        R = check_positive(max_curve_magnitude, 'max_curve_magnitude')
        if ax is None:
            fig, ax = plt.subplots()
        fig = ax.figure
        lines = []
        if kind == 'eigenloci':
            curves, critical = list(self.eigenloci.T), -1.0
        else:
            curves, critical = [self.det], 0.0
        color = kwargs.pop('color', None)
        for i, z in enumerate(curves):
            if np.all(np.abs(z) < 1e-3 * R) and kind == 'eigenloci' and i:
                continue        # branches of high harmonics that never leave the origin
            line, = ax.plot(z.real, z.imag, color=color or 'C0', **kwargs)
            _arrow(ax, z, line.get_color())
            lines.append(line)
        lines.append(ax.plot([critical], [0.0], 'r+', markersize=10)[0])
        ax.set_xlabel("Real axis")
        ax.set_ylabel("Imaginary axis")
        ax.grid(True, alpha=0.3)
        allz = np.concatenate([c[np.abs(c) <= R] for c in curves] + [np.array([critical])])
        span = max(1.5, 1.1 * np.abs(allz).max())
        ax.set_xlim(-span, span)
        ax.set_ylim(-span, span)
        ax.set_aspect('equal', adjustable='box')
        what = "eigenloci of L̂" if kind == 'eigenloci' else "det(I + L̂)"
        ax.set_title(title or f"Nyquist plot ({what}, N={self.nharmonics}) of "
                     f"{self.sysname}: {self.encirclements} encirclement(s), "
                     f"P={self.open_loop_unstable}")
        return ct.ControlPlot(_line_array(lines), np.array([[ax]]), fig)


def nyquist_htf(L, nharmonics, omega=None, *, period=None, indent_radius=None,
                closure_tol=0.05, internal_harmonics=None, check='auto',
                floquet_steps=None, open_loop_unstable=None):
    """Generalized Nyquist criterion for a periodic loop with negative feedback.

    Counts the encirclements of the origin by ``det(I + L̂_N(s))`` along the
    strip ``s = jω``, ``ω ∈ [-ω_p/2, ω_p/2]`` (closed by periodicity), and
    gives the verdict ``Z = P - encirclements`` on the closed loop
    ``u = r - y`` (module notes; Conventions page for the HTF).

    Parameters
    ----------
    L : LTPStateSpace, control.StateSpace or sequence of systems
        The continuous-time loop, square (m inputs, m outputs).  A sequence
        ``(L_1, ..., L_k)`` is the product ``L_1 ... L_k`` (``L_k`` acts
        first), e.g. ``(plant, controller)``; their periods must be
        commensurate.  An LTI loop needs `period`.  A sequence holding
        measured HTFs (`HTFData`, e.g. from `estimate_htf`) gives the count
        of the sampled curve, with its caveats (`impedance_nyquist`).
    nharmonics : int
        Truncation N >= 1 of the loop HTF.
    omega : array_like, optional
        Initial frequencies of the contour in ``[-ω_p/2, ω_p/2]`` (default
        201 uniform points); points are added around every open- and
        closed-loop exponent near the axis, spaced by its distance to it,
        and the contour is refined wherever the phase of the determinant
        turns by more than π/4, or its modulus changes by more than a
        factor e^0.5, between points.
    period : float, optional
        Period of an LTI loop.
    indent_radius : float, optional
        Radius of the semicircles around open-loop exponents on the
        imaginary axis (default ``1e-4 ω_p``).
    closure_tol : float
        Without a Floquet check, the outermost harmonic blocks of the
        loop HTF less its feedthrough (which fills them exactly, e.g. for
        a biproper loop) reaching this magnitude warn that the count is
        only that of the truncated loop.
    internal_harmonics : int, optional
        Truncation of the harmonic state space (see `htf`).
    check : bool or 'auto'
        Cross-check the verdict by the Floquet exponents of the closed
        loop (one more monodromy, whose exponents also place points of
        the contour).  'auto' (default) checks loops with a constant A or
        at most 60 states.
    floquet_steps : int, optional
        Steps per period of the Floquet computations (`monodromy`'s
        `nsteps`; default: its own choice, each step integrated with the
        sub-steps its error estimate asks).  Each system's exponents are
        computed once per call.
    open_loop_unstable : int, optional
        Loops with measured factors only: the open-loop exponents of the
        measured factors in the right half plane (see `impedance_nyquist`);
        without it their count gives no verdict.

    Returns
    -------
    HarmonicNyquistResponse
        With ``encirclements`` (counter-clockwise positive),
        ``open_loop_unstable`` (P), ``closed_loop_unstable`` (Z),
        ``closure_gap`` and ``.plot()``.

    Raises
    ------
    ControlDimension
        If the loop is not square.
    ValueError
        For a discrete-time loop, incommensurate periods, or `omega`
        outside the strip.

    Warns
    -----
    UserWarning
        When the count contradicts the closed loop's Floquet exponents
        (increase `nharmonics`); when, unchecked, the truncation edge of
        the loop HTF is not small; when the contour passes within
        rounding of a closed-loop exponent (the loop is at a stability
        boundary and the count is not reliable).

    Notes
    -----
    The determinant's phase is accumulated on the axis and along the
    strip's horizontal edges ``Im s = ±ω_p/2 + 10^-3 ω_p`` out to beyond
    every exponent of the truncated loop (module notes); an open-loop
    exponent whose harmonic representative lies beyond N is not seen.
    python-control's `control.nyquist_response` counts clockwise
    encirclements of -1: for an LTI loop written as periodic,
    ``ct.nyquist_response(L).count == -resp.encirclements`` when N covers
    the loop's bandwidth (``(N + 1/2) ω_p`` beyond the last crossing).

    Examples
    --------
    An unstable plant ``1/(s - 1)`` stabilized by the gain 2 (P = 1, one
    counter-clockwise encirclement):

    >>> L = ltp.ltpss(ct.tf([2], [1, -1]), period=0.2)
    >>> resp = ltp.nyquist_htf(L, 10)
    >>> resp.open_loop_unstable, resp.encirclements, resp.closed_loop_unstable
    (1, 1, 0)
    >>> ct.nyquist_response(ct.tf([2], [1, -1])).count == resp.count
    True
    """
    # -- loops with delays (ltpcontrol._delays.nyquist) or measured factors
    # (measured_loop): their own count --
    if (own := overridden('nyquist_htf', *(L if isinstance(L, (list, tuple)) else [L]))):
        extra = {} if open_loop_unstable is None else {'open_loop_unstable': open_loop_unstable}
        return own(L, nharmonics, omega, period=period, indent_radius=indent_radius,
                   closure_tol=closure_tol, internal_harmonics=internal_harmonics,
                   check=check, floquet_steps=floquet_steps, **extra)
    if open_loop_unstable is not None:
        raise ValueError("nyquist_htf: open_loop_unstable is for loops with measured "
                         "factors (HTFData); a model loop's exponents are computed")
    # --
    L = as_loop(L, 'L', period, 'nyquist_htf')
    loop = LoopHTF(L, nharmonics, internal_harmonics)
    wp = L.omega_p
    r = 1e-4 * wp if indent_radius is None else check_positive(
        indent_radius, 'indent_radius', below=wp / 4)
    closure_tol = check_positive(closure_tol, 'closure_tol')
    nsteps = _floquet_steps(floquet_steps)
    do_check = _check_flag(check, L)
    # each system's exponents once: the open loop's give P, the indentations and
    # points of the contour; the closed loop's the cross-check and more points
    lam_open = loop_exponents(L, nsteps)
    P, axis_w = open_loop_exponents(L, lam=lam_open)
    lam_closed = closed_loop_exponents(L, nsteps) if do_check else None
    w = _initial_grid(omega, wp, axis_w, r, (lam_open, lam_closed))

    w, s, logabs, phase, eig, edge, smin = _refined_contour(loop, w, axis_w, r)
    edge_turn, resolved = _close_strip(loop, axis_w, r)
    Zf = None if lam_closed is None else closed_loop_unstable_count(L, lam=lam_closed)
    return counted_response(L.name, loop.N, wp, w, s, logabs, phase, eig, edge, edge_turn,
                            resolved, P, float(smin.min()), Zf, closure_tol,
                            "closed loop's Floquet exponents", "Floquet check")



def counted_response(name, N, wp, w, s, logabs, phase, eig, edge, edge_turn, resolved, P,
                     dist, Zf, closure_tol, truth, check_name, stacklevel=3):
    """Encirclements of the contour's ``det(I + L̂)``, its diagnostics and the response.

    ``logabs``, ``phase`` along the imaginary-axis part ``s`` (frequencies
    `w`), `edge_turn` the phase turned along the strip's closure; `Zf` the
    closed loop's unstable count from `truth` (None: no check), `dist` the
    smallest singular value of ``I + L̂`` met.  Used by the counts of loops
    with and without delays.

    Examples
    --------
    >>> from ltpcontrol._frequency.nyquist import counted_response
    >>> w = np.linspace(-0.5, 0.5, 5)
    >>> r = counted_response('L', 1, 1.0, w, 1j * w, np.zeros(5), np.zeros(5),
    ...                      np.zeros((5, 1)), 0.0, 0.0, True, 0, 1.0, None, 0.05,
    ...                      'closed loop', 'check')
    >>> r.encirclements, r.stable
    (0, True)
    """
    axis_turn = float(_wrap(np.diff(phase)).sum())
    closing = _wrap(phase[0] - phase[-1])
    with np.errstate(over='ignore', under='ignore'):
        gap = float(np.abs(np.exp(logabs[0] - logabs[-1] + 1j * closing) - 1))
        det = np.exp(logabs + 1j * phase)
    total = (axis_turn + edge_turn) / (2 * np.pi)
    encirclements = int(np.round(total))
    resolved &= abs(total - encirclements) < 0.05
    if Zf is not None and Zf != P - encirclements:
        warnings.warn(f"nyquist_htf: the count of the loop HTF truncated to nharmonics="
                      f"{N} (Z = {P - encirclements}) contradicts the {truth} (Z = {Zf}): "
                      "increase nharmonics", UserWarning, stacklevel=stacklevel)
    elif Zf is None and edge > closure_tol:
        warnings.warn(f"nyquist_htf: the loop HTF is not small at its truncation edge "
                      f"(|L̂ - D̂| up to {edge:.2g} in harmonics ±{N} > closure_tol="
                      f"{closure_tol:g}) and no {check_name} was made: the count is exact "
                      "for the truncated loop only; increase nharmonics or pass check=True",
                      UserWarning, stacklevel=stacklevel)
    if dist < 1e-8 or not resolved:
        warnings.warn("nyquist_htf: the contour passes through a closed-loop exponent "
                      f"(min singular value of I + L̂ = {dist:.1e}): the loop is at a "
                      "stability boundary and the count is not reliable", UserWarning,
                      stacklevel=stacklevel)
    return HarmonicNyquistResponse(
        encirclements=encirclements, open_loop_unstable=P, closure_gap=gap,
        min_distance=dist, omega=w, contour=s, det=det, eigenloci=track(eig),
        nharmonics=N, omega_p=wp, sysname=name,
        edge_turns=float(edge_turn / (2 * np.pi)), floquet_unstable=Zf)

def closed_loop_exponents(L, nsteps=None):
    """Characteristic exponents of ``feedback(L, I)`` (one Floquet computation).

    Examples
    --------
    >>> from ltpcontrol._frequency.nyquist import closed_loop_exponents
    >>> closed_loop_exponents(ltp.ltpss(ct.tf([3], [1, 1]), period=1.0))
    array([-4.+0.j])
    """
    with warnings.catch_warnings():
        # a cross-check: only the count is used, and a wrong one shows as a
        # contradiction with the Nyquist count
        warnings.filterwarnings('ignore', message='product_eigenvalues')
        return loop_exponents(feedback(L, np.eye(L.ninputs)), nsteps)


def closed_loop_unstable_count(L, nsteps=None, lam=None):
    """Closed-loop exponents with positive real part of ``feedback(L, I)``.

    `lam`: those exponents when already computed (`closed_loop_exponents`);
    exponents within ``1e-9 ω_p`` of the axis are not counted.

    Examples
    --------
    >>> from ltpcontrol._frequency.nyquist import closed_loop_unstable_count
    >>> closed_loop_unstable_count(ltp.ltpss(ct.tf([3], [1, 1]), period=1.0))
    0
    >>> closed_loop_unstable_count(ltp.ltpss(ct.tf([-3], [1, 1]), period=1.0))
    1
    """
    if lam is None:
        lam = closed_loop_exponents(L, nsteps)
    lam = np.asarray(lam)
    return int(np.count_nonzero(lam.real > 1e-9 * L.omega_p))


def contour_points(w, axis_w, r, wp):
    """``s(ω) = jω``, pushed right onto semicircles of radius r around `axis_w`.

    Examples
    --------
    >>> from ltpcontrol._frequency.nyquist import contour_points
    >>> contour_points(np.array([-0.5, 0.0, 0.05]), np.array([0.0]), 0.1, 1.0)
    array([0.        -0.5j , 0.1       +0.j  , 0.08660254+0.05j])
    """
    s = 1j * w.astype(complex)
    for wk in axis_w:
        for c in (wk - wp, wk, wk + wp):
            d = w - c
            inside = np.abs(d) < r
            s[inside] += np.sqrt(r ** 2 - d[inside] ** 2)
    return s


def track(eig):
    """Eigenvalue branches: each row's order matched to the previous row's.

    Examples
    --------
    >>> from ltpcontrol._frequency.nyquist import track
    >>> track(np.array([[1.0, 2.0], [2.1, 1.1]]))
    array([[1. , 2. ],
           [1.1, 2.1]])
    """
    out = np.array(eig, copy=True)
    for i in range(1, len(out)):
        cost = np.abs(out[i - 1][:, None] - out[i][None, :])
        _, col = linear_sum_assignment(cost)
        out[i] = out[i][col]
    return out


#
# Helpers
#

def _initial_grid(omega, wp, axis_w, r, exponents=()):
    if omega is None:
        w = np.linspace(-wp / 2, wp / 2, _INITIAL_POINTS)
    else:
        w = np.unique(real_array(omega, 'omega', ndim=1))
        if w.size < 2 or w[0] < -wp / 2 * (1 + 1e-12) or w[-1] > wp / 2 * (1 + 1e-12):
            raise ValueError("omega must hold at least two frequencies in the strip "
                             f"[-ω_p/2, ω_p/2] = [{-wp / 2:g}, {wp / 2:g}]")
        w = np.unique(np.concatenate([[-wp / 2], w, [wp / 2]]))
    theta = np.sin(np.linspace(-np.pi / 2, np.pi / 2, 41))
    extra = [c + r * theta for wk in axis_w for c in (wk - wp, wk, wk + wp)]
    w = np.concatenate([w, _near_exponents(exponents, wp, np.diff(w).max())] + extra)
    return np.unique(w[(w >= -wp / 2) & (w <= wp / 2)])


def _near_exponents(exponents, wp, spacing):
    """Strip frequencies around every exponent closer to the axis than four
    grid spacings, spaced by its distance to the axis: there f may turn
    within less than a grid step (the grid resolves the others)."""
    pts = []
    for lam in exponents:
        if lam is None:
            continue
        lam = np.asarray(lam)
        d = np.abs(lam.real)
        near = (d > 0) & (d < 4 * spacing)
        if near.any():
            c = fold(lam[near].imag, wp)
            pts.append((c[:, None] + d[near][:, None] * _NEAR[None, :]).ravel())
    if not pts:
        return np.zeros(0)
    w = np.concatenate(pts)
    return w[np.abs(w) <= wp / 2]


def _evaluate(loop, s):
    """log|f|, arg f, eigenvalues of L̂_N, the truncation edge and the smallest
    singular value of I + L̂_N at the points s, from one evaluation of L̂_N."""
    Lh = loop(s)
    IL = np.eye(loop.size) + Lh
    sign, logabs = np.linalg.slogdet(IL)
    smin = np.linalg.svd(IL, compute_uv=False)[:, -1]
    return logabs, np.angle(sign), np.linalg.eigvals(Lh), _edge(loop, Lh), smin


def _edge(loop, Lh):
    """Largest entry of the outermost harmonic blocks of L̂_N without its
    feedthrough (which fills them exactly): the truncation diagnostic."""
    m = loop.m
    dyn = Lh - loop.hss.J
    return float(max(np.abs(dyn[:, :m, :]).max(), np.abs(dyn[:, -m:, :]).max(),
                     np.abs(dyn[:, :, :m]).max(), np.abs(dyn[:, :, -m:]).max()))


def _refined_contour(loop, w, axis_w, r):
    wp = loop.omega_p
    s = contour_points(w, axis_w, r, wp)
    logabs, phase, eig, edge, smin = _evaluate(loop, s)
    while True:
        # a fast turn of the phase, or a fast change of the modulus (a lightly
        # damped exponent nearby, where the phase may turn between samples)
        bad = (np.abs(_wrap(np.diff(phase))) > _MAX_TURN) | (np.abs(np.diff(logabs)) > 0.5)
        bad &= np.diff(w) > 1e-13 * wp
        if not bad.any() or len(w) + bad.sum() > _MAX_POINTS:
            break
        wn = 0.5 * (w[:-1][bad] + w[1:][bad])
        sn = contour_points(wn, axis_w, r, wp)
        la, ph, ev, _, sm = _evaluate(loop, sn)
        order = np.argsort(np.concatenate([w, wn]), kind='stable')
        w = np.concatenate([w, wn])[order]
        s = np.concatenate([s, sn])[order]
        logabs = np.concatenate([logabs, la])[order]
        phase = np.concatenate([phase, ph])[order]
        eig = np.concatenate([eig, ev])[order]
        smin = np.concatenate([smin, sm])[order]
    if np.any(np.isinf(logabs)):
        warnings.warn("nyquist_htf: det(I + L̂_N) vanishes on the contour: the loop is "
                      "at a stability boundary", UserWarning, stacklevel=3)
    return w, s, logabs, phase, eig, edge, smin


def _close_strip(loop, axis_w, r):
    """Phase change of det(I + L̂_N) over the other sides of the half strip."""
    wp = loop.omega_p
    eps = EDGE_OFFSET * wp
    grid = np.linspace(0.0, 1.0, 9)

    def along_axis(w0, w1):
        return lambda t: contour_points(w0 + (w1 - w0) * np.asarray(t), axis_w, r, wp)
    up, ok1, _ = path_phase(loop.logdet, along_axis(wp / 2, wp / 2 + eps), None, grid)
    down, ok2, _ = path_phase(loop.logdet, along_axis(-wp / 2 + eps, -wp / 2), None, grid)
    s_top = complex(contour_points(np.array([wp / 2 + eps]), axis_w, r, wp)[0])
    s_bot = complex(contour_points(np.array([-wp / 2 + eps]), axis_w, r, wp)[0])
    sigma = 2 * abscissa_bound(loop.hss) + wp
    edges, ok3 = strip_closure(loop.logdet, s_top, s_bot, wp, sigma)
    return up + edges + down, ok1 and ok2 and ok3


def _floquet_steps(nsteps):
    return None if nsteps is None else check_positive_int(nsteps, 'floquet_steps')


def _check_flag(check, L):
    if check == 'auto':
        return L.A.is_constant or L.nstates <= _CHECK_STATES
    if not isinstance(check, (bool, np.bool_)):
        raise ValueError(f"check must be True, False or 'auto', got {check!r}")
    return bool(check)


def _wrap(x):
    """Angles wrapped into [-π, π)."""
    return np.remainder(x + np.pi, 2 * np.pi) - np.pi


def _arrow(ax, z, color):
    """Direction arrow at the middle of a curve."""
    if len(z) < 3:
        return
    i = len(z) // 2
    ax.annotate('', xy=(z[i + 1].real, z[i + 1].imag), xytext=(z[i].real, z[i].imag),
                arrowprops=dict(arrowstyle='->', color=color))


def _line_array(lines):
    arr = np.empty((1, 1), dtype=object)
    arr[0, 0] = lines
    return arr
