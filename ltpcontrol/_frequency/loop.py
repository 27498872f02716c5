"""A periodic feedback loop seen through its truncated HTF.

Shared by the generalized Nyquist criterion, the margins and the
closed-loop frequency functions.  The loop ``L`` is closed with negative
feedback, ``u = r - y``; its HTF truncated to N harmonics is ``L̂_N(s)``
(Conventions page) and the return difference ``I + L̂_N(s)``.

The strip ``s = jω``, ``ω ∈ (-ω_p/2, ω_p/2]``, sees every frequency once:
``L̂(s + jω_p)`` is ``L̂(s)`` with the harmonic blocks shifted by one.
"""

import warnings

import numpy as np
from control.exception import ControlArgument, ControlDimension

from .harmonic_ss import build
from .._core.floquet import floquet_exponents
from .._core.ltpsys import LTPStateSpace, series
from .._core.coerce import as_ltp
from .._core.validation import check_positive_int
from .._core.wellposed import check_well_posed

__all__ = []


def as_loop(L, name='L', period=None, where=None):
    """The loop as one square continuous-time `LTPStateSpace`.

    `L` is a system, or a sequence of systems ``(L_1, ..., L_k)`` meaning
    the product ``L_1 L_2 ... L_k`` (``L_k`` acts first), for example
    ``(plant, controller)``.  The closed loop must be well posed: ``I +
    D(t)`` nonsingular over the whole period (else ValueError naming the
    function `where` and the instant).

    Examples
    --------
    >>> from ltpcontrol._frequency.loop import as_loop
    >>> P = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> as_loop((P, ct.tf([2], [1, 3]))).nstates
    2
    >>> as_loop(ltp.ltpss([[-1.0]], [[1.0]], [[1.0], [2.0]], 0, period=1.0))
    Traceback (most recent call last):
    ...
    control.exception.ControlDimension: L must be a square loop (as many outputs as inputs) to be closed by negative feedback; it has 2 outputs and 1 inputs
    """
    # --- products of harmonic objects (impedances, HTF models), realized exactly;
    # --- module products (impedance workflow)
    from .products import harmonic_product, is_harmonic_sequence
    if is_harmonic_sequence(L):
        L = harmonic_product(*L, period=period, name=name)
    # ---
    if isinstance(L, (list, tuple)):
        if not L:
            raise ControlArgument(f"{name} must be a system or a non-empty sequence of systems")
        if len(L) > 1:
            if period is not None:
                L = [as_ltp(s, name, period=period) if not isinstance(s, LTPStateSpace)
                     else s for s in L]
            try:
                # L_1 L_2 ... L_k: signals flow from L_k to L_1
                L = series(*reversed(L), name='L')
            except ValueError as err:
                raise ValueError(f"{name}: the systems of the loop cannot be connected: "
                                 f"{err}") from None
        else:
            L = L[0]
    L = as_ltp(L, name, period=period if not isinstance(L, LTPStateSpace) else None)
    if L.isdtime():
        raise ValueError(f"{name} must be a continuous-time loop (for a discrete-time "
                         "loop use ltp.lift(L) and python-control's LTI tools)")
    if L.ninputs != L.noutputs:
        raise ControlDimension(f"{name} must be a square loop (as many outputs as inputs) "
                               "to be closed by negative feedback; it has "
                               f"{L.noutputs} outputs and {L.ninputs} inputs")
    check_well_posed(np.eye(L.ninputs) + L.D, where or name)
    return L


class HarmonicLoop:
    """What the Nyquist and margin computations ask of a loop HTF ``L̂_N``: a
    subclass sets ``N`` and ``m`` (channels) and evaluates ``self(s)`` as
    ``(points, M, M)``, ``M = (2N+1) m``, harmonic-major.

    Examples
    --------
    >>> from ltpcontrol._frequency.loop import LoopHTF
    >>> P = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> loop = LoopHTF(P, 2)
    >>> loop.size, loop.dominant_harmonic(np.array([0, 0, 0, 1.0, 0]))
    (5, 1)
    """

    def logdet(self, s):
        """``(log|f|, arg f)`` of ``f = det(I + L̂_N(s))`` at the points `s`."""
        sign, logabs = np.linalg.slogdet(np.eye(self.size) + self(s))
        return logabs, np.angle(sign)

    @property
    def size(self):
        return (2 * self.N + 1) * self.m

    def dominant_harmonic(self, v):
        """Harmonic n whose block carries most of the vector v."""
        blocks = np.abs(v.reshape(2 * self.N + 1, self.m)) ** 2
        return int(np.argmax(blocks.sum(axis=1))) - self.N


