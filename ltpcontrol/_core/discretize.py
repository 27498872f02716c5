"""Discretization of LTP systems (Tustin, zero-order hold) and its inverse.

Tustin (bilinear) rule, thesis eqs. (4.36)-(4.53).  The trapezoidal rule

    x_{k+1} - x_k = (1/c) [A_{k+1} x_{k+1} + B_{k+1} u_{k+1} + A_k x_k + B_k u_k],

with ``M_k = M(k Ts)`` and ``c = 2/Ts`` (or the prewarped ``c = ω/tan(ωTs/2)``),
becomes with the balanced state ``√(2/c) x_d[k+1] = (I + A_k/c) x_k + B_k u_k / c``

    A_d[k] = (cI - A_k)^{-1} (cI + A_k),    B_d[k] = √(2c) (cI - A_k)^{-1} B_k,
    C_d[k] = √(2c) C_k (cI - A_k)^{-1},     D_d[k] = D_k + C_k (cI - A_k)^{-1} B_k,

which are eqs. (4.50)-(4.53) when A is constant (Floquet form).  The
inverse (thesis eq. 4.104) is, per step,

    A_k = c (I + A_d[k])^{-1} (A_d[k] - I),   B_k = √(2c) (I + A_d[k])^{-1} B_d[k],
    C_k = √(2c) C_d[k] (I + A_d[k])^{-1},      D_k = D_d[k] - C_d[k] (I + A_d[k])^{-1} B_d[k].

Zero-order hold is exact: ``x[k+1] = Φ(t_{k+1}, t_k) x[k] + ∫ Φ(t_{k+1}, τ) B(τ) dτ u[k]``;
so is first-order hold (inputs linear between samples, see `_foh`).
"""

import warnings

import numpy as np
import scipy.linalg as la
import control as ct

from .ltpsys import LTPStateSpace
from .periodic_matrix import PeriodicMatrix
from .transition import expm_batch, step_transitions
from .coerce import as_ltp
from .validation import check_positive, steps_per_period
from .registry import method_alias

__all__ = ['sample_system', 'd2c']

_TUSTIN = ('tustin', 'bilinear')
_LABEL_KEYS = ('inputs', 'outputs', 'states')
# largest condition number accepted for cI - A_k or I + A_d[k]
_COND_MAX = 1e12


