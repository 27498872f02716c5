"""Canonical form and matrix errors for comparing LTP realizations.

An identified LTP is known only up to a state transformation.  For a
system in Floquet form (constant A) the thesis compares realizations in
controllable canonical form (eqs. 4.122-4.124): with the period average
``b = B̄_0`` of the input column and the characteristic polynomial
``s^n + a_1 s^{n-1} + ... + a_n`` of A, the constant change of state
``x = Q z``, ``Q = [b, Ab, ..., A^{n-1}b] W``, with the Hankel matrix

    W = [[a_{n-1}, a_{n-2}, ..., a_1, 1],
         [a_{n-2}, ...,       1,   0],
         ...
         [1,       0,  ...,        0]],

gives ``Q^{-1} A Q`` the companion form with last row ``[-a_n, ..., -a_1]``
and ``Q^{-1} b = e_n``; ``B(t) -> Q^{-1} B(t)``, ``C(t) -> C(t) Q``.

The errors of eq. (4.125) are normalised norms: ``‖A - Â‖_2 / ‖A‖_2``
(spectral norm) for constant A, and for periodic matrices the signal norm
``‖M‖ = (mean over one period of ‖M(t)‖_F^2)^{1/2}``.
"""

from typing import NamedTuple

import numpy as np
import scipy.signal
from control.exception import ControlArgument, ControlDimension
from scipy.optimize import linear_sum_assignment

from .._core.ltpsys import ltpss
from .._core.floquet import floquet_exponents
from .._core.timeresp import forced_response
from .._frequency.htf import htf
from .._core.coerce import as_ltp
from .._core.validation import check_positive_int, real_array

__all__ = ['to_canonical', 'matrix_errors', 'MatrixErrors', 'compare_ltp', 'LTPComparison']

# Controllability matrices with a larger condition number are treated as singular.
_COND_MAX = 1e12


def to_canonical(sys, input=0, name=None):
    """Controllable canonical form of an LTP system in Floquet form.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous- or discrete-time LTP with constant A.
    input : int
        Input whose period-averaged column ``B̄_0`` defines the form
        (default 0).
    name : str, optional
        Name of the result (default: name of `sys` with '$canonical').

    Returns
    -------
    LTPStateSpace
        Same system with ``A`` in companion form (last row ``[-a_n, ...,
        -a_1]``), ``B̄_0[:, input] = e_n``, ``B(t) = Q^{-1} B(t)`` and
        ``C(t) = C(t) Q`` (module notes), as in thesis eqs. (4.122)-(4.124).

    Notes
    -----
    The form removes constant changes of state only.  Two Floquet forms of
    one system may differ by the branch of their exponents (``λ -> λ +
    jkω_p`` with a periodic change of state, which also moves the
    harmonics of B(t) and C(t)); their canonical forms then differ by
    O(ω_p) in A.  Compare identified models with `compare_ltp` (HTFs and
    exponents modulo ``jω_p``), or bring both to the same branch first.

    Raises
    ------
    ControlArgument
        If `sys` is not an `LTPStateSpace` or `input` is not an integer.
    ValueError
        If A is not constant, `input` is out of range, or ``(A, B̄_0)`` is
        not controllable.
    TypeError
        For unknown keyword arguments.

    Examples
    --------
    >>> B = ltp.PeriodicMatrix([[[0.0], [0.2]], [[0.0], [1.0]], [[0.0], [0.2]]], 1.0)
    >>> sys = ltp.ltpss([[-1.0, 2.0], [0.0, -3.0]], B, [[1.0, 0.0]], 0, period=1.0)
    >>> can = to_canonical(sys)
    >>> np.round(can.A(0), 10) + 0.0
    array([[ 0.,  1.],
           [-3., -4.]])
    >>> np.round(can.B.fourier(0)[0].real, 10) + 0.0
    array([[0.],
           [1.]])
    """
    sys = as_ltp(sys)
    if not sys.is_floquet_form:
        raise ValueError("sys must be in Floquet form (constant A); apply "
                         "ltpcontrol.floquet_transform first")
    if isinstance(input, (bool, np.bool_)) or not isinstance(input, (int, np.integer)):
        raise ControlArgument(f"input must be an integer, got {input!r}")
    if not 0 <= input < sys.ninputs:
        raise ValueError(f"input must be in 0..{sys.ninputs - 1}, got {input}")
    n = sys.nstates
    A = sys.A(0.0)
    b = _mean(sys.B, sys)[:, input]
    # Q = [b, Ab, ..., A^{n-1} b] W,  char poly s^n + a_1 s^{n-1} + ... + a_n
    ctrb = np.column_stack([np.linalg.matrix_power(A, k) @ b for k in range(n)])
    if np.linalg.cond(ctrb) > _COND_MAX:
        raise ValueError(f"(A, mean B[:, {input}]) of sys is not controllable; the "
                         "controllable canonical form does not exist")
    a = np.poly(A).real
    W = np.zeros((n, n))
    for i in range(n):
        W[i, :n - i] = a[n - 1 - i::-1][:n - i]          # a_{n-1-i}, ..., a_1, 1
    Q = ctrb @ W
    Qinv = np.linalg.inv(Q)
    if sys.isdtime(strict=True):
        N = sys.nsteps
        Bn, Cn = Qinv @ sys.B.sample(N), sys.C.sample(N) @ Q
        D = sys.D.sample(N)
    else:
        Bn, Cn, D = Qinv @ sys.B, sys.C @ Q, sys.D
    return ltpss(Qinv @ A @ Q, Bn, Cn, D, period=sys.period, dt=sys.dt,
                 name=sys.name + '$canonical' if name is None else name,
                 inputs=sys.input_labels, outputs=sys.output_labels)


