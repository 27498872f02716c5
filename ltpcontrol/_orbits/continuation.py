"""Natural-parameter continuation of periodic orbits and their bifurcations.

`orbit_continuation` follows an orbit ``x̄(p)`` while one plant parameter p
steps through given values.  Each orbit is computed by the same shooting
as the start orbit (`limit_cycle` for autonomous plants, `periodic_orbit`
for forced ones), started from the secant predictor through the two
previous orbits; a step that fails is halved.

Bifurcations are read from the stability multipliers ``μ_i`` (the phase
multiplier of an autonomous orbit left out) through test functions that
change sign where a multiplier leaves the unit circle:

* ``∏ (μ_i − 1)``: a real multiplier crosses +1 (fold or branch point);
* ``∏ (μ_i + 1)``: a real multiplier crosses −1 (period doubling);
* ``∏ (|μ_i|² − 1)`` over complex pairs: Neimark–Sacker (torus).

A sign change between two branch points is located by Brent's method on
the test function.  At a fold the branch turns back, so natural-parameter
continuation cannot pass it: the steps fail while a multiplier tends to
+1 like ``1 + c √(p − p_fold)``.  The fold is then located by extrapolating
``(μ − 1)²``, linear in p near the fold, from the last branch points.
"""

import numbers
from dataclasses import dataclass
from typing import NamedTuple

import control as ct
import matplotlib.pyplot as plt
import numpy as np
from control.exception import ControlArgument
from scipy.optimize import brentq
from tqdm.auto import tqdm

from .autonomous import limit_cycle
from .orbits import PeriodicOrbit, periodic_orbit
from .._core.validation import check_positive_int, real_array

__all__ = ['Bifurcation', 'OrbitBranch', 'orbit_continuation']

_KINDS = {'fold': 'fold', 'period-doubling': 'period doubling', 'torus': 'Neimark-Sacker'}


class Bifurcation(NamedTuple):
    """A bifurcation found along a branch.

    Attributes
    ----------
    kind : str
        ``'fold'`` (a real multiplier crosses or reaches +1),
        ``'period-doubling'`` (crosses −1) or ``'torus'`` (a complex pair
        crosses the unit circle).
    value : float
        Parameter value.
    multiplier : complex
        The critical multiplier at `value`.
    orbit : PeriodicOrbit or None
        The orbit at `value` (None for a fold located by extrapolation).

    Examples
    --------
    Returned in `OrbitBranch.bifurcations`; a named tuple:

    >>> b = ltp.Bifurcation('period-doubling', 2.8324, -1.0 + 0j, None)
    >>> b.kind, b.value
    ('period-doubling', 2.8324)
    """

    kind: str
    value: float
    multiplier: complex
    orbit: object


