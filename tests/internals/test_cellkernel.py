"""The compiled march over the cells of a phase table equals the NumPy march.

Tests of internals: they import private names (see the Developer notes).
Without numba, the kernel's loop runs as Python (the same statements).
"""

import numpy as np
import pytest

import ltpcontrol as ltp
import ltpcontrol._core.cellkernel as cellkernel
import ltpcontrol._core.gridmarch as gridmarch


def rel(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / np.abs(np.asarray(b)).max())


def plant(n, m, seed):
    """A stable random plant with a periodic A (one harmonic), period 1."""
    rng = np.random.default_rng(seed)
    c = 0.4 * rng.normal(size=(3, n, n)) + 0.4j * rng.normal(size=(3, n, n))
    c[2] = c[0].conj()
    c[1] = c[1].real - 1.5 * np.eye(n)
    return ltp.ltpss(ltp.PeriodicMatrix(c, 1.0), rng.normal(size=(n, m)),
                     rng.normal(size=(2, n)), rng.normal(size=(2, m)), period=1.0)


def grid(seed):
    """40 samples a period, jittered, then steps of about 2.5 samples (cells
    without a sample)."""
    rng = np.random.default_rng(seed)
    dense = np.arange(600) / 40 + 0.013
    dense[1:] += rng.uniform(-0.2, 0.2, 599) / 40
    sparse = dense[-1] + np.cumsum(rng.uniform(2.3, 2.7, 200)) / 40
    return np.concatenate([dense, sparse])


class Spy:
    """Stands for `compiled_kernel`: the loops of `make` (default: the
    Python form) for any sizes, their calls counted."""

    def __init__(self, make=cellkernel.march_kernel):
        self.make, self.calls = make, 0

    def __call__(self, *sizes):
        loop = self.make(*sizes)

        def counted(*args):
            self.calls += 1
            return loop(*args)
        return counted


def periodic_output(n, m, seed):
    """The plant of `plant` with a periodic C."""
    sys = plant(n, m, seed)
    c = np.zeros((3, 2, n), complex)
    c[1] = sys.C(0.0)
    c[0] = c[2] = 0.3
    return ltp.ltpss(sys.A, sys.B, ltp.PeriodicMatrix(c, 1.0), sys.D, period=1.0)


def periodic_feedthrough(n, m, seed):
    """The plant of `plant` with C and D of two harmonics, sines and cosines."""
    sys = plant(n, m, seed)
    rng = np.random.default_rng(seed + 1)
    C, D = np.zeros((5, 2, n), complex), np.zeros((5, 2, m), complex)
    C[2], D[2] = sys.C(0.0), sys.D(0.0)
    for M in (C, D):
        M[3] = 0.2 * rng.normal(size=M.shape[1:]) + 0.2j * rng.normal(size=M.shape[1:])
        M[4] = 0.1j * rng.normal(size=M.shape[1:])
        M[1], M[0] = M[3].conj(), M[4].conj()
    return ltp.ltpss(sys.A, sys.B, ltp.PeriodicMatrix(C, 1.0), ltp.PeriodicMatrix(D, 1.0),
                     period=1.0)


def switching(n, m, seed):
    """A plant whose A switches at 0.3 and 0.8 of the period (cells split there)."""
    rng = np.random.default_rng(seed)
    A1, A2 = (ltp.PeriodicMatrix.constant(0.5 * rng.normal(size=(n, n)) - 1.5 * np.eye(n), 1.0)
              for _ in range(2))
    A = ltp.PeriodicMatrix.switching([A1, A2, A1], [0.0, 0.3, 0.8], 1.0)
    return ltp.ltpss(A, rng.normal(size=(n, m)), rng.normal(size=(1, n)), 0, period=1.0)


CASES = [(plant, 2, 1, 'foh'), (plant, 2, 1, 'zoh'), (plant, 3, 2, 'foh'),
         (periodic_output, 2, 1, 'foh'), (periodic_feedthrough, 3, 2, 'foh'),
         (periodic_feedthrough, 2, 1, 'zoh'), (switching, 2, 1, 'foh'), (switching, 3, 1, 'zoh')]


