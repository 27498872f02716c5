"""Transmission zeros of square LTP systems.

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
"""

import numpy as np
import scipy.linalg as la
from control.exception import ControlDimension

from .._frequency.harmonic_ss import _toeplitz
from .._core.lifting import lift
from .._core.coerce import as_ltp
from .._core.validation import check_positive_int
from .._core.registry import method_alias

__all__ = ['zeros']


@method_alias
def zeros(sys, nharmonics=None, *, rtol=1e-8):
    """Transmission zeros of a square LTP system.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous- or discrete-time system with as many inputs as outputs.
    nharmonics : int, optional
        Continuous time: truncation order K of the harmonic pencil (default
        ``min(40, 12 + 4 K_sys)`` with K_sys the number of harmonics above
        1e-14 of the largest coefficient of the system matrices); the check
        uses ``K + max(8, K/2)``.  Ignored in discrete time (exact).
    rtol : float, optional
        Continuous time: relative agreement required between the two
        truncations for a value to be reported.

    Returns
    -------
    ndarray of complex
        Continuous time: the zeros in the strip ``−ω_p/2 < Im <= ω_p/2``
        (zeros are defined modulo ``jω_p``).  Discrete time: per-step
        values ``μ^{1/N}``.  Sorted by real part.  An LTI system (constant
        matrices, or the same matrices at every step) gives the zeros of
        `control.zeros`, also outside the strip.

    Raises
    ------
    ControlDimension
        If the system is not square.

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
    """
    sys = as_ltp(sys)
    if sys.ninputs != sys.noutputs:
        raise ControlDimension(f"zeros: the system must be square, got {sys.noutputs} "
                               f"outputs and {sys.ninputs} inputs")
    if not (isinstance(rtol, (int, float, np.floating)) and 0 < rtol < 1):
        raise ValueError(f"rtol must be a number in (0, 1), got {rtol!r}")
    if nharmonics is not None:
        K = check_positive_int(nharmonics, 'nharmonics', minimum=1)
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
    n, m = sys.nstates, sys.ninputs
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
