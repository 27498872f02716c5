"""
VHOP hopping limit cycle
========================

Analogue of thesis Fig. 3.12.  The vertical hopper with the pumping force
``u(t) = 75 cos(2π t / 0.33)`` is released from rest 0.3 m above the
ground, simulated for 20 periods and its periodic orbit is then refined by
shooting.  The body height and velocity on the limit cycle are drawn with
the stance phase in red and the flight phase in blue; the lower panel shows
the body and toe heights over one period, with the touchdown impact that
resets the toe velocity to zero.
"""

import matplotlib

matplotlib.use('Agg')

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from vhop import vhop_orbit  # noqa: E402


def main():
    # the orbit of the other VHOP examples (computed once per documentation
    # build), drawn on a finer grid of 660 points: the state from the orbit's
    # own interpolation, the mode from its event times
    orbit = vhop_orbit()
    t = np.arange(660) * orbit.period / 660
    states = orbit(t)
    modes = np.array(orbit.mode_sequence)[np.searchsorted(orbit.switching_times, t,
                                                          side='right')]
    stance = modes == orbit.plant.mode_index('stance')
    h, ht, hdot = states[0], states[1], states[2]
    fig, (ax_phase, ax_time) = plt.subplots(2, 1, figsize=(6, 7))
    for mask, color, label in [(stance, 'red', 'stance'), (~stance, 'blue', 'flight')]:
        ax_phase.plot(h[mask], hdot[mask], '.', ms=2, color=color, label=label)
    ax_phase.set_xlabel('body height h [m]')
    ax_phase.set_ylabel('body velocity dh/dt [m/s]')
    ax_phase.legend()
    ax_phase.set_title(f'VHOP limit cycle, T = {orbit.period} s, '
                       f'|multipliers| ≤ {np.abs(orbit.multipliers).max():.3f}')
    ax_time.plot(t, h, 'k-', label='body h')
    ax_time.plot(t, ht, 'g-', label='toe h_t')
    for t in orbit.switching_times:
        ax_time.axvline(t, color='gray', ls=':')
    ax_time.set_xlabel('time in period [s]')
    ax_time.set_ylabel('height [m]')
    ax_time.legend()
    fig.tight_layout()
    fig.savefig('vhop_limit_cycle.png', dpi=100)
    print(orbit)
    print('liftoff and touchdown times:', orbit.switching_times)
    return orbit


if __name__ == '__main__':
    main()
