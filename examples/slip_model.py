"""Extended spring-loaded inverted pendulum (SLIP) and four stride predictors.

The extended SLIP of thesis Chapter 2 (Table 2.1) is a point body of mass
``m_b`` on a massless prismatic leg with stiffness ``k``, viscous damping
``d`` and rest length ``rho0``; a leg mass ``m_l`` sits at the toe and only
matters at the liftoff collision (2.21).  Flight has horizontal and vertical
viscous damping ``d_h``, ``d_v`` (2.4).  One stride is the apex return map

    X_{n+1} = (f_a o f_c o f_s o f_d)(X_n, theta_td),     X = [y, ydot, z]   (2.1-2.3)

with descent ``f_d`` and ascent ``f_a`` in closed form (2.5-2.8), the
liftoff collision ``f_c`` (2.21) and one of four stance maps ``f_s``:

``"AAS"``
    approximate analytic stance solution with leg damping (2.11-2.19) and
    the gravity correction of the angular momentum (2.20).  (2.20) is the
    stance average of a momentum growing linearly under the mean gravity
    torque; the trajectory uses that average and the liftoff velocity the
    momentum reached at liftoff, ``2 p_hat - p_td`` (the literal reading,
    average up to liftoff, is ``liftoff_momentum="average"``);
``"Geyer"``
    Geyer's lossless approximation (closed-form stance time, no damping,
    no gravity correction);
``"SLIP"``
    numerical integration of the lossless stance dynamics (2.9-2.10), c = 0;
``"SLIPD"``
    numerical integration of the damped stance dynamics (2.9-2.10).

Conventions: ``y`` is horizontal (forward), ``z`` vertical; the leg angle
``theta`` is measured from the vertical with the body at
``(y_toe + rho sin(theta), rho cos(theta))``, so forward running touches down
with ``theta_td < 0`` and lifts off with ``theta > 0``.  The flight damping
coefficients are accelerations per unit velocity (units 1/s), as in (2.4).
Liftoff happens when the leg force ``k (rho0 - rho) - d rhodot`` (hence the
vertical ground reaction force) reaches zero; for a lossless leg this is the
rest length.  Every method shares the flight maps and the collision map, so
"lossless" refers to the leg only.
"""

from dataclasses import dataclass, replace
from typing import Callable, NamedTuple

import numpy as np
from scipy.integrate import solve_ivp

__all__ = ["SLIPParams", "Event", "Stride", "METHODS", "boom_gravity",
           "flight_state", "descent_time", "ascent_apex_time",
           "liftoff_collision", "stance_energy", "predict_stride",
           "stride_trajectory", "neutral_touchdown_angle"]

METHODS = ("SLIPD", "AAS", "SLIP", "Geyer")


def boom_gravity(M, m, g0=9.81):
    """Gravity perceived by a boom-mounted robot, eq. (2.24).

    Parameters
    ----------
    M : float
        Mass of the leg assembly at the boom tip (kg).
    m : float
        Mass of the boom, a rod rotating about its far end (kg).
    g0 : float, optional
        Gravitational acceleration (m/s^2).

    Returns
    -------
    float
        ``g0 (M + m/2) / (M + m/3)``.

    Examples
    --------
    >>> round(boom_gravity(3.4, 0.39), 2)
    9.99
    """
    M, m, g0 = float(M), float(m), float(g0)
    if M <= 0 or m < 0 or g0 <= 0:
        raise ValueError("boom_gravity: M and g0 must be positive and m >= 0")
    # (2.22)-(2.24) with I = m l^2 / 3 and small boom angle
    return g0 * (M + m / 2) / (M + m / 3)


