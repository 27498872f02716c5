"""Steps of the data-to-controller chain shared by the control examples.

1. `record`: input–output records of a hybrid plant about its orbit
   (output deviation ``y − ȳ(t)`` sampled every ``dt``), optionally with
   white measurement noise on input and output at a given SNR (thesis
   §3.7.5: ``SNR = (A_signal / A_noise)²`` with RMS amplitudes).
2. `output_lqg`: periodic LQG on a discrete LTP model, weighting the
   output: ``Σ y² + r u²``, process noise on the input, sensor noise ``rn``;
   `band_limited_lqg`: the same kept inside the band the data excited.
3. `push_recovery`: response to a velocity push, open and closed loop, and
   the strides taken to return within 1 % of the orbit.
4. `record_experiments`: records of multi-experiment designs (channels, experiments,
   samples; e.g. multisines in several bands), each started on the orbit.
"""

import control as ct
import numpy as np
from joblib import Parallel, delayed
from scipy.signal import butter

import ltpcontrol as ltp


def _orbit_mode(orbit, t):
    return int(orbit._flow.evaluate([np.mod(t, orbit.period)])[1][0])


def _simulate_record(plant, orbit, exc, seg, solver):
    a, b = exc.segments[seg]
    t = exc.time[a:b]
    x0 = orbit(np.mod(t[0], orbit.period))
    resp = ltp.simulate_hybrid(plant, t, x0, _orbit_mode(orbit, t[0]),
                               inputs=lambda s: np.atleast_1d(exc.signal(np.atleast_1d(s))),
                               **solver)
    xbar = orbit(np.mod(t, orbit.period))
    ybar = [plant.outfcn(tk, xk, orbit.u0, orbit.params)[0] for tk, xk in zip(t, xbar.T)]
    return resp.outputs - np.array(ybar)


def record(plant, orbit, exc, *, snr=None, seed=0, solver=None, n_jobs=2):
    """Records ``(t, u, y)`` of every analysis segment of `exc`, started on the orbit.

    Each segment of the excitation is an independent experiment that starts
    on the orbit at the segment's phase.  With `snr`, white noise of RMS
    ``rms(signal) / sqrt(snr)`` is added to the recorded input and output.
    """
    solver = solver or {'rtol': 1e-8, 'atol': 1e-11}
    ys = Parallel(n_jobs=n_jobs)(delayed(_simulate_record)(plant, orbit, exc, seg, solver)
                                 for seg in range(len(exc.segments)))
    u = exc.inputs.copy()
    y = np.concatenate(ys)
    if snr is not None:
        rng = np.random.default_rng(seed)
        u = u + rng.standard_normal(u.shape) * np.sqrt(np.mean(u ** 2) / snr)
        y = y + rng.standard_normal(y.shape) * np.sqrt(np.mean(y ** 2) / snr)
    # one channel, one experiment per segment: shape (1, nexp, L)
    return exc.time, np.reshape(u, (1, -1, u.shape[-1])), np.reshape(y, (1, -1, y.shape[-1]))


def output_lqg(model, r, rn, qn=1.0):
    """Periodic LQG of a discrete LTP model for the cost ``Σ y[k]² + r u[k]²``."""
    C = model.C.sample(model.nsteps)
    Q = np.einsum('kij,kil->kjl', C, C)
    return ltp.lqg(model, Q, [[r]], [[qn]], [[rn]], name='lqg')


def band_limited_lqg(model, dt, band_top, r, rn, order=4, qn=1.0):
    """`output_lqg` of `model` sampled at `dt`, acting only inside ``[0, band_top]`` Hz.

    The command passes a Butterworth low-pass of `order` with its cutoff at
    `band_top` (``ltpcontrol.lqg(..., input_filter=F)``, Tustin-sampled),
    and the cost weighs the output through the harmonics ``n`` of ``C(t)``
    inside the band (``n ≤ band_top·T``).
    """
    period = model.period
    dsys = ltp.sample_system(model, dt)
    C = ltp.PeriodicMatrix(model.C.fourier(int(band_top * period)), period).sample(dsys.nsteps)
    b, a = butter(order, 2 * np.pi * band_top, analog=True)
    F = ct.sample_system(ct.ss(ct.tf(b, a)), dt, method='tustin')
    return ltp.lqg(dsys, np.einsum('kij,kil->kjl', C, C), [[r]], [[qn]], [[rn]],
                   input_filter=F, name='lqg')


