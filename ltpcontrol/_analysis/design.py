"""Periodic LQR, Kalman filters and LQG controllers.

The gains come from the stabilizing periodic Riccati solutions of
`ltpcontrol._analysis.riccati`.  LQR: ``K = R⁻¹(BᵀX + Nᵀ)`` (continuous),
``K_k = (R_k + B_kᵀX_{k+1}B_k)⁻¹(B_kᵀX_{k+1}A_k + N_kᵀ)`` (discrete).

Kalman filters by duality.  Continuous time: the filter Riccati equation
``Ṗ = AP + PAᵀ - (PCᵀ + GN) R⁻¹ (CPᵀ + NᵀGᵀ) + GQGᵀ`` runs forward; with
``τ = -t`` it is the control equation of the time-reversed, transposed
plant ``Ã(τ) = A(-τ)ᵀ, B̃(τ) = C(-τ)ᵀ``, so ``P(t) = X̃(-t)`` and
``L(t) = G̃(-t)ᵀ``.  Discrete time (predictor form, as `control.dlqe`):
``P_{k+1} = A_kP_kA_kᵀ - (A_kP_kC_kᵀ + G_kN)(C_kP_kC_kᵀ + R_k)⁻¹(.)ᵀ +
G_kQG_kᵀ`` is the control equation of the step-reversed dual ``Ã_j =
A_{N-1-j}ᵀ``, ``B̃_j = C_{N-1-j}ᵀ`` with ``P_k = X̃_{N-k}``.  The time
reversal keeps the Floquet multipliers (``Φ̃(T, 0) = Φ(T, 0)ᵀ``).
"""

import numpy as np
from control import LTI, common_timebase
from control.exception import ControlArgument, ControlDimension

from .._core.floquet import lti_representatives
from .._core.ltpsys import LTPStateSpace, series
from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .riccati import _GainTable, _care_solution, _check_weights, _table_edges, care, dare
from .._core.coerce import as_ltp
from .._core.validation import check_method, real_array
from .._core.subperiods import align_weights, common_period
from .._core.tvsystem import DiscreteLTPSystem
from .tvlyap import is_varying
from .tvdesign import tv_dlqe, tv_dlqr

__all__ = ['lqr', 'dlqr', 'lqe', 'dlqe', 'lqg']


def lqr(sys, Q, R, N=None, nsteps=None, *, integral_action=None, method=None, output=False):
    """Periodic linear quadratic regulator, as `control.lqr`.

    Minimizes ``∫ (xᵀQx + uᵀRu + 2xᵀNu) dt`` for ``ẋ = A(t)x + B(t)u``
    with the periodic state feedback ``u = -K(t) x``.  A discrete-time
    system is passed on to `dlqr`, as python-control does.

    Parameters
    ----------
    sys : LTPStateSpace
        Plant (its A and B are used).
    Q, R : array_like, PeriodicMatrix or callable
        State and input weights, (n, n) and (m, m); R(t) positive definite.
    N : array_like, PeriodicMatrix or callable, optional
        Cross weight (n, m).
    nsteps : int, optional
        Continuous time: steps per period of the Riccati solver (see
        `ltpcontrol.care`).
    integral_action : ndarray, optional
        Matrix ``C_i`` (nint, n), as in `control.lqr`: the plant is
        augmented with integrators ``ż = C_i x`` (discrete time ``z[k+1] =
        z[k] + C_i x[k]``), Q and N then have ``n + nint`` rows and K has
        ``n + nint`` columns.
    method : {None, 'slycot', 'scipy'}, optional
        python-control's choice of LTI solver, accepted so that the same
        call works; the periodic algorithm is always used.
    output : bool, optional
        Q weights the outputs ``y = Cx + Du`` instead of the state (Q is
        (p, p)): the cost ``∫ (yᵀQy + uᵀRu + 2xᵀNu) dt`` is the state
        problem with ``CᵀQC``, ``R + DᵀQD`` and ``N + CᵀQD``.

    Returns
    -------
    K : PeriodicMatrix
        Gain ``K(t) = R⁻¹(BᵀX + Nᵀ)``, shape (m, n).
    X : PeriodicMatrix
        Stabilizing periodic Riccati solution; the optimal cost from
        ``x(t0)`` is ``x(t0)ᵀ X(t0) x(t0)``.
    E : ndarray of complex
        Closed-loop Floquet exponents of ``A - BK`` (full precision).

    Raises
    ------
    ValueError
        No stabilizing solution, R not positive definite, Q or R not symmetric.
    ControlDimension
        Wrong weight shapes.

    Examples
    --------
    >>> sys = ltp.ltpss(lambda t: np.array([[0.0, 1.0], [-1 - 0.5 * np.cos(t), 0.1]]),
    ...                 [[0.0], [1.0]], np.eye(2), 0, period=2 * np.pi)
    >>> K, X, E = ltp.lqr(sys, np.eye(2), [[1.0]])
    >>> K.shape, bool(np.all(E.real < 0))
    ((1, 2), True)
    """
    check_method(method)
    if _discrete(sys, nsteps):
        return dlqr(sys, Q, R, N, integral_action=integral_action, output=output)
    if output:
        Q, R, N = _output_weights(as_ltp(sys), Q, R, N, integral_action)
    A, B = _with_integrators(sys, integral_action, 'lqr')
    X, E, K = care(A, B, Q, R, N, period=sys.period, nsteps=nsteps)
    return K, X, E


