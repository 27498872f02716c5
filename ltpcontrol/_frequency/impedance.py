"""Impedances of electrical networks as harmonic objects.

A linear time-invariant network seen from a periodic converter — a grid
impedance ``R + sL``, an RLC branch, a transmission line model — has the
HTF of an LTI system written with the converter's period: block diagonal,
``H_{n,n}(s) = Z(s + jnω_p)`` (Conventions page).  `LTIHTF` evaluates it
exactly at any s, also for an *improper* Z: ``sL`` grows without bound and
no state space holds it, but its HTF on the grid ``s + jnω_p`` is exact,
so it can be multiplied with the HTF of a converter model or with an
estimated HTF (`harmonic_product`, `impedance_nyquist`).

`rlc_impedance` builds the usual networks (series, parallel, and the
Thévenin grid ``R + sL`` shunted by a capacitor), per phase or as the
balanced three-phase impedance in a synchronous (dq) frame, where the
rotation couples d and q:

    Z_dq(s) = [[z_r(s), -z_i(s)], [z_i(s), z_r(s)]],
    z_r = (Z(s + jω_1) + Z(s - jω_1))/2,  z_i = (Z(s + jω_1) - Z(s - jω_1))/(2j),

the real form of the complex-vector impedance ``Z(s + jω_1)`` (for
``Z = R + sL``: ``z_r = R + sL``, ``z_i = ω_1 L``).
"""

import numbers

import numpy as np
import control as ct
from control.exception import ControlArgument

from .htf import HTF, default_omega
from .._core.validation import check_period, check_positive, check_positive_int, real_array

__all__ = ['LTIHTF', 'rlc_impedance']


class LTIHTF(HTF):
    """Exact HTF of an LTI system (proper or improper) with a given period.

    The block-diagonal HTF ``H_{n,n}(s) = G(s + jnω_p)`` of a
    time-invariant G seen with the period T, evaluated from G itself at
    every point, so that an improper G (an inductance ``sL``) is exact on
    the grid ``s + jnω_p`` of the HTF.  Products with the HTF of a periodic
    model are realized exactly by `harmonic_product`.

    Parameters
    ----------
    sys : control.TransferFunction, control.StateSpace or array_like
        Continuous-time LTI system (a transfer function may be improper),
        or a static gain matrix.
    period : float
        The period T of the loop the system is part of.
    nharmonics : int
        Number K >= 0 of harmonics.
    name : str, optional
        Name (default: the system's name, 'Z' for a gain).

    Attributes
    ----------
    sys : control.TransferFunction or control.StateSpace
        The LTI system.

    Examples
    --------
    A grid inductance ``sL`` at the period of a 50 Hz grid:

    >>> Z = ltp.LTIHTF(ct.tf([2e-3, 0], [1]), 0.02, 2)
    >>> s = 10j
    >>> bool(np.isclose(Z(s)[3, 3], 2e-3 * (s + 1j * 2 * np.pi * 50)))
    True
    >>> float(abs(Z(s)[3, 2]))                   # no coupling between harmonics
    0.0
    """

    def __init__(self, sys, period, nharmonics, *, name=None):
        sys = as_lti(sys, 'sys')
        K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
        self._set_signals(check_period(period), K, sys.noutputs, sys.ninputs, 0.0,
                          name if name is not None else sys.name, sys.input_labels,
                          sys.output_labels)
        self.sys = sys

    def __neg__(self):
        return LTIHTF(-self.sys, self.period, self.nharmonics, name=f'-{self.name}')

    def __mul__(self, scalar):
        if not isinstance(scalar, numbers.Real) or isinstance(scalar, bool):
            return NotImplemented
        return LTIHTF(float(scalar) * self.sys, self.period, self.nharmonics,
                      name=self.name)

    __rmul__ = __mul__

    def _evaluate(self, s, progress):
        K, ny, nu = self.nharmonics, self.noutputs, self.ninputs
        out = np.zeros((len(s), (2 * K + 1) * ny, (2 * K + 1) * nu), complex)
        for a, n in enumerate(self.harmonics):
            G = evaluate_lti(self.sys, s + 1j * n * self.omega_p)
            out[:, a * ny:(a + 1) * ny, a * nu:(a + 1) * nu] = G
        return out

    def _components_on(self, omega, ks, progress=None):
        omega = (default_omega(self) if omega is None
                 else real_array(omega, 'omega', ndim=(0, 1)).reshape(-1))
        G = np.zeros((len(ks), self.noutputs, self.ninputs, len(omega)), complex)
        for i, k in enumerate(ks):
            if k == 0:
                G[i] = evaluate_lti(self.sys, 1j * omega).transpose(1, 2, 0)
        return omega, G


