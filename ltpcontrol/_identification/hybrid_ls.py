"""Least-squares identification of switching LTP systems from full-state data.

The model (thesis §4.1) is a linear time-periodic system

    x'(t) = A(t) x(t) + B(t) u(t),    A(t) = Σ_i s^i(t) A^i(t),  B(t) = Σ_i s^i(t) B^i(t),

whose `M` modes are switched on by known rectangular functions ``s^i(t) = 1`` on
``[t_i, t_{i+1}) + nT``.  Each mode is a smooth periodic matrix truncated to
```K``` harmonics, ``A^i(t) = Σ_{|k|≤K} A^i_k e^{jkω_p t}``.  In the frequency domain
(eq. 4.11)

    jω X(ω) = Σ_i Σ_k A^i_k X^i_k(ω) + Σ_i Σ_k B^i_k U^i_k(ω),
    X^i_k(ω) = Σ_{|n|≤N} S^i_{n-k} X(ω - nω_p),

which is linear in the unknown coefficients.  Evaluating it at ``ω + hω_p``
(``|h| ≤ h_max``) for every excited input line ``ω`` of every record, splitting
real and imaginary parts and imposing ``A^i_{-k} = conj(A^i_k)`` (eqs. 4.13–4.21)
gives a real linear regression solved by least squares (eq. 4.22).
"""

import warnings

import numpy as np
from control.exception import ControlDimension

from .._core.ltpsys import ltpss
from .._core.periodic_matrix import PeriodicMatrix
from .._core.validation import (check_period, check_positive, check_positive_int, real_array,
                          time_record)

__all__ = ["hybrid_ls", "HybridLSResult"]

# relative rms of the state spectrum off the excited lines above which the
# records are reported as not being steady-state responses
_STRAY_TOL = 1e-3


