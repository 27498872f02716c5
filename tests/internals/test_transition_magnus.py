"""`step_transitions` equals a plain re-implementation of its documented scheme
(to rounding: the sum of many sub-step products).

Sixth-order Magnus (Blanes, Casas and Ros: three Gauss points) on ``nsub``
sub-steps, ``nsub = 1, 2, 4, ...`` doubled until two resolutions agree on
every step, Richardson-extrapolated; here one step and one sub-step at a
time with `scipy.linalg.expm`.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np
import pytest
import scipy.linalg as la

import ltpcontrol as ltp
from ltpcontrol._core.transition import _magnus, step_transitions

NODES = (0.5 - np.sqrt(15) / 10, 0.5, 0.5 + np.sqrt(15) / 10)


def _magnus6(A, s, dl):
    """Ω of one sub-step [s, s + dl]."""
    M1, M2, M3 = (A(s + c * dl) for c in NODES)
    a1 = dl * M2
    a2 = np.sqrt(15) / 3 * dl * (M3 - M1)
    a3 = 10 / 3 * dl * (M3 - 2 * M2 + M1)

    def comm(X, Y):
        return X @ Y - Y @ X
    C1 = comm(a1, a2)
    C2 = -comm(a1, 2 * a3 + C1) / 60
    return a1 + a3 / 12 + comm(-20 * a1 - a3 + C1, a2 + C2) / 240


def _product(A, p, q, nsub):
    dl = (q - p) / nsub
    E = np.eye(A.shape[0])
    for j in range(nsub):
        E = la.expm(_magnus6(A, p + j * dl, dl)) @ E
    return E


def _reference(A, t0, h, rtol=1e-12):
    bps = np.mod(A.breakpoints, A.period)
    segs = []                       # (step, start, end) in time order
    for k, (a, hk) in enumerate(zip(t0, h)):
        inner = sorted(t for t in bps if a + 1e-12 < t < a + hk - 1e-12)
        pts = [a] + inner + [a + hk]
        segs += [(k, p, q) for p, q in zip(pts[:-1], pts[1:])]

    def level(nsub):
        return np.array([_product(A, p, q, nsub) for _, p, q in segs])
    nsub, prev = 1, level(1)
    while True:
        nsub *= 2
        E = level(nsub)
        err = np.abs(E - prev).max(axis=(1, 2)) / 63
        if np.all(err <= rtol * np.maximum(1.0, np.abs(E).max(axis=(1, 2)))):
            break
        prev = E
    E = E + (E - prev) / 63
    Phi = np.broadcast_to(np.eye(A.shape[0]), (len(t0),) + A.shape).copy()
    for (k, _, _), Ek in zip(segs, E):
        Phi[k] = Ek @ Phi[k]
    return Phi


def _systems(rng, n):
    c = rng.standard_normal((5, n, n)) + 1j * rng.standard_normal((5, n, n))
    c = 0.5 * (c + np.conj(c[::-1]))
    yield 'smooth', ltp.PeriodicMatrix(c, 1.0)
    yield 'stiff', ltp.PeriodicMatrix(c, 1.0) + np.diag(-10.0 ** np.arange(n))
    yield 'switching', ltp.PeriodicMatrix.switching(
        [rng.standard_normal((n, n)), 3 * rng.standard_normal((n, n))], [0.0, 0.37], 1.0)


@pytest.mark.parametrize("seed", [0])
def test_step_transitions_match_plain_scheme(seed):
    rng = np.random.default_rng(seed)
    zero = ltp.PeriodicMatrix.constant(np.zeros((3, 0)), 1.0)
    t0 = np.sort(rng.uniform(0, 1, 4))
    h = rng.uniform(0.05, 0.25, 4)
    for name, A in _systems(rng, 3):
        Phi = step_transitions(A, zero.with_period(A.period), t0, h)[0]
        ref = _reference(A, t0, h)
        scale = np.maximum(1.0, np.abs(ref).max(axis=(1, 2)))
        assert np.all(np.abs(Phi - ref).max(axis=(1, 2)) <= 5e-14 * scale), name


def test_sub_step_error_is_sixth_order():
    # halving the sub-steps divides the error of a step by about 2^6 = 64
    # (against a resolution 64 times finer), the factor the Richardson
    # extrapolation and the error estimate assume
    rng = np.random.default_rng(3)
    A = next(_systems(rng, 3))[1]
    exact = _product(A, 0.1, 0.6, 256)
    a, b = np.array([0.1]), np.array([0.6])

    def library(nsub):
        return _magnus(A, None, a, b, a, b - a, nsub, 3, 0, 3)[0]
    for integrate in (library, lambda nsub: _product(A, 0.1, 0.6, nsub)):
        errors = [np.abs(integrate(nsub) - exact).max() for nsub in (2, 4, 8)]
        ratios = np.array(errors[:-1]) / np.array(errors[1:])
        assert np.all((ratios > 40) & (ratios < 100)), ratios


def test_a_plant_without_states_has_empty_step_data():
    # a static gain written as an LTP system (no states, one input)
    A = ltp.PeriodicMatrix.constant(np.zeros((0, 0)), 1.0)
    B = ltp.PeriodicMatrix.constant(np.zeros((0, 1)), 1.0)
    Phi, G0, G1 = step_transitions(A, B, np.arange(3) / 3, np.full(3, 1 / 3))
    assert Phi.shape == (3, 0, 0) and G0.shape == (3, 0, 1) and G1.shape == (3, 0, 1)
