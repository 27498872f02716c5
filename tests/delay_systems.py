"""Reference periodic delay-differential equations and independent truths for the delay tests.

Turning (regenerative chatter, closed-form lobes), 1-DOF milling
(Insperger-Stépán's benchmark), the damped delayed Mathieu equation (closed
D-curves at ε = 0), and a method-of-steps monodromy built on scipy's
``solve_ivp`` that shares nothing with the library's spectral elements.
"""

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import ltpcontrol as ltp

# turning: m x'' + c x' + k x = -k_c w (x - x(t - tau)), dimensionless
TURN = dict(m=1.0, c=0.1, k=1.0, kc=1.0)


def turning(tau, w, period=None, m=1.0, c=0.1, k=1.0, kc=1.0):
    """Turning as a delayed LTP system (constant coefficients, any period)."""
    A = [[0.0, 1.0], [-(k + kc * w) / m, -c / m]]
    Ad = [[0.0, 0.0], [kc * w / m, 0.0]]
    return ltp.ltpdss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=period or tau,
                      delays=[(tau, Ad)])


def turning_critical(tau, m=1.0, c=0.1, k=1.0, kc=1.0, lobes=10):
    """Closed-form critical depth at delay tau: the lowest lobe boundary there."""
    def wlim(om):
        return ((m * om**2 - k) ** 2 + (c * om) ** 2) / (2 * kc * (m * om**2 - k))

    def tau_of(om, j):
        z = (m * om**2 - k - 1j * c * om) / (kc * wlim(om))
        return (np.mod(-np.angle(1 - z), 2 * np.pi) + 2 * np.pi * j) / om

    om_n = np.sqrt(k / m)
    oms = om_n * (1 + np.geomspace(1e-7, 4, 6000))
    best = np.inf
    for j in range(lobes):
        t = tau_of(oms, j)
        for i in np.flatnonzero(np.diff(np.sign(t - tau)) != 0):
            if abs(t[i] - t[i + 1]) > 0.5 * tau:      # the wrap of the phase
                continue
            om = brentq(lambda o: tau_of(o, j) - tau, oms[i], oms[i + 1], xtol=1e-15)
            best = min(best, wlim(om))
    return best


# 1-DOF milling (Insperger & Stépán): up-milling, 2 teeth, 5 % radial immersion
MILL = dict(N=2, Kt=6e8, Kn=2e8, fn=922.0, zeta=0.011, m=0.03993, aD=0.05)


def milling_h(rpm, N=2, Kt=6e8, Kn=2e8, aD=0.05):
    """Specific cutting force h(t) over one tooth period (up-milling): (function, t_exit, T)."""
    T = 60.0 / (N * rpm)
    phi_ex = np.arccos(1 - 2 * aD)
    w_spin = 2 * np.pi * rpm / 60
    t_ex = phi_ex / w_spin

    def h(t):
        t = np.mod(np.asarray(t, float), T)
        phi = w_spin * t
        return np.where(t < t_ex, np.sin(phi) * (Kt * np.cos(phi) + Kn * np.sin(phi)), 0.0)
    return h, t_ex, T


def milling(rpm, ap, **kw):
    """1-DOF milling at spindle speed `rpm` (rev/min) and axial depth `ap` (m)."""
    p = dict(MILL, **kw)
    h, t_ex, T = milling_h(rpm, p['N'], p['Kt'], p['Kn'], p['aD'])
    wn = 2 * np.pi * p['fn']
    m, z = p['m'], p['zeta']

    def A(t):
        hv = np.asarray(h(t))
        out = np.zeros(hv.shape + (2, 2))
        out[..., 0, 1] = 1.0
        out[..., 1, 0] = -wn**2 - ap * hv / m
        out[..., 1, 1] = -2 * z * wn
        return out

    def Ad(t):
        hv = np.asarray(h(t))
        out = np.zeros(hv.shape + (2, 2))
        out[..., 1, 0] = ap * hv / m
        return out
    PA = ltp.PeriodicMatrix.from_function(A, T, (2, 2), breakpoints=[0.0, t_ex], check=False)
    PAd = ltp.PeriodicMatrix.from_function(Ad, T, (2, 2), breakpoints=[0.0, t_ex],
                                           check=False)
    return ltp.ltpdss(PA, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T, delays=[(T, PAd)])


