"""The modal parametrisation of the HTF refinement: model response and Jacobian.

Tests of internals: they import private names (see the Developer notes).
"""

import numpy as np
import pytest

from ltpcontrol._identification.refine import (_Parametrisation, _data_points, _modal, _normalise,
                                               _response)
from test_refine import OMEGA, data_htf, random_floquet


@pytest.mark.parametrize("seed, shape, pair", [(0, (1, 1), True), (1, (2, 2), True),
                                               (2, (2, 1), False)])
def test_model_response_and_jacobian(seed, shape, pair):
    sys = random_floquet(seed, ny=shape[0], nu=shape[1], KC=2, d=0.3, complex_pair=pair)
    H, G = data_htf(sys, 2, OMEGA)
    k, Om, vals, _, _ = _data_points(H, sys.period, *shape)
    lam, V, kinds = _modal(sys.A(0.0))
    Bt, Ct = np.linalg.inv(V) @ sys.B.fourier(1), sys.C.fourier(2) @ V
    _normalise(Bt, Ct, kinds)
    par = _Parametrisation(lam, Bt, Ct, sys.D.fourier(0), kinds, True, True)
    Gm, J = _response(*par.unpack(par.theta0), k, Om, 2 * np.pi, jac=True)
    assert np.max(np.abs(Gm - vals)) < 1e-12 * np.max(np.abs(vals))
    Jz, th, eps = J @ par.M, par.theta0, 1e-6
    for i in range(th.size):
        step = np.zeros_like(th)
        step[i] = eps
        num = (_response(*par.unpack(th + step), k, Om, 2 * np.pi)
               - _response(*par.unpack(th - step), k, Om, 2 * np.pi)).ravel() / (2 * eps)
        assert np.max(np.abs(num - Jz[:, i])) < 1e-6 * max(1.0, np.abs(Jz[:, i]).max())
