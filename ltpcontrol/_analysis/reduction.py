"""Model reduction of periodic systems: balanced truncation and minimal realization.

Discrete time (N steps per period): the periodic gramians ``P_k`` (forward,
``P_{k+1} = A_kP_kA_kᵀ + B_kB_kᵀ``) and ``Q_k`` (adjoint, ``Q_k =
A_kᵀQ_{k+1}A_k + C_kᵀC_k``) come from `ltpcontrol.dlyap`.  With square-root
factors ``P_k = S_kS_kᵀ``, ``Q_k = R_kR_kᵀ`` and the SVD ``R_kᵀS_k =
U_kΣ_kV_kᵀ``, the Hankel singular values at step k are ``diag Σ_k`` and the
square-root balancing projections of order r are

    W_k = Σ_r^{-1/2} U_rᵀ R_kᵀ  (r x n),   V_k = S_k V_r Σ_r^{-1/2}  (n x r),

``W_kV_k = I_r``.  The reduced system is ``Â_k = W_{k+1}A_kV_k``,
``B̂_k = W_{k+1}B_k``, ``Ĉ_k = C_kV_k``, ``D̂_k = D_k`` (time-varying
projections: the state at step k is ``x̂_k = W_kx_k``), with the a-priori
bound ``‖G - Ĝ‖∞ <= 2 Σ_{j>r} max_k σ_j(k)`` on the ℓ2 gain of the error.

A continuous-time system with constant matrices is reduced with its
constant gramians (the same formulas with ``Â = WAV``), which is
`control.balred`'s balanced truncation.  A continuous-time system with
periodic matrices is reduced by time-varying balanced truncation
(`_periodic_balancing`) when the gap ``σ_r(t) > σ_{r+1}(t)`` holds for all
t, with the bound of Sandberg and Rantzer (IEEE TAC 49(2), 2004)
``‖G - Ĝ‖ <= 2 Σ_{j>r} sup_t σ_j(t)`` on the L2 gain of the error, the
supremum taken along each branch of the discarded values.
"""

import warnings

import numpy as np
import control as ct
from control.exception import ControlArgument

from .._core.ltpsys import LTPStateSpace
from .._core.tvsystem import DiscreteLTPSystem, dltpss
from .minimal import MINREAL_TOL, periodic_minreal, tv_balred, tv_hsvd
from .lyapunov import dlyap
from .lyapchol import lyapchol
from .periodic_balancing import hankel_svd, truncate
from .._core.coerce import as_ltp
from .._core.validation import check_positive_int, real_array

__all__ = ['hsvd', 'balred', 'minreal']


def hsvd(sys, t=None, *, nsteps=None):
    """Hankel singular values of a stable periodic system (Conventions page).

    ``σ_j = sqrt(λ_j(P Q))`` of the periodic gramians (`gram`), at every
    step of a discrete-time system and at the instants `t` of a
    continuous-time one (there by the square-root method, from the
    factors of `lyapchol`).

    Parameters
    ----------
    sys : LTPStateSpace
        Stable continuous- or discrete-time system.
    t : array_like, optional
        Continuous time only: instants of evaluation (default 64 uniform
        instants ``kT/64``; one row for a system with constant matrices).
    nsteps : int, optional
        Continuous time only: uniform steps of the gramians' grid (`lyap`).

    Returns
    -------
    ndarray, shape (N, n) or (len(t), n)
        ``σ_j(k)`` or ``σ_j(t)``, decreasing in j.  A continuous-time system
        with constant matrices gives `control.hankel_singular_values`.

    Examples
    --------
    >>> G = ct.ss([[-1.0, 0.0, 0.0], [1.0, -2.0, 0.0], [0.0, 1.0, -3.0]],
    ...           [[1.0], [0.0], [0.5]], [[0.0, 1.0, 1.0]], 0)
    >>> hsv = ltp.hsvd(ltp.ltpss(G, period=1.0))
    >>> np.allclose(hsv[0], np.sort(ct.hankel_singular_values(G))[::-1])
    True

    A periodic gain on the input makes the values vary over the period:

    >>> sys = ltp.ltpss([[-1.0, 0.0], [1.0, -2.0]],
    ...                 lambda t: np.array([[1.0 + 0.5 * np.cos(t)], [0.0]]),
    ...                 [[0.0, 1.0]], 0, period=2 * np.pi)
    >>> hsv = ltp.hsvd(sys, t=[0.0, np.pi])
    >>> hsv.shape, bool(hsv[0, 0] > hsv[1, 0])
    ((2, 2), True)
    """
    if isinstance(sys, DiscreteLTPSystem):          # time-varying dimensions
        return tv_hsvd(sys)
    _check(sys)
    if sys.isdtime(strict=True) or (sys.is_lti and t is None):
        if t is not None:
            raise ControlArgument("t applies to continuous-time systems only; a "
                                  "discrete-time system has one row per step")
        return _balance(sys)[0]
    _require_stable(sys)
    if t is None:
        t = np.arange(64) * sys.period / 64
    t = real_array(t, 't', ndim=(0, 1)).reshape(-1)
    # square-root method: σ_j(t) are the singular values of R_o(t) R_c(t)ᵀ
    # for the factored gramians P = R_cᵀR_c, Q = R_oᵀR_o (never formed)
    Rc = lyapchol(sys.A, sys.B, nsteps=nsteps)(t)
    Ro = lyapchol(sys.A, sys.C, adjoint=True, nsteps=nsteps)(t)
    return np.linalg.svd(Ro @ np.swapaxes(Rc, 1, 2), compute_uv=False)


