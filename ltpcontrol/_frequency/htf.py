"""Harmonic transfer functions (HTF) of LTP systems.

Convention (Wereley; stated on the Conventions page): with exponentially
modulated periodic signals ``u(t) = Σ_m U_m e^{(s + jmω_p)t}``, the truncated
HTF at ``s`` is the ``(2K+1)ny x (2K+1)nu`` matrix with blocks ``H_{n,m}``,
n, m = -K..K, such that ``Y_n = Σ_m H_{n,m}(s) U_m``.  The thesis components
are ``G_k(s) = H_{0,-k}(s)``, so that ``Y(jω) = Σ_k G_k(jω) U(jω - jkω_p)``
and ``H_{n,m}(s) = G_{n-m}(s + jnω_p)``.

As python-control separates `StateSpace` from `FrequencyResponseData`, an
HTF is either an `HTFModel` (from a system, evaluated anywhere through its
harmonic state space) or an `HTFData` (components sampled on a frequency
grid, e.g. estimated from data); `HTF` is their common interface.
Frequency is the last axis of every array result, as in python-control.
"""

import abc
import warnings

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension

from .. import config
from .harmonic_ss import build, marked_ss
from .._core.coerce import as_ltp
from .._core.validation import check_period, check_positive_int, real_array
from .._core.registry import aliased, method_alias, overridden

__all__ = ['HTF', 'HTFModel', 'HTFData', 'htf']


