"""Harmonic state space, lifting from any start step, LTI-only requests."""

import warnings

import numpy as np
import pytest
import control as ct

import ltpcontrol as ltp
from analysis_systems import stable_rss
from systems import mathieu, real_fourier_basis, switching_mathieu


@pytest.mark.parametrize('make', [mathieu, switching_mathieu])
def test_harmonic_ss_response_is_the_htf(make):
    sys = make()
    K = 2
    H = ltp.htf(sys, K, internal_harmonics=30)
    Hs = ltp.harmonic_ss(sys, K, internal_harmonics=30)
    V = real_fourier_basis(K)
    Vu, Vy = np.kron(V, np.eye(sys.ninputs)), np.kron(V, np.eye(sys.noutputs))
    for s in (0.3j, 1.7j, 0.2 + 5j):
        assert np.allclose(Hs(s), Vy.conj().T @ H(s) @ Vu, rtol=1e-10, atol=1e-12)
    # HTF.to_ss is the same system
    assert np.allclose(H.to_ss()(0.3j), Hs(0.3j), rtol=1e-12)
    # the frequency response through python-control
    resp = ct.frequency_response(Hs, [1.0])
    assert np.allclose(resp.complex[:, :, 0], Vy.conj().T @ H(1j) @ Vu, rtol=1e-10)


def test_harmonic_ss_lti():
    G = stable_rss(2, 1, 1, seed=1)
    Hs = ltp.harmonic_ss(ltp.ltpss(G, period=2.0), 1)
    assert np.isclose(Hs(0.4j)[0, 0], G(0.4j), rtol=1e-12)
    with pytest.raises(ValueError, match="lift"):
        ltp.harmonic_ss(ltp.ltpss(ct.c2d(G, 0.1), period=0.5), 1)
    # frequency data have no state space: the method exists only on models
    data = ltp.HTFData(np.ones((1, 1, 1, 2)), [1.0, 2.0], period=1.0)
    assert not hasattr(data, 'to_ss')


@pytest.mark.parametrize('N', [4, 5])
def test_lift_start_gramians_and_hankel(N):
    rng = np.random.default_rng(N)
    A = 0.5 * rng.standard_normal((N, 3, 3))
    B, C = rng.standard_normal((N, 3, 2)), rng.standard_normal((N, 1, 3))
    sys = ltp.ltpss(A, B, C, 0, period=N * 0.1, dt=0.1)
    P = ltp.gram(sys, 'c').sample(N)
    Q = ltp.gram(sys, 'o').sample(N)
    hsv = []
    for k in range(N):
        L = ltp.lift(sys, method='time', start=k)
        # A_L = Φ(k + N, k); the lifted gramians are the periodic ones at step k
        Phi = np.eye(3)
        for j in range(N):
            Phi = A[(k + j) % N] @ Phi
        assert np.allclose(L.A, Phi, rtol=1e-12, atol=1e-12)
        assert np.allclose(ct.dlyap(L.A, L.B @ L.B.T), P[k], rtol=1e-9)
        assert np.allclose(ct.dlyap(L.A.T, L.C.T @ L.C), Q[k], rtol=1e-9)
        Pl, Ql = ct.dlyap(L.A, L.B @ L.B.T), ct.dlyap(L.A.T, L.C.T @ L.C)
        hsv.append(np.sqrt(np.linalg.eigvals(Pl @ Ql).real.max()))
    # the Hankel norm is the maximum over the start steps
    assert np.isclose(ltp.norm(sys, 'hankel'), max(hsv), rtol=1e-9)
    with pytest.raises(ValueError, match="start"):
        ltp.lift(sys, start=N)


def test_lti_only_requests_name_the_htf():
    sys = mathieu()
    with pytest.raises(TypeError, match="ltp.htf"):
        ct.frequency_response(sys, [1.0])
    with pytest.raises(TypeError, match="ltp.htf"):
        ct.dcgain(sys)


def test_harmonic_ss_of_static_periodic_gain():
    # a zero-state system: its HTF is the Toeplitz matrix of D(t) at every s
    K = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[1 + 0.5 * np.cos(2 * np.pi * t), 0.2 * np.sin(4 * np.pi * t)]]),
        1.0)
    gain = ltp.ltpss(K)
    Kh = 2
    c = K.fourier(2 * Kh)
    harm = np.arange(-Kh, Kh + 1)
    toeplitz = c[harm[:, None] - harm[None, :] + 2 * Kh].transpose(0, 2, 1, 3).reshape(
        (2 * Kh + 1), 2 * (2 * Kh + 1))
    assert np.allclose(ltp.htf(gain, Kh)(0.3j), toeplitz, rtol=0, atol=1e-14)
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        Hs = ltp.harmonic_ss(gain, Kh)
    assert Hs.nstates == 0 and Hs.modes.eigenvalues.size == 0 and Hs.modes.stable
    # the same gain with a decoupled state goes through the dynamic path
    ref = ltp.harmonic_ss(ltp.ltpss([[-1.0]], np.zeros((1, 2)), [[0.0]], K, period=1.0), Kh)
    assert np.allclose(Hs.D, ref.D, rtol=0, atol=1e-14)
    assert Hs.input_labels == ref.input_labels and Hs.output_labels == ref.output_labels
