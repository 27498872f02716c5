"""Stability charts of two-parameter families of LTP systems, with or without delays.

At every grid point ``(x_i, y_j)`` the family's system ``factory(x_i,
y_j)`` gives its dominant multiplier modulus ``ρ = max|μ|``; between
neighbouring values of y where ``ρ - 1`` changes sign the boundary is
located by Brent's method on ``log ρ`` to a tolerance, so the chart carries
the stability boundary itself, not only a grid contour.  For a delayed
system the sweep uses a fixed discretization degree and every boundary
point is checked at a refined degree (recomputed there when the two
disagree).  The columns (one value of x each) are independent; in
parallel they are run in a few chunks per worker by joblib (any of its
backends, Dask's with a ``dask.distributed`` client), so that the factory
is sent once per chunk and the pool's workers start once.
A factory that raises at some points does not lose the others: the
finished points are kept and the failures reported.
"""

import os
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq
from control.exception import ControlArgument
from tqdm.auto import tqdm

from .._core.floquet import floquet_multipliers
from .._core.ltpsys import LTPStateSpace
from .._core.validation import real_array
from .ltpdsys import LTPDelayStateSpace
from .monodromy import _ORDER, _REFINE, _Problem, _change

__all__ = ['stability_chart', 'StabilityChart', 'StabilityChartError']

# parallel tasks per worker (each a chunk of columns): balances the load, few round trips
_CHUNKS_PER_WORKER = 4


class StabilityChartError(RuntimeError):
    """The factory of `stability_chart` raised; ``chart`` holds every finished point.

    Parameters
    ----------
    message : str
        What failed, and where first.
    chart : StabilityChart
        The chart with every finished point (failed points are NaN).

    Examples
    --------
    >>> def factory(x, y):
    ...     if x > 1:
    ...         raise ValueError("no model there")
    ...     return ltp.ltpss([[x - y]], np.zeros((1, 0)), np.zeros((0, 1)), 0, period=1.0)
    >>> try:
    ...     ltp.stability_chart(factory, [0.0, 2.0], [0.0, 1.0], n_jobs=1)
    ... except ltp.StabilityChartError as err:
    ...     print(np.isfinite(err.chart.radius).sum(), "points kept")
    2 points kept
    """

    def __init__(self, message, chart):
        super().__init__(message)
        self.chart = chart