@dataclass(frozen=True)
class SLIPParams:
    """Parameters of the extended SLIP model (Table 2.1).

    Defaults are the thesis's monopod: Table 2.3 masses and flight damping,
    ``d_h`` of Section 2.4.2, the hard spring of Table 2.5 (vertical
    experiments), a 22 cm leg and the boom-corrected gravity (2.24).

    Parameters
    ----------
    m_b, m_l : float
        Body and leg (toe) mass, kg.
    k : float
        Leg stiffness, N/m.
    d : float
        Leg viscous damping, N s/m.
    d_h, d_v : float
        Horizontal and vertical flight damping, 1/s, as in (2.4).
    rho0 : float
        Leg rest length, m.
    g : float
        Gravitational acceleration, m/s^2.

    Examples
    --------
    >>> p = SLIPParams()
    >>> round(p.kappa, 1), round(p.c, 3)
    (45.5, 0.587)
    """

    m_b: float = 3.21
    m_l: float = 0.19
    k: float = 6630.0
    d: float = 12.7
    d_h: float = 0.3
    d_v: float = 0.06
    rho0: float = 0.22
    g: float = 9.99

    def __post_init__(self):
        for name in ("m_b", "k", "rho0", "g"):
            value = getattr(self, name)
            if not np.isfinite(value) or value <= 0:
                raise ValueError(f"SLIPParams: {name} must be positive, got {value}")
        for name in ("m_l", "d", "d_h", "d_v"):
            value = getattr(self, name)
            if not np.isfinite(value) or value < 0:
                raise ValueError(f"SLIPParams: {name} must be >= 0, got {value}")

    def replace(self, **changes):
        """Return a copy with some parameters changed."""
        return replace(self, **changes)

    @property
    def lam(self):
        """Time scale ``lambda = sqrt(rho0 / g)`` (Table 2.2)."""
        return float(np.sqrt(self.rho0 / self.g))

    @property
    def kappa(self):
        """Non-dimensional stiffness ``k rho0 / (m_b g)`` (Table 2.2)."""
        return self.k * self.rho0 / (self.m_b * self.g)

    @property
    def c(self):
        """Non-dimensional damping ``d rho0 / (lambda m_b g)`` (Table 2.2)."""
        return self.d * self.lam / self.m_b


class Event(NamedTuple):
    """Body state at a transition event; arrays of equal shape.

    ``t`` is measured from the initial apex and ``y`` in the frame of the
    initial apex state.  Velocities at liftoff are taken before the
    collision (2.21).
    """

    t: np.ndarray
    y: np.ndarray
    z: np.ndarray
    vy: np.ndarray
    vz: np.ndarray


class Stride(NamedTuple):
    """Transition events of one predicted stride (apex to apex)."""

    touchdown: Event
    bottom: Event
    liftoff: Event
    apex: Event


# ---------------------------------------------------------------- flight maps

def _expm1_ratio(x):
    """``(1 - exp(-x)) / x`` with its limit 1 at x = 0."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 1e-8
    safe = np.where(small, 1.0, x)
    return np.where(small, 1.0 - x / 2, -np.expm1(-safe) / safe)


def _expm1_ratio2(x):
    """``(exp(-x) - 1 + x) / x^2`` with its limit 1/2 at x = 0."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 1e-4
    safe = np.where(small, 1.0, x)
    return np.where(small, 0.5 - x / 6 + x ** 2 / 24,
                    (np.expm1(-safe) + safe) / safe ** 2)


def flight_state(t, y0, z0, vy0, vz0, d_h, d_v, g):
    """Damped ballistic flight, eqs. (2.5)-(2.8).

    Parameters
    ----------
    t : array_like
        Time since the initial state, s.
    y0, z0, vy0, vz0 : array_like
        Initial position (m) and velocity (m/s); broadcast with `t`.
    d_h, d_v : float
        Horizontal and vertical flight damping, 1/s (zero allowed).
    g : float
        Gravity, m/s^2.

    Returns
    -------
    y, z, vy, vz : ndarray

    Examples
    --------
    >>> y, z, vy, vz = flight_state(0.1, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 10.0)
    >>> float(y), float(z), float(vy), float(vz)
    (0.2, 0.95, 2.0, -1.0)
    """
    t = np.asarray(t, dtype=float)
    xh, xv = d_h * t, d_v * t
    # (2.5), (2.7): y = y0 + vy0 (1 - e^{-d_h t}) / d_h
    y = y0 + vy0 * t * _expm1_ratio(xh)
    vy = vy0 * np.exp(-xh)
    # (2.6), (2.8) written with stable ratios for small d_v t
    z = z0 + vz0 * t * _expm1_ratio(xv) - g * t ** 2 * _expm1_ratio2(xv)
    vz = vz0 * np.exp(-xv) - g * t * _expm1_ratio(xv)
    return y, z, vy, vz


#: Descent times already computed, by their arguments (at most `_DESCENT_CACHE_SIZE`).
#: A leg fit predicts the same strides again and again with other leg
#: parameters, and the descent does not depend on the leg.
_DESCENT_CACHE = {}
_DESCENT_CACHE_SIZE = 64


def descent_time(z0, z_td, d_v, g):
    """Time to fall from apex height `z0` to touchdown height `z_td`.

    Solves ``z(t) = z_td`` of (2.6) with zero initial vertical velocity by
    Newton's method (``z`` is monotone on the descent).  The result for the
    same arguments is computed once (see `_DESCENT_CACHE`).

    Examples
    --------
    >>> round(float(descent_time(1.0, 0.0, 0.0, 2.0)), 12)
    1.0
    """
    z0, z_td = np.broadcast_arrays(np.asarray(z0, float), np.asarray(z_td, float))
    if np.ndim(d_v) or np.ndim(g):
        return _descent_time(z0, z_td, d_v, g)
    key = (z0.shape, z0.tobytes(), z_td.tobytes(), float(d_v), float(g))
    if key not in _DESCENT_CACHE:
        if len(_DESCENT_CACHE) >= _DESCENT_CACHE_SIZE:
            del _DESCENT_CACHE[next(iter(_DESCENT_CACHE))]      # the oldest entry
        _DESCENT_CACHE[key] = _descent_time(z0, z_td, d_v, g)
    return _DESCENT_CACHE[key].copy()


