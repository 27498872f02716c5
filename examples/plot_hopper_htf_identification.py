"""
Harmonic transfer functions of the simplified hopper from chirp data
====================================================================

Analogue of thesis §3.4.3 (Figs. 3.5-3.6) and §3.5 (Fig. 3.7).

The hybrid spring-mass hopper of eq. (3.36) (damper on only while the mass
moves up, forcing ``f0(t) = cos 2πt``) is simulated with event detection,
not its LTP model: the data come from the hybrid plant, as in the thesis.

1. Thirty unperturbed periods from rest reach the 1 s limit cycle; the 30th
   period is recorded as the nominal output ``x̄(t)``.
2. Nine 30 s chirps ``0.004 sin(2π (7/60) τ²)`` sweeping 0-7 Hz (eq. 3.40
   with the stated 7 Hz end frequency), each started ``T/9`` later in the
   cycle than the previous one, perturb the cycle.  Each chirp is followed by
   a quiet gap so that its record of whole periods holds the complete
   response; the records are independent experiments started on the cycle.
3. ``ξ1 = x − x̄`` and the input give the nonparametric estimate of
   ``G_0, G_±1, ..., G_±3`` (eq. 3.31; nine records determine the seven
   components at each frequency without regularisation).
4. ``k`` and ``c`` of the LTP model (3.39) are fitted to ``G_{-1}, G_0,
   G_1`` (thesis: k = 200, c = 2.12 for the true 200 and 2).  The switching
   instants of the damping flag ``s(t)`` come from the recorded cycle: they
   are the extrema of ``x̄(t)``, where ``dx̄/dt = 0``.
5. Fig. 3.7: for several spring constants the identification is repeated
   and the eigenvalues of the identified model's return map (3.43) are
   compared with the exact Jacobian of the hybrid return map.

The estimates of ``G_0`` and ``G_±1`` match the theory closely and the fit
recovers k and c far more accurately than the thesis's c = 2.12.  ``G_±2``
(and partly ``G_±3``) are poor near 12-15 rad/s, as in the thesis.  The
cause is the nine-replica design itself: replica r multiplies the regressor
of harmonic k by ``e^{j2πkr/9}``, so components k and k ± 9 cannot be told
apart, and the unmodelled ``G_∓7`` (up to 2.6e-4, larger than ``G_±2``)
is attributed to ``G_±2``.  Repeating the experiment on the LTP model (3.39) gives the same
errors with 9 replicas, and errors of a few percent with 19.

Set ``LTP_EXAMPLES_QUICK=1`` for a reduced run (shorter chirps, fewer
spring constants).
"""

import math
import os
import time
import warnings

import matplotlib

matplotlib.use('Agg')

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from joblib import Parallel, delayed  # noqa: E402

import ltpcontrol as ltp  # noqa: E402
from hopper import (HOPPER_PARAMS, PERIOD, cached_experiment, hopper_ltp,  # noqa: E402
                    hopper_orbit, hopper_plant, plant_key)

QUICK = os.environ.get('LTP_EXAMPLES_QUICK', '0') == '1'

#: Sample time: 180 samples per period, 20 per T/9 shift, so that the
#: sampled replicas are exact delayed copies of each other.
DT = PERIOD / 180
#: Experiment design of §3.4.3: 9 replicas, 0-7 Hz, amplitude 0.004.
DESIGN = {'nreplicas': 9, 'duration': 30.0, 'f0': 0.0, 'f1': 7.0, 'amplitude': 0.004,
          'gap': 6.0}
#: Reduced design for quick runs and tests.
QUICK_DESIGN = {**DESIGN, 'duration': 12.0, 'gap': 5.0}
#: Simulation processes: one in the quick run (the documentation build runs beside
#: the test suite, where more processes only compete for the cores).
N_JOBS = 1 if QUICK else 2
#: Number of harmonics on each side estimated (G_-3 ... G_3).
NHARMONICS = 3
#: Frequency band of the estimate and of the parametric fit (rad/s).
BAND = (0.5, 25.0)
#: Integration tolerances of the hybrid simulations.
SOLVER = {'rtol': 1e-8, 'atol': 1e-11}


