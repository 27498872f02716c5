"""Campbell diagrams: Floquet modes tracked over a parameter sweep.

At every value ``p_k`` of the sweep the Floquet modes are computed
(`floquet_modes`); modes of neighbouring values are matched by a linear
assignment on the cost

    c_ij = 1 - MAC(u_i, v_j) + |λ_i - λ_j| / max(|λ|),
    MAC(u, v) = |uᴴv|² / (‖u‖² ‖v‖²),

with the periodic mode shapes u, v (all instants of one period stacked), and
a unit penalty between modes of opposite damped-frequency sign, so that a
track follows its mode shape through near-crossings instead of swapping
with a mode of similar frequency.  Resonance crossings are the values where
a track's frequency meets an nP line ``n Ω(p)``, located by linear
interpolation between sweep values.
"""

import os
from dataclasses import dataclass, replace

import numpy as np
import control as ct
from control.exception import ControlArgument
from scipy.optimize import linear_sum_assignment

from .._analysis.floquet_modes import floquet_modes
from .._core.coerce import as_ltp
from .._core.ltpsys import LTPStateSpace
from .._core.periodic_matrix import PeriodicMatrix
from .._core.validation import real_array
from .mbc import mbc
from .rotor_model import RotorStateSpace

__all__ = ['campbell', 'CampbellDiagram']


