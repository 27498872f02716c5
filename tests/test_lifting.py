"""Tests of the frequency and time lifting of discrete-time LTP systems."""

import numpy as np
import pytest
import control as ct
from control.exception import ControlArgument

import ltpcontrol as ltp
from ltpcontrol import lift


def _random_dt(N, n=2, m=2, p=1, seed=0, dt=0.1):
    rng = np.random.default_rng(seed)
    A = 0.4 * rng.standard_normal((N, n, n))
    B = rng.standard_normal((N, n, m))
    C = rng.standard_normal((N, p, n))
    D = rng.standard_normal((N, p, m))
    return ltp.ltpss(A, B, C, D, period=N * dt, dt=dt, name='plant')


def _htf_truth(sysd, z, harmonics):
    """DT HTF from the periodic steady state of ``x[k] = z^k p[k]``.

    For ``u[k] = z^k w^{mk} e_i`` the N-periodic ``p`` solves the cyclic system
    ``z p[k+1] = A[k] p[k] + B[k] w^{mk} e_i``; ``Y_n = (1/N) Σ_k y[k] z^{-k} w^{-nk}``.
    """
    N = sysd.nsteps
    A, B, C, D = (M.sample(N) for M in (sysd.A, sysd.B, sysd.C, sysd.D))
    n, m, p = sysd.nstates, sysd.ninputs, sysd.noutputs
    w = np.exp(2j * np.pi / N)
    k = np.arange(N)
    M = np.zeros((N * n, N * n), complex)
    for i in range(N):
        M[i * n:(i + 1) * n, ((i + 1) % N) * n:((i + 1) % N + 1) * n] += z * np.eye(n)
        M[i * n:(i + 1) * n, i * n:(i + 1) * n] -= A[i]
    H = np.zeros((len(harmonics) * p, len(harmonics) * m), complex)
    for cm, mh in enumerate(harmonics):
        U = np.eye(m)[None, :, :] * (w ** (mh * k))[:, None, None]       # (N, m, m)
        P = np.linalg.solve(M, (B @ U).reshape(N * n, m)).reshape(N, n, m)
        Y = C @ P + D @ U                                                 # (N, p, m)
        for rn, nh in enumerate(harmonics):
            H[rn * p:(rn + 1) * p, cm * m:(cm + 1) * m] = \
                np.tensordot(w ** (-nh * k), Y, axes=1) / N
    return H


def _eval(A, B, C, D, z):
    return C @ np.linalg.solve(z * np.eye(A.shape[0]) - A, B) + D


def _basis(harmonics, N):
    """Unitary map from real (cos, sin) coordinates to harmonic coordinates."""
    idx = {int(h) % N: i for i, h in enumerate(harmonics)}
    cols = []
    for h in range(int(np.abs(harmonics).max()) + 1):
        e = np.eye(len(harmonics))
        if h % N == (-h) % N:
            cols.append(e[idx[h % N]])
        else:
            a, b = e[idx[h % N]], e[idx[(-h) % N]]
            cols += [(a + b) / np.sqrt(2), 1j * (a - b) / np.sqrt(2)]
    return np.array(cols).T


