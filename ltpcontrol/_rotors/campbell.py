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
from dataclasses import dataclass

import numpy as np
import control as ct
from control.exception import ControlArgument
from scipy.optimize import linear_sum_assignment

from .._analysis.floquet_modes import floquet_modes
from .._core.coerce import as_ltp
from .._core.validation import real_array

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
        The modes at each value (in their own order).

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

    def __repr__(self):
        return (f"<CampbellDiagram: {self.frequency.shape[1]} tracks over "
                f"{len(self.values)} values>")

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

    def plot(self, ax=None, *, per_rev=(1, 2, 3), tracks=None, title=None):
        """Campbell diagram: frequency and damping ratio against the sweep value.

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
        >>> cplt = cd.plot()
        >>> cplt.axes.shape
        (2, 1)
        """
        import matplotlib.pyplot as plt
        if ax is None:
            fig, ax = plt.subplots(2, 1, sharex=True, squeeze=False)
            ax = ax[:, 0]
        else:
            ax = np.asarray(ax).ravel()
            if ax.size != 2:
                raise ControlArgument("ax must hold two axes (frequency, damping)")
            fig = ax[0].figure
        if tracks is None:
            tracks = [k for k in range(self.frequency.shape[1])
                      if np.mean(self.damped_frequency[:, k] >= 0) >= 0.5]
        lines = np.empty((2, 1), dtype=object)
        freq_lines, damp_lines = [], []
        for k in tracks:
            freq_lines += ax[0].plot(self.values, self.frequency[:, k], label=f'track {k}')
            damp_lines += ax[1].plot(self.values, self.damping[:, k],
                                     color=freq_lines[-1].get_color())
        for n in per_rev:
            freq_lines += ax[0].plot(self.values, n * self.rotor_speed, 'k--', lw=0.7)
            ax[0].annotate(f'{n}P', (self.values[-1], n * self.rotor_speed[-1]),
                           fontsize='small')
        for _, n, value, freq in self.crossings:
            if n in per_rev:
                ax[0].plot(value, freq, 'ko', ms=3)
        ax[1].axhline(0, color='k', lw=0.5)
        ax[0].set_ylabel('frequency [rad/s]')
        ax[1].set_ylabel('damping ratio')
        ax[1].set_xlabel('sweep value')
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
    kwargs = dict(frame=frame, nharmonics=nharmonics)
    if jobs == 1 and backend is None:
        modes = [_modes_at(factory, v, kwargs) for v in values]
    else:
        import joblib
        with joblib.parallel_config(backend=backend or 'loky', n_jobs=jobs):
            modes = joblib.Parallel()(joblib.delayed(_modes_at)(factory, v, kwargs)
                                      for v in values)
    sizes = {len(m) for m in modes}
    if len(sizes) != 1:
        raise ValueError(f"the models of the sweep have different numbers of states {sizes}")
    n = sizes.pop()
    K = len(values)
    perm = np.zeros((K, n), int)
    perm[0] = np.arange(n)
    mac = np.zeros((K - 1, n))
    for k in range(1, K):
        prev, cur = modes[k - 1], modes[k]
        cost, macs = _cost(prev, cur)
        # rows: the tracks' modes at k-1 (in their order perm[k-1])
        rows, cols = linear_sum_assignment(cost[perm[k - 1]])
        perm[k, rows] = cols
        mac[k - 1, rows] = macs[perm[k - 1][rows], cols]
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
    for track in range(n):
        for nrev in per_rev:
            for value in _zeros(values, freq[:, track] - nrev * speeds):
                crossings.append((track, int(nrev), float(value),
                                  float(nrev * np.interp(value, values, speeds)
                                        if steps[0] > 0 else
                                        nrev * np.interp(value, values[::-1], speeds[::-1]))))
    return CampbellDiagram(values=values, exponents=exps, frequency=freq,
                           damped_frequency=exps.imag, damping=damping,
                           principal_harmonic=hstar, mac=mac,
                           rotor_speed=speeds, crossings=crossings, modes=tuple(modes))


def _modes_at(factory, value, kwargs):
    sys = as_ltp(factory(value), 'factory(value)')
    return floquet_modes(sys, **kwargs)


def _jobs(n_jobs, nvalues):
    cores = os.cpu_count() or 1
    if n_jobs is None or n_jobs == -1:
        return max(1, min(cores, nvalues))
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, (int, np.integer)) or n_jobs < 1:
        raise ControlArgument(f"n_jobs must be a positive integer or -1, got {n_jobs!r}")
    return int(min(n_jobs, cores, nvalues))


def _cost(prev, cur):
    """Assignment cost and MAC between the modes of two neighbouring values."""
    # MAC over the period = MAC of the Fourier coefficients (Parseval), on the
    # harmonics both sweep values resolve
    keep = min(prev.shapes.shape[-1], cur.shapes.shape[-1]) // 2
    U, V = (_harmonics(m.shapes, keep) for m in (prev, cur))
    cross = np.abs(np.conj(U) @ V.T) ** 2
    norms = np.outer(np.sum(np.abs(U) ** 2, axis=1), np.sum(np.abs(V) ** 2, axis=1))
    macs = np.divide(cross, norms, out=np.zeros_like(cross), where=norms > 0)
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
