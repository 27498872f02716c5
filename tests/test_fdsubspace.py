"""Tests of frequency-domain subspace identification (McKelvey-Akçay-Ljung)."""

import control as ct
import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

from ltpcontrol import FDSubspaceInfo, fdsubspace

SHAPES = [(1, 1), (2, 2), (3, 2), (2, 3)]


def random_dt(rng, n, p, m, dt=1.0, strictly_proper=False):
    """Random minimal stable DT system, spectral radius in (0.5, 0.95)."""
    A = rng.standard_normal((n, n))
    A *= rng.uniform(0.5, 0.95) / max(abs(np.linalg.eigvals(A)))
    D = np.zeros((p, m)) if strictly_proper else rng.standard_normal((p, m))
    return ct.ss(A, rng.standard_normal((n, m)), rng.standard_normal((p, n)), D, dt)


def random_ct(rng, n, p, m, strictly_proper=False):
    """Random minimal stable CT system, slowest decay rate in (0.1, 1)."""
    A = rng.standard_normal((n, n))
    A -= (max(np.linalg.eigvals(A).real) + rng.uniform(0.1, 1.0)) * np.eye(n)
    D = np.zeros((p, m)) if strictly_proper else rng.standard_normal((p, m))
    return ct.ss(A, rng.standard_normal((n, m)), rng.standard_normal((p, n)), D)


def frf_error(true, model, omega):
    """max |G - G_hat| / max |G| on the grid `omega`."""
    G = ct.frd(true, omega).frdata
    return np.max(np.abs(G - ct.frd(model, omega).frdata)) / np.max(np.abs(G))


def add_noise(rng, G, level):
    """Complex Gaussian noise with rms `level` times the rms of `G`."""
    noise = rng.standard_normal(G.shape) + 1j * rng.standard_normal(G.shape)
    return G + noise * level * np.sqrt(np.mean(np.abs(G) ** 2) / 2)


DT_GRID = np.linspace(0.02, np.pi - 0.02, 40)
DT_CHECK = np.linspace(0.001, np.pi - 0.001, 301)     # off the data grid
CT_GRID = np.logspace(-2, 2, 50)
CT_CHECK = np.logspace(-3, 3, 301)


# --- exact recovery from noise-free data --------------------------------------

@pytest.mark.parametrize("n", range(2, 9))
@pytest.mark.parametrize("p, m", SHAPES)
def test_dt_recovery(n, p, m):
    rng = np.random.default_rng(100 * n + 10 * p + m)
    sys = random_dt(rng, n, p, m)
    model = fdsubspace(ct.frd(sys, DT_GRID), order=n)
    assert model.nstates == n and model.dt == 1.0
    assert model.ninputs == m and model.noutputs == p
    assert frf_error(sys, model, DT_CHECK) < 1e-8
    np.testing.assert_allclose(np.sort_complex(model.poles()),
                               np.sort_complex(sys.poles()), atol=1e-5)


@pytest.mark.parametrize("n", range(2, 9))
@pytest.mark.parametrize("p, m", SHAPES)
def test_ct_recovery(n, p, m):
    rng = np.random.default_rng(200 * n + 10 * p + m)
    sys = random_ct(rng, n, p, m)
    model = fdsubspace(ct.frd(sys, CT_GRID), order=n)
    assert model.nstates == n and model.dt == 0
    assert frf_error(sys, model, CT_CHECK) < 1e-8
    np.testing.assert_allclose(model.D, sys.D, atol=1e-8)
    np.testing.assert_allclose(np.sort_complex(model.poles()),
                               np.sort_complex(sys.poles()), rtol=1e-5)


@pytest.fixture
def seeded_global_rng():
    """`ct.rss`/`ct.drss` draw from numpy's global generator: seed and restore it."""
    state = np.random.get_state()
    np.random.seed(1234)
    yield
    np.random.set_state(state)


def test_drss_rss_recovery(seeded_global_rng):
    for _ in range(5):
        sysd = ct.drss(5, 3, 2, dt=0.1)
        sysc = ct.rss(6, 2, 2)
        md = fdsubspace(ct.frd(sysd, DT_GRID / 0.1), order=5)
        mc = fdsubspace(ct.frd(sysc, CT_GRID), order=6)
        assert md.dt == 0.1
        assert frf_error(sysd, md, DT_CHECK / 0.1) < 1e-8
        assert frf_error(sysc, mc, CT_CHECK) < 1e-8