@pytest.mark.parametrize("N", [6, 5])
def test_frequency_lifting_equals_dt_htf(N):
    sysd = _random_dt(N, seed=N)
    harmonics = np.arange(-(N // 2), N - N // 2)
    A, B, C, D = lift(sysd, real=False)
    for z in (np.exp(0.3j), 1.2 * np.exp(-2.1j), 0.9):
        truth = _htf_truth(sysd, z, harmonics)
        assert np.abs(_eval(A, B, C, D, z) - truth).max() < 1e-10 * np.abs(truth).max()


@pytest.mark.parametrize("N", [6, 5])
def test_real_lifting(N):
    sysd = _random_dt(N, seed=10 + N)
    harmonics = np.arange(-(N // 2), N - N // 2)
    V = _basis(harmonics, N)
    Vx, Vu, Vy = (np.kron(V, np.eye(k)) for k in (2, 2, 1))
    # the similarity leaves no imaginary part
    A, B, C, D = lift(sysd, real=False)
    for M, left, right in ((A, Vx, Vx), (B, Vx, Vu), (C, Vy, Vx), (D, Vy, Vu)):
        assert np.abs((left.conj().T @ M @ right).imag).max() < 1e-14
    L = lift(sysd)
    assert isinstance(L, ct.StateSpace) and L.dt == sysd.dt
    assert L.nstates == 2 * N and L.ninputs == 2 * N and L.noutputs == N
    for z in (np.exp(0.7j), 1.1):
        truth = Vy.conj().T @ _htf_truth(sysd, z, harmonics) @ Vu
        assert np.abs(L(z) - truth).max() < 1e-10 * np.abs(truth).max()
    expected = ['c0', 'c1', 's1', 'c2', 's2'] + (['c3'] if N == 6 else [])
    assert L.input_labels == [f'u[{i}]_{t}' for t in expected for i in range(2)]


def test_block_circulant_needed():
    # B with all harmonics: the banded Toeplitz of the printed eq. (4.68) would differ
    sysd = _random_dt(6, seed=3)
    A, B, C, D = lift(sysd, real=False)
    Bl = np.fft.fft(sysd.B.sample(6), axis=0) / 6
    # block (n, m) = (-3, 2): (n - m) mod 6 = 1, not zero as in the banded form
    w = np.exp(2j * np.pi / 6)
    assert np.allclose(B[0:2, 10:12] * w ** (-3), Bl[1])
    assert np.abs(Bl[1]).max() > 0.1


def test_truncated_lifting_central_blocks():
    # constant A and B, C, D with harmonics +-1: rows |n| <= K - 1 are exact
    N, K = 8, 2
    k = np.arange(N)
    Bk = np.stack([[[1.0 + 0.5 * np.cos(2 * np.pi * j / N)], [0.3]] for j in k])
    Ck = np.stack([[[1.0, 0.2 * np.sin(2 * np.pi * j / N)]] for j in k])
    sysd = ltp.ltpss([[0.5, 0.2], [-0.3, 0.6]], Bk, Ck, 0.1, period=1.0, dt=1 / N)
    A, B, C, D = lift(sysd, real=False, nharmonics=K)
    assert A.shape == (2 * (2 * K + 1),) * 2
    z = np.exp(0.4j)
    Ht = _eval(A, B, C, D, z)
    truth = _htf_truth(sysd, z, np.arange(-K, K + 1))
    rows = slice(1, 4)          # n = -1, 0, 1
    assert np.abs(Ht[rows] - truth[rows]).max() < 1e-12
    # the dropped harmonics matter for the outer rows
    assert np.abs(Ht[0] - truth[0]).max() > 1e-6
    Lr = lift(sysd, nharmonics=K)
    assert Lr.nstates == 10 and np.isrealobj(Lr.A)


def test_time_lifting_matches_simulation():
    N, P = 5, 4
    sysd = _random_dt(N, seed=7)
    rng = np.random.default_rng(1)
    t = sysd.dt * np.arange(N * P)
    u = rng.standard_normal((2, N * P))
    x0 = rng.standard_normal(2)
    y = ltp.forced_response(sysd, t, u, x0).outputs
    Lt = lift(sysd, method='time')
    assert Lt.dt == sysd.period and Lt.shape == (N, 2 * N)
    uL = u.reshape(2, P, N).transpose(2, 0, 1).reshape(2 * N, P)
    yL = ct.forced_response(Lt, sysd.period * np.arange(P), uL, x0).outputs
    assert np.abs(yL - y.reshape(P, N).T).max() < 1e-12 * np.abs(y).max()
    assert Lt.input_labels[:3] == ['u[0]@0', 'u[1]@0', 'u[0]@1']
    # the lifted state is the state at the period starts
    F = np.eye(2)
    for Ak in sysd.A.sample(N):
        F = Ak @ F
    assert np.allclose(Lt.A, F, atol=1e-14)


def test_lti_lifting_poles():
    # an LTI system lifted in frequency has poles p w^{-n}; in time p^N
    G = ct.ss([[0.5]], [[1.0]], [[1.0]], 0, 0.1)
    sysd = ltp.ltpss(G, 0.4)
    L = lift(sysd)
    expected = 0.5 * np.exp(-2j * np.pi * np.arange(-2, 2) / 4)
    assert np.allclose(np.sort_complex(L.poles()), np.sort_complex(expected))
    assert np.allclose(lift(sysd, method='time').A, 0.5 ** 4)


def test_bad_inputs():
    sysd = _random_dt(4)
    sysc = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    with pytest.raises(ValueError, match="sysd"):
        lift(sysc)
    with pytest.raises(ControlArgument, match="sysd"):
        lift(ct.ss([[0.5]], [[1]], [[1]], 0, 0.1))
    with pytest.raises(ValueError, match="method"):
        lift(sysd, method='fft')
    with pytest.raises(TypeError, match="harmonics"):
        lift(sysd, harmonics=2)
    with pytest.raises(ValueError, match="nharmonics"):
        lift(sysd, nharmonics=2)
    with pytest.raises(ValueError, match="nharmonics"):
        lift(sysd, method='time', nharmonics=1)
    with pytest.raises(ControlArgument, match="real"):
        lift(sysd, real='yes')


@pytest.mark.parametrize("N", [6, 5])
def test_dt_htf_is_the_central_part_of_the_frequency_lifting(N):
    # one construction serves both: the HTF's blocks -K..K are those of lift()
    sysd = _random_dt(N, seed=20 + N)
    K = (N - 1) // 2
    A, B, C, D = lift(sysd, real=False)
    full = np.arange(-(N // 2), N - N // 2)
    keep = [int(np.flatnonzero(full == k)[0]) for k in range(-K, K + 1)]
    ny, nu = sysd.noutputs, sysd.ninputs
    rows = np.concatenate([np.arange(i * ny, (i + 1) * ny) for i in keep])
    cols = np.concatenate([np.arange(i * nu, (i + 1) * nu) for i in keep])
    H = ltp.htf(sysd, K)
    z = np.array([np.exp(0.3j), 1.2 * np.exp(-2.1j), 0.9])
    for i, zi in enumerate(z):
        np.testing.assert_allclose(H(z)[..., i], _eval(A, B, C, D, zi)[np.ix_(rows, cols)],
                                   rtol=1e-11, atol=1e-13)


def test_harmonic_modules_import_at_the_top():
    # the HTF modules import each other at module level only (HTF.plot reaches
    # bode_htf through the method registry, not an import)
    import ast
    import pathlib
    root = pathlib.Path(ltp.__file__).parent
    lazy = {}
    paths = {'_htf': '_frequency/htf', '_htfplot': '_frequency/htfplot',
             '_harmonic_ss': '_frequency/harmonic_ss', '_lifting': '_core/lifting',
             '_htf_estimate': '_identification/htf_estimate',
             '_htf_fit': '_identification/htf_fit', '_ltpsys': '_core/ltpsys'}
    for mod, path in paths.items():
        tree = ast.parse((root / f'{path}.py').read_text())
        for func in ast.walk(tree):
            if isinstance(func, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for node in ast.walk(func):
                    if isinstance(node, ast.ImportFrom) and node.level >= 1:
                        lazy.setdefault(mod, set()).add(node.module.rpartition('.')[2])
    assert not any(lazy.get(m) for m in ('_htf', '_htfplot', '_harmonic_ss', '_lifting',
                                         '_htf_estimate', '_htf_fit'))
    assert not lazy.get('_ltpsys')
