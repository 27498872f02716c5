"""
From data to a periodic controller: the simplified hopper
=========================================================

The whole chain on the simplified hopper of thesis §3.4-3.5 (a mass on a
spring whose damper acts only while it moves up, pumped by ``cos 2πt``):

1. **Data.**  Phase-shifted chirps (the thesis's excitation, §3.3.3) on the
   actuator perturbation ``u``, started on the limit cycle; the output is
   the height deviation ``y = x − x̄(t)`` sampled 25 times a period.  A
   second data set adds white noise to input and output at SNR 12.5
   (§3.7.5).
2. **Model.**  A periodic ARX model (`ltpcontrol.identify_arx`), realized
   with past outputs and inputs as its states.  Full-state feedback of an
   identified model is meaningless (its states are not the robot's), so
3. **Design** is output feedback: periodic LQG (`ltpcontrol.lqg`) for the
   cost ``Σ y² + r u²``, a sampled-data controller on the plant's clock.
4. **Verification on the hybrid plant**, not on the model: the Floquet
   multipliers of the closed loop's orbit (`ltpcontrol.closed_loop_orbit`,
   exact return map with the events' saltation matrices), the same design
   on the true linearization (`ltpcontrol.linearize_orbit` sampled with
   zero-order hold) for comparison, and the recovery from a push in the
   falling phase (`ltpcontrol.closed_loop_response`): strides until the state is
   back within 1 % of the orbit (per state, relative to its range on the
   orbit), with the actuator effort.

With noise on both signals at SNR 12.5, least squares (an equation-error
fit) is biased: the identified model's multipliers shrink towards zero, and
the design on it removes only a fraction of the multiplier; the example
prints both.  Set ``LTP_EXAMPLES_QUICK=1`` for shorter records.
"""

import os
import time

import matplotlib

matplotlib.use('Agg')

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402
from control_chain import output_lqg, push_study, record  # noqa: E402
from hopper import PERIOD, hopper_orbit, hopper_plant  # noqa: E402

QUICK = os.environ.get('LTP_EXAMPLES_QUICK', '0') == '1'

#: Samples per period of the records, the model and the controller.
NSAMPLES = 25
#: Chirp design: replicas shifted by T/R, 0-10 Hz, amplitude 0.3 N.
CHIRPS = {'nreplicas': 3, 'duration': 6.0 if QUICK else 12.0, 'f0': 0.0, 'f1': 10.0,
          'amplitude': 0.3}
#: ARX orders (past outputs, past inputs).
ORDERS = (2, 3)
#: LQG: input weight r, sensor noise rn (process noise 1 on the input).
R_WEIGHT, RN = 1e-4, 1e-6
#: Push: velocity change (m/s) in the middle of the lossless phase.
PUSH, NSTRIDES = 0.3, 12
#: Actuator effort bound (N) that the closed loop must respect.
EFFORT_BOUND = 6.0
#: Signal-to-noise ratio of the noisy data set.
SNR = 12.5


def run(progress=False):
    """The chain; returns the figures printed by the example."""
    start = time.perf_counter()
    plant = hopper_plant()
    orbit = hopper_orbit(plant)
    dt = PERIOD / NSAMPLES
    exc = ltp.chirp_replicas(PERIOD, dt=dt, **CHIRPS)
    out = {'open': float(np.abs(orbit.multipliers).max())}

    # data → periodic ARX → LQG → closed-loop return map on the hybrid plant
    designs = {}
    for label, snr in (('identified', None), ('identified, SNR 12.5', SNR)):
        # one process in the quick run: the documentation build runs beside the tests
        data = record(plant, orbit, exc, snr=snr, seed=1, n_jobs=1 if QUICK else 2)
        model = ltp.identify_arx(data, PERIOD, *ORDERS)
        out[f'{label} model'] = float(np.abs(ltp.floquet_multipliers(model)).max())
        designs[label] = output_lqg(model, R_WEIGHT, RN)
    true_model = ltp.sample_system(ltp.linearize_orbit(plant, orbit), dt)
    designs['true linearization'] = output_lqg(true_model, R_WEIGHT, RN)
    for label, ctrl in designs.items():
        out[label] = ltp.closed_loop_orbit(plant, ctrl, orbit).dominant_multiplier

    # push in the middle of the lossless (falling) phase, on a sample instant
    t_push, (opened, closed), figures = push_study(
        plant, orbit, designs['identified'], 'lossless', np.array([0.0, PUSH]), NSTRIDES, dt,
        progress=progress)
    out.update(figures)
    out['seconds'] = time.perf_counter() - start
    return out, orbit, (opened, closed), t_push


def main():
    out, orbit, (opened, closed), t_push = run(progress=True)
    reduction = {k: out['open'] - out[k] for k in
                 ('identified', 'identified, SNR 12.5', 'true linearization')}
    print(f"dominant Floquet multiplier of the hopping orbit (|μ|), T = {PERIOD} s")
    print(f"  open loop                              {out['open']:.4f}")
    for label in ('identified', 'identified, SNR 12.5', 'true linearization'):
        share = reduction[label] / reduction['true linearization']
        print(f"  LQG on the {label:28s}{out[label]:.4f}  ({100 * share:.0f} % of the "
              "true-model reduction)")
    for label in ('identified', 'identified, SNR 12.5'):
        print(f"  open-loop |μ| of the model {label:24s}{out[label + ' model']:.4f}")
    print(f"push of {PUSH} m/s at t = {t_push:.2f} s: strides to within 1 % of the orbit: "
          f"open {out['strides open']}, closed {out['strides closed']}")
    print(f"actuator effort |u| <= {out['effort']:.2f} N (bound {EFFORT_BOUND} N)")
    print(f"total {out['seconds']:.1f} s")

    fig, axes = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    ref = orbit(np.mod(opened.time, orbit.period))
    axes[0].plot(opened.time, opened.states[0] - ref[0], label='open loop')
    axes[0].plot(closed.time, closed.states[0] - ref[0], label='periodic LQG')
    axes[0].set_ylabel('x − x̄ (m)')
    axes[0].legend()
    axes[0].set_title('Simplified hopper: recovery from a push while falling')
    axes[1].plot(closed.time, closed.inputs, drawstyle='steps-post', color='C1')
    axes[1].set_ylabel('u (N)')
    axes[1].set_xlabel('time (s)')
    fig.tight_layout()
    fig.savefig('hopper_control.png', dpi=120)


if __name__ == '__main__':
    main()