def dlqr(sys, Q, R, N=None, *, integral_action=None, method=None, output=False):
    """Periodic discrete-time linear quadratic regulator, as `control.dlqr`.

    Minimizes ``Σ_k (x_kᵀQ_kx_k + u_kᵀR_ku_k + 2x_kᵀN_ku_k)`` for
    ``x_{k+1} = A_kx_k + B_ku_k`` with ``u_k = -K_k x_k``.

    Parameters
    ----------
    sys : LTPStateSpace or DiscreteLTPSystem
        Discrete-time plant with N = period/dt steps per period (weights of
        a sub-period repeat; a `DiscreteLTPSystem` with time-varying
        dimensions takes lists of weights and returns lists).
    Q, R, N : array_like, PeriodicMatrix or callable
        Weights: a 2D array (the same at every step), an array of shape
        (N, rows, cols) (one matrix per step), or a periodic matrix sampled
        at ``t = k dt``.  N (cross weight) is zero by default.
    integral_action : ndarray, optional
        Matrix ``C_i`` (nint, n): integrators ``z[k+1] = z[k] + C_i x[k]``
        augment the plant, as in `control.dlqr`.
    method : {None, 'slycot', 'scipy'}, optional
        python-control's choice of LTI solver, accepted so that the same
        call works; the periodic algorithm is always used.
    output : bool, optional
        Q weights the outputs ``y_k = C_kx_k + D_ku_k`` (see `lqr`).

    Returns
    -------
    K : PeriodicMatrix
        Gains ``K_k`` stored as held samples (``K(k dt) = K_k``), shape (m, n).
    X : PeriodicMatrix
        Stabilizing periodic Riccati solution ``X_k``, held likewise.
    E : ndarray of complex
        Closed-loop per-step exponents ``μ^{1/N}`` (see
        `ltpcontrol.floquet_exponents`).

    Examples
    --------
    >>> A = np.array([[[1.1, 0.2], [0.0, 0.9]], [[0.7, 0.0], [0.3, 1.2]]])
    >>> sysd = ltp.ltpss(A, [[0.0], [1.0]], np.eye(2), 0, period=2.0, dt=1.0)
    >>> K, X, E = ltp.dlqr(sysd, np.eye(2), [[1.0]])
    >>> K(0.0).shape, K(1.0).shape, bool(np.all(np.abs(E) < 1))
    ((1, 2), (1, 2), True)
    """
    check_method(method)
    if _time_varying(sys, Q, R, N):
        return tv_dlqr(sys, Q, R, N, integral_action=integral_action)
    sys = as_ltp(sys)
    if not sys.isdtime(strict=True):
        raise ControlArgument("dlqr: sys must be a discrete-time system (use lqr)")
    sys, (Q, R, N) = align_weights(sys, {'Q': Q, 'R': R, 'N': N})   # sub-periods
    steps = sys.nsteps
    if output:
        Q, R, N = _output_weights(sys, Q, R, N, integral_action)
    A, B = _with_integrators(sys, integral_action, 'dlqr')
    A, B = A.sample(steps), B.sample(steps)
    Qs, Rs = _steps(Q, sys, 'Q'), _steps(R, sys, 'R')
    Ns = None if N is None else _steps(N, sys, 'N')
    X, E, K = dare(A, B, Qs, Rs, Ns)
    if _same_steps(A, B, Qs, Rs, Ns):             # LTI data: constant gain and X
        return (PeriodicMatrix.constant(K[0], sys.period),
                PeriodicMatrix.constant(X[0], sys.period), E)
    return _held(K, sys), _held(X, sys), E