def balred(sys, orders, method='truncate', *, return_bound=False, nsteps=None):
    """Periodic balanced truncation, as `control.balred`.

    Discrete time: per-step balancing projections of the periodic gramians.
    Continuous time: time-varying balanced truncation with a smooth periodic
    projection (see the Notes), which needs the order-r gap
    ``σ_r(t) > σ_{r+1}(t)`` at every t.

    Parameters
    ----------
    sys : LTPStateSpace
        Stable continuous- or discrete-time system.
    orders : int
        Order r of the reduced system, 1 <= r <= n.
    method : {'truncate'}
        Balanced truncation (the only method).
    return_bound : bool
        Also return the a-priori bound ``2 Σ_{j>r} sup σ_j`` on the L2
        (ℓ2) gain of the error.
    nsteps : int, optional
        Continuous time only: uniform steps of the period grid (`lyap`);
        the reduced matrices are interpolated on it.

    Returns
    -------
    rsys : LTPStateSpace
        Reduced system (same period, time base and signal names).
    bound : float
        With ``return_bound=True``: the bound on ``‖G - Ĝ‖∞``.

    Raises
    ------
    ValueError
        If the system is unstable, `orders` is out of range, the order-r
        Hankel singular value vanishes at some step, or (continuous time)
        ``σ_r(t)`` and ``σ_{r+1}(t)`` meet: no balanced truncation of constant
        order r exists then.

    Notes
    -----
    Continuous time, with ``P = SSᵀ``, ``Q = RRᵀ``, ``RᵀS = UΣVᵀ`` at every
    t, the state is projected on the span of ``V_b = S V_r Σ_r^{-1/2}``
    along the kernel of ``W_b = Σ_r^{-1/2} U_rᵀ Rᵀ`` (the dominant
    invariant subspace of ``P(t)Q(t)``).  In a smooth periodic basis
    ``V(t)`` of that span, with ``W V = I``, the reduced model is
    ``(W A V − W V̇, W B, C V, D)``; the derivative of the projector is
    computed exactly from the Lyapunov equations.  The bound is that of
    Sandberg and Rantzer (IEEE TAC 49(2), 2004) for balanced truncation of
    time-varying systems, ``2 Σ_{j>r} sup_t σ_j(t)``, with the supremum
    along each branch of the discarded values where two of them cross
    (discrete time: ``2 Σ_{j>r} max_k σ_j(k)``).

    Examples
    --------
    >>> A = np.array([[[0.5, 0.1, 0.0], [0.0, 0.2, 0.1], [0.0, 0.0, -0.3]],
    ...               [[0.4, 0.0, 0.1], [0.2, 0.1, 0.0], [0.0, 0.1, 0.05]]])
    >>> sysd = ltp.ltpss(A, [[1.0], [0.5], [0.1]], [[1.0, 0.3, 0.01]], 0,
    ...                  period=2.0, dt=1.0)
    >>> rsys, bound = ltp.balred(sysd, 2, return_bound=True)
    >>> rsys.nstates, bool(bound < 0.1)
    (2, True)

    A continuous-time plant with a periodic input gain:

    >>> sys = ltp.ltpss([[-1.0, 0.0], [1.0, -4.0]],
    ...                 lambda t: np.array([[1.0 + 0.5 * np.cos(t)], [0.2]]),
    ...                 [[0.0, 1.0]], 0, period=2 * np.pi)
    >>> rsys, bound = ltp.balred(sys, 1, return_bound=True)
    >>> rsys.nstates, round(bound, 3)
    (1, 0.03)
    """
    if method != 'truncate':
        raise ValueError(f"method must be 'truncate', got {method!r}")
    if not isinstance(return_bound, (bool, np.bool_)):
        raise ControlArgument(f"return_bound must be True or False, got {return_bound!r}")
    if isinstance(sys, DiscreteLTPSystem):          # time-varying dimensions
        r = check_positive_int(orders, 'orders')
        if r > min(sys.nstates):
            raise ValueError(f"orders must be at most the smallest number of states "
                             f"{min(sys.nstates)}, got {r}")
        if not sys.is_stable():
            raise ValueError("sys must be stable: the gramians of an unstable system do "
                             "not exist")
        rsys, bound = tv_balred(sys, r)
        return (rsys, bound) if return_bound else rsys
    _check(sys)
    r = check_positive_int(orders, 'orders')
    n = sys.nstates
    if r > n:
        raise ValueError(f"orders must be at most the number of states {n}, got {r}")
    if not sys.isdtime(strict=True) and not sys.is_lti:
        _require_stable(sys)
        rsys, bound = _truncate_periodic(sys, r, nsteps, '$reduced')
        return (rsys, bound) if return_bound else rsys
    hsv, W, V = _balance(sys)
    if np.min(hsv[:, r - 1]) <= 1e-13 * max(1.0, hsv.max()):
        raise ValueError(f"the Hankel singular value {r} vanishes at some step of the "
                         "period: no balanced truncation of constant order "
                         f"{r} exists (use a smaller order)")
    if np.any(hsv[:, r - 1] <= hsv[:, r] * (1 + 1e-8) if r < n else False):
        warnings.warn(f"Hankel singular values {r} and {r + 1} coincide at some step: the "
                      "truncation is not unique", UserWarning, stacklevel=2)
    bound = 2 * float(np.sum(np.max(hsv[:, r:], axis=0))) if r < n else 0.0
    rsys = _project(sys, W[:, :r], V[:, :, :r])
    return (rsys, bound) if return_bound else rsys


