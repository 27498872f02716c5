"""Parametric fits to estimated harmonic transfer functions, and delays.

`fit_htf` fits the parameters of a model family to a nonparametric HTF
estimate by nonlinear least squares on the components (thesis §3.4.3, where
k and c of the leg model are fitted to G_{-1}, G_0, G_1), optionally on
magnitudes only (§3.6.3: delays leave magnitudes unchanged, eq. 3.46).

`estimate_delays` separates input and measurement delays from the phase of
several components (thesis §3.6, eqs. 3.45-3.50): with input delay τ_u and
measurement delay τ_y the measured components are

    H_k(jω) = G_k(jω) e^{-j[(ω - kω_p) τ_u + ω τ_y]}.

G_0 only sees ``τ_u + τ_y``; the harmonics k ≠ 0 carry ``k ω_p τ_u`` and
separate the two.  Because ``e^{jkω_p T} = 1``, τ_u is identifiable modulo
the period T (an input delay of one period equals an output delay of one
period for a T-periodic system), and a shift of the phase reference of the
cycle looks like an input delay.
"""

from dataclasses import dataclass

import numpy as np
import scipy.optimize
from control.exception import ControlArgument, ControlDimension

from .._frequency.htf import HTF, HTFData
from .._core.validation import real_array

__all__ = ['fit_htf', 'estimate_delays', 'HTFFit', 'HTFFitInfo', 'DelayEstimate']

# largest number of total-delay grid points searched by `estimate_delays`
_MAX_DELAY_GRID = 2 ** 18
# frequencies x delays evaluated at once in that search
_DELAY_CHUNK = 2 ** 20


@dataclass(frozen=True)
class HTFFit:
    """Fitted model of `fit_htf`: parameters, their covariance and the components.

    `fit_htf` returns this object as its model; the diagnostics of the
    optimisation come as an `HTFFitInfo` with ``return_info=True``.  The
    fields `cost`, `success`, `message` and `nfev` repeat that information
    and are kept for compatibility.

    Attributes
    ----------
    params : ndarray
        Fitted parameters.
    cov : ndarray
        Covariance of the parameters, ``s² (JᵀJ)⁻¹`` with ``s²`` the residual
        variance (NaN without residual degrees of freedom).
    std : ndarray
        Standard deviations ``sqrt(diag cov)``.
    components : ndarray, shape (2K+1, ny, nu, F)
        Model components at the fitted parameters on the estimate's grid
        (zero for harmonics beyond those the model returns).
    omega : ndarray
        Frequency grid (rad/s) of the fit.
    cost : float
        Final value of ``½ Σ r²``.
    success : bool
        Optimiser success flag.
    message : str
        Optimiser message.
    nfev : int
        Number of model evaluations.

    Examples
    --------
    >>> omega = np.linspace(0.1, 5, 20)
    >>> model = lambda p, w: (p[0] / (1j * w + 1))[None, None, None, :]
    >>> fit = ltp.fit_htf(model, ltp.HTFData(model([3.0], omega), omega, 1.0), [1.0])
    >>> fit.success, fit.components.shape
    (True, (1, 1, 1, 20))
    """

    params: np.ndarray
    cov: np.ndarray
    std: np.ndarray
    components: np.ndarray
    omega: np.ndarray
    cost: float
    success: bool
    message: str
    nfev: int


@dataclass(frozen=True)
class HTFFitInfo:
    """Diagnostics of `fit_htf` (``return_info=True``).

    ``success``, ``message`` and ``nfev`` follow `scipy.optimize.OptimizeResult`.

    Attributes
    ----------
    success : bool
        Optimiser success flag.
    message : str
        Optimiser message.
    cost : float
        Final value of ``½ Σ r²``.
    nfev : int
        Number of model evaluations.
    nresiduals : int
        Number of real residuals of the fit.
    dof : int
        Residual degrees of freedom, ``nresiduals`` minus the number of
        parameters (the covariance is NaN when it is not positive).
    rms : float
        Root-mean-square (weighted) residual ``sqrt(2 cost / nresiduals)``.

    Examples
    --------
    >>> omega = np.linspace(0.1, 5, 20)
    >>> model = lambda p, w: (p[0] / (1j * w + 1))[None, None, None, :]
    >>> fit, info = ltp.fit_htf(model, ltp.HTFData(model([3.0], omega), omega, 1.0), [1.0],
    ...                         return_info=True)
    >>> info.success, info.nresiduals, info.dof
    (True, 40, 39)
    """

    success: bool
    message: str
    cost: float
    nfev: int
    nresiduals: int
    dof: int
    rms: float