@dataclass(frozen=True)
class CampbellDiagram:
    """Floquet modes of a sweep, tracked by mode shape.

    Returned by `campbell`.  Arrays have one row per sweep value and one
    column per track.

    Attributes
    ----------
    values : ndarray, shape (K,)
        The sweep values.
    exponents : ndarray of complex, shape (K, n)
        Exponents on the branch chosen by `campbell` (see its ``branch``).
    frequency : ndarray, shape (K, n)
        Natural frequencies (rad/s).
    damped_frequency : ndarray, shape (K, n)
        Imaginary parts of the exponents (rad/s).
    damping : ndarray, shape (K, n)
        Damping ratios.
    principal_harmonic : ndarray of int, shape (K, n)
        Branch of each track at each value, counted in harmonics from the
        strip of `floquet_exponents`.
    mac : ndarray, shape (K-1, n)
        MAC between a track's shapes at neighbouring values (1: same shape).
    rotor_speed : ndarray, shape (K,)
        Ω at each value (rad/s), for the nP lines.
    crossings : list of tuple
        ``(track, n, value, frequency)`` where track ``track`` crosses the
        nP line ``n Ω``.
    modes : tuple of FloquetModes
        The modes at each value (in their own order; empty for a diagram
        read back by `load`).
    indices : ndarray of int, shape (K, n)
        The index of each track's mode in ``modes[k]``.
    labels : tuple of str
        A name for each track (e.g. ``'1st tower FA'``, ``'1st flap BW'``
        from `campbell_lin`), or empty.
    wind_speed : ndarray or None
        Wind speed (m/s) at each value, when known.
    xlabel : str
        Name of the sweep value.
    frame : str or None
        Coordinates of the modes ('rotating', 'multiblade' or None).

    Examples
    --------
    >>> def spring(k):
    ...     return ltp.ltpss([[0.0, 1.0], [-k, -0.1]], np.zeros((2, 0)), np.zeros((0, 2)),
    ...                      0, period=1.0)
    >>> cd = ltp.campbell(spring, [1.0, 4.0, 9.0], rotor_speed=[1.0, 1.0, 1.0], n_jobs=1)
    >>> cd.frequency[:, 0].round(6)
    array([1., 2., 3.])
    >>> [(n, round(value, 6)) for _, n, value, _ in cd.crossings if n == 2][:1]
    [(2, 4.0)]
    """

    values: np.ndarray
    exponents: np.ndarray
    frequency: np.ndarray
    damped_frequency: np.ndarray
    damping: np.ndarray
    principal_harmonic: np.ndarray
    mac: np.ndarray
    rotor_speed: np.ndarray
    crossings: list
    modes: tuple
    labels: tuple = ()
    indices: np.ndarray = None
    wind_speed: np.ndarray = None
    xlabel: str = 'sweep value'
    frame: str = None

    def __repr__(self):
        frame = f", {self.frame} frame" if self.frame else ""
        return (f"<CampbellDiagram: {self.frequency.shape[1]} tracks over "
                f"{len(self.values)} values{frame}>")

    def table(self, tracks=None):
        """The diagram as columns of a long table: one row per value and track.

        Columns: ``track``, ``label``, ``value``, ``rotor_speed_rpm``,
        ``wind_speed`` (NaN when unknown), ``frequency_hz``,
        ``damped_frequency_hz``, ``damping_ratio``, ``damping_percent``,
        ``log_decrement`` (``2πζ/√(1-ζ²)``), ``principal_harmonic``.

        Parameters
        ----------
        tracks : sequence of int, optional
            Default: one track of each complex pair (those with
            non-negative damped frequency at most values).

        Returns
        -------
        dict of ndarray

        Examples
        --------
        >>> A = lambda p: np.array([[0.0, 1.0], [-(4 + p), -0.2]])
        >>> cd = ltp.campbell(lambda p: ltp.ltpss(A(p), np.zeros((2, 0)), np.zeros((0, 2)),
        ...                                       0, period=1.0), [1.0, 2.0], n_jobs=1)
        >>> t = cd.table()
        >>> t['frequency_hz'].round(4), t['damping_percent'].round(3)
        (array([0.3559, 0.3898]), array([4.472, 4.082]))
        """
        tracks = self._tracks(tracks)
        K = len(self.values)
        cols = {'track': np.repeat(np.asarray(tracks, int), K)}
        labels = [self.labels[k] if k < len(self.labels) else '' for k in tracks]
        cols['label'] = np.repeat(np.asarray(labels, dtype=object), K)
        cols['value'] = np.tile(self.values, len(tracks))
        cols['rotor_speed_rpm'] = np.tile(self.rotor_speed * 30 / np.pi, len(tracks))
        wind = self.wind_speed if self.wind_speed is not None else np.full(K, np.nan)
        cols['wind_speed'] = np.tile(np.asarray(wind, float), len(tracks))
        cols['frequency_hz'] = self.frequency[:, tracks].T.ravel() / (2 * np.pi)
        cols['damped_frequency_hz'] = self.damped_frequency[:, tracks].T.ravel() / (2 * np.pi)
        zeta = self.damping[:, tracks].T.ravel()
        cols['damping_ratio'] = zeta
        cols['damping_percent'] = 100 * zeta
        with np.errstate(invalid='ignore', divide='ignore'):
            cols['log_decrement'] = 2 * np.pi * zeta / np.sqrt(1 - zeta ** 2)
        cols['principal_harmonic'] = self.principal_harmonic[:, tracks].T.ravel()
        return cols

    def to_dataframe(self, tracks=None):
        """The diagram as a pandas ``DataFrame`` (see ``table``; needs pandas).

        Examples
        --------
        >>> A = lambda p: np.array([[0.0, 1.0], [-(4 + p), -0.2]])
        >>> cd = ltp.campbell(lambda p: ltp.ltpss(A(p), np.zeros((2, 0)), np.zeros((0, 2)),
        ...                                       0, period=1.0), [1.0, 2.0], n_jobs=1)
        >>> cd.to_dataframe().shape
        (2, 11)
        """
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("to_dataframe needs pandas (pip install pandas); to_csv and "
                              "table work without it") from None
        return pd.DataFrame(self.table(tracks))

    def to_csv(self, path, tracks=None):
        """Write the diagram's ``table`` to a CSV file (no pandas needed).

        Examples
        --------
        >>> import csv, os, tempfile
        >>> A = lambda p: np.array([[0.0, 1.0], [-(4 + p), -0.2]])
        >>> cd = ltp.campbell(lambda p: ltp.ltpss(A(p), np.zeros((2, 0)), np.zeros((0, 2)),
        ...                                       0, period=1.0), [1.0, 2.0], n_jobs=1)
        >>> path = os.path.join(tempfile.mkdtemp(), 'campbell.csv')
        >>> cd.to_csv(path)
        >>> with open(path) as fh:
        ...     rows = list(csv.DictReader(fh))
        >>> len(rows), bool(float(rows[1]['frequency_hz']) == cd.frequency[1, 0] / (2 * np.pi))
        (2, True)
        """
        import csv
        cols = self.table(tracks)
        names = list(cols)
        with open(path, 'w', newline='') as fh:
            writer = csv.writer(fh)
            writer.writerow(names)
            for i in range(len(cols['track'])):
                writer.writerow([repr(float(cols[c][i])) if isinstance(cols[c][i], float)
                                 else cols[c][i] for c in names])

    def _tracks(self, tracks):
        if tracks is None:
            return [k for k in range(self.frequency.shape[1])
                    if np.mean(self.damped_frequency[:, k] >= 0) >= 0.5]
        tracks = [int(k) for k in tracks]
        if any(not 0 <= k < self.frequency.shape[1] for k in tracks):
            raise ValueError(f"tracks must be in 0..{self.frequency.shape[1] - 1}")
        return tracks

    def track_crossings(self, i, j):
        """Values where tracks i and j have equal frequencies (linear interpolation).

        Examples
        --------
        Two oscillators at ``1 + p`` and ``3 - p`` rad/s cross at p = 1:

        >>> def factory(p):
        ...     A = np.zeros((4, 4))
        ...     A[:2, :2] = [[-0.01, 1 + p], [-1 - p, -0.01]]
        ...     A[2:, 2:] = [[-0.01, 3 - p], [-3 + p, -0.01]]
        ...     return ltp.ltpss(A, np.zeros((4, 0)), np.zeros((0, 4)), 0, period=1.0)
        >>> cd = ltp.campbell(factory, np.linspace(0, 2, 20), n_jobs=1)
        >>> up = int(np.argmax(cd.frequency[-1]))        # the track rising to 3 rad/s
        >>> down = [k for k in range(4) if abs(cd.frequency[-1, k] - 1) < 1e-3][0]
        >>> np.round(cd.track_crossings(up, down), 6)
        array([1.])
        """
        d = self.frequency[:, i] - self.frequency[:, j]
        return _zeros(self.values, d)

    def plot(self, ax=None, *, per_rev=(1, 2, 3), tracks=None, title=None, x='value',
             frequency_unit='rad/s', damping='ratio', legend=None):
        """Campbell diagram: frequency and damping against the sweep value.

        Parameters
        ----------
        ax : array of two matplotlib.axes.Axes, optional
            Axes for the frequency and damping plots (default: a new
            figure with two stacked axes).
        per_rev : sequence of int
            The nP lines ``n Ω`` drawn (empty for none).
        tracks : sequence of int, optional
            The tracks drawn (default: those with non-negative damped
            frequency at most values, one per complex pair).
        title : str, optional
            Figure title.
        x : {'value', 'rpm', 'rotor_speed', 'wind_speed'}
            Abscissa: the sweep value, the rotor speed in rpm or rad/s, or
            the wind speed in m/s.
        frequency_unit : {'rad/s', 'Hz'}
        damping : {'ratio', 'percent', 'logdec'}
            Damping ratio, in percent, or logarithmic decrement.
        legend : bool, optional
            Legend of the track labels (default: when the tracks have
            labels).

        Returns
        -------
        control.ControlPlot

        Examples
        --------
        >>> import matplotlib
        >>> matplotlib.use('Agg')
        >>> A = lambda p: np.array([[0.0, 1.0], [-(4 + p), -0.2]])
        >>> cd = ltp.campbell(lambda p: ltp.ltpss(A(p), np.zeros((2, 0)), np.zeros((0, 2)),
        ...                                       0, period=1.0), [0.0, 1.0, 2.0], n_jobs=1)
        >>> cplt = cd.plot(frequency_unit='Hz', damping='percent')
        >>> cplt.axes.shape, cplt.axes[0, 0].get_ylabel()
        ((2, 1), 'frequency [Hz]')
        """
        import matplotlib.pyplot as plt
        if x == 'value':
            xs, xlabel = self.values, self.xlabel
        elif x == 'rpm':
            xs, xlabel = self.rotor_speed * 30 / np.pi, 'rotor speed [rpm]'
        elif x == 'rotor_speed':
            xs, xlabel = self.rotor_speed, 'rotor speed [rad/s]'
        elif x == 'wind_speed':
            if self.wind_speed is None:
                raise ValueError("x='wind_speed': the diagram has no wind speeds")
            xs, xlabel = np.asarray(self.wind_speed, float), 'wind speed [m/s]'
        else:
            raise ValueError(f"x must be 'value', 'rpm', 'rotor_speed' or 'wind_speed', "
                             f"got {x!r}")
        if frequency_unit not in ('rad/s', 'Hz'):
            raise ValueError(f"frequency_unit must be 'rad/s' or 'Hz', got {frequency_unit!r}")
        fscale = 1 / (2 * np.pi) if frequency_unit == 'Hz' else 1.0
        zeta = self.damping
        if damping == 'ratio':
            dvals, dlabel = zeta, 'damping ratio'
        elif damping == 'percent':
            dvals, dlabel = 100 * zeta, 'damping ratio [%]'
        elif damping == 'logdec':
            with np.errstate(invalid='ignore', divide='ignore'):
                dvals = 2 * np.pi * zeta / np.sqrt(1 - zeta ** 2)
            dlabel = 'logarithmic decrement'
        else:
            raise ValueError(f"damping must be 'ratio', 'percent' or 'logdec', got "
                             f"{damping!r}")
        if ax is None:
            fig, ax = plt.subplots(2, 1, sharex=True, squeeze=False)
            ax = ax[:, 0]
        else:
            ax = np.asarray(ax).ravel()
            if ax.size != 2:
                raise ControlArgument("ax must hold two axes (frequency, damping)")
            fig = ax[0].figure
        tracks = self._tracks(tracks)
        lines = np.empty((2, 1), dtype=object)
        freq_lines, damp_lines = [], []
        for k in tracks:
            label = self.labels[k] if k < len(self.labels) and self.labels[k] else \
                f'track {k}'
            freq_lines += ax[0].plot(xs, fscale * self.frequency[:, k], label=label)
            damp_lines += ax[1].plot(xs, dvals[:, k], color=freq_lines[-1].get_color())
        for n in per_rev:
            freq_lines += ax[0].plot(xs, fscale * n * self.rotor_speed, 'k--', lw=0.7)
            ax[0].annotate(f'{n}P', (xs[-1], fscale * n * self.rotor_speed[-1]),
                           fontsize='small')
        for _, n, value, freq in self.crossings:
            if n in per_rev:
                at = np.interp(value, self.values, xs) if self.values[-1] > self.values[0] \
                    else np.interp(value, self.values[::-1], xs[::-1])
                ax[0].plot(at, fscale * freq, 'ko', ms=3)
        ax[1].axhline(0, color='k', lw=0.5)
        ax[0].set_ylabel(f'frequency [{frequency_unit}]')
        ax[1].set_ylabel(dlabel)
        ax[1].set_xlabel(xlabel)
        if legend or (legend is None and any(self.labels)):
            ax[0].legend(fontsize='x-small', ncol=2)
        lines[0, 0], lines[1, 0] = freq_lines, damp_lines
        if title:
            fig.suptitle(title)
        return ct.ControlPlot(lines, ax.reshape(2, 1), fig)


