"""Step transitions: splitting at switching instants and piecewise-constant steps.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np
import pytest
import scipy.linalg as sla

import ltpcontrol as ltp
from ltpcontrol._core.steps import step_integrals
from ltpcontrol._core.transition import _segments, step_transitions


def segments_by_loop(t0, h, bps, period):
    # per step: the instants bps + jT strictly inside it (1e-12 relative margin)
    steps, starts, ends = [], [], []
    for k, (a, hk) in enumerate(zip(t0, h)):
        b = a + hk
        j = np.arange(np.floor(a / period), np.floor(b / period) + 1)
        cand = (bps[None, :] + (j * period)[:, None]).ravel()
        tol = 1e-12 * max(1.0, abs(b))
        pts = np.concatenate([[a], np.sort(cand[(cand > a + tol) & (cand < b - tol)]), [b]])
        steps += [k] * (len(pts) - 1)
        starts += list(pts[:-1])
        ends += list(pts[1:])
    return np.array(steps, int), np.array(starts), np.array(ends)


@pytest.mark.parametrize("seed", range(40))
def test_segments_equal_per_step_splitting(seed):
    rng = np.random.default_rng(seed)
    T = rng.uniform(0.1, 3.0)
    bps = np.unique(np.concatenate([[0.0] if seed % 2 else [],
                                    rng.uniform(0, T, rng.integers(1, 5))]))
    S = int(rng.integers(1, 12))
    t0 = rng.uniform(-2 * T, 5 * T, S)
    h = np.where(rng.random(S) < 0.5, rng.uniform(0, 0.2 * T, S), rng.uniform(0, 4 * T, S))
    # steps that start or end exactly on a switching instant of another period
    on = rng.random(S) < 0.4
    t0[on] = bps[rng.integers(0, len(bps), on.sum())] + rng.integers(-2, 4, on.sum()) * T
    end = t0 + h
    on = rng.random(S) < 0.4
    end[on] = bps[rng.integers(0, len(bps), on.sum())] + np.ceil(t0[on] / T + 1) * T
    h = end - t0 + 1e-9
    got = _segments(t0, h, bps, T)
    ref = segments_by_loop(t0, h, bps, T)
    for g, r in zip(got, ref):
        np.testing.assert_array_equal(g, r)
    assert np.all(got[2] > got[1])
    # the segments tile every step
    np.testing.assert_allclose(np.bincount(got[0], got[2] - got[1], minlength=S), h,
                               rtol=1e-12, atol=1e-12)


def test_segments_without_switching_keep_the_steps():
    t0, h = np.array([0.3, -1.0]), np.array([2.0, 0.5])
    steps, a, b = _segments(t0, h, np.zeros(0), 1.0)
    np.testing.assert_array_equal(steps, [0, 1])
    np.testing.assert_array_equal(a, t0)
    np.testing.assert_allclose(b - a, h, rtol=1e-15)


def switching_A(rng, n=3, T=1.0):
    pieces = [rng.normal(size=(n, n)) for _ in range(3)]
    return ltp.PeriodicMatrix.switching(pieces, [0.0, 0.2 * T, 0.65 * T], T), pieces


@pytest.mark.parametrize("seed", range(3))
def test_piecewise_constant_transition_is_the_product_of_exponentials(seed):
    rng = np.random.default_rng(seed)
    A, pieces = switching_A(rng)
    assert A._piecewise_constant
    # steps crossing several switching instants and a whole period
    t0, h = np.array([0.1, 0.65, -0.3]), np.array([0.7, 0.35, 1.45])
    Phi, G0, G1 = step_transitions(A, None, t0, h)
    assert G0.shape == G1.shape == (3, 3, 0)
    piece_of = lambda t: pieces[np.searchsorted([0.0, 0.2, 0.65], np.mod(t, 1.0),
                                                side='right') - 1]
    for k in range(3):
        cuts = np.unique(np.concatenate([[t0[k], t0[k] + h[k]], [x + j for x in (0, .2, .65)
                                                                  for j in (-1, 0, 1)]]))
        cuts = cuts[(cuts >= t0[k]) & (cuts <= t0[k] + h[k])]
        ref = np.eye(3)
        for a, b in zip(cuts[:-1], cuts[1:]):
            ref = sla.expm((b - a) * piece_of(0.5 * (a + b))) @ ref
        np.testing.assert_allclose(Phi[k], ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())


def test_piecewise_constant_path_equals_the_magnus_integrator():
    rng = np.random.default_rng(7)
    A, _ = switching_A(rng)
    smooth_form = ltp.PeriodicMatrix._new(1.0, A.shape, func=A._eval, breakpoints=A.breakpoints)
    assert not smooth_form._piecewise_constant
    t0 = np.linspace(0, 1, 9)[:-1]
    fast, _, _ = step_transitions(A, None, t0, 0.125)
    magnus, _, _ = step_transitions(smooth_form, None, t0, 0.125)
    np.testing.assert_allclose(fast, magnus, rtol=1e-12, atol=1e-13)


def test_piecewise_constant_forms():
    T = 1.0
    S = ltp.PeriodicMatrix.switching([[[1.0]], [[2.0]]], [0, 0.5], T)
    smooth = ltp.PeriodicMatrix([[[0.5]], [[1.0]], [[0.5]]], T)
    assert ltp.PeriodicMatrix.constant([[1.0]], T)._piecewise_constant
    assert (S @ S.T - 2 * S)._piecewise_constant
    assert ltp.PeriodicMatrix.block([[S, [[0.0]]], [[[1.0]], S]])._piecewise_constant
    assert not smooth._piecewise_constant
    assert not (S + smooth)._piecewise_constant
    assert not ltp.PeriodicMatrix.switching([smooth, [[1.0]]], [0, 0.5], T)._piecewise_constant


@pytest.mark.parametrize("form", ['switching', 'smooth'])
def test_step_integrals_equal_van_loan_exponentials(form):
    # constant A on each step: Ψ = expm(h M) with the full 3n generator
    rng = np.random.default_rng(3)
    n, T = 2, 1.0
    A0 = rng.normal(size=(n, n)) - 2 * np.eye(n)
    Bs = [rng.normal(size=(n, 1)) for _ in range(2)]
    Cs = [rng.normal(size=(1, n)) for _ in range(2)]
    A = ltp.PeriodicMatrix.constant(A0, T)
    if form == 'smooth':
        A = ltp.PeriodicMatrix._new(T, (n, n), func=A._eval)
    B = ltp.PeriodicMatrix.switching(Bs, [0, 0.5], T)
    C = ltp.PeriodicMatrix.switching(Cs, [0, 0.5], T)
    t0, h = np.array([0.0, 0.5, 0.25]), np.array([0.5, 0.25, 0.25])
    Phi, W, V, S = step_integrals(A, t0, h, Qf=B @ B.T, Qa=C.T @ C)
    for k, piece in enumerate([0, 1, 0]):
        Qf, Qa = Bs[piece] @ Bs[piece].T, Cs[piece].T @ Cs[piece]
        Z = np.zeros((n, n))
        M = np.block([[-A0.T, Qa, Z], [Z, A0, Qf], [Z, Z, -A0.T]])
        Psi = sla.expm(h[k] * M)
        P22 = Psi[n:2 * n, n:2 * n]
        np.testing.assert_allclose(Phi[k], sla.expm(h[k] * A0), rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(W[k], Psi[n:2 * n, 2 * n:] @ P22.T, rtol=1e-11, atol=1e-14)
        np.testing.assert_allclose(V[k], P22.T @ Psi[:n, n:2 * n], rtol=1e-11, atol=1e-14)
        np.testing.assert_allclose(S[k], np.trace(P22.T @ Psi[:n, 2 * n:]), rtol=1e-11)
