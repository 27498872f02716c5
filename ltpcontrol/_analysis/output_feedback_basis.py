"""Gain families of periodic output feedback: switching and harmonic.

``F(t) = Σ_i φ_i(t) F_i`` with indicator functions of the pieces of a
partition ``0 = t_0 < ... < t_{s-1} < T`` (switching) or ``1, cos jω_pt,
sin jω_pt`` up to a given order (harmonic); `ltpcontrol.ofstab` and
`ltpcontrol.oflqr` optimize the ``F_i``.
"""

import numpy as np
from control.exception import ControlArgument

from .._core.periodic_matrix import PeriodicMatrix
from .._core.validation import real_array

__all__ = []


class Basis:
    """Switching indicators or harmonics ``φ_i`` of the gain family."""

    def __init__(self, sys, times, order):
        T = sys.period
        self.period, self.discrete = T, sys.isdtime(strict=True)
        if times is not None and order is not None:
            raise ControlArgument("give times (switching gain) or order (harmonic gain), "
                                  "not both")
        if order is not None:
            if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 0:
                raise ValueError(f"order must be a non-negative integer, got {order!r}")
            if self.discrete and 2 * order + 1 > sys.nsteps:
                raise ValueError(f"order {order} needs {2 * order + 1} samples per period, "
                                 f"the plant has {sys.nsteps}")
            self.kind, self.order, self.size = 'harmonic', int(order), 2 * int(order) + 1
            return
        times = np.zeros(1) if times is None else real_array(times, 'times', ndim=1)
        if len(times) == 0 or abs(times[0]) > 1e-12 * T:
            raise ValueError("times must start at 0 (the partition must cover the period "
                             f"from its start), got {times[:1]}")
        if np.any(np.diff(times) <= 0) or times[-1] >= T or times[0] < 0:
            raise ValueError(f"times must increase strictly within [0, {T}) (one period), "
                             f"got {times}")
        if self.discrete:
            k = times / sys.dt
            if np.any(np.abs(k - np.round(k)) > 1e-9 * max(1.0, k.max())):
                raise ValueError(f"times must be multiples of dt={sys.dt} for a discrete "
                                 f"plant, got {times}")
            self.steps = np.round(k).astype(int)
        self.kind, self.times, self.size = 'switching', times.copy(), len(times)

    def values(self, t):
        """``φ_i(t)``, shape (len(t), s)."""
        t = np.mod(np.asarray(t, float), self.period)
        if self.kind == 'switching':
            idx = np.searchsorted(self.times, t + 1e-12 * self.period, side='right') - 1
            return (idx[:, None] == np.arange(self.size)).astype(float)
        w = 2 * np.pi / self.period * np.arange(1, self.order + 1)
        out = np.empty((len(t), self.size))
        out[:, 0] = 1.0
        out[:, 1::2] = np.cos(t[:, None] * w)
        out[:, 2::2] = np.sin(t[:, None] * w)
        return out

    def lift(self, F):
        """Parameters of the constant gain F in this family."""
        out = np.zeros((self.size,) + np.shape(F))
        if self.kind == 'switching':
            out[:] = F
        else:
            out[0] = F
        return out

    def matrix(self, theta):
        """The continuous-time gain F as a `PeriodicMatrix`."""
        if self.kind == 'switching':
            return PeriodicMatrix.switching(list(theta), self.times, self.period)
        q = self.order
        coeffs = np.zeros((2 * q + 1,) + theta.shape[1:], complex)
        coeffs[q] = theta[0]
        for j in range(1, q + 1):
            c = 0.5 * (theta[2 * j - 1] - 1j * theta[2 * j])
            coeffs[q + j], coeffs[q - j] = c, np.conj(c)
        return PeriodicMatrix(coeffs, self.period)
