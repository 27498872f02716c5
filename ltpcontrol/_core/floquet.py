"""Floquet analysis: monodromy, characteristic multipliers and exponents,
and the Floquet (Lyapunov) transform (thesis Section 4.2.2).

The period map is the product of step transition matrices over a grid
``0 = t_0 < t_1 < ... < t_M = T`` containing every switching instant,

    Φ(T, 0) = Φ_{M-1} ... Φ_1 Φ_0,   Φ_k = Φ(t_{k+1}, t_k)

(discrete time: ``Φ_k = A[k]``, M = N).  Multipliers and exponents come
from the periodic real Schur form of the factors, which never forms the
product, so multipliers far below machine precision relative to the
largest one (stiff systems) keep full relative accuracy.

The Floquet transform ``x = P(t) z`` uses the periodic Floquet vectors
``p_i(t) = e^{-λ_i t} Φ(t, 0) v_i``, obtained as the periodic solutions
of the cyclic two-point problem ``e^{λ_i h_k} p_{k+1} = Φ_k p_k``.  No
growing or decaying exponential is ever multiplied out, which keeps the
transform accurate for stiff systems.
"""

import numbers
import warnings

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from control.exception import ControlArgument

from .ltpsys import ltpss
from .periodic_matrix import PeriodicMatrix
from .periodic_schur import product_eigenvalues
from .periodic_vectors import cyclic_eigenvectors
from .chebyshev import chebyshev_nodes, piecewise_chebyshev
from .steps import floquet_grid, floquet_norm, step_grid
from .graded import STIFF, stiff_log_multipliers
from .fastform import constant_value, fast_form
from .memory import check_allocation
from .transition import expm_batch, step_transitions, uniform_transitions
from .coerce import as_ltp
from .validation import check_positive_int, steps_per_period
from .registry import method_alias, overridden

__all__ = ['monodromy', 'floquet_multipliers', 'floquet_exponents',
           'is_stable', 'floquet_transform']

# largest condition number accepted for the matrix of Floquet vectors
_COND_MAX = 1e10
# degree of the Chebyshev interpolant of P(t) on each grid interval
_CHEB_DEG = 24
# log-spread h‖A‖ of a plain factor whose small multipliers stay above rounding
_LOG_SPREAD = 36.0
# bytes of the P(t) table of `floquet_transform` above which the default grid is refused
_TABLE_BUDGET = 2e9
# entries of the step factors accumulated at once by `monodromy`
_CHUNK_ENTRIES = 2 ** 17


