"""Floquet multipliers of stiff periodic systems from graded exponential factors.

A stiff system (eigenvalues far below ``-1/T``: sensor and actuator lags,
high structural modes of a rotor) has multipliers such as ``e^{-6e4}``
that no formed product holds, and a product of step factors ``e^{Ω_k}``
keeps them only when each factor holds its own small part to working
precision, i.e. when its log-spread ``h ‖A‖`` stays below about 36
(thousands of factors for ``T ‖A‖ = 10⁵``).

Here each step of a grid of M steps (``h ‖A‖ <= 512``, ``e^{-512}`` is
above the underflow limit) is integrated by the fourth-order Magnus exponential
``e^{Ω_k}`` and written in its real Schur basis,

    e^{Ω_k} = U_k E_k U_kᵀ,   E_k = e^{S_k},   Ω_k = U_k S_k U_kᵀ,

with the eigenvalues of ``S_k`` ordered by decreasing real part (to within
a band of width 16), so that the rows of the upper quasi-triangular
``E_k`` are graded: row i is of the size ``e^{Re s_ii}`` of its diagonal.
The monodromy is similar to the cyclic product of the factors

    H_k = E_k (U_kᵀ U_{k-1}),   k = 0..M-1  (U_{-1} = U_{M-1}),

whose rows keep their grading under the orthogonal factors
``U_kᵀ U_{k-1}``.  The periodic QR sweeps (`product_eigenvalues`) act on
rows one at a time and return every log-modulus as a sum of logarithms
of diagonal entries, each accurate relative to its own size: the stiff
exponents keep their relative accuracy although their multipliers
underflow any product (``e^{-6e4}``).  M does not grow with the accuracy
asked of the stiff part; it is doubled only until the Magnus steps meet
the relative accuracy of the dominant part (probe steps against two half
steps).  Memory O(M n²) for the factors and their QR copies, time linear
in M (one Schur form and one exponential per step).
"""

import numpy as np
import scipy.linalg as la
from scipy.linalg import lapack

from .memory import check_allocation
from .periodic_schur import _product_qr
from .threads import small_blas
from .transition import _balancing, expm_batch

__all__ = []

#: largest log-spread h‖A‖ of one factor (e^{-512} ≈ 1e-222: above underflow)
SPREAD = 512.0
#: T‖A‖ above which exponents are computed from graded factors (the plain
#: factors would need more than this many steps for their small multipliers)
STIFF = 4096.0
#: eigenvalues of one factor whose real parts differ by more than this are ordered
_BAND = 16.0
#: estimated error of the exponents, relative to the largest |Re λ|
_RTOL = 1e-8
_PROBES = 8
_MAX_STEPS = 2 ** 15
#: entries of the working arrays of one chunk of steps
_CHUNK_ENTRIES = 2 ** 21
_C1, _C2 = 0.5 - np.sqrt(3) / 6, 0.5 + np.sqrt(3) / 6


def stiff_log_multipliers(A, norm):
    """``log|μ_i|`` and ``arg μ_i`` of a stiff periodic A by graded factors.

    Parameters
    ----------
    A : PeriodicMatrix, shape (n, n)
        Continuous-time state matrix (any form; switching instants are
        grid points).
    norm : float
        An estimate of ``max_t ‖A(t)‖`` (balanced), which sets the least
        number of steps ``T norm / 512``.

    Returns
    -------
    logmod, arg : ndarray, shape (n,)
        As `product_eigenvalues`, sorted by decreasing log-modulus.

    Examples
    --------
    A lag at ``-10⁴`` driven by an oscillator whose stiffness varies: the
    lag's exponent is its rate (it does not feed back), although its
    multiplier ``e^{-10⁴}`` underflows:

    >>> from ltpcontrol._core.graded import stiff_log_multipliers
    >>> A = ltp.PeriodicMatrix.from_function(lambda t: np.array(
    ...     [[0.0, 1.0, 0.0], [-1.0 - 0.3 * np.cos(t), -0.1, 0.0], [0.0, 5.0, -1e4]]),
    ...     2 * np.pi)
    >>> logmod, arg = stiff_log_multipliers(A, 1e4)
    >>> float(logmod[-1] / (2 * np.pi))
    -10000.0
    """
    n = A.shape[0]
    M, scale = graded_steps(A, norm)
    ratio = None if scale is None else scale[None, :] / scale[:, None]
    grid = _grid(A, M)
    check_allocation((len(grid) - 1, n, n), f"the {len(grid) - 1} graded Floquet factors "
                     f"of {n} states", copies=2)
    H = graded_cycle(A, grid, ratio)
    with small_blas(n):
        logmod, arg, _ = _product_qr(H, min_sweeps=2)
    return logmod, arg