def campbell(factory, values, *, rotor_speed=None, per_rev=(1, 2, 3), branch='continuous',
             frame=None, nharmonics=None, n_jobs=None, backend=None):
    """Floquet modes over a parameter sweep, tracked by mode shape.

    Parameters
    ----------
    factory : callable
        ``factory(value) -> LTPStateSpace``: the model at one sweep value
        (rotor speed, wind speed, advance ratio, ...).  It must be picklable
        for process-based parallel backends (module-level functions,
        ``functools.partial``, lambdas with joblib's default backend).
    values : array_like, shape (K,)
        Sweep values, at least two, strictly monotonic.
    rotor_speed : array_like or callable, optional
        Ω (rad/s) at each value, for the nP lines: an array of K values or
        ``rotor_speed(value)``.  Default: the values themselves (a sweep
        over rotor speed).
    per_rev : sequence of int
        The nP lines whose crossings with the tracks are reported.
    branch : {'continuous', 'principal'}
        Branch of each exponent (defined modulo ``jω_p``): 'principal'
        keeps the principal-harmonic branch of `floquet_modes` at every
        value, which jumps by ``ω_p`` where two harmonics exchange the
        largest share; 'continuous' (default, continuous-time models) takes
        the principal-harmonic branch at the first value and then, along
        each track, the branch nearest to the track's previous exponent.
    frame, nharmonics
        Passed to `floquet_modes`.
    n_jobs : int, optional
        Parallel workers of joblib (default: all cores, at most one per
        value; capped to the machine's cores).  1 runs serially.
    backend : str, optional
        joblib backend ('loky', the default; 'threading'; 'dask' with a
        running ``dask.distributed`` client).

    Returns
    -------
    CampbellDiagram

    Raises
    ------
    ValueError
        If the models do not all have the same number of states, or the
        values are not strictly monotonic.

    Examples
    --------
    A blade with a lag spring, seen from the hub: its two whirl modes move
    apart as ``ω ± Ω``:

    >>> def blade(Om):
    ...     A = np.array([[0.0, 1.0], [-4.0, -0.1]])
    ...     return ltp.ltpss(A, np.zeros((2, 0)), np.zeros((0, 2)), 0,
    ...                      period=2 * np.pi / Om)
    >>> cd = ltp.campbell(blade, np.linspace(0.5, 3.0, 6), n_jobs=1)
    >>> cd.frequency.shape
    (6, 2)
    >>> bool(np.allclose(cd.frequency, np.hypot(0.05, np.sqrt(4 - 0.05**2))))
    True
    """
    if not callable(factory):
        raise ControlArgument(f"factory must be a callable value -> LTPStateSpace, got "
                              f"{type(factory).__name__}")
    values = real_array(values, 'values', ndim=1)
    if len(values) < 2:
        raise ValueError("values must hold at least two sweep values")
    steps = np.diff(values)
    if not (np.all(steps > 0) or np.all(steps < 0)):
        raise ValueError("values must be strictly monotonic")
    if rotor_speed is None:
        speeds = values.copy()
    elif callable(rotor_speed):
        speeds = np.array([float(rotor_speed(v)) for v in values])
    else:
        speeds = real_array(rotor_speed, 'rotor_speed', ndim=1)
        if speeds.shape != values.shape:
            raise ValueError(f"rotor_speed must have one value per sweep value "
                             f"({len(values)}), got {len(speeds)}")
    jobs = _jobs(n_jobs, len(values))
    if isinstance(frame, str) and frame != 'multiblade':
        raise ValueError(f"frame must be 'multiblade', a matrix, a PeriodicMatrix or a "
                         f"callable, got {frame!r}")
    kwargs = dict(frame=frame, nharmonics=nharmonics)
    if jobs == 1 and backend is None:
        modes = [_modes_at(factory, v, w, kwargs) for v, w in zip(values, speeds)]
    else:
        import joblib
        with joblib.parallel_config(backend=backend or 'loky', n_jobs=jobs):
            modes = joblib.Parallel()(joblib.delayed(_modes_at)(factory, v, w, kwargs)
                                      for v, w in zip(values, speeds))
    sizes = {len(m) for m in modes}
    if len(sizes) != 1:
        raise ValueError(f"the models of the sweep have different numbers of states {sizes}")
    n = sizes.pop()
    K = len(values)
    perm = np.zeros((K, n), int)
    perm[0] = np.arange(n)
    mac = np.zeros((K - 1, n))
    modes = list(modes)
    for k in range(1, K):
        prev, cur = modes[k - 1], modes[k]
        cost, macs = _cost(prev, cur)
        # rows: the tracks' modes at k-1 (in their order perm[k-1])
        rows, cols = linear_sum_assignment(cost[perm[k - 1]])
        perm[k, rows] = cols
        mac[k - 1, rows] = macs[perm[k - 1][rows], cols]
        # modes of a repeated exponent: the basis that follows the previous shapes
        modes[k] = _follow(prev, cur, perm[k - 1][rows], cols)
    pick = lambda attr: np.array([getattr(m, attr)[p] for m, p in zip(modes, perm)])
    exps, hstar = pick('exponents'), pick('principal_harmonic')
    if branch not in ('continuous', 'principal'):
        raise ValueError(f"branch must be 'continuous' or 'principal', got {branch!r}")
    if branch == 'continuous' and not modes[0].dt:
        strip = pick('strip_exponents')
        for k in range(1, K):
            wp = 2 * np.pi / modes[k].period
            # the branch strip + j m ω_p nearest to the previous exponent
            m = np.round((exps[k - 1] - strip[k]).imag / wp)
            exps[k], hstar[k] = strip[k] + 1j * m * wp, m.astype(int)
    freq = np.abs(exps)
    with np.errstate(invalid='ignore', divide='ignore'):
        damping = np.where(freq > 0, -exps.real / np.where(freq > 0, freq, 1.0),
                           -np.sign(exps.real))
    crossings = []
    # one track of each complex pair: those turning forward at most values
    upper = [k for k in range(n) if np.mean(exps[:, k].imag >= 0) >= 0.5]
    for track in upper:
        for nrev in per_rev:
            for value in _zeros(values, freq[:, track] - nrev * speeds):
                crossings.append((track, int(nrev), float(value),
                                  float(nrev * np.interp(value, values, speeds)
                                        if steps[0] > 0 else
                                        nrev * np.interp(value, values[::-1], speeds[::-1]))))
    return CampbellDiagram(values=values, exponents=exps, frequency=freq,
                           damped_frequency=exps.imag, damping=damping,
                           principal_harmonic=hstar, mac=mac,
                           rotor_speed=speeds, crossings=crossings, modes=tuple(modes),
                           indices=perm)


