"""The core objects against independent truths: scipy's integrators, brute-force
loops, sine simulations, python-control in the LTI limit."""

import numpy as np
import pytest
import control as ct
from control.exception import ControlArgument

import ltpcontrol as ltp

T, TS = 0.5, 0.01
WP = 2 * np.pi / T


def _oscillator(D):
    A = lambda t: np.array([[0.0, 1.0], [-10 - 3 * np.cos(WP * t), -1.0]])
    return ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], D, T)


D_PERIODIC = lambda t: np.array([[0.7 + 0.4 * np.sin(WP * t)]])     # noqa: E731


#
# Lifted frequency response with held inputs and a direct term
#

@pytest.mark.parametrize('hold, over', [('foh', 1), ('foh', 4), ('zoh', 1)])
def test_lifted_response_hold_with_feedthrough_matches_htf(hold, over):
    """y(t_k) = C x(t_k) + D(t_k) u_k: the direct term sees the samples, so the
    hold correction applies to the dynamic part only."""
    sys = _oscillator(D_PERIODIC)
    freqs = np.array([1.7, 7.3, 21.1])
    t = np.arange(int(30 / TS) * over) * TS / over
    u = np.cos(2 * np.pi * freqs[:, None] * t)
    y = ltp.forced_response(sys, t, u[None], input_hold=hold).outputs
    data = (t[::over], u[:, ::over], y[:, :, ::over])
    opts = dict(transient=10.0, input_hold=hold, hold_step=TS / over, real=False)
    G = ltp.lifted_frequency_response(data, T, 1, feedthrough=D_PERIODIC, **opts)
    H = ltp.htf(sys, 1)(1j * G.omega)[:, 1, :]          # H_{n,0}(jΩ), n = -1..1
    assert np.abs(G.frdata[:, 0, :] - H).max() < 1e-5
    # without the direct term the hold correction is biased by (1/h - 1) D_n
    Gb = ltp.lifted_frequency_response(data, T, 1, **opts)
    assert np.abs(Gb.frdata[:, 0, -1] - H[:, -1]).max() > 1e-3
    # a strictly proper plant: feedthrough=0 changes nothing
    y0 = ltp.forced_response(_oscillator(0), t, u[None], input_hold=hold).outputs
    data0 = (t[::over], u[:, ::over], y0[:, :, ::over])
    G0 = ltp.lifted_frequency_response(data0, T, 1, feedthrough=0, **opts)
    G0b = ltp.lifted_frequency_response(data0, T, 1, **opts)
    assert np.allclose(G0.frdata, G0b.frdata, rtol=1e-12, atol=1e-14)


def test_lifted_response_feedthrough_shape_checked():
    sys = _oscillator(0)
    t = np.arange(1000) * TS
    u = np.cos(2 * np.pi * 1.7 * t)
    y = ltp.forced_response(sys, t, u).outputs
    with pytest.raises(ct.ControlDimension, match='feedthrough'):
        ltp.lifted_frequency_response((t, u, y), T, 1, input_hold='foh',
                                      feedthrough=np.zeros((2, 1)))


def test_identify_ltp_hold_with_feedthrough():
    """identify_ltp refits with the fitted D(t) as feedthrough: the Floquet
    exponent comes out right (−1.87 instead of −2 without it)."""
    sys = ltp.ltpss([[-2.0]], lambda t: np.array([[1 + 0.5 * np.cos(WP * t)]]), [[1.0]],
                    lambda t: np.array([[0.8 + 0.3 * np.cos(WP * t)]]), period=T)
    w = np.pi / 2 * np.array([k for k in range(1, 40) if k % 4])
    exc = ltp.sine_experiments(w, T, dt=0.0125, nperiods=8, settle=12)
    resp = ltp.forced_response(sys, exc.time, exc.inputs[None])
    model = ltp.identify_ltp(resp, T, 1, q=10, transient=6.0, input_hold='foh')
    assert abs(model.A(0.0)[0, 0] + 2) < 1e-2
    assert np.allclose(model.D.fourier(1)[:, 0, 0], sys.D.fourier(1)[:, 0, 0], atol=2e-3)


#
# HTF construction
#

def test_htf_direct_construction_points_to_factory():
    sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    with pytest.raises(ControlArgument, match=r"ltp\.htf\(sys, nharmonics\)"):
        ltp.HTF(sys, 1)
    with pytest.raises(TypeError, match="HTFData"):
        ltp.HTF()
    # the concrete classes are constructed directly, as documented
    assert isinstance(ltp.HTFModel(sys, 1), ltp.HTF)
    G = np.zeros((1, 1, 1, 2), complex)
    assert isinstance(ltp.HTFData(G, [1.0, 2.0], 1.0), ltp.HTF)
