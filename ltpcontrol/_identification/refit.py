"""Structured refit of an identified Floquet-form model (`identify_ltp`, step 5).

`fit_floquet` fits the model to the data harmonics |n| <= K first and then
to all of them (`_staged_fit`); `_refit` chooses between H = K and K + 1
harmonics in B(t) by BIC, and carries a start realized with fewer
harmonics through the intermediate structures (each contains the one
before, so the K-harmonic fit starts at the best (K-1)-harmonic model).
"""

import warnings

import numpy as np

from .._core.discretize import d2c
from .._core.ltpsys import LTPStateSpace
from .._core.periodic_matrix import PeriodicMatrix
from .floquet_fit import _harmonic_response, fit_floquet


def _refit(sys, Gc, omega, K, harmonics, estimate_d, fit_a, labels, progress=False, k0=None):
    """Step 5: the refit with ``H = harmonics`` harmonics in B; for 'auto' the refits
    with H = K and H = K + 1 (both from `sys`), K + 1 kept if it earns its place.

    A start realized with ``k0 < K`` harmonics is also carried through the
    structures k0, k0 + 1, ..., K in turn (each started at the optimum of the
    one before, which it contains): the K-harmonic fit then starts at the best
    (K-1)-harmonic model, and the lower residual of the two paths is kept.  A
    K-harmonic model has directions the data barely determine (harmonics a
    plant of fewer harmonics does not have); from the realization alone the
    refit can stall in them.
    """
    fit = dict(estimate_d=estimate_d, fit_a=fit_a, progress=progress, **labels)
    model, res, converged, nfev = _refit_from(sys, Gc, omega, K, harmonics, fit)
    if k0 is not None and k0 < K:
        nested = sys
        for k in range(k0, K):
            nested, _, _, more = _staged_fit(nested, Gc, omega, k, k, fit)
            nfev += more
        other, res1, conv1, more = _refit_from(nested, Gc, omega, K, harmonics, fit)
        nfev += more
        if res1 < res:
            model, converged = other, conv1
    return model, converged, nfev


def _refit_from(sys, Gc, omega, K, harmonics, fit):
    """`_refit` from one start: ``(model, residual, converged, nfev)``."""
    model, res, converged, nfev = _staged_fit(sys, Gc, omega, K, (
        K if harmonics == 'auto' else harmonics), fit)
    if harmonics == 'auto' and K > 0:            # K = 0: B_{±1} would meet no C harmonic
        wide, res1, conv1, nfev1 = _staged_fit(sys, Gc, omega, K, K + 1, fit)
        nfev += nfev1
        # BIC = N log(SSE / N) + p log N: N real residuals, B_{±(K+1)} add 2 n_p m parameters
        nres, extra = 2 * Gc.size, 2 * sys.nstates * Gc.shape[0]
        tiny = np.finfo(float).tiny
        # in logs: the ratio of squares can overflow or divide by zero (exact fits)
        bic = (2 * nres * (np.log(max(res1, tiny)) - np.log(max(res, tiny)))
               + extra * np.log(nres))
        # with the data harmonics K + 1 measured, B_{±(K+1)} is seen directly
        seen = Gc.shape[1] > 2 * K + 1 or _visibility(wide, omega, K) <= _MAX_VISIBILITY
        if bic < 0 and seen:
            model, res, converged = wide, res1, conv1
    return model, res, converged, nfev


def _staged_fit(sys, Gc, omega, K, H, fit):
    """`fit_floquet` on the data harmonics -K..K, then on all of `Gc` (-Kd..Kd) from
    there: the harmonics |n| <= K carry the structure, a start far from it
    meets local minima when the small outer harmonics weigh in from the outset."""
    Kd = (Gc.shape[1] - 1) // 2
    nfev = 0
    if Kd > K:
        sys, _, _, nfev = fit_floquet(sys, Gc[:, Kd - K:Kd + K + 1], omega, K, harmonics=H,
                                      **fit)
    model, res, converged, more = fit_floquet(sys, Gc, omega, K, harmonics=H, **fit)
    return model, res, converged, nfev + more


#: largest ratio of the effect of B_{±(K+1)} on the unmeasured harmonics ±(K+1) to
#: that on the measured ones (<= 10.4 on the random plants at K = 3, > 6e5 where undetermined)
_MAX_VISIBILITY = 1e3


def _visibility(model, omega, K):
    """``‖Σ C_{n-m} R_m B_m‖`` over n = ±(K+1) divided by that over |n| <= K, for
    the terms m = ±(K+1) alone."""
    Bc = model.B.fourier(K + 1).copy()
    Bc[1:-1] = 0                                          # keep B_{±(K+1)}
    extra = LTPStateSpace(model.A(0.0), PeriodicMatrix(Bc, model.period), model.C, 0,
                          model.period)
    G = _harmonic_response(extra, omega, K + 1)
    return np.linalg.norm(G[:, [0, -1]]) / max(np.linalg.norm(G[:, 1:-1]),
                                                np.finfo(float).tiny)


def _to_continuous(sysd, conversion, labels):
    """The continuous-time model of the realization `sysd` ('tustin', else 'log'); a
    multiplier on the negative real axis has no real logarithm: then the inverse
    Tustin map, with a warning (None if that fails too)."""
    method = 'tustin' if conversion == 'tustin' else 'log'
    try:
        return d2c(sysd, method, **labels)
    except (ValueError, np.linalg.LinAlgError) as err:
        if method == 'tustin':
            return None
        warnings.warn(f"the realized multipliers have no real logarithm ({err}); the "
                      "continuous model starts from the inverse Tustin map instead",
                      UserWarning, stacklevel=4)
    try:
        return d2c(sysd, 'tustin', **labels)
    except (ValueError, np.linalg.LinAlgError):
        return None