class HTF(abc.ABC):
    """Harmonic transfer function: the interface of `HTFModel` and `HTFData`.

    An abstract class, not instantiated itself: `htf` builds the HTF of a
    system (`HTFModel`), `HTFData` holds components sampled on a frequency
    grid, and ``HTF(...)`` raises a `control.ControlArgument` naming both.
    Both are evaluated, plotted and converted through the methods below.

    Attributes
    ----------
    nharmonics : int
        Number K of harmonics (blocks and components -K..K).
    period : float
        The period T.
    dt : float
        Sampling time (0 in continuous time).
    ninputs, noutputs : int
        Numbers of input and output signals.
    input_labels, output_labels : list of str
        Signal names.
    name : str
        Name used in plots.

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> H = ltp.htf(sys, 1)
    >>> w, G = H.components([1.0, 2.0])
    >>> D = ltp.HTFData(G, w, period=1.0)
    >>> isinstance(H, ltp.HTF), isinstance(D, ltp.HTF), type(D).__name__
    (True, True, 'HTFData')
    """

    def __new__(cls, *args, **kwargs):
        if cls is HTF:
            raise ControlArgument(
                "HTF is the common interface of HTFModel and HTFData and is not created "
                "directly: use ltp.htf(sys, nharmonics) for the HTF of a system, or "
                "ltp.HTFData(components, omega, period) for components on a grid")
        return super().__new__(cls)

    def _set_signals(self, period, nharmonics, noutputs, ninputs, dt, name, inputs,
                     outputs):
        """The attributes every HTF has (called by the constructors)."""
        self.period = check_period(period)
        self.nharmonics = nharmonics
        self.noutputs, self.ninputs = noutputs, ninputs
        self.dt = dt
        self.name = name if name is not None else 'htf'
        self.input_labels = _labels(inputs, ninputs, 'u', 'inputs')
        self.output_labels = _labels(outputs, noutputs, 'y', 'outputs')

    @property
    def omega_p(self):
        """Fundamental frequency ``ω_p = 2π/T`` in rad/s."""
        return 2 * np.pi / self.period

    @property
    def harmonics(self):
        """Harmonic indices ``-K..K``."""
        return np.arange(-self.nharmonics, self.nharmonics + 1)

    def isdtime(self):
        """True for the HTF of a discrete-time system."""
        return self.dt > 0

    def __repr__(self):
        return (f"<{type(self).__name__} {self.name}: {self.input_labels} -> "
                f"{self.output_labels}, K={self.nharmonics}, period={self.period:g}>")

    #
    # Evaluation
    #

    def __call__(self, s, *, progress=None):
        """Evaluate the block matrix ``H(s)`` (``H(z)`` in discrete time).

        Long requests are evaluated in chunks of points whose working
        memory stays within ``ltp.config.defaults['htf.max_memory']``; a
        request that cannot fit raises `MemoryError` with its estimated
        size.

        Parameters
        ----------
        s : complex or 1D array_like of complex
            Evaluation points.  An `HTFData` accepts only ``s = jω`` with
            every ``ω + nω_p`` (n = -K..K) on its grid.
        progress : bool, optional
            Show a progress bar over the chunks (default
            ``ltp.config.defaults['htf.progress']``).

        Returns
        -------
        ndarray
            Shape ``((2K+1)ny, (2K+1)nu)`` for scalar `s`, else
            ``((2K+1)ny, (2K+1)nu, len(s))``: the points on the last axis,
            as `control.StateSpace.__call__` returns them.

        Examples
        --------
        >>> H = ltp.htf(ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=np.pi), 1)
        >>> np.round(H(0.0).diagonal(), 3)      # 1/(jnω_p + 1), ω_p = 2
        array([0.2+0.4j, 1. +0.j , 0.2-0.4j])
        >>> H([0.0, 1j]).shape
        (3, 3, 2)
        """
        sarr = real_array(s, 's', ndim=(0, 1), allow_complex=True).astype(complex)
        out = self._evaluate(np.atleast_1d(sarr), progress)
        return out[0] if sarr.ndim == 0 else np.moveaxis(out, 0, -1)

    def component(self, k, omega=None, *, name=None):
        """Component ``G_k(jω) = H_{0,-k}(jω)`` as a `control.FrequencyResponseData`.

        Parameters
        ----------
        k : int
            Harmonic index in -K..K.
        omega : array_like, optional
            Frequencies in rad/s.  An `HTFData` uses its grid (a given
            `omega` must be a subset of it); an `HTFModel` uses the default
            grid (`ltpcontrol.htf_response`) when omitted.
        name : str, optional
            Name of the FRD (default ``'<htf name> G_k'``).

        Returns
        -------
        control.FrequencyResponseData

        Examples
        --------
        >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
        >>> G0 = ltp.htf(sys, 2).component(0, [1.0])
        >>> np.round(G0.frdata[0, 0, 0], 6)
        np.complex128(0.5-0.5j)
        """
        return self._frds([_harmonic(k, self.nharmonics)], omega, name=name)[0]

    def components(self, omega=None):
        """Frequencies and all components ``G_k(jω)``, k = -K..K, as arrays.

        Parameters
        ----------
        omega : array_like, optional
            Frequencies in rad/s (see `component`).

        Returns
        -------
        omega : ndarray
            The frequencies, shape (F,).
        G : ndarray of complex, shape (2K+1, ny, nu, F)
            ``G[k + K]`` is ``G_k``; frequency is the last axis.

        Examples
        --------
        >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
        >>> w, G = ltp.htf(sys, 1).components([1.0, 2.0])
        >>> G.shape
        (3, 1, 1, 2)
        """
        return self._components_on(omega, list(self.harmonics))

    def to_frd(self, omega=None, *, name=None):
        """The central block row as one FRD with harmonic input channels.

        The FRD maps the stacked inputs ``U(jω - jkω_p)``, k = -K..K (input
        names ``'u<k>'``), to ``Y(jω)``, i.e. ``[G_{-K} ... G_K]`` (eq. 3.27).

        Parameters
        ----------
        omega : array_like, optional
            Frequencies in rad/s (see `component`).
        name : str, optional
            Name of the FRD.

        Returns
        -------
        control.FrequencyResponseData

        Examples
        --------
        >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
        >>> ltp.htf(sys, 1).to_frd([1.0]).ninputs
        3
        """
        omega, G = self.components(omega)
        data = np.concatenate(list(G), axis=1)       # (ny, (2K+1) nu, nw)
        inputs = [f"{u}<{k}>" for k in self.harmonics for u in self.input_labels]
        return ct.frd(data, omega, name=name or self.name, inputs=inputs,
                      outputs=self.output_labels, dt=self.dt if self.dt else 0)

    def predict(self, timepts, inputs):
        """Output predicted by the HTF for an input signal (steady state).

        The input is transformed by FFT, ``Y(jω) = Σ_k G_k(jω) U(jω - jkω_p)``
        is formed on the FFT grid and transformed back (as the thesis does
        for Figs. 3.14/3.16).  The record is treated as one period of a
        periodic signal, so its length must be an integer number of periods.
        An `HTFData` is interpolated linearly between its frequencies and
        taken as zero outside its grid.

        Parameters
        ----------
        timepts : array_like, shape (L,)
            Uniform time points; ``L dt`` must be a multiple of the period.
        inputs : array_like, shape (nu, L) or (L,)
            Input samples.

        Returns
        -------
        resp : control.TimeResponseData
            ``resp.outputs`` of shape ``(ny, L)`` (squeezed to ``(L,)`` for
            a single-input, single-output HTF, as python-control does).

        Raises
        ------
        ValueError
            If `timepts` is not uniform, or the arguments are given in the
            order ``(inputs, timepts)`` of earlier versions.

        Examples
        --------
        >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
        >>> t = np.arange(400) * 0.01
        >>> y = ltp.htf(sys, 1).predict(t, np.cos(2 * np.pi * t)).outputs
        >>> G = 1 / (2j * np.pi + 1)
        >>> bool(np.allclose(y, abs(G) * np.cos(2 * np.pi * t + np.angle(G))))
        True
        """
        if not _is_time_vector(timepts) and _is_time_vector(inputs):
            raise ValueError("predict takes (timepts, inputs), python-control's order; "
                             "the inputs given look like time points and the time points "
                             "do not: pass predict(t, u)")
        t = real_array(timepts, 'timepts', ndim=1)
        u = real_array(inputs, 'inputs', ndim=(1, 2))
        u = np.atleast_2d(u)
        if u.shape != (self.ninputs, len(t)):
            raise ControlDimension(f"inputs must have shape ({self.ninputs}, {len(t)}), "
                                   f"got {u.shape}")
        L = len(t)
        if not _is_time_vector(t):
            raise ValueError("timepts must be increasing and uniformly spaced with at "
                             "least two points")
        h = t[1] - t[0]
        shift = L * h / self.period
        r = int(round(shift))
        if r < 1 or abs(shift - r) > 1e-6 * shift:
            raise ValueError(f"the record length {L * h:g} must be an integer number of "
                             f"periods ({self.period:g}) for an HTF prediction")
        U = np.fft.fft(u, axis=1)
        wbin = 2 * np.pi * np.fft.fftfreq(L, h)
        # G_k at negative frequencies from G_k(-jω) = conj(G_{-k}(jω))
        G = self._spectrum(np.abs(wbin), list(self.harmonics))
        neg = wbin < 0
        G[:, :, :, neg] = np.conj(G[::-1][:, :, :, neg])
        Y = np.zeros((self.noutputs, L), complex)
        unknown = 0.0
        for i, k in enumerate(self.harmonics):
            # U(jω - jkω_p) is bin b - k r
            Uk = np.roll(U, k * r, axis=1)
            miss = np.isnan(G[i])
            if miss.any():
                # energy of the input terms whose component the data left undetermined
                unknown = max(unknown, float(np.max(np.abs(Uk)[None] * miss, initial=0.0)))
                G[i][miss] = 0
            Y += np.einsum('ijb,jb->ib', G[i], Uk)
        if unknown > 1e-3 * np.abs(U).max():
            warnings.warn("the input excites HTF components that the data did not "
                          "identify; those terms are taken as zero", UserWarning,
                          stacklevel=2)
        y = np.fft.ifft(Y, axis=1).real
        return ct.TimeResponseData(t, y, None, u, issiso=self.ninputs == self.noutputs == 1,
                                   output_labels=self.output_labels,
                                   input_labels=self.input_labels,
                                   title=f"HTF prediction of {self.name}")

    def plot(self, *args, **kwargs):
        """Bode plot of selected components; see `ltpcontrol.bode_htf`.

        Examples
        --------
        >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
        >>> type(ltp.htf(sys, 1).plot(omega_num=20)).__name__
        'ControlPlot'
        """
        return aliased('bode_htf')(self, *args, **kwargs)

    #
    # What each kind provides
    #

    @abc.abstractmethod
    def _evaluate(self, s, progress):
        """``H(s)`` at the points `s` (1D), shape (len(s), rows, cols)."""

    @abc.abstractmethod
    def _components_on(self, omega, ks, progress=None):
        """(omega, G) with G of shape (len(ks), ny, nu, F) for harmonics `ks`."""

    def _spectrum(self, omega, ks):
        """Components at any frequencies >= 0 (for `predict`)."""
        return self._components_on(omega, ks)[1]

    def _frds(self, ks, omega=None, name=None, progress=None):
        """Components ``G_k`` for all `ks` from ONE evaluation of the block row."""
        omega, G = self._components_on(omega, ks, progress=progress)
        return [ct.frd(Gk, omega, name=name or f"{self.name} G_{k}",
                       inputs=self.input_labels, outputs=self.output_labels,
                       dt=self.dt if self.dt else 0) for k, Gk in zip(ks, G)]


