"""Identification and cross-validated assessment of SLIP predictors.

Implements thesis Sections 2.4-2.5 on processed stride data
(:class:`slip_data.StrideSet`):

* body/leg masses, vertical flight damping and per-spring leg parameters
  from vertical hops, cost (2.25), with the measured total mass
  ``m_b + m_l`` held fixed (stance dynamics depend on ``k / m_b`` and
  ``d / m_b`` only, so the split needs that one scale);
* horizontal flight damping by linear least squares (2.26)-(2.28);
* prediction errors (2.29)-(2.32) and the leg-parameter fit on the cost
  (2.33) with ``scipy.optimize.least_squares(method="trf")``;
* k-fold cross-validation (Table 2.4) and the relative touchdown-angle
  study (2.34)-(2.35), Fig. 2.6.
"""

from typing import NamedTuple

import numpy as np
from scipy.optimize import least_squares

try:                    # imported as the package ``examples`` (tests)
    from .slip_model import METHODS, neutral_touchdown_angle, predict_stride
except ImportError:     # run from this folder (gallery scripts)
    from slip_model import METHODS, neutral_touchdown_angle, predict_stride

__all__ = ["identify_vertical", "identify_flight_damping", "prediction_errors",
           "fit_leg", "CVResult", "cross_validate", "format_table",
           "relative_angle_study"]

_LOSSLESS = ("SLIP", "Geyer")
_FAILED = 100.0   # percentage error charged to a stride the model cannot complete


def _relative(truth, estimate):
    """``100 ||truth - estimate|| / ||truth||`` along the last axis."""
    return 100 * np.linalg.norm(truth - estimate, axis=-1) / np.linalg.norm(truth, axis=-1)


def identify_vertical(hops, total_mass, base, manual_k, iterations=None):
    """Masses, vertical flight damping and leg parameters from vertical hops.

    Minimises ``sum C_v^2`` over all hops of all springs with
    ``C_v = ||[z_a, z_b] - [z_a_hat, z_b_hat]|| / ||[z_a, z_b]||`` (2.25).
    Vertical stance is linear, so the AAS map is exact here.

    Parameters
    ----------
    hops : dict of str to StrideSet
        Vertical experiments of each spring.
    total_mass : float
        Measured ``m_b + m_l``, kg.
    base : SLIPParams
        Supplies ``rho0``, ``g`` and ``d_h`` (irrelevant vertically).
    manual_k : dict of str to float
        Initial stiffness per spring (e.g. a manual measurement), N/m.

    Returns
    -------
    dict
        ``m_b, m_l, d_v`` and ``springs`` mapping spring to ``(k, d)``.
    """
    if total_mass <= 0:
        raise ValueError(f"total_mass must be positive, got {total_mass}")
    names = list(hops)
    missing = [s for s in names if s not in manual_k]
    if missing:
        raise ValueError(f"manual_k lacks springs {missing}")
    n_s = len(names)
    scale = np.r_[0.1, 0.1, [manual_k[s] for s in names], np.full(n_s, 10.0)]

    def unpack(x):
        x = x * scale
        m_l, d_v = x[0], x[1]
        return m_l, d_v, x[2:2 + n_s], x[2 + n_s:]

    def residuals(x):
        m_l, d_v, ks, ds = unpack(x)
        res = []
        for s, k, d in zip(names, ks, ds):
            data = hops[s]
            p = base.replace(m_b=total_mass - m_l, m_l=m_l, d_v=d_v, k=k, d=d)
            pred = predict_stride(data.apex0, data.theta_td, p, method="AAS")
            truth = np.column_stack([data.apex1[:, 2], data.bottom[:, 2]])
            est = np.column_stack([pred.apex.z, pred.bottom.z])
            r = (est - truth) / np.linalg.norm(truth, axis=1, keepdims=True)
            res.append(np.nan_to_num(r, nan=1.0).ravel())
        return np.concatenate(res)

    x0 = np.r_[1.0, 0.0, np.ones(n_s), np.ones(n_s) * 0.5]
    lower = np.r_[0.0, 0.0, np.full(n_s, 0.2), np.zeros(n_s)]
    upper = np.r_[total_mass / scale[0] * 0.5, 50.0, np.full(n_s, 5.0), np.full(n_s, 10.0)]
    sol = least_squares(residuals, x0, bounds=(lower, upper), method="trf",
                        x_scale=1.0, diff_step=1e-6, max_nfev=iterations)
    m_l, d_v, ks, ds = unpack(sol.x)
    return {"m_b": total_mass - m_l, "m_l": m_l, "d_v": d_v,
            "springs": {s: (k, d) for s, k, d in zip(names, ks, ds)}}