def _modes_at(factory, value, speed, kwargs):
    sys = factory(value)
    if isinstance(sys, ct.StateSpace) and not isinstance(sys, LTPStateSpace):
        # an LTI model (e.g. an azimuth average) viewed over one revolution
        if sys.isdtime(strict=True):
            raise ControlArgument("factory(value) returned a discrete-time LTI model: "
                                  "return an LTPStateSpace")
        sys = as_ltp(sys, 'factory(value)',
                     period=2 * np.pi / speed if speed > 0 else 2 * np.pi)
    sys = as_ltp(sys, 'factory(value)')
    kwargs = dict(kwargs)
    if isinstance(kwargs['frame'], str):
        kwargs['frame'] = _multiblade_frame(sys)
    return floquet_modes(sys, **kwargs)


def _multiblade_frame(sys):
    """``T(t)⁻¹`` of the multi-blade transform of a rotating-frame rotor model."""
    if not isinstance(sys, RotorStateSpace) or sys.frame != 'rotating':
        raise ValueError("frame='multiblade' needs rotor models in the rotating frame "
                         "(read_lin, or a RotorStateSpace with rotating-frame flags)")
    _, P = mbc(sys, nblades=sys.nblades or 3)
    return PeriodicMatrix.from_function(lambda t: np.linalg.inv(P(t)), P.period, P.shape,
                                        check=False)