@dataclass(frozen=True)
class StabilityChart:
    """Dominant multiplier modulus of a family of LTP systems on a grid.

    Returned by `stability_chart`.

    Attributes
    ----------
    x, y : ndarray
        The grid values.
    radius : ndarray, shape (len(y), len(x))
        ``max|μ|`` at each grid point (NaN where the factory failed).
    boundary : ndarray, shape (k, 2)
        Refined boundary points ``(x, y)`` with ``max|μ| = 1``.
    failures : list of tuple
        ``(x, y, message)`` for every point where the factory or the
        analysis raised.
    tol : float
        Relative tolerance of the boundary points.
    xlabel, ylabel : str
        Axis labels of `plot`.

    Examples
    --------
    The damped Mathieu equation ``x'' + κx' + (δ + ε cos t) x = 0``: at
    δ = 1/4 the principal tongue begins at ``ε ≈ 2κ√δ = κ`` (averaging):

    >>> def mathieu(delta, eps):
    ...     A = lambda t: np.array([[0.0, 1.0], [-delta - eps * np.cos(t), -0.02]])
    ...     return ltp.ltpss(A, np.zeros((2, 0)), np.zeros((0, 2)), 0, period=2 * np.pi)
    >>> chart = ltp.stability_chart(mathieu, [0.25], [0.0, 0.2], n_jobs=1)
    >>> chart.boundary.round(3)
    array([[0.25, 0.02]])
    """

    x: np.ndarray
    y: np.ndarray
    radius: np.ndarray
    boundary: np.ndarray
    failures: list = field(default_factory=list)
    tol: float = 1e-8
    xlabel: str = 'x'
    ylabel: str = 'y'

    def __repr__(self):
        return (f"<StabilityChart: {len(self.x)} x {len(self.y)} grid, "
                f"{len(self.boundary)} boundary points, {len(self.failures)} failures>")

    @property
    def stable(self):
        """Boolean grid: ``max|μ| < 1`` (False where the point failed)."""
        with np.errstate(invalid='ignore'):
            return self.radius < 1

    def critical(self):
        """Lowest boundary y of each column that is stable at ``y[0]`` (a lobe diagram).

        Returns
        -------
        ndarray, shape (len(x),)
            NaN where the column is unstable at ``y[0]`` or has no boundary.

        Examples
        --------
        >>> def family(a, k):
        ...     return ltp.ltpss([[k - a]], np.zeros((1, 0)), np.zeros((0, 1)), 0, period=1.0)
        >>> chart = ltp.stability_chart(family, [1.0, 2.0], np.linspace(0, 3, 4), n_jobs=1)
        >>> chart.critical().round(8)
        array([1., 2.])
        """
        out = np.full(len(self.x), np.nan)
        for i, x in enumerate(self.x):
            if not self.radius[0, i] < 1:
                continue
            ys = self.boundary[self.boundary[:, 0] == x, 1]
            if ys.size:
                out[i] = ys.min() if self.y[-1] >= self.y[0] else ys.max()
        return out

    def plot(self, ax=None, *, levels=None, cmap='RdYlGn_r', boundary=True, title=None):
        """Draw the chart: ``max|μ|`` as a filled contour and the refined boundary.

        Stable points (``|μ| < 1``) on the cool side of the colour map; the
        refined boundary points are joined column by column into lines,
        which is the stability lobe diagram of chatter or the Ince-Strutt
        chart of a Mathieu equation.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (default: a new figure).
        levels : array_like, optional
            Contour levels of ``log10 max|μ|`` (default: symmetric about 0).
        cmap : str, optional
            Colour map (default 'RdYlGn_r').
        boundary : bool, optional
            Draw the refined boundary (default True).
        title : str, optional
            Axes title.

        Returns
        -------
        control.ControlPlot

        Examples
        --------
        >>> def family(a, k):
        ...     return ltp.ltpss([[k - a]], np.zeros((1, 0)), np.zeros((0, 1)), 0, period=1.0)
        >>> chart = ltp.stability_chart(family, [1.0, 2.0], np.linspace(0, 3, 4), n_jobs=1)
        >>> cplt = chart.plot()
        """
        import control as ct
        import matplotlib.pyplot as plt
        if ax is None:
            fig, ax = plt.subplots()
        else:
            fig = ax.figure
        lines = []
        with np.errstate(divide='ignore', invalid='ignore'):
            logr = np.log10(self.radius)
        finite = logr[np.isfinite(logr)]
        if len(self.x) > 1 and len(self.y) > 1 and finite.size:
            if levels is None:
                top = max(float(np.max(np.abs(finite))), 1e-3)
                levels = np.linspace(-top, top, 21)
            cs = ax.contourf(self.x, self.y, np.clip(logr, levels[0], levels[-1]),
                             levels=levels, cmap=cmap)
            fig.colorbar(cs, ax=ax, label='log10 max|μ|')
        if boundary and len(self.boundary):
            b = self.boundary
            lines += ax.plot(b[:, 0], b[:, 1], 'k.', ms=2)
            crit = self.critical()
            ok = np.isfinite(crit)
            if np.count_nonzero(ok) > 1:
                lines += ax.plot(self.x[ok], crit[ok], 'k-', lw=1.2)
        ax.set_xlabel(self.xlabel)
        ax.set_ylabel(self.ylabel)
        if title is not None:
            ax.set_title(title)
        return ct.ControlPlot(np.array([[lines]], dtype=object), np.array([[ax]]), fig)


