"""P8: system norms of a continuous-time LTP system.

Workloads, both on damped Mathieu-type plants (thesis eq. 4.24, T = 0.5 s):

* P8a, L∞ to 1e-6 (ω_n = 0.74π, ζ = 0.05, β = 0.3: a sharp resonance
  peak inside [0, ω_p/2]).  Ours: ``ltp.norm(sys, 'inf', tol=1e-6)`` (HTF
  estimate certified by the unit-circle Floquet multipliers of the periodic
  Hamiltonian).  Peer: what a user does without it, the sup of σ_max of
  ``ltp.htf(sys, K)`` on a uniform grid of ω ∈ [0, ω_p/2], refined (grid
  doubled from 1000 points, then K doubled) until two successive values
  agree to 1e-7; the peer time is the whole refinement.  Reference:
  ``ltp.norm(sys, 'inf', tol=1e-12)``, checked against the finest grid value.
* P8b, H2 (constant A, input matrix switching between [0; 1] and [0; 0.2] at
  T/2).  Ours: ``ltp.norm(sys, 2)`` (periodic Lyapunov equation).  Peer:
  quadrature of ``(1/π) ∫_0^∞ Σ_k ‖G_k(jω)‖_F² dω`` over the HTF components
  (``ω = ω_n tan θ``, 800 midpoints in θ, converged to 1e-6 in ω), with K
  doubled from 8 until the error is <= 1e-3.  The switching input makes
  ``‖G_k‖ ~ 1/k``, so the truncated sum converges only like O(1/K): the
  log-log slope of the peer error against K is reported (about -1).
  Reference: ours, checked against the Lyapunov value with the
  controllability gramian (``(1/T)∫ tr(C P Cᵀ)`` by Gauss quadrature).
"""

import warnings

import numpy as np

from _common import loglog_slope, median_time, row, timed

import ltpcontrol as ltp
from systems import damped_mathieu

TOL_INF = 1e-6
TOL_H2 = 1e-3
FULL = dict(repeats=3, ks=(8, 16, 32, 64, 128), max_points=256000)
QUICK = dict(repeats=1, ks=(8, 16), max_points=8000)


def linf_plant():
    return damped_mathieu(wn=2 * np.pi * 0.37, zeta=0.05, beta=0.3)


def h2_plant():
    T, wn, zeta = 0.5, 2 * np.pi, 0.3
    B = ltp.PeriodicMatrix.switching([[[0.0], [1.0]], [[0.0], [0.2]]], [0, T / 2], T)
    return ltp.ltpss([[0, 1], [-wn ** 2, -2 * zeta * wn]], B, [[1.0, 0.0]], 0, period=T)


def grid_sup(sys, K, npoints, chunk=20000):
    """Largest σ_max of the K-harmonic HTF on a uniform grid of [0, ω_p/2].

    Evaluated in chunks of the grid: only the maximum is kept, so the whole
    response (over 1 GB at the finest grids) is never held at once.
    """
    H = ltp.htf(sys, K)
    w = np.linspace(0, sys.omega_p / 2, npoints)
    return max(float(np.linalg.norm(H(1j * w[i:i + chunk]), ord=2, axis=(0, 1)).max())
               for i in range(0, npoints, chunk))


def peer_linf(sys, agree=1e-7, max_points=256000):
    """Grid sup refined in ω, then in K, until two successive values agree."""
    K, M = 2, 1000
    prev = grid_sup(sys, K, M)
    while M < max_points:
        M *= 2
        val = grid_sup(sys, K, M)
        done = abs(val - prev) <= agree * val
        prev = val
        if done:
            break
    while True:
        K *= 2
        val = grid_sup(sys, K, M)
        done = abs(val - prev) <= agree * val
        prev = val
        if done:
            return val, (K, M)