@dataclass(repr=False, eq=False)
class OrbitBranch:
    """A branch of periodic orbits computed by `orbit_continuation`.

    Returned by `orbit_continuation`; not meant to be built directly.

    Attributes
    ----------
    param : str
        The continuation parameter.
    values : ndarray
        Parameter values of the branch points (including points inserted by
        step halving).
    orbits : list of PeriodicOrbit
        The orbits.
    periods : ndarray
        Their periods.
    multipliers : ndarray of complex, shape (npoints, m)
        Stability multipliers of each orbit, sorted by decreasing modulus.
    stable : ndarray of bool
        Stability of each orbit.
    bifurcations : list of Bifurcation
        Bifurcations found, in branch order.
    message : str
        How the continuation ended.

    Examples
    --------
    >>> def f(t, x, u, p):
    ...     r2 = x[0] ** 2 + x[1] ** 2
    ...     return [p['a'] * x[0] * (1 - r2) - x[1], p['a'] * x[1] * (1 - r2) + x[0]]
    >>> sys = ct.nlsys(f, None, states=2, inputs=0, params={'a': 0.2})
    >>> branch = ltp.orbit_continuation(ltp.limit_cycle(sys, 6.0, [1.0, 0.0]), 'a', [0.2, 0.1])
    >>> branch.values, np.round(branch.periods, 6), branch.message
    (array([0.2, 0.1]), array([6.283185, 6.283185]), 'completed')
    """

    param: str
    values: np.ndarray
    orbits: list
    periods: np.ndarray
    multipliers: np.ndarray
    stable: np.ndarray
    bifurcations: list
    message: str

    @classmethod
    def _from_orbits(cls, param, orbits, bifurcations, message):
        return cls(param, np.array([o.params[param] for o in orbits], float), orbits,
                   np.array([o.period for o in orbits]),
                   np.array([_sorted(o.stability_multipliers) for o in orbits]),
                   np.array([o.is_stable for o in orbits]), bifurcations, message)

    def __repr__(self):
        bif = ', '.join(f'{b.kind} at {self.param}={b.value:.6g}' for b in self.bifurcations)
        return (f"<OrbitBranch {self.param} in [{self.values.min():g}, {self.values.max():g}], "
                f"{len(self.orbits)} orbits, bifurcations: [{bif}]>")

    def plot(self, title=None):
        """Multipliers and period along the branch.

        Top: real parts of the stability multipliers (filled markers for
        real multipliers, open for complex pairs) with the stability limits
        ±1; bottom: the period.  Bifurcations are marked by vertical lines.

        Returns
        -------
        control.ControlPlot

        Examples
        --------
        >>> def f(t, x, u, p):
        ...     r2 = x[0] ** 2 + x[1] ** 2
        ...     return [p['a'] * x[0] * (1 - r2) - x[1], p['a'] * x[1] * (1 - r2) + x[0]]
        >>> sys = ct.nlsys(f, None, states=2, inputs=0, params={'a': 0.2})
        >>> orbit = ltp.limit_cycle(sys, 6.0, [1.0, 0.0])
        >>> branch = ltp.orbit_continuation(orbit, 'a', [0.2, 0.1])
        >>> cplt = branch.plot()
        >>> cplt.axes.shape
        (2, 1)
        """
        fig, (ax_mu, ax_T) = plt.subplots(2, 1, sharex=True)
        lines = np.empty((2, 1), dtype=object)
        mu = self.multipliers
        real = np.abs(mu.imag) <= 1e-9 * np.maximum(1, np.abs(mu))
        mu_lines = []
        for j in range(mu.shape[1]):
            mu_lines += ax_mu.plot(self.values[real[:, j]], mu[real[:, j], j].real, 'o', ms=4,
                                   color=f'C{j}')
            mu_lines += ax_mu.plot(self.values[~real[:, j]], mu[~real[:, j], j].real, 'o',
                                   ms=4, mfc='none', color=f'C{j}')
        for level in (1, -1):
            ax_mu.axhline(level, color='k', lw=0.8, ls='--')
        lines[0, 0] = mu_lines
        lines[1, 0] = ax_T.plot(self.values, self.periods, '.-')
        for b in self.bifurcations:
            for ax in (ax_mu, ax_T):
                ax.axvline(b.value, color='C3', lw=1)
            ax_mu.text(b.value, 0.5, f" {_KINDS[b.kind]}, {self.param} = {b.value:.6g}",
                       transform=ax_mu.get_xaxis_transform(), color='C3', fontsize=8,
                       rotation=90, va='center', ha='right')
        ax_mu.set_ylabel("Re μ (stability multipliers)")
        ax_T.set_ylabel("period")
        ax_T.ticklabel_format(axis='y', useOffset=False)
        if np.ptp(self.periods) <= 1e-6 * np.mean(self.periods):
            ax_T.set_ylim(np.mean(self.periods) * np.array([0.99, 1.01]))
        ax_T.set_xlabel(self.param)
        fig.suptitle(title or f"Orbit branch in {self.param}")
        return ct.ControlPlot(lines, np.array([[ax_mu], [ax_T]]), fig)


def _sorted(mu):
    return np.asarray(mu, complex)[np.argsort(-np.abs(mu), kind='stable')]


def _tests(mu):
    """Test functions (fold, period doubling, torus) of the stability multipliers."""
    mu = np.asarray(mu, complex)
    pairs = mu[mu.imag > 1e-9 * np.maximum(1, np.abs(mu))]
    return {'fold': float(np.prod(mu - 1).real), 'period-doubling': float(np.prod(mu + 1).real),
            'torus': float(np.prod(np.abs(pairs) ** 2 - 1))}


def _critical(kind, mu):
    target = {'fold': 1.0, 'period-doubling': -1.0}.get(kind)
    if target is None:
        return complex(mu[np.argmin(np.abs(np.abs(mu) - 1))])
    return complex(mu[np.argmin(np.abs(mu - target))])