class HybridLSResult:
    """Fourier coefficients of a switching LTP model identified by `hybrid_ls`.

    The model is ``x' = A(t) x + B(t) u`` with ``A(t) = A^i(t)`` for
    ``t mod T`` in ``[t_i, t_{i+1})`` and
    ``A^i(t) = Σ_{k=-K}^{K} A[i, k+K] e^{jkω_p t}`` (likewise for `B`).

    Parameters
    ----------
    A : array_like, shape (M, 2K+1, n, n)
        Fourier coefficients of the mode state matrices, harmonics -K..K.
    B : array_like, shape (M, 2K+1, n, m)
        Fourier coefficients of the mode input matrices.
    period : float
        Period ``T`` of the system.
    switching_times : array_like, shape (M,)
        Mode start times ``t_1 = 0 < t_2 < ... < t_M < T``.
    nequations, rank : int, optional
        Size and numerical rank of the regression that produced the estimate.
    residual : float, optional
        Relative least-squares residual of that regression.

    Attributes
    ----------
    A : ndarray, shape (M, 2K+1, n, n), complex
        Fourier coefficients of the mode state matrices ``A^i(t)``; index
        ``k + K`` holds harmonic ``k``, and ``A[i, K-k] == A[i, K+k].conj()``.
    B : ndarray, shape (M, 2K+1, n, m), complex
        Fourier coefficients of the mode input matrices ``B^i(t)``.
    period : float
        Period ``T``.
    switching_times : ndarray, shape (M,)
        Mode start times.
    nharmonics : int
        Number ``K`` of harmonics per mode.
    nunknowns : int
        Number of real unknowns per state component, ``M (2K+1) (n+m)``.
    nequations, rank : int or None
        Real equations per state component and rank of the regression matrix.
    residual : float or None
        Relative residual ``‖N v - Y‖ / ‖Y‖`` of eq. 4.21.
    success : bool
        True unless the regression was rank deficient (`rank` below
        `nunknowns`), in which case the estimate is not unique.
    message : str
        Description of the outcome.
    nfev : int
        0: the estimate is a single least-squares solve.

    The attributes are read-only.

    Examples
    --------
    Usually returned by `hybrid_ls`; a model can also be set up by hand:

    >>> A = np.zeros((2, 3, 1, 1), complex)
    >>> A[0, 1], A[1, 1], A[1, 0], A[1, 2] = -1, -2, 0.5, 0.5
    >>> res = ltp.HybridLSResult(A, np.ones((2, 3, 1, 1)) / 3, 1.0, [0, 0.5])
    >>> res
    <HybridLSResult: M=2 modes, K=1, n=1, m=1, period=1.0>
    >>> res.nunknowns
    12
    """

    def __init__(self, A, B, period, switching_times, *, nequations=None, rank=None,
                 residual=None):
        A = real_array(A, "A", ndim=4, allow_complex=True).astype(complex)
        B = real_array(B, "B", ndim=4, allow_complex=True).astype(complex)
        M, nk, n, _ = A.shape
        if nk % 2 != 1 or A.shape[3] != n:
            raise ControlDimension(
                f"A must have shape (M, 2K+1, n, n), got {A.shape}")
        if B.shape[:3] != (M, nk, n):
            raise ControlDimension(
                f"B must have shape {(M, nk, n)} + (m,) to match A, got {B.shape}")
        self.period = check_period(period)
        self.switching_times = _check_switching_times(switching_times, self.period)
        if len(self.switching_times) != M:
            raise ControlDimension(f"switching_times must hold M={M} times (one "
                                   f"per mode of A), got {len(self.switching_times)}")
        A.flags.writeable = B.flags.writeable = False
        self.A, self.B = A, B
        self.nharmonics = nk // 2
        self.nunknowns = M * nk * (n + B.shape[3])
        self.nequations, self.rank, self.residual = nequations, rank, residual
        self.success = rank is None or rank >= self.nunknowns
        self.message = ("" if rank is None else
                        f"rank {rank} of {self.nunknowns} unknowns from {nequations} "
                        f"equations, relative residual {residual:.3g}")
        self.nfev = 0
        self._frozen = True

    def __setattr__(self, key, value):
        if getattr(self, '_frozen', False):
            raise AttributeError(f"HybridLSResult is read-only (cannot set {key})")
        super().__setattr__(key, value)

    def __repr__(self):
        M, _, n, _ = self.A.shape
        return (f"<HybridLSResult: M={M} modes, K={self.nharmonics}, n={n}, "
                f"m={self.B.shape[3]}, period={self.period}>")

    def matrices(self):
        """Return the identified ``A(t)`` and ``B(t)`` as periodic matrices.

        Each is a switching `PeriodicMatrix` whose i-th piece is the Fourier
        synthesis ``Σ_{|k|≤K} A^i_k e^{jkω_p t}`` (eq. 4.23), active on
        ``[t_i, t_{i+1})``.

        Returns
        -------
        A : PeriodicMatrix
            State matrix, shape (n, n).
        B : PeriodicMatrix
            Input matrix, shape (n, m).

        Examples
        --------
        >>> A = np.zeros((2, 3, 1, 1), complex)
        >>> A[0, 1], A[1, 1], A[1, 0], A[1, 2] = -1, -2, 0.5, 0.5
        >>> res = ltp.HybridLSResult(A, np.ones((2, 3, 1, 1)) / 3, 1.0, [0, 0.5])
        >>> At, Bt = res.matrices()
        >>> At([0.25, 0.5, 1.25])[:, 0, 0]      # -1, then -2 + cos(2πt)
        array([-1., -3., -1.])
        """
        times = list(self.switching_times)
        return tuple(
            PeriodicMatrix.switching([PeriodicMatrix(c, self.period) for c in coeffs],
                                     times, self.period)
            for coeffs in (self.A, self.B))

    def model(self, name=None):
        """Return the identified model as an `LTPStateSpace`.

        The state is the output (``C = I``, ``D = 0``); ``A(t)`` and ``B(t)``
        are the switching periodic matrices of `matrices`.

        Parameters
        ----------
        name : str, optional
            Name of the system.

        Returns
        -------
        sys : LTPStateSpace
            ``x' = A(t) x + B(t) u``, ``y = x``.

        Examples
        --------
        >>> A = np.zeros((2, 1, 1, 1)); A[:, 0] = [[[-1.0]], [[-3.0]]]
        >>> res = ltp.HybridLSResult(A, np.ones((2, 1, 1, 1)), 1.0, [0, 0.5])
        >>> sys = res.model()
        >>> sys.period
        1.0
        """
        n, m = self.A.shape[2], self.B.shape[3]
        At, Bt = self.matrices()
        return ltpss(At, Bt, np.eye(n), np.zeros((n, m)), self.period, name=name)


