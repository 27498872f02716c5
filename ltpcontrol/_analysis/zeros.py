"""Transmission zeros of LTP systems, square or not, and their structure.

Continuous time: the finite generalized eigenvalues s of the harmonic
(Toeplitz) Rosenbrock pencil truncated at K harmonics (Conventions page),

    [[𝒜 − 𝒩 − sI, ℬ], [𝒞, 𝒟]],   𝒩 = blkdiag(jnω_p I),

A genuine zero z appears in every truncation, repeated as ``z − jnω_p``;
the copy in the strip ``−ω_p/2 < Im s <= ω_p/2`` (the central harmonic,
the most accurate one) is kept when a second, larger truncation reproduces
it, which removes the truncation artefacts.

Discrete time: the finite generalized eigenvalues μ of the Rosenbrock
pencil of the time-lifted system (`lift`, method 'time'), reported per
step as ``ρ = μ^{1/N}`` (principal root) like the poles
(`floquet_exponents`).

Non-square systems (and ``structure=True``): the zeros are the values
where the Rosenbrock pencil loses rank below its normal rank; the pencil is
reduced to a regular one carrying exactly these zeros by the staircase
algorithm of Emami-Naeini and Van Dooren (SLICOT AB08ND through slycot),
which also returns the normal rank of the transfer matrix, the orders of
the infinite zeros (infinite elementary divisors) and the right and left
Kronecker indices.  Discrete time these are the zeros and structure of the
lifted system (the convention of Grasselli and Longhi for periodic
systems); continuous time the finite zeros of the truncated harmonic
system are kept when two truncations agree, as for square systems, and
the structure is that of the smaller truncation.
"""

from collections import namedtuple

import numpy as np
import scipy.linalg as la
import slycot

from .._frequency.harmonic_ss import _toeplitz
from .._core.lifting import lift
from .._core.coerce import as_ltp
from .._core.validation import check_positive_int
from .._core.registry import method_alias
from .._core.tvsystem import DiscreteLTPSystem, dltpss
from .._core.lifting_forms import tv_time_lift

__all__ = ['zeros']

#: Zeros and their structure (``zeros(sys, structure=True)``): finite zeros,
#: normal rank of the transfer matrix, orders of the infinite zeros (one
#: entry per infinite elementary divisor, its degree), right and left
#: Kronecker indices (of the lifted or truncated harmonic system).
ZeroStructure = namedtuple('ZeroStructure', ['zeros', 'normal_rank', 'infinite_orders',
                                             'right_kronecker', 'left_kronecker'])


