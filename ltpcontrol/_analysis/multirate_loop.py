"""Gain and phase margins of discrete periodic (multirate) loops.

The loop gain ``L`` (square, negative feedback ``u = -y``) is replaced by
its time-lifted LTI equivalent ``L_L`` (`ltpcontrol.lift`, method 'time'),
an exact equivalent on which the periodic closed loop is stable iff the
lifted one is.  A scalar gain k (or a complex unit gain ``e^{-jφ}``) applied
to the loop acts on every sample of every channel, so it multiplies ``L_L``:
the closed loop ``A_L − k B_L (I + k D_L)⁻¹ C_L`` is stable for k in
``(1/gm_lower, gm)`` and for ``φ`` below the phase margin.  The margins are
found exactly by bisection on this stability verdict (scanned on a
logarithmic grid first, so the first loss of stability is found even when
the stable set is not an interval).  For an LTI loop written as periodic
they are python-control's `stability_margins` gain and phase margins.
"""

import numpy as np
from control.exception import ControlDimension

from .._core.lifting import lift
from .._core.coerce import as_ltp

__all__ = ['lifted_margins']


def lifted_margins(loop, *, kmax=1e6, rtol=1e-10):
    """Gain and phase margins of a discrete periodic loop through its lifting.

    Parameters
    ----------
    loop : LTPStateSpace
        Discrete-time loop gain with as many outputs as inputs (e.g. a
        multirate plant in series with its periodic controller), closed by
        negative unit feedback.
    kmax : float, optional
        Largest gain examined (gain margins above it are reported as inf).
    rtol : float, optional
        Relative accuracy of the bisection.

    Returns
    -------
    gm : float
        Upper gain margin: the loop is stable for gains in ``[1, gm)``.
    pm : float
        Phase margin in degrees: stable for ``e^{-jφ}``, ``|φ| < pm``.
    gm_lower : float
        Lower gain margin: stable for gains in ``(1/gm_lower, 1]``.

    Raises
    ------
    ValueError
        If the nominal closed loop is unstable.

    Examples
    --------
    An LTI loop written as periodic has python-control's margins:

    >>> L = ct.c2d(ct.tf([2.0], [1, 1, 0]), 0.1)
    >>> gm, pm, _ = ltp.lifted_margins(ltp.ltpss(ct.ss(L), period=0.2))
    >>> want = ct.stability_margins(L, method='frd')
    >>> bool(np.isclose(gm, want[0], rtol=1e-7) and np.isclose(pm, want[1], rtol=1e-7))
    True
    """
    loop = as_ltp(loop, 'loop', discrete=True)
    if loop.ninputs != loop.noutputs:
        raise ControlDimension(f"loop must be square, got {loop.noutputs} outputs and "
                               f"{loop.ninputs} inputs")
    if not (isinstance(kmax, (int, float)) and kmax > 1):
        raise ValueError(f"kmax must be a number > 1, got {kmax!r}")
    L = lift(loop, method='time')
    A, B, C, D = L.A, L.B, L.C, L.D

    def stable(k):
        M = np.eye(D.shape[0]) + k * D
        try:
            Acl = A - k * B @ np.linalg.solve(M, C)
        except np.linalg.LinAlgError:
            return False
        return bool(A.shape[0] == 0 or np.max(np.abs(np.linalg.eigvals(Acl))) < 1)

    if not stable(1.0):
        raise ValueError("the nominal closed loop is unstable: its margins are undefined")
    gm = _first_loss(lambda g: stable(g), 1.0, kmax, rtol)
    gl = _first_loss(lambda g: stable(1.0 / g), 1.0, kmax, rtol)
    pm = _first_loss(lambda phi: stable(np.exp(-1j * np.deg2rad(phi))), 0.0, 180.0, rtol,
                     log=False)
    return gm, pm, gl


def _first_loss(ok, start, stop, rtol, log=True):
    """Smallest x in (start, stop] where ok(x) fails (inf if none on the grid)."""
    grid = np.geomspace(start * (1 + 1e-9), stop, 400) if log else \
        np.linspace(start, stop, 721)[1:]
    prev = start
    for x in grid:
        if not ok(x):
            lo, hi = prev, x
            while hi - lo > rtol * max(abs(hi), 1e-300):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if ok(mid) else (lo, mid)
            return float(0.5 * (lo + hi))
        prev = x
    return np.inf