def _descent_time(z0, z_td, d_v, g):
    """`descent_time` of broadcast arrays, computed."""
    drop = z0 - z_td
    t = np.sqrt(2 * np.maximum(drop, 0) / g)
    for _ in range(30):
        # z and vz of `flight_state` from rest (vz0 = 0), without the horizontal part
        xv = d_v * t
        ratio = _expm1_ratio(xv)
        z = z0 + 0.0 * t * ratio - g * t ** 2 * _expm1_ratio2(xv)
        vz = 0.0 * np.exp(-xv) - g * t * ratio
        step = np.where(vz < 0, (z - z_td) / np.where(vz < 0, vz, -1.0), 0.0)
        t = t - step
        if np.all(np.abs(step) <= 1e-15 * np.maximum(t, 1e-3)):
            break
    return np.where(drop > 0, t, np.nan)


def ascent_apex_time(vz0, d_v, g):
    """Time from liftoff to apex, the root of (2.8).

    ``t = log(1 + vz0 d_v / g) / d_v`` (``vz0 / g`` when ``d_v = 0``); NaN
    when the body does not rise.

    Examples
    --------
    >>> float(ascent_apex_time(2.0, 0.0, 10.0))
    0.2
    """
    vz0 = np.asarray(vz0, dtype=float)
    u = vz0 * d_v / g
    ratio = np.where(np.abs(u) < 1e-10, 1.0 - u / 2,
                     np.log1p(u) / np.where(u == 0, 1.0, u))
    return np.where(vz0 > 0, vz0 / g * ratio, np.nan)


def liftoff_collision(vy, vz, m_b, m_l):
    """Inelastic body-leg collision at liftoff, eq. (2.21).

    Examples
    --------
    >>> liftoff_collision(1.0, 2.0, 3.0, 1.0)
    (0.75, 1.5)
    """
    ratio = m_b / (m_b + m_l)
    return vy * ratio, vz * ratio


def stance_energy(rho, theta, rhod, thetad, kappa):
    """Non-dimensional stance energy ``E / (m_b g rho0)`` of (2.9)-(2.10).

    ``E = (rhod^2 + rho^2 thetad^2) / 2 + rho cos(theta) + kappa (rho - 1)^2 / 2``;
    conserved when the leg damping ``c`` is zero.
    """
    return (0.5 * (rhod ** 2 + (rho * thetad) ** 2) + rho * np.cos(theta)
            + 0.5 * kappa * (rho - 1) ** 2)


# ---------------------------------------------------------------- stance maps
# All stance maps work in the non-dimensional polar coordinates of Table 2.2,
# start at touchdown (rho = 1, rhod = rhod0 < 0, theta = theta0,
# p = thetad0) and return the bottom and liftoff times plus an evaluator of
# (rho, theta, rhod, thetad) at per-stride times.

class _Stance(NamedTuple):
    t_b: np.ndarray
    t_lo: np.ndarray
    state: Callable


def _newton_root(fun, lo, hi, iterations=40, f_hi=None):
    """Vectorised safeguarded Newton for the root of ``fun`` in ``[lo, hi]``.

    ``fun(t)`` returns the value and the derivative; the value must change
    sign over the bracket.  Steps leaving the bracket fall back to bisection.
    `f_hi` is the value at `hi` when the caller has it already.
    """
    f_lo = fun(lo)[0]
    active = np.sign(f_lo) != np.sign(fun(hi)[0] if f_hi is None else f_hi)
    inactive = ~active
    t = 0.5 * (lo + hi)
    for _ in range(iterations):
        f, df = fun(t)
        same = np.sign(f) == np.sign(f_lo)
        lo, f_lo = np.where(same, t, lo), np.where(same, f, f_lo)
        hi = np.where(same, hi, t)
        step = t - f / np.where(df == 0, np.inf, df)
        inside = (step >= lo) & (step <= hi)
        t_new = np.where(inside, step, 0.5 * (lo + hi))
        done = np.abs(t_new - t) <= 1e-12
        t = t_new
        if (done | inactive).all():
            break
    return np.where(active, t, np.nan)