def _jobs(n_jobs, nvalues):
    cores = os.cpu_count() or 1
    if n_jobs is None or n_jobs == -1:
        return max(1, min(cores, nvalues))
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, (int, np.integer)) or n_jobs < 1:
        raise ControlArgument(f"n_jobs must be a positive integer or -1, got {n_jobs!r}")
    return int(min(n_jobs, cores, nvalues))


def _repeated(modes, tol=1e-6):
    """Groups (size > 1) of modes with equal exponents (relative `tol`)."""
    lam = modes.exponents
    scale = max(np.abs(lam).max(initial=0.0), 1e-300)
    out, done = [], np.zeros(len(lam), bool)
    for i in range(len(lam)):
        if done[i]:
            continue
        g = np.flatnonzero((np.abs(lam - lam[i]) <= tol * scale) & ~done)
        done[g] = True
        if len(g) > 1:
            out.append(g)
    return out


def _follow(prev, cur, src, dst):
    """`cur` with the basis of each repeated exponent rotated to follow `prev`'s shapes."""
    groups = _repeated(cur)
    if not groups:
        return cur
    keep = min(prev.shapes.shape[-1], cur.shapes.shape[-1]) // 2
    U, V = _harmonics(prev.shapes, keep), _harmonics(cur.shapes, keep)
    vectors, left, shapes = cur.vectors.copy(), cur.left_vectors.copy(), cur.shapes.copy()
    match = dict(zip(dst, src))
    for g in groups:
        targets = [match[j] for j in g if j in match]
        if len(targets) != len(g) or not np.all(np.isfinite(V[g])):
            continue
        # R: the combinations of the group's shapes nearest the previous ones
        R = np.linalg.lstsq(V[g].T, U[targets].T, rcond=None)[0]
        norms = np.linalg.norm(cur.vectors[:, g] @ R, axis=0)
        if np.any(norms == 0) or np.linalg.cond(R) > 1e8:
            continue
        R = R / norms
        vectors[:, g] = cur.vectors[:, g] @ R
        left[:, g] = cur.left_vectors[:, g] @ np.linalg.inv(R).conj().T
        shapes[:, g] = np.einsum('rit,ij->rjt', cur.shapes[:, g], R)
    return replace(cur, vectors=vectors, left_vectors=left, shapes=shapes)


