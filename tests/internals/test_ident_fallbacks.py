"""Internal failures of the identification pipeline become fallbacks or clear
results, never leaked exceptions: d2c of multipliers on the negative real axis,
an SVD that does not converge or a Jacobian that is not finite."""

import warnings

import numpy as np
import pytest

import ltpcontrol as ltp
from ltpcontrol._identification.floquet_fit import _robust_svd
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