def minreal(sys, tol=None, *, verbose=False, nsteps=None):
    """Remove the uncontrollable and unobservable periodic modes, as `control.minreal`.

    Discrete time: orthogonal projection on the periodic reachable, then
    observable, subspaces (a periodic staircase), which removes
    every unreachable and every unobservable part, stable or not, and keeps
    the input-output map exactly; the minimal order may vary with the step,
    and the result is then a `DiscreteLTPSystem`.  Continuous time with
    periodic matrices: balanced truncation of the states whose Hankel
    singular values stay below ``tol`` (relative to the largest) over the
    whole period.  Constant matrices (continuous, or discrete with the same
    matrices at every step) are passed to `control.minreal`.

    Parameters
    ----------
    sys : LTPStateSpace or DiscreteLTPSystem
        Discrete-time system (any stability), stable continuous-time system
        with periodic matrices, or continuous-time system with constant
        matrices.
    tol : float, optional
        Discrete time and constant matrices: relative rank tolerance
        (default ``1000 sqrt(eps)``, about 1.5e-5: the relative distance
        below which python-control's ``TransferFunction.minreal`` cancels a
        pole and a zero, so that the near-cancellation
        ``(s+1)(s+2.00000000001)/((s+2)(s²+s+1))`` gives 2 states as in
        python-control; constant matrices go to `control.minreal` with this
        `tol`).  Continuous periodic matrices: relative tolerance on the
        Hankel singular values (default 1e-6, the gramians are integrated
        to about 1e-12).
    verbose : bool, optional
        Print the number of removed states, as `control.minreal` (whose
        default is True; here False).
    nsteps : int, optional
        Continuous time only: uniform steps of the period grid (`lyap`).

    Returns
    -------
    LTPStateSpace or DiscreteLTPSystem
        A `DiscreteLTPSystem` when the minimal order varies with the step
        (or when `sys` is one).

    Raises
    ------
    ValueError
        If a continuous-time system with periodic matrices is unstable (its
        gramians do not exist).

    Examples
    --------
    A mode that the input never reaches is removed:

    >>> A = np.array([[[0.5, 0.0], [0.0, 0.3]], [[0.2, 0.0], [0.0, -0.4]]])
    >>> sysd = ltp.ltpss(A, [[1.0], [0.0]], [[1.0, 1.0]], 0, period=2.0, dt=1.0)
    >>> ltp.minreal(sysd).nstates
    1
    """
    red = _minreal(sys, tol, nsteps)
    if not isinstance(verbose, (bool, np.bool_)):
        raise ValueError(f"verbose must be True or False, got {verbose!r}")
    if verbose and red.nstates < sys.nstates:
        print(f"{sys.nstates - red.nstates} states have been removed from the model")
    return red


