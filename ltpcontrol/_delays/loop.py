"""A periodic feedback loop with delays seen through its truncated HTF (exact ``e^{-sτ}``).

Shared by `nyquist_htf` and `harmonic_margins` of delayed loops.  The loop
``L`` (an `LTPDelayStateSpace`, or a product of systems and `delay`
elements) is closed with negative feedback ``u = r - y``.  Its HTF
truncated to N harmonics, ``L̂_N(s) = 𝒞(s) (𝒩(s) - 𝒜(s))^{-1} ℬ(s) + 𝒟(s)``
(module `ltpcontrol._delays.htf`), is not rational in s, but it is
meromorphic: ``f(s) = det(I + L̂_N(s))`` has finitely many zeros and
poles in any bounded part of the strip, and none to the right of the
abscissa `DelayLoop.sigma_bound` gives.  So the argument principle on the
boundary of the half strip ``0 < Re s < σ`` counts them exactly, as for
loops without delays.

Bound: for ``Re s = σ >= 0`` every delayed block carries ``|e^{-(s +
jlω_p)a}| = e^{-σa}``, so ``‖𝒜(s)‖ <= α(σ) = Σ_a e^{-σa} ‖𝒯(A_a)‖`` and
likewise β, γ, δ for B, C and the delayed part of D.  A zero of ``det(𝒩 -
𝒜)`` has ``Re s <= α(Re s)``; for ``σ > α(σ)``, ``‖(𝒩 - 𝒜)^{-1}‖ <= 1/(σ -
α(σ))``, so ``I + L̂_N`` is nonsingular where ``β γ / (σ - α) + δ <
σ_min(I + 𝒟_0)``.  Both conditions hold for all larger σ.
"""

import warnings

import numpy as np
from control.exception import ControlArgument, ControlDimension

from .._core.periodic_matrix import PeriodicMatrix
from .._core.validation import check_positive_int
from .._core.wellposed import check_well_posed
from .._frequency.loop import HarmonicLoop, fold, open_loop_exponents
from .connect import Delay, feedback, series, _convert
from .htf import DelayHTF
from .ltpdsys import LTPDelayStateSpace
from .monodromy import delay_monodromy

__all__ = []

_NO_STEPS = ("floquet_steps does not apply to a loop with delays (its multipliers come "
             "from the spectral-element discretization of delay_monodromy)")


def as_delayed_loop(L, name='L', period=None, where=None):
    """The loop as one square continuous-time `LTPDelayStateSpace` and its closed loop.

    `L` is a system or delay element, or a sequence ``(L_1, ..., L_k)``
    meaning the product ``L_1 ... L_k`` (``L_k`` acts first).  Returns
    ``(L, feedback(L, I))``; a loop whose direct path feeds a signal back
    through a delay onto itself (a neutral equation) is refused by
    `feedback`.

    Examples
    --------
    >>> from ltpcontrol._delays.loop import as_delayed_loop
    >>> P = ltp.ltpss(ct.tf([2.0], [1.0, 1.0]), period=1.0)
    >>> L, cl = as_delayed_loop((P, ltp.delay(0.3)))
    >>> L.delays, [tau for tau, _ in cl.state_delays]
    ((0.3,), [0.3])
    """
    where = where or name
    if isinstance(L, (list, tuple)):
        if not L:
            raise ControlArgument(f"{name} must be a system or a non-empty sequence of systems")
        try:
            L = series(*reversed(L)) if len(L) > 1 else L[0]
        except ValueError as err:
            raise ValueError(f"{name}: the systems of the loop cannot be connected: "
                             f"{err}") from None
    if isinstance(L, Delay):
        (L,), _ = _convert([L], where, [None])
    if not isinstance(L, LTPDelayStateSpace):
        raise ControlArgument(f"{name} must be a loop with delays (LTPDelayStateSpace, delay "
                              f"elements), got {type(L).__name__}")
    if period is not None and L.is_lti:
        L = LTPDelayStateSpace({k: {a: PeriodicMatrix.constant(M(0.0), period)
                                    for a, M in X.items()} for k, X in L.terms.items()},
                               period, name=L.name, inputs=L.input_labels,
                               outputs=L.output_labels, states=L.state_labels)
    if L.ninputs != L.noutputs:
        raise ControlDimension(f"{name} must be a square loop (as many outputs as inputs) "
                               "to be closed by negative feedback; it has "
                               f"{L.noutputs} outputs and {L.ninputs} inputs")
    check_well_posed(np.eye(L.ninputs) + L.D, where)
    cl = feedback(L, np.eye(L.ninputs))
    return L, cl


