"""Synthetic monopod experiments for the extended SLIP (thesis Section 2.3).

A stand-in for the planarized monopod of thesis Chapter 2: single strides of
the extended SLIP are simulated in Cartesian coordinates (independently of
the polar stance maps in :mod:`slip_model`), then "measured" the way the
robot measures them and processed the way the thesis processes them:

* perturbations the predictors do not model: a boom bending mode excited by
  the touchdown and liftoff impacts, small stride-to-stride variation of
  the leg stiffness, damping and of the true touchdown angle;
* boom encoders with 0.21 mm resolution sampled at 500 Hz;
* zero-phase 5th-order Butterworth low-pass at 50 Hz, numerical
  differentiation, and extraction of the apex, touchdown, bottom, liftoff
  and next-apex transitions (Section 2.3.2).

The monopod constants are those identified in the thesis: Table 2.3 masses
(``m_b + m_l = 3.4`` kg), ``d_h`` of Section 2.4.2, a 22 cm leg, the boom
gravity (2.24), and the four springs of Table 2.5 (vertical experiments).
"""

from dataclasses import dataclass, replace
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from scipy.integrate import solve_ivp
from scipy.signal import butter, sosfiltfilt

try:                    # imported as the package ``examples`` (tests)
    from .slip_model import Event, SLIPParams, boom_gravity, neutral_touchdown_angle
except ImportError:     # run from this folder (gallery scripts)
    from slip_model import Event, SLIPParams, boom_gravity, neutral_touchdown_angle

__all__ = ["MONOPOD", "SPRINGS", "Perturbations", "spring_params",
           "simulate_stride", "record_stride", "process_record",
           "Record", "Transitions", "StrideSet", "generate_strides", "IDEAL",
           "CLEAN"]

#: Monopod constants (Table 2.3, Section 2.4.2, eq. 2.24).
MONOPOD = SLIPParams(m_b=3.21, m_l=0.19, d_h=0.3, d_v=0.06, rho0=0.22,
                     g=boom_gravity(3.4, 0.39))

#: Leg springs: (k in N/m, d in N s/m) from the vertical experiments, Table 2.5.
SPRINGS = {"softer": (2600.0, 6.7), "soft": (3536.0, 9.9),
           "medium": (4972.0, 12.4), "hard": (6630.0, 12.7)}


def spring_params(spring):
    """Monopod parameters with one of the four leg springs.

    Examples
    --------
    >>> spring_params("hard").k
    6630.0
    """
    if spring not in SPRINGS:
        raise ValueError(f"spring must be one of {tuple(SPRINGS)}, got {spring!r}")
    k, d = SPRINGS[spring]
    return MONOPOD.replace(k=k, d=d)


@dataclass(frozen=True)
class Perturbations:
    """Measurement and modelling imperfections of the synthetic robot.

    Parameters
    ----------
    fs : float
        Sampling rate, Hz.
    resolution : float
        Encoder resolution of the body position, m.
    boom_frequency, boom_damping : float
        Frequency (Hz) and damping ratio of the boom bending mode.
    boom_gain : float
        Fraction of an impact's velocity jump passed to the boom mode.
    stiffness_jitter, damping_jitter : float
        Relative standard deviation of the per-stride leg stiffness and
        damping around their nominal values.
    angle_jitter : float
        Standard deviation (rad) of the true touchdown angle around the
        measured one.
    """

    fs: float = 500.0
    resolution: float = 0.21e-3
    boom_frequency: float = 25.0
    boom_damping: float = 0.1
    boom_gain: float = 0.5
    stiffness_jitter: float = 0.01
    damping_jitter: float = 0.05
    angle_jitter: float = np.deg2rad(0.3)

    def __post_init__(self):
        if self.fs <= 0 or self.boom_frequency <= 0:
            raise ValueError("Perturbations: fs and boom_frequency must be positive")
        for name in ("resolution", "boom_damping", "boom_gain", "stiffness_jitter",
                     "damping_jitter", "angle_jitter"):
            if getattr(self, name) < 0:
                raise ValueError(f"Perturbations: {name} must be >= 0")


#: Ideal measurements: exact samples, no unmodelled effects.
IDEAL = Perturbations(resolution=0.0, boom_gain=0.0, stiffness_jitter=0.0,
                      damping_jitter=0.0, angle_jitter=0.0)