def _minreal(sys, tol, nsteps):
    if isinstance(sys, DiscreteLTPSystem) or (isinstance(sys, LTPStateSpace)
                                              and sys.isdtime(strict=True)):
        return _discrete_minreal(sys, tol, nsteps)
    periodic_ct = not sys.isdtime(strict=True) and not sys.is_lti \
        if isinstance(sys, LTPStateSpace) else False
    lti_ct = isinstance(sys, LTPStateSpace) and not sys.isdtime(strict=True) and sys.is_lti
    if tol is None:
        tol = 1e-6 if periodic_ct else MINREAL_TOL if lti_ct else np.sqrt(np.finfo(float).eps)
    if tol is not None and (isinstance(tol, (bool, np.bool_))
                            or not isinstance(tol, (int, float, np.floating))
                            or not 0 <= tol < 1):
        raise ValueError(f"tol must be a number in [0, 1), got {tol!r}")
    _check(sys)
    if lti_ct:
        # python-control's algorithm, its transfer functions' tolerance
        red = ct.minreal(sys.to_ss(), tol=tol, verbose=False)
        return LTPStateSpace(red.A, red.B, red.C, red.D, sys.period,
                             inputs=sys.input_labels, outputs=sys.output_labels,
                             name=sys.name + '$minreal')
    if periodic_ct:
        hsv = hsvd(sys, nsteps=nsteps)
    else:
        hsv, W, V = _balance(sys)
    keep = int(np.count_nonzero(np.max(hsv, axis=0) > tol * max(hsv.max(), 1e-300)))
    if keep == hsv.shape[1]:
        return sys
    if periodic_ct:
        return _truncate_periodic(sys, keep, nsteps, '$minreal')[0]
    return _project(sys, W[:, :keep], V[:, :, :keep])


def _discrete_minreal(sys, tol, nsteps):
    """Discrete time: python-control's minreal for constant matrices, else the
    periodic reachable/observable projections (`minimal.periodic_minreal`)."""
    if nsteps is not None:
        raise ControlArgument("nsteps applies to continuous-time systems only")
    if tol is not None and (isinstance(tol, (bool, np.bool_))
                            or not isinstance(tol, (int, float, np.floating))
                            or not 0 <= tol < 1):
        raise ValueError(f"tol must be a number in [0, 1), got {tol!r}")
    tv = sys if isinstance(sys, DiscreteLTPSystem) else dltpss(sys)
    same = all(all(np.array_equal(M[0], Mk) for Mk in M) for M in (tv.A, tv.B, tv.C, tv.D))
    if same and tv.has_constant_dimensions:
        # python-control's algorithm, its transfer functions' tolerance
        red = ct.minreal(ct.ss(tv.A[0], tv.B[0], tv.C[0], tv.D[0], tv.dt),
                         tol=MINREAL_TOL if tol is None else tol,
                         verbose=False)
        red = DiscreteLTPSystem([red.A], [red.B], [red.C], [red.D], tv.dt,
                                name=tv.name + '$minreal')
        red = DiscreteLTPSystem(*(list(M) * tv.nsteps for M in (red.A, red.B, red.C, red.D)),
                                dt=tv.dt, name=red.name)
    else:
        red = periodic_minreal(tv, tol)
    return _as_input_kind(sys, red)