@method_alias
def monodromy(sys, nsteps=None):
    """Monodromy (period) matrix ``Φ(T, 0)`` of an LTP system.

    Continuous time: the ordered product of the exact transition matrices
    of `nsteps` uniform steps, refined at every switching instant of A.
    Discrete time: ``A[N-1] ... A[1] A[0]`` with ``N = period/dt``.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous- or discrete-time LTP system.
    nsteps : int, optional
        Continuous time only: number of uniform steps per period.  By
        default ``ceil(T max_t ||A(t)||_2)`` (A balanced when its states
        are badly scaled) clipped to [16, 4096] and to a memory budget of
        512 MB for the factors, so that every factor is well conditioned.
        Each factor is integrated with the sub-steps its error estimate
        asks for (sixth-order Magnus, relative accuracy 1e-12).  The
        factors are accumulated in chunks of steps, so the memory is
        O(n²) whatever `nsteps` and the stiffness, and the time linear in
        the steps.  A matrix that is
        constant to 1e-10 of its size (e.g. an isotropic rotor in
        multi-blade coordinates read from linearization files) is taken as
        its mean.

    Returns
    -------
    ndarray, shape (n, n)

    Warns
    -----
    UserWarning
        For a stiff system (``T max‖A(t)‖ > 4096``, `nsteps` not given):
        the formed product loses the multipliers far below the largest
        (``e^{-6e4}`` underflows; below about 1e-16 of the largest they
        are rounding noise).  `floquet_multipliers`, `floquet_exponents`
        and `floquet_modes` keep them without forming the product.

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=2.0)
    >>> np.allclose(ltp.monodromy(sys), np.exp(-2.0))
    True
    """
    if (own := overridden('monodromy', sys)) is not None:      # systems with delays
        return own(sys, nsteps)
    sys = as_ltp(sys)
    if sys.dt or sys.nstates == 0:
        _, factors = _factors(sys, nsteps)
        out = np.eye(factors.shape[1])
        for phi in factors:
            out = phi @ out
        return out
    A, n = fast_form(sys.A), sys.nstates
    if nsteps is not None:
        nsteps = check_positive_int(nsteps, 'nsteps')
        check_allocation((nsteps + 1,), f"the step grid of nsteps={nsteps}")
        grid = step_grid(A, nsteps=nsteps)
    else:
        norm = floquet_norm(A)
        stiff = sys.period * norm > STIFF
        with warnings.catch_warnings():
            if stiff:       # announced below, once
                warnings.simplefilter('ignore', UserWarning)
            grid = floquet_grid(A)
        if stiff:
            warnings.warn(f"sys is stiff (T max‖A(t)‖ = {sys.period * norm:.3g}): its formed "
                          "monodromy cannot hold the multipliers far below the largest "
                          "(they underflow or drown in rounding); floquet_exponents, "
                          "floquet_multipliers and floquet_modes keep them without forming "
                          "it", UserWarning, stacklevel=2)
    # accumulate in chunks of steps: memory O(chunk n²) whatever the step count
    mean = constant_value(A)
    h = np.diff(grid)
    chunk = max(512, _CHUNK_ENTRIES // max(n * n, 1))
    check_allocation((min(chunk, len(h)), n, n), f"a chunk of step factors of {n} states",
                     copies=3)
    out = np.eye(n)
    for c0 in range(0, len(h), chunk):
        c1 = min(len(h), c0 + chunk)
        if mean is not None:
            factors = expm_batch(h[c0:c1, None, None] * mean)
        else:
            factors = uniform_transitions(A, grid[c0:c1], h[c0:c1])
        for phi in factors:
            out = phi @ out
    return out


@method_alias
def floquet_multipliers(sys, nsteps=None):
    """Characteristic (Floquet) multipliers: eigenvalues of ``Φ(T, 0)``.

    Computed by the periodic real Schur decomposition of the factors
    ``H_1 H_2 ... H_p`` with ``H_1 = Φ_{M-1}, ..., H_p = Φ_0`` (SLICOT
    MB03VD/MB03WD) without forming the product; see [BittantiColaneri2009]_
    for the theory and [Varga2008]_ for periodic Schur methods.

    Parameters
    ----------
    sys : LTPStateSpace or DiscreteLTPSystem
        Continuous- or discrete-time LTP system.  With time-varying
        dimensions: the ``min n_k`` core multipliers of the cyclic product,
        padded with zeros to ``n_0`` (see `DiscreteLTPSystem`).
    nsteps : int, optional
        Continuous time only; see `monodromy`.

    Returns
    -------
    ndarray of complex, shape (n,)
        Multipliers sorted by decreasing modulus; complex conjugate pairs
        are adjacent with the positive imaginary part first.  Moduli below
        about 1e-308 underflow to 0 (use `floquet_exponents`, which keeps
        them).

    Examples
    --------
    >>> sys = ltp.ltpss([[-1.0, 0.0], [0.0, -3.0]], [[1.0], [1.0]],
    ...                 [[1.0, 1.0]], 0, period=1.0)
    >>> np.allclose(ltp.floquet_multipliers(sys), np.exp([-1.0, -3.0]))
    True
    """
    if (own := overridden('floquet_multipliers', sys)) is not None:   # delays, varying dims
        return own(sys, nsteps)
    logmod, arg = _log_multipliers(sys, nsteps)
    with np.errstate(under='ignore', over='ignore', invalid='ignore'):
        mu = np.exp(logmod) * np.exp(1j * arg)
        real = (arg == 0) | (arg == np.pi)
        mu[real] = np.where(arg[real] == 0, 1.0, -1.0) * np.exp(logmod[real])
    return mu


@method_alias
def floquet_exponents(sys, nsteps=None):
    """Characteristic (Floquet) exponents of an LTP system.

    Continuous time: the exponents λ with ``μ = e^{λT}``, ``λ = (log|μ| +
    j arg μ)/T``, imaginary parts in the strip ``(-ω_p/2, ω_p/2]``
    (exponents are defined modulo ``j k ω_p``).  The real parts are sums
    of logarithms of the periodic Schur diagonals, so they stay accurate
    when the multipliers span hundreds of orders of magnitude.  A system
    with constant A gives the eigenvalues of A (each the representative of
    its exponent, also outside the strip), as `control.poles`.

    Discrete time: the per-step z-plane exponents ``ρ = μ^{1/N}``
    (principal root, ``arg ρ`` in ``(-π/N, π/N]``), i.e. the eigenvalues
    of the constant matrix of the Floquet form ``z[k+1] = A_F z[k]``.
    They are defined up to a factor ``e^{j2πk/N}``; a system with the same
    A at every step gives the eigenvalues of A.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous- or discrete-time LTP system.
    nsteps : int, optional
        Continuous time only; see `monodromy`.

    Returns
    -------
    ndarray of complex, shape (n,)
        In the order of `floquet_multipliers`.

    Notes
    -----
    Stiff systems (continuous time, ``T max‖A(t)‖ > 4096`` after balancing,
    `nsteps` not given): multipliers such as ``e^{-6e4}`` underflow any
    formed product, and a product of step factors keeps them only with a
    number of steps proportional to the stiffness.  Instead each
    fourth-order Magnus step ``e^{Ω_k}`` (``h‖A‖ <= 512``) is taken in the
    real Schur basis of ``Ω_k``, eigenvalues ordered by decreasing real
    part, so that the rows of each factor are graded by the size of their
    own multiplier; the periodic QR iteration of these factors returns
    every ``log|μ|`` as a sum of logarithms, each accurate relative to its
    own size.  The number of steps is doubled until the estimated error of
    the exponents (one step against two half steps, on probe steps) is
    below 1e-8 of the largest ``|Re λ|``; the stiff exponents themselves
    come out to about their own relative precision.  What is compared in
    the benchmarks (P14) is therefore every exponent, stiff ones included,
    against an independent value that forms no product either (periodic
    Schur form, exact lag rates, or the eigenvalues of a constant
    rotating-frame matrix), relative to the largest ``|Re λ|``.

    Examples
    --------
    The stiff example ``A(t) = [[0, 1], [-10 cos t, -24 - 10 sin t]]``,
    T = 2π, has exponents 0 and -24 (multipliers 1 and 1.6e-66):

    >>> A = lambda t: np.array([[0.0, 1.0], [-10 * np.cos(t), -24 - 10 * np.sin(t)]])
    >>> sys = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi)
    >>> np.round(ltp.floquet_exponents(sys).real, 8) + 0.0
    array([  0., -24.])
    """
    if (own := overridden('floquet_exponents', sys)) is not None:   # systems with delays
        return own(sys, nsteps)
    logmod, arg = _log_multipliers(sys, nsteps)
    if sys.dt:
        nper = steps_per_period(sys.period, sys.dt)
        with np.errstate(under='ignore', over='ignore'):
            rho = np.exp(logmod / nper) * np.exp(1j * arg / nper)   # log|μ| may be -inf
        A = sys.A.sample(nper)
        return lti_representatives(rho, A[0], nper=nper) if np.all(A == A[0]) else rho
    lam = logmod / sys.period + 1j * (arg / sys.period)
    mean = constant_value(fast_form(sys.A))
    return lam if mean is None else lti_representatives(lam, mean, period=sys.period)


def lti_representatives(values, A, *, period=None, nper=None):
    """The eigenvalues of a constant matrix A standing for exponents `values`.

    Exponents are defined modulo ``jω_p`` (continuous, `period`) or a factor
    ``e^{j2π/N}`` (discrete, `nper`); when the dynamics are those of one
    constant matrix, its eigenvalues are the natural representatives (those
    of python-control).  Each value is replaced by the eigenvalue equal to
    it modulo that ambiguity, in the order of `values`.

    Examples
    --------
    Exponents known modulo ``2πj/T`` are mapped back onto the eigenvalues of A:

    >>> from ltpcontrol._core.floquet import lti_representatives
    >>> A = np.diag([-1.0, -3.0])
    >>> lti_representatives([-3 + 2j * np.pi, -1 - 4j * np.pi], A, period=1.0).real
    array([-3., -1.])
    """
    ev = list(np.linalg.eigvals(np.asarray(A, float)).astype(complex))
    if period is not None:
        log, wrap = (lambda z: z), 2 * np.pi / period
    else:
        with np.errstate(divide='ignore'):
            log = (lambda z: np.log(np.maximum(np.abs(z), 1e-300)) + 1j * np.angle(z))
        wrap = 2 * np.pi / nper
    out = []
    for x in np.atleast_1d(values):
        d = log(np.array(ev)) - log(x)
        gap = np.abs(d.real) + np.abs(np.angle(np.exp(2j * np.pi * d.imag / wrap))) \
            * wrap / (2 * np.pi)
        out.append(ev.pop(int(np.argmin(gap))))
    return np.array(out, complex)


@method_alias
def is_stable(sys, tol=1e-10, nsteps=None, *, autonomous=False):
    """True when every Floquet multiplier satisfies ``|μ| < 1 - tol``.

    With ``autonomous=True``, `sys` is the linearisation about an orbit of
    an autonomous plant (see `limit_cycle`): the multiplier nearest 1
    belongs to the phase direction and is left out, so the verdict is
    orbital stability.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous- or discrete-time LTP system.
    tol : float, optional
        Stability margin on the multiplier moduli (default 1e-10), so that
        a multiplier on the unit circle perturbed by rounding is not taken
        as stable.
    nsteps : int, optional
        Continuous time only; see `monodromy`.
    autonomous : bool, optional
        Leave out the phase multiplier of an autonomous orbit (default
        False).

    Returns
    -------
    bool

    Examples
    --------
    >>> A = lambda t: np.array([[0.0, 1.0], [-1 - 0.2 * np.cos(2 * t), -0.1]])
    >>> ltp.is_stable(ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=np.pi))
    True
    """
    if (own := overridden('is_stable', sys)) is not None:      # delays, varying dims
        return own(sys, tol, nsteps, autonomous=autonomous)
    if isinstance(tol, (bool, np.bool_)) or not isinstance(tol, numbers.Real) \
            or not 0 <= tol < 1:
        raise ValueError(f"tol must be a number in [0, 1), got {tol!r}")
    logmod, arg = _log_multipliers(sys, nsteps)
    if autonomous:
        logmod = _without_phase_multiplier(logmod, arg)
    return bool(logmod.size == 0 or np.max(logmod) < np.log1p(-tol))


def _without_phase_multiplier(logmod, arg):
    """Log-moduli without the multiplier nearest 1 (phase of an autonomous orbit)."""
    if logmod.size == 0:
        raise ValueError("autonomous=True needs at least one multiplier (the phase one)")
    return np.delete(logmod, np.argmin(np.hypot(logmod, arg)))


def floquet_transform(sys, real=True, nsteps=None):
    """Floquet (Lyapunov) transform to a system with constant A.

    With ``x = P(t) z`` (thesis eqs. 4.30-4.35), ``Φ(t, 0) = P(t) e^{Ft}``,
    ``P(0) = I`` and ``F = log(Φ(T, 0))/T``, the system becomes

        ż = F z + P^{-1}(t) B(t) u,   y = C(t) P(t) z + D(t) u.

    Discrete time: ``x[k] = P[k] z[k]``, ``z[k+1] = A_F z[k] + P[k+1]^{-1}
    B[k] u[k]``, ``y[k] = C[k] P[k] z[k] + D[k] u[k]`` with
    ``A_F^N = Φ(N, 0)``.

    F is real.  A real logarithm (N-th root) of the monodromy with period T
    does not exist when it has negative real eigenvalues; then, with
    ``real=True``, P(t) is built 2T-periodic (thesis Remark 5; in discrete
    time only when N is even) and the returned system has period 2T, which
    is announced by a warning.

    Size and stiffness.  P(t) is stored as Chebyshev values of degree 24
    on every step of the Floquet grid: ``25 M n²`` numbers for M steps.
    The memory needed is checked first: with the default grid a table (and
    its working copies) above 2 GB raises a MemoryError naming the size,
    and any size above the memory available does; give a smaller `nsteps`
    for large models.  The time is linear in M (periodic Schur form and
    back-substitution, O(M n³)).  For
    a stiff system the grid is the capped one of `monodromy` (a warning
    says when its factors cannot hold the stiffest multipliers);
    `floquet_exponents` and `floquet_modes` are the tools for the
    exponents and mode shapes of large stiff models, which a constant-F
    model does not make easier to use: ``B_F = P^{-1}(t) B(t)`` is then
    dominated by the stiff modes.

    P(t) is computed from the periodic Floquet vectors (see the module
    notes), so the transform is accurate for stiff systems; if the
    monodromy is defective or has repeated multipliers it falls back to
    ``F = logm(Φ(T, 0))/T`` and ``P(t) = Φ(t, 0) e^{-Ft}``, which is
    accurate only when the multipliers span a moderate range (a warning is
    issued otherwise).  Every Floquet transformation has ``det P(t) =
    exp(∫_0^t tr A - t tr F)``, which can be tiny inside the period (e^{-20}
    at t = π for the stiff example of `floquet_exponents`); then
    ``P^{-1}(t) B(t)`` is huge, simulating the Floquet form loses accuracy,
    and a warning reports the condition number of P(t).

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous- or discrete-time LTP system.
    real : bool, optional
        If True (default) double the period when needed to keep F real.  If
        False the period is kept and a ValueError is raised when the
        monodromy has negative real eigenvalues.
    nsteps : int, optional
        Continuous time only: uniform steps per period of the grid on which
        ``P(t_k)`` is stored (switching instants are added); see
        `monodromy`.

    Returns
    -------
    sysF : LTPStateSpace
        Floquet form with constant ``A = F``; same time base, inputs,
        outputs and state count; period T or 2T.
    P : PeriodicMatrix
        The transformation ``x = P(t) z`` (discrete time: a 'hold' matrix
        with ``P(k dt) = P[k]``), continuous with ``P(0) = I``.

    Raises
    ------
    ValueError
        If the monodromy is singular (discrete time with a singular A[k]),
        or ``real=False`` and there is a negative real multiplier.

    Examples
    --------
    The damped Mathieu equation (thesis eq. 4.24, ζ = 0.3, β = 0.1,
    ω_p = 2ω_n) lies in the principal resonance region: its multipliers are
    negative, so the real Floquet form has period 2T = 1:

    >>> import warnings
    >>> wn, wp = 2 * np.pi, 4 * np.pi
    >>> A = lambda t: np.array([[0.0, 1.0],
    ...                         [-(1 + 0.2 * np.cos(wp * t)) * wn**2, -0.6 * wn]])
    >>> sys = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=0.5)
    >>> ltp.floquet_multipliers(sys).real
    array([-0.4195..., -0.3618...])
    >>> with warnings.catch_warnings(record=True):
    ...     sysF, P = ltp.floquet_transform(sys)
    >>> sysF.period, sysF.is_floquet_form
    (1.0, True)
    >>> F = sysF.A(0.0)
    >>> np.allclose(np.sort(np.linalg.eigvals(F).real),
    ...             np.sort(ltp.floquet_exponents(sys).real))
    True
    >>> np.allclose(P(0.0), np.eye(2)), np.allclose(P(1.0), np.eye(2))
    (True, True)
    """
    if not isinstance(real, (bool, np.bool_)):
        raise ControlArgument(f"real must be True or False, got {real!r}")
    sys = as_ltp(sys)
    nstates = sys.nstates
    if nstates == 0:
        raise ValueError("sys has no states; there is nothing to transform")
    if not sys.dt:
        # P(t) is a table of Chebyshev values on every step (with the short-step
        # transitions that produce them): check its size before any work
        A = fast_form(sys.A)
        steps = len(floquet_grid(A, nsteps=nsteps)) - 1
        table = 8.0 * 3 * steps * (_CHEB_DEG + 1) * nstates ** 2
        if nsteps is None and table > _TABLE_BUDGET:
            raise MemoryError(
                f"the Floquet transformation P(t) of {nstates} states on {steps} "
                f"steps needs {table / 1e9:.1f} GB (Chebyshev values of degree {_CHEB_DEG} "
                f"on every step; the step count keeps the factors of T max‖A(t)‖ = "
                f"{sys.period * floquet_norm(A):.3g} well conditioned): give "
                "a smaller nsteps (the stiffest modes then lose accuracy), or use "
                "floquet_modes / floquet_exponents, which handle large stiff models")
        spread = sys.period * floquet_norm(A) / steps
        if nsteps is not None and spread > _LOG_SPREAD:
            warnings.warn(f"the {steps} Floquet factors of sys have h max‖A(t)‖ up to "
                          f"{spread:.3g}: each holds its multipliers only down to about "
                          f"e^-{_LOG_SPREAD:.0f} of its largest, so exponents below about "
                          f"{-_LOG_SPREAD * steps / sys.period:.3g} (stiff modes) and their "
                          "columns of F and P(t) are lost to rounding; floquet_exponents and "
                          "floquet_modes keep them", UserWarning, stacklevel=2)
        check_allocation((steps, _CHEB_DEG + 1, nstates, nstates),
                         f"the Floquet transformation P(t) of {nstates} states on "
                         f"{steps} steps (Chebyshev values of degree {_CHEB_DEG}; "
                         "fewer steps with nsteps=)", copies=3)
    grid, factors = _factors(sys, nsteps)
    if sys.dt:
        # x[k] = P[k] z[k] needs an invertible period map: every A[k] regular
        sv = np.linalg.svd(factors, compute_uv=False)
        bad = np.flatnonzero(sv[:, -1] <= nstates * np.finfo(float).eps * sv[:, 0])
        if bad.size:
            raise ValueError(f"the monodromy of sys is singular (A[{bad[0]}] is singular): "
                             "no Floquet transform exists")
    logmod, arg = _log_multipliers(sys, nsteps, grid=grid, factors=factors)
    negative = arg == np.pi
    dtime = bool(sys.dt)
    nper = len(factors)
    # a real root/logarithm with the original period exists unless there are
    # negative real multipliers (discrete time with N odd: -|μ|^{1/N} is real)
    double = bool(np.any(negative)) and not (dtime and nper % 2 == 1)
    if double and not real:
        raise ValueError("the monodromy of sys has negative real eigenvalues: no real "
                         "Floquet form with the same period exists; use real=True")
    if double:
        warnings.warn("the monodromy has negative real eigenvalues: the Floquet "
                      "transform uses the period 2T to keep F real", UserWarning,
                      stacklevel=2)
        grid = np.concatenate([grid, grid[1:] + grid[-1]])
        factors = np.concatenate([factors, factors])
    # exponents per unit time (continuous) or per step (discrete), real for
    # negative multipliers (whose sign is then absorbed by the period 2T or,
    # for odd N, by the real root -|μ|^{1/N})
    scale = nper if dtime else sys.period
    rate = (logmod + 1j * np.where(negative, 0.0, arg)) / scale
    flip = negative & dtime & (nper % 2 == 1)
    modal = _floquet_vectors(grid, factors, rate, flip, dtime) if dtime else \
        _periodic_vectors(grid, factors)
    if modal is None:
        grid_vals, E, R = _logm_form(grid, factors, logmod, dtime)
    else:
        grid_vals, E, R = modal
    return _assemble(sys, grid, grid_vals, E, R)


#
# Private helpers
#

def _factors(sys, nsteps):
    """Grid ``t_0..t_M`` and step transition matrices ``Φ_k`` (M, n, n)."""
    sys = as_ltp(sys)
    A, T = sys.A, sys.period
    n = A.shape[0]
    if nsteps is not None:
        nsteps = check_positive_int(nsteps, 'nsteps')
    if sys.dt:
        if nsteps is not None:
            raise ControlArgument("nsteps applies to continuous-time systems only; a "
                                  "discrete-time system has N = period/dt steps")
        nper = steps_per_period(T, sys.dt)
        return np.arange(nper + 1) * sys.dt, A.sample(nper)
    if n == 0:
        return np.array([0.0, T]), np.zeros((1, 0, 0))
    A = fast_form(A)
    grid = floquet_grid(A, nsteps=nsteps)
    check_allocation((len(grid) - 1, n, n), f"the {len(grid) - 1} Floquet factors of "
                     f"{n} states", copies=2)
    mean = constant_value(A)
    if mean is not None:
        # constant to the precision of its data: every factor is e^{Ā h}
        return grid, expm_batch(np.diff(grid)[:, None, None] * mean)
    return grid, uniform_transitions(A, grid[:-1], np.diff(grid))


def _log_multipliers(sys, nsteps, grid=None, factors=None):
    """``log|μ_i|`` and ``arg μ_i`` from the periodic Schur form, sorted."""
    if factors is None:
        sys = as_ltp(sys)
        if nsteps is not None:
            nsteps = check_positive_int(nsteps, 'nsteps')     # also where A is constant
        mean = None if sys.dt or sys.nstates == 0 else constant_value(fast_form(sys.A))
        if mean is not None:
            # constant to the precision of its data: μ = e^{λT}, λ the eigenvalues of Ā
            lam = np.linalg.eigvals(mean) * sys.period
            arg = np.angle(np.exp(1j * lam.imag))
            arg[arg == -np.pi] = np.pi
            order = np.lexsort((-arg, -lam.real))
            return lam.real[order], arg[order]
        if not sys.dt and nsteps is None and sys.nstates >= 2:
            A = fast_form(sys.A)
            norm = floquet_norm(A)
            if sys.period * norm > STIFF:
                # stiff: graded factors keep every exponent without stiff step counts
                return stiff_log_multipliers(A, norm)
        grid, factors = _factors(sys, nsteps)
    if factors.shape[1] == 0:
        return np.zeros(0), np.zeros(0)
    return product_eigenvalues(factors)


def _floquet_vectors(grid, factors, rate, flip, dtime):
    """Periodic Floquet vectors on the grid, real form.

    For each exponent solve the cyclic problem ``c_k p_{k+1} = Φ_k p_k``,
    ``p_M = p_0`` with ``c_k = e^{λ h_k}`` (continuous) or ``c_k = ρ``
    (discrete), normalised by a border row.  Returns ``(G, Λ_r, Pm_0^{-1})``
    with ``P(t_k) = G_k Pm_0^{-1}`` and ``F = Pm_0 Λ_r Pm_0^{-1}`` (Λ_r: the
    exponents in real block form), or None when the vectors are not a
    well-conditioned basis (defective or repeated multipliers).
    """
    nsteps, n = factors.shape[0], factors.shape[1]
    size = nsteps * n
    h = np.diff(grid)
    rng = np.random.default_rng(12345)
    border_col, border_row = rng.standard_normal(size), rng.standard_normal(n)
    # sparse pattern: -Φ_k in block (k, k), c_k I in block (k, k+1 mod M),
    # the border column (index M n) and the border row acting on p_0
    blk = np.arange(nsteps)[:, None, None] * n
    diag_rows = np.broadcast_to(blk + np.arange(n)[None, :, None], factors.shape).ravel()
    diag_cols = np.broadcast_to(blk + np.arange(n)[None, None, :], factors.shape).ravel()
    shift_cols = (((np.arange(nsteps) + 1) % nsteps)[:, None] * n + np.arange(n)).ravel()
    rows = np.concatenate([diag_rows, np.arange(size), np.arange(size), np.full(n, size)])
    cols = np.concatenate([diag_cols, shift_cols, np.full(size, size), np.arange(n)])
    vectors, blocks = [], []
    i = 0
    while i < n:
        pair = rate[i].imag > 0
        lam = rate[i] if pair else rate[i].real
        sign = -1.0 if flip[i] else 1.0
        coef = np.full(nsteps, sign * np.exp(lam)) if dtime else np.exp(lam * h)
        dtype = complex if pair else float
        values = np.concatenate([-factors.ravel(), np.repeat(coef, n), border_col, border_row])
        L = sp.csc_matrix((values.astype(dtype), (rows, cols)), shape=(size + 1, size + 1))
        rhs = np.zeros(size + 1, dtype)
        rhs[-1] = 1.0
        try:
            with warnings.catch_warnings():
                warnings.simplefilter('error', spla.MatrixRankWarning)
                sol = spla.splu(L).solve(rhs)
        except (RuntimeError, spla.MatrixRankWarning):
            return None
        p = sol[:-1].reshape(nsteps, n)
        p = p / np.linalg.norm(p[0])
        if pair:
            # rotate the phase so that Re p ⟂ Im p (best-conditioned real pair)
            p = p * np.exp(-0.5j * np.angle(np.sum(p * p)))
            vectors += [p.real, p.imag]
            # x = e^{λt} p: [Re x, Im x] = [Re p, Im p] exp(t [[a, b], [-b, a]])
            a, b = (np.exp(lam).real, np.exp(lam).imag) if dtime else (lam.real, lam.imag)
            blocks.append(np.array([[a, b], [-b, a]]))
            i += 2
        else:
            vectors.append(p.real)
            blocks.append(np.array([[sign * np.exp(lam.real) if dtime else lam.real]]))
            i += 1
    G = np.stack(vectors, axis=-1)
    if not np.all(np.isfinite(G)) or np.linalg.cond(G[0]) > _COND_MAX:
        return None
    return G, la.block_diag(*blocks), np.linalg.inv(G[0])


def _periodic_vectors(grid, factors):
    """Periodic Floquet vectors on the grid (continuous time), real form.

    As `_floquet_vectors`, from the periodic Schur form of the factors and
    its block back-substitution (`cyclic_eigenvectors`): time O(M n³) and
    memory O(M n²) for M steps.  The exponents are those of the cycle
    (period ``grid[-1]``, doubled by the caller for negative multipliers).
    """
    M, n = factors.shape[0], factors.shape[1]
    period = grid[-1]
    logmod, arg, X, logscales = cyclic_eigenvectors(factors, range(M))
    lam = (logmod + 1j * arg) / period
    t = grid[:-1]
    with np.errstate(under='ignore', over='ignore', invalid='ignore'):
        X *= np.exp(logscales - np.outer(lam.real, t) - 1j * np.outer(lam.imag, t))[:, :, None]
        X /= np.linalg.norm(X[:, 0], axis=1)[:, None, None]
    vectors, blocks = [], []
    for i in np.lexsort((-arg, -logmod)):
        if arg[i] < 0:
            continue                      # the conjugate of a pair
        p = X[i]
        if arg[i] > 0:
            # rotate the phase so that Re p ⟂ Im p (best-conditioned real pair)
            p = p * np.exp(-0.5j * np.angle(np.sum(p * p)))
            vectors += [p.real, p.imag]
            a, b = lam[i].real, lam[i].imag
            blocks.append(np.array([[a, b], [-b, a]]))
        else:
            # a real multiplier: a real vector up to a phase
            vectors.append((p * np.exp(-1j * np.angle(p[0][np.argmax(np.abs(p[0]))]))).real)
            blocks.append(np.array([[lam[i].real]]))
    if sum(len(b) for b in blocks) != n:
        return None
    G = np.stack(vectors, axis=-1)
    if not np.all(np.isfinite(G)) or np.linalg.cond(G[0]) > _COND_MAX:
        return None
    return G, la.block_diag(*blocks), np.linalg.inv(G[0])


def _logm_form(grid, factors, logmod, dtime):
    """Fallback ``F = logm(Φ)/T``, ``P(t_k) = Φ(t_k, 0) e^{-F t_k}``."""
    if np.ptp(logmod) > 25:
        warnings.warn("the monodromy is defective or has repeated multipliers and its "
                      f"multipliers span {np.ptp(logmod) / np.log(10):.0f} decades: the "
                      "Floquet transform may be inaccurate", UserWarning, stacklevel=3)
    cumulative = [np.eye(factors.shape[1])]
    for phi in factors:
        cumulative.append(phi @ cumulative[-1])
    cumulative = np.array(cumulative)
    L = la.logm(cumulative[-1])
    if np.max(np.abs(np.imag(L)), initial=0.0) > 1e-8 * max(1.0, np.abs(L).max()):
        raise ValueError("the monodromy of sys has no real logarithm")
    L = np.real(L)
    span = len(factors) if dtime else grid[-1]
    E = la.expm(L / len(factors)) if dtime else L / span
    # discrete time: P[k] = Φ(k, 0) A_F^{-k};  continuous: P = Φ(t_k, 0) e^{-F t_k}
    times = np.arange(len(factors)) if dtime else grid[:-1]
    G = cumulative[:-1] @ la.expm(-L[None] * (times / span)[:, None, None])
    return G, E, np.eye(factors.shape[1])


def _assemble(sys, grid, G, E, R):
    """Build P(t) and the Floquet-form system from the grid values."""
    period = grid[-1]
    n = G.shape[1]
    labels = dict(inputs=sys.input_labels, outputs=sys.output_labels,
                  states=sys.state_labels, name=f'{sys.name}$floquet')
    if sys.dt:
        # discrete time: P[k] = G_k R, B_F[k] = P[k+1]^{-1} B[k], C_F[k] = C[k] P[k]
        nw = len(G)
        nper = steps_per_period(sys.period, sys.dt)
        Pk = G @ R
        Bk, Ck, Dk = (np.tile(M.sample(nper), (nw // nper, 1, 1)) for M in (sys.B, sys.C, sys.D))
        BF = np.linalg.solve(np.roll(Pk, -1, axis=0), Bk)
        sysF = ltpss(np.linalg.solve(R, E @ R), BF, Ck @ Pk, Dk, period, dt=sys.dt,
                     **labels)
        return sysF, PeriodicMatrix.from_samples(Pk, period, kind='hold')
    transform = _chebyshev_transform(sys.A, grid, G, E, R)
    breaks = np.concatenate([M.with_period(period).breakpoints
                             for M in (sys.A, sys.B, sys.C)])
    P = PeriodicMatrix.from_function(transform, period, (n, n), breakpoints=breaks,
                                     check=False)
    B, C = sys.B, sys.C
    BF = PeriodicMatrix.from_function(lambda t: np.linalg.solve(transform(t), B(t)), period,
                                      B.shape, breakpoints=breaks, check=False)
    CF = PeriodicMatrix.from_function(lambda t: C(t) @ transform(t), period, C.shape,
                                      breakpoints=breaks, check=False)
    # F = R^{-1} E R (E = Λ_r for Floquet vectors, R = Pm_0^{-1})
    sysF = ltpss(np.linalg.solve(R, E @ R), BF, CF, sys.D, period, **labels)
    return sysF, P


def _chebyshev_transform(A, grid, G, E, R):
    """Callable P(t) interpolating exact values on every grid interval.

    On ``[t_k, t_{k+1}]`` the values ``P(s) = Φ(s, t_k) G_k e^{-E (s - t_k)} R``
    at Chebyshev points ``s_j = t_k + h_k (1 - cos(jπ/D))/2`` are computed
    exactly and P is evaluated by barycentric interpolation.
    """
    n = G.shape[1]
    starts, h = grid[:-1], np.diff(grid)
    cheb = chebyshev_nodes(_CHEB_DEG)
    zero = PeriodicMatrix.constant(np.zeros((n, 0)), A.period)
    nodes = starts[:, None] + h[:, None] * cheb                        # (M, D+1)
    # Φ(s_j, t_k) = Φ(s_j, s_{j-1}) ... Φ(s_1, s_0): short steps, chained
    steps, _, _ = step_transitions(A, zero, nodes[:, :-1].ravel(), np.diff(nodes, axis=1).ravel())
    steps = steps.reshape(len(starts), _CHEB_DEG, n, n)
    phi = np.empty((len(starts), _CHEB_DEG + 1, n, n))
    phi[:, 0] = np.eye(n)
    for j in range(_CHEB_DEG):
        phi[:, j + 1] = steps[:, j] @ phi[:, j]
    offsets = (nodes - starts[:, None]).ravel()
    values = (phi @ G[:, None]).reshape(-1, n, n) @ expm_batch(-E[None] * offsets[:, None, None])
    values = (values @ R).reshape(len(starts), _CHEB_DEG + 1, n, n)
    # det P(t) = exp(∫_0^t tr A - t tr F) may get tiny: P^{-1} B is then huge
    cond = np.linalg.cond(values.reshape(-1, n, n)).max()
    if cond > 1e8:
        warnings.warn(f"the Floquet transformation P(t) is ill-conditioned (condition "
                      f"number up to {cond:.1e}): B_F = P^{{-1}} B is large and the "
                      "Floquet form amplifies rounding errors", UserWarning, stacklevel=4)

    transform = piecewise_chebyshev(grid, values)

    # check the interpolant against exact values inside every interval
    probe = starts + 0.3717 * h
    exact, _, _ = step_transitions(A, zero, starts, probe - starts)
    exact = exact @ G @ expm_batch(-E[None] * (probe - starts)[:, None, None]) @ R
    err = np.abs(transform(probe) - exact).max()
    if err > 1e-9 * max(1.0, np.abs(exact).max()):
        warnings.warn(f"the interpolated Floquet transformation P(t) has errors up to "
                      f"{err:.1e}; increase nsteps", UserWarning, stacklevel=4)
    return transform
