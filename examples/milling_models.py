"""The 1-DOF milling model of Insperger and Stépán's benchmark, shared by the gallery and P12.

``m x'' + c x' + k x = -a_p h(t) (x(t) - x(t - τ))``: up-milling, 2 teeth,
5 % radial immersion, f_n = 922 Hz, ζ = 0.011, m = 0.03993 kg, K_t = 6e8,
K_n = 2e8 N/m²; the delay τ = 60/(N Ω) is the tooth period.  The specific
cutting force h(t) is nonzero only while the tooth is in the cut; its exit
instant is a breakpoint of the periodic matrices.

>>> sys = milling(10000.0, 1e-3)
>>> sys.delays == (sys.period,), sys.nstates
(True, 2)
"""

import numpy as np

import ltpcontrol as ltp

N_TEETH, KT, KN, FN, ZETA, MASS, AD = 2, 6e8, 2e8, 922.0, 0.011, 0.03993, 0.05
WN = 2 * np.pi * FN


def cut(rpm):
    """h(t) over one tooth period (N/m²), the instant the tooth leaves the cut, the period.

    >>> h, t_ex, T = cut(10000.0)
    >>> bool(0 < t_ex < T), float(h(t_ex + 1e-9))
    (True, 0.0)
    """
    T = 60.0 / (N_TEETH * rpm)
    ws = 2 * np.pi * rpm / 60
    t_ex = np.arccos(1 - 2 * AD) / ws

    def h(t):
        t = np.mod(np.asarray(t, float), T)
        phi = ws * t
        return np.where(t < t_ex, np.sin(phi) * (KT * np.cos(phi) + KN * np.sin(phi)), 0.0)
    return h, t_ex, T


def h_mean(rpm, a, b):
    """Exact mean of h over [a, b] within one period (semi-discretization's coefficient).

    >>> from scipy.integrate import quad
    >>> h, t_ex, T = cut(10000.0)
    >>> bool(np.isclose(h_mean(10000.0, 0.0, T), quad(h, 0.0, t_ex)[0] / T, rtol=1e-10))
    True
    """
    _, t_ex, _ = cut(rpm)
    ws = 2 * np.pi * rpm / 60
    lo, hi = max(a, 0.0), min(b, t_ex)
    if hi <= lo:
        return 0.0
    # ∫ sin φ (Kt cos φ + Kn sin φ) dφ = Kt sin²φ/2 + Kn (φ/2 - sin 2φ/4)
    F = lambda p: KT * np.sin(p) ** 2 / 2 + KN * (p / 2 - np.sin(2 * p) / 4)  # noqa: E731
    return (F(ws * hi) - F(ws * lo)) / ws / (b - a)


def milling(rpm, ap):
    """The milling model at spindle speed `rpm` (rev/min) and axial depth `ap` (m).

    >>> milling(10000.0, 2e-3).period
    0.003
    """
    h, t_ex, T = cut(rpm)

    def A(t):
        hv = np.asarray(h(t))
        out = np.zeros(hv.shape + (2, 2))
        out[..., 0, 1] = 1.0
        out[..., 1, 0] = -WN**2 - ap * hv / MASS
        out[..., 1, 1] = -2 * ZETA * WN
        return out

    def Ad(t):
        hv = np.asarray(h(t))
        out = np.zeros(hv.shape + (2, 2))
        out[..., 1, 0] = ap * hv / MASS
        return out
    bps = [0.0, t_ex]
    PA = ltp.PeriodicMatrix.from_function(A, T, (2, 2), breakpoints=bps, check=False)
    PAd = ltp.PeriodicMatrix.from_function(Ad, T, (2, 2), breakpoints=bps, check=False)
    return ltp.ltpdss(PA, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T, delays=[(T, PAd)])


def milling_mm(rpm, depth_mm):
    """`milling` with the axial depth in mm (the gallery's chart axis).

    >>> milling_mm(10000.0, 2.0).period
    0.003
    """
    return milling(rpm, depth_mm * 1e-3)