class MatrixErrors(NamedTuple):
    """Normalised matrix errors of `matrix_errors` (thesis eq. 4.125).

    Attributes
    ----------
    A, B, C, D : float
        ``‖M_est - M_true‖ / ‖M_true‖`` for each system matrix (absolute
        error when ``‖M_true‖ = 0``).

    Examples
    --------
    >>> MatrixErrors(0.1, 0.0, 0.0, 0.0).A
    0.1
    """

    A: float
    B: float
    C: float
    D: float


def matrix_errors(est, true, nsamples=512):
    """Normalised errors between the matrices of two LTP systems (eq. 4.125).

    Parameters
    ----------
    est, true : LTPStateSpace
        Estimated and true systems, in the same state coordinates (e.g.
        both from `to_canonical`), with equal sizes, periods and timebases.
    nsamples : int
        Continuous time only: samples per period for the signal norms
        (default 512).  Discrete time uses the N steps of the period.

    Returns
    -------
    MatrixErrors
        ``‖A - Â‖_2/‖A‖_2`` (spectral norm) when both A are constant, and
        for the other matrices ``‖ΔM‖/‖M‖`` with the signal norm
        ``‖M‖ = (mean_t ‖M(t)‖_F^2)^{1/2}`` over one period.  When the true
        matrix vanishes the absolute error is returned.

    Raises
    ------
    ControlArgument
        If `est` or `true` is not an `LTPStateSpace`.
    ControlDimension
        If the sizes differ.
    ValueError
        If the periods or timebases differ.
    TypeError
        For unknown keyword arguments.

    Examples
    --------
    >>> B = ltp.PeriodicMatrix([[[0.4]], [[1.0]], [[0.4]]], 1.0)
    >>> true = ltp.ltpss([[-2.0]], B, [[1.0]], 0, period=1.0)
    >>> est = ltp.ltpss([[-2.2]], B, [[1.0]], 0, period=1.0)
    >>> err = ltp.matrix_errors(est, true)
    >>> round(err.A, 6), err.B, err.C
    (0.1, 0.0, 0.0)
    """
    _check_pair(est, true)
    nsamples = true.nsteps if true.isdtime(strict=True) else \
        check_positive_int(nsamples, 'nsamples')
    errors = []
    for key in 'ABCD':
        Me, Mt = getattr(est, key), getattr(true, key)
        if key == 'A' and Me.is_constant and Mt.is_constant:
            num = np.linalg.norm(Me(0.0) - Mt(0.0), 2)
            den = np.linalg.norm(Mt(0.0), 2)
        else:
            Se, St = Me.sample(nsamples), Mt.sample(nsamples)
            num = np.sqrt(np.mean(np.sum((Se - St) ** 2, axis=(1, 2))))
            den = np.sqrt(np.mean(np.sum(St ** 2, axis=(1, 2))))
        errors.append(float(num / den) if den > 0 else float(num))
    return MatrixErrors(*errors)


def _mean(P, sys):
    """Period average of a periodic matrix (mean of the N steps in discrete time)."""
    if sys.isdtime(strict=True):
        return P.sample(sys.nsteps).mean(axis=0)
    return P.fourier(0)[0].real


