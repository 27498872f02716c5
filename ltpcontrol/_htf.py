"""Harmonic transfer functions (HTF) of LTP systems.

Convention (Wereley; stated on the Conventions page): with exponentially
modulated periodic signals ``u(t) = Σ_m U_m e^{(s + jmω_p)t}``, the truncated
HTF at ``s`` is the ``(2K+1)ny x (2K+1)nu`` matrix with blocks ``H_{n,m}``,
n, m = -K..K, such that ``Y_n = Σ_m H_{n,m}(s) U_m``:

    H(s) = C_T [sI - (A_T - N)]^{-1} B_T + D_T,
    (A_T)_{n,m} = A_{n-m},   N = blkdiag(jnω_p I).

The thesis components are ``G_k(s) = H_{0,-k}(s)``, so that
``Y(jω) = Σ_k G_k(jω) U(jω - jkω_p)`` and ``H_{n,m}(s) = G_{n-m}(s + jnω_p)``.

Discrete time (N steps per period, ``w = e^{j2π/N}``, ``u[k] = Σ_m U_m z^k w^{mk}``):
``H(z) = C_T (zΛ - A_T)^{-1} B_T + D_T`` with ``Λ = blkdiag(w^n I)`` and
block-circulant ``(A_T)_{n,m} = A_{(n-m) mod N}`` (exact, finite).

Both are evaluated from a "harmonic state space" ``(F, G, H, J)`` with
``H(x) = H (xI - F)^{-1} G + J``; F is diagonalised once (in Floquet form it
is block diagonal, so one eigendecomposition of A suffices), after which
each frequency costs a diagonal solve.
"""

import warnings

import numpy as np
import control as ct
from scipy import sparse
from control.exception import ControlArgument, ControlDimension

from tqdm.auto import tqdm

from . import config
from ._validation import check_kwargs, check_period, check_positive_int, real_array

__all__ = ['HTF', 'htf']


