r"""
A computation delay that changes the verdict
============================================

A digitally controlled plant with a periodic gain (a converter's duty-cycle
dependent gain, a rotor's azimuth-dependent control effectiveness) is
stabilised by proportional feedback of its velocity.  Analysed without the
controller's computation and PWM delay (here 1.5 sampling periods, the
classic figure of digital control), the loop looks stable for every gain in
the range; with the delay the gain margin is finite and the large gains are
unstable.  `ltpcontrol.feedback` closes the loop through `ltpcontrol.delay`,
which gives a periodic delay-differential equation whose multipliers decide.
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402

T = 0.02                  # period of the plant's gain (50 Hz)
TS = 1e-3                 # controller sampling period
DELAY = 1.5 * TS          # computation + PWM delay
wn, zeta = 2 * np.pi * 40, 0.05
b = lambda t: np.array([[0.0], [1 + 0.4 * np.cos(2 * np.pi * t / T)]])  # noqa: E731
plant = ltp.ltpss([[0.0, 1.0], [-wn**2, -2 * zeta * wn]], b, [[0.0, 1.0]], 0, period=T,
                  name='plant')

gains = np.linspace(50.0, 2500.0, 15)
rho_ideal, rho_delay = [], []
for k in gains:
    ideal = ltp.feedback(plant, k)
    delayed = ltp.feedback(plant, k * ltp.delay(DELAY))
    rho_ideal.append(np.max(np.abs(ltp.floquet_multipliers(ideal))))
    rho_delay.append(np.max(np.abs(ltp.floquet_multipliers(delayed))))
rho_ideal, rho_delay = np.array(rho_ideal), np.array(rho_delay)

k_test = 2000.0
print(f"gain {k_test:g}: stable without the delay: "
      f"{ltp.is_stable(ltp.feedback(plant, k_test))}, with the 1.5 Ts delay: "
      f"{ltp.is_stable(ltp.feedback(plant, k_test * ltp.delay(DELAY)))}")
cross = gains[np.argmax(rho_delay >= 1)] if np.any(rho_delay >= 1) else np.nan
print(f"the delayed loop loses stability near gain {cross:.0f}")

fig, ax = plt.subplots(figsize=(7, 4))
ax.semilogy(gains, rho_ideal, label='delay ignored')
ax.semilogy(gains, rho_delay, label=f'computation delay {DELAY * 1e3:g} ms')
ax.axhline(1.0, color='k', lw=0.8)
ax.set_xlabel('velocity feedback gain')
ax.set_ylabel('largest multiplier modulus')
ax.legend()
ax.set_title('Verdicts with and without the computation delay')
plt.show()
