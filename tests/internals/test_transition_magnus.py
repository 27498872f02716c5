"""`step_transitions` equals a plain re-implementation of its documented scheme
(to rounding: the sum of many sub-step products).

Fourth-order Magnus on ``nsub`` sub-steps, ``nsub = 2, 4, ...`` doubled
until two resolutions agree on every step, Richardson-extrapolated; here
one step and one sub-step at a time with `scipy.linalg.expm`.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np
import pytest
import scipy.linalg as la

import ltpcontrol as ltp
from ltpcontrol._core.transition import step_transitions

C1, C2 = 0.5 - np.sqrt(3) / 6, 0.5 + np.sqrt(3) / 6


def _reference(A, t0, h, rtol=1e-12):
    bps = np.mod(A.breakpoints, A.period)
    segs = []                       # (step, start, end) in time order
    for k, (a, hk) in enumerate(zip(t0, h)):
        inner = sorted(t for t in bps if a + 1e-12 < t < a + hk - 1e-12)
        pts = [a] + inner + [a + hk]
        segs += [(k, p, q) for p, q in zip(pts[:-1], pts[1:])]

    def level(nsub):
        out = []
        for _, p, q in segs:
            dl = (q - p) / nsub
            E = np.eye(A.shape[0])
            for j in range(nsub):
                s = p + j * dl
                M1, M2 = A(s + C1 * dl), A(s + C2 * dl)
                E = la.expm(0.5 * dl * (M1 + M2) + np.sqrt(3) / 12 * dl ** 2
                            * (M2 @ M1 - M1 @ M2)) @ E
            out.append(E)
        return np.array(out)
    nsub, prev = 2, level(2)
    while True:
        nsub *= 2
        E = level(nsub)
        err = np.abs(E - prev).max(axis=(1, 2)) / 15
        if np.all(err <= rtol * np.maximum(1.0, np.abs(E).max(axis=(1, 2)))):
            break
        prev = E
    E = E + (E - prev) / 15
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
