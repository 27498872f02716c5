"""P5: Floquet exponents of a stiff periodic system.

Workload: ``A(t) = [[0, 1], [-10 cos t, -24 - 10 sin t]]``, T = 2π, whose
exponents are exactly {0, -24} (multipliers 1 and e^{-48π} = 1.6e-66).

* ours: ``ltp.floquet_exponents`` (periodic Schur form of the step
  transition matrices: the product, which underflows the small multiplier,
  is never formed).  A is given by its exact Fourier coefficients (row P5a);
  row P5c gives the same call with A(t) as the scalar Python callable of the
  docstring, which the library must call point by point.
* peer: the monodromy integrated in one shot with `scipy.integrate.
  solve_ivp` (the 2 x 2 matrix ODE ``Φ' = A(t) Φ``, ``Φ(0) = I``, plain
  numpy right-hand side), then ``log(eig Φ(T))/T``: RK45 (rtol 1e-9,
  atol 1e-12) and the stiff solver Radau (same tolerances).

Accuracy: largest error of the exponents against {0, -24}.  The product
Φ(T) holds the multiplier 1.6e-66 next to 1, far below the rounding of its
entries, so the one-shot monodromy cannot resolve the exponent -24 at any
tolerance; its error is reported ('lost' when the computed multiplier is
zero or negative) and no ratio is claimed as matched.  Ours must reach 1e-8.
"""

import math

import numpy as np
from scipy.integrate import solve_ivp

from _common import median_time, row

import ltpcontrol as ltp

TOL = 1e-8
EXACT = np.array([0.0, -24.0])
T = 2 * np.pi
FULL = dict(repeats=5)
QUICK = dict(repeats=2)


def system_fourier():
    A0 = np.array([[0.0, 1.0], [0.0, -24.0]])
    A1 = np.array([[0.0, 0.0], [-5.0, 5.0j]])      # -10 cos t, -10 sin t
    A = ltp.PeriodicMatrix([A1.conj(), A0, A1], T)
    return ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T, name='stiff')


def system_callable():
    A = lambda t: np.array([[0.0, 1.0], [-10 * np.cos(t), -24 - 10 * np.sin(t)]])  # noqa: E731
    return ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T, name='stiff')


def exponent_error(lam):
    lam = np.asarray(lam, complex)
    if not np.all(np.isfinite(lam)):
        return np.inf
    got = np.sort(lam.real)[::-1]
    return float(np.max(np.abs(got - EXACT)) + np.max(np.abs(lam.imag)))


def peer(method, rtol=1e-9, atol=1e-12):
    def rhs(t, y):
        c, s = math.cos(t), math.sin(t)
        return np.array([y[2], y[3], -10 * c * y[0] - (24 + 10 * s) * y[2],
                         -10 * c * y[1] - (24 + 10 * s) * y[3]])

    sol = solve_ivp(rhs, (0.0, T), np.eye(2).ravel(), method=method, rtol=rtol, atol=atol)
    mu = np.linalg.eigvals(sol.y[:, -1].reshape(2, 2))
    with np.errstate(divide='ignore', invalid='ignore'):
        lam = np.where(mu.real > 0, np.log(np.abs(mu)) / T, np.nan)
    return lam


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    log("P5: stiff Floquet exponents")
    t_ours, times, lam = median_time(ltp.floquet_exponents, cfg['repeats'],
                                     setup=system_fourier)
    err_ours = exponent_error(lam)
    t_call, times_call, lam_call = median_time(ltp.floquet_exponents, cfg['repeats'],
                                               setup=system_callable)
    err_call = exponent_error(lam_call)
    rows = []
    for rid, method in (('P5a', 'RK45'), ('P5b', 'Radau')):
        t_peer, ptimes, plam = median_time(lambda: peer(method), cfg['repeats'])
        err_peer = exponent_error(plam)
        rows.append(row(
            rid, 'Floquet exponents of the stiff system (exact 0, -24)',
            ours='ltp.floquet_exponents (A as Fourier series)',
            peer=f'solve_ivp {method} rtol 1e-9 one-shot monodromy, log(eig)/T',
            t_ours=t_ours, t_peer=t_peer, err_ours=err_ours, err_peer=err_peer, tol=TOL,
            checks={'ours <= tol': err_ours <= TOL}, matched=err_peer <= TOL,
            notes='the one-shot monodromy loses the multiplier 1.6e-66',
            extra=dict(ours_times=times, peer_times=ptimes,
                       ours_exponents=[str(x) for x in lam],
                       peer_exponents=[str(x) for x in plam])))
    rows.append(row(
        'P5c', 'Floquet exponents of the stiff system (exact 0, -24)',
        ours='ltp.floquet_exponents (A as scalar callable)',
        peer=rows[0]['peer'], t_ours=t_call, t_peer=rows[0]['t_peer'],
        err_ours=err_call, err_peer=rows[0]['err_peer'], tol=TOL,
        checks={'ours <= tol': err_call <= TOL}, matched=rows[0]['matched'],
        notes='A(t) evaluated point by point through the user callable',
        extra=dict(ours_times=times_call)))
    return rows