def _as_input_kind(sys, red):
    """An LTPStateSpace when `sys` was one and the orders stay constant."""
    if isinstance(sys, DiscreteLTPSystem) or not red.has_constant_dimensions:
        return red
    if red.nstates == tuple(sys.nstates for _ in range(sys.nsteps)) and red.nsteps == sys.nsteps \
            and all(np.array_equal(a, b) for a, b in zip(red.A, sys.A.sample(sys.nsteps))):
        return sys
    return LTPStateSpace(np.array(red.A).reshape(red.nsteps, red.nstates[0], red.nstates[0]),
                         np.array(red.B).reshape(red.nsteps, red.nstates[0], -1),
                         np.array(red.C).reshape(red.nsteps, -1, red.nstates[0]),
                         np.array(red.D), sys.period, dt=sys.dt, inputs=sys.input_labels,
                         outputs=sys.output_labels, name=sys.name + '$minreal')


#
# Shared steps
#

def _check(sys):
    as_ltp(sys)


def _require_stable(sys):
    if not sys.is_stable():
        raise ValueError("sys must be stable: the gramians of an unstable system do "
                         "not exist")


def _truncate_periodic(sys, r, nsteps, suffix):
    """Continuous-time periodic balanced truncation and its a-priori bound."""
    (A, B, C), sup = truncate(sys, r, nsteps)
    bound = 2 * float(np.sum(sup))
    rsys = LTPStateSpace(A, B, C, sys.D, sys.period, inputs=sys.input_labels,
                         outputs=sys.output_labels, name=sys.name + suffix)
    return rsys, bound


def _balance(sys):
    """Hankel singular values (N, n) and balancing projections W (N, n, n), V (N, n, n)."""
    _require_stable(sys)
    if sys.isdtime(strict=True):
        N = sys.nsteps
        A, B, C = (M.sample(N) for M in (sys.A, sys.B, sys.C))
        P = dlyap(A, B @ np.swapaxes(B, 1, 2))
        Q = dlyap(A, np.swapaxes(C, 1, 2) @ C, adjoint=True)
    else:
        G = sys.to_ss()
        P, Q = ct.gram(G, 'c')[None], ct.gram(G, 'o')[None]
    S, R, U, hsv, Vt = hankel_svd(P, Q)
    with np.errstate(divide='ignore'):
        scale = np.where(hsv > 0, 1 / np.sqrt(hsv), 0.0)
    W = scale[:, :, None] * (np.swapaxes(U, 1, 2) @ np.swapaxes(R, 1, 2))
    V = S @ np.swapaxes(Vt, 1, 2) * scale[:, None, :]
    return hsv, W, V


def _project(sys, W, V):
    """Reduced system ``(W_{k+1} A_k V_k, W_{k+1} B_k, C_k V_k, D_k)``."""
    labels = dict(inputs=sys.input_labels, outputs=sys.output_labels,
                  name=sys.name + '$reduced')
    if not sys.isdtime(strict=True):
        A, B, C, D = (M(0.0) for M in (sys.A, sys.B, sys.C, sys.D))
        return LTPStateSpace(W[0] @ A @ V[0], W[0] @ B, C @ V[0], D, sys.period, **labels)
    N = sys.nsteps
    A, B, C, D = (M.sample(N) for M in (sys.A, sys.B, sys.C, sys.D))
    Wn = np.roll(W, -1, axis=0)
    return LTPStateSpace(Wn @ A @ V, Wn @ B, C @ V, D, sys.period, dt=sys.dt, **labels)
