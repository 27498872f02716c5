"""Generalized Nyquist criterion and margins of periodic loops against
independent truths: closed-loop monodromy integrated by solve_ivp, and
python-control on LTI loops written as periodic."""

import warnings

import numpy as np
import control as ct
import pytest
from control.exception import ControlDimension
from hypothesis import assume, given, settings, strategies as st
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

import ltpcontrol as ltp

# damped Mathieu plant x'' + c x' + (a + b cos t) x = u, y = x, inside the first
# instability tongue: one open-loop multiplier below -1 (P = 1)
A_, B_, C_ = 0.2, 0.8, 0.05
T = 2 * np.pi
K0 = 0.55          # a stabilizing output gain


def mathieu():
    A = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-(A_ + B_ * np.cos(t)), -C_]]), T)
    return ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T, name='mathieu')


def closed_loop_radius(gain):
    """Spectral radius of the closed-loop monodromy (u = -gain y, gain may be
    complex) by solve_ivp: independent of the library."""
    def rhs(t, x):
        X = x.reshape(2, 2)
        A = np.array([[0.0, 1.0], [-(A_ + B_ * np.cos(t)) - gain, -C_]])
        return (A @ X).ravel()
    sol = solve_ivp(rhs, (0, T), np.eye(2, dtype=complex).ravel(), rtol=1e-11,
                    atol=1e-13, method='DOP853')
    return np.abs(np.linalg.eigvals(sol.y[:, -1].reshape(2, 2))).max()


def bisect(fun, lo, hi, tol=1e-7):
    """Boundary between fun(lo) < 1 and fun(hi) >= 1 (or the reverse)."""
    flo = fun(lo) < 1
    assert flo != (fun(hi) < 1)
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if (fun(mid) < 1) == flo:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def test_open_loop_has_one_unstable_multiplier():
    assert closed_loop_radius(0.0) > 1
    mu = np.abs(ltp.floquet_multipliers(mathieu()))
    assert np.count_nonzero(mu > 1) == 1


@pytest.mark.parametrize("N", [5, 10, 20])
def test_mathieu_loop_one_encirclement(N):
    resp = ltp.nyquist_htf((mathieu(), K0), N)
    assert resp.open_loop_unstable == 1
    assert resp.encirclements == 1
    assert resp.stable and resp.closed_loop_unstable == 0
    assert closed_loop_radius(K0) < 1


def test_closure_gap_shrinks_with_truncation():
    gaps = [ltp.nyquist_htf((mathieu(), K0), N).closure_gap for N in (5, 10, 20)]
    assert gaps[0] > gaps[1] > gaps[2]
    assert gaps[2] < 1e-4


def test_nyquist_verdict_agrees_with_floquet_over_gains():
    G = mathieu()
    checked = 0
    for k in np.linspace(0.05, 2.5, 11):
        rho = closed_loop_radius(k)
        if abs(rho - 1) < 1e-3:
            continue            # at a stability boundary
        resp = ltp.nyquist_htf((G, k), 6)
        assert resp.stable == (rho < 1), (k, rho, resp)
        checked += 1
    assert checked >= 9


@pytest.fixture(scope='module')
def mathieu_margins():
    return ltp.harmonic_margins((mathieu(), K0), 10)


def test_gain_margins_equal_floquet_bisection(mathieu_margins):
    m = mathieu_margins
    k_hi = bisect(closed_loop_radius, K0, 0.8)
    k_lo = bisect(closed_loop_radius, 0.2, K0)
    assert abs(m.gain_upper.value - k_hi / K0) < 1e-4
    assert abs(m.gain_lower.value - k_lo / K0) < 1e-4
    # the lower margin sits at the multiplier -1: the strip edge ω_p/2
    assert abs(abs(m.gain_lower.omega) - 0.5) < 1e-6
    mu = np.linalg.eigvals(_monodromy(k_lo))
    assert np.min(np.abs(mu + 1)) < 1e-3
    # the upper one at the multiplier +1 (ω = 0)
    assert abs(m.gain_upper.omega) < 1e-6


