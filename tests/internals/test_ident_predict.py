"""Identified models predict: every produced harmonic fitted, held-out validation,
time-domain comparison, refinement fallback (independent truth: simulation of the
true plant by forced_response).

Tests of internals: they import private names (see the Developer notes).
"""

import warnings

import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp
import ltpcontrol._identification.ltp_subspace as subspace
from ltpcontrol._identification.floquet_fit import (_FloquetFit, _harmonic_data,
                                                   _harmonic_response, fit_floquet)

from examples.random_ltp_plants import design_lines, lifted_data, random_ltp
from example_scripts import import_script

study = import_script('ident_prediction_study')
evaluate, plant_classes = study.evaluate, study.plant_classes

T, DT = 1.0, 1 / 64
LINES = design_lines(T, 60)


def _identify(plant, K, Kd, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return ltp.identify_ltp(lifted_data(plant, Kd, LINES, DT), T, plant.nstates, K,
                                return_info=True, **kw)


def test_fit_uses_all_data_harmonics():
    """Data with harmonics |n| <= 3K+1 of a Floquet-form plant: the exact model is a
    zero-residual point of the fit, a perturbed start returns to it."""
    plant = random_ltp(200, 2, 1, periodic='B')
    Kd = 7
    Gc = _harmonic_data(lifted_data(plant, Kd, LINES, DT).frdata, Kd, 64, 1)
    assert np.abs(_harmonic_response(plant, LINES, Kd) - Gc).max() < 1e-12
    start = ltp.ltpss(plant.A(0.0) * 1.05, plant.B, plant.C, 0, period=T)
    model, res, converged, _ = fit_floquet(start, Gc, LINES, 2)
    assert converged and res < 1e-10
    with pytest.raises(ValueError, match='harmonics'):
        fit_floquet(start, Gc[:, 6:9], LINES, 2)


@pytest.mark.parametrize('estimate_d', [True, False])
def test_fit_jacobian_equals_finite_differences(estimate_d):
    """The refit's Jacobian (all of B, C, D and A, real parameters of complex
    coefficient series) against central differences of its response."""
    nx, ny, nu, K, H, Kd = 2, 2, 3, 1, 2, 4
    fit = _FloquetFit(nx, ny, nu, K, H, T, estimate_d, True, Kd)
    rng = np.random.default_rng(3)
    theta = rng.standard_normal(fit.ncoef + nx * nx)
    theta[fit.ncoef:] = (np.diag([-1.0, -2.5]) + 0.3 * rng.standard_normal((2, 2))).ravel()
    omega = np.array([0.7, 2.9, 8.1])
    G, J = fit.response_and_jacobian(theta, omega)
    assert J.shape == (G.size, theta.size)
    h = 1e-6
    fd = np.stack([(fit.response_and_jacobian(theta + h * e, omega, jac=False)[0]
                    - fit.response_and_jacobian(theta - h * e, omega, jac=False)[0]).ravel()
                   / (2 * h) for e in np.eye(theta.size)], axis=1)
    assert np.abs(J - fd).max() < 1e-7 * np.abs(fd).max()


def test_periodic_a_model_predicts_in_time_domain():
    """Periodic A(t), constant B, C: fitted with all the harmonics it produces the model
    predicts filtered noise; fitted with |n| <= K only, its outer harmonics are free
    and the prediction is worse."""
    plant = random_ltp(101, 3, 1, periodic='A')
    errors = {}
    for K in (2, 3):
        model, info = _identify(plant, K, 3 * K + 1)
        assert info.success and info.data_harmonics == 3 * K + 1
        assert info.holdout_nrmse < 1e-2 and info.holdout_lines.size == 15
        cmp = ltp.compare_ltp(model, plant, LINES[:20], signal='noise')
        errors[K] = cmp.time_nrmse
    assert errors[2] <= 1e-2 and errors[3] <= 2 * errors[2]
    partial, info = _identify(plant, 3, 3)
    assert 'neither fitted nor validated' in info.message
    assert ltp.compare_ltp(partial, plant, LINES[:20], signal='noise').time_nrmse > errors[3]


def test_poor_structure_flagged_by_holdout():
    """Too few states: the held-out prediction fails, success is False and the warning
    names the figure."""
    plant = random_ltp(501, 3, 1)
    with pytest.warns(UserWarning, match='holdout_nrmse'):
        model, info = ltp.identify_ltp(lifted_data(plant, 7, LINES, DT), T, 1, 2,
                                       return_info=True)
    assert not info.success and info.holdout_nrmse > 0.05
    t = np.arange(1280) * DT
    u = np.sin(1.7 * t) + np.sin(5.1 * t)
    y = ltp.forced_response(plant, t, u).outputs
    assert np.linalg.norm(ltp.forced_response(model, t, u).outputs - y) > 0.05 * np.linalg.norm(y)


def test_holdout_options():
    plant = random_ltp(200, 2, 1, periodic='B')
    model, info = _identify(plant, 1, 3, holdout=None)
    assert np.isnan(info.holdout_nrmse) and info.holdout_lines.size == 0
    with pytest.raises(ValueError, match='holdout'):
        _identify(plant, 1, 3, holdout=1)
    with pytest.raises(ValueError, match='validation_tol'):
        _identify(plant, 1, 3, validation_tol=-1.0)
    # too few lines to hold some out: a warning, no validation
    few = lifted_data(plant, 3, LINES[:8], DT)
    with pytest.warns(UserWarning, match='not validated'):
        _, info = ltp.identify_ltp(few, T, 2, 1, q=None, return_info=True)
    assert np.isnan(info.holdout_nrmse)


def test_refinement_never_predicts_worse(monkeypatch):
    """A refinement that spoils the model is rejected on the held-out lines."""
    plant = random_ltp(101, 2, 1, periodic='A')
    real = subspace.refine_ltp

    def spoiling(sys, data, **kw):
        model, info = real(sys, data, **kw)
        bad = ltp.ltpss(model.A(0.0) * 1.3, model.B, model.C, model.D, period=T)
        return bad, info
    monkeypatch.setattr(subspace, 'refine_ltp', spoiling)
    model, info = _identify(plant, 2, 7, refine='ml')
    assert info.refine_fallback and 'worse than its start' in info.message
    assert info.holdout_nrmse < 1e-2
    assert ltp.compare_ltp(model, plant, LINES[:20], signal='noise').time_nrmse < 1e-2


def test_compare_all_harmonics_and_time_domain():
    """The default compares every produced harmonic: an error in an outer harmonic of C
    is understated with nharmonics=1 and seen by default and in the time domain."""
    plant = random_ltp(200, 2, 1, periodic='B')                  # B: 2 harmonics
    C = np.zeros((7, 1, 2), complex)
    C[3] = plant.C(0.0)
    C[0], C[6] = 0.05, 0.05                                       # C_{±3}
    est = ltp.ltpss(plant.A, plant.B, ltp.PeriodicMatrix(C, T), 0, period=T)
    one = ltp.compare_ltp(est, plant, LINES[:10], 1)
    full = ltp.compare_ltp(est, plant, LINES[:10])
    assert full.nharmonics == 5 and 5 * one.htf_error < full.htf_error
    t = np.arange(640) * DT
    u = np.sin(2.3 * t)
    cmp = ltp.compare_ltp(est, plant, LINES[:10], signal=(t, u))
    # independent: the outputs differ by C_{±3}-terms only
    x = ltp.forced_response(plant, t, u, return_states=True).states
    dy = 0.1 * np.cos(6 * np.pi * t) * x.sum(axis=0)
    y = ltp.forced_response(plant, t, u).outputs
    assert np.isclose(cmp.time_nrmse, np.linalg.norm(dy) / np.linalg.norm(y), rtol=1e-6)
    with pytest.raises(ValueError, match='signal'):
        ltp.compare_ltp(est, plant, [1.0], signal='chirp')
    with pytest.raises(ControlArgument, match='signal'):
        ltp.compare_ltp(est, plant, [1.0], signal=3.0)
    with pytest.raises(ControlDimension, match='signal'):
        ltp.compare_ltp(est, plant, [1.0], signal=(t, np.ones((2, t.size))))


def test_progress_bar_on_the_refit(capsys):
    plant = random_ltp(200, 2, 1, periodic='B')
    ltp.identify_ltp(lifted_data(plant, 3, LINES, DT), T, 2, 1, progress=True)
    assert 'refit' in capsys.readouterr().err


@pytest.mark.slow
def test_reduced_prediction_study():
    """One plant of each class (A only, B, fast actuator, 2x2 MIMO, ABC), K = 2 and 3,
    noise-free: filtered-noise NRMSE <= 1e-2; 20 dB draws: no silent failure."""
    for cls, plant in plant_classes(1):
        e2, ok2, _, _ = evaluate(plant, 2)
        e3, ok3, _, _ = evaluate(plant, 3)
        assert e2 <= 1e-2 and e3 <= 1e-2, cls
        assert e3 <= 2 * e2 + 1e-9, cls
        e, ok, _, _ = evaluate(plant, 2, snr_db=20.0, seed=7)
        assert e <= 0.1 or not ok, cls


def test_more_harmonics_start_from_fewer():
    """A periodic-B plant that K = 2 models exactly: at K = 3 the refit also passes
    through the optimum of 2 harmonics and stays exact (from the realization alone it
    stalls at a relative residual of 5e-6)."""
    plant = random_ltp(201, 3, 1, periodic='B')
    model, info = _identify(plant, 3, 10)
    assert info.success and info.relative_residual < 1e-12
    assert 'refit converged' in info.message
    assert ltp.compare_ltp(model, plant, LINES[:20], signal='noise').time_nrmse < 1e-10


def test_unconverged_refit_validated_by_holdout():
    """A refit that creeps along a flat valley stops before converging: the held-out
    lines decide (success, no warning); without them the stop is reported."""
    plant = random_ltp(302, 3, 1, periodic='ABC', actuator=20)   # 4 states
    data = lifted_data(plant, 7, LINES, DT)
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        model, info = ltp.identify_ltp(data, T, 4, 2, return_info=True)
    assert info.success and 'validated by the held-out lines' in info.message
    assert info.holdout_nrmse < 1e-2
    truth = ltp.compare_ltp(model, plant, LINES[:20], signal='noise').time_nrmse
    assert truth < 1e-2 and abs(truth - info.holdout_nrmse) < 0.5 * truth
    with pytest.warns(UserWarning, match='did not converge'):
        _, info = ltp.identify_ltp(data, T, 4, 2, holdout=None, return_info=True)
    assert not info.success and 'stopped before converging' in info.message


def test_output_noise_ignores_the_response():
    """White noise under a periodically modulated response and a periodic offset:
    the free DFT bins give the noise variance σ²/L of the output coefficients."""
    from ltpcontrol._identification.lifted_response import _output_noise
    N, P, sigma, K = 16, 20, 0.3, 2
    L, dt = N * P, 1 / N                                  # period 1, window of P periods
    t = np.arange(L) * dt
    lines = [np.array([3, 7, 45]) * 2 * np.pi / (L * dt), np.array([11]) * 2 * np.pi / (L * dt)]
    rng = np.random.default_rng(1)
    y = sigma * rng.standard_normal((2, 2, L))
    for e, Om in enumerate(lines):
        for w in Om:
            y[:, e] += 5 * np.cos(w * t) * (1 + np.cos(2 * np.pi * t)) + 2 * np.cos(4 * np.pi * t)
    var = _output_noise(y, lines, N, K, dt)
    assert var.shape == (4, (2 * K + 1) * 2)
    assert 0.8 < var.mean() / (sigma ** 2 / L) < 1.25
    # an experiment whose lines were all skipped has no pairs
    assert _output_noise(y, [lines[0], lines[1][:0]], N, K, dt).shape == (3, (2 * K + 1) * 2)
    # off the DFT grid the bins leak: no estimate
    assert np.isnan(_output_noise(y, [lines[0] * 1.01, lines[1]], N, K, dt)[:3]).all()