def _aas_radial(rhod0, p, kappa, c):
    """Coefficients of the damped radial solution, eqs. (2.11)-(2.19)."""
    w = np.sqrt(kappa + 3 * p ** 2)                     # omega_0 hat
    xi = c / (2 * w)
    wd = w * np.sqrt(1 - xi ** 2)
    F = kappa + 4 * p ** 2 - 1
    A = 1 - F / w ** 2                                  # (2.18), rho_td = 1
    B = (rhod0 + xi * w * A) / wd                       # (2.19)
    M = np.hypot(A, B)                                  # (2.15)
    phi = np.arctan2(-B, A)                             # (2.16)
    phi2 = np.arctan2(-np.sqrt(1 - xi ** 2), xi)        # (2.17)
    return w, xi, wd, F, M, phi, phi2


def _aas_evaluator(theta0, p, kappa, c, rhod0, p_td=None):
    """Stance evaluator of (2.11)-(2.14) with the angular momentum ``p``.

    With ``p_td`` given, ``p`` is read as the stance average of a momentum
    growing linearly from ``p_td`` (the reading of (2.20) explained in
    :func:`_stance_aas`): the radial motion and the angle keep the average
    ``p`` of (2.11)-(2.13), while the angular rate (2.14) uses the momentum
    at the evaluation time, ``p_td + 2 (p - p_td) t / t_lo``.
    """
    w, xi, wd, F, M, phi, phi2 = _aas_radial(rhod0, p, kappa, c)
    X = 3 * p - 2 * p * F / w ** 2
    Y = 2 * p * M / w          # integral of (2.14) gives (2.13)
    rate = np.zeros_like(w)    # d p / d t, set below once t_lo is known

    def state(t):
        t = np.asarray(t, dtype=float)
        shape = (-1,) + (1,) * (t.ndim - np.ndim(theta0))
        a = [np.reshape(v, shape) if np.ndim(v) else v
             for v in (theta0, p, w, xi, wd, F, M, phi, phi2, X, Y, rate)]
        th0, pp, w_, xi_, wd_, F_, M_, ph, ph2, X_, Y_, r_ = a
        decay = np.exp(-xi_ * w_ * t)
        rho = M_ * decay * np.cos(wd_ * t + ph) + F_ / w_ ** 2            # (2.11)
        rhod = -M_ * w_ * decay * np.cos(wd_ * t + ph + ph2)             # (2.12)
        theta = th0 + X_ * t + Y_ * (decay * np.cos(wd_ * t + ph - ph2)
                                     - np.cos(ph - ph2))                 # (2.13)
        # (2.14) is thetad = p (3 - 2 rho), the linearised p / rho^2
        p_now = pp if p_td is None else pp + r_ * (t - t_mid(t, shape))
        thetad = p_now * (3 - 2 * rho)                                   # (2.14)
        return rho, theta, rhod, thetad

    def t_mid(t, shape):
        half = 0.5 * np.nan_to_num(t_lo)
        return np.reshape(half, shape) if np.ndim(half) else half

    # bottom: rhod = 0, first zero of cos(wd t + phi + phi2) after t = 0
    t_b = np.mod(np.pi / 2 - phi - phi2, np.pi) / wd
    t_top = t_b + np.pi / wd            # next maximum of rho

    # factors of `force` that do not depend on t (the Newton iteration calls it often)
    rate_t, rho_mean = -xi * w, F / w ** 2
    amp_d, amp_dd, neg_kappa, two_phi2 = -M * w, M * w ** 2, -kappa, 2 * phi2

    def force(t):
        # leg force kappa (1 - rho) - c rhod and its derivative, with
        # rhodd = M w^2 e^{-xi w t} cos(wd t + phi + 2 phi2) from (2.12)
        decay = np.exp(rate_t * t)
        arg = wd * t + phi
        rho = M * decay * np.cos(arg) + rho_mean
        rhod = amp_d * decay * np.cos(arg + phi2)
        rhodd = amp_dd * decay * np.cos(arg + two_phi2)
        return kappa * (1 - rho) - c * rhod, neg_kappa * rhod - c * rhodd

    f_top = force(t_top)[0]
    lifts = (f_top < 0) & (rhod0 < 0) & (xi < 1)
    t_lo = np.where(lifts, _newton_root(force, t_b, t_top, f_hi=f_top), np.nan)
    if p_td is not None:
        # p grows from p_td at touchdown to 2 p - p_td at liftoff
        rate[...] = np.nan_to_num(2 * (p - p_td) / np.where(lifts, t_lo, 1.0))
    return _Stance(t_b, t_lo, state)