def stability_chart(factory, x_values, y_values, *, tol=1e-8, refine=True, order=None,
                    on_error='raise', n_jobs=None, backend=None, progress=None,
                    xlabel='x', ylabel='y'):
    """Stability chart of a two-parameter family of LTP systems, with or without delays.

    Parameters
    ----------
    factory : callable
        ``factory(x, y)`` returns an `LTPStateSpace` or an
        `LTPDelayStateSpace`.  For process-based parallel backends it must
        be picklable (a module-level function or ``functools.partial``;
        joblib's default backend also takes lambdas).
    x_values, y_values : array_like
        Grid values (1D, strictly monotonic); the boundary is refined along y.
    tol : float, optional
        Relative tolerance of the refined boundary values (default 1e-8);
        the multipliers of delayed systems are checked to ``tol/10``.
    refine : bool, optional
        Locate the boundary between grid values (default True).
    order : int, optional
        Degree of the delayed systems' discretization during the sweep
        (default 16; see `delay_monodromy`).
    on_error : {'raise', 'keep'}, optional
        When the factory (or the analysis) raises at some points: 'raise'
        (default) finishes every other point, then raises
        `StabilityChartError` holding the partial chart; 'keep' returns it
        with a warning.  Failed points are NaN in ``radius``.
    n_jobs : int, optional
        joblib workers (default: all cores, at most one per column); 1 runs
        in the calling process.
    backend : str, optional
        joblib backend ('loky' by default; 'threading'; 'dask' with a
        running ``dask.distributed`` client).
    progress : bool, optional
        Progress bar over the columns (default: shown for more than 20
        columns).
    xlabel, ylabel : str, optional
        Axis labels stored for `StabilityChart.plot`.

    Returns
    -------
    StabilityChart

    Raises
    ------
    StabilityChartError
        With ``on_error='raise'`` when some points failed (after all others
        are computed); its ``chart`` attribute keeps them.

    Examples
    --------
    ``ẋ = -a x + b x(t - 1)`` is stable for ``|b| < a`` when a > 0 ... up to
    the delay-dependent boundary ``b = -ω/sin ω`` with ``ω = -a tan ω``
    (here a = 1, b < 0: b ≈ -2.2618):

    >>> def family(a, b):
    ...     return ltp.ltpdss([[-a]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[b]])])
    >>> chart = ltp.stability_chart(family, [1.0], np.linspace(0.0, -3.0, 4), n_jobs=1)
    >>> chart.critical().round(4)
    array([-2.2618])
    """
    if not callable(factory):
        raise ControlArgument(f"factory must be a callable (x, y) -> system, got "
                              f"{type(factory).__name__}")
    xs = _grid(x_values, 'x_values')
    ys = _grid(y_values, 'y_values')
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating)) \
            or not 0 < tol < 0.1:
        raise ValueError(f"tol must be a number in (0, 0.1), got {tol!r}")
    if on_error not in ('raise', 'keep'):
        raise ValueError(f"on_error must be 'raise' or 'keep', got {on_error!r}")
    if order is not None and (isinstance(order, bool) or not isinstance(order, (int, np.integer))
                              or order < _REFINE + 2):
        raise ValueError(f"order must be an integer >= {_REFINE + 2}, got {order!r}")
    opts = dict(tol=float(tol), refine=bool(refine), order=int(order or _ORDER))
    jobs = _jobs(n_jobs, len(xs))
    show = len(xs) > 20 if progress is None else bool(progress)
    if jobs == 1 and backend is None:
        results = [_column(factory, x, ys, opts)
                   for x in tqdm(xs, desc="stability chart", unit="column", disable=not show,
                                 leave=False)]
    else:
        import joblib
        # a few chunks of columns per worker: the factory is pickled once per chunk and
        # the pool (loky's, reused between calls) starts its workers once
        chunks = np.array_split(xs, min(len(xs), _CHUNKS_PER_WORKER * jobs))
        results = []
        with joblib.parallel_config(backend=backend or 'loky', n_jobs=jobs), \
                tqdm(total=len(xs), desc="stability chart", unit="column",
                     disable=not show, leave=False) as bar:
            gen = joblib.Parallel(return_as='generator')(
                joblib.delayed(_columns)(factory, c, ys, opts) for c in chunks)
            for part in gen:
                results += part
                bar.update(len(part))
    radius = np.column_stack([r[0] for r in results])
    bnd = [pt for r in results for pt in r[1]]
    failures = [f for r in results for f in r[2]]
    chart = StabilityChart(x=xs, y=ys, radius=radius,
                           boundary=np.array(bnd, float).reshape(-1, 2), failures=failures,
                           tol=float(tol), xlabel=str(xlabel), ylabel=str(ylabel))
    if failures:
        x, y, msg = failures[0]
        text = (f"stability_chart: {len(failures)} of {radius.size} points failed, first at "
                f"x={x:g}, y={y:g}: {msg}")
        if on_error == 'raise':
            raise StabilityChartError(text + "; the finished points are in the exception's "
                                      "chart attribute", chart)
        warnings.warn(text + "; they are NaN in the chart", UserWarning, stacklevel=2)
    return chart