@method_alias
def sample_system(sys, Ts, method='zoh', alpha=None, prewarp_frequency=None,
                  name=None, copy_names=True, *, inputs=None, outputs=None, states=None):
    """Discretize a continuous-time LTP system.

    ``ct.sample_system(sys, Ts, ...)`` and ``sys.sample(Ts, ...)`` call this
    function for an `LTPStateSpace`.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous-time LTP system with period T.
    Ts : float
        Sampling time; ``N = T/Ts`` must be an integer (the period of the
        result in steps).
    method : {'zoh', 'foh', 'tustin', 'bilinear'}
        'zoh' (default): exact discretization for inputs held constant over
        each step.  'foh': exact for inputs linear between samples, with
        python-control's state ``x[k] - Γ1 u[k]`` (so ``D_d ≠ D``).  'tustin' or 'bilinear': the balanced bilinear rule of
        thesis eqs. (4.46)-(4.53) (see Notes).
    alpha : None
        Accepted for compatibility with `control.sample_system`; it only
        applies to the 'gbt' method, which is not offered, and is ignored
        with a warning.
    prewarp_frequency : float, optional
        Tustin only: frequency ω (rad/s) at which the bilinear map is exact,
        ``c = ω/tan(ωTs/2)`` instead of ``2/Ts``.  Ignored with a warning
        for 'zoh'.
    name : str, optional
        Name of the result; by default the name of `sys` with the suffix
        '$sampled' (when `copy_names` is True).
    copy_names : bool
        Copy the signal names of `sys` (default True).
    inputs, outputs, states : int, str or list of str, optional
        New signal names.

    Returns
    -------
    sysd : LTPStateSpace
        Discrete-time system with ``dt = Ts`` and period T (N steps).  Its
        A is constant whenever A of `sys` is constant.

    Raises
    ------
    ValueError
        If `sys` is not continuous-time, `Ts` does not divide the period,
        `method` is unknown, or ``cI - A(k Ts)`` is singular (Tustin).
    ControlArgument
        If `sys` is not an `LTPStateSpace`.
    TypeError
        For unknown keyword arguments.

    Notes
    -----
    The Tustin rule is the trapezoidal rule applied to the whole right-hand
    side, so a periodic ``A(t)`` is treated exactly like the periodic
    ``B(t)`` of the thesis derivation: ``A_d[k]`` uses ``A(k Ts)`` (module
    notes).  For constant A this *is* eqs. (4.50)-(4.53); for periodic A it
    keeps the original state coordinates (scaled by ``√(2/c)``), needs no
    monodromy logarithm (no period doubling, no loss of accuracy for stiff
    systems) and converges with order 2 in Ts.  To obtain the constant
    ``A_d`` of the thesis pipeline, apply `ltpcontrol.floquet_transform`
    first (continuous time) or to the result (discrete time).

    The Tustin output is ``y_d[k] ≈ y(k Ts)`` for ``u_d[k] = u(k Ts)``; the
    state is ``x_d[k] = √(c/2) [(I - A_k/c) x(k Ts) - B_k u(k Ts)/c]``.

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], lambda t: np.array([[1 + 0.5 * np.cos(2 * np.pi * t)]]),
    ...                 [[1.0]], 0, period=1.0, name='plant')
    >>> sysd = ct.sample_system(sys, 0.1, method='tustin')
    >>> sysd.name, sysd.nsteps, sysd.is_floquet_form
    ('plant$sampled', 10, True)
    >>> round(float(sysd.A(0.0)[0, 0]), 12) == round((20 - 1) / (20 + 1), 12)
    True
    """
    labels = _labels(inputs, outputs, states)
    sys = as_ltp(sys, discrete=False, lti_hint='control.sample_system')
    Ts = check_positive(Ts, 'Ts')
    N = steps_per_period(sys.period, Ts, 'Ts')
    if method not in _TUSTIN + ('zoh', 'foh'):
        raise ValueError(f"method must be 'zoh', 'foh', 'tustin' or 'bilinear', got "
                         f"{method!r}")
    if alpha is not None:
        warnings.warn("alpha only applies to the 'gbt' method, which is not available "
                      "for LTP systems; alpha is ignored", UserWarning, stacklevel=2)
    c = _bilinear_constant(Ts, prewarp_frequency, method in _TUSTIN)
    consts = [M.is_constant for M in (sys.A, sys.B, sys.C, sys.D)]
    if method == 'zoh':
        mats = _zoh(sys, N)
        consts = [consts[0], consts[0] and consts[1], consts[2], consts[3]]
    elif method == 'foh':
        mats = _foh(sys, N)
        consts = [consts[0], consts[0] and consts[1], consts[2], all(consts)]
    else:
        mats = _tustin(*(M.sample(N) for M in (sys.A, sys.B, sys.C, sys.D)), c)
        consts = _bilinear_constants(consts)
    return _build(sys, mats, consts, sys.period, Ts, name, copy_names, labels, 'sampled')


def d2c(sysd, method='tustin', prewarp_frequency=None, interpolation='fourier',
        name=None, copy_names=True, *, inputs=None, outputs=None, states=None):
    """Continuous-time LTP system from a discrete-time one (inverse Tustin).

    Parameters
    ----------
    sysd : LTPStateSpace
        Discrete-time LTP system (period N steps of ``Ts = sysd.dt``).
    method : {'tustin', 'bilinear', 'log'}
        'tustin' (default): the exact inverse of `sample_system` with
        method 'tustin' (thesis eq. 4.104, applied per step, see the module
        notes).  'log': inverse of the exact ZOH sampling of a system with
        constant A: ``A = log(A_d)/Ts``, ``B_k = W^{-1} B_d[k]`` with
        ``W = ∫_0^Ts e^{Aτ} dτ``, ``C_k = C_d[k]``, ``D_k = D_d[k]``
        (exact for B, C, D constant over each step; requires a constant
        ``A_d`` without eigenvalues on the negative real axis).
    prewarp_frequency : float, optional
        Tustin only: the prewarp frequency used for sampling.
    interpolation : {'fourier', 'hold'}
        How the N values ``M_k = M(k Ts)`` of a periodic matrix define
        ``M(t)``: trigonometric interpolation (default; exact for matrices
        with fewer than N/2 harmonics) or held constant over each step.
        Constant matrices stay constant.
    name : str, optional
        Name of the result; by default the name of `sysd` with the suffix
        '$converted' (when `copy_names` is True).
    copy_names : bool
        Copy the signal names of `sysd` (default True).
    inputs, outputs, states : int, str or list of str, optional
        New signal names.

    Returns
    -------
    sys : LTPStateSpace
        Continuous-time system with the period of `sysd`; in Floquet form
        (constant A) when ``A_d`` is constant.

    Raises
    ------
    ValueError
        If `sysd` is not discrete-time, `method` or `interpolation` is
        unknown, ``I + A_d[k]`` is singular (Tustin), or ``A_d`` is not
        constant or has no real logarithm ('log').

    Examples
    --------
    Round trip through the Tustin rule:

    >>> B = lambda t: np.array([[0.0], [1 + 0.4 * np.cos(2 * np.pi * t)]])
    >>> sys = ltp.ltpss([[0.0, 1.0], [-4.0, -0.4]], B, [[1.0, 0.0]], 0, period=1.0)
    >>> sysc = ltp.d2c(sys.sample(0.05, 'tustin'))
    >>> sysc.is_floquet_form, np.allclose(sysc.A(0.0), sys.A(0.0))
    (True, True)
    >>> np.allclose(sysc.B(0.3), sys.B(0.3))
    True
    """
    labels = _labels(inputs, outputs, states)
    sysd = as_ltp(sysd, 'sysd', discrete=True)
    if method not in _TUSTIN + ('log',):
        raise ValueError(f"method must be 'tustin', 'bilinear' or 'log', got {method!r}")
    if interpolation not in ('fourier', 'hold'):
        raise ValueError(f"interpolation must be 'fourier' or 'hold', got {interpolation!r}")
    Ts, N = sysd.dt, sysd.nsteps
    c = _bilinear_constant(Ts, prewarp_frequency, method in _TUSTIN)
    samples = [M.sample(N) for M in (sysd.A, sysd.B, sysd.C, sysd.D)]
    consts = [M.is_constant or bool(np.all(S == S[0])) for M, S in
              zip((sysd.A, sysd.B, sysd.C, sysd.D), samples)]
    if method == 'log':
        mats = _inverse_zoh(*samples, Ts, consts[0])
        consts = [True] + consts[1:]
    else:
        mats = _inverse_tustin(*samples, c)
        consts = _bilinear_constants(consts)
    mats = [M[0] if const else PeriodicMatrix.from_samples(M, sysd.period, kind=interpolation)
            for M, const in zip(mats, consts)]
    return _build(sysd, mats, [False] * 4, sysd.period, 0, name, copy_names, labels,
                  'converted')


