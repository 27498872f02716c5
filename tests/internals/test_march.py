"""Block march kernel: equal to the plain recurrence it replaces, for every shape.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import ltpcontrol as ltp
from ltpcontrol._core.march import block_length, periodic_march
from systems import mathieu, switching_mathieu


def scalar_recurrence(Phi, E, F, C, D, u, x0):
    """x[k+1] = Φ_k x[k] + E_k u[k] + F_k u[k+1], y[k] = C_k x[k] + D_k u[k], one sample at a time."""
    N = Phi.shape[0]
    m, R, L = u.shape
    x = np.empty((Phi.shape[1], R, L))
    y = np.empty((C.shape[1], R, L))
    xk = x0.copy()
    for k in range(L):
        c = k % N
        x[:, :, k] = xk
        y[:, :, k] = C[c] @ xk + D[c] @ u[:, :, k]
        if k + 1 < L:
            xk = Phi[c] @ xk + E[c] @ u[:, :, k] + (0 if F is None else F[c] @ u[:, :, k + 1])
    return x, y


def random_data(rng, n, m, p, N, R, L, foh):
    # step maps of moderate growth so that long records stay well scaled
    Phi = rng.normal(size=(N, n, n)) / np.sqrt(n) * 0.9
    E, F = rng.normal(size=(N, n, m)), rng.normal(size=(N, n, m)) if foh else None
    C, D = rng.normal(size=(N, p, n)), rng.normal(size=(N, p, m))
    return Phi, E, F, C, D, rng.normal(size=(m, R, L)), rng.normal(size=(n, R))


@settings(derandomize=True, max_examples=40, deadline=None, database=None)
@given(seed=st.integers(0, 2 ** 16), n=st.integers(1, 5), m=st.integers(1, 3),
       p=st.integers(1, 3), N=st.sampled_from([1, 2, 3, 6, 7, 25, 37, 40]),
       R=st.integers(1, 4), L=st.integers(1, 130), foh=st.booleans())
def test_equals_scalar_recurrence(seed, n, m, p, N, R, L, foh):
    args = random_data(np.random.default_rng(seed), n, m, p, N, R, L, foh)
    x, y = periodic_march(*args)
    xr, yr = scalar_recurrence(*args)
    scale = max(1.0, np.abs(xr).max())
    np.testing.assert_allclose(x, xr, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(y, yr, rtol=0, atol=1e-12 * max(1.0, np.abs(yr).max()))


def test_row_chunks_give_the_same_result(monkeypatch):
    import ltpcontrol._core.march as march
    args = random_data(np.random.default_rng(1), 3, 2, 2, 10, 7, 333, True)
    whole = periodic_march(*args)
    monkeypatch.setattr(march, '_CHUNK_BYTES', 1)          # one row per matrix product
    chunked = periodic_march(*args)
    for a, b in zip(whole, chunked):
        np.testing.assert_allclose(a, b, rtol=1e-14, atol=1e-14 * np.abs(a).max())


@pytest.mark.parametrize("N, L, expected", [(50, 20001, 25), (40, 1000, 20), (37, 1000, 37),
                                            (2, 1000, 20), (1, 1000, 20), (7, 100, 21),
                                            (50, 5, 2), (50, 1, 1)])
def test_block_length_divides_or_repeats_the_period(N, L, expected):
    b = block_length(N, L)
    assert b == expected
    assert N % b == 0 or b % N == 0


@pytest.mark.parametrize("make", [mathieu, switching_mathieu])
@pytest.mark.parametrize("hold", ['foh', 'zoh'])
def test_forced_response_equals_step_recurrence(make, hold):
    # the exact discretization marched one step at a time, from the public step data
    from ltpcontrol._core.transition import step_transitions
    sys = make()
    h = sys.period / 50
    t = 0.13 + h * np.arange(377)                    # starts inside a period
    rng = np.random.default_rng(4)
    U = rng.normal(size=(1, 3, len(t)))
    x0 = rng.normal(size=(2, 3))
    resp = ltp.forced_response(sys, t, U, x0, input_hold=hold)
    tk = t[0] + h * np.arange(50)
    Phi, G0, G1 = step_transitions(sys.A, sys.B, tk, h)
    F = G1 if hold == 'foh' else None
    xr, yr = scalar_recurrence(Phi, G0 - G1 if F is not None else G0, F, sys.C(tk),
                               sys.D(tk), U, x0)
    np.testing.assert_allclose(resp.x, xr, rtol=0, atol=1e-12 * np.abs(xr).max())
    np.testing.assert_allclose(resp.y, yr, rtol=0, atol=1e-12 * np.abs(yr).max())


def test_time_varying_feedthrough_discrete_odd_and_even_N():
    rng = np.random.default_rng(8)
    for N in (4, 5):
        A = 0.6 * rng.normal(size=(N, 3, 3)) / np.sqrt(3)
        B, C, D = rng.normal(size=(N, 3, 2)), rng.normal(size=(N, 2, 3)), rng.normal(size=(N, 2, 2))
        sys = ltp.ltpss(A, B, C, D, period=N * 0.1, dt=0.1)
        t = 0.1 * (3 + np.arange(61))                 # phase 3
        u = rng.normal(size=(2, 61))
        phase = (3 + np.arange(N)) % N
        xr, yr = scalar_recurrence(A[phase], B[phase], None, C[phase], D[phase],
                                   u[:, None], np.zeros((3, 1)))
        np.testing.assert_allclose(ltp.forced_response(sys, t, u).y, yr[:, 0], rtol=1e-12,
                                   atol=1e-12)


@pytest.mark.parametrize("scale", [1e-4, 1e-2, 0.2, 0.8, 2.0, 5.0, 50.0])
def test_expm_batch_equals_scipy_at_every_pade_degree(scale):
    import scipy.linalg as sla
    from ltpcontrol._core.transition import expm_batch
    X = np.random.default_rng(2).normal(size=(30, 5, 5)) * scale / 5
    E = expm_batch(X)
    for x, e in zip(X, E):
        ref = sla.expm(x)
        np.testing.assert_allclose(e, ref, rtol=0, atol=1e-13 * np.abs(ref).max() * max(1, scale))