class LTPComparison(NamedTuple):
    """Basis- and branch-invariant distance between two LTP systems (`compare_ltp`).

    Attributes
    ----------
    htf_error : float
        ``max_ω ‖H_est(jω) - H_true(jω)‖_F / max_ω ‖H_true(jω)‖_F`` of the
        HTF blocks with harmonics -K..K.
    exponent_error : float
        Largest distance ``min_k |λ_est - λ_true - jkω_p|`` between matched
        Floquet exponents (absolute, in 1/s; z-plane per-step exponents in
        discrete time, compared modulo ``e^{j2π/N}``).
    exponents : ndarray
        Floquet exponents of `est`, ordered to match ``exponents_true`` and
        moved to the branch nearest to them.
    exponents_true : ndarray
        Floquet exponents of `true`.
    time_nrmse : float
        ``‖y_est - y_true‖ / ‖y_true‖`` of the simulated responses to the
        `signal` of `compare_ltp` (NaN without a signal).
    nharmonics : int
        Harmonics K of the compared HTF blocks.

    Examples
    --------
    >>> LTPComparison(1e-6, 1e-7, np.array([-1.0]), np.array([-1.0])).htf_error
    1e-06
    """

    htf_error: float
    exponent_error: float
    exponents: np.ndarray
    exponents_true: np.ndarray
    time_nrmse: float = np.nan
    nharmonics: int = 0


#: harmonics compared by default when a system's are unbounded (periodic A) or unknown
_K_ALL = 8


def _produced(sys):
    """Largest output harmonic |n| of the response to an input harmonic 0 (capped)."""
    h = [_highest(M) for M in (sys.A, sys.B, sys.C, sys.D)]
    if any(x is None for x in h) or h[0] > 0:
        return _K_ALL
    return min(_K_ALL, max(h[1] + h[2], h[3]))


def _highest(P):
    """Highest non-zero harmonic of a periodic matrix (None if given as a function)."""
    if P.nharmonics is None:
        return None
    c = np.abs(P.fourier(P.nharmonics))
    size = c.reshape(c.shape[0], -1).max(axis=1)
    K = P.nharmonics
    nonzero = [abs(k) for k in range(-K, K + 1) if size[k + K] > 0]
    return max(nonzero, default=0)


def _signal(signal, true, omega, seed):
    """(timepts, inputs) of the time-domain comparison."""
    if isinstance(signal, str):
        if signal != 'noise':
            raise ValueError(f"signal must be None, 'noise' or (timepts, inputs), got "
                             f"{signal!r}")
        # white noise low-passed to the compared band: 30 periods, 64 samples each
        rng = np.random.default_rng(seed)
        dt = true.dt if true.isdtime(strict=True) else true.period / 64
        L = int(round(30 * true.period / dt))
        cut = min(float(np.max(omega)) * dt / np.pi, 0.9)
        b, a = scipy.signal.butter(4, cut)
        u = scipy.signal.lfilter(b, a, rng.standard_normal((true.ninputs, L)), axis=1)
        return np.arange(L) * dt, u
    try:
        t, u = signal
    except (TypeError, ValueError):
        raise ControlArgument("signal must be None, 'noise' or a tuple (timepts, inputs)"
                              ) from None
    t = real_array(t, 'signal timepts', ndim=1)
    u = real_array(u, 'signal inputs', ndim=(1, 2))
    u = u.reshape(true.ninputs, -1) if u.ndim == 1 or true.ninputs == 1 else u
    if u.shape != (true.ninputs, t.size):
        raise ControlDimension(f"signal inputs must have shape (ninputs, len(timepts)) = "
                               f"{(true.ninputs, t.size)}, got {u.shape}")
    return t, u