def lqe(sys, QN, RN, NN=None, nsteps=None, *, method=None, G=None, Dw=None):
    """Periodic Kalman(-Bucy) filter gain, as `control.lqe`.

    For ``ẋ = A(t)x + B(t)u + G(t)w``, ``y = C(t)x + v`` with white noises
    of intensities ``E[wwᵀ] = QN``, ``E[vvᵀ] = RN``, ``E[wvᵀ] = NN``, the
    estimator ``x̂' = Ax̂ + Bu + L(y - Cx̂)``.  As in python-control, G is
    the B matrix of `sys`.  A discrete-time system is passed on to `dlqe`.

    Parameters
    ----------
    sys : LTPStateSpace
        Plant; its B serves as the noise input matrix G.
    QN, RN : array_like, PeriodicMatrix or callable
        Process and sensor noise intensities (shapes (m, m), (p, p)); RN
        positive definite.
    NN : array_like, PeriodicMatrix or callable, optional
        Cross intensity (m, p).
    nsteps : int, optional
        Steps per period of the Riccati solver.
    method : {None, 'slycot', 'scipy'}, optional
        python-control's choice of LTI solver, accepted so that the same
        call works; the periodic algorithm is always used.
    G : array_like, PeriodicMatrix or callable, optional
        Noise input matrix (n, q) when the process noise w does not enter
        through B (the reference toolbox's separate noise inputs); QN is
        then (q, q) and NN (q, p).
    Dw : array_like, PeriodicMatrix or callable, optional
        Feedthrough (p, q) of w to the measurement, ``y = Cx + Du + Dw w +
        v``: the filter sees the sensor noise ``Dw w + v`` (covariance
        ``RN + Dw QN Dwᵀ + Dw NN + NNᵀDwᵀ``) correlated with the process
        noise (cross term ``G(QN Dwᵀ + NN)``).

    Returns
    -------
    L : PeriodicMatrix
        Estimator gain ``L(t) = (PCᵀ + GN) RN⁻¹``, shape (n, p).
    P : PeriodicMatrix
        Stabilizing periodic error covariance.
    E : ndarray of complex
        Floquet exponents of the error dynamics ``A - LC``.

    Examples
    --------
    >>> sys = ltp.ltpss(lambda t: np.array([[0.0, 1.0], [-1 - 0.5 * np.cos(t), -0.1]]),
    ...                 [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi)
    >>> L, P, E = ltp.lqe(sys, [[1.0]], [[0.1]])
    >>> L.shape, bool(np.all(E.real < 0))
    ((2, 1), True)
    """
    check_method(method)
    if _discrete(sys, nsteps):
        return dlqe(sys, QN, RN, NN)
    T = _common_period(sys, {'G': G, 'QN': QN, 'RN': RN, 'NN': NN, 'Dw': Dw})
    A, C = sys.A.with_period(T), sys.C.with_period(T)
    G = sys.B.with_period(T) if G is None else as_periodic(G, T, 'G')
    if G.shape[0] != sys.nstates:
        raise ControlDimension(f"G must have {sys.nstates} rows, got shape {G.shape}")
    QN = as_periodic(QN, T, 'QN', shape=(G.shape[1],) * 2)
    RN = as_periodic(RN, T, 'RN', shape=(sys.noutputs,) * 2)
    NN = as_periodic(np.zeros((G.shape[1], sys.noutputs)) if NN is None else NN, T, 'NN',
                     shape=(G.shape[1], sys.noutputs))
    if Dw is not None:
        Dw = as_periodic(Dw, T, 'Dw', shape=(sys.noutputs, G.shape[1]))
        RN = RN + Dw @ QN @ Dw.T + Dw @ NN + NN.T @ Dw.T
        NN = QN @ Dw.T + NN
    probe = np.arange(16) * T / 16
    _check_weights(QN(probe), RN(probe), 'QN', 'RN')
    if all(M.is_constant for M in (A, G, C, QN, RN, NN)):   # LTI data
        X, E, Gd, _ = _care_solution(A.T, C.T, G @ QN @ G.T, RN, G @ NN, T, nsteps)
        L = PeriodicMatrix.constant(Gd(0.0).T, T)
        E = lti_representatives(E, A(0.0) - L(0.0) @ C(0.0), period=T)
        return L, X, E
    X, E, Gd, exact = _care_solution(_reverse(A, True), _reverse(C, True),
                                    _reverse(G @ QN @ G.T, False), _reverse(RN, False),
                                    _reverse(G @ NN, False), T, nsteps)
    L = _reversed_gain(exact, T - Gd.function.grid[::-1])
    L.function._build()                          # tabulated now, bounded
    return L, _reverse(X, False), E


