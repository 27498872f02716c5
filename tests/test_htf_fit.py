"""Tests of parametric HTF fits and input/measurement delay estimation.

The data come from the independent scalar LTP simulator of
``test_htf_estimate`` (exact between samples), with delays applied to the
continuous input and to the output sampling instants (thesis §3.6.2).
"""

import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

from ltpcontrol import chirp_replicas
from ltpcontrol import HTFData, htf
from ltpcontrol import estimate_htf
from ltpcontrol import ltpss
from ltpcontrol import estimate_delays, fit_htf, HTFFit, HTFFitInfo
from test_htf_estimate import ScalarLTP

TRUE = np.array([-2.0, 0.8])                 # (a0, a1)


def model(p, omega):
    return ScalarLTP(a0=p[0], a1=p[1]).htf(omega, 2)


def _delayed_estimate(tau_u, tau_y, noise=0.0, seed=0):
    system = ScalarLTP(a0=TRUE[0], a1=TRUE[1])
    exc = chirp_replicas(1.0, 7, 20.0, 0.0, 4.0, dt=0.01, gap=8.0)
    # ȳ responds to ū(t) = u(t - τ_u); the measurement is y(t) = ȳ(t - τ_y)
    y = system.simulate(lambda s: exc.signal(s - tau_u), exc.time - tau_y)[0]
    y = y + noise * np.random.default_rng(seed).standard_normal(y.size)
    return estimate_htf((exc.time, exc.inputs, y), 1.0, 2, segments=exc.segments)


@pytest.fixture(scope="module")
def undelayed():
    return _delayed_estimate(0.0, 0.0)


@pytest.fixture(scope="module")
def delayed():
    return _delayed_estimate(0.04, 0.05)         # Table 3.1, experiment 5


def test_fit_recovers_parameters(undelayed):
    fit = fit_htf(model, undelayed, [-1.0, 0.2], harmonics=[-1, 0, 1])
    assert fit.success
    assert np.allclose(fit.params, TRUE, rtol=1e-3)
    assert fit.components.shape == undelayed.components()[1].shape
    assert np.all(fit.std < 1e-2)


def test_return_info_gives_fit_and_diagnostics(undelayed):
    default = fit_htf(model, undelayed, [-1.0, 0.2], harmonics=[-1, 0, 1])
    assert isinstance(default, HTFFit)                     # default return unchanged
    fit, info = fit_htf(model, undelayed, [-1.0, 0.2], harmonics=[-1, 0, 1],
                        return_info=True)
    assert isinstance(fit, HTFFit) and isinstance(info, HTFFitInfo)
    np.testing.assert_array_equal(fit.params, default.params)
    assert info.success and isinstance(info.message, str) and info.message
    # the info repeats the optimiser fields kept on the fit for compatibility
    assert (info.success, info.message, info.cost, info.nfev) == \
        (fit.success, fit.message, fit.cost, fit.nfev)
    F = undelayed.components()[0].size
    assert info.nresiduals == 2 * 3 * F and info.dof == info.nresiduals - 2
    assert info.rms == pytest.approx(np.sqrt(2 * info.cost / info.nresiduals))
    with pytest.raises(AttributeError):
        info.cost = 0.0                                     # frozen


def test_fit_with_noise_std_weights_covers_truth():
    est = _delayed_estimate(0.0, 0.0, noise=0.01, seed=3)
    fit = fit_htf(model, est, [-1.5, 0.5], weights='std')
    assert np.all(np.abs(fit.params - TRUE) < 4 * fit.std)
    assert np.all(fit.std < 0.05)


def test_magnitude_fit_ignores_delays_and_delays_are_separated(delayed):
    # a complex fit is biased by the delays; the magnitude fit is not (eq. 3.46)
    biased = fit_htf(model, delayed, [-1.5, 0.5], harmonics=[-1, 0, 1])
    mag = fit_htf(model, delayed, [-1.5, 0.5], harmonics=[-1, 0, 1],
                  magnitude_only=True)
    assert np.allclose(mag.params, TRUE, rtol=2e-3)
    assert np.max(np.abs(biased.params - TRUE)) > 10 * np.max(np.abs(mag.params - TRUE))
    # phases of G_{-1}, G_0, G_1 against the fitted undelayed model (eqs. 3.49-3.50)
    reference = model(mag.params, delayed.omega)
    d = estimate_delays(delayed, reference, omega_limits=(0.5, 15.0))
    assert d.input_delay == pytest.approx(0.04, rel=0.05)
    assert d.output_delay == pytest.approx(0.05, rel=0.05)
    assert d.total_delay == pytest.approx(0.09, rel=0.01)
    assert d.phase_rms < 0.05
    # G_0 alone only gives the sum (as for an LTI system)
    d0 = estimate_delays(delayed, reference, harmonics=[0], omega_limits=(0.5, 15.0))
    assert d0.input_delay is None and d0.output_delay is None
    assert d0.total_delay == pytest.approx(0.09, rel=0.01)


