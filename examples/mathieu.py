"""Mathieu-type LTP plants of thesis Chapter 4.

* `mathieu_ltp`: the damped oscillator with periodically modulated input
  and output gains of eqs. (4.113)-(4.115),
  ``ẍ = −ω_n² x − 2ζω_n ẋ + (1 + 2β_b cos ω_p t) u``,
  ``y = (1 + 2β_c cos ω_p t) x``.
* `switching_mathieu_ltp`: the switching damped Mathieu equation of
  eqs. (4.24)-(4.25) with Table 4.1 parameters,
  ``ẍ + 2ζ_i ω_n ẋ + (1 + 2β_i cos ω_p t) ω_n² x = u`` with ``i = 1`` on
  the first half of each period and ``i = 2`` on the second, full state
  output.
"""

import numpy as np

import ltpcontrol as ltp

#: Parameters of eqs. (4.113)-(4.114).
MATHIEU_PARAMS = {'omega_n': 2 * np.pi, 'zeta': 0.3, 'beta_b': 0.2, 'beta_c': 0.1,
                  'omega_p': 4 * np.pi}

#: Table 4.1 parameters (period T = 0.5 s).
SWITCHING_PARAMS = {'omega_n': 2 * np.pi, 'omega_p': 4 * np.pi, 'zeta1': 0.3, 'beta1': 0.1,
                    'zeta2': 0.1, 'beta2': 0.2}


def _cosine_series(mean, amplitude, period):
    """``mean + 2 amplitude cos(ω_p t)`` as a K = 1 Fourier series."""
    mean, amplitude = np.atleast_2d(mean), np.atleast_2d(amplitude)
    return ltp.PeriodicMatrix(np.stack([amplitude, mean, amplitude]), period)


def mathieu_ltp(omega_n=MATHIEU_PARAMS['omega_n'], zeta=MATHIEU_PARAMS['zeta'],
                beta_b=MATHIEU_PARAMS['beta_b'], beta_c=MATHIEU_PARAMS['beta_c'],
                omega_p=MATHIEU_PARAMS['omega_p']):
    """LTP model of eqs. (4.113)-(4.115).

    ``A = [[0, 1], [−ω_n², −2ζω_n]]``, ``B(t) = [0, 1 + 2β_b cos ω_p t]ᵀ``,
    ``C(t) = [1 + 2β_c cos ω_p t, 0]``, ``D = 0``; period ``2π/ω_p``.
    """
    period = 2 * np.pi / omega_p
    A = [[0.0, 1.0], [-omega_n ** 2, -2 * zeta * omega_n]]
    B = _cosine_series([[0.0], [1.0]], [[0.0], [beta_b]], period)
    C = _cosine_series([[1.0, 0.0]], [[beta_c, 0.0]], period)
    return ltp.ltpss(A, B, C, 0, period, name='mathieu', inputs=['u'], outputs=['y'],
                     states=['x', 'xdot'])


def switching_mathieu_ltp(omega_n=SWITCHING_PARAMS['omega_n'],
                          omega_p=SWITCHING_PARAMS['omega_p'],
                          zeta1=SWITCHING_PARAMS['zeta1'], beta1=SWITCHING_PARAMS['beta1'],
                          zeta2=SWITCHING_PARAMS['zeta2'], beta2=SWITCHING_PARAMS['beta2']):
    """Switching damped Mathieu system of eqs. (4.24)-(4.25), full state output.

    ``A^i(t) = [[0, 1], [−(1 + 2β_i cos ω_p t) ω_n², −2ζ_i ω_n]]`` is active
    on ``[0, T/2)`` for i = 1 and on ``[T/2, T)`` for i = 2; ``B = [0, 1]ᵀ``.
    Each piece is a K = 1 Fourier series (eq. 4.26), so the Fourier
    coefficients of the switching ``A(t)`` are exact.
    """
    period = 2 * np.pi / omega_p
    pieces = [_cosine_series([[0.0, 1.0], [-omega_n ** 2, -2 * zeta * omega_n]],
                             [[0.0, 0.0], [-beta * omega_n ** 2, 0.0]], period)
              for zeta, beta in ((zeta1, beta1), (zeta2, beta2))]
    A = ltp.PeriodicMatrix.switching(pieces, [0.0, period / 2], period)
    return ltp.ltpss(A, [[0.0], [1.0]], np.eye(2), 0, period, name='switching_mathieu',
                     inputs=['u'], outputs=['x', 'xdot'], states=['x', 'xdot'])


if __name__ == '__main__':
    print(mathieu_ltp())
    print(switching_mathieu_ltp())
