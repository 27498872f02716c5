"""Nyquist criterion and margins of periodic loops with delays (exact e^{-sτ}).

Every verdict of `nyquist_htf` is checked against the multipliers of the
closed delayed loop (`is_stable`, spectral-element monodromy) and, for LTI
plants written as periodic, against python-control on a high-order Padé
approximation of the delay; the margins against python-control on the
exact frequency response ``e^{-jωτ} G(jω)``.
"""

import warnings

import numpy as np
import control as ct
import pytest

import ltpcontrol as ltp


def _pade_unstable(G, tau, order=12):
    """Closed-loop poles of G e^{-sτ} (Padé) in the open right half plane (python-control)."""
    num, den = ct.pade(tau, order)
    L = G * ct.tf(num, den)
    cl = ct.feedback(L, 1)
    poles_cl = int(np.count_nonzero(ct.poles(cl).real > 1e-9))
    # python-control's Nyquist count agrees: Z = N + P
    P = int(np.count_nonzero(ct.poles(L).real > 1e-9))
    resp = ct.nyquist_response(L, omega=np.geomspace(1e-3, 1e3, 4000), warn_encirclements=False,
                               warn_nyquist=False)
    assert resp.count + P == poles_cl
    return poles_cl


@pytest.mark.parametrize("num, den, tau", [
    ([2.0], [1.0, -1.0], 0.3),           # unstable plant, stabilized (τ < 0.6046)
    ([2.0], [1.0, -1.0], 0.7),           # ... destabilized by the delay
    ([3.0], [1.0, 2.0, 1.0], 0.2),       # stable plant, stable loop
    ([3.0], [1.0, 2.0, 1.0], 1.5),       # ... unstable loop
])
def test_nyquist_of_input_delayed_lti_loop_equals_pade_and_closed_loop(num, den, tau):
    G = ct.tf(num, den)
    P = ltp.ltpss(G, period=0.5)
    with warnings.catch_warnings():
        warnings.simplefilter('error')                  # no contradiction, no boundary
        resp = ltp.nyquist_htf((P, ltp.delay(tau)), 3)
    cl = ltp.feedback(ltp.series(ltp.delay(tau), P), 1.0)
    assert resp.open_loop_unstable == int(np.any(np.roots(den).real > 0))
    assert resp.floquet_unstable == resp.closed_loop_unstable
    assert resp.stable == ltp.is_stable(cl)
    assert resp.closed_loop_unstable == _pade_unstable(G, tau)


def _mathieu_plant(delta=1.2, eps=0.4, c=0.3):
    """x'' + c x' + (δ + ε cos 2t) x = u, period π (unstable at δ = 1, ε = 0.8, c = 0.1)."""
    A = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-delta - eps * np.cos(2 * t), -c]]), np.pi)
    return ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, np.pi)


def test_nyquist_of_periodic_loops_with_input_delay_equals_closed_loop_multipliers():
    stable_plant, unstable_plant = _mathieu_plant(), _mathieu_plant(1.0, 0.8, 0.1)
    seen = set()
    for P, k, tau in [(stable_plant, 0.5, 0.3), (stable_plant, 3.0, 1.0),
                      (unstable_plant, 1.5, 0.05), (unstable_plant, 1.5, 0.2)]:
        with warnings.catch_warnings():
            warnings.simplefilter('error')
            resp = ltp.nyquist_htf((k * P, ltp.delay(tau)), 4, check=False, closure_tol=0.1)
        assert resp.open_loop_unstable == int(not ltp.is_stable(P))
        cl = ltp.feedback(ltp.series(ltp.delay(tau), k * P), 1.0)
        assert resp.stable == ltp.is_stable(cl)
        seen.add((resp.open_loop_unstable, resp.stable))
    assert seen == {(0, True), (0, False), (1, True), (1, False)}


