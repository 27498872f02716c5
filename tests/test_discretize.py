"""Tests of Tustin / ZOH discretization of LTP systems and of its inverse."""

import numpy as np
import pytest
import control as ct
from control.exception import ControlArgument

import ltpcontrol as ltp
from ltpcontrol import d2c, sample_system

WP = 2 * np.pi          # period 1


def _floquet_form():
    """Constant A; B, C, D with harmonics up to 2 (band-limited)."""
    B = lambda t: np.array([[0.2 * np.sin(WP * t)], [1 + 0.4 * np.cos(WP * t)]])
    C = lambda t: np.array([[1 + 0.2 * np.cos(2 * WP * t), 0.1 * np.sin(WP * t)]])
    D = lambda t: np.array([[0.3 * np.cos(WP * t)]])
    return ltp.ltpss([[0.0, 1.0], [-9.0, -0.6]], B, C, D, period=1.0, name='plant')


def _periodic_a():
    """Mathieu-type system with periodic A, B and C."""
    A = lambda t: np.array([[0.0, 1.0], [-(1 + 0.3 * np.cos(WP * t)) * 9.0, -0.8]])
    B = lambda t: np.array([[0.0], [1 + 0.4 * np.cos(WP * t)]])
    C = lambda t: np.array([[1.0, 0.1 * np.sin(WP * t)]])
    return ltp.ltpss(A, B, C, 0, period=1.0, name='mathieu')


def _lti():
    G = ct.ss([[0.0, 1.0], [-4.0, -1.2]], [[0.0, 1.0], [1.0, 0.5]], [[1.0, 0.3]],
              [[0.0, 0.1]], name='G')
    return G, ltp.ltpss(G, 0.5)


def _freqresp(sys, z):
    return np.stack([sys(zk) for zk in z])


@pytest.mark.parametrize("method, prewarp", [('tustin', None), ('bilinear', 3.0),
                                             ('zoh', None)])
def test_lti_matches_python_control(method, prewarp):
    G, sys = _lti()
    Ts = 0.05
    sysd = sample_system(sys, Ts, method, prewarp_frequency=prewarp)
    assert sysd.is_lti and sysd.nsteps == 10
    ref = G.sample(Ts, method, prewarp_frequency=prewarp)
    z = np.exp(1j * np.linspace(0.01, 3.1, 9))
    ours, theirs = _freqresp(sysd.to_ss(), z), _freqresp(ref, z)
    assert np.abs(ours - theirs).max() < 1e-12 * np.abs(theirs).max()
    if method == 'zoh':           # same state coordinates
        assert np.abs(sysd.A(0.0) - ref.A).max() < 1e-12
        assert np.abs(sysd.B(0.0) - ref.B).max() < 1e-12


def test_dispatch_and_names():
    sys = _floquet_form()
    sysd = ct.sample_system(sys, 0.1, method='tustin')
    assert isinstance(sysd, ltp.LTPStateSpace) and sysd.dt == 0.1
    assert sysd.name == 'plant$sampled' and sysd.is_floquet_form
    assert sysd.state_labels == sys.state_labels
    assert sys.sample(0.1, name='d', inputs=['v']).input_labels == ['v']
    assert sys.sample(0.1, name='d').name == 'd'
    assert sys.sample(0.1, copy_names=False).name != 'plant$sampled'
    # the thesis's balanced Tustin matrices, eqs. (4.50)-(4.53)
    A, Ts = sys.A(0.0), 0.1
    M = np.linalg.inv(2 / Ts * np.eye(2) - A)
    assert np.allclose(sysd.A(0.0), (2 / Ts * np.eye(2) + A) @ M)
    assert np.allclose(sysd.B(0.3), 2 / np.sqrt(Ts) * M @ sys.B(0.3))
    assert np.allclose(sysd.C(0.3), 2 / np.sqrt(Ts) * sys.C(0.3) @ M)
    assert np.allclose(sysd.D(0.3), sys.D(0.3) + sys.C(0.3) @ M @ sys.B(0.3))


@pytest.mark.parametrize("prewarp", [None, 5.0])
def test_tustin_round_trip_floquet_form(prewarp):
    sys = _floquet_form()
    sysd = sample_system(sys, 1 / 20, 'tustin', prewarp_frequency=prewarp)
    back = d2c(sysd, prewarp_frequency=prewarp)
    assert back.isctime() and back.is_floquet_form and back.name == 'plant$sampled$converted'
    assert np.abs(back.A(0.0) - sys.A(0.0)).max() < 1e-10
    for M0, M1 in ((sys.B, back.B), (sys.C, back.C), (sys.D, back.D)):
        assert np.abs(M0.fourier(4) - M1.fourier(4)).max() < 1e-10


def test_tustin_round_trip_periodic_a():
    sys = _periodic_a()
    back = d2c(sys.sample(1 / 16, 'tustin'))
    t = np.linspace(0, 1, 13)
    for M0, M1 in ((sys.A, back.A), (sys.B, back.B), (sys.C, back.C)):
        assert np.abs(M0(t) - M1(t)).max() < 1e-10
    held = d2c(sys.sample(1 / 16, 'tustin'), interpolation='hold')
    assert np.allclose(held.A(3 / 16 + 0.01), sys.A(3 / 16))


def _sim_error(sys, Ts, method):
    """Max output error of the DT system against the CT response at the samples."""
    t = Ts * np.arange(int(round(2 / Ts)) + 1)
    u = np.sin(3 * t)
    yd = ltp.forced_response(sys.sample(Ts, method), t, u).outputs
    fine = 8
    tf = (Ts / fine) * np.arange(fine * (len(t) - 1) + 1)
    yc = ltp.forced_response(sys, tf, np.sin(3 * tf), input_hold='foh').outputs[::fine]
    return np.abs(yd - yc).max()