def test_input_delay_is_defined_modulo_the_period():
    omega = np.linspace(0.3, 20, 80)
    k = np.arange(-2, 3)[:, None, None, None]
    G = ScalarLTP().htf(omega, 2)
    for tau_u, tau_y in [(0.13, 0.07), (1.13, 0.07), (0.0, 0.3), (0.6, 0.0)]:
        H = G * np.exp(-1j * ((omega - k * 2 * np.pi) * tau_u + omega * tau_y))
        d = estimate_delays(HTFData(H, omega, 1.0), G, harmonics=[-2, -1, 0, 1, 2],
                            max_delay=2.0)
        tu = (tau_u + 0.5) % 1.0 - 0.5                  # returned in [-T/2, T/2)
        assert d.input_delay == pytest.approx(tu, abs=1e-8)
        assert d.output_delay == pytest.approx(tau_u + tau_y - tu, abs=1e-8)


def test_reference_can_be_an_htf_object(undelayed):
    ref = HTFData(model(TRUE, undelayed.omega), undelayed.omega, 1.0)
    d = estimate_delays(undelayed, ref)
    assert abs(d.input_delay) < 1e-4 and abs(d.total_delay) < 1e-4


def test_fit_accepts_object_models_and_only_htf_data():
    omega = np.linspace(0.5, 10, 30)
    obj_model = lambda p, w: HTFData(model(p, w), w, 1.0)
    fit = fit_htf(obj_model, _estimate_like(omega), [-1.0, 0.3], bounds=([-5, 0], [0, 2]))
    assert np.allclose(fit.params, TRUE, rtol=1e-6)
    assert fit.success and fit.nfev >= 1          # scipy.optimize's vocabulary
    with pytest.raises(AttributeError):
        fit.params = None                         # frozen result
    # the estimate is an HTFData; a model HTF is refused by name
    plant = ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    with pytest.raises(ControlArgument, match="HTFData .*model HTF"):
        fit_htf(obj_model, htf(plant, 1), [-1.0, 0.3])
    with pytest.raises(ControlArgument, match="HTFData"):
        estimate_delays(htf(plant, 1), np.ones((3, 1, 1, 30)))


def _estimate_like(omega):
    return HTFData(model(TRUE, omega), omega, 1.0)


@pytest.mark.parametrize("call, exc_type, match", [
    (lambda e: fit_htf(model, "x", [0, 0]), ControlArgument, "estimate"),
    (lambda e: fit_htf(1.0, e, [0, 0]), ControlArgument, "model"),
    (lambda e: fit_htf(model, e, [-1, 0.5], harmonics=[3]), ValueError, "harmonics"),
    (lambda e: fit_htf(model, e, [-1, 0.5], harmonics=[0.5]), ControlArgument, "harmonics"),
    (lambda e: fit_htf(model, e, [-1, 0.5], omega_limits=(100, 200)), ValueError,
     "omega_limits"),
    (lambda e: fit_htf(model, e, [-1, 0.5], weights='std'), ValueError, "std"),
    (lambda e: fit_htf(model, e, [-1, 0.5], weights='var'), ValueError, "weights"),
    (lambda e: fit_htf(lambda p, w: np.ones((3, 1, 1, 2)), e, [0.0]), ControlDimension,
     "model"),
    (lambda e: fit_htf(model, e, [-1, 0.5], method='lm'), TypeError, "method"),
    (lambda e: estimate_delays(e, np.ones((5, 1, 1, 3))), ControlDimension, "reference"),
    (lambda e: estimate_delays(e, model(TRUE, e.omega), input=1), ValueError, "input"),
    (lambda e: estimate_delays(e, model(TRUE, e.omega), max_delay=-1), ValueError,
     "max_delay"),
    (lambda e: estimate_delays(e, model(TRUE, e.omega), harmonics=[-3]), ValueError,
     "harmonics"),
])
def test_errors(call, exc_type, match):
    est = _estimate_like(np.linspace(0.5, 10, 12))
    with pytest.raises(exc_type, match=match):
        call(est)
