"""Cheap exact forms of a periodic matrix for long integrations.

A model built from callables (a multi-blade transform applied point by
point, a lambda) costs a Python call per evaluation, and the Floquet
integrators evaluate the state matrix at every node of every sub-step.
Many such matrices are trigonometric polynomials of low degree (a rotor
model from tabulated azimuths transformed to multi-blade coordinates, a
Mathieu-type stiffness) or constant to the precision of their data (an
isotropic rotor in multi-blade coordinates, read from files of ten
significant digits).  `fast_form` samples the matrix once, recognises
these cases and returns the equivalent Fourier form, checked at instants
off the sampling grid, so that later evaluations are one small matrix
product.
"""

import numpy as np

from .periodic_matrix import PeriodicMatrix

__all__ = []

#: harmonics below this fraction of the largest entry count as absent
BAND_TOL = 1e-14
#: a matrix whose time variation is below this fraction of its largest
#: entry is constant to the precision of its data (linearization files
#: hold ten significant digits and azimuths to four decimals)
CONSTANT_RTOL = 1e-10
_KMAX = 128


def fast_form(A, band_tol=BAND_TOL):
    """An equivalent Fourier form of `A` when it is a low trigonometric polynomial.

    Returns `A` itself for Fourier, switching and piecewise-constant forms,
    matrices with switching instants, and matrices that are not
    band-limited to ``_KMAX`` harmonics within ``band_tol``.

    Examples
    --------
    >>> from ltpcontrol._core.fastform import fast_form
    >>> A = ltp.PeriodicMatrix.from_function(
    ...     lambda t: np.array([[np.cos(t) ** 2, 1.0], [0.0, np.sin(2 * t)]]), 2 * np.pi)
    >>> F = fast_form(A)
    >>> F.nharmonics, bool(np.allclose(F(0.3), A(0.3)))
    (2, True)
    """
    if A.nharmonics is not None or A.switching_times is not None or A.breakpoints.size \
            or A._piecewise_constant:
        return A
    T = A.period
    N = 32
    while N <= 4 * _KMAX:
        S = A._eval(np.arange(N) * T / N)
        if not np.all(np.isfinite(S)):
            return A
        scale = max(np.abs(S).max(), np.finfo(float).tiny)
        C = np.fft.fft(S, axis=0) / N
        mags = np.abs(C).max(axis=(1, 2))
        ks = np.arange(N // 2 + 1)
        per_k = np.maximum(mags[ks], mags[(-ks) % N])
        K = int(np.flatnonzero(per_k > band_tol * scale).max(initial=0))
        if K < N // 4:
            coeffs = C[np.arange(-K, K + 1) % N]
            F = PeriodicMatrix(0.5 * (coeffs + np.conj(coeffs[::-1])), T)
            probe = T * np.array([0.1234567, 0.3819660, 0.6180340, 0.8765433])
            if np.abs(F._eval(probe) - A._eval(probe)).max() <= 10 * band_tol * scale \
                    + 4 * np.finfo(float).eps * scale:
                return F
            return A
        N *= 2
    return A


def constant_value(A, rtol=CONSTANT_RTOL):
    """The mean of `A` when its time variation is below ``rtol`` of its size, else None.

    Examples
    --------
    >>> from ltpcontrol._core.fastform import constant_value
    >>> A = ltp.PeriodicMatrix.from_function(
    ...     lambda t: np.array([[-1.0 + 1e-13 * np.cos(t)]]), 2 * np.pi)
    >>> constant_value(A)
    array([[-1.]])
    >>> constant_value(A, rtol=1e-14) is None
    True
    """
    if A.nharmonics is None:
        A = fast_form(A)
        if A.nharmonics is None:
            return None
    K = A.nharmonics
    coeffs = A.fourier(K)
    mean = np.real(coeffs[K])
    if A.is_constant:
        return mean.copy()
    # max_t |A(t) - mean| <= 2 Σ_{k>0} |A_k|
    variation = 2 * np.abs(coeffs[K + 1:]).sum(axis=0).max(initial=0.0)
    scale = np.abs(mean).max(initial=0.0) + variation
    return mean.copy() if variation <= rtol * scale else None
