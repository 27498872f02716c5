"""Floquet functions of the public API for systems with delays.

`ltpcontrol.floquet_multipliers`, `floquet_exponents`, `is_stable` and
`monodromy` hand a `LTPDelayStateSpace` to the functions here (through
`ltpcontrol._core.registry.override`); they use the spectral-element
monodromy operator of `delay_monodromy`.  Input and output delays do not
change the multipliers; a system without state delays is analysed as the
ODE it is.
"""

import warnings

import numpy as np

from .._core.floquet import floquet_exponents as _ode_exponents
from .._core.floquet import floquet_multipliers as _ode_multipliers
from .._core.floquet import monodromy as _ode_monodromy
from .._core.registry import override
from .ltpdsys import LTPDelayStateSpace
from .monodromy import _REFINE, _Problem, delay_monodromy

__all__ = []

_NO_NSTEPS = ("nsteps does not apply to a system with delays; pass the degree and "
              "tolerance of its discretization with delay_monodromy(sys, order=..., tol=...)")


def _ode(sys):
    """The system as an ODE when it has no state delay, else None."""
    return None if sys.state_delays else sys.undelayed()


@override('monodromy', LTPDelayStateSpace)
def monodromy(sys, nsteps=None):
    """Discretized monodromy operator of a delayed system (see `delay_monodromy`).

    Examples
    --------
    >>> sys = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[0.5]])])
    >>> ltp.monodromy(sys).shape[0] > 1
    True
    """
    if nsteps is not None:
        raise TypeError(_NO_NSTEPS)
    ode = _ode(sys)
    return _ode_monodromy(ode) if ode is not None else delay_monodromy(sys).matrix


@override('floquet_multipliers', LTPDelayStateSpace)
def floquet_multipliers(sys, nsteps=None):
    """Characteristic multipliers of a delayed system resolved by its discretization.

    The multipliers of the discretization at the degree `delay_monodromy`
    reaches, by decreasing modulus, as long as each agrees with the coarser
    discretization to 1e-8 (relative to ``max(1, |μ_1|)``); at least the
    dominant one (with a warning from `delay_monodromy` when it is not
    resolved to 1e-10).

    Examples
    --------
    >>> from scipy.optimize import brentq
    >>> lam = brentq(lambda l: l + 1 - 0.5 * np.exp(-l), -1, 0)
    >>> sys = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[0.5]])])
    >>> bool(abs(ltp.floquet_multipliers(sys)[0] - np.exp(lam)) < 1e-12)
    True
    """
    if nsteps is not None:
        raise TypeError(_NO_NSTEPS)
    ode = _ode(sys)
    if ode is not None:
        return _ode_multipliers(ode)
    M = delay_monodromy(sys)
    coarse = _Problem(sys).multipliers(M.order - _REFINE)
    fine = M.multipliers
    if not fine.size:
        return fine
    gap = np.min(np.abs(fine[:, None] - coarse[None, :]), axis=1) if coarse.size else \
        np.abs(fine)
    bad = np.flatnonzero(gap > 1e-8 * max(1.0, abs(fine[0])))
    keep = max(1, int(bad[0]) if bad.size else fine.size)
    if keep < fine.size and fine[keep - 1].imag != 0 and \
            abs(fine[keep] - np.conj(fine[keep - 1])) <= 1e-10 * max(1.0, abs(fine[0])):
        keep += 1                                   # keep conjugate pairs together
    return fine[:keep]


@override('floquet_exponents', LTPDelayStateSpace)
def floquet_exponents(sys, nsteps=None):
    """Characteristic exponents ``λ = log(μ)/T`` of a delayed system (principal branch).

    Examples
    --------
    >>> sys = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[0.5]])])
    >>> float(ltp.floquet_exponents(sys)[0].real.round(6))
    -0.31492
    """
    if nsteps is not None:
        raise TypeError(_NO_NSTEPS)
    ode = _ode(sys)
    if ode is not None:
        return _ode_exponents(ode)
    mu = floquet_multipliers(sys)
    return np.log(mu.astype(complex)) / sys.period


@override('is_stable', LTPDelayStateSpace)
def is_stable(sys, tol=1e-10, nsteps=None, *, autonomous=False):
    """True when every characteristic multiplier of a delayed system has ``|μ| < 1 - tol``.

    A warning is issued when the accuracy estimate of the dominant
    multiplier exceeds its distance to the unit circle.

    Examples
    --------
    >>> sys = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[0.5]])])
    >>> ltp.is_stable(sys), ltp.is_stable(ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0,
    ...                                   period=1.0, delays=[(1.0, [[1.5]])]))
    (True, False)
    """
    if nsteps is not None:
        raise TypeError(_NO_NSTEPS)
    if isinstance(tol, (bool, np.bool_)) or not isinstance(tol, (int, float, np.floating)) \
            or not 0 <= tol < 1:
        raise ValueError(f"tol must be a number in [0, 1), got {tol!r}")
    if autonomous:
        raise ValueError("autonomous=True (orbital stability) is not defined for a system "
                         "with delays")
    ode = _ode(sys)
    if ode is not None:
        mu = _ode_multipliers(ode)
        return bool(mu.size == 0 or np.max(np.abs(mu)) < 1 - tol)
    M = delay_monodromy(sys)
    if not M.multipliers.size:
        return True
    rho = abs(M.multipliers[0])
    if M.error > abs(rho - 1):
        warnings.warn(f"is_stable: the dominant multiplier |μ| = {rho:.12g} is within its "
                      f"accuracy estimate {M.error:.1e} of the unit circle", UserWarning,
                      stacklevel=2)
    return bool(rho < 1 - tol)