def _stance_aas(rhod0, theta0, p0, kappa, c, gravity_correction=True,
                liftoff_momentum="final", iterations=30):
    """AAS stance map, eqs. (2.11)-(2.20).

    The gravity correction (2.20),
    ``p_hat = p_td + t_lo/4 (rho_td sin theta_td + rho_lo sin theta_lo)``,
    depends on the liftoff state it produces, so it is applied as a
    fixed-point iteration started from ``p0``.

    (2.20) is the stance average of the angular momentum when the gravity
    torque ``rho sin(theta)`` of (2.10) is replaced by the mean of its
    touchdown and liftoff values: the momentum then grows linearly from
    ``p_td`` to ``p_lo = p_td + t_lo/2 (rho_td sin theta_td + rho_lo sin
    theta_lo) = 2 p_hat - p_td``, whose average is ``p_hat``.  The average
    shapes the stance trajectory (2.11)-(2.13).  With
    ``liftoff_momentum="final"`` (default) the angular rate (2.14) uses the
    momentum at the evaluation time, so the liftoff velocity carries
    ``p_lo``; ``"average"`` keeps ``p_hat`` in (2.14) throughout, which
    under-predicts the liftoff angular rate of asymmetric strides (the
    gravity torque changes sign between touchdown and liftoff only for
    symmetric ones).
    """
    if liftoff_momentum not in ("final", "average"):
        raise ValueError("liftoff_momentum must be 'final' or 'average', "
                         f"got {liftoff_momentum!r}")
    p_hat = p0
    stance = _aas_evaluator(theta0, p_hat, kappa, c, rhod0)
    if not gravity_correction:
        return stance
    for _ in range(iterations):
        rho_lo, theta_lo, _, _ = stance.state(stance.t_lo)
        # (2.20): p_hat = p_td + t_lo/4 (rho_td sin theta_td + rho_lo sin theta_lo)
        p_new = p0 + stance.t_lo / 4 * (np.sin(theta0) + rho_lo * np.sin(theta_lo))
        p_new = np.where(np.isfinite(p_new), p_new, p0)
        converged = bool(np.all(np.abs(p_new - p_hat) <= 1e-11))   # allclose(atol=1e-11)
        p_hat = p_new
        stance = _aas_evaluator(theta0, p_hat, kappa, c, rhod0)
        if converged:
            break
    if liftoff_momentum == "final":
        stance = _aas_evaluator(theta0, p_hat, kappa, c, rhod0, p_td=p0)
    return stance


def _stance_geyer(rhod0, theta0, p0, kappa):
    """Geyer's lossless approximation (small sweep, small compression).

    With compression ``u = 1 - rho``, ``u'' + w^2 u = 1 - p^2`` and
    ``thetad = p (1 + 2u)`` with ``w^2 = kappa + 3 p^2``, giving the
    closed-form stance time ``t_s = (pi + 2 arctan(a / b)) / w`` with
    ``a = (1 - p^2)/w^2``, ``b = -rhod0 / w``.
    """
    p = p0
    w = np.sqrt(kappa + 3 * p ** 2)
    a = (1 - p ** 2) / w ** 2
    b = -rhod0 / w

    def state(t):
        t = np.asarray(t, dtype=float)
        shape = (-1,) + (1,) * (t.ndim - np.ndim(theta0))
        th0, pp, w_, a_, b_ = [np.reshape(v, shape) if np.ndim(v) else v
                               for v in (theta0, p, w, a, b)]
        s, co = np.sin(w_ * t), np.cos(w_ * t)
        u = a_ * (1 - co) + b_ * s
        rho = 1 - u
        rhod = -w_ * (a_ * s + b_ * co)
        theta = th0 + pp * (1 + 2 * a_) * t - 2 * pp * a_ * s / w_ \
            + 2 * pp * b_ * (1 - co) / w_
        thetad = pp * (1 + 2 * u)
        return rho, theta, rhod, thetad

    valid = rhod0 < 0
    t_lo = np.where(valid, (np.pi + 2 * np.arctan(a / np.where(valid, b, 1))) / w,
                    np.nan)
    return _Stance(t_lo / 2, t_lo, state)