def peer_h2(sys, K):
    theta = (np.arange(800) + 0.5) * (np.pi / 2) / 800
    wn = 2 * np.pi
    w = wn * np.tan(theta)
    _, G = ltp.htf(sys, K).components(w)
    integrand = np.sum(np.abs(G) ** 2, axis=(0, 1, 2)) * wn / np.cos(theta) ** 2
    return float(np.sqrt(np.sum(integrand) * (np.pi / 2 / 800) / np.pi))


def h2_by_controllability(sys):
    # Gauss-Legendre on each half period (P(t) has a kink at the switch)
    P = ltp.gram(sys, 'c')
    x, wts = np.polynomial.legendre.leggauss(40)
    T = sys.period
    C = sys.C(0.0)
    ts = np.concatenate([T / 4 * (x + 1), T / 2 + T / 4 * (x + 1)])
    vals = np.einsum('ij,tjk,lk->t', C, P(ts), C)
    return float(np.sqrt(np.sum(np.tile(wts, 2) * vals) / 4))


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        log("P8a: L-infinity norm, certified vs HTF grid sup")
        sys = linf_plant()
        ref = ltp.norm(sys, 'inf', tol=1e-12)
        t_ours, times, val = median_time(lambda: ltp.norm(sys, 'inf', tol=TOL_INF),
                                         cfg['repeats'])
        t_peer, (pval, (K, M)) = timed(peer_linf, sys, max_points=cfg['max_points'])
        fine = grid_sup(sys, 8, 256000) if not quick else pval
        err_ours, err_peer = abs(val - ref) / ref, abs(pval - ref) / ref
        rows.append(row(
            'P8a', 'L-inf norm of a damped Mathieu plant to 1e-6',
            ours='ltp.norm(sys, "inf", tol=1e-6)',
            peer='sup sigma_max of ltp.htf on a uniform grid, refined to agreement',
            t_ours=t_ours, t_peer=t_peer, err_ours=err_ours, err_peer=err_peer,
            tol=TOL_INF, target='>= 10x', target_met=t_peer / t_ours >= 10,
            checks={'ours <= tol': err_ours <= TOL_INF,
                    'reference = finest grid (1e-8)': quick or abs(fine - ref) <= 1e-8 * ref},
            matched=err_peer <= TOL_INF,
            notes=f'peer stopped at K={K}, {M} frequencies',
            extra=dict(ours_times=times, reference=ref, finest_grid=fine)))

        log("P8b: H2 norm, periodic Lyapunov vs HTF quadrature")
        sys = h2_plant()
        t_ours, times, h2 = median_time(lambda: ltp.norm(sys, 2), cfg['repeats'])
        check = h2_by_controllability(sys)
        errs, ks, t_peer, k_hit, err_hit = [], [], None, None, None
        for K in cfg['ks']:
            t, v = timed(peer_h2, sys, K)
            e = abs(v - h2) / h2
            errs.append(e)
            ks.append(K)
            if e <= TOL_H2 and t_peer is None:
                t_peer, k_hit, err_hit = t, K, e
        slope = loglog_slope(ks, errs)
        if t_peer is None:
            t_peer, err_hit = t, errs[-1]
        rows.append(row(
            'P8b', 'H2 norm of a switching-input plant to 1e-3',
            ours='ltp.norm(sys, 2) (periodic Lyapunov)',
            peer='HTF quadrature (1/pi) int sum_k |G_k(jw)|^2, K doubled',
            t_ours=t_ours, t_peer=t_peer, err_ours=abs(check - h2) / h2, err_peer=err_hit,
            tol=TOL_H2, target='>= 100x', target_met=t_peer / t_ours >= 100,
            checks={'ours = controllability form (1e-9)': abs(check - h2) <= 1e-9 * h2,
                    'peer error ~ O(1/K)': quick or -1.3 <= slope <= -0.7},
            matched=err_hit <= TOL_H2,
            notes=(f'peer reached {TOL_H2:.0e} at K={k_hit}; error vs K slope {slope:.2f}; '
                   f'K={ks[-1]}: error {errs[-1]:.1e} in {t:.2f} s'),
            extra=dict(ours_times=times, ks=ks, peer_errors=errs, slope=slope)))
    return rows