@dataclass(frozen=True)
class DelayEstimate:
    """Result of `estimate_delays` (seconds).

    Attributes
    ----------
    input_delay, output_delay : float or None
        τ_u (in ``[-T/2, T/2)``, as it is only defined modulo T) and τ_y;
        None when only G_0 was used.
    total_delay : float
        ``τ_u + τ_y``.
    std : ndarray
        Standard deviations of ``(τ_u, τ_y)``, or of the total alone.
    phase_rms : float
        Magnitude-weighted RMS phase error after compensation (rad).

    Examples
    --------
    >>> omega = np.linspace(0.5, 20, 40)
    >>> G = np.ones((1, 1, 1, 40)) / (1j * omega + 1)
    >>> d = ltp.estimate_delays(ltp.HTFData(G * np.exp(-0.1j * omega), omega, 1.0), G,
    ...                         harmonics=[0])
    >>> round(d.total_delay, 6), d.input_delay
    (0.1, None)
    """

    input_delay: float
    output_delay: float
    total_delay: float
    std: np.ndarray
    phase_rms: float


def _estimate_arrays(estimate, name="estimate"):
    """Return (omega, components, std or None, period) of an `HTFData`."""
    if not isinstance(estimate, HTFData):
        what = ("a model HTF (ltp.htf); evaluate it on a grid with HTFData"
                if isinstance(estimate, HTF) else type(estimate).__name__)
        raise ControlArgument(f"{name} must be an HTFData (e.g. from estimate_htf), "
                              f"got {what}")
    omega, comps = estimate.components()
    return omega, comps, estimate.std, estimate.period


def _select(omega, omega_limits, name="omega_limits"):
    if omega_limits is None:
        return np.ones(omega.size, bool)
    lim = real_array(omega_limits, name, ndim=1)
    if lim.size != 2 or lim[0] >= lim[1]:
        raise ValueError(f"{name} must be (wmin, wmax) with wmin < wmax, got {lim}")
    keep = (omega >= lim[0]) & (omega <= lim[1])
    if not np.any(keep):
        raise ValueError(f"{name} {lim.tolist()} contains no estimated frequency")
    return keep


def _harmonics(harmonics, K, name="harmonics"):
    if harmonics is None:
        return np.arange(-K, K + 1)
    ks = np.atleast_1d(np.asarray(harmonics))
    if ks.ndim != 1 or ks.size == 0 or ks.dtype.kind not in "iu":
        raise ControlArgument(f"{name} must be a non-empty sequence of integers")
    if np.any(np.abs(ks) > K):
        raise ValueError(f"{name} {ks.tolist()} exceed the estimate's K = {K}")
    return ks


def _model_components(model, params, omega, K, ks, shape):
    """Components k in `ks` of `model(params, omega)`: array or object with `components`."""
    out = model(params, omega)
    if hasattr(out, "components"):
        out = out.components(omega)
        out = out[1] if isinstance(out, tuple) else out
    out = np.asarray(out)
    if out.ndim != 4 or out.shape[0] % 2 != 1 or out.shape[1:] != shape:
        raise ControlDimension(f"model must return components of shape (2K'+1, "
                               f"{shape[0]}, {shape[1]}, {shape[2]}), got {out.shape}")
    kmod = out.shape[0] // 2
    if kmod < np.max(np.abs(ks)):
        raise ControlDimension(f"model returns K'={kmod} harmonics, fit needs "
                               f"{np.max(np.abs(ks))}")
    return out[ks + kmod]


def _model_harmonics(model, params, omega):
    """Number K' of harmonics that `model` returns."""
    out = model(params, omega[:1])
    if hasattr(out, "components"):
        out = out.components(omega[:1])
        out = out[1] if isinstance(out, tuple) else out
    return np.asarray(out).shape[0] // 2