def orbit_continuation(orbit, param, values, *, locate_tol=1e-8, max_halvings=10,
                       progress=False, **kwargs):
    """Follow a periodic orbit as one plant parameter changes.

    Natural-parameter continuation: the orbit is recomputed at each value
    of `values` by the shooting method that produced `orbit` (`limit_cycle`
    or `periodic_orbit`, with the same section, input and parameters),
    started from the secant predictor; failed steps are halved (up to
    `max_halvings` times below the spacing of `values`), after which the
    branch ends.  Folds, period
    doublings and Neimark–Sacker bifurcations are detected from the
    stability multipliers and located (see the module notes).

    Parameters
    ----------
    orbit : PeriodicOrbit
        A start orbit near the first value, from `limit_cycle` or
        `periodic_orbit`.
    param : str
        Name of a plant parameter (a key of ``orbit.params``).
    values : array_like
        Strictly monotone parameter values of the branch points.
    locate_tol : float, optional
        Tolerance on the parameter of a located bifurcation (1e-8).
    max_halvings : int, optional
        The smallest step is the spacing of `values` halved this many times
        (10); the branch ends when it fails.  Steps double again after
        each success.
    progress : bool, optional
        Show a progress bar (default False).
    **kwargs
        Passed to the shooting function (``tol``, ``max_iter``, ``rtol``,
        ``atol``, ``method``, ``npoints``, ...).

    Returns
    -------
    OrbitBranch

    Raises
    ------
    RuntimeError
        If no orbit is found at the first value.

    Examples
    --------
    The cycle ``r = 1`` of ``ṙ = a r (1 − r²), θ̇ = 1`` has the stability
    multiplier ``e^{−4πa}``:

    >>> def f(t, x, u, p):
    ...     r2 = x[0] ** 2 + x[1] ** 2
    ...     return [p['a'] * x[0] * (1 - r2) - x[1], p['a'] * x[1] * (1 - r2) + x[0]]
    >>> sys = ct.nlsys(f, None, states=2, inputs=0, params={'a': 0.2})
    >>> orbit = ltp.limit_cycle(sys, 6.0, [1.0, 0.0])
    >>> branch = ltp.orbit_continuation(orbit, 'a', [0.2, 0.1, 0.05])
    >>> bool(np.allclose(branch.multipliers[:, 0], np.exp(-4 * np.pi * branch.values)))
    True
    >>> branch.bifurcations, bool(branch.stable.all())
    ([], True)

    See the user guide for a fold and a period doubling.
    """
    if not isinstance(orbit, PeriodicOrbit):
        raise ControlArgument(f"orbit must be a PeriodicOrbit, got {type(orbit).__name__}")
    if not isinstance(param, str) or param not in orbit.params:
        raise ValueError(f"param must name one of the plant parameters "
                         f"{sorted(orbit.params)}, got {param!r}")
    values = real_array(values, 'values', ndim=1)
    steps = np.diff(values)
    if values.size < 1 or not (np.all(steps > 0) or np.all(steps < 0)):
        raise ValueError("values must be a non-empty, strictly monotone sequence")
    if isinstance(locate_tol, bool) or not isinstance(locate_tol, numbers.Real) \
            or not locate_tol > 0:
        raise ValueError(f"locate_tol must be a positive number, got {locate_tol!r}")
    max_halvings = check_positive_int(max_halvings, 'max_halvings', minimum=0)
    solver = _Solver(orbit, param, kwargs)
    start = solver.solve(values[0], [orbit])
    if start is None:
        raise RuntimeError(f"orbit_continuation: no orbit found at {param}={values[0]:g} "
                           f"from the start orbit: {solver.last_error}")
    branch, bifurcations, message = [start], [], "completed"
    step, previous = np.inf, values[0]
    for target in tqdm(values[1:], desc="continuation", leave=False, disable=not progress):
        nominal, previous = abs(target - previous), target
        while branch[-1].params[param] != target:
            new, step = _advance(solver, branch, target, min(2 * step, nominal),
                                 nominal / 2 ** max_halvings)
            if new is None:
                message = (f"the branch ends near {param}={branch[-1].params[param]:.8g}: "
                           f"no orbit found beyond it ({solver.last_error})")
                fold = _extrapolated_fold(branch, param)
                if fold is not None and not any(b.kind == 'fold' and abs(b.value - fold.value)
                                                <= 1e-3 * (1 + abs(fold.value))
                                                for b in bifurcations):
                    bifurcations.append(fold)
                break
            bifurcations += _detect(solver, branch[-1], new, locate_tol)
            branch.append(new)
        else:
            continue
        break
    return OrbitBranch._from_orbits(param, branch, bifurcations, message)