# %%
# Limit cycle and experiments
# ---------------------------

def limit_cycle(plant, nperiods=30):
    """Simulate `nperiods` unperturbed periods from rest (thesis §3.4.3).

    Returns the state and mode at ``t = nperiods T`` (phase 0 of the cycle)
    and the samples of the last period of the output, used as the nominal
    output ``x̄(t)`` that is subtracted from every experiment.
    """
    p = plant.params
    rest = [p['x0'] - p['m'] * p['g'] / p['k'], 0.0]
    nper = int(round(PERIOD / DT))
    t = np.arange(nperiods * nper + 1) * DT
    resp = ltp.simulate_hybrid(plant, t, rest, 'lossless', **SOLVER)
    xbar = resp.outputs[-nper - 1:-1]
    return resp.final_state, resp.final_mode, xbar


def chirp_function(design, replica, period=PERIOD):
    """Fast scalar form of replica `replica` of `ltpcontrol.chirp_replicas`.

    In its own record (local time τ from the record start) the replica is
    ``a sin(2π (f0 + (f1 − f0) s / (2D)) s)`` for ``0 <= s = τ − rT/R < D``
    and zero elsewhere (eqs. 3.40, 3.48).  Used inside the ODE solver, where
    evaluating the vectorised signal at single points would dominate.
    """
    a, f0, dur = design['amplitude'], design['f0'], design['duration']
    sweep = (design['f1'] - f0) / (2 * dur)
    shift = replica * period / design['nreplicas']

    def u(tau):
        s = tau - shift
        return a * math.sin(2 * math.pi * (f0 + sweep * s) * s) if 0 <= s < dur else 0.0
    return u


def _run_record(plant, x0, mode0, xbar, chirp, t, input_delay):
    """One record: hybrid response to ``u(t − τ_u)`` minus the nominal output."""
    # the plant sees the delayed input ū(t) = u(t − τ_u)   (§3.6.2)
    resp = ltp.simulate_hybrid(plant, t - t[0], x0, mode0,
                               inputs=lambda tau: [chirp(tau - input_delay)], **SOLVER)
    # ξ1 = x − x̄ with x̄ repeated every period (records start at phase 0)
    return resp.outputs - np.resize(xbar, t.size)


def chirp_experiment(plant, cycle, design=DESIGN, input_delay=0.0, n_jobs=N_JOBS):
    """Simulate the phase-shifted chirp experiment on the hybrid plant.

    Parameters
    ----------
    plant : ltpcontrol.HybridPlant
        Hopper plant.
    cycle : tuple
        ``(x0, mode0, xbar)`` from `limit_cycle`.
    design : dict
        Keywords of `ltpcontrol.chirp_replicas`.
    input_delay : float
        Input delay τ_u in seconds (the recorded input is undelayed).
    n_jobs : int
        Parallel simulations (joblib).

    Returns
    -------
    exc : ltpcontrol.Excitation
        The (undelayed) input and the record windows.
    y : ndarray
        Output deviation ``ξ1`` on ``exc.time``.
    """
    # the same experiment on the same hopper is simulated once per process
    params = plant_key(plant)
    key = None if params is None else (
        'chirp', params, np.asarray(cycle[0], float).tobytes(), cycle[1],
        np.asarray(cycle[2], float).tobytes(), tuple(sorted(design.items())),
        float(input_delay), DT, tuple(sorted(SOLVER.items())))
    return cached_experiment(key, lambda: _chirp_experiment(plant, cycle, design,
                                                            input_delay, n_jobs))


def _chirp_experiment(plant, cycle, design, input_delay, n_jobs):
    """`chirp_experiment`, simulated."""
    x0, mode0, xbar = cycle
    exc = ltp.chirp_replicas(PERIOD, dt=DT, **design)
    chirps = [chirp_function(design, r) for r in range(len(exc.segments))]
    for (a, b), chirp in zip(exc.segments, chirps):
        local = exc.time[a:b:97] - exc.time[a]
        assert np.allclose([chirp(tau) for tau in local], exc.inputs[a:b:97], atol=1e-12)
    parts = Parallel(n_jobs=n_jobs)(
        delayed(_run_record)(plant, x0, mode0, xbar, chirp, exc.time[a:b], input_delay)
        for (a, b), chirp in zip(exc.segments, chirps))
    return exc, np.concatenate(parts)