def dlqe(sys, QN, RN, NN=None, *, method=None, G=None, Dw=None):
    """Periodic discrete-time Kalman filter gain (predictor form), as `control.dlqe`.

    For ``x_{k+1} = A_kx_k + B_ku_k + G_kw_k``, ``y_k = C_kx_k + v_k``, the
    one-step predictor ``x̂_{k+1} = A_kx̂_k + B_ku_k + L_k(y_k - C_kx̂_k)``
    with ``L_k = (A_kP_kC_kᵀ + G_kN_k)(C_kP_kC_kᵀ + RN_k)⁻¹`` and the a
    priori error covariance ``P_k``.  G is the B matrix of `sys`.

    Parameters
    ----------
    sys : LTPStateSpace or DiscreteLTPSystem
        Discrete-time plant (a `DiscreteLTPSystem` returns lists).
    QN, RN, NN : array_like, PeriodicMatrix or callable
        Noise covariances per step (2D: the same at every step; (N, ., .):
        one per step); NN (cross covariance) is zero by default.
    method : {None, 'slycot', 'scipy'}, optional
        python-control's choice of LTI solver, accepted so that the same
        call works; the periodic algorithm is always used.
    G, Dw : array_like, PeriodicMatrix or callable, optional
        Separate noise input matrix (n, q) and its feedthrough (p, q) to the
        measurement, as in `lqe` (2D, or one matrix per step).

    Returns
    -------
    L : PeriodicMatrix
        Predictor gains ``L_k`` (held samples), shape (n, p).
    P : PeriodicMatrix
        A priori error covariance ``P_k`` (held samples).
    E : ndarray of complex
        Per-step exponents of the error dynamics ``A_k - L_kC_k``.

    Examples
    --------
    >>> A = np.array([[[1.1, 0.2], [0.0, 0.9]], [[0.7, 0.0], [0.3, 1.2]]])
    >>> sysd = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2.0, dt=1.0)
    >>> L, P, E = ltp.dlqe(sysd, [[1.0]], [[0.5]])
    >>> L(0.0).shape, bool(np.all(np.abs(E) < 1))
    ((2, 1), True)
    """
    check_method(method)
    if _time_varying(sys, QN, RN, NN):
        return tv_dlqe(sys, QN, RN, NN)
    sys = as_ltp(sys)
    if not sys.isdtime(strict=True):
        raise ControlArgument("dlqe: sys must be a discrete-time system (use lqe)")
    sys, (QN, RN, NN) = align_weights(sys, {'QN': QN, 'RN': RN, 'NN': NN})   # sub-periods
    steps = sys.nsteps
    A, C = (M.sample(steps) for M in (sys.A, sys.C))
    G = sys.B.sample(steps) if G is None else np.broadcast_to(
        _steps(G, sys, 'G'), (steps,) + _steps(G, sys, 'G').shape[1:])
    if G.shape[1] != sys.nstates:
        raise ControlDimension(f"G must have {sys.nstates} rows, got shape {G.shape[1:]}")
    QN, RN = _steps(QN, sys, 'QN'), _steps(RN, sys, 'RN')
    NN = np.zeros((1, G.shape[2], C.shape[1])) if NN is None else _steps(NN, sys, 'NN')
    _shape_check(QN, (G.shape[2],) * 2, 'QN')
    _shape_check(RN, (C.shape[1],) * 2, 'RN')
    _shape_check(NN, (G.shape[2], C.shape[1]), 'NN')
    if Dw is not None:
        Dw = _steps(Dw, sys, 'Dw')
        _shape_check(Dw, (C.shape[1], G.shape[2]), 'Dw')
        Dwt, NNt = np.swapaxes(Dw, 1, 2), np.swapaxes(NN, 1, 2)
        RN = RN + Dw @ QN @ Dwt + Dw @ NN + NNt @ Dwt
        NN = QN @ Dwt + NN
    _check_weights(QN, RN, 'QN', 'RN')
    Gt = np.swapaxes(G, 1, 2)
    # dual problem on the reversed step order j = N-1-k
    flip = (lambda M: np.ascontiguousarray(M[::-1]))
    X, E, Gd = dare(flip(np.swapaxes(A, 1, 2)), flip(np.swapaxes(C, 1, 2)),
                    flip(G @ QN @ Gt), flip(np.broadcast_to(RN, (steps,) + RN.shape[1:])),
                    flip(G @ NN))
    P = np.roll(X[::-1], 1, axis=0)              # P_k = X̃_{N-k}
    L = np.swapaxes(Gd[::-1], 1, 2)              # L_k = G̃_{N-1-k}ᵀ
    if _same_steps(A, G, C, QN, RN, NN):          # LTI data: constant gain and P
        return (PeriodicMatrix.constant(L[0], sys.period),
                PeriodicMatrix.constant(P[0], sys.period), E)
    return _held(L, sys), _held(P, sys), E