#: Measurement only: encoder quantisation, 500 Hz sampling, filtering and
#: differentiation, with a robot that is exactly the extended SLIP (no boom
#: mode, constant leg parameters, touchdown angle as measured).  The fair
#: setting for judging identification accuracy against known parameters.
CLEAN = Perturbations(boom_gain=0.0, stiffness_jitter=0.0, damping_jitter=0.0,
                      angle_jitter=0.0)


def simulate_stride(apex, theta_td, params, rtol=1e-11, atol=1e-12):
    """Cartesian hybrid simulation of one extended-SLIP stride.

    Flight obeys (2.4); stance is the body on a damped spring leg pinned at
    the toe, ``m_b a = (k (rho0 - r) - d rdot) e_r - m_b g e_z``; liftoff
    when the leg force reaches zero, followed by the collision (2.21).

    Parameters
    ----------
    apex : array_like, shape (3,)
        Apex state ``[y, ydot, z]`` at time 0.
    theta_td : float
        True touchdown angle, rad.
    params : SLIPParams

    Returns
    -------
    trajectory : callable
        ``trajectory(t)`` gives ``y, z, vy, vz`` (shape (4, len(t))) at
        times `t`, which may start before 0 and end after the next apex.
    events : dict
        ``touchdown, bottom, liftoff, apex`` as :class:`slip_model.Event`.
        Both are ``None`` if the stride does not complete.

    Examples
    --------
    >>> traj, ev = simulate_stride([0.0, 1.0, 0.35], -0.1, spring_params("hard"))
    >>> bool(ev["touchdown"].t < ev["bottom"].t < ev["liftoff"].t < ev["apex"].t)
    True
    """
    P = params
    y0, vy0, z0 = (float(v) for v in apex)
    opts = dict(method="DOP853", rtol=rtol, atol=atol, dense_output=True)

    def flight(_, x):                                   # (2.4)
        return [x[2], x[3], -P.d_h * x[2], -P.g - P.d_v * x[3]]

    def touchdown(_, x):
        return x[1] - P.rho0 * np.cos(theta_td)
    touchdown.terminal, touchdown.direction = True, -1
    descent = solve_ivp(flight, (0.0, 5.0), [y0, z0, vy0, 0.0], events=touchdown, **opts)
    if not descent.t_events[0].size:
        return None, None
    t_td, x_td = descent.t_events[0][0], descent.y_events[0][0]
    y_toe = x_td[0] - P.rho0 * np.sin(theta_td)

    def leg(x):
        dy = x[0] - y_toe
        r = np.hypot(dy, x[1])
        rdot = (dy * x[2] + x[1] * x[3]) / r
        return dy, r, rdot, P.k * (P.rho0 - r) - P.d * rdot

    def stance(_, x):
        dy, r, _, force = leg(x)
        return [x[2], x[3], force * dy / (P.m_b * r), force * x[1] / (P.m_b * r) - P.g]

    def liftoff(_, x):
        return leg(x)[3]
    liftoff.terminal, liftoff.direction = True, -1

    def bottom(_, x):
        return leg(x)[2]
    bottom.direction = 1
    if liftoff(0, x_td) <= 0:
        return None, None
    support = solve_ivp(stance, (t_td, t_td + 2.0), x_td, events=[liftoff, bottom], **opts)
    if not (support.t_events[0].size and support.t_events[1].size):
        return None, None
    t_lo, x_lo = support.t_events[0][0], support.y_events[0][0]
    t_b, x_b = support.t_events[1][0], support.y_events[1][0]
    ratio = P.m_b / (P.m_b + P.m_l)                     # (2.21)
    x_up = np.r_[x_lo[:2], ratio * x_lo[2:]]
    if x_up[3] <= 0:
        return None, None

    def apex_event(_, x):
        return x[3]
    apex_event.direction = -1
    ascent = solve_ivp(flight, (t_lo, t_lo + 2 * x_up[3] / P.g + 0.2), x_up,
                       events=apex_event, **opts)
    t_a, x_a = ascent.t_events[0][0], ascent.y_events[0][0]
    back = solve_ivp(flight, (0.0, -0.2), [y0, z0, vy0, 0.0], **opts)

    def trajectory(t):
        t = np.asarray(t, dtype=float)
        if t.min() < -0.2 or t.max() > ascent.t[-1]:
            raise ValueError("t must lie within 0.2 s before the apex and "
                             "0.2 s after the next apex")
        states = np.empty((4, t.size))
        for sol, mask in ((back.sol, t < 0), (descent.sol, (t >= 0) & (t < t_td)),
                          (support.sol, (t >= t_td) & (t < t_lo)),
                          (ascent.sol, t >= t_lo)):
            if np.any(mask):
                states[:, mask] = sol(t[mask])
        return states

    events = {"touchdown": Event(t_td, *x_td[[0, 1, 2, 3]]),
              "bottom": Event(t_b, *x_b), "liftoff": Event(t_lo, *x_lo),
              "apex": Event(t_a, *x_a)}
    return trajectory, events


