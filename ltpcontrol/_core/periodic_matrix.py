"""Real matrix-valued periodic functions of time.

A `PeriodicMatrix` ``P(t) = P(t + T)`` is stored in one of four forms:

* Fourier coefficients ``P(t) = Σ_{k=-K}^{K} P_k e^{jkω_p t}``, ``ω_p = 2π/T``;
* a callable ``f(t) -> (n, m)`` (smooth; coefficients by FFT);
* a switching form ``P(t) = Σ_i P^i(t) s^i(t)`` (thesis eqs. 4.3-4.4) whose
  pieces are active on ``[t_i, t_{i+1})``; evaluation keeps the exact
  discontinuities and the Fourier coefficients are computed exactly (closed
  form for constant or band-limited pieces, Gauss-Legendre quadrature between
  the switching instants otherwise);
* a pointwise combination of other periodic matrices (sums, products).

See the Conventions page of the documentation for the Fourier scaling.
"""

import math
import numbers
import warnings

import numpy as np
from control.exception import ControlDimension

from .display import describe
from .pm_ops import Block, Identity, Index, Scale, Transpose, add_series, mul_series
from .validation import as_matrix, check_period, check_positive_int, commensurate, real_array

__all__ = ['PeriodicMatrix']

# scalar time types evaluated on the fast path of a data-backed table
_FLOATS = (float, int, np.float64)

# Gauss-Legendre nodes used for Fourier coefficients of piecewise-smooth data
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(20)