def estimate(exc, y, nharmonics=NHARMONICS):
    """Nonparametric HTF estimate (eq. 3.31) on `BAND`."""
    with warnings.catch_warnings():
        # bins with an unexcited shifted input ω − kω_p ≈ 0 are dropped
        warnings.filterwarnings('ignore', message='.*unexcited shifted inputs')
        return ltp.estimate_htf((exc.time, exc.inputs, y), PERIOD, nharmonics,
                                segments=exc.segments, omega_limits=BAND,
                                name='estimated')


# %%
# Parametric model (3.39)
# -----------------------

def switching_times(xbar):
    """Extrema of the sampled nominal output (``dx̄/dt = 0``), refined by parabolas.

    Returns the switching instants within the period and whether the damper
    is on (``dx̄/dt > 0``, lossy) at ``t = 0``.
    """
    prev, nxt = np.roll(xbar, 1), np.roll(xbar, -1)
    idx = np.nonzero(((xbar >= prev) & (xbar > nxt)) | ((xbar <= prev) & (xbar < nxt)))[0]
    # vertex of the parabola through three samples
    offset = 0.5 * (prev[idx] - nxt[idx]) / (prev[idx] - 2 * xbar[idx] + nxt[idx])
    times = np.mod((idx + offset) * DT, PERIOD)
    lossy_at_zero = xbar[1] > xbar[-1]
    return np.sort(times), bool(lossy_at_zero)


def ltp_model(k, c, switching, m=HOPPER_PARAMS['m']):
    """LTP model (3.39): ``A(t) = [[0, 1], [−k/m, −c s(t)/m]]``, ``B = [0, 1/m]ᵀ``.

    ``s(t)`` is the square wave equal to 1 between the switching instants
    where the mass moves up.
    """
    times, lossy0 = switching
    starts = np.concatenate([[0.0], times])
    flags = (np.arange(starts.size) + (0 if lossy0 else 1)) % 2 == 0
    mats = [np.array([[0.0, 1.0], [-k / m, -c * s / m]]) for s in flags]
    A = ltp.PeriodicMatrix.switching(mats, starts, PERIOD)
    return ltp.ltpss(A, [[0.0], [1.0 / m]], [[1.0, 0.0]], 0, PERIOD, name='fitted',
                     inputs=['u'], outputs=['x'], states=['x', 'v'])


def return_map(model):
    """Return map (3.43) of a piecewise-constant model: ``Π e^{A_i Δt_i}``."""
    return ltp.monodromy(model)


def model_htf(params, switching, nharmonics):
    """HTF of `ltp_model` (the harmonic state space is truncated at K + 15)."""
    with warnings.catch_warnings():
        warnings.filterwarnings('ignore', message='.*truncation.*')
        return ltp.htf(ltp_model(params[0], params[1], switching), nharmonics,
                       internal_harmonics=nharmonics + 15)


def fit_parameters(H, switching, magnitude_only=False):
    """Fit k and c of (3.39) to ``Ĝ_{-1}, Ĝ_0, Ĝ_1`` (thesis §3.4.3).

    The start value of k is the squared frequency of the peak of ``|Ĝ_0|``
    (m = 1 known), that of c is 1.
    """
    omega, G = H.components()
    K = H.nharmonics
    k0 = omega[np.argmax(np.abs(G[K, 0, 0]))] ** 2 * HOPPER_PARAMS['m']

    def model(p, w):
        return model_htf(p, switching, K)

    return ltp.fit_htf(model, H, [k0, 1.0], harmonics=[-1, 0, 1],
                       magnitude_only=magnitude_only, bounds=([1.0, 0.0], [1e4, 1e2]))