def compare_ltp(est, true, omega, nharmonics='all', *, signal=None, seed=0):
    """Compare two LTP systems by their HTFs and Floquet exponents.

    Both quantities are invariant under any (periodic) change of state
    coordinates, so an identified model can be compared with the truth
    without aligning bases.  `to_canonical` with `matrix_errors` is not
    such a comparison: the Floquet form of a system is unique only up to
    the branch of the exponents (``λ -> λ + jkω_p`` with a periodic change
    of state that shifts the harmonics of ``B(t)`` and ``C(t)``), and a
    branch change alters the canonical A by O(ω_p) although the systems
    are identical.

    Parameters
    ----------
    est, true : LTPStateSpace
        Systems with equal sizes, periods and timebases.
    omega : array_like
        Frequencies (rad/s) at which the HTFs are compared, e.g. lines not
        used for identification.
    nharmonics : int or 'all', optional
        Harmonics -K..K of the compared HTF blocks.  'all' (default): every
        output harmonic either system produces, ``K = max(K_B + K_C, K_D)``
        for a system with constant A (a Floquet-form model), and 8 for a
        periodic A (infinitely many) or matrices given as functions.  Small
        K understates the prediction error of a model whose outer
        harmonics are wrong.
    signal : None, 'noise' or tuple, optional
        Also compare in the time domain: the responses of both systems from
        the zero state to ``(timepts, inputs)`` (inputs of shape
        ``(ninputs, len(timepts))``), or to white noise low-passed to
        ``max(omega)`` over 30 periods of 64 samples ('noise', drawn with
        `seed`), simulated by `ltpcontrol.forced_response`.  Default None.
    seed : int, optional
        Seed of the 'noise' signal (default 0).

    Returns
    -------
    LTPComparison
        ``(htf_error, exponent_error, exponents, exponents_true,
        time_nrmse, nharmonics)``.

    Raises
    ------
    ControlArgument
        If `est` or `true` is not an `LTPStateSpace`.
    ControlDimension
        If the sizes differ.
    ValueError
        If the periods or timebases differ or `omega` is empty.
    TypeError
        For unknown keyword arguments.

    Examples
    --------
    A system and the same system in other coordinates, ``x = S z``:

    >>> B = ltp.PeriodicMatrix([[[0.0], [0.2]], [[0.0], [1.0]], [[0.0], [0.2]]], 1.0)
    >>> true = ltp.ltpss([[-1.0, 2.0], [0.0, -3.0]], B, [[1.0, 0.0]], 0, period=1.0)
    >>> S = np.array([[2.0, 1.0], [0.0, 1.0]])
    >>> est = ltp.ltpss(np.linalg.solve(S, true.A(0) @ S), np.linalg.inv(S) @ B,
    ...                 true.C(0) @ S, 0, period=1.0)
    >>> cmp = ltp.compare_ltp(est, true, [0.5, 1.5])
    >>> cmp.htf_error < 1e-12, cmp.exponent_error < 1e-12
    (True, True)
    >>> cmp.nharmonics                              # B has 1 harmonic, C none
    1
    >>> cmp = ltp.compare_ltp(est, true, [0.5, 1.5], signal='noise')
    >>> bool(cmp.time_nrmse < 1e-10)
    True
    """
    _check_pair(est, true)
    omega = real_array(omega, 'omega', ndim=(0, 1)).ravel()
    if omega.size == 0:
        raise ValueError("omega must hold at least one frequency")
    if isinstance(nharmonics, str) and nharmonics == 'all':
        K = max(_produced(est), _produced(true))
    else:
        K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
    time_nrmse = np.nan
    if signal is not None:
        t, u = _signal(signal, true, omega, seed)
        yt = forced_response(true, t, u).outputs
        ye = forced_response(est, t, u).outputs
        time_nrmse = float(np.linalg.norm(ye - yt) / max(np.linalg.norm(yt),
                                                         np.finfo(float).tiny))
    s = np.exp(1j * omega * true.dt) if true.isdtime(strict=True) else 1j * omega
    Ht, He = htf(true, K)(s), htf(est, K)(s)
    scale = max(np.linalg.norm(Ht, axis=(0, 1)).max(), np.finfo(float).tiny)
    htf_error = float(np.linalg.norm(He - Ht, axis=(0, 1)).max() / scale)
    lt, le = floquet_exponents(true), floquet_exponents(est)
    if true.isdtime(strict=True):
        # per-step exponents ρ are defined up to e^{j2πk/N}
        rot = np.exp(2j * np.pi / true.nsteps)
        k = np.round(np.angle(lt[:, None] / le[None, :]) / np.angle(rot))
        moved = le[None, :] * rot ** k
    else:
        wp = 2 * np.pi / true.period
        k = np.round((lt[:, None] - le[None, :]).imag / wp)
        moved = le[None, :] + 1j * wp * k
    dist = np.abs(moved - lt[:, None])
    rows, cols = linear_sum_assignment(dist)
    return LTPComparison(htf_error, float(dist[rows, cols].max()) if lt.size else 0.0,
                         moved[rows, cols], lt, time_nrmse, K)


def _check_pair(est, true):
    """Both LTPStateSpace of equal sizes, periods and timebases."""
    est, true = as_ltp(est, 'est'), as_ltp(true, 'true')
    if (est.nstates, est.ninputs, est.noutputs) != (true.nstates, true.ninputs, true.noutputs):
        raise ControlDimension(
            f"est has (states, inputs, outputs) = {(est.nstates, est.ninputs, est.noutputs)} "
            f"but true has {(true.nstates, true.ninputs, true.noutputs)}")
    if not np.isclose(est.period, true.period, rtol=1e-9, atol=0):
        raise ValueError(f"est and true have different periods ({est.period} and {true.period})")
    if est.isdtime(strict=True) != true.isdtime(strict=True) or (
            est.isdtime(strict=True) and not np.isclose(est.dt, true.dt, rtol=1e-9, atol=0)):
        raise ValueError(f"est and true have different timebases (dt={est.dt} and {true.dt})")
