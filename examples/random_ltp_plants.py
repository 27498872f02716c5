"""Seeded random LTP plants with periodic A(t), B(t), C(t) and their exact lifted data
(used by the generic identification study and the test suite)."""

import numpy as np
import control as ct

import ltpcontrol as ltp
from ltpcontrol._core.lifting import _real_basis


def random_ltp(seed, nstates=2, noutputs=1, harmonics=2, period=1.0, depth=0.3,
               allow_negative=False, ninputs=1, periodic='ABC', actuator=None):
    """Random stable continuous LTP plant with harmonics up to `harmonics` in A, B, C
    (`ninputs` inputs, `noutputs` outputs).

    Only the matrices named in `periodic` vary (e.g. ``'A'``: periodic A(t)
    with constant B and C).  With ``actuator=r``, the last state is a
    first-order actuator ``ẋ_n = -a (x_n - u)`` driving the others, with
    ``a`` r times the largest modulus of the other exponents (a fast
    actuator for r >= 10; one input, B constant).

    The mean A has exponents with real parts in [-3, -0.5] and imaginary
    parts below ω_p/4; every harmonic of A, B and C has a relative size of
    about ``depth / h``.  Stability is checked with the Floquet multipliers.
    Plants with negative real multipliers (exponents on ``Im λ = ω_p/2``
    with distinct real parts, a parametric resonance) are redrawn: they
    have no real Floquet form of period T, so no real K-harmonic model of
    period T can match them (see `negative_multiplier_plant`).
    """
    rng = np.random.default_rng(seed)
    wp = 2 * np.pi / period
    n = nstates
    while True:
        # mean A with prescribed exponents in a random basis
        re = -rng.uniform(0.5, 3.0, n)
        A0 = np.diag(re)
        for i in range(0, n - 1, 2):
            if rng.random() < 0.5:
                im = rng.uniform(0.2, 0.25) * wp
                A0[i:i + 2, i:i + 2] = [[re[i], im], [-im, re[i]]]
        S = rng.normal(size=(n, n)) + 2 * np.eye(n)
        A0 = S @ A0 @ np.linalg.inv(S)
        scale = np.abs(np.linalg.eigvals(A0)).max()

        def coeffs(mean, rows, cols, size):
            c = np.zeros((2 * harmonics + 1, rows, cols), complex)
            c[harmonics] = mean
            for h in range(1, harmonics + 1):
                ch = size / h * (rng.normal(size=(rows, cols))
                                 + 1j * rng.normal(size=(rows, cols))) / 2
                c[harmonics + h], c[harmonics - h] = ch, ch.conj()
            return c

        A = coeffs(A0, n, n, depth * scale / np.sqrt(n) * ('A' in periodic))
        B = coeffs(rng.normal(size=(n, ninputs)), n, ninputs, depth * ('B' in periodic))
        C = coeffs(rng.normal(size=(noutputs, n)), noutputs, n, depth * ('C' in periodic))
        if actuator is not None:
            # states 0..n-1 driven by the actuator state n through the old B_0
            a = actuator * scale
            Aa = np.zeros((2 * harmonics + 1, n + 1, n + 1), complex)
            Aa[:, :n, :n] = A
            Aa[:, :n, n] = B[:, :, 0]
            Aa[harmonics, n, n] = -a
            B = np.zeros((2 * harmonics + 1, n + 1, 1), complex)
            B[harmonics, n, 0] = a
            C = np.concatenate([C, np.zeros((2 * harmonics + 1, noutputs, 1))], axis=2)
            A = Aa
        sys = ltp.ltpss(ltp.PeriodicMatrix(A, period), ltp.PeriodicMatrix(B, period),
                        ltp.PeriodicMatrix(C, period), 0, period=period,
                        name=f'plant{seed}')
        mu = ltp.floquet_multipliers(sys)
        negative = (np.abs(mu.imag) <= 1e-9 * np.abs(mu)) & (mu.real < 0)
        if np.abs(mu).max() < np.exp(-0.3 * period) and (allow_negative
                                                       or not negative.any()):
            return sys


def lifted_data(sys, nharmonics, omega, dt):
    """Exact real lifted response (as `lifted_frequency_response` returns) on `omega`:
    the HTF columns of input harmonic 0, ``V^H H_{:,0}(jΩ)``."""
    K, ny, nu = nharmonics, sys.noutputs, sys.ninputs
    G = ltp.htf(sys, K)(1j * np.asarray(omega))[:, K * nu:(K + 1) * nu]   # (.., nu, M)
    V, tags = _real_basis(np.arange(-K, K + 1), int(round(sys.period / dt)))
    Gr = np.einsum('ba,bjw->ajw', np.kron(V, np.eye(ny)).conj(), G)
    outputs = [f'y[{i}]_{tag}' for tag in tags for i in range(ny)]
    return ct.frd(Gr, omega, dt, outputs=outputs, inputs=[f'u[{j}]_c0' for j in range(nu)])


def design_lines(period, nlines, wmax_factor=3.0, offset=0.37):
    """`nlines` lines in (0, wmax_factor ω_p), away from the multiples of ω_p/2."""
    wp = 2 * np.pi / period
    return (np.arange(nlines) + offset) * wmax_factor * wp / nlines
