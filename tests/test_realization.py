"""Tests of the Floquet-form realization of lifted LTI models (thesis 4.2.7-4.2.9)."""

import logging

import numpy as np
import pytest
import control as ct
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp
from ltpcontrol import lift
from ltpcontrol import floquet_realization, FloquetRealization
from ltpcontrol import to_canonical, matrix_errors, MatrixErrors

from systems import mathieu

Z = np.exp(1j * np.array([0.03, 0.3, 1.1, 2.5, -2.0]))   # points on the unit circle


def _band_limited(rng, N, K, rows, cols):
    """Samples ``M[k] = Σ_{|l|<=K} M_l w^{lk}`` of a real random N-periodic matrix."""
    half = rng.standard_normal((K + 1, rows, cols)) + 1j * rng.standard_normal((K + 1, rows, cols))
    half[0] = half[0].real
    coeffs = np.concatenate([half[:0:-1].conj(), half])          # l = -K..K
    w = np.exp(2j * np.pi / N)
    return np.einsum('lk,lij->kij', w ** np.outer(np.arange(-K, K + 1), np.arange(N)),
                     coeffs).real


def _random_floquet(seed, nx, K, N, m=1, p=1, dt=0.1):
    """Stable DT LTP in Floquet form with B, C, D band-limited to K harmonics."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((nx, nx))
    A *= rng.uniform(0.3, 0.95) / np.abs(np.linalg.eigvals(A)).max()
    return ltp.ltpss(A, _band_limited(rng, N, K, nx, m), _band_limited(rng, N, K, p, nx),
                     _band_limited(rng, N, K, p, m), period=N * dt, dt=dt, name='truth')


def _scramble(L, seed):
    """The lifted model in arbitrary real coordinates, as an identification returns it."""
    S = np.random.default_rng(1000 + seed).standard_normal((L.nstates, L.nstates))
    return ct.similarity_transform(L, S)


def _dt_htf(sysd, z, K):
    """DT-HTF blocks n, m = -K..K from the periodic steady state of ``x[k] = z^k p[k]``.

    For ``u[k] = z^k w^{mk} e_i`` the N-periodic p solves
    ``z p[k+1] = A[k] p[k] + B[k] w^{mk} e_i``, found from one period of the
    recursion and the monodromy; ``Y_n = (1/N) Σ_k (C[k] p[k] + D[k] w^{mk} e_i) w^{-nk}``.
    """
    N = sysd.nsteps
    A, B, C, D = (M.sample(N) for M in (sysd.A, sysd.B, sysd.C, sysd.D))
    n, m, p = sysd.nstates, sysd.ninputs, sysd.noutputs
    w, k, harm = np.exp(2j * np.pi / N), np.arange(N), np.arange(-K, K + 1)
    U = w ** np.outer(k, harm)                                    # (N, 2K+1)
    F = np.einsum('kij,km->kimj', B, U).reshape(N, n, -1)
    q, Phi = np.zeros(F.shape[1:], complex), np.eye(n, dtype=complex)
    for j in range(N):                      # from p[0] = 0; Φ = Π A[k] / z^N
        q, Phi = (A[j] @ q + F[j]) / z, A[j] @ Phi / z
    P = np.empty(F.shape, complex)
    P[0] = np.linalg.solve(np.eye(n) - Phi, q)
    for j in range(N - 1):
        P[j + 1] = (A[j] @ P[j] + F[j]) / z
    Y = C @ P + np.einsum('kij,km->kimj', D, U).reshape(N, p, -1)
    H = np.einsum('kr,kiq->riq', w ** (-np.outer(k, harm)), Y) / N
    return H.reshape((2 * K + 1) * p, -1)


def _htf_error(sys, truth, K):
    """Largest relative deviation of the DT-HTFs on the points Z."""
    err = 0.0
    for z in Z:
        Ht = _dt_htf(truth, z, K)
        err = max(err, np.abs(_dt_htf(sys, z, K) - Ht).max() / np.abs(Ht).max())
    return err


def _response(sys, z):
    return np.array([sys(zz) for zz in z])


@pytest.fixture(scope='module')
def mathieu_dt():
    """Thesis eq. (4.115) sampled by Tustin with N = 50 steps per period."""
    sysc = mathieu()
    return sysc, ltp.sample_system(sysc, sysc.period / 50, 'tustin')


class TestDirect:
    def test_mathieu_all_inputs(self, mathieu_dt):
        sysc, sysd = mathieu_dt
        ident = _scramble(lift(sysd, nharmonics=1), 0)
        sys_res, res = floquet_realization(ident, 1, 50, return_info=True)
        assert isinstance(res, FloquetRealization)
        assert res.success and res.corrected_distance < 1e-18 and res.ladder_mismatch < 1e-9
        assert sys_res.is_floquet_form and sys_res.nsteps == 50
        assert np.isclose(sys_res.dt, sysd.dt) and np.isclose(sys_res.period, sysd.period)
        # exact DT-HTF of the realization equals the truth (D has harmonics ±2)
        assert _htf_error(sys_res, sysd, 1) < 1e-8
        np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(sys_res.A(0))),
                                   np.sort_complex(np.linalg.eigvals(sysd.A(0))), atol=1e-12)
        # T^{-1} Â T is the real lifted model of the realization itself
        T, Lr = res.transform, lift(sys_res, nharmonics=1)
        np.testing.assert_allclose(np.linalg.solve(T, ident.A @ T), Lr.A, atol=1e-10)
        np.testing.assert_allclose(np.linalg.solve(T, ident.B), Lr.B, atol=1e-10)
        np.testing.assert_allclose(ident.C @ T, Lr.C, atol=1e-10)

    def test_mathieu_thesis_comparison(self, mathieu_dt):
        # thesis 4.122-4.125: inverse Tustin, canonical form, normalised errors
        sysc, sysd = mathieu_dt
        sys_res, res = floquet_realization(_scramble(lift(sysd, nharmonics=1), 1), 1, 50,
                                           return_info=True)
        can = to_canonical(ltp.d2c(sys_res, 'tustin'))
        np.testing.assert_allclose(can.A(0), [[0, 1], [-4 * np.pi ** 2, -1.2 * np.pi]],
                                   atol=1e-9)
        err = matrix_errors(can, sysc)
        assert isinstance(err, MatrixErrors)
        assert max(err) < 1e-9

    def test_mathieu_zeroth_input_column(self, mathieu_dt):
        # the thesis identifies only the U_0 column (B̄, D̄ of 4.78-4.79)
        sysc, sysd = mathieu_dt
        ident = _scramble(lift(sysd, nharmonics=1), 2)[:, :1]
        sys_res, res = floquet_realization(ident, 1, 50, input_harmonics='zero', return_info=True)
        assert res.success and res.terms['B'] < 1e-20
        lifted = lift(sys_res, nharmonics=1)[:, :1]
        np.testing.assert_allclose(_response(lifted, Z), _response(ident, Z), atol=1e-10)
        # B and C have one harmonic and are recovered; D_{±2} is not in the U_0 column
        can, ref = to_canonical(sys_res), to_canonical(sysd)
        err = matrix_errors(can, ref)
        assert max(err.A, err.B, err.C) < 1e-9 and 1e-3 < err.D < 0.1

    def test_identified_mathieu(self, mathieu_dt):
        # thesis pipeline: U_0 column of the lifted response, noise, fdsubspace, realization
        sysc, sysd = mathieu_dt
        omega = np.linspace(0.01, 0.99 * np.pi, 300) / sysd.dt
        G = ct.frd(lift(sysd, nharmonics=1)[:, :1], omega).frdata
        rng = np.random.default_rng(0)
        G = G + 1e-6 * np.abs(G).max() * (rng.standard_normal(G.shape)
                                          + 1j * rng.standard_normal(G.shape))
        ident = ltp.fdsubspace(G, omega, 6, dt=sysd.dt, q=20)
        sys_res, res = floquet_realization(ident, 1, 50, input_harmonics='zero', return_info=True)
        assert res.success and res.fit_error < 1e-3
        err = matrix_errors(to_canonical(ltp.d2c(sys_res, 'tustin')), sysc)
        assert max(err.A, err.B, err.C) < 1e-3

    @pytest.mark.parametrize('input_harmonics', ['all', 'zero'])
    def test_random_systems(self, input_harmonics):
        rng = np.random.default_rng(7)
        failures, count = [], 24
        for seed in range(count):
            nx, K = int(rng.integers(1, 4)), int(rng.integers(0, 3))
            N = int(rng.integers(2 * K + 1, 4 * K + 8))     # includes wrapped (n-m) mod N
            m, p = int(rng.integers(1, 3)), int(rng.integers(1, 3))
            truth = _random_floquet(seed, nx, K, N, m, p)
            ident = _scramble(lift(truth, nharmonics=K), seed)
            if input_harmonics == 'zero':
                ident = ident[:, :m]
            sys_res, res = floquet_realization(ident, K, N, input_harmonics=input_harmonics,
                                               return_info=True)
            if not res.success or _htf_error(sys_res, truth, K) > 1e-8:
                failures.append((seed, nx, K, N, res.message))
        assert not failures

    def test_literal_distance(self, mathieu_dt):
        _, sysd = mathieu_dt
        ident = _scramble(lift(sysd, nharmonics=1), 3)
        sys_res, res = floquet_realization(ident, 1, 50, distance='literal', return_info=True)
        assert set(res.terms) == {'A', 'B', 'C'}
        assert np.isclose(res.distance, sum(res.terms.values()))
        # the printed demodulation e^{-j2kπ/N} leaves Im Ā ≠ 0 at the true structure
        # (errata item 5): only the corrected distance vanishes there
        assert res.success and res.corrected_distance < 1e-18
        assert res.terms['A'] > 1e-3 and res.terms['C'] < 1e-18

    def test_no_ladders_is_flagged(self):
        rng = np.random.default_rng(3)
        bad = ct.ss(0.3 * rng.standard_normal((6, 6)), rng.standard_normal((6, 3)),
                    rng.standard_normal((3, 6)), 0, 0.1)
        sys_res, res = floquet_realization(bad, 1, 12, return_info=True)
        assert not res.success and 'ladder' in res.message
        assert res.ladder_mismatch > 0.1

    def test_repeated_eigenvalues_are_flagged(self):
        sysd = ltp.ltpss(0.5 * np.eye(2), [[1.0], [2.0]], [[1.0, 1.0]], 0, period=1.0, dt=0.25)
        sys_res, res = floquet_realization(lift(sysd, nharmonics=1), 1, 4, return_info=True)
        assert not res.success and sys_res is None and 'repeated' in res.message
        with pytest.raises(ValueError, match="no Floquet realization can be formed"):
            floquet_realization(lift(sysd, nharmonics=1), 1, 4)

    def test_without_info_returns_the_model_or_warns(self):
        rng = np.random.default_rng(3)
        bad = ct.ss(0.3 * rng.standard_normal((6, 6)), rng.standard_normal((6, 3)),
                    rng.standard_normal((3, 6)), 0, 0.1)
        with pytest.warns(UserWarning, match="ladder"):
            model = floquet_realization(bad, 1, 12)
        assert isinstance(model, ltp.LTPStateSpace)
        sysd = ltp.ltpss([[0.5]], [[1.0]], [[1.0]], 0, period=1.0, dt=0.25)
        model = floquet_realization(lift(sysd, nharmonics=1), 1, 4)
        assert model.is_floquet_form and np.isclose(model.A(0)[0, 0], 0.5)

    def test_structure_violation_is_flagged(self, mathieu_dt):
        # right ladders, but an output map that is not block Toeplitz
        _, sysd = mathieu_dt
        L = lift(sysd, nharmonics=1)
        C = L.C + 0.3 * np.random.default_rng(4).standard_normal(L.C.shape)
        sys_res, res = floquet_realization(ct.ss(L.A, L.B, C, L.D, L.dt), 1, 50, return_info=True)
        assert not res.success and sys_res is not None
        assert res.corrected_distance > 1e-3 and 'no Floquet structure' in res.message


def _small_case(seed):
    truth = _random_floquet(seed, 1, 1, 12)
    return truth, _scramble(lift(truth, nharmonics=1), seed)


class TestPSO:
    @pytest.mark.slow
    def test_small_cases(self, tmp_path, monkeypatch):
        monkeypatch.chdir(tmp_path)
        handlers = list(logging.getLogger().handlers)
        outcomes = []
        for seed in range(3):
            truth, ident = _small_case(seed)
            sys_res, res = floquet_realization(ident, 1, 12, method='pso', seed=seed, progress=False,
                                      tol=1e-10, pso_options={'iters': 300},
                                      minimize_options={'maxfev': 3000}, return_info=True)
            assert res.method == 'pso' and res.nfev > 0
            if res.success:                 # a certified result recovers the true HTF
                assert _htf_error(sys_res, truth, 1) < 1e-4
            else:
                assert res.corrected_distance > 1e-10
            outcomes.append(res.success)
        assert any(outcomes)
        # the search must not reconfigure logging or write files
        assert logging.getLogger().handlers == handlers
        assert not list(tmp_path.iterdir())

    def test_seed_reproducible(self):
        _, ident = _small_case(0)
        state = np.random.get_state()[1].copy()
        opts = dict(method='pso', seed=5, progress=False, pso_options={'iters': 10},
                    minimize_options={'maxfev': 50})
        sys_r1, r1 = floquet_realization(ident, 1, 12, **opts, return_info=True)
        sys_r2, r2 = floquet_realization(ident, 1, 12, **opts, return_info=True)
        assert r1.corrected_distance == r2.corrected_distance
        np.testing.assert_array_equal(np.random.get_state()[1], state)


class TestInputs:
    @pytest.fixture
    def ident(self):
        sysd = ltp.ltpss([[0.5]], [[1.0]], [[1.0]], 0, period=1.0, dt=0.25)
        return lift(sysd, nharmonics=1)

    def test_unknown_keyword(self, ident):
        with pytest.raises(TypeError, match="unexpected keyword argument 'bogus'"):
            floquet_realization(ident, 1, 4, bogus=1)

    def test_wrong_sizes(self, ident):
        with pytest.raises(ControlDimension, match='nstates'):
            floquet_realization(ident, 2, 8)
        with pytest.raises(ControlDimension, match='ninputs'):
            floquet_realization(ident[:, :2], 1, 4)
        with pytest.raises(ValueError, match='nsteps'):
            floquet_realization(ident, 1, 2)

    def test_bad_arguments(self, ident):
        with pytest.raises(ControlArgument, match='sys'):
            floquet_realization(ident.A, 1, 4)
        with pytest.raises(ValueError, match='discrete'):
            floquet_realization(ct.ss(-np.eye(3), np.eye(3), np.eye(3), 0), 1, 4)
        with pytest.raises(ValueError, match='method'):
            floquet_realization(ident, 1, 4, method='ga')
        with pytest.raises(ValueError, match='distance'):
            floquet_realization(ident, 1, 4, distance='l2')
        with pytest.raises(ValueError, match='input_harmonics'):
            floquet_realization(ident, 1, 4, input_harmonics='none')
        with pytest.raises(ValueError, match='period'):
            floquet_realization(ident, 1, 4, period=2.0)
        with pytest.raises(ValueError, match='tol'):
            floquet_realization(ident, 1, 4, tol=-1.0)
        with pytest.raises(ControlArgument, match='seed'):
            floquet_realization(ident, 1, 4, seed=1.5)
        with pytest.raises(ValueError, match='pso_options'):
            floquet_realization(ident, 1, 4, pso_options={'iters': 5})
        with pytest.raises(TypeError, match='pso_options'):
            floquet_realization(ident, 1, 4, method='pso', pso_options={'iter': 5})
        with pytest.raises(ValueError, match='period'):
            floquet_realization(ct.ss(ident.A, ident.B, ident.C, ident.D, True), 1, 4)

    def test_timebase_true_with_period(self, ident):
        sys_res, res = floquet_realization(ct.ss(ident.A, ident.B, ident.C, ident.D, True), 1, 4,
                                  period=2.0, return_info=True)
        assert res.success and sys_res.period == 2.0 and sys_res.dt == 0.5


class TestCanonical:
    def test_canonical_invariants(self):
        rng = np.random.default_rng(2)
        truth = _random_floquet(2, 3, 1, 10)
        can = to_canonical(truth)
        # same HTF, companion A, averaged B column e_n
        assert _htf_error(can, truth, 1) < 1e-10
        np.testing.assert_allclose(can.A(0)[:-1], np.eye(3)[1:], atol=1e-10)
        np.testing.assert_allclose(np.poly(can.A(0)), np.poly(truth.A(0)), atol=1e-10)
        np.testing.assert_allclose(can.B.sample(10).mean(0)[:, 0], [0, 0, 1], atol=1e-10)
        # the canonical form does not depend on the starting coordinates
        S = rng.standard_normal((3, 3))
        moved = ltp.ltpss(np.linalg.solve(S, truth.A(0) @ S),
                          np.linalg.solve(S, truth.B.sample(10)), truth.C.sample(10) @ S,
                          truth.D.sample(10), period=truth.period, dt=truth.dt)
        assert max(matrix_errors(to_canonical(moved), can)) < 1e-9

    def test_canonical_errors(self):
        periodic_a = ltp.ltpss(np.array([[[0.5]], [[0.6]]]), [[1.0]], [[1.0]], 0,
                               period=1.0, dt=0.5)
        with pytest.raises(ValueError, match='Floquet'):
            to_canonical(periodic_a)
        unctrb = ltp.ltpss(np.diag([0.5, 0.2]), [[1.0], [0.0]], [[1.0, 1.0]], 0,
                           period=1.0, dt=0.5)
        with pytest.raises(ValueError, match='controllable'):
            to_canonical(unctrb)
        with pytest.raises(ValueError, match='input'):
            to_canonical(unctrb, input=1)
        with pytest.raises(ControlArgument, match='sys'):
            to_canonical(ct.ss(-1, 1, 1, 0))
        with pytest.raises(TypeError, match="unexpected keyword argument 'foo'"):
            to_canonical(unctrb, foo=1)

    def test_matrix_errors(self):
        sysc = mathieu()
        est = ltp.ltpss(sysc.A(0) * 1.01, sysc.B, sysc.C, 0, period=sysc.period)
        err = matrix_errors(est, sysc)
        assert np.isclose(err.A, 0.01) and err.B == 0 and err.C == 0 and err.D == 0
        # signal norm of B: mean ‖B(t)‖² = 1 + 0.4²/2 for B = [0, 1 + 0.4 cos]
        half = ltp.ltpss(sysc.A(0), 0.5 * sysc.B, sysc.C, 0, period=sysc.period)
        assert np.isclose(matrix_errors(half, sysc).B, 0.5)
        with pytest.raises(ControlDimension):
            matrix_errors(est, ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=sysc.period))
        with pytest.raises(ValueError, match='period'):
            matrix_errors(est, ltp.ltpss(sysc.A(0), sysc.B, sysc.C, 0, period=1.0))
        with pytest.raises(ControlArgument, match='true'):
            matrix_errors(est, ct.ss(-1, 1, 1, 0))