class Record(NamedTuple):
    """One measured stride: sample times, quantised body position, leg angle."""

    t: np.ndarray
    y: np.ndarray
    z: np.ndarray
    theta_td: float


def record_stride(apex, theta_td, params, rng, perturbations=Perturbations()):
    """Simulate and measure one stride of the synthetic monopod.

    Parameters
    ----------
    apex : array_like, shape (3,)
        Apex state ``[y, ydot, z]`` the robot is thrown to.
    theta_td : float
        Touchdown angle held by the hip motor (the measured angle), rad.
    params : SLIPParams
        Nominal robot parameters.
    rng : numpy.random.Generator
    perturbations : Perturbations

    Returns
    -------
    Record or None
        ``None`` when the stride fails (no liftoff or no second apex).
    """
    Q = perturbations
    true = params.replace(
        k=params.k * (1 + Q.stiffness_jitter * rng.standard_normal()),
        d=max(params.d * (1 + Q.damping_jitter * rng.standard_normal()), 0.0))
    theta_true = theta_td + Q.angle_jitter * rng.standard_normal()
    trajectory, events = simulate_stride(apex, theta_true, true)
    if events is None:
        return None
    t = np.arange(-0.06, events["apex"].t + 0.06, 1 / Q.fs) + rng.uniform(0, 1 / Q.fs)
    y, z, _, _ = trajectory(t)
    # boom bending mode rung by the touchdown and liftoff impacts:
    # x_boom = sum_i a_i e^{-zeta w (t - t_i)} sin(w_d (t - t_i))
    w = 2 * np.pi * Q.boom_frequency
    wd = w * np.sqrt(1 - Q.boom_damping ** 2)
    lo = events["liftoff"]
    jump = np.hypot(lo.vy, lo.vz) * params.m_l / (params.m_b + params.m_l)
    impacts = ((events["touchdown"].t, 0.3 * abs(events["touchdown"].vz) * params.m_l
                / (params.m_b + params.m_l)), (lo.t, jump))
    for t_i, dv in impacts:
        s = np.clip(t - t_i, 0, None)
        ring = Q.boom_gain * dv / wd * np.exp(-Q.boom_damping * w * s) * np.sin(wd * s)
        z = z + ring
        y = y + 0.3 * ring
    if Q.resolution > 0:   # incremental encoders: quantised with a random offset
        offset = rng.uniform(0, Q.resolution, 2)
        y = Q.resolution * np.round((y + offset[0]) / Q.resolution) - offset[0]
        z = Q.resolution * np.round((z + offset[1]) / Q.resolution) - offset[1]
    return Record(t, y, z, float(theta_td))


class Transitions(NamedTuple):
    """Processed stride: filtered states and the extracted transitions.

    Times and horizontal positions are relative to the first apex.
    """

    t: np.ndarray
    y: np.ndarray
    z: np.ndarray
    vy: np.ndarray
    vz: np.ndarray
    apex0: Event
    touchdown: Event
    bottom: Event
    liftoff: Event
    apex1: Event
    theta_td: float


def _crossing(values, start, rising):
    """Fractional index of the first sign change of `values` after `start`."""
    v = values[start:]
    hit = (v[:-1] < 0) & (v[1:] >= 0) if rising else (v[:-1] > 0) & (v[1:] <= 0)
    if not hit.any():
        raise ValueError("transition not found in the record")
    i = int(np.argmax(hit))
    return start + i + v[i] / (v[i] - v[i + 1])


@lru_cache(maxsize=16)
def _butterworth(order, cutoff, fs):
    """Second-order sections of the Butterworth low-pass, designed once per
    ``(order, cutoff, fs)`` (the records share a handful of sampling rates)."""
    return butter(order, cutoff, fs=fs, output="sos")


