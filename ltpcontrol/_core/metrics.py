"""Prediction error metrics for validating identified models.

``e_rms`` is the percentage RMS error of thesis eq. 3.59 and ``nrmse`` the
normalised RMS error ``‖y - ŷ‖ / ‖y‖`` (used for N-RMSE in thesis Table 4.2,
whose definition is not stated there).  Both compare uniformly sampled
signals over the last axis; restrict the arrays to the evaluation window
(e.g. steady state) before calling.
"""

import numpy as np
from control.exception import ControlDimension

from .validation import real_array

__all__ = ['e_rms', 'nrmse']


def _pair(y, y_hat):
    y = real_array(y, "y", allow_complex=True)
    y_hat = real_array(y_hat, "y_hat", allow_complex=True)
    if y.shape != y_hat.shape:
        raise ControlDimension(f"y_hat has shape {y_hat.shape}, y has {y.shape}")
    if y.size == 0:
        raise ValueError("y must not be empty")
    return y, y_hat


def nrmse(y, y_hat):
    """Normalised root-mean-square error ``‖y - ŷ‖ / ‖y‖``.

    Parameters
    ----------
    y : array_like
        Measured (reference) signal; time along the last axis.  Several
        signals (leading axes) are pooled into one norm.
    y_hat : array_like
        Prediction, same shape as `y`.

    Returns
    -------
    float
        The ratio of the 2-norms (0 for a perfect prediction).

    See Also
    --------
    e_rms : the same error in percent, ``100 * nrmse`` (thesis eq. 3.59).

    Examples
    --------
    >>> y = np.sin(np.linspace(0, 2 * np.pi, 100, endpoint=False))
    >>> round(ltp.nrmse(y, 0.8 * y), 12)
    0.2
    """
    y, y_hat = _pair(y, y_hat)
    ref = np.linalg.norm(y)
    if ref == 0:
        raise ValueError("y is identically zero; the normalised error is undefined")
    return float(np.linalg.norm(y - y_hat) / ref)


def e_rms(y, y_hat):
    """Percentage RMS prediction error of thesis eq. 3.59.

    ``E_rms = 100 · sqrt(mean (y - ŷ)²) / sqrt(mean y²)`` over the samples of
    a uniformly sampled window; this equals ``100 · nrmse(y, y_hat)``.

    Parameters
    ----------
    y : array_like
        Measured (reference) signal; time along the last axis.
    y_hat : array_like
        Prediction, same shape as `y`.

    Returns
    -------
    float
        Error in percent.

    See Also
    --------
    nrmse : the same error as a ratio.

    Examples
    --------
    >>> t = np.linspace(0, 20 * np.pi, 1000, endpoint=False)
    >>> round(ltp.e_rms(np.sin(t), np.sin(t) + 0.01 * np.cos(t)), 3)
    1.0
    """
    return 100.0 * nrmse(y, y_hat)
