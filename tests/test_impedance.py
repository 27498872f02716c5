"""Impedance workflow: network impedances as harmonic objects, exact products
with periodic models, and loops with measured (sampled) HTFs.

Truths: the impedance formulas, the product of the factors' HTFs, python-control
on LTI loops, and the Floquet multipliers of the closed loop integrated by
solve_ivp from a hand elimination of the impedance (independent of the code).
"""

import warnings

import control as ct
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

T = 1.0
WP = 2 * np.pi / T
_A0 = np.array([[-1.0, 3.0], [-3.0, -0.5]])
_A1 = np.array([[0.4, 0.3j], [0.2, -0.2]])
A = ltp.PeriodicMatrix(np.stack([_A1.conj(), _A0 + 0j, _A1]), T)
B = np.array([[1.0], [0.5]])
C = np.array([[1.0, 0.0]])
#: a small periodic "converter admittance" with C B != 0 (s L Y is biproper)
Y = ltp.ltpss(A, B, C, 0, period=T, name='Y')
#: (R, L) of grid impedances R + sL: stable and unstable closed loops
CASES = [(0.5, 0.2), (-2.0, 0.2), (2.0, -0.7)]


def floquet_radius(R, L):
    """Closed loop u = -(R y + L dy/dt), y = C x, by hand: dy/dt = C A x + C B u."""
    cb = float((C @ B)[0, 0])

    def rhs(t, x):
        At = A(t)
        K = -(R * C + L * C @ At) / (1 + L * cb)
        return ((At + B @ K) @ x.reshape(2, 2)).ravel()
    sol = solve_ivp(rhs, (0, T), np.eye(2).ravel(), method='DOP853', rtol=1e-11,
                    atol=1e-13)
    return float(np.abs(np.linalg.eigvals(sol.y[:, -1].reshape(2, 2))).max())


@pytest.fixture(scope='module')
def radii():
    return {case: floquet_radius(*case) for case in CASES}


@pytest.fixture(scope='module')
def measured():
    """Y as frequency samples on a grid of spacing ω_p/32 (components |k| <= 4)."""
    N = 8
    w = np.arange(1, 32 * (N + 2)) * WP / 32
    return ltp.HTFData(ltp.htf(Y, 4).components(w)[1], w, period=T, name='Y measured')


def test_lti_htf_is_exact_for_an_improper_impedance():
    Z = ltp.LTIHTF(ct.tf([2e-3, 0.1, 0.0], [1.0, 4.0]), 0.02, 3)    # improper
    s = np.array([0.3 + 7j, -2.0 + 1e4j])
    H = Z(s)
    wp = 2 * np.pi / 0.02
    for a, n in enumerate(range(-3, 4)):
        x = s + 1j * n * wp
        assert np.allclose(H[a, a], (2e-3 * x ** 2 + 0.1 * x) / (x + 4.0), rtol=1e-13)
    off = H.copy()
    off[np.arange(7), np.arange(7)] = 0
    assert not np.any(off)
    w, G = Z.components([1.0, 10.0])
    assert np.allclose(G[3, 0, 0], (2e-3 * (1j * w) ** 2 + 0.1j * w) / (1j * w + 4))
    assert not np.any(G[[0, 1, 2, 4, 5, 6]])


@pytest.mark.parametrize('connection, formula', [
    ('series', lambda s, R, L, C: R + s * L + 1 / (s * C)),
    ('parallel', lambda s, R, L, C: 1 / (1 / R + 1 / (s * L) + s * C)),
    ('grid', lambda s, R, L, C: (R + s * L) / (1 + s * C * (R + s * L))),
])
def test_rlc_impedance_formulas(connection, formula):
    R, L, Cap = 0.3, 2e-3, 5e-5
    Z = ltp.rlc_impedance(R, L, Cap, connection=connection, period=0.02, nharmonics=2)
    s = 0.1 + 300j
    wp = 2 * np.pi / 0.02
    H = Z(s)
    for a, n in enumerate(range(-2, 3)):
        assert np.isclose(H[a, a], formula(s + 1j * n * wp, R, L, Cap), rtol=1e-12)


def test_dq_impedance_is_the_rotated_complex_vector_impedance():
    # per phase Z(s); in dq the complex-vector impedance Z(s + jω_1)
    R, L, Cap, w1 = 0.1, 2e-3, 1e-5, 2 * np.pi * 50
    Zp = ltp.rlc_impedance(R, L, Cap, connection='grid', period=0.02, nharmonics=1)
    Zdq = ltp.rlc_impedance(R, L, Cap, connection='grid', period=0.02, nharmonics=1,
                            omega1=w1)
    s = 0.2 + 40j
    zp, zm = Zp.sys(s + 1j * w1), Zp.sys(s - 1j * w1)
    zr, zi = (zp + zm) / 2, (zp - zm) / 2j
    assert np.allclose(Zdq.sys(s), [[zr, -zi], [zi, zr]], rtol=1e-10)
    # i_d + j i_q -> v_d + j v_q is Z(s + jω_1)
    M = Zdq.sys(s)
    assert np.isclose(M[0, 0] + 1j * M[1, 0], zp, rtol=1e-10)
    three = ltp.rlc_impedance(R, L, period=0.02, nharmonics=0, nphases=3)
    assert np.allclose(three.sys(s), (R + s * L) * np.eye(3))


