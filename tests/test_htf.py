"""Harmonic transfer functions against simulation, the LTI limit and bad input."""

import warnings

import numpy as np
import control as ct
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp
from systems import mathieu, damped_mathieu, switching_mathieu


def steady_state_harmonics(sys, freqs, nharm, h=0.005, settle=40.0, window=20.0):
    """Simulated output harmonics Y_n at f + n f_p for cosine inputs (one batch)."""
    t = np.arange(0, settle + window, h)
    U = np.cos(2 * np.pi * np.asarray(freqs)[:, None] * t)[None]
    y = ltp.forced_response(sys, t, U).y[0]
    sel = t >= settle
    tw, yw = t[sel][:int(round(window / h))], y[:, sel][:, :int(round(window / h))]
    wp = sys.omega_p
    out = np.empty((len(freqs), 2 * nharm + 1), complex)
    for i, f in enumerate(freqs):
        for j, n in enumerate(range(-nharm, nharm + 1)):
            out[i, j] = np.mean(yw[i] * np.exp(-1j * (2 * np.pi * f + n * wp) * tw))
    return out


@pytest.mark.parametrize("make", [mathieu, lambda: damped_mathieu(zeta=0.3)],
                         ids=["mathieu-4.115", "damped-mathieu-4.24"])
def test_htf_predicts_simulated_steady_state_harmonics(make):
    sys = make()
    freqs = [0.25, 0.35, 0.6, 1.15, 2.05]           # integer cycles in the 20 s window
    h, K = 0.005, 2
    Y = steady_state_harmonics(sys, freqs, K, h=h)
    H = ltp.htf(sys, K)
    for i, f in enumerate(freqs):
        w = 2 * np.pi * f
        # U_0 = 1/2; the simulated input is the linear interpolant of the samples,
        # whose line at ω is scaled by sinc²(ωh/2)
        hold = np.sinc(w * h / 2 / np.pi) ** 2
        pred = 0.5 * hold * H(1j * w)[:, K]          # column m = 0: Y_n = H_{n,0} U_0
        big = np.abs(pred) > 1e-3 * np.abs(pred).max()
        rel = np.abs(Y[i] - pred)[big] / np.abs(pred)[big]
        assert rel.max() <= 1e-6, (f, rel)


def test_lti_limit_is_shifted_diagonal():
    G = ct.rss(3, 2, 2)
    T = 0.9
    H = ltp.htf(ltp.ltpss(G, T), 3)
    s = np.array([0.3j, 2.0j, 0.5 + 1j])
    M = H(s)
    wp = 2 * np.pi / T
    for a, n in enumerate(range(-3, 4)):
        for b in range(7):
            # frequency last, as in python-control: G(s) is (ny, nu, len(s))
            blk = M[2 * a:2 * a + 2, 2 * b:2 * b + 2]
            expected = G(s + 1j * n * wp) if a == b else np.zeros_like(blk)
            # both sides solve ((s + jnω_p)I - A) x = B in floating point: they
            # agree to eps · cond((s + jnω_p)I - A) · |G|, not bit for bit
            cond = max(np.linalg.cond((z + 1j * n * wp) * np.eye(3) - G.A) for z in s)
            scale = 1 + np.abs(G(s + 1j * n * wp)).max()
            np.testing.assert_allclose(blk, expected, rtol=0, atol=1e-14 * cond * scale)


def test_component_convention_and_shift_property():
    sys = damped_mathieu(zeta=0.3)
    K = 3
    H = ltp.htf(sys, K, internal_harmonics=30)
    w = np.array([0.7, 3.1])
    _, G = H.components(w)
    M = H(1j * w)
    for k in range(-K, K + 1):
        # G_k(s) = H_{0,-k}(s)
        np.testing.assert_allclose(G[k + K, 0, 0], M[K, K - k], atol=1e-14)
    # H_{n,m}(s) = G_{n-m}(s + jnω_p)
    n, m = 1, -1
    _, Gs = H.components(w + n * sys.omega_p)
    np.testing.assert_allclose(M[n + K, m + K], Gs[n - m + K, 0, 0], rtol=1e-8)
    # real system: G_k(-jω) = conj(G_{-k}(jω))
    neg = H(-1j * w)
    np.testing.assert_allclose(neg[K, K - 1], np.conj(M[K, K + 1]), atol=1e-13)