def test_sampling_time_and_dt_true():
    rng = np.random.default_rng(7)
    sys = random_dt(rng, 3, 2, 1, dt=0.01)
    model = fdsubspace(ct.frd(sys, DT_GRID / 0.01))
    assert model.dt == 0.01 and model.nstates == 3
    assert frf_error(sys, model, DT_CHECK / 0.01) < 1e-8
    # dt=True: frequencies in rad/sample; the array path needs dt explicitly
    sys_true = ct.ss(sys.A, sys.B, sys.C, sys.D, True)
    G = ct.frd(sys_true, DT_GRID).frdata
    model = fdsubspace(G, DT_GRID, dt=True)
    assert model.dt is True
    assert frf_error(sys_true, model, DT_CHECK) < 1e-8


def test_strictly_proper():
    rng = np.random.default_rng(8)
    sysd = random_dt(rng, 4, 2, 2, strictly_proper=True)
    sysc = random_ct(rng, 4, 2, 2, strictly_proper=True)
    for sys, grid, check in [(sysd, DT_GRID, DT_CHECK), (sysc, CT_GRID, CT_CHECK)]:
        model = fdsubspace(ct.frd(sys, grid), order=4, estimate_d=False)
        assert np.all(model.D == 0)
        assert frf_error(sys, model, check) < 1e-8
    # forcing D = 0 on a system with a feedthrough cannot fit the data
    sys = random_dt(rng, 4, 2, 2)
    model, info = fdsubspace(ct.frd(sys, DT_GRID), order=4, estimate_d=False,
                             return_info=True)
    assert info.relative_residual > 1e-3


def test_siso_1d_array_and_frd_agree():
    rng = np.random.default_rng(9)
    sys = random_ct(rng, 3, 1, 1)
    data = ct.frd(sys, CT_GRID)
    m1 = fdsubspace(data, order=3)
    m2 = fdsubspace(data.frdata[0, 0], CT_GRID, order=3)
    for model in (m1, m2):
        assert frf_error(sys, model, CT_CHECK) < 1e-8
    np.testing.assert_allclose(ct.frd(m1, CT_CHECK).frdata,
                               ct.frd(m2, CT_CHECK).frdata, rtol=1e-9)


def test_unsorted_frequencies():
    rng = np.random.default_rng(10)
    sys = random_dt(rng, 4, 2, 2)
    omega = rng.permutation(DT_GRID)
    G = ct.frd(sys, np.sort(omega)).frdata
    G = G[..., np.argsort(np.argsort(omega))]           # data in the order of omega
    model = fdsubspace(G, omega, order=4, dt=1.0)
    assert frf_error(sys, model, DT_CHECK) < 1e-8


def test_few_frequencies_are_enough():
    # 2*M*m >= q*m + n with M = 5, m = 1, n = 4, q = 5 is the minimum
    rng = np.random.default_rng(11)
    sys = random_dt(rng, 4, 1, 1)
    omega = np.array([0.3, 0.9, 1.5, 2.1, 2.8])
    model = fdsubspace(ct.frd(sys, omega), order=4, q=5)
    assert frf_error(sys, model, DT_CHECK) < 1e-8
    with pytest.raises(ValueError, match="too few frequencies"):
        fdsubspace(ct.frd(sys, omega[:4]), order=4, q=5)


# --- order selection, diagnostics ---------------------------------------------

@pytest.mark.parametrize("n", range(2, 9))
def test_automatic_order(n):
    rng = np.random.default_rng(300 + n)
    sysd = random_dt(rng, n, 2, 2)
    sysc = random_ct(rng, n, 3, 2)
    md, info_d = fdsubspace(ct.frd(sysd, DT_GRID), return_info=True)
    mc, info_c = fdsubspace(ct.frd(sysc, CT_GRID), return_info=True)
    assert info_d.order == md.nstates == n
    assert info_c.order == mc.nstates == n
    for info in (info_d, info_c):
        sv = info.singular_values
        assert np.all(np.diff(sv) <= 0)
        assert sv[n] < 1e-10 * sv[0] < sv[n - 1]
        assert info.relative_residual < 1e-10
    assert info_d.timescale is None
    np.testing.assert_allclose(info_c.timescale, 2 / np.exp(np.mean(np.log(CT_GRID))))


def test_max_order_and_q():
    rng = np.random.default_rng(12)
    sys = random_dt(rng, 6, 1, 1)
    data = ct.frd(sys, DT_GRID)
    # the gap search cannot look beyond max_order
    model, info = fdsubspace(data, max_order=4, return_info=True)
    assert info.order <= 4 and info.q == 8
    model, info = fdsubspace(data, max_order=8, q=15, return_info=True)
    assert info.order == 6 and info.q == 15
    assert frf_error(sys, model, DT_CHECK) < 1e-8
    # with q alone the search covers orders up to q - 1
    model, info = fdsubspace(data, q=8, return_info=True)
    assert info.order == 6 and info.q == 8
    assert frf_error(sys, model, DT_CHECK) < 1e-8