def rlc_impedance(R=0.0, L=0.0, C=None, *, connection='series', period, nharmonics,
                  nphases=1, omega1=None, name=None):
    """Impedance of an R, L, C network as an exact harmonic object.

    Parameters
    ----------
    R, L : float
        Resistance (Ω) and inductance (H), >= 0.
    C : float, optional
        Capacitance (F), > 0 (None: no capacitor).
    connection : {'series', 'parallel', 'grid'}
        'series': ``R + sL + 1/(sC)``; 'parallel': the three elements in
        parallel (an element given as 0, or C None, is left out);
        'grid': the Thévenin grid ``R + sL`` shunted by C at the point of
        coupling, ``(R + sL)/(1 + sC(R + sL))``.
    period : float
        Period T of the converter loop.
    nharmonics : int
        Number K of harmonics of the HTF.
    nphases : int
        Identical uncoupled phases (1: single phase; 3: abc).
    omega1 : float, optional
        The balanced three-phase impedance in the dq frame rotating at
        `omega1` (rad/s): 2x2, d and q coupled by the rotation (module
        notes); `nphases` is then ignored.
    name : str, optional
        Name of the result (default 'Z').

    Returns
    -------
    LTIHTF
        Exact at every point, also when the impedance is improper.

    Raises
    ------
    ValueError
        For negative or non-finite element values, a network without any
        element, or an unknown `connection`.

    Examples
    --------
    A grid ``R + sL`` and its dq form at 50 Hz (``-ω_1 L`` couples q into d):

    >>> Zg = ltp.rlc_impedance(0.1, 2e-3, period=0.02, nharmonics=1)
    >>> bool(np.isclose(Zg(0.0)[1, 1], 0.1))
    True
    >>> w1 = 2 * np.pi * 50
    >>> Zdq = ltp.rlc_impedance(0.1, 2e-3, period=0.02, nharmonics=1, omega1=w1)
    >>> np.round(Zdq.sys(0.0).real, 6)
    array([[ 0.1     , -0.628319],
           [ 0.628319,  0.1     ]])
    """
    R = _element(R, 'R')
    L = _element(L, 'L')
    C = None if C is None else check_positive(C, 'C')
    if connection not in ('series', 'parallel', 'grid'):
        raise ValueError(f"connection must be 'series', 'parallel' or 'grid', got "
                         f"{connection!r}")
    s = ct.tf('s')
    if connection == 'series':
        Z = R + L * s if (R or L) else 0 * s
        if C is not None:
            Z = Z + 1 / (C * s)
        if not (R or L or C is not None):
            raise ValueError("rlc_impedance: the series network has no element")
    elif connection == 'parallel':
        Y = 0 * s
        if R:
            Y = Y + 1 / R
        if L:
            Y = Y + 1 / (L * s)
        if C is not None:
            Y = Y + C * s
        if not (R or L or C is not None):
            raise ValueError("rlc_impedance: the parallel network has no element")
        Z = ct.tf(Y.den[0][0], Y.num[0][0])
    else:
        if C is None or not (R or L):
            raise ValueError("rlc_impedance: the 'grid' network needs R or L, and C")
        branch = ct.tf([L, R], [1])
        Z = ct.tf(branch.num[0][0], np.polyadd([1.0], C * np.polymul([L, R], [1.0, 0.0])))
    Z = ct.tf(np.trim_zeros(np.atleast_1d(Z.num[0][0]), 'f') if np.any(Z.num[0][0]) else [0.0],
              Z.den[0][0])
    if omega1 is not None:
        w1 = float(real_array(omega1, 'omega1', ndim=0))
        if w1 == 0:
            raise ValueError("omega1 must be nonzero (the speed of the dq frame)")
        Z = dq_form(Z, w1)
        labels = dict(inputs=['i_d', 'i_q'], outputs=['v_d', 'v_q'])
    else:
        nph = check_positive_int(nphases, 'nphases', minimum=1)
        if nph > 1:
            Z = _diagonal(Z, nph)
        labels = {}
    Z = ct.tf(Z, name=name or 'Z', **labels)
    return LTIHTF(Z, period, nharmonics, name=name or 'Z')