class HTF:
    """Harmonic transfer function of a linear time-periodic system.

    An HTF comes from a state-space model (`htf`, evaluable anywhere) or
    from data on a frequency grid (identification), in which case it holds
    the components ``G_k(jω)``, k = -K..K, on ``omega``.

    Parameters
    ----------
    components : array_like, shape (2K+1, ny, nu, nomega)
        ``G_k(jω)`` for k = -K..K on the grid `omega`; NaN marks a
        component that the data do not determine at that frequency.
    omega : array_like
        Frequencies in rad/s (increasing).
    period : float
        Period T of the system.
    std : array_like, optional
        Standard deviations of the components (same shape).
    diagnostics : dict, optional
        Estimator diagnostics (condition numbers, residuals, ...).
    name : str, optional
        Name used in plots.
    inputs, outputs : list of str, optional
        Signal names.

    Attributes
    ----------
    nharmonics : int
        Number K of harmonics.
    period : float
        The period T.
    omega : ndarray or None
        Frequency grid of a data HTF (None for a model HTF).
    std : ndarray or None
        Standard deviations of the components of a data HTF.

    Examples
    --------
    >>> omega = np.linspace(0.1, 10, 50)
    >>> G = np.zeros((3, 1, 1, 50), complex)
    >>> G[1, 0, 0] = 1 / (1j * omega + 1)
    >>> H = ltp.HTF(G, omega, period=1.0, name='estimate')
    >>> H.nharmonics, H.component(0).ninputs
    (1, 1)
    """

    def __init__(self, components, omega, period, *, std=None, diagnostics=None,
                 name=None, inputs=None, outputs=None):
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
        self._init(period, comps.shape[0] // 2, comps.shape[1], comps.shape[2], 0.0,
                   name, inputs, outputs)
        self._components = comps.astype(complex)
        self.omega = omega
        self.std = std
        self.diagnostics = {} if diagnostics is None else dict(diagnostics)

    def _init(self, period, K, ny, nu, dt, name, inputs, outputs):
        self.period = check_period(period)
        self.nharmonics = K
        self.noutputs, self.ninputs = ny, nu
        self.dt = dt
        self.name = name if name is not None else 'htf'
        self.input_labels = _labels(inputs, nu, 'u', 'inputs')
        self.output_labels = _labels(outputs, ny, 'y', 'outputs')
        self.omega, self.std, self.diagnostics = None, None, {}
        self._components = None
        self._hss = None

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
        src = (f"data on {len(self.omega)} frequencies" if self._components is not None
               else "model")
        return (f"<HTF {self.name}: {self.input_labels} -> {self.output_labels}, "
                f"K={self.nharmonics}, period={self.period:g}, {src}>")

    #
    # Evaluation
    #

    def __call__(self, s, progress=None):
        """Evaluate the block matrix ``H(s)`` (``H(z)`` in discrete time).

        Long requests are evaluated in chunks of points whose working
        memory stays within ``ltp.config.defaults['htf.max_memory']``; a
        request that cannot fit raises `MemoryError` with its estimated
        size.

        Parameters
        ----------
        s : complex or 1D array_like of complex
            Evaluation points.  A data HTF accepts only ``s = jω`` with
            every ``ω + nω_p`` (n = -K..K) on its grid.
        progress : bool, optional
            Show a progress bar over the chunks (default
            ``ltp.config.defaults['htf.progress']``).

        Returns
        -------
        ndarray
            Shape ``((2K+1)ny, (2K+1)nu)`` for scalar `s`, else
            ``(len(s), (2K+1)ny, (2K+1)nu)``.

        Examples
        --------
        >>> H = ltp.htf(ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=np.pi), 1)
        >>> np.round(H(0.0).diagonal(), 3)      # 1/(jnω_p + 1), ω_p = 2
        array([0.2+0.4j, 1. +0.j , 0.2-0.4j])
        """
        sarr = real_array(s, 's', ndim=(0, 1), allow_complex=True).astype(complex)
        pts = np.atleast_1d(sarr)
        if self._hss is not None:
            out = self._hss.evaluate(pts, progress=progress)
        else:
            out = self._data_matrix(pts)
        return out[0] if sarr.ndim == 0 else out

    def component(self, k, omega=None, name=None):
        """Component ``G_k(jω) = H_{0,-k}(jω)`` as a `control.FrequencyResponseData`.

        Parameters
        ----------
        k : int
            Harmonic index in -K..K.
        omega : array_like, optional
            Frequencies in rad/s; a data HTF uses its grid (a given
            `omega` must be a subset of it).  A model HTF uses a default
            grid when omitted.
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

    def _frds(self, ks, omega=None, name=None, progress=None):
        """Components ``G_k`` for all `ks` from ONE evaluation of the block row."""
        omega, G = self._components_on(omega, ks, progress=progress)
        return [ct.frd(Gk, omega, name=name or f"{self.name} G_{k}",
                       inputs=self.input_labels, outputs=self.output_labels,
                       dt=self.dt if self.dt else 0) for k, Gk in zip(ks, G)]

    def components(self, omega=None):
        """All components ``G_k(jω)``, shape ``(2K+1, ny, nu, len(omega))``.

        Parameters
        ----------
        omega : array_like, optional
            Frequencies in rad/s (see `component`).

        Returns
        -------
        omega : ndarray
        G : ndarray of complex

        Examples
        --------
        >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
        >>> w, G = ltp.htf(sys, 1).components([1.0, 2.0])
        >>> G.shape
        (3, 1, 1, 2)
        """
        return self._components_on(omega, list(self.harmonics))

    def to_frd(self, omega=None, name=None):
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

    # -- harmonic state space (implemented in _harmonic_ss) --
    def to_ss(self, name=None):
        """Real harmonic state space of a model HTF; see `ltpcontrol.harmonic_ss`."""
        from ._harmonic_ss import htf_to_ss
        return htf_to_ss(self, name)

    def predict(self, u, t):
        """Output predicted by the HTF for an input signal (steady state).

        The input is transformed by FFT, ``Y(jω) = Σ_k G_k(jω) U(jω - jkω_p)``
        is formed on the FFT grid and transformed back (as the thesis does
        for Figs. 3.14/3.16).  The record is treated as one period of a
        periodic signal, so its length must be an integer number of periods.

        Parameters
        ----------
        u : array_like, shape (nu, L) or (L,)
            Input samples.
        t : array_like, shape (L,)
            Uniform time points; ``L dt`` must be a multiple of the period.

        Returns
        -------
        y : ndarray, shape (ny, L) (or (L,) for SISO input given as 1D)

        Examples
        --------
        >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
        >>> t = np.arange(400) * 0.01
        >>> y = ltp.htf(sys, 1).predict(np.cos(2 * np.pi * t), t)
        >>> G = 1 / (2j * np.pi + 1)
        >>> bool(np.allclose(y, abs(G) * np.cos(2 * np.pi * t + np.angle(G))))
        True
        """
        t = real_array(t, 't', ndim=1)
        u = real_array(u, 'u', ndim=(1, 2))
        squeeze = u.ndim == 1
        u = np.atleast_2d(u)
        if u.shape != (self.ninputs, len(t)):
            raise ControlDimension(f"u must have shape ({self.ninputs}, {len(t)}), got {u.shape}")
        L = len(t)
        if L < 2 or not np.allclose(np.diff(t), t[1] - t[0], rtol=1e-9, atol=0):
            raise ValueError("t must be uniformly spaced with at least two points")
        h = t[1] - t[0]
        shift = L * h / self.period
        r = int(round(shift))
        if r < 1 or abs(shift - r) > 1e-6 * shift:
            raise ValueError(f"the record length {L * h:g} must be an integer number of "
                             f"periods ({self.period:g}) for an HTF prediction")
        U = np.fft.fft(u, axis=1)
        wbin = 2 * np.pi * np.fft.fftfreq(L, h)
        # G_k at negative frequencies from G_k(-jω) = conj(G_{-k}(jω))
        pos = np.abs(wbin)
        _, G = self._components_on(pos, list(self.harmonics), interpolate=True)
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
        return y[0] if squeeze and self.noutputs == 1 else y

    def plot(self, *args, **kwargs):
        """Bode plot of selected components; see `ltpcontrol.bode_htf`."""
        from ._htfplot import bode_htf
        return bode_htf(self, *args, **kwargs)

    #
    # Internals
    #

    def _components_on(self, omega, ks, interpolate=False, progress=None):
        K = self.nharmonics
        idx = [k + K for k in ks]
        if self._components is None:
            if omega is None:
                omega = _default_omega(self)
            omega = real_array(omega, 'omega', ndim=(0, 1)).reshape(-1)
            s = (np.exp(1j * omega * self.dt) if self.dt else 1j * omega)
            # G_k = H_{0,-k}: central block row, block column -k
            G = self._hss.evaluate(s, rows=[0], cols=[-k for k in ks], progress=progress)
            ny, nu = self.noutputs, self.ninputs
            G = G.reshape(len(s), ny, len(ks), nu).transpose(2, 1, 3, 0)
            return omega, G
        if omega is None:
            return self.omega.copy(), self._components[idx].copy()
        omega = real_array(omega, 'omega', ndim=(0, 1)).reshape(-1)
        if interpolate:
            G = np.zeros((len(ks), self.noutputs, self.ninputs, len(omega)), complex)
            inside = (omega >= self.omega[0]) & (omega <= self.omega[-1])
            flat = self._components[idx].reshape(-1, len(self.omega))
            G.reshape(-1, len(omega))[:, inside] = np.array(
                [np.interp(omega[inside], self.omega, row.real)
                 + 1j * np.interp(omega[inside], self.omega, row.imag) for row in flat])
            return omega, G
        pos = np.searchsorted(self.omega, omega)
        pos = np.clip(pos, 0, len(self.omega) - 1)
        if not np.allclose(self.omega[pos], omega, rtol=1e-10, atol=1e-12):
            raise ValueError("omega must be a subset of the HTF's frequency grid for a data HTF")
        return omega, self._components[idx][..., pos]

    def _data_matrix(self, s):
        if np.any(np.abs(s.real) > 0):
            raise ValueError("a data HTF can only be evaluated on the imaginary axis (s = jω)")
        K, ny, nu = self.nharmonics, self.noutputs, self.ninputs
        out = np.empty((len(s), (2 * K + 1) * ny, (2 * K + 1) * nu), complex)
        for a, n in enumerate(self.harmonics):
            # H_{n,m}(jω) = G_{n-m}(jω + jnω_p)
            _, G = self._components_on(s.imag + n * self.omega_p, list(self.harmonics))
            for b, m in enumerate(self.harmonics):
                if abs(n - m) <= K:
                    out[:, a * ny:(a + 1) * ny, b * nu:(b + 1) * nu] = \
                        G[n - m + K].transpose(2, 0, 1)
                else:
                    out[:, a * ny:(a + 1) * ny, b * nu:(b + 1) * nu] = 0
        return out


def htf(sys, nharmonics, *, internal_harmonics=None, method='auto', **kwargs):
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
        Period for an LTI `sys`.

    Returns
    -------
    HTF

    Examples
    --------
    LTI limit: ``H_{n,n}(s) = G(s + jnω_p)``.

    >>> G = ct.tf([1], [1, 1])
    >>> H = ltp.htf(ct.ss(G), 2, period=2 * np.pi)
    >>> bool(np.isclose(H(0.5j)[3, 3], G(1.5j)))
    True
    """
    period = kwargs.pop('period', None)
    check_kwargs(kwargs, 'htf')
    from ._ltpsys import LTPStateSpace, ltpss
    if isinstance(sys, (ct.StateSpace, ct.TransferFunction)):
        if period is None:
            raise ControlArgument("htf of an LTI system needs the keyword period")
        sys = ltpss(sys, period)
    elif not isinstance(sys, LTPStateSpace):
        raise ControlArgument(f"sys must be an LTPStateSpace, got {type(sys).__name__}")
    elif period is not None:
        raise TypeError("htf: period is taken from the LTPStateSpace; do not pass it")
    K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
    if method not in ('auto', 'modal', 'solve'):
        raise ValueError(f"method must be 'auto', 'modal' or 'solve', got {method!r}")
    if not sys.is_stable():
        warnings.warn(f"{sys.name} is unstable: its HTF is defined wherever the harmonic "
                      "resolvent exists, but on the imaginary axis it describes no "
                      "steady-state response", UserWarning, stacklevel=2)
    H = HTF.__new__(HTF)
    H._init(sys.period, K, sys.noutputs, sys.ninputs, sys.dt, sys.name,
            sys.input_labels, sys.output_labels)
    if sys.isdtime():
        N = sys.nsteps
        if 2 * K + 1 > N:
            raise ValueError(f"nharmonics={K} exceeds the {N} harmonics of a discrete "
                             f"system with {N} steps per period (need 2K+1 <= N)")
        _check_setup_memory(N * sys.nstates, 0, 'htf')
        H._hss = _HarmonicStateSpace.discrete(sys, K, method)
    else:
        Ki = _internal_order(sys, K, internal_harmonics)
        checked = internal_harmonics is None and not sys.A.is_constant
        _check_setup_memory((2 * Ki + 1) * sys.nstates,
                            (2 * Ki + 17) * sys.nstates if checked else 0, 'htf')
        H._hss = _HarmonicStateSpace.continuous(sys, K, Ki, method)
        if internal_harmonics is None and not H._hss.exact:
            _check_truncation(sys, K, Ki, H._hss, method)
    return H


