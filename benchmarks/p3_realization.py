"""P3: Floquet-form realization of identified lifted models.

Workload: 20 seeded random discrete-time LTP systems in Floquet form (2
states, one input and output, N = 8 steps per period, B[k] and C[k] with one
harmonic), lifted with K = 1 harmonic (`ltp.lift`, 6 real states) and
identified by `ltp.fdsubspace` from 60 noise-free points of the lifted
frequency response, so that each model is in arbitrary coordinates.  The
identified model is handed to ``floquet_realization`` with method 'direct'
(eigenvalue ladders, no search) and 'pso' (thesis particle swarm with
Nelder-Mead refinement, default options, seeded).

Reported: time per model of each method, their ratio and success rates.
A realization is counted as successful when its ``success`` flag is set;
its accuracy is the largest error of the recovered Floquet exponents (the
eigenvalues of the constant A_F) against those of the true system.  The
checks require 'direct' to succeed on every model with exponents accurate
to 1e-8.  The swarm takes seconds per model, so in the full run it is run
on the first `pso_models` models only and its time per model is the mean
over those (said in the JSON file).

``floquet_realization`` is looked up as ``ltpcontrol.floquet_realization``
and then in ``ltpcontrol._identification.realization``; when neither exists the workload
is reported as not available.
"""

import warnings

import numpy as np

import control as ct

from _common import median_time, not_available, row, timed

import ltpcontrol as ltp

TOL = 1e-8
NSTEPS, K, NP = 8, 1, 2
FULL = dict(models=20, pso_models=8, repeats=3, pso_options=None, minimize_options=None)
QUICK = dict(models=3, pso_models=1, repeats=1, pso_options={'iters': 20},
             minimize_options={'maxfev': 300})


def _function():
    fn = getattr(ltp, 'floquet_realization', None)
    if fn is None:
        try:
            from ltpcontrol._identification.realization import floquet_realization as fn
        except ImportError:
            fn = None
    return fn


def make_model(seed):
    """True Floquet-form LTP and the lifted model identified from its response."""
    rng = np.random.default_rng(seed)
    if seed % 2:
        r, th = rng.uniform(0.4, 0.9), rng.uniform(0.1, 0.3)
        A = r * np.array([[np.cos(th), np.sin(th)], [-np.sin(th), np.cos(th)]])
    else:
        A = np.diag(np.sort(rng.uniform(-0.8, 0.9, NP)))
    Q = rng.standard_normal((NP, NP)) + 2 * np.eye(NP)
    A = Q @ A @ np.linalg.inv(Q)
    k = np.arange(NSTEPS)
    B = rng.standard_normal((1, NP, 1)) \
        + 0.5 * rng.standard_normal((1, NP, 1)) * np.cos(2 * np.pi * k / NSTEPS)[:, None, None]
    C = rng.standard_normal((1, 1, NP)) \
        + 0.5 * rng.standard_normal((1, 1, NP)) * np.sin(2 * np.pi * k / NSTEPS)[:, None, None]
    sysd = ltp.ltpss(A, B, C, 0, period=1.0, dt=1.0 / NSTEPS, name=f'model{seed}')
    lifted = ltp.lift(sysd, nharmonics=K)
    omega = np.linspace(0.1, 0.95 * np.pi * NSTEPS, 60)
    ident = ltp.fdsubspace(ct.frd(lifted, omega), order=lifted.nstates)
    return sysd, ident


def exponent_error(realization, sysd):
    if realization is None:
        return np.inf
    got = np.sort_complex(np.linalg.eigvals(realization.A(0.0)))
    true = np.sort_complex(np.linalg.eigvals(sysd.A(0.0)))
    return float(np.abs(got - true).max())


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    work = f"realize {cfg['models']} identified lifted models (n=6)"
    fn = _function()
    if fn is None:
        return [not_available('P3', work, 'floquet_realization is not in ltpcontrol')]
    models = [make_model(seed) for seed in range(cfg['models'])]

    def call(ident, **kw):
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            return fn(ident, K, NSTEPS, progress=False, return_info=True, **kw)

    log(f"P3: 'direct' on {len(models)} models")
    t_direct, d_ok, d_err = [], [], []
    for sysd, ident in models:
        el, _, (real, res) = median_time(lambda: call(ident, method='direct'), cfg['repeats'])
        t_direct.append(el)
        d_ok.append(bool(res.success))
        d_err.append(exponent_error(real, sysd))
    log(f"P3: 'pso' on {cfg['pso_models']} models")
    t_pso, p_ok, p_err, p_dist = [], [], [], []
    for seed, (sysd, ident) in enumerate(models[:cfg['pso_models']]):
        opts = {}
        if cfg['pso_options']:
            opts['pso_options'] = cfg['pso_options']
        if cfg['minimize_options']:
            opts['minimize_options'] = cfg['minimize_options']
        el, (real, res) = timed(call, ident, method='pso', seed=seed, **opts)
        t_pso.append(el)
        p_ok.append(bool(res.success))
        p_err.append(exponent_error(real, sysd))
        p_dist.append(float(res.corrected_distance))
    per_direct = float(np.mean(t_direct))
    per_pso = float(np.mean(t_pso))
    rate_direct = float(np.mean(d_ok))
    rate_pso = float(np.mean(p_ok))
    err_direct = float(np.max(d_err))
    err_pso = float(np.max(p_err))
    matched = rate_pso == 1.0 and err_pso <= TOL
    return [row(
        'P3', work, ours="floquet_realization 'direct'",
        peer="floquet_realization 'pso'" + (' (quick: few iterations)' if quick else ''),
        t_ours=per_direct, t_peer=per_pso,
        target='>= 100x, 100% success', target_met=per_pso / per_direct >= 100
        and rate_direct == 1.0, err_ours=err_direct, err_peer=err_pso, tol=TOL,
        checks={'direct succeeds on every model': rate_direct == 1.0,
                'direct exponents <= tol': err_direct <= TOL},
        matched=matched,
        notes=(f"times per model; success direct {sum(d_ok)}/{len(d_ok)}, "
               f"pso {sum(p_ok)}/{len(p_ok)}"),
        extra=dict(direct_times=t_direct, direct_success=d_ok, direct_exponent_errors=d_err,
                   pso_times=t_pso, pso_success=p_ok, pso_exponent_errors=p_err,
                   pso_corrected_distance=p_dist, pso_models=len(t_pso),
                   success_rate_direct=rate_direct, success_rate_pso=rate_pso,
                   pso_options=cfg['pso_options'], minimize_options=cfg['minimize_options']))]