@pytest.mark.parametrize("make, n, m, hold", CASES)
@pytest.mark.parametrize("compiled", [False, True])
def test_kernel_equals_the_numpy_march(monkeypatch, make, n, m, hold, compiled):
    # equal cells located in the loop, or cells split at switching instants
    # located before; constant outputs in the loop, or periodic ones after
    if compiled:
        pytest.importorskip('numba')
        spy = Spy(cellkernel.compiled_kernel)
    else:
        spy = Spy()
    sys = make(n, m, seed=n + m)
    t = grid(n)
    rng = np.random.default_rng(1)
    U = rng.normal(size=(m, 2, len(t)))
    X0 = rng.normal(size=(n, 2))
    with ltp.config.defaults_context({'timeresp.compiled': False}):
        ref = ltp.forced_response(sys, t, U, X0, input_hold=hold)
    monkeypatch.setattr(cellkernel, 'MIN_SAMPLES', 0)
    monkeypatch.setattr(cellkernel, 'compiled_kernel', spy)
    resp = ltp.forced_response(sys, t, U, X0, input_hold=hold)
    assert spy.calls == 1
    assert rel(resp.states, ref.states) < 1e-13
    assert rel(resp.outputs, ref.outputs) < 1e-13
    # and the exact discretization, step by step
    with monkeypatch.context() as mp:
        for name in ('_table_steps', '_cell_table', '_repeat_length'):
            mp.setattr(gridmarch, name, lambda *a, **k: None)
        direct = ltp.forced_response(sys, t, U, X0, input_hold=hold)
    assert rel(resp.states, direct.states) < 1e-11
    assert rel(resp.outputs, direct.outputs) < 1e-11


def test_two_samples_in_one_cell_are_refused(monkeypatch):
    # the loop locates equal cells itself and reports a shared cell; the
    # layout is then made from every step
    monkeypatch.setattr(gridmarch, '_LAYOUT_STEPS', 100)
    monkeypatch.setattr(cellkernel, 'MIN_SAMPLES', 0)
    spy = Spy()
    monkeypatch.setattr(cellkernel, 'compiled_kernel', spy)
    sys = plant(2, 1, seed=6)
    t = grid(2)
    t[7] = t[6] + 0.2 / 40                            # not in the subsample
    u = np.cos(2.0 * t)
    resp = ltp.forced_response(sys, t, u)
    assert spy.calls == 2
    with ltp.config.defaults_context({'timeresp.compiled': False}):
        ref = ltp.forced_response(sys, t, u)
    assert rel(resp.outputs, ref.outputs) < 1e-13


def test_kernel_only_when_enabled_long_and_small(monkeypatch):
    spy = Spy()
    monkeypatch.setattr(cellkernel, 'compiled_kernel', spy)
    sys, t = plant(2, 1, seed=3), grid(2)
    u = np.cos(3.0 * t)
    monkeypatch.setattr(cellkernel, 'MIN_SAMPLES', len(t) + 1)      # too short
    ltp.forced_response(sys, t, u)
    monkeypatch.setattr(cellkernel, 'MIN_SAMPLES', 0)
    with ltp.config.defaults_context({'timeresp.compiled': False}):  # disabled
        ltp.forced_response(sys, t, u)
    monkeypatch.setattr(cellkernel, 'MAX_STATES', 1)                # too many states
    ltp.forced_response(sys, t, u)
    assert spy.calls == 0
    monkeypatch.setattr(cellkernel, 'MAX_STATES', 2)
    ltp.forced_response(sys, t, u)
    assert spy.calls == 1


def test_without_numba_the_numpy_march_runs(monkeypatch):
    import builtins
    real_import = builtins.__import__

    def no_numba(name, *args, **kwargs):
        if name == 'numba':
            raise ImportError('numba')
        return real_import(name, *args, **kwargs)
    monkeypatch.setattr(builtins, '__import__', no_numba)
    monkeypatch.setattr(cellkernel, '_COMPILED', {})
    monkeypatch.setattr(cellkernel, 'MIN_SAMPLES', 0)
    monkeypatch.setattr(cellkernel.importlib.util, 'find_spec', lambda name: None)
    assert not cellkernel.available()
    assert cellkernel.compiled_kernel(2, 1, 2, 7, 1, 0) is None
    sys, t = plant(2, 1, seed=4), grid(3)
    u = np.sin(2.0 * t)
    resp = ltp.forced_response(sys, t, u)
    with ltp.config.defaults_context({'timeresp.compiled': False}):
        ref = ltp.forced_response(sys, t, u)
    assert np.array_equal(resp.outputs, ref.outputs)


def test_a_kernel_numba_cannot_compile_falls_back_to_numpy(monkeypatch):
    def broken(*args):
        raise RuntimeError('no LLVM here')

    class Broken(dict):
        """A loop for any sizes, which fails as numba's compilation would."""

        def __contains__(self, sizes):
            return True

        def __getitem__(self, sizes):
            return cellkernel._guarded(broken)
    monkeypatch.setattr(cellkernel, 'MIN_SAMPLES', 0)
    monkeypatch.setattr(cellkernel, '_COMPILED', Broken())
    sys, t = plant(2, 1, seed=5), grid(2)
    u = np.cos(1.5 * t)
    with pytest.warns(UserWarning, match='simulating with NumPy'):
        resp = ltp.forced_response(sys, t, u)
    assert cellkernel._COMPILED is False
    assert cellkernel.compiled_kernel(2, 1, 2, 7, 1, 0) is None
    assert not cellkernel.available()
    with ltp.config.defaults_context({'timeresp.compiled': False}):
        ref = ltp.forced_response(sys, t, u)
    assert np.array_equal(resp.outputs, ref.outputs)
