"""Held-out validation and quality flags of `identify_ltp`.

The held-out NRMSE of a model contains the noise of the held-out data,
which the model never saw: ``E holdout² = error² + noise²``.  With the
noise known (estimated from time records, or ``std``) the model's share
``sqrt(holdout² - noise²)`` is compared with the tolerance; the relative
residual on all lines likewise.
"""

import warnings

import numpy as np
from control.exception import ControlDimension

from .floquet_fit import _harmonic_data, _harmonic_response
from .._core.validation import real_array

#: a noise level above the held-out NRMSE that contains it leaves the model's share
#: unknown (``sqrt(h² - noise²)`` would clip it to 0)
_NOISE_EXCESS = 1.0
#: a noise level above this many times the held-out NRMSE is not noise at all
_NOT_NOISE = 1.5


def _nrmse(sys, G, lines, Kd, N, ny):
    """``‖Ĝ - G‖ / ‖G‖`` on the lines `lines`, harmonics -Kd..Kd (the steady-state
    time-domain NRMSE of the held-out records, by Parseval)."""
    Gc = _harmonic_data(G.frdata, Kd, N, ny)[..., lines]
    with np.errstate(all='ignore'):
        err = np.linalg.norm(_harmonic_response(sys, G.omega[lines], Kd) - Gc)
    err = err / max(np.linalg.norm(Gc), np.finfo(float).tiny)
    return float(err) if np.isfinite(err) else np.inf


def _data_variance(std, data):
    """``std²`` broadcast to the entries of the lifted data, ``(M, rows, inputs)``."""
    std = real_array(std, 'std')
    if np.any(std < 0) or not np.all(np.isfinite(std)):
        raise ValueError("std must be finite and >= 0")
    try:
        var = np.broadcast_to(std ** 2, data.frdata.shape)
    except ValueError:
        raise ControlDimension(f"std of shape {std.shape} does not broadcast to the "
                               f"data's shape {data.frdata.shape} (outputs, inputs, "
                               "lines)") from None
    return var.transpose(2, 0, 1)


def _noise_nrmse(var, G, lines, Kd, N, ny):
    """The held-out NRMSE of the noise alone: ``sqrt(Σ var) / ‖G‖`` over the lines
    `lines` (the trace of the noise covariance is that of any unitary basis of the
    harmonics); NaN when the noise is unknown there."""
    if var is None:
        return np.nan
    power = float(np.sum(var[lines]))
    Gc = _harmonic_data(G.frdata, Kd, N, ny)[..., lines]
    return np.sqrt(power) / max(np.linalg.norm(Gc), np.finfo(float).tiny) \
        if np.isfinite(power) else np.nan


def _model_share(nrmse, noise):
    """``sqrt(nrmse² - noise²)``; `nrmse` when the noise is unknown; NaN (unknown)
    when the noise exceeds `nrmse`: the share is then not 0 but not determined.

    >>> round(_model_share(0.05, 0.03), 12), _model_share(0.05, np.nan)
    (0.04, 0.05)
    >>> _model_share(0.05, 0.06)
    nan
    """
    if not np.isfinite(noise):
        return nrmse
    if noise > _NOISE_EXCESS * nrmse:
        return np.nan
    return float(np.sqrt(max(nrmse ** 2 - noise ** 2, 0.0)))


def _checked_noise(nrmse, noise):
    """`noise` if the held-out `nrmse` can contain it, else NaN with a warning: the
    held-out noise was not fitted, so an estimate far above the NRMSE is not noise
    (a transient left in the window, too large a std).

    >>> _checked_noise(0.05, 0.03)
    0.03
    """
    if noise > _NOT_NOISE * nrmse:
        warnings.warn(f"the noise level ({noise:.3g}) exceeds the held-out NRMSE "
                      f"({nrmse:.3g}), which contains it: it is not used; check "
                      "transient= (time records) or std=", UserWarning, stacklevel=3)
        return np.nan
    if noise > _NOISE_EXCESS * nrmse:
        warnings.warn(f"the noise level ({noise:.3g}) is above the held-out NRMSE "
                      f"({nrmse:.3g}): the model's share of it is unknown "
                      "(holdout_error NaN); the held-out NRMSE bounds it", UserWarning,
                      stacklevel=3)
    return noise


def _quality(real, Kr, K, conversion, relres, converged, ml, options, validated=False,
             noise=np.nan):
    """``(success, message)`` of the returned model; warn when it is doubtful.  A refit
    or refinement that stopped before converging fails unless `validated` (the model
    predicts its held-out lines); `fit_tol` bounds the residual less the share of the
    `noise` (relative, NaN when unknown)."""
    checked = " (validated by the held-out lines)" if validated else ""
    if Kr < K and conversion != 'refit':
        warnings.warn(f"the lifted model of {K} harmonics has no eigenvalue ladders; "
                      f"realized with {Kr} harmonics instead: the model has {Kr} "
                      "harmonics", UserWarning, stacklevel=3)
    fit_tol = (options or {}).get('fit_tol', 0.05)
    if conversion == 'refit':
        miss, share = _model_share(relres, noise), ""
        if np.isnan(miss):
            # the fitted lines absorb part of their noise: a residual below the noise
            # level shows no model error (the held-out lines judge it)
            miss = 0.0
        if np.isfinite(noise):
            share = f", of which noise {noise:.3g}: model {miss:.3g}"
        success = (converged or validated) and miss <= fit_tol
        stop = 'converged' if converged else 'stopped before converging' + checked
        message = (f"refit {stop}, relative residual {relres:.3g}{share} (fit_tol "
                   f"{fit_tol:g})")
        if miss > fit_tol:
            warnings.warn(f"the identified model misses the data: relative residual "
                          f"{relres:.3g}{share} > {fit_tol:g} (realization: "
                          f"{real.message}); try other nstates, nharmonics or q",
                          UserWarning, stacklevel=3)
    else:
        success = real.success and Kr == K
        message = f"{real.message}; relative residual {relres:.3g}"
        if not real.success:
            warnings.warn(f"{real.message}; the model is not trustworthy (try another "
                          "realization method, seed or q)", UserWarning, stacklevel=3)
    if ml is not None:
        success = success and (ml.success or validated)
        message += f"; ML refinement: {ml.message}" + ("" if ml.success else checked)
    return bool(success), message


def _produced_harmonics(sys, K, conversion):
    """The output harmonics ``|n|`` a Floquet-form model produces: those of C(t)
    plus those of B(t) (2K + H for the refit), or of D(t) if more."""
    def harmonics(mat, default):
        n = mat.nharmonics
        return default if n is None else n
    if conversion == 'refit':
        return 2 * K + max(K, harmonics(sys.B, K))
    return max(harmonics(sys.C, 2 * K) + harmonics(sys.B, K), harmonics(sys.D, K))
