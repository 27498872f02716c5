"""Delay margin of a periodic feedback loop.

The loop ``u = r + sign L(y)`` is closed through an extra delay d on every
loop channel, ``feedback(delay(d) * L, sign=...)`` in block-diagram terms;
the delay margin is the smallest d > 0 for which the closed loop is
unstable.  For a periodic loop the delay does not act as a phase shift of
one frequency response (``e^{-(s + jkω_p)d}`` differs on every harmonic),
so the margin is decided on the closed loop's characteristic multipliers:
a scan of d on a grid, then bisection of the first change of verdict.
"""

import numpy as np
from control.exception import ControlArgument

from .._core.floquet import floquet_multipliers
from .._core.ltpsys import LTPStateSpace
from .connect import delay, feedback, series
from .ltpdsys import LTPDelayStateSpace
from .monodromy import _Problem

__all__ = ['delay_margin']


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

    def radius(d):
        loop = feedback(L, 1.0, sign=sign) if d == 0 else \
            feedback(series(delay(d), L), 1.0, sign=sign)
        if isinstance(loop, LTPDelayStateSpace) and loop.state_delays:
            mu = _Problem(loop).multipliers(16)
        else:
            mu = floquet_multipliers(loop.undelayed() if isinstance(
                loop, LTPDelayStateSpace) else loop)
        return float(np.max(np.abs(mu), initial=0.0))

    if radius(0.0) >= 1:
        return 0.0
    grid = np.linspace(0, max_delay, num + 1)[1:]
    lo = 0.0
    for d in grid:
        if radius(d) >= 1:
            hi = d
            while hi - lo > tol * hi:
                mid = 0.5 * (lo + hi)
                if radius(mid) >= 1:
                    hi = mid
                else:
                    lo = mid
            return 0.5 * (lo + hi)
        lo = d
    return np.inf