@method_alias
def zeros(sys, nharmonics=None, *, rtol=1e-8, structure=False):
    """Transmission (invariant) zeros of an LTP system, square or not.

    Parameters
    ----------
    sys : LTPStateSpace or DiscreteLTPSystem
        Continuous- or discrete-time system; non-square systems have the
        zeros of their normal rank (module notes).
    nharmonics : int, optional
        Continuous time: truncation order K of the harmonic pencil (default
        ``min(40, 12 + 4 K_sys)`` with K_sys the number of harmonics above
        1e-14 of the largest coefficient of the system matrices); the check
        uses ``K + max(8, K/2)``.  Ignored in discrete time (exact).
    rtol : float, optional
        Continuous time: relative agreement required between the two
        truncations for a value to be reported.
    structure : bool, optional
        Also return the normal rank, the infinite zero structure and the
        Kronecker indices.

    Returns
    -------
    ndarray of complex
        Continuous time: the zeros in the strip ``−ω_p/2 < Im <= ω_p/2``
        (zeros are defined modulo ``jω_p``).  Discrete time: per-step
        values ``μ^{1/N}``.  Sorted by real part.  An LTI system (constant
        matrices, or the same matrices at every step) gives the zeros of
        `control.zeros`, also outside the strip.
    ZeroStructure
        With ``structure=True`` instead: the named tuple ``(zeros,
        normal_rank, infinite_orders, right_kronecker, left_kronecker)``.

    Examples
    --------
    Bittanti & Colaneri's example (Periodic Systems, 2009, p. 26) has the
    zero ``-3 + 4/√3``:

    >>> A = ltp.PeriodicMatrix.from_function(lambda t: np.array(
    ...     [[-1 + np.sin(t), 0], [1 - np.cos(t), -3]]), 2 * np.pi)
    >>> B = lambda t: np.array([[-1 - np.cos(t)], [2 - np.sin(t)]])
    >>> sys = ltp.ltpss(A, B, [[0, 1]], 0, period=2 * np.pi)
    >>> z = ltp.zeros(sys)
    >>> bool(np.allclose(z, -3 + 4 / np.sqrt(3)))
    True
    >>> bool(np.allclose(ct.zeros(sys), z))      # python-control dispatches here
    True

    Pitelkau's satellite (a 2x1 system): every zero is infinite, so no
    finite zero is returned; the lifted system has normal rank 1 per step:

    >>> w = 0.00103448
    >>> a = np.array([[0, 0, 5.318064566757217e-02, 0], [0, 0, 0, 5.318064566757217e-02],
    ...               [-1.352134256362805e-03, 0, 0, -7.099273035392090e-02],
    ...               [0, -7.557182037479544e-04, 3.781555288420663e-02, 0]])
    >>> b = lambda t: np.array([[0], [0], [0.1389735e-6 * np.sin(w * t)],
    ...                         [-0.3701336e-7 * np.cos(w * t)]])
    >>> sys = ltp.ltpss(a, b, [[1, 0, 0, 0], [0, 1, 0, 0]], 0, period=2 * np.pi / w)
    >>> info = ltp.zeros(sys.sample(sys.period / 24), structure=True)
    >>> info.zeros.size, info.normal_rank
    (0, 24)
    """
    if not isinstance(structure, (bool, np.bool_)):
        raise ValueError(f"structure must be True or False, got {structure!r}")
    if isinstance(sys, DiscreteLTPSystem):
        return _general_discrete(sys, structure)
    sys = as_ltp(sys)
    if not (isinstance(rtol, (int, float, np.floating)) and 0 < rtol < 1):
        raise ValueError(f"rtol must be a number in (0, 1), got {rtol!r}")
    if nharmonics is not None:
        K = check_positive_int(nharmonics, 'nharmonics', minimum=1)
    if sys.ninputs != sys.noutputs or structure:
        if sys.isdtime():
            return _general_discrete(dltpss(sys), structure)
        return _general_continuous(sys, nharmonics, rtol, structure)
    if sys.isdtime():
        return _discrete(sys)
    if sys.is_lti:                   # the zeros of the constant matrices, unfolded
        return _sorted(_pencil_zeros(*(M(0.0) for M in (sys.A, sys.B, sys.C, sys.D))))
    if nharmonics is None:
        K = min(40, 12 + 4 * max(_bandwidth(M) for M in (sys.A, sys.B, sys.C, sys.D)))
    z1 = _harmonic_zeros(sys, K)
    z2 = _harmonic_zeros(sys, K + max(8, K // 2))
    keep = [z for z in z1 if z2.size and
            np.min(np.abs(z2 - z)) <= rtol * max(1.0, abs(z))]
    return _sorted(np.array(keep, complex))


def _bandwidth(M):
    """Highest harmonic of M above 1e-14 of its largest coefficient (at most 64)."""
    if M.nharmonics is not None:
        return M.nharmonics
    c = np.abs(M.fourier(64)).max(axis=(1, 2))[64:]
    big = np.flatnonzero(c > 1e-14 * max(c.max(), 1e-300))
    return int(big[-1]) if big.size else 0


def _harmonic_zeros(sys, K):
    """Finite pencil eigenvalues of truncation K in the central strip."""
    n = sys.nstates
    w = sys.omega_p
    T = [_toeplitz(M.fourier(2 * K), K) for M in (sys.A, sys.B, sys.C, sys.D)]
    F = T[0] - np.kron(np.diag(1j * w * np.arange(-K, K + 1)), np.eye(n))
    size = (2 * K + 1) * n
    pencil = np.block([[F, T[1]], [T[2], T[3]]])
    E = np.zeros_like(pencil)
    E[:size, :size] = np.eye(size)
    alpha, beta = la.eig(pencil, E, right=False, homogeneous_eigvals=True)
    finite = np.abs(beta) > 1e-10 * np.abs(alpha)
    z = alpha[finite] / beta[finite]
    # the central copies: -ω_p/2 < Im z <= ω_p/2
    return z[(z.imag > -w / 2) & (z.imag <= w / 2)]


def _discrete(sys):
    N = sys.nsteps
    steps = [M.sample(N) for M in (sys.A, sys.B, sys.C, sys.D)]
    if all(np.all(M == M[0]) for M in steps):    # the same matrices at every step
        return _sorted(_pencil_zeros(*(M[0] for M in steps)))
    L = lift(sys, method='time')
    return _sorted(_pencil_zeros(L.A, L.B, L.C, L.D) ** (1.0 / N))


def _pencil_zeros(A, B, C, D):
    """Finite generalized eigenvalues of the Rosenbrock pencil of (A, B, C, D)."""
    n = A.shape[0]
    pencil = np.block([[A, B], [C, D]])
    E = la.block_diag(np.eye(n), np.zeros_like(D))
    alpha, beta = la.eig(pencil, E, right=False, homogeneous_eigvals=True)
    scale = max(1.0, np.abs(pencil).max())
    finite = np.abs(beta) > 1e-12 * scale * np.maximum(np.abs(alpha), 1e-300) \
        / np.maximum(np.abs(alpha), 1.0)
    z = alpha[finite] / beta[finite]
    return z[np.abs(z) < 1e12 * scale].astype(complex)


def _sorted(z):
    return z[np.lexsort((z.imag, z.real))]


def _ab08(A, B, C, D):
    """Finite zeros and structure of (A, B, C, D) by SLICOT AB08ND."""
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    scale = max(1.0, np.abs(np.block([[A, B], [C, D]])).max(initial=0.0)) if n + m + p else 1.0
    nu, rank, dinfz, nkror, nkrol, infz, kronr, kronl, Af, Bf = slycot.ab08nd(
        n, m, p, A / scale, B / scale, C / scale, D / scale, equil='N',
        tol=max(n + p, n + m) * np.finfo(float).eps * 10,
        ldwork=2 * max(1, min(p, m) + max(3 * m - 1, n),
                       min(p, n) + max(3 * p - 1, n + p, n + m),
                       min(m, n) + max(3 * m - 1, n + m)) + 64)
    if nu:
        alpha, beta = la.eig(Af[:nu, :nu], Bf[:nu, :nu], right=False, homogeneous_eigvals=True)
        finite = np.abs(beta) > 1e-12 * np.abs(alpha)
        z = (alpha[finite] / beta[finite]).astype(complex) * scale
    else:
        z = np.zeros(0, complex)
    orders = [i + 1 for i in range(dinfz) for _ in range(int(infz[i]))]
    return z, int(rank), orders, [int(k) for k in kronr[:nkror]], \
        [int(k) for k in kronl[:nkrol]]


def _general_discrete(sys, structure):
    """Zeros of the lifted system, per step (module notes)."""
    N = sys.nsteps
    z, rank, orders, kr, kl = _ab08(*tv_time_lift(sys))
    if N > 1:
        z = z ** (1.0 / N)
    z = _sorted(z)
    return ZeroStructure(z, rank, orders, kr, kl) if structure else z


def _general_continuous(sys, nharmonics, rtol, structure):
    """Zeros of the truncated harmonic system kept when two truncations agree."""
    if sys.is_lti:
        mats = [M(0.0) for M in (sys.A, sys.B, sys.C, sys.D)]
        z, rank, orders, kr, kl = _ab08(*mats)
        z = _sorted(z)
        return ZeroStructure(z, rank, orders, kr, kl) if structure else z
    if nharmonics is None:
        K = min(40, 12 + 4 * max(_bandwidth(M) for M in (sys.A, sys.B, sys.C, sys.D)))
    else:
        K = nharmonics
    w = sys.omega_p
    runs = []
    for k in (K, K + max(8, K // 2)):
        T = [_toeplitz(M.fourier(2 * k), k) for M in (sys.A, sys.B, sys.C, sys.D)]
        F = T[0] - np.kron(np.diag(1j * w * np.arange(-k, k + 1)), np.eye(sys.nstates))
        runs.append(_ab08_complex(F, T[1], T[2], T[3]))
    z1, z2 = runs[0][0], runs[1][0]
    z1 = z1[(z1.imag > -w / 2) & (z1.imag <= w / 2)]
    keep = [z for z in z1 if z2.size and np.min(np.abs(z2 - z)) <= rtol * max(1.0, abs(z))]
    z = _sorted(np.array(keep, complex))
    if structure:
        return ZeroStructure(z, *runs[0][1:])
    return z


def _ab08_complex(A, B, C, D):
    """AB08ND on the real form of a complex system (zeros come in conjugate pairs)."""
    def real(M):
        return np.block([[M.real, -M.imag], [M.imag, M.real]])
    z, rank, orders, kr, kl = _ab08(real(A), real(B), real(C), real(D))
    # the real form doubles every zero of the complex system with its conjugate
    return z, rank // 2, sorted(orders)[::2], sorted(kr)[::2], sorted(kl)[::2]