def graded_steps(A, norm):
    """Number of graded steps meeting the accuracy of the exponents, and the balancing.

    ``M >= max(64, T norm / 512)``, doubled until the probe steps'
    estimated error is below 1e-8 of the largest ``|Re λ|``.  Returns
    ``(M, scale)``: the balanced matrix is ``A_ij s_j / s_i`` (scale None:
    no balancing).

    Examples
    --------
    >>> from ltpcontrol._core.graded import graded_steps
    >>> A = ltp.PeriodicMatrix.from_function(lambda t: np.array(
    ...     [[-1.0 + 0.1 * np.cos(t), 0.0], [1.0, -1e4]]), 2 * np.pi)
    >>> M, scale = graded_steps(A, 1e4)
    >>> M >= 2 * np.pi * 1e4 / 512
    True
    """
    T, n = A.period, A.shape[0]
    scale = _balancing(A, n, n)
    ratio = None if scale is None else scale[None, :] / scale[:, None]
    M = int(max(64, np.ceil(T * norm / SPREAD)))
    while M < _MAX_STEPS and _probe_error(A, _grid(A, M), ratio) > _RTOL:
        M *= 2
    return M, scale


def _grid(A, M):
    """M uniform steps refined at the switching instants of A."""
    from .steps import step_grid
    return step_grid(A, nsteps=M)


def _omegas(A, a, b, ratio):
    """Fourth-order Magnus exponents Ω of the steps ``[a, b]`` (balanced)."""
    h = (b - a)[:, None, None]
    A1 = A._eval(a + _C1 * (b - a))
    A2 = A._eval(a + _C2 * (b - a))
    if ratio is not None:
        A1, A2 = A1 * ratio, A2 * ratio
    return 0.5 * h * (A1 + A2) + (np.sqrt(3) / 12) * h ** 2 * (A2 @ A1 - A1 @ A2)


def _probe_error(A, grid, ratio):
    """Estimated error of the exponents of the grid, relative to the largest ``|Re λ|``.

    On probe steps the real parts of the eigenvalues of one Magnus step
    (``Re eig Ω``) are compared with the log-moduli of the two half steps'
    product (graded, so that stiff ones are compared too); an order-4 step
    has about 16/15 of the difference as error, and the errors of the M
    steps (their mean over the probes) add up in the exponents over the
    period.
    """
    M, T = len(grid) - 1, grid[-1]
    h = np.diff(grid)
    k = np.unique(np.concatenate([np.linspace(0, M - 1, _PROBES).round().astype(int),
                                  [int(np.argmax(h))]]))
    a, b = grid[k], grid[k + 1]
    mid = 0.5 * (a + b)
    full = _omegas(A, a, b, ratio)
    halves = np.stack([_omegas(A, a, mid, ratio), _omegas(A, mid, b, ratio)], axis=1)
    diffs, largest = [], 1.0 / T
    for j in range(len(k)):
        one = np.sort(np.linalg.eigvals(full[j]).real)
        with small_blas(A.shape[0]):
            two, _, _ = _product_qr(graded_cycle_of(halves[j]), warn=False)
        diffs.append(float(np.abs(one - np.sort(two)).max()))
        largest = max(largest, float(np.abs(one).max() / h[k[j]]))
    return float(np.mean(diffs)) * 16 / 15 * M / T / largest


