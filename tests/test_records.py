"""Identification data: one record type for every identification entry point.

Every entry point that reads time-domain records accepts a
`control.TimeResponseData` however built (by a simulation or by hand), a
tuple ``(t, u, y)`` (channels first, time last) and a list of records, with
the same checks and the same error texts, naming the argument.
"""

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp

T, TS = 0.5, 0.01


@pytest.fixture(scope='module')
def plant():
    """First-order plant with a periodic input gain (period 0.5 s)."""
    B = ltp.PeriodicMatrix([[[0.3]], [[1.0]], [[0.3]]], T)
    return ltp.ltpss([[-3.0]], B, [[1.0]], 0, period=T, name='plant')


@pytest.fixture(scope='module')
def experiments(plant):
    """Five unit cosines, 12 s each at 100 Hz: t (L,), u (5, L), y (1, 5, L)."""
    t = np.arange(1200) * TS
    u = np.cos(2 * np.pi * np.array([0.3, 0.7, 1.3, 2.1, 3.3])[:, None] * t[None, :])
    y = ltp.forced_response(plant, t, u[None]).outputs
    return t, u, y


def _by_hand(t, u, y):
    """A response built by hand, as a user holding measured data would."""
    return ct.TimeResponseData(t, y, inputs=u)


#
# The same data in every accepted form gives the same result
#

def test_lifted_response_from_a_hand_built_response(experiments):
    t, u, y = experiments
    ref = ltp.lifted_frequency_response((t, u[None], y), T, 1, transient=2.0)
    by_hand = ltp.lifted_frequency_response(_by_hand(t, u[None], y), T, 1, transient=2.0)
    listed = ltp.lifted_frequency_response([(t, u[j], y[0, j]) for j in range(5)], T, 1,
                                           transient=2.0)
    squeezed = ltp.lifted_frequency_response((t, u, y), T, 1, transient=2.0)
    for G in (by_hand, listed, squeezed):
        np.testing.assert_array_equal(G.frdata, ref.frdata)
        np.testing.assert_array_equal(G.omega, ref.omega)


def test_identify_ltp_from_a_hand_built_response(plant, experiments):
    t, u, y = experiments
    model = ltp.identify_ltp(_by_hand(t, u[None], y), T, 1, 1, transient=2.0)
    # the identified first-order model has the plant's Floquet exponent -3
    assert ltp.floquet_exponents(model).real == pytest.approx([-3.0], abs=1e-2)


def test_estimate_htf_from_hand_built_responses(plant):
    exc = ltp.chirp_replicas(T, 7, 20.0, 0.0, 4.0, dt=TS, gap=8.0)
    y = ltp.forced_response(plant, exc.time, exc.inputs).outputs
    seg = exc.segments
    ref = ltp.estimate_htf((exc.time, exc.inputs, y), T, 1, segments=seg)
    by_hand = ltp.estimate_htf(_by_hand(exc.time, exc.inputs, y), T, 1, segments=seg)
    as_list = ltp.estimate_htf(ct.TimeResponseList([_by_hand(exc.time, exc.inputs, y)]), T, 1,
                               segments=seg)
    for H in (by_hand, as_list):
        np.testing.assert_allclose(H.components()[1], ref.components()[1], rtol=1e-12)


def test_identify_arx_accepts_every_form():
    N, rng = 8, np.random.default_rng(0)
    a = 0.5 + 0.3 * np.cos(2 * np.pi * np.arange(N) / N)
    u = rng.standard_normal((2, 200))
    y = np.zeros_like(u)
    for k in range(1, 200):
        y[:, k] = a[k % N] * y[:, k - 1] + u[:, k - 1]
    t = np.arange(200) * 0.1
    forms = [(t, u[None], y[None]), [(t, u[0], y[0]), (t, u[1], y[1])],
             _by_hand(t, u[None], y[None])]
    for data in forms:
        model = ltp.identify_arx(data, 0.8, 1, 1)
        np.testing.assert_allclose(model.C.sample(N)[:, 0, 0], a, atol=1e-10)


#
# Bad records: a clear error naming the argument
#

def _entry_points(t, u, y):
    """Each entry point called on the records (t, u, y)."""
    return {
        'lifted_frequency_response':
            ('response', lambda: ltp.lifted_frequency_response((t, u, y), T, 1)),
        'identify_ltp': ('data', lambda: ltp.identify_ltp((t, u, y), T, 1, 1)),
        'estimate_htf': ('data', lambda: ltp.estimate_htf((t, u, y), T, 1)),
        'identify_arx': ('data', lambda: ltp.identify_arx((t, u, y), T, 1, 1)),
    }


def _bad(experiments, kind):
    t, u, y = experiments
    u, y = u[:1].copy(), y[:, :1].copy()
    if kind == 'nan':
        y[0, 0, 5] = np.nan
    elif kind == 'length':
        y = y[..., :-1]
    elif kind == 'sampling':
        t = t.copy()
        t[600:] += 0.3 * TS
    elif kind == 'ragged':
        u = [list(u[0]), list(u[0][:-3])]
    return t, u, y


@pytest.mark.parametrize('kind, exc, match', [
    ('nan', ValueError, "outputs must be finite"),
    ('length', ControlDimension, "samples"),
    ('sampling', ValueError, "time must be increasing and uniformly spaced"),
    ('ragged', ValueError, "inputs must be a real array of equal-length rows"),
])
def test_bad_records_are_named(experiments, kind, exc, match):
    for entry, (arg, call) in _entry_points(*_bad(experiments, kind)).items():
        with pytest.raises(exc, match=match) as err:
            call()
        assert str(err.value).startswith(arg), (entry, str(err.value))


def test_bad_record_in_a_list_is_named_by_its_index(experiments):
    t, u, y = experiments
    records = [(t, u[0], y[0, 0]), (t, u[1], y[0, 1] * np.nan)]
    with pytest.raises(ValueError, match=r"response\[1\] outputs must be finite"):
        ltp.lifted_frequency_response(records, T, 1)
    with pytest.raises(ControlArgument, match=r"data\[0\] must be a control.TimeResponseData"):
        ltp.estimate_htf([t, u, y], T, 1)


def test_records_shorter_than_a_period_are_refused(experiments):
    t, u, y = experiments
    short = (t[:30], u[0, :30], y[0, 0, :30])           # 0.3 s < T
    with pytest.raises(ValueError, match="no whole period"):
        ltp.lifted_frequency_response(short, T, 1)
    with pytest.raises(ValueError, match="shorter than one period"):
        ltp.estimate_htf(short, T, 1)
    with pytest.raises(ValueError, match="transient"):
        ltp.lifted_frequency_response((t, u, y), T, 1, transient=11.9)


def test_ambiguous_two_dimensional_records_are_refused(experiments):
    # (5, L) inputs and outputs are five channels of one experiment: the
    # single-input entry points refuse them rather than reading experiments
    t, u, y = experiments
    for call in (lambda: ltp.lifted_frequency_response((t, u, y[0]), T, 1),
                 lambda: ltp.identify_arx((t, u, y[0]), T, 1, 1)):
        with pytest.raises(ControlDimension, match=r"shape \(1, 5, L\)"):
            call()


def test_a_response_without_inputs_is_refused(experiments):
    t, u, y = experiments
    with pytest.raises(ControlArgument, match="response carries no inputs"):
        ltp.lifted_frequency_response(ct.TimeResponseData(t, y[0, :1], issiso=True), T, 1)