class DelayLoop(HarmonicLoop):
    """``L̂_N(s)`` of a delayed loop at many points, shape ``(points, M, M)``, M = (2N+1)m.

    Examples
    --------
    >>> from ltpcontrol._delays.loop import DelayLoop, as_delayed_loop
    >>> L, _ = as_delayed_loop((ltp.ltpss(ct.tf([2.0], [1.0, 1.0]), period=1.0),
    ...                         ltp.delay(0.3)))
    >>> loop = DelayLoop(L, 2)
    >>> s = 0.7j
    >>> bool(np.isclose(loop(s)[0, 2, 2], 2 * np.exp(-0.3 * s) / (s + 1)))
    True
    """

    def __init__(self, L, nharmonics, internal_harmonics=None):
        self.L = L
        self.N = check_positive_int(nharmonics, 'nharmonics', minimum=1)
        self.m = L.ninputs
        self.omega_p = L.omega_p
        self.H = DelayHTF(L, self.N, internal_harmonics=internal_harmonics)
        Ki, K, m = self.H._Ki, self.N, self.m
        ks = np.arange(-Ki, Ki + 1)
        self._keep = ((ks[:, None] + Ki)[np.abs(ks) <= K] * m + np.arange(m)).ravel()

    def __call__(self, s):
        return self.H._evaluate(np.atleast_1d(np.asarray(s, complex)), None)

    def feedthrough(self, s):
        """``𝒟_N(s)`` (with its delayed terms) at the points `s`."""
        s = np.atleast_1d(np.asarray(s, complex))
        D = self.H._operator('D', s)
        return D[:, self._keep][:, :, self._keep]

    def sigma_bound(self):
        """An abscissa σ beyond which f has neither zeros nor poles (module notes).

        Examples
        --------
        ``1 + 2 e^{-0.3 s}/(s + 1)`` (K = 1) has no zero right of σ:

        >>> from ltpcontrol._delays.loop import DelayLoop, as_delayed_loop
        >>> L, _ = as_delayed_loop((ltp.ltpss(ct.tf([2.0], [1.0, 1.0]), period=1.0),
        ...                         ltp.delay(0.3)))
        >>> loop = DelayLoop(L, 1)
        >>> sigma = loop.sigma_bound()
        >>> s = sigma + 1j * np.linspace(-50, 50, 201)
        >>> bool(np.all(np.abs(1 + 2 * np.exp(-0.3 * s) / (s + 1)) > 0.5))
        True
        """
        norms = {k: [(a, np.linalg.norm(T, 2) if T.size else 0.0) for a, T in ops]
                 for k, ops in self.H._ops.items()}
        D0 = next(T for a, T in self.H._ops['D'] if a == 0)[self._keep][:, self._keep]
        smin = np.linalg.svd(np.eye(self.size) + D0, compute_uv=False)[-1]

        def total(k, sigma, delayed_only=False):
            return sum(np.exp(-sigma * a) * v for a, v in norms[k]
                       if a > 0 or not delayed_only)
        sigma = max(total('A', 0.0), self.omega_p) + 1.0
        for _ in range(200):
            alpha = total('A', sigma)
            if sigma > alpha and (total('B', sigma) * total('C', sigma) / (sigma - alpha)
                                  + total('D', sigma, True)) < 0.5 * smin:
                return float(sigma)
            sigma *= 2
        raise ValueError("the loop's return difference has no zero-free right half plane "
                         "that can be bounded (I + D nearly singular)")


def open_loop(L):
    """(P, axis) of a delayed open loop: exponents with positive real part (one strip) and
    the strip frequencies of those on the imaginary axis.

    Examples
    --------
    >>> from ltpcontrol._delays.loop import open_loop
    >>> L = ltp.ltpdss([[0.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[0.5]])])
    >>> open_loop(L)              # x' = 0.5 x(t - 1): one real exponent > 0
    (1, array([], dtype=float64))
    """
    if not L.state_delays:
        return open_loop_exponents(L.undelayed())
    with warnings.catch_warnings():
        # the accuracy is judged below, against the distance to the unit circle
        warnings.filterwarnings('ignore', message='delay_monodromy')
        M = delay_monodromy(L, tol=1e-9)
    mu = M.multipliers
    wp, T = L.omega_p, L.period
    logm = np.log(np.abs(mu))
    atol = max(1e-9 * wp * T, 10 * M.error)
    near = (np.abs(logm) > atol) & (np.abs(np.abs(mu) - 1) <= 10 * M.error)
    if near.any():
        warnings.warn(f"a characteristic multiplier |μ| = {abs(mu[near][0]):.12g} lies within "
                      f"its accuracy estimate {M.error:.1e} of the unit circle: the count of "
                      "unstable exponents is not reliable", UserWarning, stacklevel=3)
    on_axis = np.abs(logm) <= atol
    w = fold(np.angle(mu[on_axis]) / T, wp)
    return (int(np.count_nonzero(logm > atol)),
            np.unique(np.round(w / wp, 12)) * wp if w.size else w)


def closed_loop_unstable(cl):
    """Closed-loop exponents with positive real part (multipliers outside the unit circle).

    Examples
    --------
    >>> from ltpcontrol._delays.loop import as_delayed_loop, closed_loop_unstable
    >>> P = ltp.ltpss(ct.tf([2.0], [1.0, 1.0]), period=1.0)
    >>> closed_loop_unstable(as_delayed_loop((P, ltp.delay(0.5)))[1])
    0
    >>> closed_loop_unstable(as_delayed_loop((P, ltp.delay(2.0)))[1])
    2
    """
    return open_loop(cl)[0]


def check_steps(floquet_steps):
    """Refuse `floquet_steps` for a delayed loop (TypeError).

    Examples
    --------
    >>> from ltpcontrol._delays.loop import check_steps
    >>> check_steps(None)
    >>> check_steps(100)
    Traceback (most recent call last):
    ...
    TypeError: floquet_steps does not apply to a loop with delays (its multipliers come from the spectral-element discretization of delay_monodromy)
    """
    if floquet_steps is not None:
        raise TypeError(_NO_STEPS)
