"""P14: Floquet analysis of real-size rotor models (38, 120, 300 states, stiff).

Workload: a synthetic rotor model in the style of a multi-blade
linearization, tabulated at 36 azimuths (Fourier interpolation, as
`read_lin` does), period T = 1 s (Ω = 2π rad/s):

* ``(n - s)/2`` structural degrees of freedom in scaled modal coordinates
  ``(w q, q')``, natural frequencies 0.5Ω-15Ω, damping 0.5-5 %, whose
  stiffness varies with the azimuth (harmonics 1 and 2, 10 % coupling);
* s = n/10 stiff first-order states (sensor/actuator-like lags) with rates
  ``-10⁴Ω (1 + 0.5 r)``, driven by the structural rates.  They do not feed
  back, so their exponents are exactly their rates: an independent truth
  for the stiff part, which a formed product cannot resolve (multipliers
  ``e^{-6e4}``).

Rows (n = 38, 120, 300):

* ours: ``ltp.floquet_exponents`` and ``ltp.floquet_modes`` (default call,
  own rows ``P14-modes-n``: exponents as below, the structural mode vectors
  against the independent structural monodromy, ``‖Φ_s v - μ v‖/‖v‖``, and
  the stiff modes' shapes against the unit lag vectors, see `modes_errors`).
* peer: the 20-line hand-written product a user writes: N midpoint
  ``scipy.linalg.expm`` steps ``Φ = Π e^{A((k+½)h) h}`` then ``eig``,
  with N = 720 (the smallest N of the form 36 * 2^j whose structural
  exponents reach the tolerance, checked against the reference at 2N).
* accuracy: every exponent, stiff ones included, against an independent
  reference that forms no product: the structural block's exponents from
  Richardson-extrapolated midpoint products (2N and 4N steps; N and 2N
  above 150 states) in 36 groups through the periodic Schur form, and the
  lag rates, which are the stiff exponents exactly.  Error: the largest
  difference of the sorted real parts relative to the largest ``|Re λ|``
  (the must-show measure, 1e-8); the structural exponents are also
  reported relative to their own largest ``|Re λ|``.  The peer's stiff
  multipliers (``e^{-6e4}``) underflow its formed product, so its
  all-exponent error is meaningless (shown with ``*``); its structural
  error is the fair comparison of accuracy.

Peak memory: tracemalloc peak of the call (NumPy allocations).

The BAR row: the 44-state OpenFAST model ``BAR_URC_EDBD.1.lin``
(ElastoDyn + BeamDyn, one azimuth), its rotating-frame matrix taken as
independent of the azimuth and turning at the file's rotor speed, after
``mbc``; the time-varying
multi-blade model has ``‖A‖ = 5e6`` and exponents down to -1.5e4 rad/s
(Ω = 0.83 rad/s).  Being one constant rotating-frame matrix seen through
the multi-blade transform, its exact exponents are the eigenvalues of
the file's A (modulo jΩ): that is the truth.

The HTF row: the dense path ``htf(sys, 10, method='solve')`` of a 20-state
plant with time-varying A on 1000 frequencies against the modal path of
the same request (time ratio, largest difference).

The Campbell row: `campbell` over 8 rotor speeds of a 16-state isotropic
rotor read from linearization files (36 azimuths per speed, written with
four-decimal azimuths) against MBC averaging plus ``eig`` per speed.
"""

import time
import tracemalloc

import numpy as np
import scipy.linalg as la

from _common import row, timed

import ltpcontrol as ltp

T = 1.0
OMEGA = 2 * np.pi / T
NAZ = 36
TOL = 1e-8
FULL = dict(sizes=(38, 120, 300), bar=True, modes=True, stiff=1e4, htf=(20, 10, 1000),
            campbell=True, fine=(12000, 400))
# CI smoke: a 12-state model with lags at -100 Ω
QUICK = dict(sizes=(12,), bar=False, modes=True, stiff=1e2, htf=(4, 5, 200),
             campbell=False, fine=(2000, 400))


