"""Pole placement for periodic systems: prescribed closed-loop Floquet multipliers.

Discrete time, ``x_{k+1} = A_kx_k + B_ku_k`` with ``u_k = -K_kx_k``: the
closed-loop monodromy is ``Π_k (A_k - B_kK_k)``.  Among the many periodic
gains that give prescribed multipliers, `place` returns the gain that acts
at **one step j of the period** (``K_k = 0`` for ``k != j``).  Starting the
period just after step j, the closed-loop monodromy is

    Φ_j⁺ (A_j - B_jK_j) = Ā - B̄ K_j,   Ā = Φ_j⁺A_j,  B̄ = Φ_j⁺B_j,

with ``Φ_j⁺ = A_{j-1} ... A_0 A_{N-1} ... A_{j+1}`` (the open-loop transition
over the rest of the period), an LTI placement problem for the pair (Ā, B̄),
solved by `control.place` (Tits–Yang robust assignment).  The step j is the
one whose pair has the best-conditioned controllability matrix (smallest
singular value relative to the largest), unless given.  This gain is the
simplest periodic gain (one matrix, no intra-period coupling) and equals
`control.place` for N = 1; its price is that the pair (Ā, B̄) must be
controllable for some step: plants that are only reachable through several
steps of the period (e.g. a B_k that vanishes at every single step but the
sum reaches every state) are rejected with an explanation.
"""

import warnings

import numpy as np
import control as ct
from control.exception import ControlArgument

from .._core.discretize import sample_system
from .._core.floquet import _log_multipliers
from .._core.periodic_matrix import PeriodicMatrix
from .._core.coerce import as_ltp
from .._core.validation import real_array

__all__ = ['place']


def place(sys, p, *, step=None, dt=None):
    """Periodic state feedback with prescribed closed-loop poles, as `control.place`.

    Parameters
    ----------
    sys : LTPStateSpace
        Plant.  Discrete time: the gain ``u_k = -K_k x_k`` acts at one step
        of the period (see Notes).  Continuous time with constant matrices:
        `control.place` on ``(A, B)``.  Other continuous-time plants are
        placed through sampling: give `dt`; the plant is discretized with
        `ltpcontrol.sample_system` (zero-order hold) and the gain returned
        is the discrete periodic gain of the sampled-data loop.
    p : array_like
        Desired closed-loop poles, n values closed under complex
        conjugation.  Discrete time: Floquet multipliers (eigenvalues of the
        closed-loop monodromy).  Continuous time: Floquet exponents (for a
        sampled plant, the multipliers ``e^{pT}`` are placed).
    step : int, optional
        Discrete time: the step j at which the gain acts (default: the step
        with the best-conditioned reachability, see Notes).
    dt : float, optional
        Sampling time for a continuous-time plant with time-varying matrices.

    Returns
    -------
    K : PeriodicMatrix
        Gain, shape (m, n); discrete time: held samples ``K(k dt) = K_k``,
        zero except at step j.

    Raises
    ------
    ValueError
        If `p` has the wrong length or is not closed under conjugation, or
        the poles cannot be placed with a one-step gain (the plant is not
        reachable over a period, or no single step gives a controllable
        pair).
    ControlArgument
        If `sys` is not an `LTPStateSpace`, or a time-varying continuous
        plant is given without `dt`.

    Notes
    -----
    With the gain at step j the closed-loop monodromy, started after step
    j, is ``Φ_j⁺ (A_j - B_jK_j)`` where ``Φ_j⁺`` is the open-loop transition
    over the other N - 1 steps; `control.place` assigns its eigenvalues for
    the pair ``(Φ_j⁺A_j, Φ_j⁺B_j)``.  The gain grows when that pair is
    poorly controllable; the achieved multipliers are checked and a warning
    reports a placement error above 1e-8 (relative).

    Examples
    --------
    >>> A = np.array([[[1.2, 0.3], [0.0, 0.5]], [[0.8, 0.0], [0.4, 1.1]]])
    >>> B = np.array([[[0.0], [1.0]], [[1.0], [0.0]]])
    >>> sysd = ltp.ltpss(A, B, np.eye(2), 0, period=2.0, dt=1.0)
    >>> K = ltp.place(sysd, [0.5, -0.2])
    >>> loop = ltp.feedback(sysd, K)
    >>> np.sort(ltp.floquet_multipliers(loop).real).round(8)
    array([-0.2,  0.5])
    """
    sys = as_ltp(sys)
    n = sys.nstates
    p = real_array(p, 'p', ndim=1, allow_complex=True)
    if p.size != n:
        raise ValueError(f"p must hold {n} poles (one per state), got {p.size}")
    if not np.allclose(np.sort_complex(p), np.sort_complex(np.conj(p)), rtol=1e-12, atol=0):
        raise ValueError("p must be closed under complex conjugation (a real gain "
                         "cannot place a complex pole without its conjugate)")
    if not sys.isdtime(strict=True):
        if sys.A.is_constant and sys.B.is_constant:
            K = _place_lti(sys.A(0.0), sys.B(0.0), p)
            return PeriodicMatrix.constant(K, sys.period)
        if dt is None:
            raise ControlArgument("place: a continuous-time plant with time-varying "
                                  "matrices is placed through sampling; give dt")
        sysd = sample_system(sys, dt)
        return place(sysd, np.exp(p * sys.period), step=step)
    if dt is not None:
        raise ControlArgument("place: dt applies to continuous-time plants only")
    N = sys.nsteps
    A, B = sys.A.sample(N), sys.B.sample(N)
    pairs = [_step_pair(A, B, j) for j in range(N)]
    if step is None:
        quality = [_controllability(Ab, Bb) for Ab, Bb in pairs]
        step = int(np.argmax(quality))
        if quality[step] <= 1e-12:
            raise ValueError(_unplaceable(A, B, p))
    elif isinstance(step, (bool, np.bool_)) or not isinstance(step, (int, np.integer)) \
            or not 0 <= step < N:
        raise ValueError(f"step must be an integer in [0, {N}), got {step!r}")
    Abar, Bbar = pairs[step]
    try:
        Kj = _place_lti(Abar, Bbar, p)
    except ValueError as exc:
        raise ValueError(f"the poles cannot be placed with a gain at step {step}: {exc}") \
            from None
    K = np.zeros((N,) + B.shape[2:0:-1])
    K[step] = Kj
    # achieved multipliers (periodic Schur form of the closed-loop factors)
    logmod, arg = _log_multipliers(None, None, factors=A - B @ K)
    got = np.exp(logmod + 1j * arg)
    err = _match_error(got, p)
    if err > 1e-8 * max(1.0, np.abs(p).max()):
        warnings.warn(f"the placed multipliers deviate from p by up to {err:.1e}: the "
                      f"one-step pair at step {step} is poorly controllable",
                      UserWarning, stacklevel=2)
    return PeriodicMatrix.from_samples(K, sys.period, kind='hold')