def fit_htf(model, estimate, p0, *, harmonics=None, omega_limits=None,
            magnitude_only=False, weights=None, bounds=None, return_info=False):
    """Fit a parameterised model family to an estimated HTF.

    Minimises ``Σ_{k, ω} |w (G_k(jω; p) - Ĝ_k(jω))|²`` (complex components)
    or ``Σ |w (|G_k(jω; p)| - |Ĝ_k(jω)|)|²`` (``magnitude_only``) with
    `scipy.optimize.least_squares` (thesis §3.4.3 and §3.6.3).

    Parameters
    ----------
    model : callable
        ``model(params, omega)`` returning either an array of shape
        (2K'+1, ny, nu, len(omega)) with K' >= the harmonics fitted, or an
        object with a ``components(omega)`` method (e.g. an `HTF` built by
        `ltpcontrol.htf` from a parameterised system).
    estimate : HTFData
        Estimated HTF (e.g. from `estimate_htf`).
    p0 : array_like
        Initial parameters.
    harmonics : sequence of int, optional
        Components to fit (default all of the estimate's).
    omega_limits : (float, float), optional
        Frequency range of the fit (rad/s).
    magnitude_only : bool, optional
        Fit magnitudes only (insensitive to input/output delays).
    weights : None, 'std' or array_like, optional
        Residual weights: uniform (default), ``1/std`` of the estimate, or
        an array broadcastable to (nharm, ny, nu, F).
    bounds : (array_like, array_like), optional
        Lower and upper parameter bounds.
    return_info : bool, optional
        Also return the diagnostics of the optimisation (default False).

    Returns
    -------
    fit : HTFFit
        The fitted model: parameters, their covariance and standard
        deviations, and the model's components on the estimate's grid.
    info : HTFFitInfo
        Only with ``return_info=True``: success flag, message, cost, number
        of model evaluations and residual degrees of freedom.

    Examples
    --------
    Recover the pole ``a`` of ``G_0 = 1/(jω - a)`` (a periodic system whose
    only nonzero component is G_0):

    >>> omega = np.linspace(0.1, 5, 40)
    >>> model = lambda p, w: (1 / (1j * w - p[0]))[None, None, None, :]
    >>> est = ltp.HTFData(model([-2.0], omega), omega, period=1.0)
    >>> fit = ltp.fit_htf(model, est, [-1.0])
    >>> np.round(fit.params, 6).tolist()
    [-2.0]

    With ``return_info=True`` the optimiser's diagnostics come along:

    >>> fit, info = ltp.fit_htf(model, est, [-1.0], return_info=True)
    >>> info.success, bool(info.rms < 1e-8)
    (True, True)
    """
    if not callable(model):
        raise ControlArgument("model must be callable: model(params, omega)")
    omega, comps, std, _ = _estimate_arrays(estimate)
    K = comps.shape[0] // 2
    ks = _harmonics(harmonics, K)
    keep = _select(omega, omega_limits)
    w_fit = omega[keep]
    target = comps[ks + K][..., keep]
    p0 = real_array(p0, "p0", ndim=1)
    if p0.size == 0:
        raise ValueError("p0 must hold at least one initial parameter, got an empty array")
    if isinstance(weights, str):
        if weights != 'std':
            raise ValueError(f"weights must be None, 'std' or an array, got {weights!r}")
        if std is None:
            raise ValueError("weights='std' needs an estimate with std")
        wts = 1.0 / std[ks + K][..., keep]
    elif weights is None:
        wts = np.ones(target.shape)
    else:
        wts = real_array(weights, "weights")
        try:
            wts = np.broadcast_to(wts, target.shape)
        except ValueError:
            raise ControlDimension(
                f"weights of shape {wts.shape} cannot be broadcast to the fitted "
                f"components' shape (nharm, ny, nu, F) = {target.shape}") from None
    if bounds is None:
        bounds = (-np.inf, np.inf)
    shape = target.shape[1:]

    # components the data leave undetermined (NaN) carry no residual
    known = ~np.isnan(target)
    if not known.any():
        raise ValueError("estimate has no identified component in the fitted range")
    target = np.where(known, target, 0)
    wts = np.where(known, np.nan_to_num(wts), 0)

    def residual(p):
        g = _model_components(model, p, w_fit, K, ks, shape)
        if magnitude_only:
            return (wts * (np.abs(g) - np.abs(target))).ravel()
        r = (wts * (g - target)).ravel()
        return np.concatenate([r.real, r.imag])

    res = scipy.optimize.least_squares(residual, p0, bounds=bounds, x_scale='jac')
    nres, npar = res.fun.size, p0.size
    jtj = res.jac.T @ res.jac
    if nres > npar:
        # cov = s² (JᵀJ)⁻¹, s² = |r|² / (m - p)
        cov = np.linalg.pinv(jtj) * (2 * res.cost / (nres - npar))
    else:
        cov = np.full((npar, npar), np.nan)
    # fitted model on the estimate's grid: the harmonics -K..K that the model
    # provides (a model of fewer harmonics leaves the others at zero)
    full = _model_components(model, res.x, omega, K, ks, comps.shape[1:3] + (omega.size,))
    fitted = np.zeros(comps.shape, complex)
    fitted[ks + K] = full
    provided = _model_harmonics(model, res.x, omega)
    extra = np.setdiff1d(np.arange(-min(K, provided), min(K, provided) + 1), ks)
    if extra.size:
        fitted[extra + K] = _model_components(model, res.x, omega, K, extra,
                                              comps.shape[1:3] + (omega.size,))
    fit = HTFFit(params=res.x, cov=cov, std=np.sqrt(np.abs(np.diag(cov))),
                 components=fitted, omega=omega, cost=float(res.cost),
                 success=bool(res.success), message=str(res.message), nfev=int(res.nfev))
    if not return_info:
        return fit
    info = HTFFitInfo(success=fit.success, message=fit.message, cost=fit.cost, nfev=fit.nfev,
                      nresiduals=int(nres), dof=int(nres - npar),
                      rms=float(np.sqrt(2 * res.cost / nres)))
    return fit, info


