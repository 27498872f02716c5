"""P2: evaluation of a harmonic transfer function on a frequency grid.

Workload: a seeded random 4-state SISO system in Floquet form (constant A,
B(t) and C(t) with one harmonic), its HTF truncated to K = 10 harmonics
(21 x 21 blocks), evaluated at 2000 points ``s = jω``.  The library builds the
harmonic state space with ``K_i = K + 2`` internal harmonics (exact for this
band-limited system), i.e. 100 harmonic states.

* ours: ``ltp.htf(sys, 10)`` (method 'auto', which takes the Floquet fast
  path: one eigendecomposition of the 4 x 4 A) and ``H(1j * omega)``;
* ``method='solve'``: the same HTF by a dense solve of the 100 x 100
  harmonic resolvent at every point;
* python-control: the same harmonic state space as a `control.StateSpace`
  evaluated by `control.frequency_response`.  `control.StateSpace` does not
  take complex matrices, so the harmonic state space ``(A_T - N, B_T, C_T,
  D_T)`` is written in the real coordinates ``V^H (.) V`` that pair harmonic
  n with -n (``c_n = (e_n + e_-n)/√2``, ``s_n = j(e_n - e_-n)/√2``), the
  real form `ltp.lift` uses in discrete time.  This is an exact similarity
  of the same model, so its answer is the same HTF (``H = V_y H_real
  V_u^H``) and the accuracies can be compared point by point.  Lifting a
  sampled version with `ltp.lift` would give a discrete-time HTF, a
  different function, so it could not be checked against the same
  reference.

The building of the model is timed on both sides (``ltp.htf``; the real
harmonic matrices and ``ct.ss`` for the peer).  The two slow sides are
evaluated on every 10th point and their evaluation time is extrapolated
linearly to the 2000 points.

Reference: ``H_{n,m}(s) = Σ_p C_{n-p} (s + jpω_p - A)^{-1} B_{p-m}`` with
batched 4 x 4 solves, independent of the three methods.  Error: ``max|H -
H_ref| / max|H_ref|`` over all points and blocks; tolerance 1e-10.
"""

import numpy as np

import control as ct

from _common import median_time, row

import ltpcontrol as ltp

TOL = 1e-10
FULL = dict(n=4, K=10, npoints=2000, stride=10, repeats=5, slow_repeats=3)
QUICK = dict(n=4, K=3, npoints=200, stride=5, repeats=3, slow_repeats=2)


def make_system(n, seed=0, period=1.0):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    A -= (np.max(np.linalg.eigvals(A).real) + 1.0) * np.eye(n)
    B0 = rng.standard_normal((n, 1))
    B1 = 0.3 * (rng.standard_normal((n, 1)) + 1j * rng.standard_normal((n, 1)))
    C0 = rng.standard_normal((1, n))
    C1 = 0.3 * (rng.standard_normal((1, n)) + 1j * rng.standard_normal((1, n)))
    B = ltp.PeriodicMatrix([B1.conj(), B0, B1], period)
    C = ltp.PeriodicMatrix([C1.conj(), C0, C1], period)
    return ltp.ltpss(A, B, C, 0, period=period, name='floquet4')


def reference(sys, K, s):
    A = sys.A(0.0)
    n = A.shape[0]
    w = sys.omega_p
    KB, KC = sys.B.nharmonics, sys.C.nharmonics
    Bk, Ck = sys.B.fourier(KB), sys.C.fourier(KC)
    H = np.zeros((len(s), 2 * K + 1, 2 * K + 1), complex)
    eye = np.eye(n)
    res = {}
    for p in range(-K - KC, K + KC + 1):
        M = (s[:, None, None] + 1j * p * w) * eye - A
        res[p] = np.linalg.inv(M)
    for i, nn in enumerate(range(-K, K + 1)):
        for j, m in enumerate(range(-K, K + 1)):
            for p in range(nn - KC, nn + KC + 1):
                if abs(p - m) <= KB:
                    H[:, i, j] += np.einsum('ij,sjk,kl->s', Ck[nn - p + KC], res[p],
                                            Bk[p - m + KB])
    return H


def _real_basis(K):
    m = 2 * K + 1
    V = np.zeros((m, m), complex)
    V[K, 0] = 1.0
    for i in range(1, K + 1):
        V[K + i, 2 * i - 1] = V[K - i, 2 * i - 1] = 1 / np.sqrt(2)
        V[K + i, 2 * i], V[K - i, 2 * i] = 1j / np.sqrt(2), -1j / np.sqrt(2)
    return V