@pytest.mark.parametrize('bad, match', [
    (dict(R=-1.0), 'R must be >= 0'), (dict(C=0.0), 'C'), (dict(connection='star'),
                                                          'connection'),
    (dict(R=0.0, L=0.0), 'no element')])
def test_rlc_impedance_refuses_bad_networks(bad, match):
    args = dict(R=1.0, L=1e-3, period=0.02, nharmonics=1) | bad
    with pytest.raises(ValueError, match=match):
        ltp.rlc_impedance(**args)


@pytest.mark.parametrize('Z', [ct.tf([2e-3, 0.1], [1]), ct.tf([1e-3, 0.2, 1], [1, 3]),
                               ct.tf([0.5], [1, 2])])
def test_product_realization_equals_product_of_htfs(Z):
    K = 3
    Zh = ltp.LTIHTF(Z, T, K)
    s = 0.3 + 2j
    HY = ltp.htf(Y, K, internal_harmonics=25)(s)
    for left in (True, False):
        L = ltp.harmonic_product(Zh, Y) if left else ltp.harmonic_product(Y, Zh)
        want = Zh(s) @ HY if left else HY @ Zh(s)
        got = ltp.htf(L, K, internal_harmonics=25)(s)
        # the central blocks (the truncation of HY leaves the edges alone)
        assert np.allclose(got[2:5, 2:5], want[2:5, 2:5], atol=1e-12)


def test_second_derivative_needs_relative_degree_two():
    s2 = ltp.LTIHTF(ct.tf([1e-2, 0, 0], [1]), T, 2)
    with pytest.raises(ValueError, match='improper'):
        ltp.harmonic_product(s2, Y)                  # C B != 0
    # periodic C with C B = 0: s^2 Y is proper
    Cp = ltp.PeriodicMatrix(np.array([[[0.1j, 0]], [[1.0, 0]], [[-0.1j, 0]]]), T)
    Y2 = ltp.ltpss(A, [[0.0], [1.0]], Cp, 0, period=T)
    L = ltp.harmonic_product(s2, Y2)
    s = 0.1 + 1j
    want = s2(s) @ ltp.htf(Y2, 2, internal_harmonics=25)(s)
    assert np.allclose(ltp.htf(L, 2, internal_harmonics=25)(s)[1:4, 1:4],
                       want[1:4, 1:4], atol=1e-12)


def test_product_refuses_data_and_unrealizable_factors(measured):
    with pytest.raises(ValueError, match='impedance_nyquist'):
        ltp.harmonic_product(ltp.rlc_impedance(L=1.0, period=T, nharmonics=1), measured)
    with pytest.raises(ValueError, match='improper'):
        ltp.harmonic_product(ltp.rlc_impedance(L=1.0, period=T, nharmonics=1),
                             ltp.ltpss(ct.tf([1, 2], [1, 3]), period=T))


@pytest.mark.parametrize('Zn, Yn, Yd', [
    ([0.5, 1.0], [10.0], [1, 3, 3, 1]),               # stable, finite gain margin
    ([0.1, 3.0], [1.0], [1, 1, -2]),                  # open-loop unstable pole 1
])
def test_lti_impedance_loops_equal_python_control(Zn, Yn, Yd):
    Zt, Yt = ct.tf(Zn, [1]), ct.tf(Yn, Yd)
    Zh = ltp.rlc_impedance(Zn[1], Zn[0], period=1.0, nharmonics=6)
    Ylt = ltp.ltpss(Yt, period=1.0)
    resp = ltp.nyquist_htf((Zh, Ylt), 6, check=False)
    ref = ct.nyquist_response(Zt * Yt)
    assert resp.count == ref.count
    P = int(np.sum(np.real(ct.poles(Zt * Yt)) > 0))
    assert resp.open_loop_unstable == P
    if resp.stable:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')          # truncation-edge remark
            m = ltp.impedance_margins((Zh, Ylt), 6, check=False, omega_num=201)
        gm, pm, *_ = ct.stability_margins(Zt * Yt)
        # python-control's gm is the crossing of smallest |log gm|, upper or lower
        assert any(np.isclose(g, gm, rtol=1e-6) or (np.isinf(g) and np.isinf(gm))
                   for g in (m.gain_upper.value, m.gain_lower.value))
        assert np.isclose(abs(m.phase.value), abs(pm), rtol=1e-6)


def test_impedance_verdict_equals_floquet_of_the_closed_loop(radii):
    for (R, L), rho in radii.items():
        Zh = ltp.LTIHTF(ct.tf([L, R], [1]), T, 5)
        # the as_loop entry; the Floquet check is made here, independently
        resp = ltp.nyquist_htf((Zh, Y), 5, check=False)
        assert resp.stable == (rho < 1), (R, L, rho)
    assert {rho < 1 for rho in radii.values()} == {True, False}