def test_modal_and_dense_solves_agree():
    for sys in (mathieu(), damped_mathieu(zeta=0.3)):
        s = 1j * np.linspace(0.1, 30, 7)
        a = ltp.htf(sys, 4, method='modal')(s)
        b = ltp.htf(sys, 4, method='solve')(s)
        np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-13)


def test_switching_truncation_converges_algebraically():
    sys = switching_mathieu()
    w = np.array([1.7])
    ref = ltp.htf(sys, 1, internal_harmonics=90).components(w)[1][1, 0, 0, 0]
    errs = []
    for Ki in (5, 10, 20):
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            val = ltp.htf(sys, 1, internal_harmonics=Ki).components(w)[1][1, 0, 0, 0]
        errs.append(abs(val - ref) / abs(ref))
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 2e-3
    # roughly K^-3: halving the truncation error needs far fewer than 2x harmonics
    assert errs[0] / errs[2] > 8


def test_predict_equals_simulated_steady_state():
    sys = mathieu()
    H = ltp.htf(sys, 3)
    h = 0.01
    t = np.arange(0, 30, h)
    u = np.cos(2 * np.pi * 0.7 * t) + 0.5 * np.sin(2 * np.pi * 1.3 * t)
    y = ltp.forced_response(sys, t, u).y[0]
    window = t >= 20
    yp = H.predict(t[window] - 20, u[window]).outputs
    # agreement up to the input-hold effect (sinc² ≈ 1 - 2e-4 at 1.3 Hz)
    assert np.abs(yp - y[window]).max() <= 1e-3 * np.abs(y).max()


def test_data_htf_round_trip_and_frd():
    sys = mathieu()
    model = ltp.htf(sys, 2)
    w = np.linspace(0.5, 40, 80)
    _, G = model.components(w)
    data = ltp.HTFData(G, w, sys.period, name='data')
    np.testing.assert_allclose(data.component(1).frdata, model.component(1, w).frdata)
    frd = data.to_frd()
    assert frd.ninputs == 5 and frd.noutputs == 1
    assert isinstance(model.component(0, w), ct.FrequencyResponseData)


def test_bode_htf_control_plot_and_defaults():
    H = ltp.htf(mathieu(), 2)
    cplt = ltp.bode_htf(H, omega_num=50)
    assert isinstance(cplt, ct.ControlPlot)
    assert cplt.axes.shape == (2, 1)
    with ct.config.defaults({'freqplot.dB': True, 'freqplot.Hz': True}):
        cplt = ltp.bode_htf(H, omega_num=50, plot_phase=False)
    assert 'dB' in cplt.axes[0, 0].get_ylabel()
    assert 'Hz' in cplt.axes[0, 0].get_xlabel()
    # overlay of two HTFs with a legend
    w = np.logspace(-1, 2, 40)
    _, G = H.components(w)
    est = ltp.HTFData(G * 1.01, w, H.period, name='estimate')
    cplt = ltp.bode_htf([H, est], w)
    labels = [t.get_text() for t in cplt.legend[0, 0].get_texts()] if cplt.legend.ndim == 2 \
        else [t.get_text() for t in cplt.legend[0].get_texts()]
    assert any('estimate' in lab for lab in labels)
    assert isinstance(ltp.htf_map_plot(H, 2.0), ct.ControlPlot)


@pytest.mark.parametrize("call, exc, match", [
    (lambda: ltp.htf(mathieu(), -1), ValueError, "nharmonics"),
    (lambda: ltp.htf(mathieu(), 1.5), ControlArgument, "nharmonics"),
    (lambda: ltp.htf(mathieu(), 2)(np.ones((2, 2))), ControlDimension, "s"),
    (lambda: ltp.htf(mathieu(), 2).component(3), ValueError, "outside"),
    (lambda: ltp.htf(mathieu(), 2, internal_harmonics=1), ValueError, "internal_harmonics"),
    (lambda: ltp.htf(mathieu(), 2, method='fast'), ValueError, "method"),
    (lambda: ltp.htf(ct.rss(2), 2), ControlArgument, "period"),
    (lambda: ltp.htf(mathieu(), 2, foo=3), TypeError, "unexpected keyword"),
    (lambda: ltp.htf(ltp.ltpss([[0.5]], [[1]], [[1]], 0, period=1.0, dt=0.25), 2),
     ValueError, "nharmonics"),
    (lambda: ltp.htf(mathieu(), 1).predict(np.arange(10) * 0.01, np.ones(10)), ValueError,
     "integer number of periods"),
    (lambda: ltp.HTFData(np.ones((2, 1, 1, 3)), [1, 2, 3], 1.0), ControlDimension, "2K\\+1"),
    (lambda: ltp.HTFData(np.ones((3, 1, 1, 3)), [1, 3, 2], 1.0), ValueError, "increasing"),
    (lambda: ltp.HTFData(np.ones((3, 1, 1, 3)), [1, 2, 3], 1.0).component(0, [1.5]), ValueError,
     "subset"),
])
def test_bad_input(call, exc, match):
    with pytest.raises(exc, match=match):
        call()