def identify_flight_damping(stride_sets, margin=0.012):
    """Horizontal flight damping from the descent phases, eqs. (2.26)-(2.28).

    The printed first-order model ``ydot = ydot_0 - d_h t`` (2.26) drops the
    factor ``ydot_0`` of ``ydot_0 e^{-d_h t}`` (2.7), which differs between
    experiments; its logarithm ``log ydot = log ydot_0 - d_h t`` keeps the
    regressor structure of (2.27) (one intercept per experiment, one common
    slope) and is exact for (2.7).

    Parameters
    ----------
    stride_sets : sequence of StrideSet
    margin : float
        Samples closer than this to touchdown are left out (s).

    Returns
    -------
    d_h : float
        Horizontal flight damping, 1/s.
    vy0 : list of ndarray
        Fitted apex horizontal velocity of every experiment, per set.
    """
    columns, times, values, counts = [], [], [], []
    j = 0
    for data in stride_sets:
        counts.append(len(data.strides))
        for s in data.strides:
            keep = (s.t >= 0) & (s.t <= s.touchdown.t - margin) & (s.vy > 0)
            times.append(s.t[keep])
            values.append(np.log(s.vy[keep]))
            columns.append(np.full(keep.sum(), j))
            j += 1
    col, t, b = np.concatenate(columns), np.concatenate(times), np.concatenate(values)
    A = np.zeros((t.size, j + 1))               # (2.27): [one-hot | t]
    A[np.arange(t.size), col] = 1.0
    A[:, -1] = t
    x = np.linalg.lstsq(A, b, rcond=None)[0]    # (2.28)
    vy0 = np.exp(x[:-1])
    return -x[-1], np.split(vy0, np.cumsum(counts)[:-1])


def prediction_errors(data, params, method, vy0=None, index=None):
    """Percentage stride prediction errors, eqs. (2.29)-(2.32).

    Parameters
    ----------
    data : StrideSet
    params : SLIPParams
    method : {"SLIPD", "AAS", "SLIP", "Geyer"}
    vy0 : ndarray, optional
        Apex horizontal velocities to start from (default: from the data).
    index : array_like of int, optional
        Subset of experiments.

    Returns
    -------
    ndarray, shape (n, 4)
        Columns ``E_ap, E_av, E_at, E_bp``; NaN where the prediction fails.
    """
    index = np.arange(len(data.theta_td)) if index is None else np.asarray(index)
    apex0 = data.apex0[index].copy()
    if vy0 is not None:
        apex0[:, 1] = np.asarray(vy0)[index]
    pred = predict_stride(apex0, data.theta_td[index], params, method=method)
    a1, b = data.apex1[index], data.bottom[index]
    return np.column_stack([
        _relative(a1[:, 1:3], np.column_stack([pred.apex.y, pred.apex.z])),      # (2.29)
        _relative(a1[:, 3:4], pred.apex.vy[:, None]),                           # (2.30)
        _relative(a1[:, 0:1], pred.apex.t[:, None]),                            # (2.31)
        _relative(b[:, 1:3], np.column_stack([pred.bottom.y, pred.bottom.z]))])  # (2.32)


