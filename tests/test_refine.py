"""Tests of the maximum-likelihood refinement `refine_ltp`.

Truths: the HTF of the Floquet-form model from the harmonic state space
(`ltp.htf`, exact for a constant A and band-limited B, C, D), python-control
in the LTI limit, finite differences for the Jacobian, and a Monte-Carlo
study of the estimator's bias and covariance against its Cramér-Rao bound.
"""

import warnings

import control as ct
import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings, strategies as st
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp
from example_scripts import import_script
from systems import real_fourier_basis


def random_floquet(seed, nx=3, ny=1, nu=1, KB=1, KC=1, d=0.0, T=1.0, complex_pair=True):
    """Stable Floquet-form model: random basis, one complex pair when asked."""
    rng = np.random.default_rng(seed)
    if complex_pair:
        blocks = [np.array([[-1.0, 3.0], [-3.0, -1.0]])] + [[[-0.5 - 2 * i]]
                                                            for i in range(nx - 2)]
    else:
        blocks = [[[-0.7 - 1.3 * i]] for i in range(nx)]
    S = rng.standard_normal((nx, nx))
    A = S @ scipy.linalg.block_diag(*blocks) @ np.linalg.inv(S)

    def coeffs(K, rows, cols):
        c = rng.standard_normal((2 * K + 1, rows, cols)) + 1j * rng.standard_normal(
            (2 * K + 1, rows, cols))
        return (c + np.conj(c[::-1])) / 2          # P_{-h} = conj P_h: real matrix
    B, C = coeffs(KB, nx, nu), coeffs(KC, ny, nx)
    D = np.full((1, ny, nu), d)
    return ltp.ltpss(A, ltp.PeriodicMatrix(B, T), ltp.PeriodicMatrix(C, T),
                     ltp.PeriodicMatrix(D, T), T)


def perturbed(sys, seed, size=0.1):
    """The same structure with every matrix coefficient perturbed."""
    rng = np.random.default_rng(seed)
    T = sys.period

    def jitter(M, K):
        c = M.fourier(K)
        noise = (rng.standard_normal(c.shape) + 1j * rng.standard_normal(c.shape))
        noise = (noise + np.conj(noise[::-1])) / 2
        return ltp.PeriodicMatrix(c + size * np.abs(c).max() * noise, T)
    A = sys.A(0.0) @ (np.eye(sys.nstates) + size * rng.standard_normal((sys.nstates,) * 2)
                      / sys.nstates)
    return ltp.ltpss(A, jitter(sys.B, sys.B.nharmonics), jitter(sys.C, sys.C.nharmonics),
                     sys.D, T)


def data_htf(sys, K, omega, std=None):
    _, G = ltp.htf(sys, K).components(omega)
    return ltp.HTFData(G, omega, sys.period, std=None if std is None else np.broadcast_to(
        std, G.shape).copy()), G


OMEGA = np.linspace(0.2, 15.0, 40)


@pytest.mark.parametrize("seed, shape, pair", [(3, (1, 1), True), (4, (2, 2), True),
                                               (5, (1, 2), False)])
def test_noise_free_refinement_recovers_truth(seed, shape, pair):
    sys = random_floquet(seed, ny=shape[0], nu=shape[1], complex_pair=pair)
    H, G = data_htf(sys, 2, OMEGA, std=0.01)
    model, info = ltp.refine_ltp(perturbed(sys, seed), H, return_info=True)
    assert info.success and info.cost < 1e-12 < info.initial_cost
    _, Gm = ltp.htf(model, 2).components(OMEGA)
    assert np.max(np.abs(Gm - G)) < 1e-7 * np.max(np.abs(G))
    assert np.allclose(np.sort_complex(info.exponents),
                       np.sort_complex(np.linalg.eigvals(sys.A(0.0))), atol=1e-8)
    # the minimal parametrisation has a regular Fisher information
    assert np.linalg.cond(info.fisher) < 1e10
    assert len(info.names) == info.x.size == info.fisher.shape[0]
    # A comes back in real modal (block-diagonal) form
    A = model.A(0.0)
    assert np.allclose(A, np.triu(np.tril(A, 1), -1))


def test_lti_limit_matches_python_control():
    G = ct.ss([[-1.0, 2.0], [-2.0, -1.0]], [[0.0], [1.0]], [[1.0, 0.5]], [[0.1]])
    sys = ltp.ltpss(G, 1.0)
    H, _ = data_htf(sys, 1, OMEGA, std=1e-3)
    start = ltp.ltpss(ct.ss([[-1.3, 2.2], [-2.2, -1.3]], [[0.0], [1.1]], [[0.9, 0.5]],
                            [[0.1]]), 1.0)
    model = ltp.refine_ltp(start, H, harmonics=0)
    w = np.array([0.3, 1.7, 6.0])
    lti = ct.ss(model.A(0.0), model.B(0.0), model.C(0.0), model.D(0.0))
    assert np.allclose(lti(1j * w), G(1j * w), atol=1e-9)


