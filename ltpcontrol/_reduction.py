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
`control.balred`'s balanced truncation.
"""

import warnings

import numpy as np
import control as ct
from control.exception import ControlArgument

from ._ltpsys import LTPStateSpace
from ._lyapunov import dlyap
from ._validation import check_positive_int

__all__ = ['hsvd', 'balred', 'minreal']


def hsvd(sys):
    """Hankel singular values of a stable periodic system at every step.

    Parameters
    ----------
    sys : LTPStateSpace
        Stable discrete-time system, or a continuous-time system with
        constant matrices.

    Returns
    -------
    ndarray, shape (N, n)
        ``σ_j(k)``, decreasing in j, for the N steps of the period (N = 1
        for a continuous-time LTI system, whose values equal
        `control.hankel_singular_values`).

    Examples
    --------
    >>> G = ct.rss(3, 1, 1, strictly_proper=True)
    >>> hsv = ltp.hsvd(ltp.ltpss(G, period=1.0))
    >>> np.allclose(hsv[0], np.sort(ct.hankel_singular_values(G))[::-1])
    True
    """
    return _balance(sys)[0]


def balred(sys, orders, method='truncate', return_bound=False):
    """Periodic balanced truncation, as `control.balred`.

    Parameters
    ----------
    sys : LTPStateSpace
        Stable discrete-time system, or a continuous-time system with
        constant matrices (the reduced order is constant over the period).
    orders : int
        Order r of the reduced system, 1 <= r <= n.
    method : {'truncate'}
        Balanced truncation (the only method).
    return_bound : bool
        Also return the a-priori bound ``2 Σ_{j>r} max_k σ_j(k)``.

    Returns
    -------
    rsys : LTPStateSpace
        Reduced system (same period, time base and signal names).
    bound : float
        With ``return_bound=True``: the bound on ``‖G - Ĝ‖∞``.

    Raises
    ------
    ValueError
        If the system is unstable, `orders` is out of range, or the order-r
        Hankel singular value vanishes at some step (no constant-order
        balanced truncation exists there).
    ControlArgument
        For a continuous-time system with time-varying matrices (sample it
        with `ltpcontrol.sample_system`).

    Examples
    --------
    >>> A = np.array([[[0.5, 0.1, 0.0], [0.0, 0.2, 0.1], [0.0, 0.0, -0.3]],
    ...               [[0.4, 0.0, 0.1], [0.2, 0.1, 0.0], [0.0, 0.1, 0.05]]])
    >>> sysd = ltp.ltpss(A, [[1.0], [0.5], [0.1]], [[1.0, 0.3, 0.01]], 0,
    ...                  period=2.0, dt=1.0)
    >>> rsys, bound = ltp.balred(sysd, 2, return_bound=True)
    >>> rsys.nstates, bool(bound < 0.1)
    (2, True)
    """
    if method != 'truncate':
        raise ValueError(f"method must be 'truncate', got {method!r}")
    if not isinstance(return_bound, (bool, np.bool_)):
        raise ControlArgument(f"return_bound must be True or False, got {return_bound!r}")
    hsv, W, V = _balance(sys)
    r = check_positive_int(orders, 'orders')
    n = hsv.shape[1]
    if r > n:
        raise ValueError(f"orders must be at most the number of states {n}, got {r}")
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


def minreal(sys, tol=None):
    """Remove the uncontrollable and unobservable periodic modes, as `control.minreal`.

    Discrete time: balanced truncation of the states whose Hankel singular
    values stay below ``tol`` (relative to the largest) at every step, which
    removes exactly the modes that are unreachable or unobservable over the
    period; the input-output map is unchanged to within ``2 Σ`` of the
    removed values.  A continuous-time system with constant matrices is
    passed to `control.minreal`.

    Parameters
    ----------
    sys : LTPStateSpace
        Stable discrete-time system, or a continuous-time system with
        constant matrices.
    tol : float, optional
        Relative tolerance on the Hankel singular values (default
        ``sqrt(eps)``, about 1.5e-8).

    Returns
    -------
    LTPStateSpace

    Raises
    ------
    ValueError
        If a discrete-time system is unstable (its gramians do not exist).

    Examples
    --------
    A mode that the input never reaches is removed:

    >>> A = np.array([[[0.5, 0.0], [0.0, 0.3]], [[0.2, 0.0], [0.0, -0.4]]])
    >>> sysd = ltp.ltpss(A, [[1.0], [0.0]], [[1.0, 1.0]], 0, period=2.0, dt=1.0)
    >>> ltp.minreal(sysd).nstates
    1
    """
    if tol is None:
        tol = np.sqrt(np.finfo(float).eps)
    if isinstance(tol, (bool, np.bool_)) or not isinstance(tol, (int, float, np.floating)) \
            or not 0 <= tol < 1:
        raise ValueError(f"tol must be a number in [0, 1), got {tol!r}")
    _check(sys)
    if not sys.isdtime(strict=True):
        red = ct.minreal(sys.to_ss(), tol=tol, verbose=False)
        return LTPStateSpace(red.A, red.B, red.C, red.D, sys.period,
                             inputs=sys.input_labels, outputs=sys.output_labels,
                             name=sys.name + '$minreal')
    hsv, W, V = _balance(sys)
    keep = int(np.count_nonzero(np.max(hsv, axis=0) > tol * max(hsv.max(), 1e-300)))
    if keep == hsv.shape[1]:
        return sys
    return _project(sys, W[:, :keep], V[:, :, :keep])


#
# Shared steps
#

def _check(sys):
    if not isinstance(sys, LTPStateSpace):
        raise ControlArgument(f"sys must be an LTPStateSpace, got {type(sys).__name__}")
    if not sys.isdtime(strict=True) and not sys.is_lti:
        raise ControlArgument("a continuous-time system with time-varying matrices is "
                              "reduced after sampling (ltpcontrol.sample_system)")


def _balance(sys):
    """Hankel singular values (N, n) and balancing projections W (N, n, n), V (N, n, n)."""
    _check(sys)
    if not sys.is_stable():
        raise ValueError("sys must be stable: the gramians of an unstable system do "
                         "not exist")
    if sys.isdtime(strict=True):
        N = sys.nsteps
        A, B, C = (M.sample(N) for M in (sys.A, sys.B, sys.C))
        P = dlyap(A, B @ np.swapaxes(B, 1, 2))
        Q = dlyap(A, np.swapaxes(C, 1, 2) @ C, adjoint=True)
    else:
        G = sys.to_ss()
        P, Q = ct.gram(G, 'c')[None], ct.gram(G, 'o')[None]
    S, R = _sqrt_factor(P), _sqrt_factor(Q)
    U, hsv, Vt = np.linalg.svd(np.swapaxes(R, 1, 2) @ S)
    with np.errstate(divide='ignore'):
        scale = np.where(hsv > 0, 1 / np.sqrt(hsv), 0.0)
    W = scale[:, :, None] * (np.swapaxes(U, 1, 2) @ np.swapaxes(R, 1, 2))
    V = S @ np.swapaxes(Vt, 1, 2) * scale[:, None, :]
    return hsv, W, V


def _sqrt_factor(X):
    """``S`` with ``X = S Sᵀ`` for symmetric positive semidefinite X (stacked)."""
    w, U = np.linalg.eigh(0.5 * (X + np.swapaxes(X, 1, 2)))
    return U * np.sqrt(np.clip(w, 0, None))[:, None, :]


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
