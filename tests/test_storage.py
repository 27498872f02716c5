"""Pickle and `save`/`load` round trips of every object kind, bit for bit, and bad files."""

import json
import pickle
import zipfile

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import ltpcontrol as ltp
from ltpcontrol.storage import FORMAT_VERSION
from systems import damped_mathieu, mathieu, switching_mathieu

TIMES = np.concatenate([np.linspace(-1.3, 2.7, 97), [0.0, 0.25, 0.5, 1e-15]])


def file_round_trip(obj, tmp_path, name='obj.npz'):
    path = tmp_path / name
    ltp.save(path, obj)
    return ltp.load(path)


def pickle_round_trip(obj, tmp_path=None):
    return pickle.loads(pickle.dumps(obj))


ROUND_TRIPS = [file_round_trip, pickle_round_trip]


def assert_same_matrix(P, Q):
    """Same period, shape, switching instants and values everywhere, bit for bit."""
    assert type(Q) is ltp.PeriodicMatrix
    assert Q.period == P.period and Q.shape == P.shape
    assert np.array_equal(Q.breakpoints, P.breakpoints)
    t = TIMES * P.period
    assert np.array_equal(Q(t), P(t))
    if P.nharmonics is not None:
        assert np.array_equal(Q.fourier(P.nharmonics), P.fourier(P.nharmonics))


def assert_same_system(s, r):
    assert type(r) is ltp.LTPStateSpace
    assert (r.period, r.dt, r.name) == (s.period, s.dt, s.name)
    assert (r.input_labels, r.output_labels, r.state_labels) == \
        (s.input_labels, s.output_labels, s.state_labels)
    for k in 'ABCD':
        assert_same_matrix(getattr(s, k), getattr(r, k))


def fourier_matrix(draw_coeffs, period):
    c = np.asarray(draw_coeffs)
    return ltp.PeriodicMatrix(c + np.conj(c[::-1]), period)


@settings(derandomize=True, max_examples=15, deadline=None, database=None)
@given(K=st.integers(0, 4), n=st.integers(1, 3), m=st.integers(1, 3),
       period=st.floats(0.01, 100.0), seed=st.integers(0, 2 ** 16),
       how=st.sampled_from(ROUND_TRIPS))
def test_fourier_matrix(K, n, m, period, seed, how, tmp_path_factory):
    rng = np.random.default_rng(seed)
    c = rng.normal(size=(2 * K + 1, n, m)) + 1j * rng.normal(size=(2 * K + 1, n, m))
    P = fourier_matrix(c / 3.0, period)
    assert_same_matrix(P, how(P, tmp_path_factory.mktemp('f')))


@settings(derandomize=True, max_examples=15, deadline=None, database=None)
@given(npieces=st.integers(1, 5), seed=st.integers(0, 2 ** 16),
       how=st.sampled_from(ROUND_TRIPS))
def test_switching_and_sampled_matrices(npieces, seed, how, tmp_path_factory):
    rng = np.random.default_rng(seed)
    T = float(rng.uniform(0.1, 10))
    times = np.sort(np.concatenate([[0.0], rng.uniform(0.01, 0.99, npieces - 1) * T]))
    times = np.unique(times)
    pieces = [rng.normal(size=(2, 2)) if i % 2 else
              ltp.PeriodicMatrix([[[0.1, 0.2], [0.0, 0.3]], rng.normal(size=(2, 2)),
                                  [[0.1, 0.2], [0.0, 0.3]]], T) for i in range(len(times))]
    S = ltp.PeriodicMatrix.switching(pieces, times, T)
    hold = ltp.PeriodicMatrix.from_samples(rng.normal(size=(7, 2, 1)), T, kind='hold')
    trig = ltp.PeriodicMatrix.from_samples(rng.normal(size=(8, 1, 2)), T)
    for P in (S, hold, trig):
        assert_same_matrix(P, how(P, tmp_path_factory.mktemp('s')))


@pytest.mark.parametrize("how", ROUND_TRIPS)
def test_combinations(how, tmp_path):
    A = switching_mathieu().A
    P = 2.0 * A + A.T @ A - A[0:1, :]
    Q = ltp.PeriodicMatrix.block([[A, np.eye(2)], [[[0.0, 1.0]], A[1:2, :]]])
    for M in (P, Q, A.with_period(2 * A.period)):
        assert_same_matrix(M, how(M, tmp_path))


@pytest.mark.parametrize("how", ROUND_TRIPS)
def test_riccati_solution_and_gains(how, tmp_path):
    sys = switching_mathieu()
    X, _, G = ltp.care(sys.A, sys.B, np.eye(2), [[1.0]])
    K, _, _ = ltp.lqr(damped_mathieu(), np.eye(2), [[1.0]])
    L, _, _ = ltp.lqe(damped_mathieu(), [[1.0]], [[0.1]])
    for M in (X, G, K, L):
        assert_same_matrix(M, how(M, tmp_path))


@pytest.mark.parametrize("how", ROUND_TRIPS)
def test_systems(how, tmp_path):
    dsys = ltp.sample_system(damped_mathieu(), damped_mathieu().period / 8)
    named = ltp.ltpss(mathieu().A, mathieu().B, mathieu().C, mathieu().D,
                      period=mathieu().period, name='plant', inputs=['force'],
                      outputs=['pos'], states=['q', 'v'])
    for s in (mathieu(), switching_mathieu(), damped_mathieu(), dsys, named):
        assert_same_system(s, how(s, tmp_path))