def test_info_type_and_residual():
    rng = np.random.default_rng(13)
    sys = random_dt(rng, 3, 2, 2)
    G = add_noise(rng, ct.frd(sys, DT_GRID).frdata, 1e-3)
    model, info = fdsubspace(G, DT_GRID, order=3, dt=1.0, return_info=True)
    assert isinstance(info, FDSubspaceInfo)
    Ghat = ct.frd(model, DT_GRID).frdata
    np.testing.assert_allclose(info.residual, np.linalg.norm(G - Ghat), rtol=1e-8)
    np.testing.assert_allclose(info.relative_residual,
                               info.residual / np.linalg.norm(G), rtol=1e-12)


def test_names_and_labels():
    rng = np.random.default_rng(14)
    sys = random_dt(rng, 2, 2, 1)
    data = ct.frd(sys, DT_GRID, inputs=["f"], outputs=["x", "v"])
    model = fdsubspace(data, order=2, name="plant")
    assert model.name == "plant"
    assert model.input_labels == ["f"] and model.output_labels == ["x", "v"]
    model = fdsubspace(data, order=2, outputs=["a", "b"], states=["s1", "s2"])
    assert model.output_labels == ["a", "b"] and model.state_labels == ["s1", "s2"]


# --- noise and weights -----------------------------------------------------------

@pytest.mark.parametrize("continuous", [False, True])
def test_noise_degrades_gracefully(continuous):
    rng = np.random.default_rng(15)
    if continuous:
        sys, grid, check = random_ct(rng, 4, 2, 2), np.logspace(-2, 2, 200), CT_CHECK
    else:
        sys, grid, check = random_dt(rng, 4, 2, 2), np.linspace(0.01, 3.13, 200), DT_CHECK
    G = ct.frd(sys, grid).frdata
    levels = [1e-7, 1e-5, 1e-3]
    errors = []
    for level in levels:
        model = fdsubspace(add_noise(rng, G, level), grid, order=4, dt=sys.dt)
        errors.append(frf_error(sys, model, check))
    ratios = np.array(errors) / levels
    # error proportional to the noise level (about 0.1-0.3 times it here)
    assert np.all((ratios > 1e-2) & (ratios < 3)), ratios


def test_weights_remove_outlier():
    rng = np.random.default_rng(16)
    sys = random_dt(rng, 4, 2, 2)
    G = ct.frd(sys, DT_GRID).frdata
    G[:, :, 17] += 5.0                                   # one corrupted frequency
    assert frf_error(sys, fdsubspace(G, DT_GRID, order=4, dt=1.0), DT_CHECK) > 1e-3
    w = np.ones(DT_GRID.size)
    w[17] = 0
    model = fdsubspace(G, DT_GRID, order=4, dt=1.0, weights=w)
    assert frf_error(sys, model, DT_CHECK) < 1e-8
    # elementwise weights of shape (ny, nu, nomega) give the same result
    model3 = fdsubspace(G, DT_GRID, order=4, dt=1.0,
                        weights=np.broadcast_to(w, G.shape))
    assert frf_error(sys, model3, DT_CHECK) < 1e-8


def test_weights_follow_noise_level():
    # noise 100x larger on the upper half of the band: 1/sigma weights help
    rng = np.random.default_rng(17)
    sys = random_dt(rng, 3, 1, 1)
    omega = np.linspace(0.01, 3.13, 300)
    G = ct.frd(sys, omega).frdata
    sigma = np.where(omega < np.pi / 2, 1e-5, 1e-3)
    errs_plain, errs_weighted = [], []
    for _ in range(5):
        noise = (rng.standard_normal(G.shape) + 1j * rng.standard_normal(G.shape))
        Gn = G + noise * sigma
        errs_plain.append(frf_error(sys, fdsubspace(Gn, omega, order=3, dt=1.0),
                                    DT_CHECK))
        errs_weighted.append(frf_error(
            sys, fdsubspace(Gn, omega, order=3, dt=1.0, weights=1 / sigma), DT_CHECK))
    assert np.median(errs_weighted) < 0.5 * np.median(errs_plain)


# --- continuous-time frequency map -----------------------------------------------

def test_timescale_choice():
    rng = np.random.default_rng(18)
    sys = random_ct(rng, 4, 1, 2)
    data = ct.frd(sys, CT_GRID)
    for T in [0.05, 1.0, 20.0]:
        model, info = fdsubspace(data, order=4, timescale=T, return_info=True)
        assert info.timescale == T
        assert frf_error(sys, model, CT_CHECK) < 1e-8