def test_tustin_converges_second_order_with_periodic_a():
    sys = _periodic_a()
    errs = [_sim_error(sys, 1 / N, 'tustin') for N in (20, 40, 80)]
    ratios = np.array(errs[:-1]) / np.array(errs[1:])
    assert np.all((ratios > 3.5) & (ratios < 4.5)), errs


def test_zoh_matches_simulation():
    sys = _periodic_a()
    Ts = 1 / 10
    sysd = sample_system(sys, Ts, 'zoh')
    assert not sysd.is_floquet_form
    rng = np.random.default_rng(0)
    t = Ts * np.arange(25)
    u = rng.standard_normal(25)
    x0 = np.array([0.5, -1.0])
    yd = ltp.forced_response(sysd, t, u, x0).outputs
    yc = ltp.forced_response(sys, t, u, x0, input_hold='zoh').outputs
    assert np.abs(yd - yc).max() < 1e-10 * np.abs(yc).max()
    yi = ltp.forced_response(sys, t, u, x0, input_hold='zoh', method='solve_ivp').outputs
    assert np.abs(yd - yi).max() < 1e-7 * np.abs(yc).max()


def test_log_inverse():
    G, sys = _lti()
    back = d2c(sample_system(sys, 0.05, 'zoh'), method='log')
    assert back.is_lti
    for M, ref in ((back.A, G.A), (back.B, G.B), (back.C, G.C), (back.D, G.D)):
        assert np.abs(M(0.0) - ref).max() < 1e-10
    # constant A with B held on the grid: exact inverse of exact ZOH sampling
    Bs = np.array([[[0.0], [1.0 + 0.5 * np.cos(np.pi * k / 2)]] for k in range(4)])
    Bh = ltp.PeriodicMatrix.from_samples(Bs, 0.4, kind='hold')
    sysh = ltp.ltpss([[0.0, 1.0], [-4.0, -1.2]], Bh, [[1.0, 0.0]], 0, period=0.4)
    backh = d2c(sample_system(sysh, 0.1, 'zoh'), method='log', interpolation='hold')
    t = np.linspace(0, 0.39, 11)
    assert np.abs(backh.B(t) - Bh(t)).max() < 1e-10


def test_warnings():
    sys = _floquet_form()
    with pytest.warns(UserWarning, match="prewarp_frequency"):
        sys.sample(0.1, 'zoh', prewarp_frequency=2.0)
    with pytest.warns(UserWarning, match="alpha"):
        sys.sample(0.1, 'tustin', alpha=0.5)
    with pytest.warns(UserWarning, match="prewarp_frequency"):
        d2c(sys.sample(0.1, 'zoh'), 'log', prewarp_frequency=2.0)


def test_bad_inputs():
    sys = _floquet_form()
    sysd = sys.sample(0.1)
    with pytest.raises(ValueError, match="Ts"):
        sample_system(sys, 0.3)
    with pytest.raises(ValueError, match="Ts"):
        sample_system(sys, -0.1)
    with pytest.raises(ValueError, match="sys"):
        sample_system(sysd, 0.1)
    with pytest.raises(ControlArgument, match="sys"):
        sample_system(ct.rss(2), 0.1)
    with pytest.raises(ValueError, match="method"):
        sample_system(sys, 0.1, 'gbt')
    with pytest.raises(TypeError, match="bogus"):
        sample_system(sys, 0.1, bogus=1)
    with pytest.raises(ValueError, match="prewarp_frequency"):
        sample_system(sys, 0.1, 'tustin', prewarp_frequency=40.0)
    with pytest.raises(ValueError, match="sysd"):
        d2c(sys)
    with pytest.raises(ValueError, match="method"):
        d2c(sysd, 'zoh')
    with pytest.raises(ValueError, match="interpolation"):
        d2c(sysd, interpolation='linear')
    with pytest.raises(TypeError, match="bogus"):
        d2c(sysd, bogus=1)
    with pytest.raises(ValueError, match="sysd.A"):
        d2c(_periodic_a().sample(0.1), 'log')
    with pytest.raises(ValueError, match="-1"):
        d2c(ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=0.2, dt=0.1))
    # A with an eigenvalue at the Tustin pole 2/Ts
    with pytest.raises(ValueError, match="cI - A"):
        ltp.ltpss([[20.0]], [[1.0]], [[1.0]], 0, period=1.0).sample(0.1, 'tustin')


def test_floquet_then_tustin_round_trip():
    # thesis pipeline: Floquet form (constant A), Tustin, inverse Tustin
    from ltpcontrol import floquet_transform
    A = lambda t: np.array([[0.0, 1.0], [-(1 + 0.3 * np.cos(WP * t)) * 4.0, -0.8]])
    B = lambda t: np.array([[0.0], [1 + 0.4 * np.cos(WP * t)]])
    sysF, _ = floquet_transform(ltp.ltpss(A, B, [[1.0, 0.0]], 0, period=1.0))
    assert sysF.period == 1.0
    sysd = sysF.sample(1 / 16, 'tustin')
    assert sysd.is_floquet_form
    back = d2c(sysd)
    assert back.is_floquet_form
    assert np.abs(back.A(0.0) - sysF.A(0.0)).max() < 1e-10
    for M0, M1 in ((sysF.B, back.B), (sysF.C, back.C)):
        assert np.abs(M0.sample(16) - M1.sample(16)).max() < 1e-10