def estimate_delays(estimate, reference, *, harmonics=(-1, 0, 1), omega_limits=None,
                    max_delay=None, input=0, output=0):
    """Estimate input and measurement delays from HTF phases (thesis §3.6).

    Fits ``∠Ĥ_k(jω) = ∠G_k(jω) - (ω - kω_p) τ_u - ω τ_y`` (eq. 3.47) with
    the magnitude weighting of eq. 3.50, i.e. minimises
    ``Σ_k Σ_ω |Ĥ_k|² |e^{j(∠Ĥ_k - ∠G_k)} - e^{-j[(ω - kω_p)τ_u + ωτ_y]}|²``,
    which equals ``Σ (|Ĥ_k| ∠G_err)²`` for small errors and is free of
    phase wrapping.  A grid search over the total delay and over τ_u in
    one period precedes a local least-squares refinement.  τ_u is defined
    modulo T only and is returned in ``[-T/2, T/2)``; τ_y follows from the
    total delay.

    Parameters
    ----------
    estimate : HTFData
        Estimated HTF of the delayed system (e.g. from `estimate_htf`).
    reference : HTF or array_like
        Undelayed model (e.g. from a magnitude-only `fit_htf`): an HTF that
        can be evaluated on the estimate's grid, or an array of components
        with the estimate's shape.
    harmonics : sequence of int, optional
        Components used (default (-1, 0, 1)).  ``(0,)`` gives only the total
        delay, as for an LTI system.
    omega_limits : (float, float), optional
        Frequency range used (rad/s).
    max_delay : float, optional
        Largest total delay searched (s); default the period T.  The search
        grid is spaced ``2π / (8 max ω)``, and it may hold at most 2**18
        points; a larger `max_delay` raises ValueError.
    input, output : int, optional
        Channel analysed (default 0, 0).

    Returns
    -------
    DelayEstimate

    Examples
    --------
    >>> omega = np.linspace(0.5, 30, 60)
    >>> k = np.arange(-1, 2)[:, None, None, None]
    >>> G = np.ones((3, 1, 1, 60)) / (1j * omega + 2) * (1 + 0.5 * k)
    >>> tu, ty, wp = 0.04, 0.05, 2 * np.pi
    >>> Hd = G * np.exp(-1j * ((omega - k * wp) * tu + omega * ty))
    >>> d = ltp.estimate_delays(ltp.HTFData(Hd, omega, 1.0), G)
    >>> round(d.input_delay, 6), round(d.output_delay, 6)
    (0.04, 0.05)
    """
    w, ks, weight, obs, period = _delay_data(estimate, reference, harmonics,
                                             omega_limits, input, output)
    tmax = period if max_delay is None else float(real_array(max_delay, "max_delay", ndim=0))
    if tmax <= 0:
        raise ValueError(f"max_delay must be positive, got {tmax}")
    separable = bool(np.any(ks != 0))
    x0 = _initial_delays(w, ks, weight ** 2 * obs, _delay_grid(w, tmax), period, separable)
    wp = 2 * np.pi / period

    def phase(x):
        # (ω - kω_p) τ_u + ω τ_y  (eq. 3.47)
        tin, tout = (x[0], x[1]) if separable else (0.0, x[0])
        return (w[None, :] - ks[:, None] * wp) * tin + w[None, :] * tout

    def residual(x):
        r = (weight * (obs - np.exp(-1j * phase(x)))).ravel()
        return np.concatenate([r.real, r.imag])

    res = scipy.optimize.least_squares(residual, x0, x_scale=max(tmax, 1e-3) * 1e-2)
    return _delay_result(res, weight, obs, phase(res.x), period, separable)


