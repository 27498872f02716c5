"""Lifted response and LTP identification from an HTF estimate; models at given parameters."""

import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp

T = 0.5
WP = 2 * np.pi / T


def _plant():
    # ẋ = -2x + (1 + 0.5 cos 2ω_p t... ) u: input gain with harmonics ±1 (ω_p = 4π)
    return ltp.ltpss([[-2.0]], lambda t: np.array([[1 + 0.5 * np.cos(WP * t)]]),
                     [[1.0]], 0, period=T)


def _htf_data(sys, K, nbins=8, nfreq=120):
    """Exact components of `sys` as a data HTF on a grid of spacing ω_p/nbins."""
    omega = np.arange(nfreq) * WP / nbins
    _, G = ltp.htf(sys, K).components(omega)
    return ltp.HTFData(G, omega, T, std=np.full(G.shape, 1e-3))


def test_lifted_response_from_htf_equals_sine_experiments():
    sys = _plant()
    lines = np.pi / 2 * np.array([k for k in range(1, 16) if k % 4])     # off ω_p/2 multiples
    exc = ltp.sine_experiments(lines, T, dt=0.0125, nperiods=8, settle=12)
    resp = ltp.forced_response(sys, exc.time, exc.inputs)
    G_rec = ltp.lifted_frequency_response(resp, T, 2, transient=6.0, input_hold='foh',
                                          real=False)
    G_htf = ltp.lifted_frequency_response(_htf_data(sys, 6), T, 2, real=False)
    # the HTF gives every grid line but those at multiples of ω_p/2
    assert not np.any(np.isclose(np.mod(2 * G_htf.omega / WP, 1.0), 0.0))
    idx = np.searchsorted(G_htf.omega, G_rec.omega)
    assert np.allclose(G_htf.omega[idx], G_rec.omega)
    assert np.allclose(G_htf.frdata[..., idx], G_rec.frdata, atol=1e-4)
    # real coordinates: the unitary map of the complex harmonics, every line below Nyquist
    G_real = ltp.lifted_frequency_response(_htf_data(sys, 6), T, 2)
    assert np.allclose(np.linalg.norm(G_real.frdata, axis=0),
                       np.linalg.norm(G_htf.frdata, axis=0))
    assert G_real.omega.max() * G_real.dt < np.pi


def test_lifted_response_from_htf_keeps_lines_with_all_components():
    sys = _plant()
    H = _htf_data(sys, 3)
    _, G = H.components()
    G[3 + 2, ..., 40:] = np.nan            # G_2 unknown at output frequencies 5 ω_p and up
    Hn = ltp.HTFData(G, H.omega, T)
    Gl = ltp.lifted_frequency_response(Hn, T, 2, real=False)
    assert np.all(Gl.omega + 2 * WP < H.omega[40])
    assert np.all(np.isfinite(Gl.frdata))
    with pytest.raises(ValueError, match="exceeds the HTF's"):
        ltp.lifted_frequency_response(Hn, T, 4)
    with pytest.raises(ValueError, match="period"):
        ltp.lifted_frequency_response(Hn, 2 * T, 1)
    with pytest.raises(ControlArgument, match="model HTF"):
        ltp.lifted_frequency_response(ltp.htf(sys, 1), T, 1)


def test_identify_ltp_from_htf_refines_on_its_components():
    sys = _plant()
    H = _htf_data(sys, 3)
    model, info = ltp.identify_ltp(H, T, 1, 1, estimate_d=False, refine='ml',
                                   return_info=True)
    assert info.success
    assert np.allclose(model.A(0.0), [[-2.0]], atol=1e-6)
    cmp = ltp.compare_ltp(model, sys, H.omega[1:40], 2)
    assert cmp.htf_error < 1e-6
    with pytest.raises(TypeError, match="only apply to time"):
        ltp.identify_ltp(H, T, 1, 1, transient=1.0)


def test_refine_info_realize_rebuilds_the_model():
    sys = _plant()
    H = _htf_data(sys, 2)
    start = ltp.ltpss([[-1.5]], ltp.PeriodicMatrix([[[0.3]], [[1.2]], [[0.3]]], T),
                      [[1.0]], 0, period=T)
    model, info = ltp.refine_ltp(start, H, return_info=True, name='refined')
    again = info.realize(info.x)
    omega = H.omega[1:30]
    assert np.allclose(ltp.htf(again, 2).components(omega)[1],
                       ltp.htf(model, 2).components(omega)[1], rtol=1e-12, atol=1e-14)
    assert again.name == 'refined'
    moved = info.realize(info.x + 0.1 * (np.arange(info.x.size) == 0))
    assert np.isclose(moved.A(0.0)[0, 0], model.A(0.0)[0, 0] + 0.1)
    with pytest.raises(ControlDimension, match="parameters"):
        info.realize(info.x[:-1])


def test_identify_ltp_warns_for_an_unstable_model():
    # the exact HTF of an unstable plant: identified exactly, flagged as doubtful
    sys = ltp.ltpss([[0.5]], lambda t: np.array([[1 + 0.5 * np.cos(WP * t)]]),
                    [[1.0]], 0, period=T)
    with pytest.warns(UserWarning, match="no steady-state response"):
        H = _htf_data(sys, 3)
    with pytest.warns(UserWarning, match="identified model is unstable"):
        model, info = ltp.identify_ltp(H, T, 1, 1, estimate_d=False, return_info=True)
    assert np.allclose(model.A(0.0), [[0.5]], atol=1e-6)
    assert not info.success and "unstable model" in info.message