class HTFModel(HTF):
    """Harmonic transfer function of an LTP system, evaluated anywhere.

    Built by `htf` (same parameters).  The harmonic state space is formed
    once; every evaluation solves it at the requested points (Conventions
    page: continuous time truncated at ``internal_harmonics``, discrete
    time exact).

    Parameters
    ----------
    sys : LTPStateSpace or control.StateSpace
        The system (an LTI system needs `period`).
    nharmonics : int
        Number K >= 0 of harmonics.
    internal_harmonics : int, optional
        Truncation of the harmonic state space (see `htf`).
    method : {'auto', 'modal', 'solve'}
        Evaluation method (see `htf`).
    period : float, optional
        Period for an LTI `sys`.

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, name='plant')
    >>> ltp.HTFModel(sys, 2)
    <HTFModel plant: ['u[0]'] -> ['y[0]'], K=2, period=1>
    """

    def __init__(self, sys, nharmonics, *, internal_harmonics=None, method='auto',
                 period=None):
        sys = as_ltp(sys, 'sys', period=period)
        K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
        self._set_signals(sys.period, K, sys.noutputs, sys.ninputs, sys.dt, sys.name,
                         sys.input_labels, sys.output_labels)
        self._states = list(sys.state_labels)
        self._source = (sys, internal_harmonics, method)       # what `save` stores
        # user -> htf -> HTFModel -> build
        self._hss = build(sys, K, internal_harmonics, method, 'htf', stacklevel=3)

    def to_ss(self, name=None, *, edge='warn'):
        """Real harmonic state space; see `ltpcontrol.harmonic_ss`.

        Parameters
        ----------
        name : str, optional
            Name of the result (default ``'<name>$harmonic'``).
        edge : {'warn', 'ignore', 'drop'}
            The truncation-edge eigenvalues, as in `ltpcontrol.harmonic_ss`:
            marked in ``.modes`` and warned about, marked only, or removed.

        Returns
        -------
        control.StateSpace
            With ``.modes`` (`HarmonicModes`), as `ltpcontrol.harmonic_ss`.

        Examples
        --------
        >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
        >>> ltp.htf(sys, 1).to_ss().ninputs
        3
        """
        if self.isdtime():
            raise ValueError("to_ss: the HTF is discrete-time; lift() the system instead")
        return marked_ss(self._source[0], self._hss, edge, name)

    def _evaluate(self, s, progress):
        return self._hss.evaluate(s, progress=progress)

    def _components_on(self, omega, ks, progress=None):
        omega = (default_omega(self) if omega is None
                 else real_array(omega, 'omega', ndim=(0, 1)).reshape(-1))
        s = np.exp(1j * omega * self.dt) if self.dt else 1j * omega
        # G_k = H_{0,-k}: central block row, block column -k
        G = self._hss.evaluate(s, rows=[0], cols=[-k for k in ks], progress=progress)
        G = G.reshape(len(s), self.noutputs, len(ks), self.ninputs).transpose(2, 1, 3, 0)
        return omega, G