class PeriodicMatrix:
    """Real matrix-valued T-periodic function of time.

    ``PeriodicMatrix(coeffs, period)`` builds ``P(t) = Σ_k P_k e^{jkω_p t}``
    from Fourier coefficients ``coeffs[k + K] = P_k``, k = -K..K, with
    ``ω_p = 2π/period``.  Use the class methods `constant`,
    `from_function`, `from_samples` and `switching` for the other forms.

    Parameters
    ----------
    coeffs : array_like, shape (2K+1, n, m)
        Fourier coefficients in ascending harmonic order.  They must be
        conjugate-symmetric (``P_{-k} = conj(P_k)``) so that ``P(t)`` is real.
    period : float
        Period T > 0 in seconds.

    Attributes
    ----------
    period : float
        The period T.
    shape : tuple of int
        Matrix shape ``(n, m)``.
    breakpoints : ndarray
        Instants in ``[0, T)`` where ``P(t)`` may jump (switching form).

    Examples
    --------
    >>> P = ltp.PeriodicMatrix([[[0.5]], [[1.0]], [[0.5]]], period=2 * np.pi)
    >>> float(P(0.0)[0, 0])            # 1 + cos(0)
    2.0
    >>> P.fourier(2).shape
    (5, 1, 1)
    """

    # make numpy defer to our reflected operators (ndarray @ PeriodicMatrix)
    __array_ufunc__ = None

    def __init__(self, coeffs, period):
        coeffs = real_array(coeffs, 'coeffs', ndim=(2, 3), allow_complex=True)
        if coeffs.ndim == 2:
            coeffs = coeffs[np.newaxis]
        if coeffs.shape[0] % 2 != 1:
            raise ValueError("coeffs must have an odd first dimension 2K+1 "
                             f"(harmonics -K..K), got {coeffs.shape[0]}")
        scale = max(1.0, np.max(np.abs(coeffs), initial=0.0))
        if np.max(np.abs(coeffs - np.conj(coeffs[::-1])), initial=0.0) > 1e-10 * scale:
            raise ValueError("coeffs must be conjugate-symmetric (P_{-k} = "
                             "conj(P_k)) so that the matrix is real-valued")
        coeffs = 0.5 * (coeffs + np.conj(coeffs[::-1]))
        self._init(period, coeffs.shape[1:], coeffs=coeffs.astype(complex))

    def _init(self, period, shape, coeffs=None, func=None, pieces=None,
              times=None, combine=None, breakpoints=()):
        self.period = check_period(period)
        self.shape = tuple(int(s) for s in shape)
        self._coeffs = coeffs           # exact finite Fourier series, or None
        self._func = func               # smooth callable, or None
        self._pieces = pieces           # switching form: list of PeriodicMatrix
        self._times = times             # switching instants t_1=0 < ... < t_M
        self._combine = combine         # (op, operands) pointwise combination
        self.breakpoints = np.unique(np.mod(np.asarray(breakpoints, float),
                                            self.period))
        self._cache = {}
        return self

    @classmethod
    def _new(cls, period, shape, **kwargs):
        return cls.__new__(cls)._init(period, shape, **kwargs)

    def _parts(self):
        """``(form, data)`` of the storage form (the file format of `ltpcontrol.save`)."""
        if self._coeffs is not None:
            return 'fourier', self._coeffs
        if self._pieces is not None:
            return 'switching', (list(self._pieces), self._times)
        return ('function', self._func) if self._func is not None else ('combine', self._combine)

    @classmethod
    def _assemble(cls, period, shape, breakpoints, form, data):
        """Inverse of `_parts` (data validated by the caller)."""
        keys = {'fourier': ('coeffs',), 'switching': ('pieces', 'times'),
                'function': ('func',), 'combine': ('combine',)}[form]
        data = data if len(keys) > 1 else (data,)
        return cls._new(period, shape, breakpoints=breakpoints, **dict(zip(keys, data)))

    def __getstate__(self):
        # a lambda or local function cannot be pickled: say how to get data
        for f in _callables(self):
            qual = getattr(f, '__qualname__', '')
            if '<lambda>' in qual or '<locals>' in qual:
                raise TypeError(
                    f"cannot pickle a PeriodicMatrix defined by the local function "
                    f"{qual}: define it at module level, or sample it, e.g. "
                    "PeriodicMatrix.from_samples(P.sample(N), P.period)")
        state = dict(self.__dict__)
        state['_cache'] = {}
        return state

    #
    # Alternative constructors
    #

    @classmethod
    def constant(cls, M, period):
        """Constant matrix viewed as a T-periodic matrix.

        Parameters
        ----------
        M : array_like, shape (n, m)
            Real matrix.
        period : float
            Period T > 0.

        Returns
        -------
        PeriodicMatrix

        Examples
        --------
        >>> P = ltp.PeriodicMatrix.constant([[1.0, 2.0]], period=1.0)
        >>> P(0.3)
        array([[1., 2.]])
        """
        M = as_matrix(M, 'M')
        return cls(M[np.newaxis], period)

    @classmethod
    def from_function(cls, func, period, shape=None, *, breakpoints=(), check=True):
        """Periodic matrix defined by a smooth callable ``func(t) -> (n, m)``.

        Parameters
        ----------
        func : callable
            Real T-periodic function of time returning a 2D array.  It is
            called with scalar times (and with 1D arrays when it supports
            them, returning shape ``(len(t), n, m)``).  Periodicity is
            checked at a few points.  For functions with jumps use
            `switching`, which keeps the discontinuities exactly.
        period : float
            Period T > 0.
        shape : tuple of int, optional
            Expected shape; taken from ``func(0)`` when omitted.
        breakpoints : array_like, optional
            Instants in ``[0, T)`` where `func` is not smooth (kinks of an
            interpolant, for example); integrators and quadratures restart
            there.
        check : bool, optional
            Probe `func` for periodicity (default True).  Pass False only for
            a function periodic by construction (for example an interpolant
            of one period's values, wrapped modulo T) to save its calls.

        Returns
        -------
        PeriodicMatrix

        Examples
        --------
        >>> P = ltp.PeriodicMatrix.from_function(
        ...     lambda t: np.array([[np.cos(t)]]), period=2 * np.pi)
        >>> np.round(P.fourier(1)[:, 0, 0].real, 12) + 0.0
        array([0.5, 0. , 0.5])
        """
        if not callable(func):
            raise TypeError(f"func must be callable, got {type(func).__name__}")
        period = check_period(period)
        if not check and shape is not None:
            return cls._new(period, shape, func=func, breakpoints=breakpoints)
        value = as_matrix(func(0.0), 'func(0)')
        if shape is not None and tuple(shape) != value.shape:
            raise ValueError(f"func returns shape {value.shape}, expected {tuple(shape)}")
        probe = np.array([0.123456, 0.5, 0.876543]) * period if check else ()
        for t in probe:
            a = as_matrix(func(t), 'func(t)')
            b = as_matrix(func(t + period), 'func(t + period)')
            if a.shape != value.shape:
                raise ValueError(f"func returns inconsistent shapes {value.shape} and {a.shape}")
            if not np.allclose(a, b, rtol=1e-8, atol=1e-10 * max(1.0, np.abs(a).max())):
                raise ValueError(f"func is not periodic with period={period}: "
                                 f"func({t:g}) differs from func({t + period:g})")
        return cls._new(period, value.shape, func=func, breakpoints=breakpoints)

    @classmethod
    def pointwise(cls, op, operands, shape, *, breakpoints=()):
        """Periodic matrix ``M(t) = op(P_1(t), ..., P_k(t))`` of periodic matrices.

        Parameters
        ----------
        op : callable
            Maps stacks of values, arrays of shape ``(nt,) + P_i.shape``, to
            an array of shape ``(nt,) + shape``.
        operands : sequence of PeriodicMatrix
            The matrices ``P_i``, all with the same period.
        shape : tuple of int
            Shape of ``M(t)``.
        breakpoints : array_like, optional
            Instants in ``[0, T)`` where ``M`` is not smooth, besides those
            of the operands.

        Returns
        -------
        PeriodicMatrix

        Examples
        --------
        >>> P = ltp.PeriodicMatrix.from_function(
        ...     lambda t: np.array([[2.0 + np.cos(2 * np.pi * t)]]), period=1.0)
        >>> Pinv = ltp.PeriodicMatrix.pointwise(np.linalg.inv, [P], (1, 1))
        >>> float(Pinv(0.25)[0, 0] * P(0.25)[0, 0])
        1.0
        """
        operands = list(operands)
        if not operands or not all(isinstance(o, PeriodicMatrix) for o in operands):
            raise TypeError("operands must be a non-empty sequence of PeriodicMatrix")
        period = operands[0].period
        if any(not np.isclose(o.period, period, rtol=1e-12) for o in operands):
            raise ValueError("operands must have the same period")
        breaks = np.concatenate([np.asarray(breakpoints, float)]
                                + [o.breakpoints for o in operands])
        return cls._new(period, shape, combine=(op, operands), breakpoints=breaks)

    @classmethod
    def from_samples(cls, samples, period, kind='fourier'):
        """Periodic matrix from N uniform samples over one period.

        Parameters
        ----------
        samples : array_like, shape (N, n, m)
            Values at ``t_k = k T / N``, k = 0..N-1.
        period : float
            Period T > 0.
        kind : {'fourier', 'hold'}
            'fourier' gives the trigonometric interpolant (exact for
            band-limited data with fewer than N/2 harmonics); 'hold' keeps
            each sample constant on ``[t_k, t_{k+1})``, which is how the
            matrices of a discrete-time system are stored.

        Returns
        -------
        PeriodicMatrix

        Examples
        --------
        >>> t = np.arange(8) / 8
        >>> P = ltp.PeriodicMatrix.from_samples(
        ...     np.cos(2 * np.pi * t)[:, None, None], period=1.0)
        >>> bool(np.isclose(P(0.3)[0, 0], np.cos(0.6 * np.pi)))
        True
        """
        samples = real_array(samples, 'samples', ndim=(1, 2, 3))
        if samples.ndim == 1:
            samples = samples[:, np.newaxis, np.newaxis]
        elif samples.ndim == 2:
            samples = samples[:, :, np.newaxis]
        period = check_period(period)
        nsamp = samples.shape[0]
        if nsamp < 1:
            raise ValueError("samples must contain at least one sample")
        if kind == 'hold':
            times = np.arange(nsamp) * period / nsamp
            return cls.switching(list(samples), times, period)
        if kind != 'fourier':
            raise ValueError(f"kind must be 'fourier' or 'hold', got {kind!r}")
        # P_k = (1/N) Σ_l P(t_l) e^{-j2πkl/N}; the Nyquist term (even N) is split
        # evenly between ±N/2 so that the interpolant stays real.
        spec = np.fft.fft(samples, axis=0) / nsamp
        K = nsamp // 2
        coeffs = np.zeros((2 * K + 1,) + samples.shape[1:], complex)
        ks = np.arange(-K, K + 1)
        coeffs[:] = spec[ks % nsamp]
        if nsamp % 2 == 0 and K > 0:
            coeffs[0] *= 0.5
            coeffs[-1] *= 0.5
        return cls(coeffs, period)

    @classmethod
    def switching(cls, pieces, times, period):
        """Switching (piecewise) periodic matrix, thesis eqs. (4.3)-(4.4).

        ``P(t) = P^i(t)`` for ``t_i <= t mod T < t_{i+1}`` with
        ``t_{M+1} = T``.  Evaluation is exact at the discontinuities and
        `fourier` returns exact coefficients of the discontinuous function.

        Parameters
        ----------
        pieces : sequence of array_like, PeriodicMatrix or callable
            The M sub-matrices ``P^i``.  Callables are evaluated as
            ``f(t)`` with the absolute time within the period.
        times : array_like of float
            Switching instants ``[t_1 = 0, t_2, ..., t_M]``, strictly
            increasing and below T.
        period : float
            Period T > 0.

        Returns
        -------
        PeriodicMatrix

        Examples
        --------
        >>> S = ltp.PeriodicMatrix.switching([[[1.0]], [[0.0]]], [0, 0.5], 1.0)
        >>> float(S(0.25)[0, 0]), float(S(0.75)[0, 0])
        (1.0, 0.0)
        >>> round(float(abs(S.fourier(1)[2, 0, 0])), 6)    # |1/(jπ)|
        0.31831
        """
        period = check_period(period)
        times = real_array(times, 'times', ndim=1)
        if not isinstance(pieces, (list, tuple)):
            raise TypeError("pieces must be a list of matrices, PeriodicMatrix objects "
                            f"or callables, got {type(pieces).__name__}")
        if len(pieces) != len(times) or len(times) == 0:
            raise ValueError(f"pieces ({len(pieces)}) and times ({len(times)}) "
                             "must have the same non-zero length")
        if times[0] != 0:
            raise ValueError(f"times must start at 0, got times[0]={times[0]}")
        if np.any(np.diff(times) <= 0) or times[-1] >= period:
            raise ValueError("times must be strictly increasing and below the period")
        mats = []
        for i, piece in enumerate(pieces):
            if isinstance(piece, PeriodicMatrix):
                try:
                    mats.append(piece.with_period(period))
                except ValueError:
                    raise ValueError(f"pieces[{i}] has period {piece.period}, which does "
                                     f"not divide the period {period}") from None
            elif callable(piece):
                mats.append(cls._new(period, as_matrix(piece(times[i]), f'pieces[{i}]').shape,
                                     func=piece))
            else:
                mats.append(cls.constant(piece, period))
        shape = mats[0].shape
        for i, m in enumerate(mats):
            if m.shape != shape:
                raise ValueError(f"pieces[{i}] has shape {m.shape}, expected {shape}")
        if len(mats) == 1 and mats[0]._func is None:
            return mats[0].with_period(period)
        return cls._new(period, shape, pieces=mats, times=times,
                        breakpoints=times)

    #
    # Properties
    #

    @property
    def omega_p(self):
        """Fundamental (pumping) frequency ``ω_p = 2π/T`` in rad/s."""
        return 2 * np.pi / self.period

    @property
    def is_constant(self):
        """True when the matrix does not depend on time."""
        return self._coeffs is not None and (
            self._coeffs.shape[0] == 1 or not np.any(self._coeffs[np.arange(
                self._coeffs.shape[0]) != self._coeffs.shape[0] // 2]))

    @property
    def _piecewise_constant(self):
        """True when the matrix is constant between its breakpoints (by its form)."""
        if self._coeffs is not None:
            return self.is_constant
        if self._pieces is not None:
            return all(p._piecewise_constant for p in self._pieces)
        # pointwise combinations of piecewise-constant operands
        return self._combine is not None and all(o._piecewise_constant
                                                  for o in self._combine[1])

    @property
    def switching_times(self):
        """Switching instants ``t_1 = 0 < ... < t_M`` of a switching form, else None."""
        return None if self._pieces is None else np.array(self._times, float)

    @property
    def is_function(self):
        """True when the matrix is defined by a smooth callable (`from_function`)."""
        return self._func is not None

    @property
    def function(self):
        """The callable ``t -> M(t)`` of a matrix made by `from_function`, else None.

        Examples
        --------
        >>> f = lambda t: np.array([[np.cos(t)]])
        >>> P = ltp.PeriodicMatrix.from_function(f, 2 * np.pi)
        >>> P.function is f, ltp.PeriodicMatrix.constant([[1.0]], 1.0).function
        (True, None)
        """
        return self._func

    @property
    def nharmonics(self):
        """Number K of harmonics of an exact Fourier form, else None."""
        return None if self._coeffs is None else self._coeffs.shape[0] // 2

    def __repr__(self):
        if self._coeffs is not None:
            form = f"K={self.nharmonics}"
        elif self._pieces is not None or self._func is not None:
            form = describe(self)
        else:
            form = "combination"
        return f"<PeriodicMatrix {self.shape[0]}x{self.shape[1]}, period={self.period:g}, {form}>"

    #
    # Evaluation
    #

    def __call__(self, t):
        """Evaluate at scalar ``t`` (shape (n, m)) or 1D array (shape (len(t), n, m))."""
        if type(t) in _FLOATS and self._func is not None and math.isfinite(t):
            scalar = getattr(self._func, 'scalar', None)
            if scalar is not None:          # data-backed table: one float, no validation
                return scalar(float(t))
        tarr = real_array(t, 't', ndim=(0, 1))
        out = self._eval(np.atleast_1d(tarr))
        return out[0] if tarr.ndim == 0 else out

    def _eval(self, t):
        if self._coeffs is not None:
            K = self._coeffs.shape[0] // 2
            if K == 0:
                return np.broadcast_to(self._coeffs[0].real, (len(t),) + self.shape).copy()
            # P(t) = P_0 + 2 Re Σ_{k>0} P_k e^{jkω_p t}
            ks = np.arange(1, K + 1)
            phase = np.exp(1j * self.omega_p * np.outer(t, ks))
            series = (phase @ self._coeffs[K + 1:].reshape(K, -1)).real
            return self._coeffs[K].real + 2 * series.reshape((len(t),) + self.shape)
        if self._func is not None:
            return _call_vectorised(self._func, t, self.shape)
        if self._pieces is not None:
            # t mod T, snapped onto a switching instant within rounding (so that
            # t = t_i + jT selects the piece starting at t_i for every j)
            eps = 1e-12 * self.period
            tau = np.mod(t, self.period)
            tau[tau >= self.period - eps] -= self.period
            idx = np.maximum(np.searchsorted(self._times, tau + eps, side='right') - 1, 0)
            out = np.empty((len(t),) + self.shape)
            tau = np.maximum(tau, 0.0)
            for i, piece in enumerate(self._pieces):
                mask = idx == i
                if np.any(mask):
                    # a callable piece sees the time within the period
                    out[mask] = piece._eval(tau[mask])
            return out
        op, operands = self._combine
        return op(*[o._eval(t) for o in operands])

    def sample(self, nsamples):
        """Values at ``t_k = k T / N`` for k = 0..N-1, shape (N, n, m).

        Examples
        --------
        >>> ltp.PeriodicMatrix.constant([[2.0]], 1.0).sample(3)[:, 0, 0]
        array([2., 2., 2.])
        """
        nsamples = check_positive_int(nsamples, 'nsamples')
        return self._eval(np.arange(nsamples) * self.period / nsamples)

    #
    # Fourier coefficients
    #

    def fourier(self, nharmonics):
        """Fourier coefficients ``P_k``, k = -K..K, shape (2K+1, n, m).

        ``P_k = (1/T) ∫_0^T P(t) e^{-jkω_p t} dt`` (see the Conventions page).
        Exact for the Fourier and switching forms with constant or
        band-limited pieces; computed by FFT (smooth callables) or
        Gauss-Legendre quadrature between switching instants otherwise.

        Parameters
        ----------
        nharmonics : int
            Number K >= 0 of harmonics.

        Returns
        -------
        ndarray of complex

        Examples
        --------
        >>> S = ltp.PeriodicMatrix.switching([[[2.0]], [[0.0]]], [0, 0.5], 1.0)
        >>> complex(S.fourier(0)[0, 0, 0])
        (1+0j)
        """
        K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
        if K not in self._cache:
            self._cache[K] = self._fourier(K)
        return self._cache[K].copy()

    def _fourier(self, K):
        if self._coeffs is not None:
            have = self._coeffs.shape[0] // 2
            out = np.zeros((2 * K + 1,) + self.shape, complex)
            k = min(K, have)
            out[K - k:K + k + 1] = self._coeffs[have - k:have + k + 1]
            return out
        if self._pieces is not None and all(p._coeffs is not None for p in self._pieces):
            return self._switching_fourier_exact(K)
        if self._func is not None and self.breakpoints.size == 0:
            return self._fft_fourier(K)
        return self._quadrature_fourier(K)

    def _switching_fourier_exact(self, K):
        # piece i on [a, b) with P^i(t) = Σ_l P^i_l e^{jlω t}:
        #   P_k = Σ_l P^i_l E(l - k),  E(d) = (1/T) ∫_a^b e^{jdω t} dt
        w, T = self.omega_p, self.period
        ends = np.append(self._times, T)
        out = np.zeros((2 * K + 1,) + self.shape, complex)
        ks = np.arange(-K, K + 1)
        for i, piece in enumerate(self._pieces):
            a, b = ends[i], ends[i + 1]
            Kp = piece._coeffs.shape[0] // 2
            ls = np.arange(-Kp, Kp + 1)
            d = ls[np.newaxis, :] - ks[:, np.newaxis]
            with np.errstate(divide='ignore', invalid='ignore'):
                E = (np.exp(1j * d * w * b) - np.exp(1j * d * w * a)) / (1j * d * w * T)
            E[d == 0] = (b - a) / T
            out += np.einsum('kl,lij->kij', E, piece._coeffs)
        return out

    def _fft_fourier(self, K):
        # trapezoidal rule = DFT, spectrally accurate for smooth periodic data;
        # refine until two resolutions agree.
        nsamp = max(64, 4 * (2 * K + 1))
        previous = None
        for _ in range(6):
            spec = np.fft.fft(self.sample(nsamp), axis=0) / nsamp
            coeffs = spec[np.arange(-K, K + 1) % nsamp]
            if previous is not None and np.allclose(
                    coeffs, previous, rtol=0, atol=1e-13 * max(1.0, np.abs(coeffs).max())):
                return coeffs
            previous = coeffs
            nsamp *= 2
        warnings.warn("Fourier coefficients of the callable did not converge; "
                      "for a matrix with jumps use PeriodicMatrix.switching",
                      UserWarning, stacklevel=3)
        return coeffs

    def _quadrature_fourier(self, K):
        # composite Gauss-Legendre on each smooth interval between breakpoints
        T, w = self.period, self.omega_p
        edges = np.append(self.breakpoints, T) if self.breakpoints.size else np.array([0.0, T])
        if edges[0] != 0:
            edges = np.concatenate([[0.0], edges])
        nodes, weights = [], []
        for a, b in zip(edges[:-1], edges[1:]):
            npanel = int(np.ceil((K + 8) * (b - a) / T)) + 1
            panel = np.linspace(a, b, npanel + 1)
            half = 0.5 * np.diff(panel)
            mid = 0.5 * (panel[1:] + panel[:-1])
            nodes.append((mid[:, None] + half[:, None] * _GL_NODES).ravel())
            weights.append((half[:, None] * _GL_WEIGHTS).ravel())
        nodes, weights = np.concatenate(nodes), np.concatenate(weights)
        values = self._eval(nodes)
        ks = np.arange(-K, K + 1)
        kernel = np.exp(-1j * w * np.outer(ks, nodes)) * weights / T
        return np.einsum('kt,tij->kij', kernel, values)

    #
    # Algebra
    #

    def with_period(self, period):
        """The same function viewed with period ``period = r T`` (r integer).

        Examples
        --------
        >>> P = ltp.PeriodicMatrix([[[0.5]], [[0]], [[0.5]]], 1.0).with_period(2.0)
        >>> P.fourier(2)[:, 0, 0].real
        array([0.5, 0. , 0. , 0. , 0.5])
        """
        period = check_period(period)
        ratio = period / self.period
        r = int(round(ratio))
        if r < 1 or abs(ratio - r) > 1e-9 * ratio:
            raise ValueError(f"period {period} is not an integer multiple of {self.period}")
        if r == 1:
            return self
        if self._coeffs is not None:
            K = self._coeffs.shape[0] // 2
            coeffs = np.zeros((2 * K * r + 1,) + self.shape, complex)
            coeffs[::r] = self._coeffs
            return PeriodicMatrix(coeffs, period)
        bps = (self.breakpoints[None, :] + self.period * np.arange(r)[:, None]).ravel()
        return PeriodicMatrix._new(period, self.shape, combine=(Identity(), [self]),
                                   breakpoints=bps)

    def _binary(self, other, op, shape, fourier_op):
        if not isinstance(other, PeriodicMatrix):
            other = PeriodicMatrix.constant(as_matrix(other, 'operand'), self.period)
            other_period = self.period
        else:
            other_period = other.period
        period = commensurate(self.period, other_period)
        a, b = self.with_period(period), other.with_period(period)
        if a._coeffs is not None and b._coeffs is not None:
            return PeriodicMatrix(fourier_op(a._coeffs, b._coeffs), period)
        return PeriodicMatrix._new(period, shape, combine=(op, [a, b]),
                                   breakpoints=np.concatenate([a.breakpoints, b.breakpoints]))

    def __add__(self, other):
        if not _is_operand(other):
            return NotImplemented
        shape = self.shape if isinstance(other, PeriodicMatrix) else as_matrix(other, 'operand').shape
        if shape != self.shape:
            raise ValueError(f"cannot add shapes {self.shape} and {shape}")
        return self._binary(other, np.add, self.shape, add_series)

    __radd__ = __add__

    def __neg__(self):
        return self * -1.0

    def __sub__(self, other):
        if not _is_operand(other):
            return NotImplemented
        return self + (-other if isinstance(other, PeriodicMatrix) else -np.asarray(other, float))

    def __rsub__(self, other):
        return (-self) + other

    def __mul__(self, scalar):
        if not isinstance(scalar, numbers.Real) or isinstance(scalar, bool):
            return NotImplemented
        return self._scale(float(scalar))

    __rmul__ = __mul__

    def _scale(self, c):
        if self._coeffs is not None:
            return PeriodicMatrix(c * self._coeffs, self.period)
        return PeriodicMatrix._new(self.period, self.shape, combine=(Scale(c), [self]),
                                   breakpoints=self.breakpoints)

    def __matmul__(self, other):
        if not _is_operand(other):
            return NotImplemented
        oshape = other.shape if isinstance(other, PeriodicMatrix) else as_matrix(other, 'operand').shape
        if self.shape[1] != oshape[0]:
            raise ValueError(f"cannot multiply shapes {self.shape} and {oshape}")
        return self._binary(other, np.matmul, (self.shape[0], oshape[1]), mul_series)

    def __rmatmul__(self, other):
        if not _is_operand(other):
            return NotImplemented
        return PeriodicMatrix.constant(as_matrix(other, 'operand'), self.period) @ self

    @property
    def T(self):
        """Transposed periodic matrix."""
        if self._coeffs is not None:
            return PeriodicMatrix(np.swapaxes(self._coeffs, 1, 2), self.period)
        return PeriodicMatrix._new(self.period, self.shape[::-1],
                                   combine=(Transpose(), [self]),
                                   breakpoints=self.breakpoints)

    def __getitem__(self, index):
        rows, cols = index
        probe = np.zeros(self.shape)[rows, cols]
        if probe.ndim != 2:
            raise IndexError("indexing a PeriodicMatrix must keep two dimensions (use slices)")
        if self._coeffs is not None:
            return PeriodicMatrix(self._coeffs[:, rows, cols], self.period)
        return PeriodicMatrix._new(self.period, probe.shape,
                                   combine=(Index(rows, cols), [self]),
                                   breakpoints=self.breakpoints)

    @staticmethod
    def block(rows):
        """Assemble a block matrix from a nested list of periodic/constant matrices.

        Examples
        --------
        >>> P = ltp.PeriodicMatrix.constant([[1.0]], 1.0)
        >>> ltp.PeriodicMatrix.block([[P, [[0.0]]], [[[0.0]], P]]).shape
        (2, 2)
        """
        flat = [m for row in rows for m in row]
        shapes = [[m.shape if isinstance(m, PeriodicMatrix) else as_matrix(m, 'block').shape
                   for m in row] for row in rows]
        for i, row in enumerate(shapes):
            if len({sh[0] for sh in row}) != 1:
                raise ValueError(f"block: the matrices of row {i} have different heights "
                                 f"{[sh[0] for sh in row]}")
            if [sh[1] for sh in row] != [sh[1] for sh in shapes[0]]:
                raise ValueError(f"block: the column widths of row {i} do not match row 0")
        periods = [m.period for m in flat if isinstance(m, PeriodicMatrix)]
        if not periods:
            return PeriodicMatrix.constant(np.block([[as_matrix(m, 'block') for m in r]
                                                     for r in rows]), 1.0)
        period = periods[0]
        for p in periods[1:]:
            period = commensurate(period, p)
        mats = [[m.with_period(period) if isinstance(m, PeriodicMatrix)
                 else PeriodicMatrix.constant(m, period) for m in row] for row in rows]
        operands = [m for row in mats for m in row]
        if all(m._coeffs is not None for m in operands):
            K = max(m._coeffs.shape[0] // 2 for m in operands)
            coeffs = np.block([[m.fourier(K) for m in row] for row in mats])
            return PeriodicMatrix(coeffs, period)
        assemble = Block([len(row) for row in mats])
        shape = assemble(*[np.zeros((1,) + m.shape) for m in operands]).shape[1:]
        return PeriodicMatrix._new(period, shape, combine=(assemble, operands),
                                   breakpoints=np.concatenate([m.breakpoints for m in operands]))


def as_periodic(value, period, name, shape=None):
    """Convert an array, callable or PeriodicMatrix to a PeriodicMatrix of `period`.

    Examples
    --------
    >>> from ltpcontrol._core.periodic_matrix import as_periodic
    >>> as_periodic([[1.0, 0.0]], 2.0, 'C').shape
    (1, 2)
    """
    if isinstance(value, PeriodicMatrix):
        try:
            value = value.with_period(period)
        except ValueError:
            raise ValueError(f"{name} has period {value.period}, which does not "
                             f"divide the system period {period}") from None
    elif callable(value):
        try:
            value = PeriodicMatrix.from_function(value, period)
        except (ValueError, TypeError) as exc:
            raise type(exc)(f"{name}: {exc}") from None
    else:
        value = PeriodicMatrix.constant(as_matrix(value, name), period)
    if shape is not None and value.shape != tuple(shape):
        raise ControlDimension(f"{name} must have shape {tuple(shape)}, got {value.shape}")
    return value


def _callables(P):
    """The callables a periodic matrix and its operands are made of."""
    out = [] if P._func is None else [P._func]
    if P._combine is not None:
        out.append(P._combine[0])
        for o in P._combine[1]:
            out += _callables(o)
    for piece in P._pieces or ():
        out += _callables(piece)
    return out


def _is_operand(x):
    return isinstance(x, (PeriodicMatrix, numbers.Real, np.ndarray, list))


def _call_vectorised(func, t, shape):
    try:
        out = np.asarray(func(t), float)
        if out.shape == (len(t),) + shape:
            return out
    except Exception:
        pass
    return np.array([np.asarray(func(ti), float).reshape(shape) for ti in t])