def test_lifted_response_with_std_and_identify_ltp_start():
    true = random_floquet(6, nx=2, KB=1, KC=1)
    T, K = true.period, 1
    w = 2 * np.pi / T * (np.arange(1, 40) / 8 + 1 / 16)
    _, G = ltp.htf(true, K).components(w)
    # lifted response: G_n(jΩ) at the input lines Ω (component n at Ω + nω_p)
    Gn = np.stack([ltp.htf(true, K).components(w + n * 2 * np.pi / T)[1][n + K]
                   for n in range(-K, K + 1)])                         # (H, 1, 1, M)
    V = real_fourier_basis(K)
    frd = ct.frd((V.conj().T @ Gn[:, 0, 0])[:, None, :], w, dt=T / 20)
    start = perturbed(true, 6, 0.05)
    model, info = ltp.refine_ltp(start, frd, std=0.01, return_info=True)
    assert info.cost < 1e-12
    assert np.allclose(np.sort_complex(info.exponents),
                       np.sort_complex(np.linalg.eigvals(true.A(0.0))), atol=1e-8)
    with pytest.raises(ControlDimension, match="does not broadcast"):
        ltp.refine_ltp(start, frd, std=np.ones(5))


def _mc_draw(rng, true_G, omega, std, start):
    noise = std * (rng.standard_normal(true_G.shape)
                   + 1j * rng.standard_normal(true_G.shape)) / np.sqrt(2)
    H = ltp.HTFData(true_G + noise, omega, start.period, std=std)
    _, info = ltp.refine_ltp(start, H, return_info=True)
    return np.concatenate([info.x, info.std ** 2])


@pytest.mark.slow
def test_monte_carlo_unbiased_and_efficient():
    # cheap SISO plant, heteroscedastic noise (std ∝ |G| + floor), 120 draws
    true = random_floquet(7, nx=2, KB=1, KC=1)
    omega = np.linspace(0.3, 12.0, 30)
    H0, G = data_htf(true, 1, omega)
    std = 0.05 * np.abs(G) + 0.005
    _, crb = ltp.refine_ltp(true, ltp.HTFData(G, omega, true.period, std=std), maxiter=0,
                            return_info=True)
    res = ltp.monte_carlo(_mc_draw, 120, seed=11, n_jobs=1,
                          args=(G, omega, std, perturbed(true, 7, 0.05)))
    p = crb.x.size
    x, var_rep = res.samples[:, :p], res.samples[:, p:]
    z = (res.mean[:p] - crb.x) / res.sem[:p]
    assert np.sqrt(np.mean(z ** 2)) < 1.5 and np.max(np.abs(z)) < 4     # unbiased
    sample_var = x.var(axis=0, ddof=1)
    bound = np.diag(crb.cov)
    # reported covariance = sample covariance (pooled over parameters, ±20 %)
    assert 0.8 < np.mean(sample_var / var_rep.mean(axis=0)) < 1.2
    assert 0.8 < np.trace(np.cov(x.T) @ np.linalg.inv(crb.cov)) / p < 1.2
    # efficiency: every variance within 1.5 × the Cramér-Rao bound
    assert np.max(sample_var / bound) < 1.5
    assert np.allclose(var_rep.mean(axis=0), bound, rtol=0.1)


def test_stable_constraint_active_and_infeasible():
    true = random_floquet(8, nx=2, KB=1, KC=1)
    H, _ = data_htf(true, 1, OMEGA, std=0.01)
    start = perturbed(true, 8, 0.05)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        model, info = ltp.refine_ltp(start, H, stable=1.5, return_info=True)
    assert any("constraint is active" in str(w.message) for w in caught)
    assert info.active and np.all(info.exponents.real <= -1.5 + 1e-9)
    assert model.is_stable()
    model, info = ltp.refine_ltp(start, H, stable=True, return_info=True)
    assert not info.active and info.cost < 1e-12
    unstable = ltp.ltpss(-start.A(0.0), start.B, start.C, start.D, start.period)
    with pytest.raises(ValueError, match="constraint is infeasible"):
        ltp.refine_ltp(unstable, H, stable=True, refine_a=False)


def test_warns_when_model_cannot_explain_data():
    true = random_floquet(9, nx=2, KB=1, KC=1)
    H, _ = data_htf(true, 1, OMEGA, std=1e-4)
    poor = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, true.period)
    with pytest.warns(UserWarning, match="times its expected value"):
        ltp.refine_ltp(poor, H, harmonics=1)