def test_differentiator_warns():
    # G(s) = s has its pole at infinity: the bilinear DT model has a pole at z = -1
    omega = np.logspace(-1, 1, 20)
    with pytest.warns(UserWarning, match="z = -1"):
        model = fdsubspace(1j * omega, omega, order=1)
    assert abs(model.A[0, 0]) > 1e12


# --- input validation --------------------------------------------------------------

@pytest.fixture
def siso():
    sys = ct.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], 1.0)
    return ct.frd(sys, DT_GRID)


@pytest.mark.parametrize("args, kwargs, exc, match", [
    ((np.ones((2, 2)), DT_GRID), {}, ControlDimension, "data"),
    ((np.ones((1, 1, 5)), np.arange(1, 7.0)), {}, ControlDimension, "omega"),
    ((np.ones(5),), {}, ControlArgument, "omega"),
    ((np.full(5, np.nan), np.arange(1, 6.0)), {}, ValueError, "data"),
    ((np.ones(5), [1, 2, 2, 3, 4.0]), {}, ValueError, "omega"),
    ((np.ones(5), [0, 1, 2, 3, 4.0]), {}, ValueError, "omega"),
    ((np.ones(5), [1, 2, np.inf, 3, 4.0]), {}, ValueError, "omega"),
    ((np.ones(5), [1, 2, 3, 4, 5.0]), {"dt": 1.0}, ValueError, "omega"),
    ((np.ones(5), [1, 2, 3, 4, 5.0]), {"dt": -1.0}, ValueError, "dt"),
    ((np.ones(5), [1, 2, 3, 4, 5.0]), {"dt": "x"}, ControlArgument, "dt"),
    ((np.zeros(5), [1, 2, 3, 4, 5.0]), {}, ValueError, "data"),
    ((["a", "b"], [1, 2.0]), {}, ControlArgument, "data"),
    ((ct.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]),), {}, ControlArgument, "data"),
])
def test_bad_data(args, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        fdsubspace(*args, **kwargs)


@pytest.mark.parametrize("kwargs, exc, match", [
    ({"order": 0}, ValueError, "order"),
    ({"order": 1.5}, ControlArgument, "order"),
    ({"order": 2, "q": 2}, ValueError, "q"),
    ({"order": 2, "q": "3"}, ControlArgument, "q"),
    ({"order": 50}, ValueError, "too few frequencies"),
    ({"order": 2, "q": 79}, ValueError, "too few frequencies"),
    ({"max_order": 2, "q": 2}, ValueError, "q"),
    ({"max_order": 0}, ValueError, "max_order"),
    ({"order": 1, "max_order": 3}, ControlArgument, "max_order"),
    ({"weights": np.ones(3)}, ControlDimension, "weights"),
    ({"weights": -np.ones(DT_GRID.size)}, ValueError, "weights"),
    ({"weights": np.zeros(DT_GRID.size)}, ValueError, "weights"),
    ({"estimate_d": "no"}, ControlArgument, "estimate_d"),
    ({"dt": 0.5}, ValueError, "dt"),
    ({"dt": 0}, ValueError, "dt"),
    ({"omega": DT_GRID}, ControlArgument, "omega"),
    ({"bogus": 1}, TypeError, "bogus"),
])
def test_bad_arguments(siso, kwargs, exc, match):
    with pytest.raises(exc, match=match):
        fdsubspace(siso, **kwargs)


def test_weights_zero_on_data():
    G = np.r_[np.zeros(5), np.ones(5)]
    w = np.r_[np.ones(5), np.zeros(5)]
    with pytest.raises(ValueError, match="weights"):
        fdsubspace(G, np.arange(1, 11.0), order=1, weights=w)


def test_bad_timescale():
    omega = np.logspace(-1, 1, 20)
    G = 1 / (1j * omega + 1)
    with pytest.raises(ValueError, match="timescale"):
        fdsubspace(G, omega, order=1, timescale=-1.0)
    with pytest.raises(ControlArgument, match="timescale"):
        fdsubspace(G, omega, order=1, timescale="fast")


def test_info_uses_optimize_result_vocabulary():
    # the diagnostics answer as scipy's OptimizeResult does, and cannot be altered
    import dataclasses
    data = ct.frd(ct.ss([[0.5]], [[1.0]], [[1.0]], [[0.0]], True), np.linspace(0.1, 3, 20))
    _, info = fdsubspace(data, order=1, return_info=True)
    assert info.success is True and info.nfev == 0 and 'order-1' in info.message
    with pytest.raises(dataclasses.FrozenInstanceError):
        info.order = 2