@pytest.mark.parametrize("k, stable", [(0.3, False), (1.0, True)])
def test_nyquist_counts_the_open_loops_delayed_exponents(k, stable):
    # x' = 0.5 x(t - 1) + u: one unstable exponent from the delayed monodromy;
    # closed by u = -k x it is stable iff k > 0.5
    L = ltp.ltpdss([[0.0]], [[k]], [[1.0]], 0, period=1.0, delays=[(1.0, [[0.5]])])
    resp = ltp.nyquist_htf(L, 4)
    assert resp.open_loop_unstable == 1
    assert resp.stable is stable and resp.floquet_unstable == resp.closed_loop_unstable
    assert ltp.is_stable(ltp.feedback(L, 1.0)) is stable


def test_margins_of_input_delayed_lti_loop_equal_python_control_on_exact_response():
    G = ct.tf([2.0], [1.0, 1.5, 1.0])
    tau = 0.25
    m = ltp.harmonic_margins((ltp.ltpss(G, period=1.0), ltp.delay(tau)), 4, check=False)
    w = np.linspace(0.01, 6.0, 3001)
    gm, pm, _, wpc, wgc, _ = ct.stability_margins(ct.frd(G(1j * w) * np.exp(-1j * w * tau), w))
    np.testing.assert_allclose([m.gain_upper.value, m.phase.value], [gm, pm], rtol=1e-7)
    np.testing.assert_allclose([m.gain_upper.frequency, m.phase.frequency], [wpc, wgc],
                               rtol=1e-6)
    np.testing.assert_allclose(m.delay_margin, np.radians(pm) / wgc, rtol=1e-6)
    assert "delay [s]" in m.report()


def test_margins_of_periodic_delayed_loop_are_the_closed_loops_boundaries():
    P, tau = _mathieu_plant(), 0.3
    L = ltp.series(ltp.delay(tau), P)
    with warnings.catch_warnings():
        warnings.simplefilter('error')                  # the gain-margin check passes
        m = ltp.harmonic_margins(L, 6)
    k = m.gain_upper.value
    assert 1 < k < np.inf
    assert ltp.is_stable(ltp.feedback(0.999 * k * L, 1.0))
    assert not ltp.is_stable(ltp.feedback(1.001 * k * L, 1.0))
    d = m.delay_margin
    assert 0 < d < np.inf
    assert ltp.is_stable(ltp.feedback(ltp.series(ltp.delay(0.999 * d), L), 1.0))
    assert not ltp.is_stable(ltp.feedback(ltp.series(ltp.delay(1.001 * d), L), 1.0))


def test_bad_input_of_delayed_loops():
    L = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(0.5, [[0.2]])])
    with pytest.raises(TypeError, match="floquet_steps"):
        ltp.nyquist_htf(L, 3, floquet_steps=100)
    with pytest.raises(TypeError, match="floquet_steps"):
        ltp.harmonic_margins(L, 3, floquet_steps=100)
    with pytest.raises(ValueError, match="check"):
        ltp.nyquist_htf(L, 3, check='yes')
    wide = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0], [2.0]], 0, period=1.0,
                      delays=[(0.5, [[0.2]])])
    with pytest.raises(ct.ControlDimension, match="square"):
        ltp.nyquist_htf(wide, 3)
    with pytest.raises(ValueError, match="nharmonics"):
        ltp.harmonic_margins(L, 0)


@pytest.mark.parametrize("tau", [0.1, 1.0])
def test_nyquist_of_mimo_delayed_loop_equals_pade_and_closed_loop(tau):
    G = ct.ss(ct.tf([[[1.0], [0.5]], [[0.2], [2.0]]],
                    [[[1.0, 1.0], [1.0, 2.0]], [[1.0, 3.0], [1.0, 1.0]]]))
    P = ltp.ltpss(2 * G, 1.0)
    resp = ltp.nyquist_htf((P, ltp.delay(tau)), 2, check=False, closure_tol=1.0)
    assert resp.stable == ltp.is_stable(ltp.feedback(ltp.series(ltp.delay(tau), P), np.eye(2)))
    pade = ct.ss(ct.tf(*ct.pade(tau, 12)))
    cl = ct.feedback(2 * G * ct.append(pade, pade), np.eye(2))
    assert resp.closed_loop_unstable == int(np.count_nonzero(ct.poles(cl).real > 1e-9))