def _place_lti(A, B, p):
    """`control.place` with python-control's error made to name the argument."""
    try:
        return np.asarray(ct.place(A, B, p), float)
    except ValueError as exc:
        raise ValueError(f"p cannot be placed for this plant: {exc}") from None


def _step_pair(A, B, j):
    """``(Φ_j⁺ A_j, Φ_j⁺ B_j)`` with ``Φ_j⁺`` the transition over the other steps."""
    N, n = A.shape[0], A.shape[1]
    phi = np.eye(n)
    for i in range(1, N):
        phi = A[(j + i) % N] @ phi
    return phi @ A[j], phi @ B[j]


def _controllability(A, B):
    """Smallest over largest singular value of the scaled controllability matrix."""
    scale = max(1.0, np.abs(A).max())
    sv = np.linalg.svd(ct.ctrb(A / scale, B), compute_uv=False)
    return 0.0 if sv[0] == 0 else sv[-1] / sv[0]


def _match_error(got, want):
    """Largest distance after matching each wanted pole to a distinct achieved one."""
    got = list(got)
    err = 0.0
    for w in want:
        i = int(np.argmin([abs(g - w) for g in got]))
        err = max(err, abs(got.pop(i) - w))
    return err


def _unplaceable(A, B, p):
    """Explain why no one-step gain exists."""
    N, n = A.shape[0], A.shape[1]
    # reachability over a whole period: [Φ(N,1)B_0, ..., B_{N-1}] and Φ(N, 0)
    blocks, mono = [], np.eye(n)
    for k in range(N):
        blocks = [A[k] @ b for b in blocks] + [B[k]]
        mono = A[k] @ mono
    R = np.hstack(blocks)
    rank = np.linalg.matrix_rank(ct.ctrb(mono, R))
    if rank < n:
        return (f"p cannot be placed: the plant is not reachable over a period "
                f"(rank {rank} < {n}), so some open-loop multipliers cannot be moved")
    return ("p cannot be placed with a gain at one step of the period: the plant is "
            "reachable only through several steps (no single step gives a controllable "
            "pair); use lmi_statefbk for a stabilizing gain instead")