def _monodromy(gain):
    def rhs(t, x):
        X = x.reshape(2, 2)
        return (np.array([[0.0, 1.0], [-(A_ + B_ * np.cos(t)) - gain, -C_]]) @ X).ravel()
    sol = solve_ivp(rhs, (0, T), np.eye(2).ravel(), rtol=1e-11, atol=1e-13, method='DOP853')
    return sol.y[:, -1].reshape(2, 2)


def test_phase_margin_equals_floquet_bisection(mathieu_margins):
    pm = np.radians(abs(mathieu_margins.phase.value))

    def radius(phi):
        return closed_loop_radius(K0 * np.exp(-1j * phi))
    grid = np.linspace(0, np.pi, 91)
    first = next(p for p in grid if radius(p) >= 1)
    phi = bisect(radius, first - grid[1], first)
    assert abs(phi - pm) < 1e-4


def test_stability_margin_is_inverse_sensitivity_peak(mathieu_margins):
    S = ltp.sensitivity_htf((mathieu(), K0), 10)
    w = mathieu_margins.stability.omega
    peak = np.linalg.svd(S(1j * w), compute_uv=False)[0]
    assert abs(1 / peak - mathieu_margins.stability.value) < 1e-8


LTI_LOOPS = [
    ct.tf([4], [1, 3, 3, 1]),
    ct.tf([3], [1, 3, 2, 0]),                    # integrator
    ct.tf([2, 1], [1, 0.4, 1]) * ct.tf([1], [1, 3]),
    ct.tf([10], [1, 2, 3, 4]),                   # unstable closed loop
]


@pytest.mark.parametrize("G", LTI_LOOPS)
def test_lti_loop_margins_are_python_controls(G):
    ours = ltp.stability_margins(ltp.ltpss(G, period=1.0), nharmonics=6)
    theirs = ct.stability_margins(G)
    np.testing.assert_allclose(ours, theirs, rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("G", LTI_LOOPS + [ct.tf([2], [1, -1]),
                                           ct.tf([4, 4], [1, 1, -2])])
def test_lti_loop_count_is_python_controls(G):
    resp = ltp.nyquist_htf(ltp.ltpss(G, period=0.25), 8)
    assert resp.count == ct.nyquist_response(G).count
    stable = bool(np.all(ct.poles(ct.feedback(G, 1)).real < 0))
    assert resp.stable == stable


def test_lti_disk_margin_is_python_controls():
    G = ct.tf([2, 1], [1, 0.4, 1]) * ct.tf([1], [1, 3])
    m = ltp.harmonic_margins(ltp.ltpss(G, period=1.0), 6)
    # python-control on a fine grid around the peak: its values are at most the
    # grid's discretization above the refined ones
    omega = np.linspace(1.3, 2.3, 20001)
    dm, dgm, dpm = ct.disk_margins(G, omega)
    assert 0 <= dm - m.disk.value < 1e-6
    assert abs(20 * np.log10(min(1 / m.disk_gain[0], m.disk_gain[1])) - dgm) < 1e-5
    assert abs(m.disk_phase - dpm) < 1e-4
    assert 1.3 < m.disk.frequency < 2.3


def test_bad_loops():
    G = mathieu()
    wide = ltp.ltpss(G.A, G.B, [[1.0, 0.0], [0.0, 1.0]], 0, period=T)
    with pytest.raises(ControlDimension, match="square"):
        ltp.nyquist_htf(wide, 5)
    with pytest.raises(ControlDimension, match="square"):
        ltp.harmonic_margins(wide, 5)
    other = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=np.sqrt(2))
    with pytest.raises(ValueError, match="incommensurate"):
        ltp.nyquist_htf((G, other), 5)
    with pytest.raises(ct.ControlArgument):
        ltp.nyquist_htf(ct.tf([1], [1, 1]), 5)          # an LTI loop needs a period
    with pytest.raises(ValueError, match="nharmonics"):
        ltp.nyquist_htf(G, 0)
    with pytest.raises(ValueError, match="strip"):
        ltp.nyquist_htf(G, 3, omega=[0.0, 2.0])


