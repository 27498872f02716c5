"""forced_response on grids whose steps vary: exact, against an independent integration.

Measured data come on fine grids whose steps neither divide the period nor
stay equal (jittered clocks, dropped samples, records starting anywhere).
The default path is exact for the input hold; here it is compared with
``method='solve_ivp'`` (DOP853 restarted at every sample and switching
instant, tolerance 1e-12) on a random MIMO plant with A, B, C, D periodic,
a stiff plant and a switching plant.  P10 in ``benchmarks/`` times these
grids against the aligned grid.
"""

import numpy as np
import pytest

import ltpcontrol as ltp
from systems import switching_mathieu


def rel(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max())


def mimo_plant(n=4, m=2, p=2, seed=1):
    """Random stable plant, A, B, C, D with first and second harmonics (period 1)."""
    rng = np.random.default_rng(seed)

    def fourier(rows, cols, scale, center=0.0):
        c = scale * rng.normal(size=(5, rows, cols)) / np.sqrt(max(rows, cols))
        c[3:] = c[1::-1].copy()                      # c_{-k} = c_k: real
        c[2] = center + scale * rng.normal(size=(rows, cols))
        return ltp.PeriodicMatrix(c, 1.0)

    return ltp.ltpss(fourier(n, n, 0.5, center=-2.0 * np.eye(n)), fourier(n, m, 1.0),
                     fourier(p, n, 1.0), fourier(p, m, 0.3), period=1.0)


def stiff_plant():
    """A fast pole at -100/s (more than three times the step's rate) and a slow periodic mode."""
    w = 2 * np.pi
    c = np.zeros((3, 3, 3), complex)                   # harmonics -1, 0, 1 of A
    c[1] = [[-100.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -w ** 2, -0.5]]
    c[2] = [[0.0, 20.0, 0.0], [0.0, 0.0, 0.0], [2.5j, -0.15 * w ** 2, 0.0]]
    c[0] = c[2].conj()
    return ltp.ltpss(ltp.PeriodicMatrix(c, 1.0), [[1.0], [0.0], [1.0]], [[1.0, 1.0, 0.0]],
                     0, period=1.0)


def jittered(per_period, periods, period, seed, spread=0.2, start=0.0):
    """Samples moved by up to ±spread of the nominal step."""
    L = per_period * periods + 1
    h = period / per_period
    t = start + h * np.arange(L)
    rng = np.random.default_rng(seed)
    t[1:-1] += rng.uniform(-spread, spread, L - 2) * h
    return t


@pytest.mark.parametrize("plant, hold", [(mimo_plant, 'foh'), (stiff_plant, 'foh'),
                                         (switching_mathieu, 'foh'),
                                         (switching_mathieu, 'zoh')])
def test_nonuniform_grid_equals_independent_integration(plant, hold):
    sys = plant()
    T = sys.period
    t = jittered(30, 3, T, seed=3, start=0.37 * T)
    rng = np.random.default_rng(0)
    U = np.array([np.cos((1.3 + i) * 2 * np.pi / T * t + rng.uniform(0, 6))
                  for i in range(sys.ninputs)])
    x0 = rng.normal(size=sys.nstates)
    resp = ltp.forced_response(sys, t, U, x0, input_hold=hold)
    ref = ltp.forced_response(sys, t, U, x0, input_hold=hold, method='solve_ivp',
                              rtol=1e-12)
    assert rel(resp.states, ref.states) <= 1e-10
    assert rel(resp.outputs, ref.outputs) <= 1e-10
    # outputs only: the same numbers
    fast = ltp.forced_response(sys, t, U, x0, input_hold=hold, compute_states=False)
    np.testing.assert_allclose(fast.outputs, resp.outputs, rtol=0,
                               atol=1e-13 * np.abs(resp.outputs).max())


def test_grid_with_a_few_irregular_steps_and_many_traces():
    # an aligned grid with two samples dropped and one moved, three traces
    sys = mimo_plant(n=3, m=1, p=1, seed=2)
    t = np.delete(np.arange(161) / 32, [50, 100])
    t[70] += 0.3 / 32
    rng = np.random.default_rng(1)
    U = rng.normal(size=(1, 3, len(t)))
    X0 = rng.normal(size=(3, 3))
    resp = ltp.forced_response(sys, t, U, X0)
    ref = ltp.forced_response(sys, t, U[:, 0], X0[:, 0], method='solve_ivp', rtol=1e-12)
    assert resp.outputs.shape == (1, 3, len(t)) and ref.outputs.shape == (len(t),)
    assert rel(resp.outputs[0, 0], ref.outputs) <= 1e-10
    # trace by trace: the same as one call
    for r in (1, 2):
        one = ltp.forced_response(sys, t, U[:, r], X0[:, r])
        np.testing.assert_allclose(one.outputs, resp.outputs[0, r], rtol=0,
                                   atol=1e-13 * np.abs(one.outputs).max())


def test_system_without_inputs():
    from systems import damped_mathieu
    sys = damped_mathieu()
    free = ltp.ltpss(sys.A, np.zeros((2, 0)), sys.C, np.zeros((1, 0)), period=sys.period)
    t = np.cumsum(np.r_[0.1, np.random.default_rng(4).uniform(0.008, 0.012, 150)])
    resp = ltp.forced_response(free, t, np.zeros((0, len(t))), [1.0, -0.5])
    ref = ltp.forced_response(sys, t, 0.0, [1.0, -0.5], method='solve_ivp', rtol=1e-12)
    assert rel(resp.outputs, ref.outputs) <= 1e-10