def _subspace_mac(X, Y, groups):
    """MAC of the rows of X with the span of each group of rows of Y (mode, coords)."""
    out = {}
    for g in groups:
        Q, _ = np.linalg.qr(Y[g].T)
        proj = np.sum(np.abs(np.conj(Q).T @ X.T) ** 2, axis=0)
        out[tuple(g)] = proj / np.maximum(np.sum(np.abs(X) ** 2, axis=1), 1e-300)
    return out


def _cost(prev, cur):
    """Assignment cost and MAC between the modes of two neighbouring values."""
    # MAC over the period = MAC of the Fourier coefficients (Parseval), on the
    # harmonics both sweep values resolve
    keep = min(prev.shapes.shape[-1], cur.shapes.shape[-1]) // 2
    U, V = (_harmonics(m.shapes, keep) for m in (prev, cur))
    cross = np.abs(np.conj(U) @ V.T) ** 2
    norms = np.outer(np.sum(np.abs(U) ** 2, axis=1), np.sum(np.abs(V) ** 2, axis=1))
    macs = np.divide(cross, norms, out=np.zeros_like(cross), where=norms > 0)
    # a repeated exponent has a subspace of shapes: MAC with the subspace
    if np.all(np.isfinite(U)) and np.all(np.isfinite(V)):
        for g, m in _subspace_mac(U, V, _repeated(cur)).items():
            macs[:, list(g)] = np.maximum(macs[:, list(g)], m[:, None])
        for g, m in _subspace_mac(V, U, _repeated(prev)).items():
            macs[list(g), :] = np.maximum(macs[list(g), :], m[None, :])
    lam_u, lam_v = prev.exponents, cur.exponents
    scale = max(np.abs(lam_u).max(), np.abs(lam_v).max(), 1e-300)
    dist = np.abs(lam_u[:, None] - lam_v[None, :]) / scale
    sign = np.sign(np.round(prev.damped_frequency / scale, 9))[:, None] * \
        np.sign(np.round(cur.damped_frequency / scale, 9))[None, :]
    return 1 - macs + dist + (sign < 0), macs


def _harmonics(shapes, keep):
    """Coefficients of harmonics -keep..keep of shapes (r, mode, S), as (mode, r*H)."""
    S = shapes.shape[-1]
    c = np.fft.fft(np.nan_to_num(shapes), axis=-1) / S
    c = c[..., np.arange(-keep, keep + 1) % S]
    return c.transpose(1, 0, 2).reshape(shapes.shape[1], -1)


def _zeros(x, d):
    """Zeros of the piecewise-linear function through ``(x_k, d_k)``."""
    out = []
    for k in range(len(x) - 1):
        a, b = d[k], d[k + 1]
        if a == 0:
            out.append(x[k])
        elif a * b < 0:
            out.append(x[k] + (x[k + 1] - x[k]) * a / (a - b))
    if len(d) and d[-1] == 0:
        out.append(x[-1])
    return np.array(out)
