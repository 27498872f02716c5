"""Memory- and time-safe HTF evaluation: chunking, path choice, refusal, one
evaluation per bode_htf.

Tests of internals: they import private names (see the Developer notes).
"""

import tracemalloc

import matplotlib
import numpy as np
import pytest

import ltpcontrol as ltp
from ltpcontrol._frequency import harmonic_ss as _harmonic_ss
from systems import random_periodic_plant

matplotlib.use('Agg')


SYS = random_periodic_plant(4, ninputs=2)
S = 1j * np.linspace(0.1, 20, 97)


@pytest.fixture(autouse=True)
def _restore_defaults():
    yield
    ltp.config.reset_defaults()


@pytest.mark.parametrize('method', ['solve', 'modal'])
def test_chunked_evaluation_equals_one_block(method):
    H = ltp.htf(SYS, 3, method=method)
    whole = H(S)
    nF = H._hss.F.shape[0]
    # a budget of a few points per chunk
    per_point = 16 * (2 * nF ** 2 + 2 * nF * 14 + 2 * 7 * 14)
    with ltp.config.defaults_context({'htf.max_memory': 4 * per_point + whole.nbytes}):
        H2 = ltp.htf(SYS, 3, method=method, internal_harmonics=H._hss.Ki)
        chunked = H2(S, progress=True)
    np.testing.assert_allclose(chunked, whole, rtol=1e-12, atol=1e-14)


def test_chunks_bound_the_working_memory():
    H = ltp.htf(SYS, 3, method='solve')
    H(S[:2])
    budget = 3e6
    with ltp.config.defaults_context({'htf.max_memory': budget}):
        tracemalloc.start()
        H(S)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert peak <= 1.5 * budget
    # the dense path through the Schur form needs O(nF²) once and O(nF) per point:
    # its memory is linear in the points (the result dominates)
    nF = H._hss.F.shape[0]
    peaks = []
    for reps in (1, 8):
        s = np.tile(S, reps)
        tracemalloc.start()
        out = H(s)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
        assert peaks[-1] <= 3 * out.nbytes + 16 * 4 * nF ** 2 + 1e6
    assert peaks[1] < 8 * peaks[0]


def test_requests_that_cannot_fit_are_refused_with_their_size():
    with pytest.raises(MemoryError, match=r"harmonic state space has \d+ states and needs "
                                          r"about [\d.]+ GB.*htf\.max_memory"):
        ltp.htf(SYS, 2000)
    H = ltp.htf(SYS, 3, method='solve')
    with ltp.config.defaults_context({'htf.max_memory': 1e4}):
        with pytest.raises(MemoryError, match=r"at 97 points needs about .*MB"):
            H(S)


def test_auto_path_is_modal_for_many_points_and_solve_for_few():
    H = ltp.htf(SYS, 3)
    H(S[:5])
    assert H._hss.modal is None
    H(S)
    assert H._hss.modal is not None
    np.testing.assert_allclose(H(S), ltp.htf(SYS, 3, method='solve')(S), rtol=1e-9,
                               atol=1e-12)


def test_bode_htf_evaluates_the_block_row_once(monkeypatch):
    calls = []
    orig = _harmonic_ss._HarmonicStateSpace.evaluate

    def counting(self, *args, **kwargs):
        calls.append(kwargs.get('cols'))
        return orig(self, *args, **kwargs)
    H = ltp.htf(SYS[0, 0], 3)
    monkeypatch.setattr(_harmonic_ss._HarmonicStateSpace, 'evaluate', counting)
    cplt = ltp.bode_htf(H, S.imag, harmonics=(-2, -1, 0, 1, 2))
    assert len(calls) == 1 and len(calls[0]) == 5
    resp = ltp.htf_response(H, S.imag, harmonics=(-2, 0, 2))[0]
    for k, frd in zip((-2, 0, 2), resp):
        np.testing.assert_allclose(frd.frdata, H.component(k, S.imag).frdata, rtol=1e-12)
    matplotlib.pyplot.close(cplt.figure)


def test_bode_htf_of_a_mimo_system():
    cplt = ltp.bode_htf(ltp.htf(SYS, 1), S.imag[:20], harmonics=(0, 1))
    assert cplt.axes.shape == (2, 2)                     # magnitude and phase x 2 inputs
    labels = [line.get_label() for line in cplt.lines[0, 1]]
    assert len(labels) == 2 and 'G_0' in labels[0] and 'G_1' in labels[1]
    matplotlib.pyplot.close(cplt.figure)


def test_progress_setting_shows_a_bar(capsys):
    H = ltp.htf(SYS, 3, method='solve')
    with ltp.config.defaults_context({'htf.max_memory': 2e6, 'htf.progress': True}):
        H(S)
    assert 'HTF' in capsys.readouterr().err