def hybrid_ls(t, x, u, period, switching_times, nharmonics=1, *, nconv=None,
              nshifts=None, excitation_tol=1e-3, return_info=False, name=None):
    """Identify a switching LTP system from full-state data by least squares.

    Estimates the Fourier coefficients of every mode ``A^i(t)``, ``B^i(t)`` of
    ``x' = A(t) x + B(t) u`` (thesis §4.1, eqs. 4.12–4.22) from steady-state
    records of the state and input, given the period and the switching times.

    Parameters
    ----------
    t : array_like or list of array_like
        Uniformly spaced sample times of one record, shape (L,), or a list of
        such arrays, one per record (experiment).  Each record must span an
        integer number of periods: ``L dt`` (or ``(L-1) dt`` when the last
        sample closes the record, in which case it is dropped) must be a
        multiple of `period`.
    x : array_like or list of array_like
        State measurements, shape (n, L) (or (L,) when n = 1), one array per
        record.
    u : array_like or list of array_like
        Inputs, shape (m, L) (or (L,) when m = 1), one array per record.
    period : float
        Period ``T`` of the system.
    switching_times : array_like
        Mode start times ``t_1 = 0 < t_2 < ... < t_M < T`` (thesis eq. 4.3);
        ``[0]`` identifies a single smooth LTP system.
    nharmonics : int, optional
        Number of harmonics ``K`` estimated for each ``A^i(t)``, ``B^i(t)``
        (thesis ``K``); ``K = 0`` gives a piecewise LTI model.  Default 1.

    nconv : int, optional
        Truncation ``N`` of the convolution ``X^i_k(ω) = Σ_{|n|≤N} S^i_{n-k}
        X(ω - nω_p)`` with the switching-function coefficients (thesis ``N``,
        Remark 3).  Default: the largest ``N`` with ``N ω_p`` below the Nyquist
        frequency of the slowest-sampled record.
    nshifts : int, optional
        Equations are formed at ``ω + hω_p`` for ``|h| ≤ nshifts`` around every
        excited input frequency ``ω`` (thesis ``h``, eq. 4.19).  The input
        spectrum sits on the excited lines only, so these equations see the
        harmonics ``|h| <= nshifts`` of ``B(t)`` (and, when the states carry no
        harmonics beyond the input lines, of ``A(t)``): a unique estimate
        needs ``2 nshifts + 1 >= M (2K+1)``.  Default: the smallest such
        value, and at least 2.
    excitation_tol : float, optional
        A DFT line of a record is taken as excited when its input amplitude
        exceeds ``excitation_tol`` times the largest input line of that
        record.  Default 1e-3.
    return_info : bool, optional
        Also return the estimated coefficients and regression diagnostics.
    name : str, optional
        Name of the identified system.

    Returns
    -------
    sys : LTPStateSpace
        Identified model ``x' = A(t) x + B(t) u``, ``y = x`` with switching
        periodic matrices (`HybridLSResult.model`).
    info : HybridLSResult
        Only with ``return_info=True``: the Fourier coefficients ``info.A``
        (M, 2K+1, n, n) and ``info.B`` (M, 2K+1, n, m), the rank and residual
        of the regression and scipy's `success`, `message`, `nfev`.

    Raises
    ------
    ControlDimension
        If the shapes of `t`, `x`, `u` disagree between or within records.
    ValueError
        If `switching_times` are not increasing in ``[0, T)`` from 0, a record
        is not uniformly sampled or does not span whole periods, the data
        contain NaN, the input of a record is identically zero, or there are
        fewer equations than unknowns.
    TypeError
        If an unknown keyword is given.

    Warns
    -----
    UserWarning
        If the regression matrix is rank deficient (too few or too similar
        excitation frequencies), or if more than 1e-3 (relative rms) of a
        record's state spectrum lies off the excited lines and their
        ``ω_p``-shifts, i.e. the record is not a periodic steady state.

    Notes
    -----
    Each record is assumed to be a steady-state response: the DFT of a record
    holding an integer number of periods of both the system and the input then
    gives the exact Fourier lines ``X(ω)`` up to aliasing.  Lines beyond the
    Nyquist frequency are taken as zero.  The regression per state component
    has ``M (2K+1) (n+m)`` real unknowns and ``2 (2 h + 1)`` real equations per
    excited line.  Records must therefore start from the periodic steady
    state; a lightly damped LTP (Floquet multipliers near the unit circle)
    needs the exact periodic initial state ``x0 = (I - Φ)^{-1} x_forced``
    (see :ref:`thesis-notes`).  The method is that of [Uyanik2016b]_.

    The error floor is set by aliasing of the non-smooth state and by the
    truncation ``N``; it falls as the sampling rate and `nconv` grow.  On the
    switching Mathieu example of thesis §4.1.3 the largest coefficient error
    is about 2e-2 at 100 Hz and 2e-4 at 1 kHz.  Work and memory grow as
    (excited lines) x (2h+1) x (2N+1) x (n+m); lower `nconv` for broadband
    inputs with many excited lines.

    Examples
    --------
    A scalar system whose pole switches from -1 to -3 at mid-period,
    driven by one sine per record (simulated past its transient):

    >>> from scipy.integrate import solve_ivp
    >>> T = 1.0
    >>> def rhs(s, z, w):
    ...     return (-1.0 if s % T < T / 2 else -3.0) * z + np.sin(w * s)
    >>> t = np.arange(10, 20, 1e-3)
    >>> ws = 2 * np.pi * np.array([0.3, 0.7, 1.1])
    >>> xs = [solve_ivp(rhs, [0, 20], [0.0], args=(w,), t_eval=t, method="DOP853",
    ...                 rtol=1e-10, atol=1e-12).y for w in ws]
    >>> us = [np.sin(w * t) for w in ws]
    >>> sys, res = ltp.hybrid_ls([t] * 3, xs, us, T, [0, T / 2], nharmonics=0,
    ...                          return_info=True)
    >>> res
    <HybridLSResult: M=2 modes, K=0, n=1, m=1, period=1.0>
    >>> res.success, sys.nstates
    (True, 1)
    >>> res.A[:, 0, 0, 0].real.round(3), res.B[:, 0, 0, 0].real.round(3)
    (array([-1., -3.]), array([1., 1.]))
    """
    period = check_period(period)
    K = check_positive_int(nharmonics, "nharmonics", minimum=0)
    tol = check_positive(excitation_tol, "excitation_tol", below=1)
    tsw = _check_switching_times(switching_times, period)
    # the B^i_k columns span 2h+1 shifts: 2h+1 >= M(2K+1) (see nshifts)
    h = max(2, len(tsw) * (2 * K + 1) // 2) if nshifts is None else \
        check_positive_int(nshifts, "nshifts", minimum=0)
    records = _records(t, x, u, period)
    n, m = records[0][2].shape[0], records[0][3].shape[0]

    if nconv is None:
        # largest N with N ω_p < ω_Nyquist = π/dt
        nconv = max(1, int(np.ceil(min(period / (2 * r[0]) for r in records)) - 1))
    N = check_positive_int(nconv, "nconv", minimum=0)

    # W^i = P S^i maps the 2N+1 shifted spectra X(ω - nω_p) to the 2K+1 real
    # regressors of mode i (eqs. 4.11, 4.16-4.17)
    W = _regressor_maps(tsw, period, K, N)

    rows_x, rows_u, rhs, stray = [], [], [], 0.0
    for dt, xs, us in _group_by_length(records):
        Phi_x, Phi_u, Y, off = _regression_rows(dt, xs, us, period, W, N, h, tol)
        rows_x.append(Phi_x), rows_u.append(Phi_u), rhs.append(Y)
        stray = max(stray, off)

    # eq. 4.20-4.21: stack real and imaginary parts of all equations
    Phi = np.concatenate([np.concatenate(rows_x), np.concatenate(rows_u)], axis=1)
    Y = np.concatenate(rhs)
    Phi, Y = np.concatenate([Phi.real, Phi.imag]), np.concatenate([Y.real, Y.imag])
    nunk = Phi.shape[1]
    if Phi.shape[0] < nunk:
        raise ValueError(
            f"too little data: {Phi.shape[0]} real equations per state for {nunk} "
            "unknowns; add records or excitation frequencies, or lower "
            "nharmonics or the number of switching times")
    if stray > _STRAY_TOL:
        warnings.warn(
            f"hybrid_ls: the state records are not periodic steady-state responses "
            f"({stray:.1e} of the state spectrum lies off the excited lines and "
            "their harmonics); start each record on the periodic steady state "
            "or the estimate is biased", UserWarning, stacklevel=2)

    # eq. 4.22 with column scaling for conditioning
    scale = np.linalg.norm(Phi, axis=0)
    scale[scale == 0] = 1.0
    v, _, rank, _ = np.linalg.lstsq(Phi / scale, Y, rcond=None)
    v = v / scale[:, None]
    if rank < nunk:
        warnings.warn(f"hybrid_ls: regression matrix is rank deficient (rank {rank} "
                      f"< {nunk} unknowns); the estimate is not unique. Use more or "
                      "different excitation frequencies or a larger nshifts.",
                      UserWarning, stacklevel=2)
    ynorm = np.linalg.norm(Y)
    residual = np.linalg.norm(Phi @ v - Y) / ynorm if ynorm > 0 else 0.0

    M = len(tsw)
    A = _unpack(v[:M * (2 * K + 1) * n], M, K, n)
    B = _unpack(v[M * (2 * K + 1) * n:], M, K, m)
    info = HybridLSResult(A, B, period, tsw, nequations=Phi.shape[0], rank=int(rank),
                          residual=float(residual))
    sys = info.model(name=name)
    return (sys, info) if return_info else sys


#
# Input processing
#

def _check_switching_times(switching_times, period):
    tsw = real_array(switching_times, "switching_times", ndim=(0, 1))
    tsw = np.atleast_1d(tsw)
    if tsw.size == 0 or tsw[0] != 0:
        raise ValueError(f"switching_times must start at 0, got {tsw}")
    if np.any(np.diff(tsw) <= 0):
        raise ValueError(f"switching_times must be strictly increasing, got {tsw}")
    if tsw[-1] >= period:
        raise ValueError(
            f"switching_times must lie in [0, period) = [0, {period}), got {tsw}")
    return tsw


def _records(t, x, u, period):
    """Return [(dt, t0, x (n, L), u (m, L)), ...] for one or several records."""
    multi = isinstance(t, (list, tuple)) and len(t) > 0 and np.ndim(t[0]) == 1
    if multi:
        for name, arg in (("x", x), ("u", u)):
            if not isinstance(arg, (list, tuple, np.ndarray)) or len(arg) != len(t):
                raise ControlDimension(
                    f"{name} must be a list of {len(t)} records, one per time "
                    "vector in t")
        triples = list(zip(t, x, u))
    else:
        triples = [(t, x, u)]
    records = []
    for j, (tj, xj, uj) in enumerate(triples):
        where = f"[{j}]" if multi else ""
        tj, dt, (xj, uj) = time_record(tj, {f"x{where}": xj, f"u{where}": uj},
                                       tname=f"t{where}", min_samples=3)
        L = tj.size
        if not np.any(uj):
            raise ValueError(f"u{where} is identically zero: the record has no "
                             "excitation, so it carries no information on A(t) and B(t)")
        # a record closed by a repeated periodic sample drops its last sample
        nper = L * dt / period
        if abs(nper - round(nper)) > 1e-6 * nper:
            nper_closed = (L - 1) * dt / period
            if abs(nper_closed - round(nper_closed)) > 1e-6 * nper_closed \
                    or round(nper_closed) < 1:
                raise ValueError(
                    f"t{where} must span an integer number of periods: length "
                    f"{L}*dt = {L * dt} is {nper:.6g} periods of {period}")
            tj, xj, uj = tj[:-1], xj[:, :-1], uj[:, :-1]
        records.append((dt, tj[0], xj, uj))
    n, m = records[0][2].shape[0], records[0][3].shape[0]
    for j, rec in enumerate(records):
        if rec[2].shape[0] != n or rec[3].shape[0] != m:
            raise ControlDimension(
                f"record {j} has {rec[2].shape[0]} states and {rec[3].shape[0]} "
                f"inputs, record 0 has {n} and {m}")
    return records


def _group_by_length(records):
    """Group records of equal length and step; yield (dt, xs, us) with phases removed.

    Each record's DFT is referred to absolute time: the Fourier line at
    ``ω_l`` of a record starting at ``t0`` is ``e^{-jω_l t0} DFT[l] / L``.
    """
    groups = {}
    for dt, t0, xj, uj in records:
        groups.setdefault((xj.shape[1], round(dt, 12)), []).append((dt, t0, xj, uj))
    for (L, _), recs in groups.items():
        dt = np.mean([r[0] for r in recs])
        t0 = np.array([r[1] for r in recs])
        omega = 2 * np.pi * np.fft.fftfreq(L, dt)
        phase = np.exp(-1j * np.outer(t0, omega))[:, None, :]
        xs = np.fft.fft(np.stack([r[2] for r in recs]), axis=-1) / L * phase
        us = np.fft.fft(np.stack([r[3] for r in recs]), axis=-1) / L * phase
        yield dt, xs, us


#
# Regression
#

def _regressor_maps(tsw, period, K, N):
    """Return W, shape (M, 2K+1, 2N+1): W^i = P S^i (eqs. 4.8, 4.11, 4.16)."""
    bounds = np.append(tsw, period)
    wp = 2 * np.pi / period
    # S^i_m = (e^{-jmω_p t_i} - e^{-jmω_p t_{i+1}}) / (j2πm),  S^i_0 = (t_{i+1}-t_i)/T
    mvals = np.arange(-(N + K), N + K + 1)
    safe = np.where(mvals == 0, 1, mvals)
    S = ((np.exp(-1j * np.outer(bounds[:-1], mvals) * wp)
          - np.exp(-1j * np.outer(bounds[1:], mvals) * wp)) / (2j * np.pi * safe))
    S[:, mvals == 0] = (np.diff(bounds) / period)[:, None]
    # Sk[i, k+K, n+N] = S^i_{n-k}
    k = np.arange(-K, K + 1)
    nn = np.arange(-N, N + 1)
    Sk = S[:, (nn[None, :] - k[:, None]) + N + K]
    # P rows: Re A_k (k = K..1), A_0, Im A_k (k = 1..K); A_k X_k + A_{-k} X_{-k}
    # = Re A_k (X_k + X_{-k}) + Im A_k j(X_k - X_{-k})  (eqs. 4.13-4.17)
    P = np.zeros((2 * K + 1, 2 * K + 1), complex)
    P[K, K] = 1
    for kk in range(1, K + 1):
        P[K - kk, [K - kk, K + kk]] = 1
        P[K + kk, [K - kk, K + kk]] = [-1j, 1j]
    return np.einsum("pk,ikn->ipn", P, Sk)


def _regression_rows(dt, xs, us, period, W, N, h, tol):
    """Complex regression rows of one group of equal-length records (eq. 4.19).

    Returns Phi_x (neq, M(2K+1)n), Phi_u (neq, M(2K+1)m), Y (neq, n) with
    ``Y = jω X(ω)`` at ``ω = ω_line + hω_p`` for every excited line, and the
    largest relative rms of the state spectrum off those lines' ω_p-shifts.
    """
    E, n, L = xs.shape
    nper = int(round(L * dt / period))  # bins per ω_p
    half = (L + 1) // 2  # bins |l| < half lie below the Nyquist frequency
    # excited lines: 0 <= l < L/2 with input amplitude above tol * largest line
    amp = np.abs(us[:, :, :half]).max(axis=1)
    exp_idx, lines = np.nonzero(amp > tol * amp.max(axis=1, keepdims=True))
    # steady-state check: x may only have lines at ±l + kω_p, i.e. at bins
    # b ≡ ±l (mod gcd(nper, L)); the rest is transient or leakage
    g = np.gcd(nper, L)
    table = np.zeros((E, g), bool)
    table[exp_idx, lines % g] = table[exp_idx, -lines % g] = True
    power = (np.abs(xs) ** 2).sum(axis=1)
    explained = table[:, np.arange(L) % g]
    stray = np.sqrt((power * ~explained).sum(axis=1) / power.sum(axis=1).clip(1e-300))

    # equation bins b = l + hω_p (one row per line and shift)
    shifts = np.arange(-h, h + 1) * nper
    bins = (lines[:, None] + shifts[None, :]).ravel()
    exp_idx = np.repeat(exp_idx, 2 * h + 1)
    keep = np.abs(bins) < half
    bins, exp_idx = bins[keep], exp_idx[keep]

    # shifted spectra G[e, c, n] = X(ω_b - nω_p), zero beyond Nyquist
    src = bins[:, None] - np.arange(-N, N + 1)[None, :] * nper
    valid = np.abs(src) < half
    Gx = xs[exp_idx[:, None], :, src % L] * valid[:, :, None]
    Gu = us[exp_idx[:, None], :, src % L] * valid[:, :, None]
    # regressors R[e, i, p, c] = Σ_n W[i, p, n] G[e, n, c]
    Phi_x = np.einsum("ipn,enc->eipc", W, Gx).reshape(len(bins), -1)
    Phi_u = np.einsum("ipn,enc->eipc", W, Gu).reshape(len(bins), -1)
    omega = 2 * np.pi * bins / (L * dt)
    Y = 1j * omega[:, None] * xs[exp_idx, :, bins % L]
    return Phi_x, Phi_u, Y, stray.max()


def _unpack(v, M, K, n):
    """Map real unknowns v (M(2K+1)c, r) to complex coefficients (M, 2K+1, r, c)."""
    r = v.shape[1]
    p = v.reshape(M, 2 * K + 1, n, r).transpose(0, 1, 3, 2)
    # A_0 = p[K], A_{±k} = Re A_k ± j Im A_k  with Re A_k = p[K-k], Im A_k = p[K+k]
    coeffs = np.empty((M, 2 * K + 1, r, n), complex)
    coeffs[:, K] = p[:, K]
    for k in range(1, K + 1):
        coeffs[:, K + k] = p[:, K - k] + 1j * p[:, K + k]
        coeffs[:, K - k] = p[:, K - k] - 1j * p[:, K + k]
    return coeffs
