r"""Scenario models drawn from the parameter covariance of a refined model.

The maximum-likelihood parameters θ̂ of `refine_ltp` (`RefineInfo.x`) are
asymptotically Gaussian about the truth with the covariance ``Σ = F⁻¹``
(`RefineInfo.cov`).  A scenario is the model at ``θ = θ̂ + L z`` with z
standard normal and ``L = U diag(√w)`` (``L Lᵀ = Σ``) from the eigenvalues
``w >= 0`` and eigenvectors U of Σ; directions the pseudo-inverse covariance leaves at zero
variance stay at θ̂.  Scenarios carry the covariance through any nonlinear
map of the model (closed-loop multipliers of a design, predictions) without
linearising it.
"""

import numpy as np
from control.exception import ControlArgument

from .refine import RefineInfo
from .._core.validation import check_positive_int, real_array

__all__ = ['sample_models']

# relative asymmetry and negative eigenvalue of the covariance tolerated as round-off
_PSD_TOL = 1e-10


def sample_models(info, n, *, seed=None):
    r"""Models drawn from the parameter covariance of a refined model.

    Draws parameters ``θ_i ~ N(info.x, info.cov)`` and returns the models
    ``info.realize(θ_i)``: scenarios of the identified system consistent
    with its data under the estimator's Gaussian error model, e.g. to check
    a controller designed on the estimate against the models the data do
    not rule out.

    Parameters
    ----------
    info : RefineInfo
        Diagnostics of `refine_ltp` (``return_info=True``).
    n : int
        Number of models.
    seed : None, int, numpy.random.SeedSequence or numpy.random.Generator, optional
        Seed of `numpy.random.default_rng` (a Generator is used as given).

    Returns
    -------
    list of LTPStateSpace
        ``n`` continuous-time models in the basis and with the labels of
        the refined model.

    Raises
    ------
    ControlArgument
        If `info` is not a `RefineInfo` with a realization.
    ValueError
        If `n` is not a positive integer or ``info.cov`` is not a finite
        symmetric positive semidefinite matrix of the size of ``info.x``.

    Notes
    -----
    The factor ``L = U diag(√w)`` with ``L Lᵀ = Σ`` comes from the
    eigen-decomposition of Σ, so a singular (pseudo-inverse) covariance is
    accepted: the
    parameters it does not determine keep their estimates.  With a zero
    covariance every scenario is the refined model.  The covariance is a
    local (Cramér-Rao) description: where the standard deviations are of
    the size of the parameters themselves the model is nonlinear over that
    range and the true spread of the estimator can differ from it.

    Examples
    --------
    The HTF of a first-order system with a modulated input gain, with
    noise; 20 scenarios of its refined model, all stable and with the
    exponent within a few standard deviations:

    >>> T = 1.0
    >>> true = ltp.ltpss([[-2.0]], ltp.PeriodicMatrix([[[0.25j]], [[1.0]], [[-0.25j]]], T),
    ...                  [[1.0]], 0, period=T)
    >>> w = np.linspace(0.5, 15.0, 30)
    >>> _, G = ltp.htf(true, 1).components(w)
    >>> noise = np.random.default_rng(0).standard_normal((2,) + G.shape) * 0.01
    >>> H = ltp.HTFData(G + noise[0] + 1j * noise[1], w, T, std=np.full(G.shape, 0.01 * 2 ** .5))
    >>> model, info = ltp.refine_ltp(true, H, return_info=True)
    >>> models = ltp.sample_models(info, 20, seed=1)
    >>> len(models), all(ltp.is_stable(m) for m in models)
    (20, True)
    >>> exps = np.array([m.A(0)[0, 0] for m in models])
    >>> bool(np.all(np.abs(exps - info.x[0]) < 5 * info.std[0]))
    True
    """
    if not isinstance(info, RefineInfo) or not callable(info.realize):
        raise ControlArgument("info must be the RefineInfo of refine_ltp(..., return_info="
                              f"True), got {type(info).__name__}")
    n = check_positive_int(n, 'n')
    x = real_array(info.x, 'info.x', ndim=1)
    cov = real_array(info.cov, 'info.cov', ndim=2)
    if cov.shape != (x.size, x.size):
        raise ValueError(f"info.cov must be {x.size} x {x.size} (the size of info.x), "
                         f"got {cov.shape}")
    if np.abs(cov - cov.T).max(initial=0.0) > _PSD_TOL * np.abs(cov).max(initial=0.0):
        raise ValueError("info.cov must be symmetric")
    w, U = np.linalg.eigh(cov)
    if w.size and w[0] < -_PSD_TOL * max(w[-1], 0.0):
        raise ValueError(f"info.cov must be positive semidefinite (eigenvalue {w[0]:.3g})")
    root = U * np.sqrt(np.clip(w, 0.0, None))
    z = np.random.default_rng(seed).standard_normal((n, x.size))
    return [info.realize(theta) for theta in x + z @ root.T]