def _delay_data(estimate, reference, harmonics, omega_limits, input, output):
    """Frequencies, harmonics, weights ``|Ĥ_k|`` and ``e^{j(∠Ĥ_k - ∠G_k)}`` used."""
    omega, comps, _, period = _estimate_arrays(estimate)
    K = comps.shape[0] // 2
    ks = _harmonics(harmonics, K)
    ny, nu = comps.shape[1:3]
    if not (isinstance(input, (int, np.integer)) and 0 <= input < nu):
        raise ValueError(f"input must be an index in [0, {nu}), got {input!r}")
    if not (isinstance(output, (int, np.integer)) and 0 <= output < ny):
        raise ValueError(f"output must be an index in [0, {ny}), got {output!r}")
    keep = _select(omega, omega_limits)
    if isinstance(reference, HTF):
        _, ref = reference.components(omega)
    else:
        ref = real_array(reference, "reference", allow_complex=True)
        if ref.shape != comps.shape:
            raise ControlDimension(f"reference must have shape {comps.shape}, "
                                   f"got {ref.shape}")
    meas = comps[ks + K, output, input][:, keep]
    model = np.asarray(ref)[ks + K, output, input][:, keep]
    # components the data leave undetermined (NaN) get zero weight
    known = ~np.isnan(meas)
    meas = np.where(known, meas, 0)
    model = np.where(known, model, 1)
    if np.any(model == 0):
        raise ValueError("reference components vanish on the grid; restrict "
                         "omega_limits or harmonics")
    # |Ĥ_k| (eq. 3.50) and e^{j(∠Ĥ_k - ∠G_k)}
    return omega[keep], ks, np.abs(meas), np.exp(1j * np.angle(meas * np.conj(model))), period


def _delay_grid(w, tmax):
    """Total delays searched: the objective oscillates on the scale 2π/max(ω),
    sampled 8 times per oscillation on a grid of bounded size."""
    spacing = 2 * np.pi / (8 * np.max(w))
    if tmax / spacing > _MAX_DELAY_GRID - 2:
        raise ValueError(
            f"max_delay={tmax:.6g} s is too large for this frequency grid: the delay "
            f"search would need {tmax / spacing:.3g} grid points (limit {_MAX_DELAY_GRID}); "
            f"max_delay must be at most {(_MAX_DELAY_GRID - 2) * spacing:.6g} s")
    return np.linspace(0, tmax, int(np.ceil(tmax / spacing)) + 2)


def _initial_delays(w, ks, coef, tsums, period, separable):
    """Grid search: total delay τ_s, then τ_u over one period (τ_u, τ_y or τ_s)."""
    # S_k(τ_s) = Σ_ω |Ĥ_k|² e^{j(∠Ĥ_k - ∠G_k + ωτ_s)} ≈ A_k e^{jkω_p τ_u} at the true τ_s
    sums = np.empty((ks.size, tsums.size), complex)
    chunk = max(1, _DELAY_CHUNK // w.size)         # bound the F x chunk work array
    for start in range(0, tsums.size, chunk):
        stop = start + chunk
        sums[:, start:stop] = coef @ np.exp(1j * np.outer(w, tsums[start:stop]))
    best = int(np.argmax(np.abs(sums).sum(axis=0)))
    if not separable:
        return np.array([tsums[best]])
    # τ_u maximising Re Σ_k S_k(τ_s) e^{-jkω_p τ_u} over [0, T)
    tins = np.linspace(0, period, 256, endpoint=False)
    score = np.real(np.exp(-2j * np.pi / period * np.outer(tins, ks)) @ sums[:, best])
    tin0 = tins[np.argmax(score)]
    return np.array([tin0, tsums[best] - tin0])


def _delay_result(res, weight, obs, phase, period, separable):
    """`DelayEstimate` from the least-squares refinement."""
    nres, npar = res.fun.size, res.x.size
    cov = np.linalg.pinv(res.jac.T @ res.jac) * (2 * res.cost / max(nres - npar, 1))
    std = np.sqrt(np.abs(np.diag(cov)))
    err = np.angle(obs * np.exp(1j * phase))
    rms = float(np.sqrt(np.sum((weight * err) ** 2) / np.sum(weight ** 2)))
    if not separable:
        return DelayEstimate(None, None, float(res.x[0]), std, rms)
    # representative of τ_u modulo T in [-T/2, T/2)
    tin = float(np.mod(res.x[0] + period / 2, period) - period / 2)
    tout = float(res.x[0] + res.x[1] - tin)
    return DelayEstimate(tin, tout, tin + tout, std, rms)