class HTFData(HTF):
    """Harmonic transfer function sampled on a frequency grid.

    The analogue of `control.FrequencyResponseData`: the components
    ``G_k(jω)``, k = -K..K, on the frequencies `omega`, for example from
    `estimate_htf`.

    Parameters
    ----------
    components : array_like, shape (2K+1, ny, nu, F)
        ``G_k(jω)`` for k = -K..K on the grid `omega`; NaN marks a
        component that the data do not determine at that frequency.
    omega : array_like, shape (F,)
        Frequencies in rad/s (increasing).
    period : float
        Period T of the system.
    std : array_like, optional
        Standard deviations of the components (same shape).
    name : str, optional
        Name used in plots.
    inputs, outputs : list of str, optional
        Signal names.

    Attributes
    ----------
    omega : ndarray
        The frequency grid.
    std : ndarray or None
        Standard deviations of the components.

    Examples
    --------
    >>> omega = np.linspace(0.1, 10, 50)
    >>> G = np.zeros((3, 1, 1, 50), complex)
    >>> G[1, 0, 0] = 1 / (1j * omega + 1)
    >>> H = ltp.HTFData(G, omega, period=1.0, name='estimate')
    >>> H.nharmonics, H.component(0).ninputs
    (1, 1)
    """

    def __init__(self, components, omega, period, *, std=None, name=None, inputs=None,
                 outputs=None):
        comps = _data_array(components, 'components', allow_complex=True)
        if comps.shape[0] % 2 != 1:
            raise ControlDimension("components must have 2K+1 harmonics on axis 0, "
                                   f"got {comps.shape[0]}")
        omega = real_array(omega, 'omega', ndim=1)
        if comps.shape[3] != len(omega):
            raise ControlDimension(f"components has {comps.shape[3]} frequencies but "
                                   f"omega has {len(omega)}")
        if np.any(np.diff(omega) <= 0):
            raise ValueError("omega must be strictly increasing")
        if std is not None:
            std = _data_array(std, 'std')
            if std.shape != comps.shape:
                raise ControlDimension(f"std must have shape {comps.shape}, got {std.shape}")
        self._set_signals(period, comps.shape[0] // 2, comps.shape[1], comps.shape[2], 0.0,
                         name, inputs, outputs)
        self._components = comps.astype(complex)
        self.omega = omega
        self.std = std

    def __repr__(self):
        return super().__repr__()[:-1] + f", {len(self.omega)} frequencies>"

    def _evaluate(self, s, progress):
        if np.any(np.abs(s.real) > 0):
            raise ValueError("an HTFData can only be evaluated on the imaginary axis (s = jω)")
        K, ny, nu = self.nharmonics, self.noutputs, self.ninputs
        out = np.zeros((len(s), (2 * K + 1) * ny, (2 * K + 1) * nu), complex)
        for a, n in enumerate(self.harmonics):
            # H_{n,m}(jω) = G_{n-m}(jω + jnω_p), zero beyond |n - m| <= K
            _, G = self._components_on(s.imag + n * self.omega_p, list(self.harmonics))
            for b, m in enumerate(self.harmonics):
                if abs(n - m) <= K:
                    out[:, a * ny:(a + 1) * ny, b * nu:(b + 1) * nu] = \
                        G[n - m + K].transpose(2, 0, 1)
        return out

    def _components_on(self, omega, ks, progress=None):
        idx = [k + self.nharmonics for k in ks]
        if omega is None:
            return self.omega.copy(), self._components[idx].copy()
        omega = real_array(omega, 'omega', ndim=(0, 1)).reshape(-1)
        pos = np.clip(np.searchsorted(self.omega, omega), 0, len(self.omega) - 1)
        if not np.allclose(self.omega[pos], omega, rtol=1e-10, atol=1e-12):
            raise ValueError("omega must be a subset of the frequency grid of an HTFData")
        return omega, self._components[idx][..., pos]

    def _spectrum(self, omega, ks):
        # linear interpolation on the grid, zero outside it
        idx = [k + self.nharmonics for k in ks]
        G = np.zeros((len(ks), self.noutputs, self.ninputs, len(omega)), complex)
        inside = (omega >= self.omega[0]) & (omega <= self.omega[-1])
        flat = self._components[idx].reshape(-1, len(self.omega))
        G.reshape(-1, len(omega))[:, inside] = np.array(
            [np.interp(omega[inside], self.omega, row.real)
             + 1j * np.interp(omega[inside], self.omega, row.imag) for row in flat])
        return G