def ordered_schur(X, band=_BAND):
    """Real Schur form ``X = U S Uᵀ`` with real parts decreasing to within `band`.

    Eigenvalues are grouped in bands of width `band` of their real parts;
    the bands are ordered (LAPACK ``trsen``), the order within a band is
    that of the Schur reduction.

    Examples
    --------
    >>> from ltpcontrol._core.graded import ordered_schur
    >>> X = np.array([[-100.0, 1.0, 0.0], [0.0, -1.0, 2.0], [0.0, 0.0, -50.0]])
    >>> S, U = ordered_schur(X)
    >>> np.round(np.diag(S), 10) + 0.0
    array([  -1.,  -50., -100.])
    >>> bool(np.allclose(U @ S @ U.T, X))
    True
    """
    S, U = la.schur(X, output='real', check_finite=False)
    levels = np.floor(np.diag(S) / band)
    if np.all(np.diff(levels) <= 0):         # already in order
        return S, U
    # select the bands above each level from the lowest up: the selected
    # blocks move ahead keeping their order, so the bands end up sorted
    for level in np.unique(levels)[1:]:
        select = (np.floor(np.diag(S) / band) >= level).astype(np.int32)
        if np.all(np.diff(select) <= 0):        # the selected ones lead already
            continue
        S, U, *_, info = lapack.dtrsen(select, S, U, job='N')
        if info != 0:          # reordering failed (ill-conditioned swap): keep the order
            break
    return S, U


def graded_cycle(A, grid, ratio=None, keep=None):
    """The cyclic graded factors of the Magnus steps of `grid` (module notes), (M, n, n).

    With `keep` (step indices), also the Schur bases ``U_{k-1}`` of those
    grid points (``U_{-1} = U_{M-1}``), as a dict: the state at ``t_k`` is
    ``U_{k-1} z_k`` in the coordinates in which ``z_{k+1} = H_k z_k``
    (balanced coordinates when `ratio` is given).

    Examples
    --------
    The cyclic product has the eigenvalues of the monodromy:

    >>> from ltpcontrol._core.graded import graded_cycle
    >>> A = ltp.PeriodicMatrix.constant([[-1.0, 1.0], [0.0, -2.0]], 1.0)
    >>> H = graded_cycle(A, np.linspace(0, 1, 5))
    >>> np.sort(np.linalg.eigvals(np.linalg.multi_dot(H[::-1])).real)
    array([0.13533528, 0.36787944])
    """
    M = len(grid) - 1
    chunk = max(1, _CHUNK_ENTRIES // (4 * A.shape[0] ** 2))

    def omegas():
        for c0 in range(0, M, chunk):
            c1 = min(M, c0 + chunk)
            yield _omegas(A, grid[c0:c1], grid[c0 + 1:c1 + 1], ratio)
    return _cycle(omegas(), M, A.shape[0], keep)


def graded_cycle_of(omegas):
    """The cyclic graded factors of the exponentials ``e^{Ω_k}`` (applied first to last).

    Examples
    --------
    >>> from ltpcontrol._core.graded import graded_cycle_of
    >>> H = graded_cycle_of(np.array([[[-700.0, 1.0], [0.0, -1.0]]] * 2))
    >>> np.abs(np.diagonal(H, axis1=1, axis2=2)) > 0       # no underflow: graded rows
    array([[ True,  True],
           [ True,  True]])
    """
    omegas = np.asarray(omegas, float)
    return _cycle([omegas], len(omegas), omegas.shape[1])


def _cycle(chunks, M, n, keep=None):
    """``H_k = E_k (U_kᵀ U_{k-1})`` from chunks of Magnus exponents (and kept bases)."""
    H = np.empty((M, n, n))
    wanted = set() if keep is None else {(int(k) - 1) % M for k in keep}
    bases = {}
    U_prev = U_first = None
    c0 = 0
    for Om in chunks:
        Om = np.array(Om, float)
        c1 = c0 + len(Om)
        U = np.empty_like(Om)
        for j in range(len(Om)):
            Om[j], U[j] = ordered_schur(Om[j])
            if c0 + j in wanted:
                bases[(c0 + j + 1) % M] = U[j].copy()
        E = expm_batch(Om)
        del Om
        if U_first is None:
            U_first = U[0].copy()
            H[0] = E[0]              # completed with U_{M-1} at the end
        else:
            H[c0] = E[0] @ (U[0].T @ U_prev)
        if c1 - c0 > 1:
            H[c0 + 1:c1] = E[1:] @ (np.swapaxes(U[1:], 1, 2) @ U[:-1])
        U_prev = U[-1].copy()
        c0 = c1
    H[0] = H[0] @ (U_first.T @ U_prev)
    return H if keep is None else (H, bases)