class _HarmonicStateSpace:
    """``H(x) = Hc (xI - F)^{-1} G + J`` with the central 2K+1 block rows/cols."""

    def __init__(self, F, G, Hc, J, K, Ki, ny, nu, method, exact, floquet_A=None):
        self.F, self.G, self.Hc, self.J = F, G, Hc, J
        self.K, self.Ki, self.ny, self.nu = K, Ki, ny, nu
        self.exact = exact
        self.modal = None
        self._residues = {}
        if floquet_A is not None and method in ('auto', 'modal'):
            # Floquet form: F = blkdiag(A - jnω_p I) has eigenvalues λ_i - jnω_p
            # and eigenvectors blkdiag(W) from ONE eigendecomposition A = W Λ W^{-1}
            A, w = floquet_A
            lamA, W = np.linalg.eig(A)
            if method == 'modal' or np.linalg.cond(W) < 1e8:
                n, nb = A.shape[0], F.shape[0] // A.shape[0]
                harm = np.arange(nb) - nb // 2
                lam = (lamA[None, :] - 1j * w * harm[:, None]).ravel()
                Winv = np.linalg.inv(W)
                HV = (Hc.reshape(Hc.shape[0], nb, n) @ W).reshape(Hc.shape[0], -1)
                VG = (Winv @ G.reshape(nb, n, -1)).reshape(nb * n, -1)
                self.modal = (lam, HV, VG)
        self.method = method

    def _ensure_modal(self, npoints):
        """Diagonalise F once when it pays off (or when asked to)."""
        if self.modal is not None or self.method == 'solve':
            return
        if self.method == 'auto' and npoints < _MODAL_BREAK_EVEN:
            return                  # a few dense solves are cheaper than eig(F)
        lam, V = np.linalg.eig(self.F)
        if self.method == 'modal' or np.linalg.cond(V) < 1e8:
            Vinv = np.linalg.solve(V, np.eye(len(lam)))
            self.modal = (lam, self.Hc @ V, Vinv @ self.G)
        else:
            self.method = 'solve'   # ill-conditioned eigenvectors: stay with solves

    @classmethod
    def continuous(cls, sys, K, Ki, method):
        n, ny, nu = sys.nstates, sys.noutputs, sys.ninputs
        w = sys.omega_p
        harm = np.arange(-Ki, Ki + 1)
        A_T = _toeplitz(sys.A.fourier(2 * Ki), Ki)
        B_T = _toeplitz(sys.B.fourier(2 * Ki), Ki)
        C_T = _toeplitz(sys.C.fourier(2 * Ki), Ki)
        D_T = _toeplitz(sys.D.fourier(2 * Ki), Ki)
        # F = A_T - N,  N = blkdiag(jnω_p I)
        F = A_T
        F[np.diag_indices_from(F)] -= 1j * w * np.repeat(harm, n)
        rows = _central(Ki, K, ny)
        cols = _central(Ki, K, nu)
        exact = sys.A.is_constant and _bandlimited(sys, Ki - K)
        floquet_A = (sys.A(0.0), w) if sys.A.is_constant else None
        return cls(F, B_T[:, cols], C_T[rows], D_T[np.ix_(rows, cols)], K, Ki, ny, nu,
                   method, exact, floquet_A)

    @classmethod
    def discrete(cls, sys, K, method):
        N, n, ny, nu = sys.nsteps, sys.nstates, sys.noutputs, sys.ninputs
        # DT Fourier coefficients X_l = (1/N) Σ_k X[k] w^{-lk} (l mod N)
        coef = [np.fft.fft(M.sample(N), axis=0) / N for M in (sys.A, sys.B, sys.C, sys.D)]
        harm = np.arange(-((N - 1) // 2), N // 2 + 1)
        idx = (harm[:, None] - harm[None, :]) % N
        A_T, B_T, C_T, D_T = [np.block([[c[i] for i in row] for row in idx]) for c in coef]
        lam = np.exp(2j * np.pi * harm / N)
        # (zΛ - A_T)^{-1} = (zI - Λ^{-1}A_T)^{-1} Λ^{-1}
        Linv = np.repeat(1 / lam, n)
        F = Linv[:, None] * A_T
        G = Linv[:, None] * B_T
        k0 = (N - 1) // 2
        rows = np.concatenate([np.arange((k0 + k) * ny, (k0 + k + 1) * ny) for k in range(-K, K + 1)])
        cols = np.concatenate([np.arange((k0 + k) * nu, (k0 + k + 1) * nu) for k in range(-K, K + 1)])
        return cls(F, G[:, cols], C_T[rows], D_T[np.ix_(rows, cols)], K, None, ny, nu,
                   method, True)

    def evaluate(self, x, rows=None, cols=None, progress=None):
        """H(x) for points x; `rows`/`cols` select block harmonics (-K..K).

        The points are processed in chunks whose working memory stays
        within ``ltp.config.defaults['htf.max_memory']``.
        """
        K, ny, nu = self.K, self.ny, self.nu
        r = np.arange(self.Hc.shape[0]) if rows is None else np.concatenate(
            [np.arange((k + K) * ny, (k + K + 1) * ny) for k in rows])
        c = np.arange(self.G.shape[1]) if cols is None else np.concatenate(
            [np.arange((k + K) * nu, (k + K + 1) * nu) for k in cols])
        self._ensure_modal(len(x))
        chunk, use_residues = self._plan(len(x), len(r), len(c))
        J = self.J[np.ix_(r, c)]
        out = np.empty((len(x), len(r), len(c)), complex)
        starts = range(0, len(x), chunk)
        for a in tqdm(starts, desc="HTF", unit="chunk", leave=False,
                      disable=not config._get('htf.progress', progress) or len(starts) < 2):
            sl = slice(a, a + chunk)
            if self.modal is not None:
                out[sl] = self._modal_chunk(x[sl], r, c, rows, cols, use_residues)
            else:
                out[sl] = self._solve_chunk(x[sl], r, c)
            if J.any():
                out[sl] += J
        return out

    def _plan(self, npoints, nr, nc):
        """Chunk length and modal variant that keep the working memory in budget."""
        budget = float(config.defaults['htf.max_memory'])
        nF = self.F.shape[0]
        out_bytes = _BYTES * npoints * nr * nc
        use_residues = False
        if self.modal is not None:
            # residue matrix R_{q,(ij)} = HV_iq VG_qj, formed once, when it fits
            use_residues = _BYTES * nF * nr * nc <= budget / 2
            fixed = _BYTES * nF * nr * nc if use_residues else 0
            per_point = _BYTES * (2 * nF + 2 * nr * nc + (0 if use_residues else nr * nF))
        else:
            fixed = 0
            per_point = _BYTES * (2 * nF ** 2 + 2 * nF * nc + 2 * nr * nc)
        room = budget - fixed - out_bytes
        if room < per_point:
            raise MemoryError(
                f"evaluating the HTF at {npoints} points needs about "
                f"{_size(fixed + out_bytes + per_point)} (result {_size(out_bytes)}, "
                f"harmonic state space of {nF} states), more than "
                f"ltp.config.defaults['htf.max_memory'] = {_size(budget)}; evaluate fewer "
                "points or components, or raise the limit")
        return max(1, int(room // per_point)), use_residues

    def _modal_chunk(self, x, r, c, rows, cols, use_residues):
        # H(x)_{ij} = Σ_q HV_iq VG_qj / (x - λ_q)
        lam, HV, VG = self.modal
        gap = x[:, None] - lam[None, :]
        if np.any(np.abs(gap) <= 1e-13 * np.maximum(1.0, np.abs(lam))):
            raise ValueError("the HTF is not defined at a Floquet exponent "
                             "(evaluation point is a pole)")
        inv_gap = 1.0 / gap
        if not use_residues:
            return (HV[r][None] * inv_gap[:, None, :]) @ VG[:, c]
        key = (None if rows is None else tuple(rows), None if cols is None else tuple(cols))
        if key not in self._residues:
            self._residues[key] = _residue_matrix(HV[r], VG[:, c])
        flat, shape = self._residues[key]
        prod = (flat.T @ inv_gap.T).T if sparse.issparse(flat) else inv_gap @ flat
        return prod.reshape((len(x),) + shape)

    def _solve_chunk(self, x, r, c):
        M = -np.broadcast_to(self.F, (len(x),) + self.F.shape)
        idx = np.arange(self.F.shape[0])
        M[:, idx, idx] += x[:, None]
        Gc = self.G[:, c]
        try:
            X = np.linalg.solve(M, np.broadcast_to(Gc, (len(x),) + Gc.shape))
        except np.linalg.LinAlgError:
            raise ValueError("the HTF is not defined at a pole of the harmonic "
                             "state space (singular resolvent)") from None
        return self.Hc[r] @ X


#
# Helpers
#

_BYTES = 16                 # one complex128
# eig(F) costs about as much as 25-35 dense resolvent solves of the same size
# (measured for 100 to 800 harmonic states), plus the inverse eigenvectors
_MODAL_BREAK_EVEN = 40


def _size(nbytes):
    return f"{nbytes / 1e9:.3g} GB" if nbytes >= 1e8 else f"{nbytes / 1e6:.3g} MB"


def _check_setup_memory(nF, nF_check, where):
    """Refuse a harmonic state space whose construction cannot fit the budget."""
    # F, its Toeplitz parts and eigenvectors V, V^{-1} (6 nF^2); the
    # truncation check builds one more of nF_check states (3 nF_check^2)
    need = _BYTES * (6 * nF ** 2 + 3 * nF_check ** 2)
    budget = float(config.defaults['htf.max_memory'])
    if need > budget:
        raise MemoryError(
            f"{where}: the harmonic state space has {nF} states and needs about "
            f"{_size(need)}, more than ltp.config.defaults['htf.max_memory'] = "
            f"{_size(budget)}; lower nharmonics or internal_harmonics, or raise the limit")


def _residue_matrix(HV, VG):
    """Residues ``R_{q,(ij)} = HV_iq VG_qj`` of the modal form, sparse when mostly zero.

    In Floquet form with band-limited B and C most residues vanish, and the
    evaluation ``H(x) = (1/(x - λ)) R`` is then a sparse product.
    """
    flat = (HV.T[:, :, None] * VG[:, None, :]).reshape(HV.shape[1], -1)
    big = np.abs(flat) > 1e-15 * np.abs(flat).max(initial=0.0)
    if np.count_nonzero(big) < 0.2 * flat.size:
        flat = sparse.csr_matrix(np.where(big, flat, 0))
    return flat, (HV.shape[0], VG.shape[1])


def _toeplitz(coeffs, Ki):
    """Block Toeplitz ``[P_{n-m}]``, n, m = -Ki..Ki, from coefficients -2Ki..2Ki."""
    harm = np.arange(-Ki, Ki + 1)
    idx = harm[:, None] - harm[None, :] + 2 * Ki
    blocks = coeffs[idx]                          # (2Ki+1, 2Ki+1, r, c)
    r, c = coeffs.shape[1:]
    return blocks.transpose(0, 2, 1, 3).reshape((2 * Ki + 1) * r, (2 * Ki + 1) * c)


def _central(Ki, K, size):
    return np.arange((Ki - K) * size, (Ki + K + 1) * size)


def _bandlimited(sys, margin):
    """True when B, C, D have exact Fourier series with at most `margin` harmonics."""
    for M in (sys.B, sys.C, sys.D):
        if M.nharmonics is None or M.nharmonics > margin:
            return False
    return sys.B.nharmonics + sys.C.nharmonics <= margin


def _internal_order(sys, K, internal):
    if internal is not None:
        Ki = check_positive_int(internal, 'internal_harmonics', minimum=0)
        if Ki < K:
            raise ValueError(f"internal_harmonics={Ki} must be >= nharmonics={K}")
        return Ki
    hb = [M.nharmonics for M in (sys.B, sys.C)]
    if sys.A.is_constant and None not in hb:
        return K + hb[0] + hb[1]
    return K + 10 + max(h if h is not None else 0 for h in hb)


def _check_truncation(sys, K, Ki, hss, method):
    probe = 1j * sys.omega_p * np.array([0.137, 0.61, 1.93])
    ref = _HarmonicStateSpace.continuous(sys, K, Ki + 8, method)
    try:
        a, b = hss.evaluate(probe), ref.evaluate(probe)
    except ValueError:
        return
    err = np.abs(a - b).max() / max(np.abs(b).max(), 1e-300)
    if err > 1e-6:
        warnings.warn(f"HTF truncation at internal_harmonics={Ki} has not converged "
                      f"(relative change {err:.1e} with {Ki + 8}); increase "
                      "internal_harmonics", UserWarning, stacklevel=3)


def _default_omega(H):
    w = H.omega_p
    if H.dt:
        return np.linspace(1e-3, np.pi / H.dt, 500)[:-1]
    return np.logspace(np.log10(w / 100), np.log10(10 * w * max(1, H.nharmonics)), 500)


def _data_array(data, name, allow_complex=False):
    """4D array of a data HTF: finite values or NaN (not identified)."""
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
