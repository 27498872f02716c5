"""Periodic ARX identification against exactly simulated periodic difference equations."""

import numpy as np
import control as ct
import pytest
from control.exception import ControlArgument, ControlDimension

import ltpcontrol as ltp

N, DT = 6, 0.05
T = N * DT


def simulate(a, b, u):
    """y[k] = Σ a_i(k) y[k−i] + Σ b_j(k) u[k−j] for records u of shape (nexp, L)."""
    y = np.zeros_like(u)
    na, nb = a.shape[1], b.shape[1]
    for k in range(u.shape[1]):
        p = k % N
        for i in range(1, na + 1):
            if k - i >= 0:
                y[:, k] += a[p, i - 1] * y[:, k - i]
        for j in range(1, nb + 1):
            if k - j >= 0:
                y[:, k] += b[p, j - 1] * u[:, k - j]
    return y


@pytest.fixture
def coefficients():
    rng = np.random.default_rng(5)
    a = 0.3 * rng.standard_normal((N, 2))
    b = rng.standard_normal((N, 3))
    return a, b


def test_recovers_coefficients_and_response(coefficients):
    a, b = coefficients
    rng = np.random.default_rng(0)
    u = rng.standard_normal((2, 300))
    y = simulate(a, b, u)
    t = np.arange(300) * DT
    model = ltp.identify_arx((t, u[None], y[None]), T, 2, 3)      # 2 experiments
    C = model.C.sample(N)[:, 0, :]
    np.testing.assert_allclose(C[:, :2], a, atol=1e-10)
    np.testing.assert_allclose(C[:, 2:], b, atol=1e-10)
    # the realization reproduces the difference equation from rest
    resp = ltp.forced_response(model, t, u[0])
    np.testing.assert_allclose(resp.outputs, y[0], atol=1e-9)
    assert model.dt == pytest.approx(DT) and model.nstates == 5 and model.nsteps == N


def test_return_info_gives_model_and_diagnostics(coefficients):
    a, b = coefficients
    rng = np.random.default_rng(0)
    u = rng.standard_normal((2, 300))
    y = simulate(a, b, u)
    noisy = y + 1e-3 * rng.standard_normal(y.shape)
    data = (np.arange(300) * DT, u[None], noisy[None])
    default = ltp.identify_arx(data, T, 2, 3)
    assert isinstance(default, ltp.LTPStateSpace)          # default return unchanged
    model, info = ltp.identify_arx(data, T, 2, 3, return_info=True)
    assert isinstance(info, ltp.ARXInfo) and info.success and isinstance(info.message, str)
    np.testing.assert_array_equal(model.C.sample(N), default.C.sample(N))
    assert info.nsteps == N and info.nrecords == 2 and info.ridge == 0.0
    # 2 records of 300 samples, the first 3 of each only as regressors
    assert info.nequations.sum() == 2 * 297 and info.nequations.shape == (N,)
    assert info.cond.shape == (N,) and np.all(info.cond >= 1)
    # one-step residuals sit at the noise level
    assert info.residual.shape == (N,) and np.all(info.residual < 5e-3)
    assert np.all(info.residual > 1e-4)
    with pytest.raises(AttributeError):
        info.success = False                                # frozen


def test_phase_follows_absolute_time(coefficients):
    # a record starting at step 4 of the period still maps phase k mod N
    a, b = coefficients
    u = np.random.default_rng(1).standard_normal((1, 304))
    y = simulate(a, b, u)
    t = np.arange(300) * DT + 4 * DT
    model = ltp.identify_arx((t, u[0, 4:], y[0, 4:]), T, 2, 3)
    np.testing.assert_allclose(model.C.sample(N)[:, 0, :2], a, atol=1e-9)


def test_lti_limit_matches_python_control():
    # a constant-coefficient system: the model's response equals ct.forced_response
    lti = ct.ss([[0.5, 0.2], [-0.1, 0.3]], [[1.0], [0.5]], [[1.0, -1.0]], 0, DT)
    u = np.random.default_rng(2).standard_normal(400)
    t = np.arange(400) * DT
    y = ct.forced_response(lti, t, u).outputs
    model = ltp.identify_arx((t, u, y), T, 2, 2)
    np.testing.assert_allclose(np.ptp(model.C.sample(N), axis=0), 0, atol=1e-9)
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(model.A(0.0))[:2]),
                               np.sort_complex(np.linalg.eigvals(lti.A)), atol=1e-8)
    np.testing.assert_allclose(ltp.forced_response(model, t, u).outputs, y, atol=1e-9)


def test_ridge_shrinks(coefficients):
    a, b = coefficients
    u = np.random.default_rng(3).standard_normal((1, 200))
    y = simulate(a, b, u)
    t = np.arange(200) * DT
    plain = ltp.identify_arx((t, u[0], y[0]), T, 2, 3).C.sample(N)
    shrunk = ltp.identify_arx((t, u[0], y[0]), T, 2, 3, ridge=1.0).C.sample(N)
    assert np.linalg.norm(shrunk) < np.linalg.norm(plain)


def test_bad_input():
    t = np.arange(100) * DT
    u = np.ones(100)
    with pytest.raises(ControlArgument, match="tuple"):
        ltp.identify_arx([t, u, u], T, 1, 1)
    with pytest.raises(ControlDimension, match="samples"):
        ltp.identify_arx((t, u, u[:-1]), T, 1, 1)
    with pytest.raises(ValueError, match="uniformly"):
        ltp.identify_arx((t ** 2, u, u), T, 1, 1)
    with pytest.raises(ValueError, match="integer number of steps"):
        ltp.identify_arx((t, u, u), 0.33, 1, 1)
    with pytest.raises(ValueError, match="record more periods"):
        ltp.identify_arx((t[:20], u[:20], u[:20]), T, 3, 3)
    with pytest.raises(ValueError, match="linearly dependent"):
        ltp.identify_arx((t, u, 2 * u), T, 1, 1)          # y[k-1] = 2 u[k-1]
    with pytest.raises(ValueError, match="na"):
        ltp.identify_arx((t, u, u), T, 0, 1)
    with pytest.raises(ValueError, match="ridge"):
        ltp.identify_arx((t, u, u), T, 1, 1, ridge=-1.0)
    with pytest.raises(ValueError, match="NaN"):
        ltp.identify_arx((t, u * np.nan, u), T, 1, 1)