@pytest.mark.parametrize("how", ROUND_TRIPS)
def test_htfs(how, tmp_path):
    model = ltp.htf(damped_mathieu(), 2)
    w = np.linspace(0.1, 20, 37)
    back = how(model, tmp_path)
    assert type(back) is ltp.HTFModel and back.nharmonics == 2
    assert np.array_equal(back(1j * w), model(1j * w))
    rng = np.random.default_rng(0)
    comps = rng.normal(size=(5, 1, 1, 37)) + 1j * rng.normal(size=(5, 1, 1, 37))
    data = ltp.HTFData(comps, w, 0.5, std=np.abs(comps), name='measured')
    back = how(data, tmp_path)
    assert type(back) is ltp.HTFData and back.name == 'measured'
    for a, b in zip(back.components(), data.components()):
        assert np.array_equal(a, b)
    assert np.array_equal(back.omega, data.omega) and np.array_equal(back.std, data.std)


@pytest.mark.parametrize("how", ROUND_TRIPS)
def test_identified_model(how, tmp_path):
    N, dt = 6, 0.05
    rng = np.random.default_rng(5)
    u = rng.standard_normal((2, 200))
    model0 = ltp.ltpss(0.5 * rng.standard_normal((N, 2, 2)), rng.standard_normal((N, 2, 1)),
                       rng.standard_normal((N, 1, 2)), 0, period=N * dt, dt=dt)
    t = np.arange(200) * dt
    y = np.asarray(ltp.forced_response(model0, t, u[None]).outputs)[0]
    model = ltp.identify_arx((t, u[None], y[None]), N * dt, 2, 2)        # 2 experiments
    back = how(model, tmp_path)
    assert_same_system(model, back)
    r0, r1 = ltp.forced_response(model, t, u[0]), ltp.forced_response(back, t, u[0])
    assert np.array_equal(r0.outputs, r1.outputs)


def test_local_functions_are_refused_with_the_way_out(tmp_path):
    P = ltp.PeriodicMatrix.from_function(lambda t: np.array([[np.cos(t)]]), 2 * np.pi)
    with pytest.raises(TypeError, match='from_samples'):
        pickle.dumps(P)
    with pytest.raises(TypeError, match='from_samples'):
        ltp.save(tmp_path / 'p.npz', P)
    sys = ltp.ltpss(P, [[1.0]], [[1.0]], 0, period=2 * np.pi)
    with pytest.raises(TypeError, match='sample it'):
        ltp.save(tmp_path / 's.npz', sys)
    # the way out works
    S = ltp.PeriodicMatrix.from_samples(P.sample(16), P.period)
    assert_same_matrix(S, file_round_trip(S, tmp_path))
    with pytest.raises(TypeError, match='cannot store a dict'):
        ltp.save(tmp_path / 'd.npz', {})


def test_bad_files(tmp_path, monkeypatch):
    sys = switching_mathieu()
    good = tmp_path / 'good.npz'
    ltp.save(good, sys)
    raw = good.read_bytes()
    (tmp_path / 'trunc.npz').write_bytes(raw[:len(raw) // 2])
    with pytest.raises(ValueError, match='corrupt or truncated'):
        ltp.load(tmp_path / 'trunc.npz')
    (tmp_path / 'junk.npz').write_bytes(b'not a file' * 50)
    with pytest.raises(ValueError, match='corrupt or truncated'):
        ltp.load(tmp_path / 'junk.npz')
    with pytest.raises(FileNotFoundError):
        ltp.load(tmp_path / 'missing.npz')
    # a newer version
    with np.load(good, allow_pickle=False) as data:
        members = {k: data[k] for k in data.files}
    members['version'] = np.array(FORMAT_VERSION + 1)
    np.savez(tmp_path / 'new.npz', **members)
    with pytest.raises(ValueError, match='upgrade'):
        ltp.load(tmp_path / 'new.npz')
    # not ours, and a tree naming a missing array
    np.savez(tmp_path / 'other.npz', x=np.arange(3))
    with pytest.raises(ValueError, match='not an ltpcontrol file'):
        ltp.load(tmp_path / 'other.npz')
    members['version'] = np.array(FORMAT_VERSION)
    members.pop('a0')
    np.savez(tmp_path / 'hole.npz', **members)
    with pytest.raises(ValueError, match='corrupt'):
        ltp.load(tmp_path / 'hole.npz')
    # a pickled object inside is never unpickled
    members = {'format': np.array('ltpcontrol'), 'version': np.array(1),
               'tree': np.array(json.dumps({'kind': 'HTFData'})),
               'a0': np.array([object()], dtype=object)}
    np.savez(tmp_path / 'pickled.npz', **members)
    with pytest.raises(ValueError):
        ltp.load(tmp_path / 'pickled.npz')
    calls = []
    real = np.load
    monkeypatch.setattr(np, 'load', lambda *a, **k: calls.append(k) or real(*a, **k))
    ltp.load(good)
    assert calls == [{'allow_pickle': False}]
    assert zipfile.is_zipfile(good)