def lqg(sys, Q, R, QN, RN, name=None, *, input_filter=None):
    """Periodic LQG output-feedback controller as an `LTPStateSpace`.

    Combines the LQR gain ``K`` of ``(Q, R)`` (`lqr`/`dlqr`) with the
    Kalman gain ``L`` of ``(QN, RN)`` (`lqe`/`dlqe`, noise through B):

        x̂' = (A - BK - LC + LDK) x̂ + L y,   u = -K x̂

    (discrete time: the same recursion for ``x̂_{k+1}``, the predictor form).
    The controller maps the plant outputs y to the plant inputs u, so the
    closed loop is ``feedback(sys, ctrl, sign=1)``; its Floquet exponents
    are those of ``A - BK`` and ``A - LC`` together (separation principle).

    With an `input_filter` F the design is frequency weighted: the LQG
    above is designed for ``series(F, sys)`` (state ``[x_F; x]``), with Q
    on the plant state ``x``, R on the filter input ``v`` and the process
    noise entering at ``v``, and the controller is that LQG followed by F,
    ``series(lqg, F)``.  Its command ``u = F v`` then holds only F's
    frequencies; a low-pass F at the top of the band where a model was
    identified keeps the controller from acting where the data did not
    check the model.

    Parameters
    ----------
    sys : LTPStateSpace
        Plant.
    Q, R : array_like, PeriodicMatrix or callable
        LQR weights.
    QN, RN : array_like, PeriodicMatrix or callable
        Process (on the inputs of `sys`) and sensor noise intensities.
    name : str, optional
        Name of the controller.
    input_filter : LTPStateSpace, control.StateSpace or TransferFunction, optional
        Filter F with as many inputs and outputs as `sys` has inputs and the
        time base of `sys` (an LTI filter takes its period).

    Returns
    -------
    LTPStateSpace
        Controller with inputs y and outputs u; with `input_filter`, states
        ``[x̂_F; x̂; x_F]`` (the estimated and the implemented filter state).

    Examples
    --------
    >>> sys = ltp.ltpss(lambda t: np.array([[0.0, 1.0], [1 + 0.5 * np.cos(t), -0.1]]),
    ...                 [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi)
    >>> ctrl = ltp.lqg(sys, np.eye(2), [[1.0]], [[1.0]], [[0.1]])
    >>> loop = ltp.feedback(sys, ctrl, sign=1)
    >>> loop.nstates, ltp.is_stable(loop)
    (4, True)

    The same design with the command low-passed at 0.5 rad/s:

    >>> F = ct.tf([0.5], [1.0, 0.5])
    >>> ctrl = ltp.lqg(sys, np.eye(2), [[1.0]], [[1.0]], [[0.1]], input_filter=F)
    >>> ctrl.nstates, ltp.is_stable(ltp.feedback(sys, ctrl, sign=1))
    (4, True)
    """
    sys = as_ltp(sys)
    if input_filter is not None:
        return _filtered_lqg(sys, Q, R, QN, RN, input_filter, name)
    K, _, _ = lqr(sys, Q, R)
    L, _, _ = lqe(sys, QN, RN)
    A = sys.A - sys.B @ K - L @ sys.C + L @ sys.D @ K
    return LTPStateSpace(A, L, -K, np.zeros((sys.ninputs, sys.noutputs)), sys.period,
                         dt=sys.dt, name=name, inputs=sys.output_labels,
                         outputs=sys.input_labels)