def test_bad_input():
    true = random_floquet(10, nx=2)
    H, _ = data_htf(true, 1, OMEGA, std=0.01)
    periodic_a = ltp.ltpss(ltp.PeriodicMatrix([[[0.2]], [[-1.0]], [[0.2]]], 1.0), [[1.0]],
                           [[1.0]], 0, 1.0)
    with pytest.raises(ValueError, match="Floquet form"):
        ltp.refine_ltp(periodic_a, H)
    with pytest.raises(ValueError, match="repeated eigenvalues"):
        ltp.refine_ltp(ltp.ltpss(-np.eye(2), np.ones((2, 1)), np.ones((1, 2)), 0, 1.0), H)
    with pytest.raises(ControlArgument, match="must be an LTPStateSpace"):
        ltp.refine_ltp(ct.ss(-1, 1, 1, 0), H)
    with pytest.raises(ControlArgument, match="model HTF"):
        ltp.refine_ltp(true, ltp.htf(true, 1))
    with pytest.raises(ControlArgument, match="data must be"):
        ltp.refine_ltp(true, np.ones(3))
    with pytest.raises(ControlDimension, match="outputs"):
        ltp.refine_ltp(random_floquet(10, nx=2, ny=2), H)
    with pytest.raises(ValueError, match="period"):
        ltp.refine_ltp(ltp.ltpss(true.A(0.0), true.B(0.0), true.C(0.0), 0, 2.0), H)
    bad = H.std.copy()
    bad[1, 0, 0, 3] = 0
    with pytest.raises(ValueError, match="std must be positive"):
        ltp.refine_ltp(true, ltp.HTFData(H.components()[1], H.omega, 1.0, std=bad))
    with pytest.raises(ControlArgument, match="std applies"):
        ltp.refine_ltp(true, H, std=1.0)
    for kwargs, exc in (({'stable': -1.0}, ValueError), ({'maxiter': -1}, ValueError),
                        ({'tol': 2.0}, ValueError), ({'weighted': 1}, ControlArgument),
                        ({'harmonics': (1, 2)}, ValueError), ({'colour': 1}, TypeError)):
        with pytest.raises(exc):
            ltp.refine_ltp(true, H, **kwargs)
    few = ltp.HTFData(H.components()[1][:, :, :, :2], H.omega[:2], 1.0)
    with pytest.raises(ValueError, match="cannot determine"):
        ltp.refine_ltp(true, few, harmonics=(3, 6, 0))


def test_identify_ltp_refine_hook():
    # identify_ltp(..., refine='ml') equals refine_ltp on its own model
    true = random_floquet(12, nx=2, KB=1, KC=1)
    T, K, N = true.period, 1, 20
    w = 2 * np.pi / T * (np.arange(1, 40) / 8 + 1 / 16)
    H = ltp.htf(true, K)
    Gn = np.stack([H.components(w + n * 2 * np.pi / T)[1][n + K] for n in range(-K, K + 1)])
    V = real_fourier_basis(K)
    rng = np.random.default_rng(0)
    noise = 1e-3 * (rng.standard_normal(Gn.shape) + 1j * rng.standard_normal(Gn.shape))
    frd = ct.frd((V.conj().T @ (Gn + noise)[:, 0, 0])[:, None, :], w, dt=T / N)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        base = ltp.identify_ltp(frd, T, 2, K, q=12)
        hooked = ltp.identify_ltp(frd, T, 2, K, q=12, refine='ml',
                                  refine_options={'std': 1e-3 * np.sqrt(2)})
    direct = ltp.refine_ltp(base, frd, std=1e-3 * np.sqrt(2))
    assert np.allclose(np.sort_complex(np.linalg.eigvals(hooked.A(0.0))),
                       np.sort_complex(np.linalg.eigvals(direct.A(0.0))), atol=1e-8)
    with pytest.raises(ValueError, match="refine must be"):
        ltp.identify_ltp(frd, T, 2, K, q=12, refine='pem')


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10 ** 6), nx=st.integers(1, 4), ny=st.integers(1, 2),
       nu=st.integers(1, 2), pair=st.booleans())
def test_modal_pivot_form_is_a_state_transformation(seed, nx, ny, nu, pair):
    # maxiter=0 only changes the state basis: the HTF is unchanged
    sys = random_floquet(seed, nx=nx, ny=ny, nu=nu, KC=2, d=0.2,
                         complex_pair=pair and nx >= 2)
    H, G = data_htf(sys, 2, OMEGA[::4], std=1.0)
    model, info = ltp.refine_ltp(sys, H, maxiter=0, return_info=True)
    _, Gm = ltp.htf(model, 2).components(OMEGA[::4])
    assert np.allclose(Gm, G, atol=1e-9 * np.abs(G).max())
    assert info.cost < 1e-16 * np.abs(G).max() ** 2 * G.size
    assert np.linalg.matrix_rank(info.fisher) == info.x.size


@pytest.mark.slow
def test_noise_study_refinement_lowers_subspace_error():
    # the gallery study's plant and data (SNR 12.5, per-experiment noise), 8 draws
    study = import_script('plot_noise_study')     # examples/ on the path, for its imports
    res = ltp.monte_carlo(study.draw, 8, seed=2017, n_jobs=1)
    sub, ml = res.samples[:, 0], res.samples[:, 1]
    assert np.all(sub < 0.02)                       # the subspace model forms
    # measured: ML better in 7 of 8 draws, median 4.4e-3 -> 3.4e-3
    assert np.mean(ml < sub) >= 0.75 and np.median(ml) < 0.85 * np.median(sub)
