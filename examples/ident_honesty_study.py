"""Is ``success`` honest?  Silent failures of `identify_ltp` on five kinds of plants.

Five plants of period T = 0.5 s, as a legged-locomotion user would build
them:

* ``leg``: hopper leg ``m ẍ + c(t) ẋ + k(t) x = f`` with k ±50 %, c ±30 %
  and a first-order actuator 20 times faster (3 states);
* ``gain``: first-order plant with a modulated input gain (1 state);
* ``mathieu``: damped oscillator with periodic stiffness ±40 % (2 states);
* ``stance``: stance/flight switching of stiffness, damping and the
  measured output (smoothed steps of A(t) and C(t), 2 states);
* ``impact``: clock-driven impacting hopper, an oscillator whose velocity
  is reversed with restitution 0.7 at every period (a hybrid plant,
  simulated by its own stepper with the input held between samples, ZOH).

Each plant gets single-sine records (26 lines up to 3.3 ω_p, 16 periods after
16 settling periods, 32 samples per period) with white output noise at 40, 30, 20 and 10 dB;
in one of three record sets per SNR the start-up transient is left in the
analysis window (``transient=0``).  Every record set is identified four
ways with the default settings and the records' input hold: time records
with K = 1 and K = 2, and
the lifted FRD path with K = 1 from data of K harmonics (fewer than the
model produces) and of 3K + 1.  Each model is simulated on a fresh
record of low-pass filtered noise (cut-off 2 ω_p, 40 periods) next to the
noise-free plant.

A *silent failure* is a model with ``success=True``, no warning, and a
fresh NRMSE above 0.1 or above 10 times the best of the four models from
the same records (the latter counted only above 0.01, the size of the
smallest validation tolerance the script could flag).

Run ``python examples/ident_honesty_study.py [plant,plant,...]`` (long:
about an hour on one core, so the plants can be split over processes;
``LTP_EXAMPLES_QUICK=1`` takes one SNR).
"""

import os
import sys
import time
import warnings

import numpy as np
import scipy.linalg
import scipy.signal

import ltpcontrol as ltp

T = 0.5
WP = 2 * np.pi / T
N = 32
DT = T / N
NPER, SETTLE = 16, 16


def leg():
    k0, c0, tau = 400.0, 8.0, 0.02
    A = np.zeros((3, 3, 3), complex)
    A[1] = [[0, 1, 0], [-k0, -c0, 1], [0, 0, -1 / tau]]
    A[0, 1, 0] = A[2, 1, 0] = -0.25 * k0
    A[0, 1, 1], A[2, 1, 1] = 0.15j * c0, -0.15j * c0
    return ltp.ltpss(ltp.PeriodicMatrix(A, T), [[0], [0], [1 / tau]], [[1, 0, 0]], 0,
                     period=T), 3


def gain():
    return ltp.ltpss([[-6.0]], lambda t: np.array([[1 + 0.5 * np.cos(WP * t)]]),
                     [[1.0]], 0, period=T), 1


def mathieu():
    return ltp.ltpss(lambda t: np.array([[0, 1], [-150 * (1 + 0.4 * np.cos(WP * t)), -4.0]]),
                     [[0], [1]], [[1, 0]], 0, period=T), 2


def stance():
    def s(t):                       # smoothed stance (1) / flight (0) indicator
        return 0.5 * (1 + np.tanh(8 * np.cos(WP * t)))

    return ltp.ltpss(lambda t: np.array([[0, 1], [-(60 + 240 * s(t)), -(3 + 6 * s(t))]]),
                     [[0], [1]], lambda t: np.array([[1.0, 0.05 * (1 - s(t))]]), 0,
                     period=T), 2


class Impact:
    """Oscillator ``ẍ + 2ζω ẋ + ω² x = u`` whose velocity is reversed with restitution
    e at every t = kT (an impact at a fixed phase), input held between samples."""

    nstates, ninputs, noutputs = 2, 1, 1

    def __init__(self, w=14.0, zeta=0.1, e=0.7):
        A = np.array([[0, 1], [-w ** 2, -2 * zeta * w]])
        M = scipy.linalg.expm(np.block([[A, np.array([[0], [1]])], [np.zeros((1, 3))]]) * DT)
        self.Phi, self.Gam = M[:2, :2], M[:2, 2]
        self.R = np.diag([1.0, -e])

    def simulate(self, u):
        """Output samples for input samples `u` (..., L), from rest."""
        u = np.asarray(u)
        flat = u.reshape(-1, u.shape[-1])
        y = np.zeros_like(flat)
        for i, row in enumerate(flat):
            x = np.zeros(2)
            for k in range(row.size):
                y[i, k] = x[0]
                x = self.Phi @ x + self.Gam * row[k]
                if (k + 1) % N == 0:
                    x = self.R @ x
        return y.reshape(u.shape)


PLANTS = {'leg': leg, 'gain': gain, 'mathieu': mathieu, 'stance': stance,
          'impact': lambda: (Impact(), 2)}


