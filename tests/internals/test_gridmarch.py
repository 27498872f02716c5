"""Simulation on grids whose step does not divide the period: exact, like the aligned grid.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import ltpcontrol as ltp
import ltpcontrol._core.gridmarch as gridmarch
from systems import damped_mathieu, mathieu, switching_mathieu


def rel(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max())


def direct(monkeypatch, sys, t, u, **kw):
    """The same exact discretization with every step integrated on its own."""
    with monkeypatch.context() as mp:
        mp.setattr(gridmarch, '_table_steps', lambda *a, **k: None)
        mp.setattr(gridmarch, '_cell_table', lambda *a, **k: None)
        mp.setattr(gridmarch, '_repeat_length', lambda *a, **k: None)
        return ltp.forced_response(sys, t, u, **kw)


@pytest.mark.parametrize("plant, hold", [(damped_mathieu, 'foh'), (switching_mathieu, 'foh'),
                                         (switching_mathieu, 'zoh'), (mathieu, 'foh')])
def test_linspace_grid_equals_independent_integration(plant, hold):
    sys = plant()
    t = np.linspace(0, 2.3 * sys.period, 41)               # step does not divide T
    u = np.sin(2.1 * t) + 0.3 * np.cos(5.0 * t)
    resp = ltp.forced_response(sys, t, u, input_hold=hold)
    ref = ltp.forced_response(sys, t, u, input_hold=hold, method='solve_ivp', rtol=1e-12)
    assert rel(resp.outputs, ref.outputs) < 1e-10
    assert rel(resp.states, ref.states) < 1e-10


def test_table_equals_per_step_integration(monkeypatch):
    sys = damped_mathieu()
    t = np.linspace(0, 40 * sys.period, 2001)
    U = np.array([np.cos(1.7 * t), np.sin(0.4 * t) ** 2])[None]
    x0 = np.array([[1.0, -0.5], [0.2, 0.0]])
    resp = ltp.forced_response(sys, t, U, x0)
    ref = direct(monkeypatch, sys, t, U, initial_state=x0)
    assert rel(resp.states, ref.states) < 1e-12
    assert rel(resp.outputs, ref.outputs) < 1e-12


def test_repeating_phase_pattern(monkeypatch):
    sys = switching_mathieu()
    t = 3 * sys.period / 50 * np.arange(900)              # 50 steps span three periods
    assert gridmarch._repeat_length(t, np.diff(t), sys.period) == (50, 3)
    u = np.cos(3.0 * t)
    resp = ltp.forced_response(sys, t, u)
    ref = direct(monkeypatch, sys, t, u)
    assert rel(resp.outputs, ref.outputs) < 1e-12


def test_nonuniform_grid_and_chunks(monkeypatch):
    rng = np.random.default_rng(3)
    sys = switching_mathieu()
    t = np.cumsum(np.concatenate([[0.3], rng.uniform(0.004, 0.011, 1500)]))
    u = np.sin(4.0 * t)
    resp = ltp.forced_response(sys, t, u)
    monkeypatch.setattr(gridmarch, '_CHUNK_STEPS', 60)     # chunk boundaries inside
    chunked = ltp.forced_response(sys, t, u)
    ref = direct(monkeypatch, sys, t, u)
    assert rel(resp.outputs, ref.outputs) < 1e-12
    assert rel(chunked.outputs, ref.outputs) < 1e-12
    short = ltp.forced_response(sys, t[:40], u[:40], method='solve_ivp', rtol=1e-10)
    assert rel(resp.outputs[:40], short.outputs) < 1e-8


def test_a_cell_table_larger_than_the_memory_gives_way_to_bounded_chunks(monkeypatch):
    # a jittered grid whose cell table would take more than half the memory
    # available: the steps are integrated one by one, in chunks whose arrays
    # stay within _CHUNK_BYTES (here 20 steps), with the same result
    import ltpcontrol._core.cellmarch as cellmarch
    rng = np.random.default_rng(8)
    sys = ltp.ltpss(ltp.PeriodicMatrix([[[0.1, 0.0], [0.2, 0.0]], [[0.0, 1.0], [-4.0, -0.4]],
                                        [[0.1, 0.0], [0.2, 0.0]]], 1.0),
                    [[0.0], [1.0]], [[1.0, 0.0]], 0, period=1.0)
    t = np.arange(600) / 40 + rng.uniform(-0.2, 0.2, 600) / 40
    u = np.cos(2.1 * t)
    table = ltp.forced_response(sys, t, u)
    marches = []
    monkeypatch.setattr(cellmarch, '_numpy_march', lambda *a: marches.append(a))
    monkeypatch.setattr(gridmarch, 'available_memory', lambda: 10 ** 4)
    monkeypatch.setattr(gridmarch, '_CHUNK_BYTES', 8 * 4 * 4 * 20)
    chunked = ltp.forced_response(sys, t, u)
    assert not marches
    assert rel(chunked.states, table.states) < 1e-11
    assert rel(chunked.outputs, table.outputs) < 1e-11


def test_phase_data_larger_than_the_memory_give_way_to_bounded_chunks(monkeypatch):
    # a uniform grid whose step does not divide the period, when its cells do not
    # serve: the step data interpolated in the phase, unless their samples would
    # take more than half the memory available (then step by step, same result)
    sys = damped_mathieu()
    t = 0.0137 * np.arange(300)
    u = np.cos(2.3 * t)
    monkeypatch.setattr(gridmarch, '_cell_table', lambda *a, **k: None)
    made = []
    phase_table = gridmarch._phase_table
    monkeypatch.setattr(gridmarch, '_phase_table', lambda *a: made.append(phase_table(*a))
                        or made[-1])
    interpolated = ltp.forced_response(sys, t, u)
    assert made[-1] is not None
    monkeypatch.setattr(gridmarch, 'available_memory', lambda: 10 ** 4)
    stepwise = ltp.forced_response(sys, t, u)
    assert made[-1] is None
    with pytest.MonkeyPatch.context() as mp:
        ref = direct(mp, sys, t, u)
    assert rel(interpolated.outputs, ref.outputs) < 1e-11
    assert rel(stepwise.outputs, ref.outputs) < 1e-12


@settings(derandomize=True, max_examples=12, deadline=None, database=None)
@given(ratio=st.floats(0.011, 0.3), t0=st.floats(0.0, 3.0), n=st.integers(20, 400))
def test_any_uniform_grid_matches_per_step_data(ratio, t0, n):
    sys = damped_mathieu()
    t = t0 + ratio * sys.period * np.arange(n)
    u = np.cos(2.3 * t)
    resp = ltp.forced_response(sys, t, u)
    with pytest.MonkeyPatch.context() as mp:
        ref = direct(mp, sys, t, u)
    assert rel(resp.outputs, ref.outputs) < 1e-11


def test_outputs_only():
    sys = mathieu()
    t = np.linspace(0, 3, 401)
    U = np.cos(np.outer([1.0, 2.0, 3.0], t))[None]
    full = ltp.forced_response(sys, t, U)
    fast = ltp.forced_response(sys, t, U, compute_states=False)
    assert fast.states.shape == (0, 3, len(t))
    np.testing.assert_allclose(fast.outputs, full.outputs, rtol=0, atol=1e-14)
    with pytest.raises(ValueError, match='compute_states'):
        ltp.forced_response(sys, t, U, compute_states='no')
    with pytest.raises(ValueError, match='return_states'):
        ltp.forced_response(sys, t, U, compute_states=False, return_states=True)


@pytest.mark.parametrize("few", [0, 16])
def test_both_chunk_marches(monkeypatch, few):
    # few traces: state by state; many: the block kernel of the periodic march
    monkeypatch.setattr(gridmarch, '_FEW_TRACES', few)
    monkeypatch.setattr(gridmarch, '_CHUNK_STEPS', 140)
    sys = switching_mathieu()
    t = np.linspace(0.1, 12 * sys.period, 1001)
    U = np.cos(np.outer([1.0, 2.5, 4.0], t))[None]
    x0 = np.array([[0.3, 0.0, -1.0], [0.0, 1.0, 0.5]])
    resp = ltp.forced_response(sys, t, U, x0)
    monkeypatch.setattr(gridmarch, '_CHUNK_STEPS', 4000)
    ref = direct(monkeypatch, sys, t, U, initial_state=x0)
    assert rel(resp.states, ref.states) < 1e-12
    assert rel(resp.outputs, ref.outputs) < 1e-12
    fast = ltp.forced_response(sys, t, U, x0, compute_states=False)
    assert rel(fast.outputs, ref.outputs) < 1e-12


@pytest.mark.parametrize("plant", [damped_mathieu, switching_mathieu])
def test_table_of_short_runs_equals_binary_lifting(monkeypatch, plant):
    sys = plant()
    t = np.cumsum(np.concatenate([[0.0], sys.period / 7.3 * np.linspace(0.8, 1.2, 300)]))
    h = np.diff(t)
    steps = gridmarch._table_steps(sys.A, sys.B, h, sys.period, 1e-12)
    monkeypatch.setattr(gridmarch, '_FEW_CELLS', 0)
    lifted = gridmarch._table_steps(sys.A, sys.B, h, sys.period, 1e-12)
    for a, b in zip(steps(t[:-1], h), lifted(t[:-1], h)):
        assert rel(a, b) < 1e-13


def test_substep_error_estimate_scales_as_the_fifth_power():
    from ltpcontrol._core.transition import step_transitions
    sys = damped_mathieu()
    t0 = np.linspace(0, sys.period, 8, endpoint=False)
    excess = []
    for h in (0.2, 0.1):
        info = {}
        step_transitions(sys.A, sys.B, t0, h, 1e-12, info=info)
        excess.append(info['excess'])
    assert 16 < excess[0] / excess[1] < 64            # 2^5 = 32


@pytest.mark.parametrize("N, P, R, budget", [(400, 30, 1, 2 ** 21), (12, 40, 3, 2 ** 21),
                                             (7, 9, 2, 2 ** 21), (12, 40, 3, 50)])
def test_phase_march_equals_the_recurrence(monkeypatch, N, P, R, budget):
    # blocks of a divisor of N (7: blocks of one phase), periods in one chunk or many
    import ltpcontrol._core.cellmarch as cellmarch
    monkeypatch.setattr(cellmarch, '_CHUNK_ENTRIES', budget)
    rng = np.random.default_rng(N)
    Phi = 0.5 * rng.normal(size=(N, 2, 2))
    f = rng.normal(size=(N, 2, P * R))
    x0 = rng.normal(size=(2, R))
    x, end = cellmarch.PhaseMarch(Phi)(f, R, x0.copy())
    ref, xs = np.empty_like(x), x0
    for p in range(P):
        for c in range(N):
            ref[c, :, p * R:(p + 1) * R] = xs
            xs = Phi[c] @ xs + f[c, :, p * R:(p + 1) * R]
    assert rel(x, ref) < 1e-12
    assert rel(end, xs) < 1e-12


def test_cell_layout_holds_one_sample_per_cell():
    # a grid jittered about T/400: 400 cells; a random walk of steps: the
    # shortest step decides; either way no cell holds two samples
    rng = np.random.default_rng(1)
    jittered = np.arange(4000) / 400 + rng.uniform(-0.2, 0.2, 4000) / 400
    walk = np.cumsum(np.r_[0.0, rng.uniform(0.8, 1.2, 3000) / 50])
    for t, most in ((jittered, 84), (walk, 8)):
        layout = gridmarch._cell_layout(t[:-1], np.diff(t), 1.0, most)
        if layout is None:
            assert t is walk
            continue
        Ns, offset = layout
        N = Ns * gridmarch._PIECE_CELLS
        cell = np.floor((t - offset) * N).astype(np.int64)
        assert np.all(np.diff(cell) >= 1)
        if t is jittered:
            assert N == 400


@pytest.mark.parametrize("n, m, hold, gap", [(2, 1, 'foh', False), (2, 1, 'zoh', False),
                                             (6, 2, 'foh', False), (2, 1, 'foh', True),
                                             (2, 1, 'zoh', True)])
def test_cell_march_in_chunks_equals_the_per_step_march(monkeypatch, n, m, hold, gap):
    # both ways to the samples' states (entries of the first parts, or their
    # products with the states: n + 2m below or above the table's D + 1),
    # two traces, periods taken one chunk at a time or all at once; with a
    # gap of three periods without samples (chunks holding none)
    import ltpcontrol._core.cellmarch as cellmarch
    rng = np.random.default_rng(n + m)
    c = 0.4 * rng.normal(size=(3, n, n)) + 0.4j * rng.normal(size=(3, n, n))
    c[2] = c[0].conj()
    c[1] = c[1].real - 1.5 * np.eye(n)
    sys = ltp.ltpss(ltp.PeriodicMatrix(c, 1.0), rng.normal(size=(n, m)),
                    rng.normal(size=(1, n)), 0, period=1.0)
    t = np.arange(1201) / 40 + 0.1
    t[1:-1] += rng.uniform(-0.2, 0.2, 1199) / 40
    if gap:
        t = np.delete(t, np.arange(400, 521))
    U = rng.normal(size=(m, 2, len(t)))
    X0 = rng.normal(size=(n, 2))
    whole = ltp.forced_response(sys, t, U, X0, input_hold=hold)
    monkeypatch.setattr(cellmarch, '_CHUNK_ENTRIES', 1)             # one period a chunk
    chunked = ltp.forced_response(sys, t, U, X0, input_hold=hold)
    assert rel(chunked.states, whole.states) < 1e-13
    ref = direct(monkeypatch, sys, t, U, X0=X0, input_hold=hold)
    assert rel(whole.states, ref.states) < 1e-11
    assert rel(whole.outputs, ref.outputs) < 1e-11


def test_cells_laid_out_from_a_subsample_then_from_every_step(monkeypatch):
    # a long record's cells are laid out from every k-th step first; a short
    # step outside that subsample puts two samples in one cell, and the
    # layout is made again from every step
    sys = damped_mathieu()
    T = sys.period
    rng = np.random.default_rng(5)
    t = T / 40 * (np.arange(1200) + rng.uniform(-0.05, 0.05, 1200))
    t[7] = t[6] + 0.3 * T / 40                  # not a multiple of the stride
    u = np.cos(1.3 * t)
    monkeypatch.setattr(gridmarch, '_LAYOUT_STEPS', 100)
    strides = []
    table = gridmarch._cell_table

    def spy(*args, stride=1, **kwargs):
        strides.append(stride)
        return table(*args, stride=stride, **kwargs)
    monkeypatch.setattr(gridmarch, '_cell_table', spy)
    resp = ltp.forced_response(sys, t, u)
    assert strides == [12, 1]
    monkeypatch.setattr(gridmarch, '_cell_table', table)
    ref = direct(monkeypatch, sys, t, u)
    assert rel(resp.states, ref.states) < 1e-12


def test_long_aligned_record_is_uniform_despite_the_rounding_of_its_times():
    # np.arange(L) / 400 beyond a million samples: steps that differ by 2e-10
    # relative (the rounding of t ~ 4000), still the aligned grid
    t = np.arange(1_600_000) / 400
    h = np.diff(t)
    assert np.ptp(h) / h[0] > 1e-10
    assert gridmarch._repeat_length(t, h, 1.0) == (400, 1)
    # a grid moved by more than that rounding is not uniform
    t2 = t.copy()
    t2[800_000] += 1e-9
    assert gridmarch._repeat_length(t2, np.diff(t2), 1.0) is None