def test_measured_admittance_verdict_equals_floquet(radii, measured):
    N = 8
    for (R, L), rho in radii.items():
        Zh = ltp.LTIHTF(ct.tf([L, R], [1]), T, N)
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')          # coarse-step remark near ω_p/2
            resp = ltp.impedance_nyquist((Zh, measured), N, open_loop_unstable=0)
        assert isinstance(resp, ltp.SampledNyquistResponse)
        assert resp.stable == (rho < 1), (R, L, rho)
        assert resp.caveats


def test_measured_loop_without_exponents_gives_no_verdict(measured):
    Zh = ltp.rlc_impedance(0.5, 0.2, period=T, nharmonics=8)
    resp = ltp.impedance_nyquist((Zh, measured), 8)
    assert resp.open_loop_unstable is None and resp.stable is None
    assert any('open_loop_unstable' in c for c in resp.caveats)
    assert 'Hz' in resp.report(Hz=True)
    with pytest.raises(ValueError, match='open_loop_unstable'):
        ltp.impedance_nyquist((Zh, measured), 8, open_loop_unstable=-1)
    with pytest.raises(ValueError, match='strip frequencies'):
        ltp.impedance_nyquist((Zh, measured), 40, open_loop_unstable=0)


def test_measured_margins_match_the_model_to_grid_accuracy(measured):
    Zh = ltp.LTIHTF(ct.tf([-1.0], [1]), T, 5)
    exact = ltp.impedance_margins((Zh, Y), 5, check=False, omega_num=201)
    data = ltp.impedance_margins((Zh, measured), 5)
    assert np.isclose(exact.gain_upper.value, 1.5, rtol=1e-9)
    assert np.isclose(data.gain_upper.value, exact.gain_upper.value, rtol=2e-3)
    assert np.isclose(data.gain_upper.frequency, exact.gain_upper.frequency, rtol=1e-2)
    assert np.isclose(data.stability.value, exact.stability.value, rtol=1e-3)
    assert data.report(Hz=True) == data.report(hz=True) != data.report()
    assert 'frequency [Hz]' in data.report(Hz=True)


def test_measured_two_phase_admittance_with_a_frame_changed_impedance():
    # a balanced grid given in dq, seen in αβ (frame_htf), times a measured
    # admittance y(s) per phase: two identical SISO loops z y (python-control)
    w1, N = 2 * np.pi, 3
    R, L = 1.0, 0.3
    Zab = ltp.frame_htf(ltp.rlc_impedance(R, L, period=T, nharmonics=N + 1, omega1=w1),
                        'dq', 'ab', w1, nharmonics=N)
    w = np.arange(1, 64 * (N + 2)) * WP / 64
    for k in (2.0, 40.0):
        y = ct.tf([k], [1, 2, 3, 1])
        G = np.zeros((1, 2, 2, w.size), complex)
        G[0, 0, 0] = G[0, 1, 1] = y(1j * w)
        Ym = ltp.HTFData(G, w, period=T)
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            resp = ltp.impedance_nyquist((Zab, Ym), N, open_loop_unstable=0)
        cl = ct.feedback(ct.tf([L, R], [1]) * y, 1)
        assert resp.stable == bool(np.all(np.real(ct.poles(cl)) < 0)), k
        assert any('FrameHTF' in c for c in resp.caveats)


def test_loop_functions_take_impedance_products():
    Zh = ltp.rlc_impedance(0.5, 0.2, period=T, nharmonics=3)
    S = ltp.sensitivity_htf((Zh, Y), 3)
    s = 0.4 + 1.3j
    Lh = Zh(s) @ ltp.htf(Y, 3, internal_harmonics=25)(s)
    want = np.linalg.inv(np.eye(7) + Lh)
    assert np.allclose(S(s)[2:5, 2:5], want[2:5, 2:5], atol=1e-9)


def test_nyquist_htf_and_harmonic_margins_take_measured_factors():
    """A loop with a measured admittance through the loop functions themselves: the
    count and margins of the sampled loop (as impedance_nyquist/impedance_margins),
    equal to the model loop's verdict; open_loop_unstable refused for model loops."""
    T = 0.02
    Y = ltp.ltpss(ct.tf([1], [2e-3, 0.1]), period=T)
    Zg = ltp.rlc_impedance(L=5e-3, period=T, nharmonics=4)
    w = np.arange(1, 2000) * 2 * np.pi / T / 16
    Yd = ltp.HTFData(ltp.htf(Y, 0).components(w)[1], w, period=T)
    sampled = ltp.nyquist_htf((Zg, Yd), 4, open_loop_unstable=0)
    model = ltp.nyquist_htf((Zg, Y), 4)
    assert isinstance(sampled, ltp.SampledNyquistResponse)
    assert sampled.stable == model.stable
    assert sampled.encirclements == ltp.impedance_nyquist((Zg, Yd), 4,
                                                          open_loop_unstable=0).encirclements
    assert repr(ltp.harmonic_margins((Zg, Yd), 4)) == repr(ltp.impedance_margins((Zg, Yd), 4))
    with pytest.raises(ValueError, match='open_loop_unstable'):
        ltp.nyquist_htf((Zg, Y), 4, open_loop_unstable=0)