#
# Private helpers
#

def _labels(*values):
    """The signal names given, as keywords for `LTPStateSpace`."""
    return {key: v for key, v in zip(_LABEL_KEYS, values) if v is not None}


def _bilinear_constant(Ts, prewarp_frequency, tustin):
    """``c = 2/Ts``, or ``ω/tan(ωTs/2)`` with prewarping."""
    if prewarp_frequency is None:
        return 2.0 / Ts
    if not tustin:
        warnings.warn("prewarp_frequency ignored: it only applies to the Tustin "
                      "(bilinear) method", UserWarning, stacklevel=3)
        return 2.0 / Ts
    w = check_positive(prewarp_frequency, 'prewarp_frequency')
    if w * Ts >= np.pi:
        raise ValueError(f"prewarp_frequency={w} must be below the Nyquist frequency "
                         f"π/Ts = {np.pi / Ts}")
    return w / np.tan(w * Ts / 2)


def _bilinear_constants(consts):
    """Which of A, B, C, D stay constant under the (inverse) bilinear rule."""
    cA, cB, cC, cD = consts
    return [cA, cA and cB, cA and cC, cA and cB and cC and cD]


def _check_conditioning(M, what):
    if M.shape[-1] and np.max(np.linalg.cond(M)) > _COND_MAX:
        raise ValueError(f"{what} is singular or nearly singular at some step")


def _tustin(A, B, C, D, c):
    """Per-step balanced bilinear rule, eqs. (4.50)-(4.53); arrays of shape (N, ., .)."""
    n = A.shape[1]
    M = c * np.eye(n) - A
    _check_conditioning(M, f"cI - A(k Ts) (c = {c:g}, i.e. A has an eigenvalue near the "
                           "Tustin pole at infinity; choose another Ts)")
    # A_d = (cI - A)^{-1}(cI + A),  B_d = √(2c)(cI - A)^{-1}B
    Ad = np.linalg.solve(M, c * np.eye(n) + A)
    MinvB = np.linalg.solve(M, B)
    # C_d = √(2c) C (cI - A)^{-1},  D_d = D + C (cI - A)^{-1} B
    Cd = np.sqrt(2 * c) * np.linalg.solve(M.transpose(0, 2, 1),
                                          C.transpose(0, 2, 1)).transpose(0, 2, 1)
    return Ad, np.sqrt(2 * c) * MinvB, Cd, D + C @ MinvB