@method_alias
def htf(sys, nharmonics, *, internal_harmonics=None, method='auto', period=None):
    """Harmonic transfer function of an LTP system, truncated to K harmonics.

    Parameters
    ----------
    sys : LTPStateSpace or control.StateSpace
        Continuous- or discrete-time system (an LTI system needs the
        keyword `period`).
    nharmonics : int
        Number K >= 0 of harmonics of the returned HTF (blocks -K..K).
    internal_harmonics : int, optional
        Truncation order ``K_i >= K`` of the harmonic state space.  Only the
        central blocks are returned, which converge first.  Default: exact
        for a constant A with band-limited B, C, D (``K + K_B + K_C``);
        otherwise ``K + 10 + max(K_B, K_C)``, with a warning when a check
        against ``K_i + 8`` differs by more than 1e-6 (matrices with jumps
        converge only like ``K_i^{-3}``).  Ignored in discrete time, where
        the HTF is exact (all N harmonics are kept internally).
    method : {'auto', 'modal', 'solve'}
        'modal' diagonalises the harmonic state matrix once (block diagonal
        in Floquet form), 'solve' factorises ``sI - (A_T - N)`` at every
        point; 'auto' uses 'modal' unless its eigenvectors are
        ill-conditioned.
    period : float, optional
        Period of an LTI `sys` (an `LTPStateSpace` carries its own).

    Returns
    -------
    HTFModel

    Examples
    --------
    LTI limit: ``H_{n,n}(s) = G(s + jnω_p)``.

    >>> G = ct.tf([1], [1, 1])
    >>> H = ltp.htf(ct.ss(G), 2, period=2 * np.pi)
    >>> bool(np.isclose(H(0.5j)[3, 3], G(1.5j)))
    True
    """
    if (own := overridden('htf', sys)) is not None:            # systems with delays
        return own(sys, nharmonics, internal_harmonics=internal_harmonics, method=method,
                   period=period)
    return HTFModel(sys, nharmonics, internal_harmonics=internal_harmonics, method=method,
                    period=period)