def fit_leg(data, params, method, vy0=None, index=None, start=None, max_nfev=60,
            return_errors=False):
    """Fit leg stiffness and damping on the cost (2.33).

    ``C = sqrt(C_ap^2 + C_av^2 + C_at^2 + C_bp^2)`` with each ``C`` the mean
    of the corresponding error over the experiments, minimised by the
    trust-region-reflective method.  Lossless methods fit ``k`` only.

    Parameters
    ----------
    data : StrideSet
    params : SLIPParams
        Supplies all fixed parameters and the starting ``k, d``.
    method : {"SLIPD", "AAS", "SLIP", "Geyer"}
    vy0, index : optional
        As in :func:`prediction_errors`.
    start : tuple of float, optional
        Starting ``(k, d)``, default ``(params.k, params.d)``.
    max_nfev : int, optional
        Evaluation budget of the optimiser.  The cost is a mean of norms,
        so it has kinks; loose tolerances (1e-6) stop the zig-zag near them.
    return_errors : bool, optional
        Also return the errors of :func:`prediction_errors` at the fit.

    Returns
    -------
    k, d : float
        ``d`` is 0 for lossless methods.
    cost : float
        Final value of ``C``.
    errors : ndarray, shape (n, 4)
        With `return_errors`: the errors of the fitted ``k, d`` (None if the
        optimiser did not evaluate its result).
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    scale = np.array([params.k, max(params.d, 1e-3)])
    start = np.array(start if start is not None else (params.k, params.d)) / scale
    lossless = method in _LOSSLESS

    evaluated = {}      # the errors at every point the optimiser asked for

    def residuals(x):
        # the four mean errors whose norm is C of (2.33)
        p = params.replace(k=x[0] * scale[0], d=0.0 if lossless else x[1] * scale[1])
        err = prediction_errors(data, p, method, vy0, index)
        evaluated[x.tobytes()] = err
        return np.mean(np.where(np.isnan(err), _FAILED, err), axis=0)

    x0 = start[:1] if lossless else start
    lower, upper = [0.2, 0.0][:x0.size], [5.0, 10.0][:x0.size]
    x0 = np.clip(x0, np.array(lower) + 1e-9, upper)
    sol = least_squares(residuals, x0,
                        bounds=(lower, upper), method="trf", diff_step=1e-4,
                        x_scale=1.0, ftol=1e-6, xtol=1e-6, max_nfev=max_nfev)
    k = sol.x[0] * scale[0]
    d = 0.0 if lossless else sol.x[1] * scale[1]
    if return_errors:
        # the optimiser's result is a point it evaluated: the errors there, as
        # `prediction_errors` gives them for the fitted k, d
        return k, d, float(np.sqrt(2 * sol.cost)), evaluated.get(sol.x.tobytes())
    return k, d, float(np.sqrt(2 * sol.cost))


class CVResult(NamedTuple):
    """Cross-validation of one method on one spring (a Table 2.4 block)."""

    method: str
    spring: str
    test: np.ndarray        # (folds, 3) fold means of E_ap, E_av, E_at
    train: np.ndarray       # (folds, 3)
    k: np.ndarray           # (folds,)
    d: np.ndarray           # (folds,)
    stride_test: np.ndarray  # (n, 4) every experiment's error when held out


def cross_validate(data, params, method, folds=30, vy0=None, seed=0, fold_nfev=8):
    """k-fold cross-validation of leg identification and prediction.

    The parameters are first fitted on all experiments (started from
    ``params.k, params.d``); each fold is then refitted on its training
    experiments from that fit (at most `fold_nfev` optimiser iterations) and
    evaluated on its held-out experiments.

    Returns
    -------
    CVResult
    """
    n = len(data.theta_td)
    if not 2 <= folds <= n:
        raise ValueError(f"folds must lie in [2, {n}], got {folds}")
    k_all, d_all, _ = fit_leg(data, params, method, vy0)
    order = np.random.default_rng(seed).permutation(n)
    test, train, ks, ds = [], [], [], []
    stride_test = np.full((n, 4), np.nan)
    for held in np.array_split(order, folds):
        kept = np.setdiff1d(order, held)
        k, d, _, e_train = fit_leg(data, params, method, vy0, kept, start=(k_all, d_all),
                                   max_nfev=fold_nfev, return_errors=True)
        fitted = params.replace(k=k, d=d)
        e_test = prediction_errors(data, fitted, method, vy0, held)
        if e_train is None:
            e_train = prediction_errors(data, fitted, method, vy0, kept)
        stride_test[held] = e_test
        test.append(np.nanmean(e_test[:, :3], axis=0))
        train.append(np.nanmean(e_train[:, :3], axis=0))
        ks.append(k)
        ds.append(d)
    return CVResult(method, data.spring, np.array(test), np.array(train),
                    np.array(ks), np.array(ds), stride_test)


def format_table(results):
    """Text rendering of Table 2.4 from a list of :class:`CVResult`.

    Entries are ``mean +- std`` over the folds.
    """
    head = (f"{'spring':<7} {'method':<6} | {'test E_ap':>12} {'test E_av':>12} "
            f"{'test E_at':>12} | {'train E_ap':>12} {'train E_av':>12} "
            f"{'train E_at':>12} | {'k (N/m)':>14} {'d (Ns/m)':>12}")
    lines = [head, "-" * len(head)]

    def pm(x, digits=2):
        return f"{np.mean(x):.{digits}f}±{np.std(x):.{digits}f}"

    for r in results:
        test = " ".join(f"{pm(r.test[:, i]):>12}" for i in range(3))
        train = " ".join(f"{pm(r.train[:, i]):>12}" for i in range(3))
        d = pm(r.d) if r.method not in _LOSSLESS else "–"
        lines.append(f"{r.spring:<7} {r.method:<6} | {test} | {train} | "
                     f"{pm(r.k, 1):>14} {d:>12}")
    return "\n".join(lines)


def relative_angle_study(data, params, errors, vy0=None, bins=7, method="AAS"):
    """Prediction error against the relative touchdown angle, (2.34)-(2.35).

    Parameters
    ----------
    data : StrideSet
    params : SLIPParams
        Identified model used to compute the neutral angles.
    errors : ndarray, shape (n,)
        Per-experiment apex position errors (e.g. held-out ``E_ap``).
    vy0 : ndarray, optional
        Apex horizontal velocities (default: from the data).
    bins : int
        Number of equal-width bins of the relative angle.
    method : str
        Predictor defining the neutral angle.

    Returns
    -------
    dict
        ``relative`` (n,) angles in rad (NaN where no neutral angle
        exists; those experiments are left out); per bin ``centre``, ``mean``,
        ``std``, ``count``; ``quadratic`` coefficients of a fit to the bin
        means (highest power first).
    """
    apex0 = data.apex0.copy()
    if vy0 is not None:
        apex0[:, 1] = vy0
    neutral = neutral_touchdown_angle(apex0, params, method)     # (2.35)
    # no neutral angle exists when no touchdown angle keeps the speed
    vy_next = predict_stride(apex0, neutral, params, method).apex.vy
    exists = np.abs(vy_next - apex0[:, 1]) <= 1e-3 * np.abs(apex0[:, 1])
    relative = np.where(exists, data.theta_td - neutral, np.nan)  # (2.34)
    edges = np.linspace(np.nanmin(relative), np.nanmax(relative), bins + 1)
    which = np.where(exists, np.clip(np.digitize(relative, edges) - 1, 0, bins - 1), bins)
    count = np.bincount(which, minlength=bins + 1)[:bins]
    mean = np.array([np.mean(errors[which == i]) if count[i] else np.nan
                     for i in range(bins)])
    std = np.array([np.std(errors[which == i]) if count[i] else np.nan
                    for i in range(bins)])
    centre = 0.5 * (edges[1:] + edges[:-1])
    ok = count >= 2
    quadratic = np.polyfit(centre[ok], mean[ok], 2)
    return {"relative": relative, "centre": centre, "mean": mean, "std": std,
            "count": count, "quadratic": quadratic}
