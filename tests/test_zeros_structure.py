"""Zeros of non-square periodic systems and their infinite structure.

Truths: the square system whose outputs (inputs) are repeated in
combination has the same zeros (computed by the square pencil); the rank
drop of the lifted Rosenbrock pencil at each reported zero; the reference
toolbox's Pitelkau case (all zeros infinite); python-control for LTI.
"""

import numpy as np
import control as ct
import pytest

import ltpcontrol as ltp


def _square(seed, N=3, n=3):
    rng = np.random.default_rng(seed)
    return (0.6 * rng.standard_normal((N, n, n)), rng.standard_normal((N, n, 2)),
            rng.standard_normal((N, 2, n)), rng.standard_normal((N, 2, 2)))


@pytest.mark.parametrize('seed', [0, 5])
def test_tall_and_wide_systems_keep_the_square_zeros(seed):
    A, B, C, D = _square(seed)
    N = A.shape[0]
    rng = np.random.default_rng(seed + 100)
    square = ltp.ltpss(A, B, C, D, period=N * 0.5, dt=0.5)
    zs = ltp.zeros(square)
    assert zs.size > 0
    W = rng.standard_normal((N, 1, 2))                 # a third output: W_k y_k
    tall = ltp.ltpss(A, B, np.concatenate([C, W @ C], axis=1),
                     np.concatenate([D, W @ D], axis=1), period=N * 0.5, dt=0.5)
    V = rng.standard_normal((N, 2, 1))                 # a third input: u_3 acts as V_k u_3
    wide = ltp.ltpss(A, np.concatenate([B, B @ V], axis=2), C,
                     np.concatenate([D, D @ V], axis=2), period=N * 0.5, dt=0.5)
    for sys in (tall, wide):
        info = ltp.zeros(sys, structure=True)
        assert info.normal_rank == 2 * N
        np.testing.assert_allclose(np.sort_complex(info.zeros), np.sort_complex(zs),
                                   rtol=1e-7, atol=1e-9)
        # the lifted Rosenbrock pencil loses rank at mu = rho^N
        L = ltp.lift(sys, method='time')
        n = L.nstates
        for rho in info.zeros:
            P = np.block([[L.A - rho ** N * np.eye(n), L.B], [L.C, L.D]])
            s = np.linalg.svd(P, compute_uv=False)
            assert s[n + 2 * N - 1] < 1e-8 * s[0]


def test_pitelkau_all_zeros_infinite():
    w = 0.00103448
    a = np.array([[0, 0, 5.318064566757217e-02, 0], [0, 0, 0, 5.318064566757217e-02],
                  [-1.352134256362805e-03, 0, 0, -7.099273035392090e-02],
                  [0, -7.557182037479544e-04, 3.781555288420663e-02, 0]])
    b = lambda t: np.array([[0], [0], [0.1389735e-6 * np.sin(w * t)],
                            [-0.3701336e-7 * np.cos(w * t)]])
    sys = ltp.ltpss(a, b, [[1, 0, 0, 0], [0, 1, 0, 0]], 0, period=2 * np.pi / w)
    assert ltp.zeros(sys).size == 0                     # continuous: harmonic pencil
    sysd = sys.sample(sys.period / 120)
    info = ltp.zeros(sysd, structure=True)
    assert info.zeros.size == 0 and info.normal_rank == 120
    assert sum(info.infinite_orders) > 0


def test_lti_nonsquare_zeros_and_time_varying_dimensions():
    G = ct.ss([[-1.0, 0.5], [0.0, -2.0]], [[1.0], [1.0]], [[1.0, 0.0], [1.0, 1.0]], 0)
    z = ltp.zeros(ltp.ltpss(G, period=1.0))
    # column rank of [[A - sI, B], [C, D]] drops only where both SISO channels vanish
    z1, z2 = ct.zeros(G[0, 0]), ct.zeros(G[1, 0])
    common = [x for x in z1 if np.min(np.abs(z2 - x)) < 1e-9]
    assert len(z) == len(common)
    # a time-varying-dimension system: its zeros are those of its lifting
    tv = ltp.dltpss([np.array([[0.5, 1.0]]), np.array([[1.0], [0.3]])],
                    [np.array([[1.0]]), np.array([[0.0], [1.0]])],
                    [np.array([[1.0, 0.0]]), np.array([[2.0]])], [[0.5]])
    info = ltp.zeros(tv, structure=True)
    L = ltp.lift(tv, method='time')
    mu = ct.zeros(L)
    np.testing.assert_allclose(np.sort_complex(info.zeros ** 2), np.sort_complex(mu),
                               rtol=1e-9)