def _stance_numeric(rhod0, theta0, p0, kappa, c, rtol=1e-10, atol=1e-12):
    """Numerical stance map: (2.9)-(2.10) for all strides at once.

    All strides are integrated as one ODE system with a common adaptive step
    (DOP853); bottom (``rhod = 0``) and liftoff (zero leg force) are located
    per stride by bracketing sign changes on the dense output and solving
    the cubic Hermite interpolant of the event function.
    """
    rhod0, theta0, p0, kappa, c = np.broadcast_arrays(
        *[np.atleast_1d(np.asarray(v, float)) for v in (rhod0, theta0, p0, kappa, c)])
    n = rhod0.size

    def rhs(_, x):
        # x has shape (4 n,) or (4 n, m): blocks rho, theta, rhod, thetad
        rho, theta, rhod, thetad = x.reshape((4, n) + x.shape[1:])
        kap, cc = (kappa, c) if x.ndim == 1 else (kappa[:, None], c[:, None])
        rhodd = rho * thetad ** 2 - kap * (rho - 1) - cc * rhod - np.cos(theta)  # (2.9)
        thetadd = (np.sin(theta) - 2 * rhod * thetad) / rho                     # (2.10)
        return np.concatenate([rhod, thetad, rhodd, thetadd])

    # horizon: a bit more than a half period of the radial oscillation
    guess = _stance_geyer(np.minimum(rhod0, -1e-6), theta0, p0, kappa).t_lo
    horizon = 1.5 * np.nanmax(np.where(np.isfinite(guess), guess,
                                       np.pi / np.sqrt(kappa)))
    x0 = np.concatenate([np.ones(n), theta0, rhod0, p0])
    sol = solve_ivp(rhs, (0.0, horizon), x0, method="DOP853", rtol=rtol,
                    atol=atol, dense_output=True).sol
    idx = np.arange(n)

    def state(t):
        t = np.asarray(t, dtype=float)          # shape (n,) or (n, m)
        tt = t.reshape(n, -1)
        vals = sol(tt.ravel()).reshape(4, n, n, tt.shape[1])[:, idx, idx, :]
        return tuple(vals.reshape((4,) + t.shape))

    # events: bracket sign changes on a grid, then root of the cubic Hermite
    # interpolant of the event function (values and slopes from rhs)
    grid = np.linspace(0.0, horizon, 400)
    x_g = sol(grid)
    dx_g = rhs(None, x_g)
    rho_g, _, rhod_g, _ = x_g.reshape(4, n, grid.size)
    rhodd_g = dx_g.reshape(4, n, grid.size)[2]
    h = grid[1] - grid[0]

    def hermite_root(val, slope):
        crossed = val <= 0
        crossed[:, 0] = False
        first = np.argmax(crossed, axis=1)
        found = crossed[idx, first] & (first > 0)
        i0 = np.maximum(first - 1, 0)
        f0, f1 = val[idx, i0], val[idx, first]
        m0, m1 = h * slope[idx, i0], h * slope[idx, first]

        def cubic(s):
            s2, s3 = s * s, s * s * s
            value = ((2 * s3 - 3 * s2 + 1) * f0 + (s3 - 2 * s2 + s) * m0
                     + (-2 * s3 + 3 * s2) * f1 + (s3 - s2) * m1)
            deriv = ((6 * s2 - 6 * s) * f0 + (3 * s2 - 4 * s + 1) * m0
                     + (-6 * s2 + 6 * s) * f1 + (3 * s2 - 2 * s) * m1)
            return value, deriv

        s = _newton_root(cubic, np.zeros(n), np.ones(n))
        return np.where(found, grid[i0] + h * s, np.nan)

    # bottom: -rhod changes sign; liftoff: leg force kappa (1 - rho) - c rhod
    t_b = hermite_root(-rhod_g, -rhodd_g)
    t_lo = hermite_root(kappa[:, None] * (1 - rho_g) - c[:, None] * rhod_g,
                        -kappa[:, None] * rhod_g - c[:, None] * rhodd_g)
    return _Stance(t_b, t_lo, state)


def _stance(method, rhod0, theta0, p0, kappa, c, rtol, liftoff_momentum="final"):
    if method == "AAS":
        return _stance_aas(rhod0, theta0, p0, kappa, c,
                           liftoff_momentum=liftoff_momentum)
    if method == "Geyer":
        return _stance_geyer(rhod0, theta0, p0, kappa)
    if method == "SLIP":
        return _stance_numeric(rhod0, theta0, p0, kappa, np.zeros_like(c), rtol=rtol)
    return _stance_numeric(rhod0, theta0, p0, kappa, c, rtol=rtol)


# ---------------------------------------------------------------- stride map

def _check_method(method):
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")


def _prepare(apex, theta_td, params):
    if not isinstance(params, SLIPParams):
        raise TypeError(f"params must be SLIPParams, got {type(params).__name__}")
    apex = np.asarray(apex, dtype=float)
    if apex.shape[-1:] != (3,) or apex.ndim > 2:
        raise ValueError(f"apex must have shape (3,) or (n, 3), got {apex.shape}")
    theta_td = np.asarray(theta_td, dtype=float)
    y0, vy0, z0 = np.broadcast_arrays(apex[..., 0], apex[..., 1], apex[..., 2],
                                      theta_td)[:3]
    theta_td = np.broadcast_to(theta_td, y0.shape)
    if np.any(np.abs(theta_td) >= np.pi / 2):
        raise ValueError("theta_td must lie in (-pi/2, pi/2)")
    return y0, vy0, z0, theta_td