def simulate(plant, t, u, hold='foh'):
    if isinstance(plant, Impact):
        return plant.simulate(u)
    return np.asarray(ltp.forced_response(plant, t, u, input_hold=hold).outputs).reshape(
        np.shape(u))


def records(plant, snr, seed, rng):
    # NPER = SETTLE: the lines lie on the grid of the whole record as well, so that
    # the transient can be left in the analysis window
    bins = np.array([b for b in range(1, 4 * NPER) if (2 * b) % NPER][::2])[:26]
    lines = bins * 2 * np.pi / (NPER * T)
    t = np.arange((NPER + SETTLE) * N) * DT
    u = np.cos(lines[:, None] * t)[None]
    y = simulate(plant, t, u)
    sigma = np.sqrt(np.mean(y ** 2) / 10 ** (snr / 10))
    return t, u, y + sigma * rng.standard_normal(y.shape)


def fresh(model, plant):
    L = 40 * N
    b, a = scipy.signal.butter(4, 2 * WP * DT / np.pi)
    u = scipy.signal.lfilter(b, a, np.random.default_rng(7).standard_normal(L))
    t = np.arange(L) * DT
    y = simulate(plant, t, u[None]).ravel()
    hold = 'zoh' if isinstance(plant, Impact) else 'foh'
    yhat = np.asarray(ltp.forced_response(model, t, u, input_hold=hold).outputs).ravel()
    err = np.linalg.norm(yhat - y) / np.linalg.norm(y)
    return float(err) if np.isfinite(err) else np.inf


def identify(data, n, K, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        try:
            model, info = ltp.identify_ltp(data, T, n, K, return_info=True, **kw)
        except Exception as err:                      # a refusal is honest, not silent
            return None, False, [f"{type(err).__name__}: {err}"]
    return model, info.success, [str(w.message) for w in caught]


def main():
    quick = os.environ.get('LTP_EXAMPLES_QUICK')
    snrs = (20,) if quick else (40, 30, 20, 10)
    names = sys.argv[1].split(',') if len(sys.argv) > 1 else list(PLANTS)
    rows, start = [], time.time()
    for pname in names:
        plant, n = PLANTS[pname]()
        for snr in snrs:
            for rep in range(3):
                rng = np.random.default_rng(1000 * snr + rep)
                t, u, y = records(plant, snr, rep, rng)
                transient = 0.0 if rep == 2 else SETTLE * T
                ways = {}
                # the records' hold is given: the default warns that it is assumed
                hold = 'zoh' if isinstance(plant, Impact) else 'foh'
                for K in (1, 2):
                    ways[f'records K={K}'] = identify((t, u, y), n, K, transient=transient,
                                                      input_hold=hold)
                for Kd, tag in ((1, 'FRD K=1, 1 harm.'), (4, 'FRD K=1, 4 harm.')):
                    with warnings.catch_warnings():
                        warnings.simplefilter('ignore')
                        G = ltp.lifted_frequency_response((t, u, y), T, Kd,
                                                          transient=transient,
                                                          input_hold=hold, unusable='skip')
                    ways[tag] = identify(G, n, 1)
                errs = {k: (fresh(m, plant) if m is not None else np.inf)
                        for k, (m, _, _) in ways.items()}
                best = min(errs.values())
                for k, (m, ok, warns) in ways.items():
                    e = errs[k]
                    silent = ok and not warns and (e > 0.1 or (e > 10 * best and e > 0.01))
                    rows.append((pname, snr, rep == 2, k, ok, len(warns), e, best, silent))
                    print(f"{pname:8s} {snr:3d} dB {'transient' if rep == 2 else '         '} "
                          f"{k:18s} success={ok!s:5s} warnings={len(warns)} fresh={e:.3g} "
                          f"best={best:.3g}{'  SILENT' if silent else ''}", flush=True)
                    for w in warns:
                        print(f"{'':14s}| {w[:150]}", flush=True)
    print(f"\n{len(rows)} identifications in {time.time() - start:.0f} s\n")
    print(f"{'plant':8s} {'SNR':>4s} {'n':>4s} {'success':>8s} {'flagged':>8s} "
          f"{'fresh>0.1':>10s} {'median fresh (succ.)':>21s} {'silent':>7s}")
    for pname in names:
        for snr in snrs:
            sel = [r for r in rows if r[0] == pname and r[1] == snr]
            succ = [r for r in sel if r[4] and not r[5]]
            med = np.median([r[6] for r in succ]) if succ else np.nan
            print(f"{pname:8s} {snr:4d} {len(sel):4d} {len(succ):8d} {len(sel) - len(succ):8d} "
                  f"{sum(r[6] > 0.1 for r in sel):10d} {med:21.3g} {sum(r[8] for r in sel):7d}")
    print(f"\nsilent failures: {sum(r[8] for r in rows)} of {len(rows)}")


if __name__ == '__main__':
    main()