def rotor_model(n, seed=0, stiff=1e4):
    """Synthetic rotor model (module notes): an LTPStateSpace with n states."""
    rng = np.random.default_rng(seed)
    s = max(2, n // 10)
    m = (n - s) // 2
    s = n - 2 * m
    w = OMEGA * np.sort(rng.uniform(0.5, 15.0, m))
    zeta = rng.uniform(0.005, 0.05, m)
    G = [rng.standard_normal((m, m)) for _ in range(4)]
    G = [0.5 * (g + g.T) / np.sqrt(m) for g in G]
    lag = -stiff * OMEGA * (1 + 0.5 * rng.random(s))
    drive = 0.3 * rng.standard_normal((s, m)) * np.sqrt(w)[None, :]
    samples = []
    for psi in 2 * np.pi * np.arange(NAZ) / NAZ:
        varying = 0.1 * (np.cos(psi) * G[0] + np.sin(psi) * G[1]
                         + np.cos(2 * psi) * G[2] + np.sin(2 * psi) * G[3])
        K = np.diag(w ** 2) + np.sqrt(w)[:, None] * varying * np.sqrt(w)[None, :] * w.mean()
        A = np.zeros((n, n))
        # states (w q, q', lags): d(wq)/dt = w q', dq'/dt = -K q - 2ζw q' + back lags
        A[:m, m:2 * m] = np.diag(w)
        A[m:2 * m, :m] = -K / w[None, :]
        A[m:2 * m, m:2 * m] = -np.diag(2 * zeta * w)
        A[2 * m:, m:2 * m] = drive
        A[2 * m:, 2 * m:] = np.diag(lag)
        samples.append(A)
    A = ltp.PeriodicMatrix.from_samples(np.array(samples), T, kind='fourier')
    return ltp.ltpss(A, np.zeros((n, 0)), np.zeros((0, n)), np.zeros((0, 0)), period=T)


def midpoint_factors(A, N):
    """Midpoint exponential factors e^{A((k+½)h) h}, k = 0..N-1 (generator)."""
    h = T / N
    for k in range(N):
        yield la.expm(A((k + 0.5) * h) * h)


def peer_exponents(sys, N):
    """The hand-written product: Φ = Π midpoint expm, then log(eig Φ)/T."""
    Phi = np.eye(sys.nstates)
    for F in midpoint_factors(sys.A, N):
        Phi = F @ Phi
    mu = np.linalg.eigvals(Phi)
    with np.errstate(divide='ignore'):
        return np.log(np.abs(mu)) / T + 1j * np.angle(mu) / T


def reference_exponents(n, N, seed=0, stiff=1e4, with_monodromy=False):
    """Independent exponents: the lag rates and a converged structural product.

    The structural block alone (no stiffness) is integrated by midpoint
    products at N and 2N steps, Richardson-extrapolated (order 2) on 36
    groups of steps, and the group factors go through the periodic Schur
    form (no product is formed).  The stiff exponents are the lag rates
    exactly (the lags do not feed back).  With `with_monodromy`, also the
    structural block's monodromy (product of the group factors, not stiff).
    """
    from ltpcontrol._core.periodic_schur import product_eigenvalues
    sys = rotor_model(n, seed, stiff)
    s = max(2, n // 10)
    m = (n - s) // 2
    k = 2 * m
    lags = np.diag(sys.A(0.0))[k:]
    Ab = lambda t: sys.A(t)[:k, :k]            # noqa: E731
    groups = NAZ
    factors = []
    for g in range(groups):
        t0, t1 = g * T / groups, (g + 1) * T / groups
        out = []
        for steps in (N // groups, 2 * N // groups):
            h = (t1 - t0) / steps
            P = np.eye(k)
            for j in range(steps):
                P = la.expm(Ab(t0 + (j + 0.5) * h) * h) @ P
            out.append(P)
        factors.append((4 * out[1] - out[0]) / 3)
    logmod, arg = product_eigenvalues(np.array(factors))
    ref = np.concatenate([logmod / T + 1j * arg / T, lags.astype(complex)])
    if not with_monodromy:
        return ref, k
    return ref, k, np.linalg.multi_dot(factors[::-1])


def real_error(lam, ref, keep=None, scale=None):
    """Largest error of the sorted real parts (of the `keep` largest), relative."""
    a = np.sort(np.real(lam))[::-1][:keep]
    b = np.sort(np.real(ref))[::-1][:keep]
    scale = np.max(np.abs(np.real(ref))) if scale is None else scale
    with np.errstate(invalid='ignore'):
        err = np.max(np.abs(a - b)) / scale
    return float(err) if np.isfinite(err) else np.inf


def modes_errors(modes, ref, k, Phi_s, scale):
    """Accuracy of `floquet_modes` against independent truths.

    * exponents: as `real_error` (every exponent, relative to the largest
      ``|Re λ|``);
    * structural mode vectors: the lags do not feed back, so the structural
      part ``v_s`` of a structural mode's vector is an eigenvector of the
      structural block's monodromy (independent Richardson product):
      ``max ‖Φ_s v_s - μ v_s‖ / ‖v_s‖``;
    * stiff mode shapes: a lag that does not feed back has the unit lag
      vector as its periodic shape at every sample instant: the largest
      deviation of the normalised shapes.
    """
    lam = modes.strip_exponents
    err_exp = real_error(lam, ref, scale=scale)
    order = np.argsort(lam.real)
    nlag = len(lam) - k
    stiff, slow = order[:nlag], order[nlag:]
    v = modes.vectors[:k, slow]
    mu = np.exp(lam[slow] * T)
    resid = np.linalg.norm(Phi_s @ v - v * mu, axis=0) / np.linalg.norm(v, axis=0)
    shape_err = 0.0
    for i in stiff:
        s = modes.shapes[:, i, :]
        j = int(np.argmax(np.abs(s[:, 0])))
        unit = np.zeros(len(lam))
        unit[j] = 1.0
        shape_err = max(shape_err, float(np.abs(s / s[j] - unit[:, None]).max()))
    return err_exp, float(resid.max()), shape_err


def measure(fn, *args):
    tracemalloc.start()
    try:
        t, out = timed(fn, *args)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return t, out, peak


def bar_model():
    """The 44-state BAR_URC_EDBD.1.lin (one azimuth) and its multi-blade model."""
    import os
    from _common import ROOT
    lin = ltp.read_lin(os.path.join(ROOT, 'tests', 'data', 'BAR_URC_EDBD.1.lin'))
    # BeamDyn node 2 of each blade: 6 displacements (states 9-14, 21-26, 33-38)
    # and their rates (15-20, 27-32, 39-44)
    rotating = [[8 + j, 20 + j, 32 + j] for j in range(6)]
    rates = [[14 + j, 26 + j, 38 + j] for j in range(6)]
    # the file's rotating-frame matrices taken as independent of the azimuth
    # (one linearization), turning at the file's rotor speed
    A = np.asarray(lin.samples[0][0])
    rot = ltp.ltpss(A, np.zeros((A.shape[0], 0)), np.zeros((0, A.shape[0])),
                    np.zeros((0, 0)), period=2 * np.pi / lin.rotor_speed)
    nr, _ = ltp.mbc(rot, rotating, 3, rates=rates, rotor_speed=lin.rotor_speed)
    return lin, nr


def bar_row(log=print):
    """Exponents of the BAR model after mbc against the eigenvalues of the file's A."""
    lin, nr = bar_model()
    log("P14-BAR: floquet_exponents of BAR_URC_EDBD.1.lin after mbc (44 states)")
    t_ours, lam, peak = measure(ltp.floquet_exponents, nr)
    # one constant rotating-frame matrix seen through the periodic multi-blade
    # transform: the exponents are its eigenvalues (real parts exactly)
    ev = np.linalg.eigvals(lin.samples[0][0])
    err = real_error(lam, ev)
    log(f"  ours {t_ours:.1f} s, peak {peak / 1e6:.0f} MB, error {err:.1e}")
    return row('P14-BAR', 'floquet_exponents, BAR_URC_EDBD.1.lin after mbc, 44 states, '
               '|A| = 5e6, exponents to -1.5e4', ours='floquet_exponents', peer=None,
               t_ours=t_ours, metric='time', value=t_ours, target='<= 30 s, <= 1 GB',
               target_met=t_ours <= 30 and peak <= 1e9, err_ours=err, tol=TOL,
               checks={'ours <= tol': err <= TOL},
               notes=f'peak {peak / 1e6:.0f} MB; truth: eigenvalues of the file\'s A '
                     '(real parts, relative to the largest)',
               extra=dict(peak_ours=peak))


def htf_row(n, K, npoints, log=print):
    """Dense HTF path (Schur form) against the modal path, same request."""
    from systems import random_periodic_plant
    sys = random_periodic_plant(n, name=f'random{n}')
    omega = np.linspace(0.05, 4 * K, npoints) * sys.omega_p
    log(f"P14-HTF: n={n}, K={K}, {npoints} frequencies, method='solve' vs 'modal'")

    def evaluate(method):
        return ltp.htf(sys, K, method=method)(1j * omega)
    t_modal, G_modal, peak_modal = measure(evaluate, 'modal')
    t_solve, G_solve, peak_solve = measure(evaluate, 'solve')
    err = float(np.abs(G_solve - G_modal).max() / np.abs(G_modal).max())
    ratio = t_solve / t_modal
    log(f"  solve {t_solve:.2f} s ({peak_solve / 1e6:.0f} MB), modal {t_modal:.2f} s "
        f"({peak_modal / 1e6:.0f} MB), difference {err:.1e}")
    return row(f'P14-HTF{n}', f'HTF n={n}, K={K}, {npoints} freqs, time-varying A: dense path',
               ours="ltp.htf method='solve' + H(jω)", peer="ltp.htf method='modal' + H(jω)",
               t_ours=t_solve, t_peer=t_modal, metric='time/modal', value=ratio,
               target='<= 3x modal', target_met=ratio <= 3, err_ours=err, tol=1e-9,
               checks={'solve = modal to 1e-9': err <= 1e-9},
               notes=f'peak {peak_solve / 1e6:.0f} MB (modal {peak_modal / 1e6:.0f} MB); '
                     'error: largest difference to the modal path, relative',
               extra=dict(peak_ours=peak_solve, peak_peer=peak_modal))


def rotor16_files(directory, speeds, naz=NAZ):
    """Linearization files of a 16-state isotropic rotor at `naz` azimuths per speed.

    Tower fore-aft/side-side (2 DOF) and blade flap/lag (2 DOF x 3 blades),
    displacements then rates; the tower couples to the collective flap and
    to the lag through ``cos ψ_b``.  Azimuths are written to four decimals,
    as OpenFAST does.  Returns ``{speed: [paths]}``.
    """
    from test_read_lin import write_lin
    out = {}
    for Om in speeds:
        files = []
        for i in range(naz):
            psi = 2 * np.pi * i / naz
            K = np.zeros((8, 8))
            K[0, 0], K[1, 1] = 1.8 ** 2, 1.9 ** 2
            for b in range(3):
                pb = psi + 2 * np.pi * b / 3
                f, lag = 2 + b, 5 + b
                K[f, f] = 4.2 ** 2 + 1.2 * Om ** 2
                K[lag, lag] = 6.5 ** 2 + 0.1 * Om ** 2
                K[0, f] = K[f, 0] = 0.8
                K[1, lag] = K[lag, 1] = 0.9 * np.cos(pb)
            C = 0.02 * np.sqrt(np.abs(K)) + np.diag([0.05, 0.05] + [0.4] * 3 + [0.02] * 3)
            A = np.block([[np.zeros((8, 8)), np.eye(8)], [-K, -C]])
            path = directory / f'rotor16_{Om:.2f}.{i + 1}.lin'
            write_lin(path, A, np.zeros((16, 0)), np.zeros((0, 16)), np.zeros((0, 0)), Om,
                      round(psi, 4), rotating=[False] * 2 + [True] * 6 + [False] * 2
                      + [True] * 6, order=[2] * 16)
            files.append(path)
        out[Om] = files
    return out


def campbell_row(nspeeds=8, log=print):
    """`campbell` of the 16-state rotor read from files against MBC averaging."""
    import pathlib
    import tempfile
    speeds = np.linspace(0.4, 1.2, nspeeds)
    groups = [[2, 3, 4], [5, 6, 7]]
    rates = [[10, 11, 12], [13, 14, 15]]
    with tempfile.TemporaryDirectory() as tmp:
        files = rotor16_files(pathlib.Path(tmp), speeds)
        models = {Om: ltp.read_lin(files[Om]) for Om in speeds}
        log(f"P14-Campbell: 16-state rotor from files, {nspeeds} speeds")

        def factory(Om):
            nr, _ = ltp.mbc(models[Om], groups, 3, rates=rates)
            return nr

        def averaged():
            out = []
            for Om in speeds:
                out.append(np.linalg.eigvals(np.asarray(factory(Om).average(method='samples').A)))
            return out
        t_peer, ev = timed(averaged)
        t_ours, cd = timed(ltp.campbell, factory, speeds, n_jobs=1)
    # the isotropic rotor in multi-blade coordinates is constant to the files'
    # precision: the exponents are the averaged model's eigenvalues (mod jΩ)
    freq = np.sort(np.asarray(cd.frequency)[-1])
    ref = np.sort(np.abs(ev[-1]))
    err = float(np.abs(freq - ref).max() / ref.max())
    ratio = t_ours / t_peer
    log(f"  campbell {t_ours:.2f} s, MBC averaging {t_peer:.2f} s, ratio {ratio:.1f}")
    return row('P14-Campbell', f'Campbell diagram, 16-state rotor from .lin files (36 azimuths), '
               f'{nspeeds} speeds', ours='ltp.campbell (floquet_modes per speed)',
               peer='mbc + average + eig per speed', t_ours=t_ours, t_peer=t_peer,
               metric='time/peer', value=ratio, target='<= 3x MBC averaging',
               target_met=ratio <= 3, err_ours=err, tol=1e-6,
               checks={'frequencies = averaged model (1e-6)': err is not None and err <= 1e-6},
               notes='error: natural frequencies at the last speed against the averaged '
                     'model, relative')


def fine_grid_rows(nsamples=12000, per_period=400, log=print):
    """forced_response on fine grids (400 steps per period): unaligned vs aligned."""
    from ltpcontrol._core.transition import step_transitions
    w = 2 * np.pi
    coeffs = np.zeros((3, 2, 2), complex)
    coeffs[1] = [[0, 1], [-w ** 2, -0.6 * w]]
    coeffs[0] = coeffs[2] = [[0, 0], [-0.1 * w ** 2, 0]]
    Af = ltp.PeriodicMatrix(coeffs, 1.0)
    forms = {'Fourier': Af,
             'callable': ltp.PeriodicMatrix.from_function(
                 lambda t: np.array([[0.0, 1.0], [-(1 + 0.2 * np.cos(w * t)) * w ** 2,
                                                  -0.6 * w]]), 1.0)}
    t_al = np.arange(nsamples) / per_period
    t_un = np.linspace(0, t_al[-1], nsamples)        # step does not divide the period
    # non-uniform: every inner point moved by up to ±20 % of the step
    jitter = np.random.default_rng(3).uniform(-0.2, 0.2, nsamples) / per_period
    jitter[[0, -1]] = 0.0
    t_jit = t_al + jitter
    rows = []
    for form, A in forms.items():
        sys = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=1.0)
        times = {}
        for name, t in (('aligned', t_al), ('unaligned', t_un), ('non-uniform', t_jit)):
            u = np.sin(3.1 * t)
            best = np.inf
            for _ in range(3):
                dt, resp = timed(ltp.forced_response, sys, t, u)
                best = min(best, dt)
            times[name] = (best, resp, t, u)
        for grid in ('unaligned', 'non-uniform'):
            # the same discretization step by step on the first period of the grid
            _, resp, t, u = times[grid]
            k = per_period + 1
            Phi, G0, G1 = step_transitions(Af, sys.B, t[:k - 1], np.diff(t[:k]))
            x, ys = np.zeros(2), [0.0]
            for j in range(k - 1):
                x = Phi[j] @ x + G0[j][:, 0] * u[j] + G1[j][:, 0] * (u[j + 1] - u[j])
                ys.append(x[0])
            y = np.asarray(resp.outputs).ravel()[:k]
            err = float(np.abs(y - ys).max() / np.abs(ys).max())
            ratio = times[grid][0] / times['aligned'][0]
            log(f"P14-fine ({form}, {grid}): {times[grid][0]:.3f} s, aligned "
                f"{times['aligned'][0]:.3f} s, slowdown {ratio:.2f}, error {err:.1e}")
            tag = '' if grid == 'unaligned' else '-nonuniform'
            what = 'step not dividing T' if grid == 'unaligned' else \
                'non-uniform (steps within ±20 %)'
            rows.append(row(
                f'P14-fine-{form}{tag}', f'forced_response, 2-state Mathieu plant ({form} A), '
                f'{nsamples} samples, {per_period} steps per period, {what}',
                ours=f'forced_response, {grid} grid', peer='forced_response, aligned grid',
                t_ours=times[grid][0], t_peer=times['aligned'][0], metric='slowdown',
                value=ratio, target='<= 2x the aligned grid', target_met=ratio <= 2,
                err_ours=err, tol=1e-11, checks={'ours <= tol': err <= 1e-11},
                notes='error against the same discretization, step by step (first period)'))
    return rows


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    rows = []
    modes = cfg['modes']
    for n in cfg['sizes']:
        sys = rotor_model(n, stiff=cfg['stiff'])
        log(f"P14: Floquet exponents, {n} states")
        t_ours, lam, peak = measure(ltp.floquet_exponents, sys)
        N = 720
        t_peer, lam_peer, peak_peer = measure(peer_exponents, sys, N)
        # the reference: Richardson of 2N and 4N steps (N and 2N above 150 states,
        # still fourth order against the peer's second)
        t_ref, (ref, k, Phi_s) = timed(reference_exponents, n, 2 * N if n <= 150 else N, 0,
                                       cfg['stiff'], True)
        scale = np.max(np.abs(ref.real))
        err_ours = real_error(lam, ref, scale=scale)
        err_peer = real_error(lam_peer, ref, scale=scale)
        struct_scale = np.max(np.abs(np.sort(ref.real)[::-1][:k]))
        err_struct = real_error(lam, ref, k, scale=struct_scale)
        err_struct_peer = real_error(lam_peer, ref, k, scale=struct_scale)
        rows.append(row(
            f'P14-{n}', f'floquet_exponents, {n}-state rotor, 36 azimuths, lags at -{cfg["stiff"]:.0e} Omega',
            ours='floquet_exponents', peer=f'{N} midpoint expm product + eig',
            t_ours=t_ours, t_peer=t_peer, target='<= 2x peer time, <= 1 GB',
            target_met=t_ours <= 2 * t_peer and peak <= 1e9, err_ours=err_ours,
            err_peer=err_peer, tol=TOL,
            checks={'ours <= tol (all exponents, rel. largest |Re|)': err_ours <= TOL},
            matched=err_ours <= TOL and err_peer <= TOL,
            notes=f'peak {peak / 1e6:.0f} MB (peer {peak_peer / 1e6:.0f} MB); structural '
                  f'exponents rel. their largest |Re|: ours {err_struct:.1e}, peer '
                  f'{err_struct_peer:.1e}',
            extra=dict(peak_ours=peak, peak_peer=peak_peer, err_struct=err_struct,
                       err_struct_peer=err_struct_peer, t_reference=t_ref)))
        log(f"  ours {t_ours:.1f} s {peak / 1e6:.0f} MB err {err_ours:.1e} (structural "
            f"{err_struct:.1e}); peer {t_peer:.1f} s err {err_peer:.1e} (structural "
            f"{err_struct_peer:.1e})")
        if modes:
            t_modes, fm, peak_modes = measure(ltp.floquet_modes, sys)
            err_m, resid, shape_err = modes_errors(fm, ref, k, Phi_s, scale)
            ratio = t_modes / t_peer
            rows.append(row(
                f'P14-modes-{n}', f'floquet_modes (default call), {n}-state rotor, 36 '
                f'azimuths, lags at -{cfg["stiff"]:.0e} Omega',
                ours='floquet_modes', peer=f'{N} midpoint expm product + eig',
                t_ours=t_modes, t_peer=t_peer, metric='time/peer', value=ratio,
                target='<= 2x peer time, <= 1 GB',
                target_met=ratio <= 2 and peak_modes <= 1e9, err_ours=err_m, tol=TOL,
                checks={'exponents <= tol (all, rel. largest |Re|)': err_m <= TOL,
                        'structural vectors: |Phi_s v - mu v|/|v| <= 1e-5': resid <= 1e-5,
                        'stiff shapes = unit lag vectors (1e-6)': shape_err <= 1e-6},
                notes=f'peak {peak_modes / 1e6:.0f} MB; structural vector residual '
                      f'{resid:.1e} (independent Richardson monodromy of the structural '
                      f'block); stiff shapes {shape_err:.1e}; {len(fm.times)} samples',
                extra=dict(peak_ours=peak_modes, resid=resid, shape_err=shape_err)))
            log(f"  modes {t_modes:.1f} s ({ratio:.2f}x peer) {peak_modes / 1e6:.0f} MB, "
                f"exponents {err_m:.1e}, vectors {resid:.1e}, stiff shapes {shape_err:.1e}")
    if cfg['htf']:
        rows.append(htf_row(*cfg['htf'], log=log))
    if cfg['fine']:
        rows += fine_grid_rows(*cfg['fine'], log=log)
    if cfg['campbell']:
        rows.append(campbell_row(log=log))
    if cfg['bar']:
        rows.append(bar_row(log))
    return rows


if __name__ == '__main__':
    import sys as _sys
    args = _sys.argv[1:]
    FULL['bar'] = 'bar' in args
    FULL['modes'] = 'nomodes' not in args
    FULL['sizes'] = tuple(int(a) for a in args if a.isdigit())
    if 'nohtf' in args:
        FULL['htf'] = None
    FULL['campbell'] = 'campbell' in args
    FULL['fine'] = (12000, 400) if 'fine' in args else None
    for r in run():
        print(r)
