"""Identification of LTP plants with several inputs: joint excitation, the
per-line least-squares separation of the inputs, and the whole chain
(subspace, Floquet realization, refit, ML refinement, structure selection) on
random 2-input, 2-output plants with periodic A, B, C."""

import warnings

import control as ct
import numpy as np
import pytest

import ltpcontrol as ltp
from examples.random_ltp_plants import design_lines, lifted_data, random_ltp

T, DT = 1.0, 1 / 64
LINES = design_lines(T, 120)
UNSEEN = design_lines(T, 37, wmax_factor=2.0, offset=0.61)
TP = 0.5                                                 # period of the small plants


def _identify(plant, K, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return ltp.identify_ltp(lifted_data(plant, K, LINES, DT), T, plant.nstates, K,
                                return_info=True, **kw)


def _mimo(seed):
    return random_ltp(seed, 2 + seed % 3, 2, ninputs=2)


def _sines(sys, settle=12):
    w = np.pi / 2 * np.array([k for k in range(1, 24) if k % 4])
    exc = ltp.sine_experiments(w, TP, dt=0.0125, nperiods=8, settle=settle, ninputs=2)
    return exc, ltp.forced_response(sys, exc.time, exc.inputs)


def test_joint_sines_design():
    w = np.pi / 2 * np.array([1, 3])                     # on the grid of the window
    exc = ltp.sine_experiments(w, TP, dt=0.0125, nperiods=8, ninputs=3)
    assert exc.inputs.shape == (3, 6, exc.time.size)
    assert np.allclose(exc.signal(exc.time), exc.inputs)
    assert np.allclose(exc.frequencies, np.repeat(w, 3))
    # input phasors of one line: the 3 x 3 DFT matrix (unitary up to scale)
    t = exc.time
    U = np.einsum('jek,k->je', exc.inputs[:, :3], np.exp(-1j * exc.frequencies[0] * t))
    assert np.allclose(U.conj().T @ U / np.abs(U[0, 0]) ** 2, 3 * np.eye(3))
    single = ltp.sine_experiments([2.0, 5.0], TP, dt=0.0125, nperiods=8, ninputs=1)
    plain = ltp.sine_experiments([2.0, 5.0], TP, dt=0.0125, nperiods=8)
    assert np.array_equal(single.inputs, plain.inputs)
    ms = ltp.multisine([2.0, 5.0], TP, dt=0.0125, nperiods=8, nexperiments=2, ninputs=2)
    assert ms.inputs.shape == (2, 4, ms.time.size)
    assert np.allclose(ms.inputs[0, ::2], ltp.multisine([2.0, 5.0], TP, dt=0.0125,
                                                        nperiods=8, nexperiments=2).inputs[0])


def test_lti_as_periodic_equals_python_control():
    """A 2 x 2 LTI plant written as periodic: G_0 is control's frequency response,
    the other harmonics vanish."""
    lti = ct.ss([[-1.0, 2.0], [-2.0, -1.5]], [[1.0, 0.0], [0.5, 1.0]],
                [[1.0, 0.0], [0.3, 1.0]], [[0.0, 0.0], [0.0, 0.0]])
    exc, resp = _sines(ltp.ltpss(lti, TP), settle=40)    # transient e^{-1.25 t} gone
    G = ltp.lifted_frequency_response(resp, TP, 1, transient=20.0, input_hold='foh',
                                      real=False)
    ref = ct.frequency_response(lti, G.omega).frdata            # (2, 2, M)
    assert G.frdata.shape == (6, 2, G.omega.size)
    assert np.abs(G.frdata[2:4] - ref).max() < 1e-4 * np.abs(ref).max()
    assert np.abs(G.frdata[[0, 1, 4, 5]]).max() < 1e-4 * np.abs(ref).max()
    assert G.input_labels == ['u[0]_h0', 'u[1]_h0']


def test_time_records_identify_two_input_plant():
    """Sine experiments on two inputs of a plant with periodic B(t): the model
    reproduces the plant's HTF (harmonics -1..1, which need the data's G_{±2})."""
    B = lambda t: np.array([[1 + 0.5 * np.cos(4 * np.pi * t), -0.5 + 0.3 * np.sin(4 * np.pi * t)],
                            [0.2, 1.0]])
    sys = ltp.ltpss([[-2.0, 1.0], [0.0, -3.0]], B, [[1.0, 0.0], [0.5, 1.0]], 0, period=TP)
    exc, resp = _sines(sys)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')          # the refit stalls at the data's error
        model, info = ltp.identify_ltp(resp, TP, 2, 2, transient=6.0, input_hold='foh',
                                       return_info=True)
    assert info.nfev > 0 and info.relative_residual < 1e-4
    assert (model.ninputs, model.noutputs) == (2, 2)
    assert model.input_labels == ['u[0]', 'u[1]']
    cmp = ltp.compare_ltp(model, sys, [1.1, 2.9, 7.3])
    assert cmp.htf_error < 1e-4 and cmp.exponent_error < 1e-4     # measured 3e-6, 3e-5


def test_inputs_not_separated():
    B = lambda t: np.array([[1 + 0.5 * np.cos(4 * np.pi * t), 1.0]])
    sys = ltp.ltpss([[-2.0]], B, [[1.0]], 0, period=TP)
    w = np.array([1.0, 3.0]) * np.pi
    exc = ltp.sine_experiments(w, TP, dt=0.0125, nperiods=8, settle=12, ninputs=2)
    # one experiment per line: the same phasor pattern cannot separate two inputs
    u = exc.inputs[:, ::2]
    y = ltp.forced_response(sys, exc.time, u).outputs
    with pytest.raises(ValueError, match="cannot separate the 2 inputs"):
        ltp.lifted_frequency_response((exc.time, u, y), TP, 1, transient=6.0)
    # nearly parallel phasors: a warning
    t = exc.time
    u = np.stack([np.cos(w[:, None] * t), np.cos(w[:, None] * t + 1e-3)])
    u = np.concatenate([u, np.stack([np.cos(w[:, None] * t), np.cos(w[:, None] * t)])], 1)
    y = ltp.forced_response(sys, t, u).outputs
    with pytest.warns(UserWarning, match="separate the inputs poorly"):
        ltp.lifted_frequency_response((t, u, y), TP, 1, transient=6.0)


def _check(plant, K, **kw):
    model, info = _identify(plant, K, **kw)
    assert model.nstates == plant.nstates and (model.ninputs, model.noutputs) == (2, 2)
    cmp = ltp.compare_ltp(model, plant, UNSEEN, 1)
    return info, cmp


@pytest.mark.slow
def test_random_mimo_plants():
    """6 random 2 x 2 plants (n_p = 2-4, two of each, periodic A, B, C), K = 3,
    default settings: a model for every one, HTF error at unseen frequencies and
    Floquet exponents within 1e-3 (measured <= 1.1e-6 and 4.8e-6 over 30 plants;
    with B(t) of K harmonics 1.3e-4 and 5.7e-4, and one plant of the 30 of
    examples/generic_identification_study.py misses by 1.7e-3)."""
    worst = np.zeros(2)
    for seed in range(6):
        info, cmp = _check(_mimo(seed), 3)
        # lifted data of K harmonics leave the model's outer ones unvalidated
        assert not info.success and 'neither fitted nor validated' in info.message
        worst = np.maximum(worst, [cmp.htf_error, cmp.exponent_error])
    assert worst[0] <= 1e-3 and worst[1] <= 1e-3


@pytest.mark.slow
def test_ml_refinement_and_structure_selection_mimo():
    plant = _mimo(3)                                          # n_p = 2
    G = lifted_data(plant, 2, LINES, DT)
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        base = ltp.identify_ltp(G, T, 2, 2)
        model, info = ltp.identify_ltp(G, T, 2, 2, refine='ml', return_info=True,
                                       refine_options={'std': np.full(LINES.size, 1e-3)})
    assert 'ML refinement' in info.message
    assert ltp.compare_ltp(model, plant, UNSEEN, 1).htf_error <= \
        1.01 * ltp.compare_ltp(base, plant, UNSEEN, 1).htf_error
    # the ML fit of the truncated model equals the refit's least-squares optimum
    assert info.relative_residual < 5e-3
    with pytest.raises(ltp.ControlDimension if hasattr(ltp, 'ControlDimension')
                       else ValueError, match='std'):
        ltp.refine_ltp(model, G, std=np.ones(3))
    # 40 lines (30 once every 4th is held out) hold the lifted order (2K+1) n_p = 14 of
    # the largest candidate; held-out errors 0.32, 0.32 (n_p = 1), 0.013, 4e-6 (n_p = 2),
    # on 120 lines 0.31, 0.30, 0.014, 4e-6: the same choice
    sel = ltp.select_structure(lifted_data(plant, 10, design_lines(T, 40), DT), T, [1, 2],
                               [1, 3])
    assert sel.best == (2, 3)
    assert sel.validation_error[1, 1] < 1e-3 < sel.validation_error[0, 1]