def test_too_few_harmonics_warns():
    # 2/(s+1) with ω_p = 2π: |L| at the truncation edge is not small for N = 1
    L = ltp.ltpss(ct.tf([20], [1, 1]), period=1.0)
    with pytest.warns(UserWarning, match="truncation edge"):
        ltp.nyquist_htf(L, 1, check=False)
    with pytest.warns(UserWarning, match="truncation edge"):
        ltp.harmonic_margins(L, 1)
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        ltp.nyquist_htf(ltp.ltpss(ct.tf([2], [1, 1]), period=0.1), 5)


def test_plot_is_a_controlplot():
    resp = ltp.nyquist_htf((mathieu(), K0), 4)
    cplt = resp.plot()
    assert isinstance(cplt, ct.ControlPlot)
    assert isinstance(resp.plot('det'), ct.ControlPlot)
    with pytest.raises(ValueError, match="kind"):
        resp.plot('bode')


def _pll_loop(f_bw):
    """Single-phase PLL linearized about its periodic steady state: the phase
    detector gain (V/2)(1 + cos 2ω_g t) ripples at twice the grid frequency;
    second-order low-pass filter and PI (two integrators on the axis)."""
    V, wg = 1.0, 2 * np.pi * 50
    bw = 2 * np.pi * f_bw
    kp, ki, a = bw / (V / 2), bw ** 2 / (2 * V), 3 * bw
    A = np.array([[-a, 0, 0, 0], [a, -a, 0, 0], [0, 1, 0, 0], [0, kp, ki, 0]])
    b = np.array([a, 0, 0, 0])

    def g(t):
        return V / 2 * (1 + np.cos(2 * wg * t))
    Tp = np.pi / wg
    # g has the exact Fourier series V/4, V/2, V/4 at harmonics -1, 0, 1 of ω_p = 2ω_g
    C = ltp.PeriodicMatrix(np.array([[[0, 0, 0, V / 4]], [[0, 0, 0, V / 2]],
                                     [[0, 0, 0, V / 4]]]), Tp)
    L = ltp.ltpss(A, b[:, None], C, 0, period=Tp, name='pll')

    def radius(k):
        def rhs(t, x):
            X = x.reshape(4, 4)
            return ((A - k * np.outer(b, [0, 0, 0, g(t)])) @ X).ravel()
        sol = solve_ivp(rhs, (0, Tp), np.eye(4).ravel(), rtol=1e-11, atol=1e-13,
                        method='DOP853')
        return np.abs(np.linalg.eigvals(sol.y[:, -1].reshape(4, 4))).max()
    return L, radius


@pytest.mark.parametrize("f_bw, edge", [(30, True), (45, False)])
def test_pll_gain_margin_equals_floquet_bisection(f_bw, edge):
    # 30 Hz: crossing at the multiplier -1 (strip edge); 45 Hz: at the multiplier
    # +1, where the open loop's integrators sit on the axis
    L, radius = _pll_loop(f_bw)
    m = ltp.harmonic_margins(L, 8)
    g = m.gain_upper.value
    k = bisect(radius, 0.99 * g, 1.01 * g, tol=2e-5 * g)
    assert abs(m.gain_upper.value - k) < 1e-4 * k
    assert (abs(abs(m.gain_upper.omega) - L.omega_p / 2) < 1e-6 * L.omega_p) == edge
    resp = ltp.nyquist_htf(L, 8)
    assert resp.stable and radius(1.0) < 1
    assert not ltp.nyquist_htf(ltp.series(L, 1.01 * k), 8).stable