def strides_to_recover(resp, orbit, t_push, nstrides, tol=0.01):
    """Strides after the push until the state stays within `tol` of the orbit.

    The stroboscopic deviation at ``t_push + kT`` is measured per plant
    state relative to that state's range on the orbit.
    """
    T = orbit.period
    scale = np.ptp(orbit.states, axis=1)
    ref = orbit(np.mod(t_push, T))
    n = orbit.plant.nstates
    dev = np.array([np.max(np.abs(resp.states[:n, np.argmin(np.abs(resp.time - t_push - k * T))]
                                  - ref) / scale) for k in range(nstrides + 1)])
    above = np.nonzero(dev > tol)[0]
    strides = 0 if above.size == 0 else int(above[-1] + 1)
    return (strides if strides <= nstrides else None), dev


def push_recovery(plant, orbit, controller, t_push, dv, nstrides, *, npoints=40,
                  saturation=None, progress=False):
    """Open- and closed-loop responses to a push ``Δv`` on the state at `t_push`."""
    T = orbit.period
    t = t_push + np.linspace(0, nstrides * T, nstrides * npoints + 1)
    x0 = orbit(np.mod(t_push, T)) + dv
    mode = _orbit_mode(orbit, t_push)
    opened = ltp.simulate_hybrid(plant, t, x0, mode)
    closed = ltp.closed_loop_response(plant, controller, orbit, t, x0, mode0=mode,
                                      saturation=saturation, progress=progress)
    return opened, closed


def push_study(plant, orbit, controller, mode, dv, nstrides, dt, *, progress=False):
    """Push ``Δv`` mid-`mode` (on a sample instant of `dt`): responses and figures.

    Returns ``t_push, (opened, closed), figures`` with the strides to
    recover open and closed loop and the closed loop's peak actuator effort.
    """
    t_mode = orbit.time[orbit.modes == plant.mode_index(mode)]
    t_push = round(0.5 * (t_mode[0] + t_mode[-1]) / dt) * dt
    opened, closed = push_recovery(plant, orbit, controller, t_push, dv, nstrides,
                                   progress=progress)
    figures = {'strides open': strides_to_recover(opened, orbit, t_push, nstrides)[0],
               'strides closed': strides_to_recover(closed, orbit, t_push, nstrides)[0],
               'effort': float(np.max(np.abs(closed.inputs)))}
    return t_push, (opened, closed), figures


def _simulate_experiment(plant, orbit, exc, row, solver):
    signal = exc.signal
    # a scalar time gives the (channels, experiments) values at that instant
    resp = ltp.simulate_hybrid(plant, exc.time, orbit.x0, orbit.mode0,
                               inputs=lambda s: signal(s)[0, row], **solver)
    ybar = [plant.outfcn(tk, xk, orbit.u0, orbit.params)[0]
            for tk, xk in zip(exc.time, orbit(exc.time).T)]
    return np.atleast_2d(resp.outputs)[0] - np.array(ybar)


def record_experiments(plant, orbit, excitations, *, solver=None, n_jobs=2, progress=False):
    """Records ``(t, u, y)`` of multi-experiment designs, each row started on the orbit at t = 0.

    `excitations` is a list of single-input `ltpcontrol.Excitation` of equal
    length (e.g. `ltpcontrol.multisine` in several bands); ``u`` and ``y``
    have shape (1, experiments, samples), channels first (noise-free).
    """
    from tqdm.auto import tqdm
    solver = solver or {'rtol': 1e-8, 'atol': 1e-11}
    jobs = [(exc, row) for exc in excitations
            for row in range(exc.inputs.shape[1])]
    ys = Parallel(n_jobs=n_jobs)(delayed(_simulate_experiment)(plant, orbit, exc, row, solver)
                                 for exc, row in tqdm(jobs, desc='experiments',
                                                      disable=not progress, leave=False))
    u = np.concatenate([exc.inputs for exc in excitations], axis=1)
    return excitations[0].time, u, np.array(ys)[np.newaxis]