def identify(k=HOPPER_PARAMS['k'], c=HOPPER_PARAMS['c'], design=DESIGN, n_jobs=N_JOBS):
    """Whole pipeline for one plant: data, estimate, fit and eigenvalues.

    Returns a dict with the plant ``orbit`` (exact multipliers), the
    estimate ``H``, the fit, the identified ``model`` and the eigenvalues of
    its return map ``eig_identified``.
    """
    plant = hopper_plant(k=k, c=c)
    cycle = limit_cycle(plant)
    switching = switching_times(cycle[2])
    exc, y = chirp_experiment(plant, cycle, design, n_jobs=n_jobs)
    H = estimate(exc, y)
    fit = fit_parameters(H, switching)
    model = ltp_model(fit.params[0], fit.params[1], switching)
    orbit = hopper_orbit(plant, x0=cycle[0], mode0=cycle[1])
    return {'plant': plant, 'orbit': orbit, 'switching': switching, 'excitation': exc,
            'y': y, 'H': H, 'fit': fit, 'model': model,
            'eig_identified': np.sort_complex(np.linalg.eigvals(return_map(model))),
            'eig_exact': np.sort_complex(orbit.multipliers)}


def eigen_sweep(stiffness, design=DESIGN, n_jobs=N_JOBS, known=None):
    """Fig. 3.7: eigenvalues of the identified and exact return maps versus k.

    `known` maps spring constants to results of `identify` already at hand.
    """
    known = {} if known is None else known
    ident, exact, fitted = [], [], []
    for k in stiffness:
        res = known[k] if k in known else identify(k=k, design=design, n_jobs=n_jobs)
        ident.append(res['eig_identified'])
        exact.append(res['eig_exact'])
        fitted.append(res['fit'].params)
    return np.array(ident), np.array(exact), np.array(fitted)


def _analytic_eigs(stiffness):
    """Eigenvalues of (3.43) with the true parameters on each plant's orbit."""
    out, guess = [], {}
    for k in stiffness:
        orbit = hopper_orbit(hopper_plant(k=k), **guess)
        guess = {'x0': orbit.x0, 'mode0': orbit.mode0}
        out.append(np.sort_complex(np.linalg.eigvals(ltp.monodromy(hopper_ltp(orbit, k=k)))))
    return np.array(out)


# %%
# Run
# ---