def _touchdown(y0, vy0, z0, theta_td, params):
    """Descent map f_d and the non-dimensional polar touchdown state."""
    P = params
    t_td = descent_time(z0, P.rho0 * np.cos(theta_td), P.d_v, P.g)
    y, z, vy, vz = flight_state(t_td, y0, z0, vy0, 0.0, P.d_h, P.d_v, P.g)
    s, co = np.sin(theta_td), np.cos(theta_td)
    rhod0 = (vy * s + vz * co) * P.lam / P.rho0
    p0 = (vy * co - vz * s) / P.rho0 * P.lam           # rho = 1 at touchdown
    y_toe = y - P.rho0 * s
    return Event(t_td, y, z, vy, vz), rhod0, p0, y_toe


def _cartesian(rho, theta, rhod, thetad, y_toe, params):
    """Polar (non-dimensional) stance state to body Cartesian state."""
    P = params
    s, co = np.sin(theta), np.cos(theta)
    v = P.rho0 / P.lam
    return (y_toe + P.rho0 * rho * s, P.rho0 * rho * co,
            v * (rhod * s + rho * thetad * co), v * (rhod * co - rho * thetad * s))


def _stride(apex, theta_td, params, method, rtol, liftoff_momentum="final"):
    _check_method(method)
    y0, vy0, z0, theta_td = _prepare(apex, theta_td, params)
    P = params
    scalar = y0.ndim == 0
    y0, vy0, z0, theta_td = (np.atleast_1d(v) for v in (y0, vy0, z0, theta_td))
    td, rhod0, p0, y_toe = _touchdown(y0, vy0, z0, theta_td, P)
    kappa = np.full(y0.shape, P.kappa)
    c = np.full(y0.shape, P.c)
    stance = _stance(method, rhod0, theta_td, p0, kappa, c, rtol, liftoff_momentum)

    def event_at(t_bar):
        y, z, vy, vz = _cartesian(*stance.state(t_bar), y_toe, P)
        return Event(td.t + P.lam * t_bar, y, z, vy, vz)

    bottom = event_at(np.nan_to_num(stance.t_b))
    lo = event_at(np.nan_to_num(stance.t_lo))
    vy_c, vz_c = liftoff_collision(lo.vy, lo.vz, P.m_b, P.m_l)     # (2.21)
    # the apex is the highest point of the next flight: the liftoff point
    # itself when the body leaves the ground without rising
    t_up = np.where(vz_c <= 0, 0.0, ascent_apex_time(vz_c, P.d_v, P.g))
    ya, za, vya, _ = flight_state(np.nan_to_num(t_up), lo.y, lo.z, vy_c, vz_c,
                                  P.d_h, P.d_v, P.g)
    apex_ev = Event(lo.t + t_up, ya, za, vya, np.zeros_like(ya))
    bad = ~(np.isfinite(stance.t_b) & np.isfinite(stance.t_lo) & np.isfinite(t_up))
    events = [Event(*[np.where(bad, np.nan, f) for f in ev])
              for ev in (td, bottom, lo, apex_ev)]
    if scalar:
        events = [Event(*[f[0] for f in ev]) for ev in events]
    return Stride(*events), (td, stance, y_toe, vy_c, vz_c)


def predict_stride(apex, theta_td, params, method="AAS", rtol=1e-10,
                   liftoff_momentum="final"):
    """Predict one stride of the extended SLIP, eq. (2.3).

    Parameters
    ----------
    apex : array_like, shape (3,) or (n, 3)
        Initial apex states ``[y, ydot, z]`` (2.1) (m, m/s, m).
    theta_td : float or array_like, shape (n,)
        Touchdown leg angle from vertical, rad (negative for forward motion).
    params : SLIPParams
        Model parameters; lossless methods ignore ``params.d``.
    method : {"SLIPD", "AAS", "SLIP", "Geyer"}
        Stance map, see the module description.
    rtol : float, optional
        Relative tolerance of the numerical stance integration.
    liftoff_momentum : {"final", "average"}, optional
        AAS only: angular momentum in the angular rate (2.14), see
        :func:`_stance_aas`.  ``"final"`` lifts off with the momentum the
        gravity torque has built up by liftoff; ``"average"`` keeps the
        stance average (2.20) up to liftoff.

    Returns
    -------
    Stride
        Touchdown, bottom, liftoff (pre-collision) and next-apex events;
        NaN for strides that do not complete (no touchdown or the leg never
        extends back).  A body that leaves the ground without rising has
        its apex, the highest point of the next flight, at liftoff.

    Examples
    --------
    >>> p = SLIPParams()
    >>> s = predict_stride([0.0, 1.0, 0.35], -0.2, p, method="AAS")
    >>> bool(0.2 < s.apex.z < 0.35 and s.apex.t > s.liftoff.t > s.bottom.t)
    True
    """
    return _stride(apex, theta_td, params, method, rtol, liftoff_momentum)[0]


