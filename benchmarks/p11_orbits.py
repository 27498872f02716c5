"""P11: linear models about an orbit without analytic Jacobians.

Workload: the van der Pol oscillator ``ẍ − μ(1 − x²)ẋ + x = u`` (μ = 3,
quick mode μ = 1), its limit cycle from `ltp.limit_cycle` (central
differences, no analytic Jacobian) and the LTP model `ltp.linearize_orbit`.

* P11a ``floquet_multipliers`` of the model; P11b ``lqr`` (Q = I, R = 1);
  P11c one scalar evaluation ``K(t)`` of the LQR gain.
* ours: the model as `linearize_orbit` returns it (matrices sampled once
  along the orbit into verified Chebyshev interpolants).
* before: the same model with ``A(t), B(t)`` evaluated point by point
  (dense output of the orbit and central differences at every call), as
  `linearize_orbit` built it before the interpolants; measured in the same
  run, so that its ratio to the peer can be compared with ours.
* peer (P11a, P11b): one monodromy of the cycle by `scipy.integrate.
  solve_ivp` (DOP853, rtol 1e-10) of the variational equations with the
  analytic Jacobian in plain numpy — the cost unit of any computation
  along the orbit; (P11c) a gain tabulated by hand on 200 points and read
  with `numpy.interp` (linear interpolation, no accuracy guarantee).

Accuracy: the non-trivial multiplier against Liouville's formula
``exp ∮ μ(1 − x²) dt`` (independent integral along the orbit), 1e-6
relative; the gains of ours and before agree to 1e-6.  The one-shot
monodromy of the peer is accurate only in absolute terms (its error is
reported, no ratio is claimed as matched when it misses).
"""

import numpy as np
import control as ct
from scipy.integrate import solve_ivp

from _common import median_time, row

import ltpcontrol as ltp
from ltpcontrol._core.periodic_matrix import PeriodicMatrix
from ltpcontrol._orbits.orbits import _along_orbit, as_hybrid

TOL = 1e-6
FULL = dict(mu=3.0, repeats=3, evals=200)
QUICK = dict(mu=1.0, repeats=1, evals=20)


def vdp(t, x, u, p):
    return [x[1], p['mu'] * (1 - x[0] ** 2) * x[1] - x[0] + u[0]]


def setup(mu):
    sys = ct.nlsys(vdp, None, states=2, inputs=1, params={'mu': mu}, name='vdp')
    orbit = ltp.limit_cycle(sys, None, [2.0, 0.0], section=lambda x: x[1], direction=-1)
    return sys, orbit


def before_model(sys, orbit):
    """The model with A, B evaluated point by point along the orbit."""
    hp, T = as_hybrid(sys, None), orbit.period
    u0, params = orbit.u0, orbit.params
    A = _along_orbit(orbit, lambda i, t, x: hp.state_jacobian(t, x, u0, params, mode=i))
    B = _along_orbit(orbit, lambda i, t, x: hp.input_jacobian(t, x, u0, params, mode=i))
    return ltp.ltpss(PeriodicMatrix.from_function(A, T), PeriodicMatrix.from_function(B, T),
                     np.eye(2), np.zeros((2, 1)), T)


def liouville(mu, orbit):
    def rhs(t, z):
        return [z[1], mu * (1 - z[0] ** 2) * z[1] - z[0], mu * (1 - z[0] ** 2)]
    sol = solve_ivp(rhs, (0, orbit.period), [*orbit.x0, 0.0], method='DOP853', rtol=1e-13,
                    atol=1e-14)
    return sol.y[2, -1]


def peer_monodromy(mu, orbit):
    def rhs(t, z):
        x, v = z[0], z[1]
        J = np.array([[0.0, 1.0], [-2 * mu * x * v - 1, mu * (1 - x * x)]])
        return np.concatenate([[v, mu * (1 - x * x) * v - x], (J @ z[2:].reshape(2, 2)).ravel()])
    sol = solve_ivp(rhs, (0, orbit.period), np.concatenate([orbit.x0, np.eye(2).ravel()]),
                    method='DOP853', rtol=1e-10, atol=1e-12)
    return np.linalg.eigvals(sol.y[2:, -1].reshape(2, 2))