def _grid(values, name):
    v = real_array(values, name, ndim=1)
    if v.size < 1:
        raise ValueError(f"{name} must hold at least one value")
    if v.size > 1:
        d = np.diff(v)
        if not (np.all(d > 0) or np.all(d < 0)):
            raise ValueError(f"{name} must be strictly monotonic")
    return v


def _jobs(n_jobs, ncols):
    cores = os.cpu_count() or 1
    if n_jobs is None or n_jobs == -1:
        return max(1, min(cores, ncols))
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, (int, np.integer)) or n_jobs < 1:
        raise ControlArgument(f"n_jobs must be a positive integer or -1, got {n_jobs!r}")
    return int(min(n_jobs, cores, ncols))


class _Radius:
    """``max|μ|`` of factory(x, y) at a given degree (for delayed systems)."""

    def __init__(self, factory, x):
        self.factory, self.x = factory, x

    def system(self, y):
        sys = self.factory(self.x, y)
        if not isinstance(sys, (LTPStateSpace, LTPDelayStateSpace)):
            raise ControlArgument(f"factory must return an LTPStateSpace or an "
                                  f"LTPDelayStateSpace, got {type(sys).__name__}")
        return sys

    def __call__(self, y, order):
        sys = self.system(y)
        if isinstance(sys, LTPDelayStateSpace):
            if not sys.state_delays:
                sys = sys.undelayed()
            else:
                mu = _Problem(sys).multipliers(order)
                return float(np.abs(mu[0])) if mu.size else 0.0
        mu = floquet_multipliers(sys)
        return float(np.max(np.abs(mu), initial=0.0))


def _columns(factory, xs, ys, opts):
    """`_column` over a chunk of columns (one parallel task)."""
    return [_column(factory, x, ys, opts) for x in xs]


def _column(factory, x, ys, opts):
    """Radius on one column, refined boundary points, failures (never raises).

    The matrices are small: a multi-threaded BLAS only adds overhead (10x
    measured on a loaded machine), so it is held to one thread when
    threadpoolctl is installed.
    """
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:                     # optional
        return _column_body(factory, x, ys, opts)
    with threadpool_limits(1):
        return _column_body(factory, x, ys, opts)


def _column_body(factory, x, ys, opts):
    rad = _Radius(factory, x)
    order, tol = opts['order'], opts['tol']
    r = np.full(len(ys), np.nan)
    failures, bnd = [], []
    for j, y in enumerate(ys):
        try:
            r[j] = rad(y, order)
        except Exception as exc:            # kept as a failure of the point
            failures.append((float(x), float(y), f"{type(exc).__name__}: {exc}"))
    if not opts['refine']:
        return r, bnd, failures
    for j in range(len(ys) - 1):
        a, b = r[j], r[j + 1]
        if not (np.isfinite(a) and np.isfinite(b)) or (a < 1) == (b < 1) or a == 0 or b == 0:
            continue
        try:
            bnd.append((float(x), _boundary(rad, ys[j], ys[j + 1], order, tol)))
        except Exception as exc:
            failures.append((float(x), float(ys[j]), f"boundary refinement: "
                             f"{type(exc).__name__}: {exc}"))
    return r, bnd, failures


def _boundary(rad, y0, y1, order, tol):
    """y in (y0, y1) with max|μ| = 1, to relative `tol`, at a checked degree."""
    xtol = tol * max(abs(y0), abs(y1), 1e-300)
    for _ in range(4):
        f = lambda y: np.log(rad(y, order))
        y = brentq(f, y0, y1, xtol=xtol, rtol=4 * np.finfo(float).eps, maxiter=200)
        sys = rad.system(y)
        if not isinstance(sys, LTPDelayStateSpace) or not sys.state_delays:
            return float(y)
        prob = _Problem(sys)
        err = _change(prob.multipliers(order), prob.multipliers(order + _REFINE),
                      2 * sys.nstates)
        if err <= tol / 10:
            return float(y)
        order += _REFINE
    warnings.warn(f"stability_chart: the boundary near y={y:g} is accurate to about "
                  f"{err:.1e} in the multipliers only", UserWarning, stacklevel=2)
    return float(y)