def default_omega(H, omega_limits=None, omega_num=None):
    """Default frequency grid of a model HTF (`htf_response`, `components`).

    ``omega_num`` points (default ``ltp.config.defaults['htf.omega_num']``),
    logarithmically spaced from ``ω_p/100`` to ``10 K ω_p`` (below the
    Nyquist frequency in discrete time) unless `omega_limits` is given.

    Examples
    --------
    From ``ω_p/100`` to ``10 K ω_p``, here with ``ω_p = 1`` and K = 2:

    >>> from ltpcontrol._frequency.htf import default_omega
    >>> H = ltp.htf(ct.ss(ct.tf([1], [1, 1])), 2, period=2 * np.pi)
    >>> w = default_omega(H, omega_num=50)
    >>> len(w), round(float(w[0]), 6), round(float(w[-1]), 6)
    (50, 0.01, 20.0)
    >>> default_omega(H, (1.0, 100.0), 3)
    array([  1.,  10., 100.])
    """
    num = config._get('htf.omega_num', omega_num)
    num = check_positive_int(num, 'omega_num', minimum=2)
    if omega_limits is None:
        w = H.omega_p
        omega_limits = (w / 100, 10 * w * max(1, H.nharmonics))
        if H.dt:
            omega_limits = (omega_limits[0], min(omega_limits[1], 0.999 * np.pi / H.dt))
    lo, hi = real_array(omega_limits, 'omega_limits', ndim=1)
    if not 0 < lo < hi:
        raise ValueError(f"omega_limits must satisfy 0 < low < high, got {omega_limits}")
    return np.logspace(np.log10(lo), np.log10(hi), num)


#
# Helpers
#

def _is_time_vector(x):
    """True for a real, increasing, uniformly spaced 1D array of >= 2 points."""
    x = np.asarray(x)
    if x.ndim != 1 or x.size < 2 or x.dtype.kind not in 'iuf' or not np.all(np.isfinite(x)):
        return False
    step = np.diff(x)
    return bool(step[0] > 0 and np.allclose(step, step[0], rtol=1e-9, atol=0))


def _data_array(data, name, allow_complex=False):
    """4D array of an HTFData: finite values or NaN (not identified)."""
    arr = np.asarray(data)
    if arr.dtype.kind not in 'biufc':
        raise ControlArgument(f"{name} must be numeric, got dtype {arr.dtype}")
    if np.any(np.isinf(arr)):
        raise ValueError(f"{name} contains inf")
    return real_array(np.where(np.isnan(arr), 0, arr), name, ndim=4,
                      allow_complex=allow_complex) * np.where(np.isnan(arr), np.nan, 1)


def _harmonic(k, K):
    if isinstance(k, (bool, np.bool_)) or not isinstance(k, (int, np.integer)):
        raise ControlArgument(f"harmonic index k must be an integer, got {k!r}")
    if not -K <= k <= K:
        raise ValueError(f"harmonic index k={k} is outside -K..K with K={K}")
    return int(k)


def _labels(labels, count, prefix, name):
    if labels is None:
        return [f"{prefix}[{i}]" for i in range(count)]
    labels = [labels] if isinstance(labels, str) else list(labels)
    if len(labels) != count:
        raise ControlDimension(f"{name} has {len(labels)} names for {count} signals")
    return labels