def delayed_mathieu(delta, b, eps=0.0, kappa=0.1):
    """x'' + κx' + (δ + ε cos t)x = b x(t - 2π), period 2π."""
    if eps:
        A = ltp.PeriodicMatrix.from_function(
            lambda t: np.array([[0.0, 1.0], [-delta - eps * np.cos(t), -kappa]]), 2 * np.pi)
    else:
        A = [[0.0, 1.0], [-delta, -kappa]]
    return ltp.ltpdss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi,
                      delays=[(2 * np.pi, [[0.0, 0.0], [b, 0.0]])])


def mos_multipliers(stiff, delayed, T, window, M=30, rtol=1e-11, constant_outside=False):
    """Dominant multipliers of ``x'' = -stiff(t) x - damp x' + delayed(t) x(t - T)`` ... by solve_ivp.

    The second-order equation is ``[x, v]' = F(t)[x, v] + g(t) x(t - T)``
    with ``stiff(t) -> F(t)`` (2x2) and ``delayed(t) -> g(t)`` (scalar, zero
    outside `window` ⊂ [0, T]).  The state at a period start is x(0), v(0)
    and the positions of the last period at M Chebyshev points of the window
    (where the delayed term reads them); one period is integrated by
    solve_ivp (DOP853) for every basis state at once, the history
    interpolated by the Chebyshev polynomial of those points (outside the
    window, with ``constant_outside``, the exact exponential of the constant
    F).  Returns the
    eigenvalues of the resulting matrix by decreasing modulus.
    """
    a, b = window
    k = np.arange(M)
    z = np.cos(np.pi * (2 * k + 1) / (2 * M))            # Chebyshev points on [-1, 1]
    nodes = a + (z + 1) / 2 * (b - a)
    size = 2 + M

    # Chebyshev coefficients of the history columns (first-kind interpolation at the nodes)
    Tk = np.cos(np.outer(np.arange(M), np.arccos(z)))
    coef_of = (2 / M) * Tk
    coef_of[0] /= 2

    def hist(t, coef):
        y = np.clip(2 * (t - a) / (b - a) - 1, -1, 1)
        return np.cos(np.arange(M) * np.arccos(y)) @ coef

    def rhs_cut(t, s, Q):
        X = s.reshape(2, size)
        return (stiff(t) @ X + np.outer([0.0, 1.0], delayed(t) * hist(t, Q))).ravel()

    S0 = np.zeros((2, size))
    S0[0, 0] = S0[1, 1] = 1.0
    Q = np.zeros((M, size))
    Q[:, 2:] = np.eye(M)
    Q = coef_of @ Q
    segments = [(0.0, a, None), (a, b, Q), (b, T, None)]
    S, newQ = S0.ravel(), None
    for t0, t1, Qs in segments:
        if t1 <= t0:
            continue
        if Qs is None and constant_outside:      # free flight: exact exponential
            from scipy.linalg import expm
            S = (expm(stiff(0.5 * (t0 + t1)) * (t1 - t0)) @ S.reshape(2, size)).ravel()
            continue
        if Qs is None:
            sol = solve_ivp(lambda t, s: (stiff(t) @ s.reshape(2, size)).ravel(), (t0, t1), S,
                            method='DOP853', rtol=rtol, atol=1e-14, dense_output=True)
        else:
            sol = solve_ivp(rhs_cut, (t0, t1), S, method='DOP853', rtol=rtol, atol=1e-14,
                            dense_output=True, args=(Qs,))
            newQ = np.array([sol.sol(t).reshape(2, size)[0] for t in nodes])
        S = sol.y[:, -1]
    U = np.vstack([S.reshape(2, size), newQ])
    mu = np.linalg.eigvals(U)
    return mu[np.argsort(-np.abs(mu))]