def _inverse_tustin(Ad, Bd, Cd, Dd, c):
    """Per-step inverse bilinear rule, thesis eq. (4.104)."""
    n = Ad.shape[1]
    P = np.eye(n) + Ad
    _check_conditioning(P, "I + A_d[k] (A_d has an eigenvalue near -1, which the "
                           "inverse Tustin map sends to infinity)")
    # A = c (I + A_d)^{-1}(A_d - I),  B = √(2c)(I + A_d)^{-1} B_d
    A = c * np.linalg.solve(P, Ad - np.eye(n))
    PinvB = np.linalg.solve(P, Bd)
    # C = √(2c) C_d (I + A_d)^{-1},  D = D_d - C_d (I + A_d)^{-1} B_d
    C = np.sqrt(2 * c) * np.linalg.solve(P.transpose(0, 2, 1),
                                         Cd.transpose(0, 2, 1)).transpose(0, 2, 1)
    return A, np.sqrt(2 * c) * PinvB, C, Dd - Cd @ PinvB


def _zoh(sys, N):
    """Exact ZOH: ``A_d[k] = Φ(t_{k+1}, t_k)``, ``B_d[k] = ∫ Φ(t_{k+1}, τ) B(τ) dτ``."""
    h = sys.period / N
    if sys.A.is_constant and sys.B.is_constant:
        # constant A, B: [[Φ, Γ0], [0, I]] = exp([[A, B], [0, 0]] h), one step
        n, m = sys.B.shape
        aug = np.zeros((1, n + m, n + m))
        aug[0, :n, :n], aug[0, :n, n:] = sys.A(0.0) * h, sys.B(0.0) * h
        E = expm_batch(aug)
        Phi, Gamma0 = np.repeat(E[:, :n, :n], N, 0), np.repeat(E[:, :n, n:], N, 0)
    else:
        Phi, Gamma0, _ = step_transitions(sys.A, sys.B, h * np.arange(N), h)
    return Phi, Gamma0, sys.C.sample(N), sys.D.sample(N)


def _foh(sys, N):
    """Exact FOH (inputs linear between samples), in python-control's state.

    With ``x_{k+1} = Φ_k x_k + (Γ0_k - Γ1_k) u_k + Γ1_k u_{k+1}`` (``_transition``)
    and the state ``ξ_k = x_k - Γ1_{k-1} u_k``:  ``A_d[k] = Φ_k``,
    ``B_d[k] = Γ0_k - Γ1_k + Φ_k Γ1_{k-1}``, ``C_d[k] = C_k``,
    ``D_d[k] = D_k + C_k Γ1_{k-1}`` (scipy's 'foh' when A, B are constant).
    """
    h = sys.period / N
    Phi, G0, G1 = step_transitions(sys.A, sys.B, h * np.arange(N), h)
    G1prev = np.roll(G1, 1, axis=0)
    C = sys.C.sample(N)
    return Phi, G0 - G1 + Phi @ G1prev, C, sys.D.sample(N) + C @ G1prev


def _inverse_zoh(Ad, Bd, Cd, Dd, Ts, constant):
    """Matrix-logarithm inverse of exact ZOH sampling (constant A_d)."""
    if not constant:
        raise ValueError("method='log' needs a constant sysd.A; apply "
                         "floquet_transform to sysd first")
    n, m = Ad.shape[1], Bd.shape[2]
    L = la.logm(Ad[0]) if n else np.zeros((0, 0))
    L = np.asarray(L)
    scale = max(1.0, np.abs(L).max(initial=0.0))
    if np.iscomplexobj(L) and np.abs(L.imag).max(initial=0.0) > 1e-10 * scale:
        raise ValueError("sysd.A has eigenvalues on the negative real axis: no real "
                         "matrix logarithm exists (use method='tustin')")
    A = L.real / Ts
    # W = ∫_0^Ts e^{Aτ} dτ is the upper-right block of exp([[A, I], [0, 0]] Ts)
    aug = np.zeros((1, 2 * n, 2 * n))
    aug[0, :n, :n], aug[0, :n, n:] = A * Ts, np.eye(n) * Ts
    W = expm_batch(aug)[0, :n, n:]
    _check_conditioning(W[np.newaxis], "∫ e^{Aτ} dτ over one step")
    B = np.linalg.solve(W, Bd.transpose(1, 0, 2).reshape(n, -1)) \
        .reshape(n, len(Bd), m).transpose(1, 0, 2)
    return A[np.newaxis], B, Cd, Dd


def _build(sys, mats, consts, period, dt, name, copy_names, labels, suffix):
    """New LTPStateSpace; constant matrices are passed as 2D arrays."""
    A, B, C, D = (M[0] if const else M for M, const in zip(mats, consts))
    if copy_names:
        if name is None:
            name = (ct.config.defaults[f'iosys.{suffix}_system_name_prefix'] + sys.name
                    + ct.config.defaults[f'iosys.{suffix}_system_name_suffix'])
        for key, lab in zip(_LABEL_KEYS, (sys.input_labels, sys.output_labels,
                                          sys.state_labels)):
            labels.setdefault(key, lab)
    return LTPStateSpace(A, B, C, D, period, dt=dt, name=name, **labels)
