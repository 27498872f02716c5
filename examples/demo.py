"""Identify the thesis's Mathieu-type LTP system from 400 sine experiments.

Thesis §4.2.9 end to end: simulate the 400 cosine experiments of eq. (4.117)
with the batched exact simulator, compute the lifted frequency response,
identify the lifted LTI model by frequency-domain subspace identification,
realize it as a Floquet-form LTP and convert it to continuous time.  Prints
the matrix errors of eq. (4.125) and the N-RMSE of Table 4.2 beside the
thesis's numbers and writes the HTF comparison of Fig. 4.2 to
``mathieu_htf.png`` in the current directory.

Run with ``python examples/demo.py`` (about 10-20 s on two cores).
"""

import time

import matplotlib
matplotlib.use('Agg')
import numpy as np

import ltpcontrol as ltp
from mathieu import mathieu_ltp

T, TS = 0.5, 0.01                 # period 0.5 s, records sampled at 100 Hz
OVERSAMPLE = 4                    # the simulator steps at 400 Hz
THESIS_ERRORS = (0.0003, 0.0049, 0.0056)                 # eq. (4.125): A, B, C
THESIS_NRMSE = (0.0030, 0.0042, 0.0040)                  # Table 4.2


def sine_data(sys, duration=30.0):
    """Responses to cos(2π(0.15 + 0.1k)t), k = 1..400 (eq. 4.117).

    All inputs repeat every 20 s, so 30 s records give a leakage-free 20 s
    window after a 10 s transient.  The input is interpolated linearly
    between the 400 Hz simulation steps; the records keep every 4th sample.
    """
    freqs = 0.15 + 0.1 * np.arange(1, 401)
    t = np.arange(int(round(duration / TS)) * OVERSAMPLE) * TS / OVERSAMPLE
    u = np.cos(2 * np.pi * freqs[:, None] * t[None, :])
    y = ltp.forced_response(sys, t, u[None]).outputs
    return t[::OVERSAMPLE], u[:, ::OVERSAMPLE], y[:, :, ::OVERSAMPLE]


def validation_inputs(t):
    """Table 4.2 inputs of period π (sine, square wave, periodic ramp)."""
    return {'single sine': np.sin(2 * t), 'square wave': np.sign(np.sin(2 * t)),
            'periodic ramp': 2 * ((t / np.pi) % 1) - 1}


def main():
    start = time.perf_counter()
    true = mathieu_ltp()
    data = sine_data(true)
    models = {}
    for conversion in ('tustin', 'refit'):
        models[conversion] = ltp.identify_ltp(
            data, T, 2, 1, q=50, conversion=conversion, transient=10.0,
            input_hold='foh', hold_step=TS / OVERSAMPLE, name=f'estimate ({conversion})')

    print(f"Identified an LTP model from {data[1].shape[0]} sine experiments "
          f"({data[0][-1] + TS:.0f} s at {1 / TS:.0f} Hz each)")
    print("Floquet exponents, true:      ", np.round(np.sort_complex(true.poles()), 6))
    print("Floquet exponents, identified:",
          np.round(np.sort_complex(models['refit'].poles()), 6), "\n")
    print("Eq. (4.125), controllable canonical form (relative errors)")
    print(f"{'':28s}{'A':>10s}{'B(t)':>10s}{'C(t)':>10s}")
    print(f"{'thesis':28s}" + "".join(f"{e:10.4f}" for e in THESIS_ERRORS))
    for conversion, label in (('tustin', 'inverse Tustin (thesis)'),
                              ('refit', 'exact sampling + refit')):
        err = ltp.matrix_errors(ltp.to_canonical(models[conversion]), ltp.to_canonical(true))
        print(f"{label:28s}" + "".join(f"{e:10.1e}" for e in err[:3]))

    # N-RMSE = ||y - ŷ|| / ||y|| over 0 <= t < 40 s from x(0) = 0, 100 Hz samples.
    t = np.arange(0, 40, TS)
    print("\nTable 4.2, N-RMSE over 0-40 s from zero initial state")
    print(f"{'':28s}" + "".join(f"{name:>15s}" for name in validation_inputs(t)))
    print(f"{'thesis':28s}" + "".join(f"{e:15.4f}" for e in THESIS_NRMSE))
    for conversion, label in (('tustin', 'inverse Tustin (thesis)'),
                              ('refit', 'exact sampling + refit')):
        row = [ltp.nrmse(ltp.forced_response(true, t, u).outputs,
                         ltp.forced_response(models[conversion], t, u).outputs)
               for u in validation_inputs(t).values()]
        print(f"{label:28s}" + "".join(f"{e:15.1e}" for e in row))

    # Fig. 4.2: HTF components G_-1, G_0, G_1 of the true and estimated systems.
    title = 'Mathieu system: true (solid) and identified (dashed) HTF, thesis Fig. 4.2'
    cplt = ltp.bode_htf(ltp.htf(true, 1), None, '-', omega_limits=(0.5, 200),
                        omega_num=300, title=title,
                        label=[f"true G_{k}" for k in (-1, 0, 1)])
    ltp.bode_htf(ltp.htf(models['refit'], 1), None, '--', omega_limits=(0.5, 200),
                 omega_num=300, ax=cplt.axes, title=title,
                 label=[f"identified G_{k}" for k in (-1, 0, 1)])
    cplt.figure.savefig('mathieu_htf.png', dpi=120)
    print(f"\nwrote mathieu_htf.png; total {time.perf_counter() - start:.1f} s")


if __name__ == '__main__':
    main()