def real_harmonic_ss(sys, K, Ki):
    """The harmonic state space of the HTF as a real `control.StateSpace`."""
    n, w = sys.nstates, sys.omega_p
    harm = np.arange(-Ki, Ki + 1)
    idx = harm[:, None] - harm[None, :] + 2 * Ki

    def toeplitz(P):
        c = P.fourier(2 * Ki)
        r, q = c.shape[1:]
        return c[idx].transpose(0, 2, 1, 3).reshape((2 * Ki + 1) * r, (2 * Ki + 1) * q)

    F = toeplitz(sys.A) - np.kron(np.diag(1j * w * harm), np.eye(n))
    cen = np.arange(Ki - K, Ki + K + 1)          # central harmonics (SISO)
    G, Hc, J = toeplitz(sys.B)[:, cen], toeplitz(sys.C)[cen], toeplitz(sys.D)[np.ix_(cen, cen)]
    Vx, Vk = np.kron(_real_basis(Ki), np.eye(n)), _real_basis(K)
    mats = [Vx.conj().T @ F @ Vx, Vx.conj().T @ G @ Vk, Vk.conj().T @ Hc @ Vx,
            Vk.conj().T @ J @ Vk]
    imag = max(np.abs(M.imag).max() for M in mats)
    return ct.ss(*[M.real for M in mats]), Vk, imag


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    n, K = cfg['n'], cfg['K']
    w_p = make_system(n).omega_p
    omega = np.logspace(np.log10(w_p / 100), np.log10(2 * K * w_p), cfg['npoints'])
    s = 1j * omega
    sub = slice(None, None, cfg['stride'])
    factor = len(s) / len(s[sub])
    log(f"P2: reference HTF, n={n}, K={K}, {len(s)} points")
    Href = reference(make_system(n), K, s)
    scale = np.abs(Href).max()

    def err(H, pts=slice(None)):
        return float(np.abs(H - Href[pts]).max() / scale)

    # ours: Floquet fast path
    def modal(sys):
        H = ltp.htf(sys, K)
        return H, np.moveaxis(H(s), -1, 0)         # points first, as Href
    t_ours, times, (H, Hs) = median_time(modal, cfg['repeats'], setup=lambda: make_system(n))
    # internal order documented by ltp.htf for constant A, band-limited B, C
    sys0 = make_system(n)
    Ki = K + sys0.B.nharmonics + sys0.C.nharmonics
    err_ours = err(Hs)
    fast = getattr(getattr(H, '_hss', None), 'modal', None) is not None
    del Hs

    # dense Toeplitz solve
    log("P2: method='solve'")
    t_build, _, Hsol = median_time(lambda sys: ltp.htf(sys, K, method='solve'),
                                   cfg['slow_repeats'], setup=lambda: make_system(n))
    t_eval, eval_times, Hsub = median_time(lambda: np.moveaxis(Hsol(s[sub]), -1, 0),
                                           cfg['slow_repeats'])
    t_solve = t_build + t_eval * factor
    err_solve = err(Hsub, sub)

    # python-control on the real harmonic state space
    log("P2: control.frequency_response of the real harmonic state space")
    t_ctb, _, (ss, Vk, imag) = median_time(lambda sys: real_harmonic_ss(sys, K, Ki),
                                           cfg['slow_repeats'], setup=lambda: make_system(n))
    t_cte, ct_times, fr = median_time(lambda: ct.frequency_response(ss, omega[sub]),
                                      cfg['slow_repeats'])
    t_ct = t_ctb + t_cte * factor
    Hct = np.einsum('ij,jks,lk->sil', Vk, np.asarray(fr.frdata), Vk.conj())
    err_ct = err(Hct, sub)

    ok = err_ours <= TOL
    work = f"HTF n={n} K={K} ({(2 * K + 1)}x{(2 * K + 1)}), {len(s)} pts"
    extrap = dict(points_timed=int(len(s[sub])), extrapolation_factor=factor)
    return [
        row('P2a', work, ours="ltp.htf 'auto' (Floquet modal path)",
            peer="ltp.htf method='solve' (dense harmonic resolvent)",
            t_ours=t_ours, t_peer=t_solve, target='>= 20x',
            target_met=t_solve / t_ours >= 20, err_ours=err_ours, err_peer=err_solve,
            tol=TOL, checks={'ours <= tol': ok, 'peer <= tol': err_solve <= TOL},
            matched=ok and err_solve <= TOL,
            notes='peer evaluation timed on every %d-th point, extrapolated' % cfg['stride'],
            extra=dict(ours_times=times, modal_path=fast, internal_harmonics=Ki,
                       harmonic_states=n * (2 * Ki + 1), peer_build_s=t_build,
                       peer_eval_times=eval_times, **extrap)),
        row('P2b', work, ours="ltp.htf 'auto' (Floquet modal path)",
            peer='ct.frequency_response of the real harmonic StateSpace '
                 f'({n * (2 * Ki + 1)} states)',
            t_ours=t_ours, t_peer=t_ct, target='>= 10x', target_met=t_ct / t_ours >= 10,
            err_ours=err_ours, err_peer=err_ct, tol=TOL,
            checks={'ours <= tol': ok, 'peer <= tol': err_ct <= TOL,
                    'real form is real': imag < 1e-12},
            matched=ok and err_ct <= TOL,
            notes='peer evaluation timed on every %d-th point, extrapolated' % cfg['stride'],
            extra=dict(peer_build_s=t_ctb, peer_eval_times=ct_times,
                       max_imag_part_of_real_form=imag, **extrap)),
    ]