def main():
    start = time.time()
    design = QUICK_DESIGN if QUICK else DESIGN
    res = identify(design=design)
    H, fit = res['H'], res['fit']
    k_hat, c_hat = fit.params
    k_true, c_true = HOPPER_PARAMS['k'], HOPPER_PARAMS['c']
    print(f"{design['nreplicas']} chirps of {design['duration']:g} s, 0-{design['f1']:g} Hz, "
          f"amplitude {design['amplitude']}: {len(H.omega)} frequencies in "
          f"{BAND} rad/s ({time.time() - start:.0f} s)")
    print(f"switching instants from the recorded cycle: {np.round(res['switching'][0], 4)} s "
          f"(orbit: {np.round(res['orbit'].switching_times, 4)} s)")
    print('\nParametric fit to G_-1, G_0, G_1 (thesis: k = 200, c = 2.12)')
    print(f"  k = {k_hat:8.3f} ± {fit.std[0]:.3f}   (true {k_true:g}, error "
          f"{100 * (k_hat / k_true - 1):+.3f} %)")
    print(f"  c = {c_hat:8.4f} ± {fit.std[1]:.4f}  (true {c_true:g}, error "
          f"{100 * (c_hat / c_true - 1):+.3f} %)")

    # theoretical HTF: the linearisation about the simulated orbit (3.39)
    theory = ltp.htf(hopper_ltp(res['orbit']), NHARMONICS, internal_harmonics=40)
    theory.name = 'theory'
    fitted = model_htf(fit.params, res['switching'], NHARMONICS)
    fitted.name = 'parametric fit'
    _, G_est = H.components()
    _, G_th = theory.components(H.omega)
    print('\nmax |Ĝ_k − G_k| / max |G_k| on the estimation grid:')
    for i, kh in enumerate(H.harmonics):
        err = np.abs(G_est[i] - G_th[i]).max() / np.abs(G_th[i]).max()
        print(f"  G_{kh:+d}: {100 * err:6.2f} %   (max |G_k| = {np.abs(G_th[i]).max():.2e})")

    # Fig. 3.5: fundamental harmonic G_0
    htfs = [theory, H, fitted]
    fmt = {'theory': 'r-', 'estimated': 'k.', 'parametric fit': 'b--'}
    cplt = None
    for Hx in htfs:
        cplt = ltp.bode_htf(Hx, None, fmt[Hx.name], harmonics=(0,), omega_limits=BAND,
                            label=[f'{Hx.name}'], ax=None if cplt is None else cplt.axes,
                            title='Hopper G_0: theory, estimate, parametric fit', ms=3)
    cplt.figure.savefig('hopper_htf_g0.png', dpi=100)

    # Fig. 3.6: G_±1, G_±2, G_±3 (magnitudes)
    fig, axes = plt.subplots(2, 3, figsize=(12, 6), sharex=True)
    for col, kh in enumerate((1, 2, 3)):
        for row, sign in enumerate((-1, 1)):
            ax = np.array([[axes[row, col]]])
            for Hx in htfs:
                ltp.bode_htf(Hx, None, fmt[Hx.name], harmonics=(sign * kh,),
                             omega_limits=BAND, plot_phase=False, ax=ax,
                             label=[Hx.name], title='', ms=3)
            axes[row, col].set_title(f'G_{sign * kh:+d}')
    fig.suptitle('Hopper higher harmonics')
    fig.tight_layout()
    fig.savefig('hopper_htf_harmonics.png', dpi=100)

    # Fig. 3.7: eigenvalues of the return map versus the spring constant
    stiffness = np.array([160.0, 200.0]) if QUICK else np.array(
        [120.0, 140.0, 150.0, 158.0, 170.0, 200.0, 240.0])
    t0 = time.time()
    ident, exact, params = eigen_sweep(stiffness, design, known={k_true: res})
    analytic = _analytic_eigs(stiffness)
    print(f'\nReturn-map eigenvalues versus k ({time.time() - t0:.0f} s)')
    print('    k   k_hat    c_hat   max|eig_id − eig_exact|  max|eig(3.43) − eig_exact|')
    for k, p, ei, ee, ea in zip(stiffness, params, ident, exact, analytic):
        print(f"  {k:4.0f} {p[0]:7.2f}  {p[1]:7.4f}   {np.abs(ei - ee).max():.2e}"
              f"                {np.abs(ea - ee).max():.2e}")
    fig, (ax_re, ax_im) = plt.subplots(2, 1, sharex=True, figsize=(6, 6))
    for j in range(2):
        lab = (lambda s: s if j == 0 else None)
        ax_re.plot(stiffness, exact[:, j].real, 'k-', label=lab('exact (saltation)'))
        ax_re.plot(stiffness, analytic[:, j].real, 'o', mfc='none', color='C1',
                   label=lab('analytic (3.43)'))
        ax_re.plot(stiffness, ident[:, j].real, 'x', color='C0', label=lab('identified'))
        ax_im.plot(stiffness, exact[:, j].imag, 'k-')
        ax_im.plot(stiffness, analytic[:, j].imag, 'o', mfc='none', color='C1')
        ax_im.plot(stiffness, ident[:, j].imag, 'x', color='C0')
    ax_re.set_ylabel('Re(eigenvalue)')
    ax_im.set_ylabel('Im(eigenvalue)')
    ax_im.set_xlabel('spring stiffness k [N/m]')
    ax_re.legend()
    ax_re.set_title('Hopper return map: identified vs exact')
    fig.tight_layout()
    fig.savefig('hopper_identified_eigenvalues.png', dpi=100)
    print(f'\ntotal {time.time() - start:.0f} s')
    return res, (stiffness, ident, exact, analytic, params)


if __name__ == '__main__':
    main()