def _filtered_lqg(sys, Q, R, QN, RN, F, name):
    """LQG of ``series(F, sys)`` with Q padded to ``diag(0, Q)``, followed by F."""
    if not isinstance(F, (LTPStateSpace, LTI)):
        raise ControlArgument("input_filter must be an LTPStateSpace, StateSpace or "
                              f"TransferFunction, got {type(F).__name__}")
    if F.ninputs != sys.ninputs or F.noutputs != sys.ninputs:
        raise ControlDimension(f"input_filter must have {sys.ninputs} inputs and outputs "
                               f"(the inputs of sys), got {F.ninputs} and {F.noutputs}")
    try:
        common_timebase(F.dt, sys.dt)
    except ValueError:
        raise ValueError(f"input_filter has the time base dt={F.dt}, sys has "
                         f"dt={sys.dt}") from None
    aug = series(F, sys)
    n = sys.nstates
    nf = aug.nstates - n
    if sys.isdtime(strict=True):
        Qs = _steps(Q, sys, 'Q')
        Qp = _held(Qs, sys) if len(Qs) > 1 else PeriodicMatrix.constant(Qs[0], sys.period)
    else:
        Qp = as_periodic(Q, sys.period, 'Q')
    if Qp.shape != (n, n):
        raise ControlDimension(f"Q must have shape {(n, n)} (the states of sys), "
                               f"got {Qp.shape}")
    Qa = PeriodicMatrix.block([[np.zeros((nf, nf)), np.zeros((nf, n))],
                               [np.zeros((n, nf)), Qp]])
    ctrl = series(lqg(aug, Qa, R, QN, RN), F)
    return LTPStateSpace(ctrl.A, ctrl.B, ctrl.C, ctrl.D, sys.period, dt=sys.dt, name=name,
                         inputs=sys.output_labels, outputs=sys.input_labels)


#
# Helpers
#

def _with_integrators(sys, C, where):
    """A and B of the plant augmented with integrators of ``C x`` (python-control's
    ``integral_action``): ``[[A, 0], [C, 0]]`` (discrete ``[[A, 0], [C, I]]``), ``[B; 0]``."""
    if C is None:
        return sys.A, sys.B
    if not isinstance(C, np.ndarray) or C.ndim != 2 or C.shape[1] != sys.nstates:
        raise ControlArgument(f"{where}: integral_action must be an array with "
                              f"{sys.nstates} columns (one per state), got "
                              f"{getattr(C, 'shape', type(C).__name__)}")
    C = real_array(C, 'integral_action', ndim=2)
    k = C.shape[0]
    last = np.eye(k) if sys.isdtime(strict=True) else np.zeros((k, k))
    A = PeriodicMatrix.block([[sys.A, np.zeros((sys.nstates, k))], [C, last]])
    B = PeriodicMatrix.block([[sys.B], [np.zeros((k, sys.ninputs))]])
    return A, B


