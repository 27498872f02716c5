"""The core objects against independent truths: scipy's integrators, brute-force
loops, sine simulations, python-control in the LTI limit."""

import warnings

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
    resp = ltp.forced_response(sys, exc.time, exc.inputs)
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


#
# Switching matrices with callable pieces
#

def test_switching_callable_piece_is_periodic():
    """A callable piece sees the time within the period, in every period."""
    S = ltp.PeriodicMatrix.switching([[[0.0]], lambda t: np.array([[t]])], [0, 0.5], 1.0)
    t = np.array([0.75, 1.75, -0.25, 10.75])
    assert np.allclose(S(t)[:, 0, 0], 0.75, rtol=0, atol=1e-12)
    one = ltp.PeriodicMatrix.switching([lambda t: np.array([[t]])], [0], 1.0)
    assert np.isclose(one(1.25)[0, 0], 0.25)


def test_switching_callable_forced_response_matches_solve_ivp():
    """Exact transition march against scipy over several periods (it reuses the
    first period's data, so it needs a truly periodic A)."""
    from scipy.integrate import solve_ivp
    rng = np.random.default_rng(4)
    Aa, Ab = rng.standard_normal((2, 2)) - np.eye(2), rng.standard_normal((2, 2))
    A = ltp.PeriodicMatrix.switching([Aa, lambda t: Ab * np.sin(3 * t)], [0, 0.7], 2.0)
    sys = ltp.ltpss(A, [[1.0], [1.0]], [[1.0, 0.0]], [[0.5]], 2.0)
    t = 0.45 + 0.1 * np.arange(56)
    u = np.sin(2.3 * t)
    xt = np.empty((2, len(t)))
    xt[:, 0] = [1.0, -1.0]
    for k in range(len(t) - 1):             # held input, split at the switching instants
        cuts = [c for c in 0.7 + 2.0 * np.arange(5) if t[k] < c < t[k + 1]]
        z = xt[:, k]
        for a, b in zip([t[k]] + cuts, cuts + [t[k + 1]]):
            z = solve_ivp(lambda s, z: A(s) @ z + u[k], (a, b), z, method='DOP853',
                          rtol=1e-13, atol=1e-15).y[:, -1]
        xt[:, k + 1] = z
    resp = ltp.forced_response(sys, t, u, [1.0, -1.0], input_hold='zoh', return_states=True)
    assert np.abs(resp.states - xt).max() < 1e-9 * np.abs(xt).max()


#
# Time responses: python-control's conventions in the LTI limit
#

@pytest.fixture
def lti_pair():
    rng = np.random.default_rng(7)
    G = ct.ss(np.array([[-1.0, 2.0], [-2.0, -0.5]]), [[1.0, 0.0], [0.5, 1.0]],
              [[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]], rng.standard_normal((3, 2)))
    return G, ltp.ltpss(G, 1.7)


def test_time_response_keyword_aliases(lti_pair):
    """T, U, X0, return_x, input, output: python-control's aliases."""
    G, P = lti_pair
    t = np.linspace(0, 3, 31)
    u = np.vstack([np.sin(t), np.ones_like(t)])
    for fn, kw in [('forced_response', dict(T=t, U=u, X0=[1, 0], return_x=True)),
                   ('step_response', dict(T=t, X0=[1, 0], input=1, output=2, return_x=True)),
                   ('impulse_response', dict(T=t, input=0, output=1, return_x=True)),
                   ('initial_response', dict(T=t, X0=[1, 0], output=1, return_x=True))]:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')            # impulse through D
            mine, ref = getattr(ltp, fn)(P, **kw), getattr(ct, fn)(G, **kw)
        assert len(tuple(mine)) == len(tuple(ref)) == 3
        assert mine.outputs.shape == ref.outputs.shape
        assert np.allclose(mine.outputs, ref.outputs, atol=1e-10)
    with pytest.raises(TypeError, match='multiple values'):
        ltp.forced_response(P, timepts=t, T=t, inputs=u)