def stride_trajectory(apex, theta_td, params, method, t, rtol=1e-10):
    """Body trajectory of a single predicted stride at the times `t`.

    Parameters
    ----------
    apex : array_like, shape (3,)
        Initial apex state ``[y, ydot, z]``.
    theta_td : float
        Touchdown angle, rad.
    params : SLIPParams
    method : {"SLIPD", "AAS", "SLIP", "Geyer"}
    t : array_like
        Times since the initial apex, s (clipped at the predicted next apex).

    Returns
    -------
    y, z, vy, vz : ndarray
        Body states; velocities jump at liftoff (2.21).

    Examples
    --------
    >>> p = SLIPParams()
    >>> y, z, vy, vz = stride_trajectory([0, 1.0, 0.35], -0.2, p, "Geyer", [0.0])
    >>> float(z[0])
    0.35
    """
    apex = np.asarray(apex, dtype=float)
    if apex.shape != (3,):
        raise ValueError(f"apex must have shape (3,), got {apex.shape}")
    stride, (td, stance, y_toe, vy_c, vz_c) = _stride(
        apex[None], np.atleast_1d(float(theta_td)), params, method, rtol)
    if not np.isfinite(stride.apex.t[0]):
        raise ValueError("the stride does not complete for this initial state")
    P = params
    t = np.clip(np.asarray(t, dtype=float), 0.0, stride.apex.t[0])
    y, z, vy, vz = flight_state(t, apex[0], apex[2], apex[1], 0.0, P.d_h, P.d_v, P.g)
    in_stance = (t >= td.t[0]) & (t < stride.liftoff.t[0])
    if np.any(in_stance):
        t_bar = ((t[in_stance] - td.t[0]) / P.lam)[None, :]
        ys, zs, vys, vzs = _cartesian(*stance.state(t_bar), y_toe[:, None], P)
        y[in_stance], z[in_stance], vy[in_stance], vz[in_stance] = ys[0], zs[0], vys[0], vzs[0]
    up = t >= stride.liftoff.t[0]
    lo = stride.liftoff
    ya, za, vya, vza = flight_state(t[up] - lo.t[0], lo.y[0], lo.z[0], vy_c[0], vz_c[0],
                                    P.d_h, P.d_v, P.g)
    y[up], z[up], vy[up], vz[up] = ya, za, vya, vza
    return y, z, vy, vz


def neutral_touchdown_angle(apex, params, method="AAS", bounds=(-0.6, 0.2)):
    """Neutral touchdown angle of eq. (2.35).

    ``theta_n = argmin_theta (ydot_n - ydot_{n+1}(theta))^2``, found per
    stride by a vectorised golden-section search over `bounds`.

    Parameters
    ----------
    apex : array_like, shape (3,) or (n, 3)
        Apex states ``[y, ydot, z]``.
    params : SLIPParams
    method : {"SLIPD", "AAS", "SLIP", "Geyer"}
    bounds : tuple of float
        Search interval, rad.

    Returns
    -------
    ndarray
        Neutral angles, rad.

    Examples
    --------
    >>> p = SLIPParams(m_l=0.0, d=0.0, d_h=0.0, d_v=0.0)
    >>> th = neutral_touchdown_angle([0.0, 1.0, 0.35], p, method="Geyer")
    >>> s = predict_stride([0.0, 1.0, 0.35], th, p, method="Geyer")
    >>> bool(abs(s.apex.vy - 1.0) < 1e-6)
    True
    """
    _check_method(method)
    apex = np.asarray(apex, dtype=float)
    lo, hi = (float(b) for b in bounds)
    if not -np.pi / 2 < lo < hi < np.pi / 2:
        raise ValueError(f"bounds must be increasing inside (-pi/2, pi/2), got {bounds}")
    shape = apex.shape[:-1]
    lo, hi = np.full(shape, lo), np.full(shape, hi)

    def cost(theta):
        vy_next = predict_stride(apex, theta, params, method).apex.vy
        return np.nan_to_num((apex[..., 1] - vy_next) ** 2, nan=np.inf)

    ratio = (np.sqrt(5) - 1) / 2
    a, b = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
    fa, fb = cost(a), cost(b)
    for _ in range(45):
        left = fa < fb
        hi, lo = np.where(left, b, hi), np.where(left, lo, a)
        a_new = np.where(left, hi - ratio * (hi - lo), b)
        b_new = np.where(left, a, lo + ratio * (hi - lo))
        a, b = a_new, b_new
        f_new = cost(np.where(left, a, b))
        fa, fb = np.where(left, f_new, fb), np.where(left, fa, f_new)
    return 0.5 * (lo + hi)