def test_unstable_system_warns_and_poles_raise():
    sys = ltp.ltpss([[0.5]], [[1.0]], [[1.0]], 0, period=1.0)
    with pytest.warns(UserWarning, match="unstable"):
        H = ltp.htf(sys, 1)
    with pytest.raises(ValueError, match="pole"):
        H(0.5)


def test_data_htf_marks_unidentified_components_with_nan():
    sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    model = ltp.htf(sys, 1)
    w = 2 * np.pi * np.arange(1, 40) / 4          # grid of a 4 s record
    _, G = model.components(w)
    G[2, :, :, w > 20] = np.nan                   # G_1 not identified above 20 rad/s
    data = ltp.HTFData(G, w, 1.0)
    t = np.arange(400) * 0.01
    low = np.cos(2 * np.pi * 0.5 * t)             # excites only identified terms
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        np.testing.assert_allclose(data.predict(t, low).outputs, model.predict(t, low).outputs,
                                   atol=1e-12)
    high = np.cos(2 * np.pi * 3.5 * t)            # ω = 22 rad/s needs G_1 there
    with pytest.warns(UserWarning, match="did not identify"):
        data.predict(t, high)
    with pytest.raises(ValueError, match="inf"):
        ltp.HTFData(np.where(np.isnan(G), np.inf, G), w, 1.0)


def test_models_and_data_are_two_classes_behind_one_interface():
    sys = mathieu()
    H = ltp.htf(sys, 2)
    assert type(H) is ltp.HTFModel and isinstance(H, ltp.HTF)
    w = np.linspace(0.5, 5, 10)
    direct = ltp.HTFModel(sys, 2)
    np.testing.assert_array_equal(direct(1j * w), H(1j * w))
    data = ltp.HTFData(H.components(w)[1], w, sys.period)
    assert isinstance(data, ltp.HTF) and not isinstance(data, ltp.HTFModel)
    np.testing.assert_allclose(data.to_frd().frdata, H.to_frd(w).frdata, rtol=1e-14)
    # the period of an LTI system is an explicit keyword, refused for an LTP system
    G = ct.rss(2, 1, 1)
    np.testing.assert_allclose(ltp.htf(G, 1, period=2.0)(0.3j),
                               ltp.htf(ltp.ltpss(G, 2.0), 1)(0.3j), rtol=1e-14)
    with pytest.raises(TypeError, match="period"):
        ltp.htf(sys, 1, period=2.0)


def test_default_grid_is_one_setting():
    H = ltp.htf(mathieu(), 1)
    with ltp.config.defaults_context({'htf.omega_num': 37}):
        w, G = H.components()
        resp = ltp.htf_response(H)[0][0]
    assert w.size == G.shape[-1] == 37
    np.testing.assert_array_equal(resp.omega, w)
    assert w[0] == pytest.approx(H.omega_p / 100) and w[-1] == pytest.approx(10 * H.omega_p)
    # discrete time: the same grid, below the Nyquist frequency
    Hd = ltp.htf(ltp.sample_system(mathieu(), 0.05), 1)
    wd, _ = Hd.components()
    assert wd.size == ltp.config.defaults['htf.omega_num'] and wd[-1] < np.pi / 0.05


def test_predict_in_the_old_order_is_refused():
    H = ltp.htf(mathieu(), 1)
    t = np.arange(200) * 0.01
    u = np.cos(2 * np.pi * t)
    with pytest.raises(ValueError, match="order"):
        H.predict(u, t)
    np.testing.assert_array_equal(H.predict(timepts=t, inputs=u).outputs,
                                  H.predict(t, u).outputs)