@pytest.mark.parametrize('dt', [0, 0.1])
def test_lti_limit_default_grids_and_initial_response(lti_pair, dt):
    G, _ = lti_pair
    G = G if not dt else ct.c2d(G, dt)
    P = ltp.ltpss(G, 3 * dt if dt else 1.7)
    x0 = [1.0, -0.5]
    for fn, args in [('step_response', ()), ('impulse_response', ()),
                     ('initial_response', (None, x0)), ('step_response', (4.0,))]:
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')            # impulse through D
            mine, ref = getattr(ltp, fn)(P, *args), getattr(ct, fn)(G, *args)
        assert np.array_equal(mine.time, ref.time)
        assert mine.outputs.shape == ref.outputs.shape
        assert np.allclose(mine.outputs, ref.outputs, atol=1e-9)
        assert (mine.inputs is None) == (ref.inputs is None)
        assert mine.trace_types == ref.trace_types and mine.title == ref.title


#
# Discretization with a first-order hold
#

def test_sample_system_foh_lti_limit_equals_python_control():
    G = ct.ss([[-1.0, 2.0], [-2.0, -0.5]], [[1.0, 0.0], [0.5, 1.0]], [[1.0, 0.0]],
              [[0.3, -0.2]])
    Pd = ct.sample_system(ltp.ltpss(G, 0.6), 0.1, 'foh')
    Gd = ct.sample_system(G, 0.1, 'foh')
    for mine, ref in zip((Pd.A(0.0), Pd.B(0.0), Pd.C(0.0), Pd.D(0.0)),
                         (Gd.A, Gd.B, Gd.C, Gd.D)):
        assert np.allclose(mine, ref, rtol=1e-11, atol=1e-12)
    assert Pd.is_lti and Pd.name == Gd.name


@pytest.mark.parametrize('N', [1, 3, 8])
def test_sample_system_foh_periodic_matches_foh_simulation(N):
    """y_d[k] = y(k Ts) for the continuous system driven by the linear interpolant."""
    sys = _oscillator(D_PERIODIC)
    sys = ltp.ltpss(sys.A, lambda t: np.array([[0.2], [1 + 0.5 * np.cos(WP * t)]]), sys.C,
                    sys.D, T)
    Ts = T / N
    sysd = ltp.sample_system(sys, Ts, 'foh')
    t = Ts * np.arange(6 * N + 5)
    u = np.sin(1.3 * t) * np.exp(-0.1 * t)                     # u[0] = 0: ξ_0 = x_0
    yd = ltp.forced_response(sysd, t, u, [0.3, -0.1]).outputs
    yc = ltp.forced_response(sys, t, u, [0.3, -0.1], input_hold='foh').outputs
    assert np.abs(yd - yc).max() < 1e-10


#
# Block-diagram algebra in the LTI limit
#

def test_scalar_arithmetic_matches_python_control_non_square():
    """A scalar is added to every entry of D and multiplies every channel, as
    python-control does (also for non-square systems)."""
    G = ct.ss([[-1.0, 0.5], [0.0, -2.0]], [[1.0, 0.0, 1.0], [0.0, 1.0, 2.0]],
              [[1.0, 0.0], [0.3, 1.0]], [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]])
    P = ltp.ltpss(G, 1.0)
    for mine, ref in [(P + 2, G + 2), (2 + P, 2 + G), (P - 2, G - 2), (2 - P, 2 - G),
                      (P * 2, G * 2), (2 * P, 2 * G), (P * 2.5 - 1, G * 2.5 - 1)]:
        assert mine.shape == ref.shape
        s = np.array([0.3j, 1.0 + 2j])
        Hm = np.stack([mine.to_ss()(x) for x in s])
        Hr = np.stack([ref(x) for x in s])
        assert np.allclose(Hm, Hr, rtol=1e-12, atol=1e-12)