class _Solver:
    """Recompute the orbit at a parameter value from nearby orbits."""

    def __init__(self, orbit, param, kwargs):
        self.orbit, self.param, self.kwargs = orbit, param, kwargs
        self.last_error = ""

    def solve(self, value, near, x=None, period=None):
        o = self.orbit
        guess = near[-1]
        x = guess.x0 if x is None else x
        period = guess.period if period is None else period
        params = {**o.params, self.param: float(value)}
        options = dict(self.kwargs)
        options.setdefault('npoints', len(o.time))
        # from a predictor Newton converges in a few iterations or not at all
        options.setdefault('max_iter', 6)
        try:
            if o.autonomous:
                sec = o.section
                return limit_cycle(o.plant, period, x, o.mode0, section=sec.user,
                                   direction=sec.direction, u0=o.u0, params=params,
                                   max_periods=0, **options)
            return periodic_orbit(o.plant, o.period, x, o.mode0, u0=o.u0, params=params,
                                  max_periods=0, **options)
        except (RuntimeError, ValueError) as err:
            self.last_error = str(err)
            return None


def _advance(solver, branch, target, size, smallest):
    """Next branch point towards `target` and the step size that reached it.

    The step starts at `size` and is halved after each failure down to
    `smallest`; the secant predictor starts Newton.
    """
    p_last = branch[-1].params[solver.param]
    size = min(abs(target - p_last), size)
    while size >= smallest * (1 - 1e-12):
        step = np.sign(target - p_last) * size
        value = target if abs(target - p_last - step) <= 1e-12 * size else p_last + step
        x, period = None, None
        if len(branch) >= 2:
            a, b = branch[-2], branch[-1]
            ratio = step / (b.params[solver.param] - a.params[solver.param])
            x = b.x0 + ratio * (b.x0 - a.x0)
            period = b.period + ratio * (b.period - a.period) if b.autonomous else None
        new = solver.solve(value, branch, x, period)
        if new is not None and new.mode0 == branch[-1].mode0:
            return new, size
        size /= 2
    return None, size


def _detect(solver, a, b, tol):
    """Bifurcations between the branch points `a` and `b`, located by Brent's method."""
    found = []
    ta, tb = _tests(a.stability_multipliers), _tests(b.stability_multipliers)
    pa, pb = a.params[solver.param], b.params[solver.param]
    for kind in _KINDS:
        if ta[kind] * tb[kind] >= 0 or (kind == 'torus' and len(a.stability_multipliers) < 2):
            continue
        near = [a, b]

        def test(p, kind=kind):
            closest = min(near, key=lambda o: abs(o.params[solver.param] - p))
            orbit = solver.solve(p, [closest])
            if orbit is None:
                raise _Lost
            near.append(orbit)
            return _tests(orbit.stability_multipliers)[kind]

        try:
            value = brentq(test, pa, pb, xtol=tol, rtol=4 * np.finfo(float).eps)
        except _Lost:
            # the orbit is lost inside the bracket (e.g. at a fold, where the
            # branch continued on the other side): report its middle
            value = 0.5 * (pa + pb)
        orbit = min(near, key=lambda o: abs(o.params[solver.param] - value))
        found.append(Bifurcation(kind, float(value),
                                 _critical(kind, orbit.stability_multipliers), orbit))
    return found


class _Lost(Exception):
    """No orbit found while locating a bifurcation."""


def _extrapolated_fold(branch, param):
    """Fold beyond the last branch points: zero of (μ − 1)², linear in p there."""
    if len(branch) < 2:
        return None
    p = np.array([o.params[param] for o in branch[-2:]])
    mu = np.array([_critical('fold', o.stability_multipliers) for o in branch[-2:]])
    if np.any(np.abs(mu.imag) > 0) or not abs(mu[1] - 1) < abs(mu[0] - 1):
        return None
    d2 = (mu.real - 1) ** 2
    value = p[1] - d2[1] * (p[1] - p[0]) / (d2[1] - d2[0])
    last, step = p[-1], p[-1] - p[-2]
    # accept a fold ahead of the last point, within a few of the last steps
    if not 0 <= (value - last) / step <= 4:
        return None
    return Bifurcation('fold', float(value), 1.0 + 0j, None)