def _output_weights(sys, Q, R, N, integral_action):
    """State weights ``(CᵀQC, R + DᵀQD, N + CᵀQD)`` of an output weight Q."""
    if integral_action is not None:
        raise ControlArgument("output=True cannot be combined with integral_action")
    (n, m, p) = (sys.nstates, sys.ninputs, sys.noutputs)
    T = sys.period if sys.isdtime(strict=True) else _common_period(sys, {'Q': Q, 'R': R,
                                                                         'N': N})

    def periodic(M, name, shape):
        if sys.isdtime(strict=True) and not (isinstance(M, PeriodicMatrix) or callable(M)):
            steps = _steps(M, sys, name)
            _shape_check(steps, shape, name)
            return (_held(steps, sys) if len(steps) > 1
                    else PeriodicMatrix.constant(steps[0], T))
        return as_periodic(M, T, name, shape=shape)
    Q, R = periodic(Q, 'Q', (p, p)), periodic(R, 'R', (m, m))
    C, D = sys.C, sys.D
    Nq = C.T @ Q @ D
    N = Nq if N is None else periodic(N, 'N', (n, m)) + Nq
    return C.T @ Q @ C, R + D.T @ Q @ D, N


def _time_varying(sys, *weights):
    """True when the dimensions vary over the period (system or weights): the
    problem goes to `tvdesign`."""
    return isinstance(sys, DiscreteLTPSystem) or any(is_varying(W) for W in weights)


def _common_period(sys, weights):
    """The common period of `sys` and its periodic weights (sub-periods)."""
    periodic = {k: W for k, W in weights.items() if isinstance(W, PeriodicMatrix)}
    return common_period([sys.period] + [W.period for W in periodic.values()],
                         ['sys'] + list(periodic))


def _discrete(sys, nsteps):
    """True for a discrete-time plant (which takes no nsteps)."""
    sys = as_ltp(sys)
    if sys.isdtime(strict=True):
        if nsteps is not None:
            raise ControlArgument("nsteps applies to continuous-time systems only")
        return True
    return False


def _steps(M, sys, name):
    """Per-step values of a weight, shape (N or 1, rows, cols)."""
    if isinstance(M, PeriodicMatrix) or callable(M):
        return as_periodic(M, sys.period, name).sample(sys.nsteps)
    arr = real_array(M, name, ndim=(0, 1, 2, 3))
    if arr.ndim == 3 and arr.shape[0] != sys.nsteps:
        raise ControlDimension(f"{name} has {arr.shape[0]} matrices but the period has "
                               f"{sys.nsteps} steps")
    arr = np.atleast_2d(arr)
    return arr if arr.ndim == 3 else arr[np.newaxis]


def _same_steps(*mats):
    """True when every per-step stack holds one matrix (LTI data)."""
    return all(M is None or np.all(M == M[:1]) for M in mats)


def _shape_check(M, shape, name):
    if M.shape[1:] != shape:
        raise ControlDimension(f"{name} must have shape {shape}, got {M.shape[1:]}")


def _held(values, sys):
    return PeriodicMatrix.from_samples(values, sys.period, kind='hold')


def _reversed_gain(exact, grid):
    """``L(t) = Gd(-t)ᵀ`` of the dual problem's exact gain, as a verified gain
    table like `care`'s on the reversed step grid (built by the caller)."""
    rev = PeriodicMatrix.from_function(_Reversed(exact, True), exact.period, exact.shape[::-1],
                                       breakpoints=np.mod(-exact.breakpoints, exact.period),
                                       check=False)
    return PeriodicMatrix.from_function(
        _GainTable(exact=rev, grid=_table_edges(grid, rev.breakpoints)), rev.period,
        rev.shape, breakpoints=rev.breakpoints, check=False)


class _Reversed:
    """``t -> M(-t)`` (transposed if asked), a picklable callable."""

    def __init__(self, M, transpose):
        self.M, self.transpose = M, transpose

    def __call__(self, t):
        out = self.M._eval(np.mod(-np.asarray(t, float), self.M.period))
        return np.swapaxes(out, -1, -2) if self.transpose else out


def _reverse(M, transpose):
    """``M(-t)`` (transposed if asked) as a periodic matrix."""
    T = M.period

    def value(t):
        out = M._eval(np.mod(-np.asarray(t, float), T))
        return np.swapaxes(out, 1, 2) if transpose else out
    shape = M.shape[::-1] if transpose else M.shape
    return PeriodicMatrix.from_function(value, T, shape, breakpoints=np.mod(-M.breakpoints, T),
                                        check=False)
