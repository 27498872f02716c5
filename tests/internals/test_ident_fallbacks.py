"""Internal failures of the identification pipeline become fallbacks or clear
results, never leaked exceptions: d2c of multipliers on the negative real axis,
an SVD that does not converge or a Jacobian that is not finite."""

import warnings

import numpy as np
import pytest

import ltpcontrol as ltp
from ltpcontrol._identification.floquet_fit import _projected_svd, _robust_svd
from ltpcontrol._identification.refit import _to_continuous


def test_negative_real_multiplier_falls_back_to_tustin():
    sysd = ltp.ltpss(np.diag([-0.5, 0.3]), np.ones((2, 1)), np.ones((1, 2)), 0, 1.0, dt=0.25)
    with pytest.raises(ValueError, match='negative real axis'):
        ltp.d2c(sysd, 'log')
    with pytest.warns(UserWarning, match='no real logarithm'):
        model = _to_continuous(sysd, 'refit', {})
    # the inverse Tustin map of z = -0.5 and 0.3 with Ts = 0.25
    z = np.array([-0.5, 0.3])
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(model.A(0.0)).real),
                               np.sort(8 * (z - 1) / (z + 1)), rtol=1e-10)
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        assert _to_continuous(sysd, 'tustin', {}) is not None


def test_svd_fallbacks():
    J = np.random.default_rng(0).standard_normal((8, 3))
    U, s, Vt = _robust_svd(J)
    np.testing.assert_allclose((U * s) @ Vt, J, atol=1e-12)
    J[2, 1] = np.nan
    assert _robust_svd(J) == (None, None, None)


def test_projected_svd_equals_the_svd():
    # tall, badly column-scaled and rank-deficient, as refit Jacobians are
    rng = np.random.default_rng(1)
    J = rng.standard_normal((40, 6)) * np.logspace(0, -7, 6)
    J[:, 5] = J[:, 0] + J[:, 1]
    r = rng.standard_normal(40)
    U, s, Vt = np.linalg.svd(J, full_matrices=False)
    Utr, s2, Vt2 = _projected_svd(J, r)
    np.testing.assert_allclose(s2, s, rtol=1e-12, atol=1e-14 * s[0])
    # singular vectors are unique up to sign for distinct singular values
    sign = np.sign(np.sum(Vt2 * Vt, axis=1))[:5]
    np.testing.assert_allclose(Vt2[:5] * sign[:, None], Vt[:5], atol=1e-9)
    np.testing.assert_allclose(Utr[:5] * sign, (U.T @ r)[:5], rtol=1e-9)
    # a wide Jacobian (fewer residuals than parameters)
    Jw, rw = J[:4], r[:4]
    U, s, Vt = np.linalg.svd(Jw, full_matrices=False)
    Utr, s2, Vt2 = _projected_svd(Jw, rw)
    np.testing.assert_allclose(s2[:4], s, rtol=1e-12)
    np.testing.assert_allclose(np.abs(Utr[:4]), np.abs(U.T @ rw), rtol=1e-9)
    J[0, 0] = np.inf
    assert _projected_svd(J, r) == (None, None, None)