class LoopHTF(HarmonicLoop):
    """``L̂_N(s)`` evaluated at many points, shape ``(points, M, M)``.

    ``M = (2N+1) m`` with m loop channels, harmonic-major (Conventions).
    The harmonic state space is built without the open loop's stability
    remark (an unstable open loop is the point of the criterion), so that
    the Floquet exponents are computed once per call, by the caller.
    """

    def __init__(self, L, nharmonics, internal_harmonics=None, where='L'):
        self.L = L
        self.N = check_positive_int(nharmonics, 'nharmonics', minimum=1)
        self.m = L.ninputs
        self.omega_p = L.omega_p
        self.nharmonics, self.dt = self.N, 0.0       # what default_omega reads
        with warnings.catch_warnings():
            # the accuracy of the multipliers behind a remark is not the caller's concern
            warnings.filterwarnings('ignore', message='product_eigenvalues')
            self.hss = build(L, self.N, internal_harmonics, "auto", where, stacklevel=3,
                             warn_unstable=False)

    def __call__(self, s):
        s = np.atleast_1d(np.asarray(s, complex))
        return self.hss.evaluate(s)


def loop_exponents(L, nsteps=None):
    """Characteristic exponents of the system L (eigenvalues of a constant A).

    One Floquet computation (`nsteps`: steps per period, see `monodromy`;
    default its own choice, with sub-steps set by the integrator's error).

    Examples
    --------
    >>> from ltpcontrol._frequency.loop import loop_exponents
    >>> loop_exponents(ltp.ltpss(ct.tf([1], [1, 2]), period=1.0))
    array([-2.+0.j])
    """
    if not L.nstates:
        return np.zeros(0, complex)
    if L.A.is_constant:
        return np.linalg.eigvals(L.A(0.0)).astype(complex)    # constant A: its eigenvalues
    return np.atleast_1d(floquet_exponents(L, nsteps)).astype(complex)


def open_loop_exponents(L, atol=None, nsteps=None, lam=None):
    """(P, axis) of the open loop: count of exponents with positive real part
    and the strip frequencies of those on the imaginary axis.

    An exponent with ``|Re λ| <= atol`` (default ``1e-9 ω_p``) counts as on
    the axis (`nsteps`: Floquet steps, see `monodromy`); the Nyquist contour
    indents to its right, so it is not counted in P, as python-control
    does.  `lam`: the exponents when already computed (`loop_exponents`).

    Examples
    --------
    >>> from ltpcontrol._frequency.loop import open_loop_exponents
    >>> L = ltp.ltpss(ct.ss(ct.tf([1], [1, 0, -1])), period=1.0)   # poles ±1
    >>> open_loop_exponents(L)
    (1, array([], dtype=float64))
    """
    wp = L.omega_p
    atol = 1e-9 * wp if atol is None else atol
    if lam is None:
        lam = loop_exponents(L, nsteps)
    on_axis = np.abs(lam.real) <= atol
    P = int(np.count_nonzero(lam.real > atol))
    w = fold(lam[on_axis].imag, wp)
    return P, np.unique(np.round(w / wp, 12)) * wp if w.size else w


def fold(omega, omega_p):
    """Frequencies folded into the strip ``(-ω_p/2, ω_p/2]``.

    Examples
    --------
    >>> from ltpcontrol._frequency.loop import fold
    >>> fold(np.array([0.5, -0.5, 1.2, 3.0]), 1.0)
    array([0.5, 0.5, 0.2, 0. ])
    """
    w = np.asarray(omega, float)
    return 0.0 - (np.remainder(-w + omega_p / 2, omega_p) - omega_p / 2)