@settings(max_examples=10, deadline=None)
@given(k=st.floats(0.2, 30), a=st.floats(0.3, 3), b=st.floats(0.3, 3),
       c=st.floats(-2, 4))
def test_lti_loops_match_python_control(k, a, b, c):
    # k (s + c) / ((s + a)(s + b)(s + 1)) written as periodic: same count, same margins
    G = ct.tf([k, k * c], np.polymul([1, a + b, a * b], [1, 1]))
    cl = ct.poles(ct.feedback(G, 1))
    assume(np.all(np.abs(cl.real) > 1e-3))        # not at a stability boundary
    assume(abs(abs(k * c / (a * b)) - 1) > 1e-3)    # no tangency of |L| = 1 at ω = 0
    assume(abs(c) > 1e-3)                            # L(0) = 0 is a degenerate crossing
    L = ltp.ltpss(G, period=0.1)
    resp = ltp.nyquist_htf(L, 6)
    assert resp.count == ct.nyquist_response(G).count
    assert resp.stable == bool(np.all(cl.real < 0))
    ours, theirs = ltp.stability_margins(L, nharmonics=6), ct.stability_margins(G)
    np.testing.assert_allclose(ours[:2], theirs[:2], rtol=1e-6, atol=1e-9)
    # python-control's sm is the least interior local minimum of |1 + L(jω)|, ω > 0;
    # ours the minimum over all ω (also at ω = 0): a dense grid decides
    w = np.concatenate([[0.0], np.logspace(-3, 3, 20001)])
    dist = np.abs(1 + G(1j * w))
    i = int(np.argmin(dist))
    local = minimize_scalar(lambda x: abs(1 + G(1j * x)), method='bounded',
                            bounds=(w[max(i - 1, 0)], w[min(i + 1, len(w) - 1)]),
                            options={'xatol': 1e-12})
    dense = min(dist[i], local.fun)
    assert abs(ours[2] - dense) <= 1e-7 and ours[2] <= theirs[2] + 1e-9


def test_mimo_loop_generalisations():
    # a diagonal 2x2 LTI loop written as periodic: the counts add up, and the
    # uniform-gain margins are those of the more fragile channel
    G1, G2 = ct.tf([4], [1, 3, 3, 1]), ct.tf([2, 1], [1, 0.4, 1]) * ct.tf([1], [1, 3])
    G = ct.append(ct.ss(G1), ct.ss(G2))
    L = ltp.ltpss(G, period=0.5)
    resp = ltp.nyquist_htf(L, 6)
    assert resp.count == ct.nyquist_response(G1).count + ct.nyquist_response(G2).count
    m = ltp.harmonic_margins(L, 6)
    s1, s2 = ct.stability_margins(G1), ct.stability_margins(G2)
    assert abs(m.gain_upper.value - min(s1[0], s2[0])) < 1e-8
    assert abs(abs(m.phase.value) - min(abs(s1[1]), abs(s2[1]))) < 1e-6
    assert abs(m.stability.value - min(s1[2], s2[2])) < 1e-8


def test_edge_warning_says_when_the_floquet_check_confirmed_the_margin():
    # 4/(s+1)³ with ω_p = 1.2: |L̂| reaches 0.3 in the edge blocks at N = 2, yet the
    # gain margin 2 (python-control's) is confirmed by the closed-loop exponents
    G = ct.tf([4], [1, 3, 3, 1])
    L = ltp.ltpss(G, period=2 * np.pi / 1.2)
    with pytest.warns(UserWarning, match="truncation edge") as rec:
        m = ltp.harmonic_margins(L, 2)
    assert m.gain_upper.value == pytest.approx(ct.stability_margins(G)[0], rel=1e-9)
    msg = " ".join(str(w.message) for w in rec)
    assert "gain margins are confirmed" in msg and "may be missed" not in msg
    with pytest.warns(UserWarning, match="may be missed"):
        ltp.harmonic_margins(L, 2, check=False)