def dq_form(Z, omega1):
    """Balanced three-phase impedance ``Z(s)`` in the dq frame rotating at ω_1.

    Examples
    --------
    >>> from ltpcontrol._frequency.impedance import dq_form
    >>> Zdq = dq_form(ct.tf([1.0, 2.0], [1]), 3.0)            # R = 2, L = 1
    >>> np.round(Zdq(0.5j), 12)
    array([[ 2.+0.5j, -3.+0.j ],
           [ 3.+0.j ,  2.+0.5j]])
    """
    num, den = np.asarray(Z.num[0][0], float), np.asarray(Z.den[0][0], float)
    a = 1j * omega1
    # Z(s ± a) = num(s ± a) / den(s ± a)
    np_, dp = _shift(num, a), _shift(den, a)
    nm, dm = _shift(num, -a), _shift(den, -a)
    # z_r = (np/dp + nm/dm)/2, z_i = (np/dp - nm/dm)/(2j) over the real den dp dm
    d = np.real_if_close(np.polymul(dp, dm), tol=1e6).real
    zr = 0.5 * np.polyadd(np.polymul(np_, dm), np.polymul(nm, dp))
    zi = (np.polysub(np.polymul(np_, dm), np.polymul(nm, dp))) / 2j
    zr, zi = _real_poly(zr), _real_poly(zi)
    # the poles of Z(s ± jω_1) are distinct: no common factor to cancel
    lead = d[0]
    zr, zi, d = zr / lead, zi / lead, d / lead
    return ct.tf([[zr, -zi], [zi, zr]], [[d, d], [d, d]])


def as_lti(sys, name):
    """A continuous-time LTI system (transfer function kept as it is).

    Examples
    --------
    >>> from ltpcontrol._frequency.impedance import as_lti
    >>> as_lti(2.0, 'K').ninputs, as_lti(ct.tf([1, 0], [1]), 'Z').isctime()
    (1, True)
    """
    if isinstance(sys, (ct.TransferFunction, ct.StateSpace)):
        if sys.isdtime(strict=True):
            raise ValueError(f"{name} must be a continuous-time system")
        return sys
    if isinstance(sys, ct.InputOutputSystem):
        raise ControlArgument(f"{name} must be an LTI system (TransferFunction or "
                              f"StateSpace), got {type(sys).__name__}")
    K = real_array(sys, name, ndim=(0, 2))
    K = np.atleast_2d(K)
    return ct.ss([], [], [], K, name=None)


def evaluate_lti(sys, x):
    """``G(x)`` at the points x, shape (len(x), ny, nu); inf at a pole.

    Examples
    --------
    >>> from ltpcontrol._frequency.impedance import evaluate_lti
    >>> evaluate_lti(ct.tf([1, 0], [1]), np.array([2j])).shape
    (1, 1, 1)
    """
    with np.errstate(divide='ignore', invalid='ignore'):
        G = np.asarray(sys(np.asarray(x, complex), squeeze=False), complex)
    return G.reshape(sys.noutputs, sys.ninputs, -1).transpose(2, 0, 1)


#
# Helpers
#

def _element(x, name):
    x = float(real_array(x, name, ndim=0))
    if x < 0:
        raise ValueError(f"{name} must be >= 0, got {x}")
    return x


def _shift(p, a):
    """Coefficients of ``p(s + a)`` (highest power first)."""
    out = np.zeros(1, complex)
    base = np.array([1.0, a])
    for c in np.asarray(p, complex):
        out = np.polyadd(np.polymul(out, base), [c])
    return out


def _real_poly(p):
    p = np.asarray(p)
    scale = max(1.0, np.abs(p).max(initial=0.0))
    if np.abs(p.imag).max(initial=0.0) > 1e-9 * scale:
        raise ValueError("dq_form: the impedance does not have real coefficients")
    p = p.real
    nz = np.nonzero(np.abs(p) > 1e-14 * scale)[0]
    return p[nz[0]:] if nz.size else np.zeros(1)


def _diagonal(Z, n):
    zero = [0.0]
    num = [[Z.num[0][0] if i == j else zero for j in range(n)] for i in range(n)]
    den = [[Z.den[0][0] if i == j else [1.0] for j in range(n)] for i in range(n)]
    return ct.tf(num, den)