def process_record(record, rho0, cutoff=50.0, order=5):
    """Filter, differentiate and extract transitions (Section 2.3.2).

    Parameters
    ----------
    record : Record
    rho0 : float
        Leg rest length, m.
    cutoff : float
        Butterworth cutoff, Hz.
    order : int
        Butterworth order (applied forward and backward: zero phase).

    Returns
    -------
    Transitions
        Touchdown when the body reaches ``rho0 cos(theta_td)``; bottom at the
        minimum of the leg length measured from the touchdown toe position;
        liftoff when that length is back at ``rho0``; apexes where the
        vertical velocity changes sign from + to -.

    Raises
    ------
    ValueError
        If a transition is missing from the record.
    """
    t = record.t
    fs = 1 / np.mean(np.diff(t))
    sos = _butterworth(order, cutoff, fs).copy()
    y, z = sosfiltfilt(sos, record.y), sosfiltfilt(sos, record.z)
    vy, vz = np.gradient(y, t), np.gradient(z, t)
    idx = np.arange(t.size)

    def at(frac):
        vals = [np.interp(frac, idx, s) for s in (t, y, z, vy, vz)]
        return Event(*vals)

    theta = record.theta_td
    a0 = at(_crossing(vz, 0, rising=False))
    i_td = _crossing(rho0 * np.cos(theta) - z, int(np.ceil(np.interp(a0.t, t, idx))),
                     rising=True)
    td = at(i_td)
    y_toe = td.y - rho0 * np.sin(theta)
    leg = np.hypot(y - y_toe, z)
    i_b = _crossing(np.gradient(leg, t), int(np.ceil(i_td)), rising=True)
    i_lo = _crossing(leg - rho0, int(np.ceil(i_b)), rising=True)
    i_a1 = _crossing(vz, int(np.ceil(i_lo)), rising=False)

    def shift(ev):
        return ev._replace(t=ev.t - a0.t, y=ev.y - a0.y)

    return Transitions(t - a0.t, y - a0.y, z, vy, vz, shift(a0), shift(td),
                       shift(at(i_b)), shift(at(i_lo)), shift(at(i_a1)), theta)


class StrideSet(NamedTuple):
    """Processed experiments of one spring, stacked for identification."""

    spring: str
    theta_td: np.ndarray        # measured touchdown angles, rad
    apex0: np.ndarray           # (n, 3) first apex [0, ydot, z] from the data
    apex1: np.ndarray           # (n, 4) next apex [t, y, z, ydot]
    bottom: np.ndarray          # (n, 3) bottom [t, y, z]
    strides: list               # Transitions, one per experiment


def generate_strides(spring, n, rng, vertical=False, perturbations=Perturbations(),
                     speed=(0.3, 2.5), height=(0.24, 0.48), angle_spread=0.12,
                     min_speed=0.3):
    """Run `n` valid synthetic experiments with one spring.

    Running experiments draw the apex speed and height uniformly from the
    thesis's ranges (Section 2.5) and a touchdown angle uniformly within
    `angle_spread` of the neutral angle (2.35) of the nominal model;
    vertical experiments use zero speed and angle, with the leg held
    exactly vertical (no angle jitter; Section 2.4.1).  Strides
    that fail, whose transitions cannot be extracted, or (running) whose
    next apex is slower than `min_speed` are discarded, as problematic
    experiments were.

    Returns
    -------
    StrideSet
    """
    params = spring_params(spring)
    if vertical:
        perturbations = replace(perturbations, angle_jitter=0.0)
    strides = []
    for _ in range(10):
        m = 2 * (n - len(strides)) + 5          # a batch of candidate throws
        z0 = rng.uniform(*height, m)
        vy0 = np.zeros(m) if vertical else rng.uniform(*speed, m)
        apex = np.column_stack([np.zeros(m), vy0, z0])
        theta = np.zeros(m) if vertical else (
            neutral_touchdown_angle(apex, params)
            + rng.uniform(-angle_spread, angle_spread, m))
        for a, th in zip(apex, theta):
            record = record_stride(a, float(th), params, rng, perturbations)
            if record is None:
                continue
            try:
                stride = process_record(record, params.rho0)
            except ValueError:
                continue
            if vertical or stride.apex1.vy >= min_speed:
                strides.append(stride)
            if len(strides) == n:
                break
        if len(strides) == n:
            break
    else:
        raise RuntimeError("too many failed strides; check the ranges")
    a0 = [s.apex0 for s in strides]
    return StrideSet(
        spring, np.array([s.theta_td for s in strides]),
        np.array([[0.0, e.vy, e.z] for e in a0]),
        np.array([[s.apex1.t, s.apex1.y, s.apex1.z, s.apex1.vy] for s in strides]),
        np.array([[s.bottom.t, s.bottom.y, s.bottom.z] for s in strides]),
        strides)