def small_multiplier_error(mult, ref):
    """Relative error of the smaller multiplier against exp(ref)."""
    m = np.sort(np.abs(np.asarray(mult, complex)))[0]
    return float(abs(np.log(m) - ref)) if m > 0 else np.inf


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    mu = cfg['mu']
    log(f"P11: van der Pol mu={mu}: multipliers, LQR, gain evaluation")
    sys, orbit = setup(mu)
    ref = liouville(mu, orbit)
    t_peer, ptimes, pmult = median_time(lambda: peer_monodromy(mu, orbit), cfg['repeats'])
    err_peer = small_multiplier_error(pmult, ref)
    rows = []
    results = {}
    for label, build in (('ours', lambda: ltp.linearize_orbit(sys, orbit)),
                         ('before', lambda: before_model(sys, orbit))):
        t_fm, _, mult = median_time(lambda: ltp.floquet_multipliers(build()), cfg['repeats'])
        t_lqr, _, (K, _, _) = median_time(lambda: ltp.lqr(build(), np.eye(2), [[1.0]]),
                                          cfg['repeats'])
        ts = np.linspace(0, orbit.period, cfg['evals'], endpoint=False) + 0.0123
        K(ts[0])                                        # interpolants built once
        t_k, _, Kvals = median_time(lambda: [K(t) for t in ts], cfg['repeats'])
        results[label] = dict(t_fm=t_fm, t_lqr=t_lqr, t_k=t_k / len(ts), mult=mult,
                              K=np.array(Kvals))
    gain_gap = float(np.max(np.abs(results['ours']['K'] - results['before']['K'])))
    # peer of P11c: the gain tabulated by hand, one entry read by numpy.interp
    grid = np.linspace(0, orbit.period, 200)
    table = np.array([results['ours']['K'][0][0, 0]] * len(grid))
    probes = np.linspace(0, orbit.period, cfg['evals'], endpoint=False) + 0.0123
    t_interp, _, _ = median_time(lambda: [np.interp(t, grid, table) for t in probes],
                                 cfg['repeats'])
    t_interp /= cfg['evals']
    for label in ('ours', 'before'):
        r = results[label]
        err = small_multiplier_error(r['mult'], ref)
        rows.append(row(
            f"P11a-{label}", f'Floquet multipliers of the van der Pol cycle (mu={mu:g})',
            ours=f'floquet_multipliers(linearize_orbit(...)) [{label}]',
            peer='solve_ivp DOP853 one-shot monodromy, analytic Jacobian',
            t_ours=r['t_fm'], t_peer=t_peer, err_ours=err, err_peer=err_peer, tol=TOL,
            checks={'ours <= tol': err <= TOL}, matched=err_peer <= TOL,
            notes='before = A(t) by central differences at every call' if label == 'before'
            else 'A(t) sampled once into verified Chebyshev interpolants',
            extra=dict(peer_times=ptimes)))
        rows.append(row(
            f"P11b-{label}", f'lqr on the van der Pol linearisation (mu={mu:g})',
            ours=f'lqr(linearize_orbit(...)) [{label}]',
            peer='solve_ivp DOP853 one-shot monodromy (cost unit)',
            t_ours=r['t_lqr'], t_peer=t_peer, err_ours=gain_gap, err_peer=0.0, tol=TOL,
            checks={'gains agree': gain_gap <= TOL}, matched=True,
            notes='peer: cost unit only; accuracy: gap between the gains of ours and before'
            if label == 'ours' else ''))
        rows.append(row(
            f"P11c-{label}", 'one scalar evaluation K(t) of the LQR gain',
            ours=f'K(t) [{label}]', peer='numpy.interp on a 200-point table (one entry)',
            t_ours=r['t_k'], t_peer=t_interp, err_ours=gain_gap, err_peer=0.0, tol=TOL,
            checks={'gains agree': gain_gap <= TOL}, matched=True))
    return rows
