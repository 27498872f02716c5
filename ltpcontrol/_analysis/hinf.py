"""H∞ norm of LTP systems, with the peak frequency located and unfolded.

The H∞ norm is the L∞ norm (`ltpcontrol.norm` with ``p='inf'``, certified
bisection on the periodic Hamiltonian) of a stable system, and infinite for
an unstable one (the induced L2 gain from zero initial state is unbounded),
as the reference toolbox's ``pshinfnorm`` does.

The bisection brackets the norm to the requested tolerance, but its
frequency estimate (the unit-circle multipliers of the Hamiltonian just
below the norm) is only accurate to about the square root of it.  The
peak is therefore refined by maximizing ``σ_max`` of the harmonic transfer
function on a small bracket around the estimate, to ``1e-12 ω_p``.

Folding: ``H(jω)`` and ``H(j(ω + ω_p))`` describe the same operator, so the
peak is found in ``[0, ω_p/2]``.  Unfolded, it is ``|ω + nω_p|`` where n is
the input harmonic that carries most of the worst-case input (the top
right singular vector of the HTF at the peak): the frequency of the input
sinusoid that is amplified most.  For an LTI plant in rotating coordinates
(a Lyapunov transformation of the state) that is the LTI peak.
"""

import warnings

import numpy as np
from scipy.optimize import minimize_scalar

from .._core.coerce import as_ltp
from .._frequency.harmonic_ss import _HarmonicStateSpace, _internal_order
from .norms import norm

__all__ = ['hinfnorm']

# harmonics of the HTF used to refine and unfold the peak
_HARMONICS = 6


def hinfnorm(sys, tol=1e-6, *, unfolded=False, print_warning=True, nsteps=None):
    """H∞ norm and peak frequency of an LTP system, as `control.linfnorm`.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous- or discrete-time LTP system.
    tol : float, optional
        Relative accuracy of the norm.
    unfolded : bool, optional
        Continuous time: report the peak frequency unfolded, ``|ω + nω_p|``
        with n the input harmonic of the worst-case input (module notes),
        instead of folded into ``[0, ω_p/2]``.
    print_warning : bool, optional
        Warn when the system is unstable (the norm is then inf).
    nsteps : int, optional
        Continuous time: steps of the period grid (see `lyap`).

    Returns
    -------
    gpeak : float
        The H∞ norm (inf for an unstable system).
    fpeak : float
        Peak frequency in rad/s (nan for an unstable system; discrete time
        the lifted system's peak frequency, in ``[0, π/T]``).

    Examples
    --------
    The peak of 1/(s² + 0.2s + 9) is at sqrt(8.98) = 2.9967 rad/s:

    >>> G = ct.tf([1.0], [1.0, 0.2, 9.0])
    >>> g, w = ltp.hinfnorm(ltp.ltpss(G, period=2.0), unfolded=True)
    >>> bool(np.isclose(g, ct.linfnorm(G)[0], rtol=1e-6)), round(w, 4)
    (True, 2.9967)
    >>> unstable = ltp.ltpss(ct.tf([1.0], [1.0, -1.0]), period=1.0)
    >>> ltp.hinfnorm(unstable, print_warning=False)
    (inf, nan)
    """
    sys = as_ltp(sys)
    if not isinstance(unfolded, (bool, np.bool_)):
        raise TypeError(f"unfolded must be True or False, got {unfolded!r}")
    if sys.nstates and not sys.is_stable():
        if print_warning:
            warnings.warn("System is unstable: its H∞ norm is infinite (the L∞ norm of "
                          "norm(sys, 'inf') is finite)", UserWarning, stacklevel=2)
        return float('inf'), float('nan')
    gpeak, fpeak = norm(sys, 'inf', tol=tol, print_warning=print_warning,
                        return_frequency=True, nsteps=nsteps)
    if sys.isdtime() or not np.isfinite(gpeak) or not np.isfinite(fpeak) or sys.nstates == 0:
        return float(gpeak), float(fpeak)
    H, wp = _harmonic(sys), sys.omega_p

    def sigma(w):
        return np.linalg.norm(H.evaluate(1j * np.atleast_1d(w)), ord=2, axis=(1, 2))[0]
    # refine the peak on a bracket around the bisection's estimate
    delta = max(10 * np.sqrt(tol), 1e-4) * wp
    lo, hi = max(fpeak - delta, 0.0), min(fpeak + delta, wp / 2)
    if hi > lo:
        res = minimize_scalar(lambda w: -sigma(w), bounds=(lo, hi), method='bounded',
                              options={'xatol': 1e-12 * wp})
        if -res.fun >= sigma(fpeak):
            fpeak = float(res.x)
    if unfolded:
        M = H.evaluate(1j * np.array([fpeak]))[0]
        _, _, vh = np.linalg.svd(M)
        energy = (np.abs(vh[0]) ** 2).reshape(2 * H.K + 1, -1).sum(axis=1)
        n = int(np.argmax(energy)) - H.K
        fpeak = abs(fpeak + n * wp)
    return float(gpeak), float(fpeak)


def _harmonic(sys):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return _HarmonicStateSpace.continuous(sys, _HARMONICS,
                                              _internal_order(sys, _HARMONICS, None), 'auto')
