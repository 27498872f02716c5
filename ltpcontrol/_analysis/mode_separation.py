"""Separation of repeated Floquet multipliers by harmonic content.

An isotropic rotor's collective mode and its backward and forward whirl
modes differ by multiples of ``jΩ``: they share one Floquet multiplier, and
any basis of its eigenspace is a valid set of eigenvectors — generally a
mixture of the three, whose harmonic content (and so principal harmonic,
frequency and mode-shape tracking) means nothing.  The physical modes are
the basis vectors whose periodic shapes each carry one harmonic.

For a cluster of g (nearly) equal multipliers with periodic vectors
``p_i(t)`` and the Fourier coefficients ``c_{i,h}`` of their shapes
``F(t) p_i(t)``, the Hermitian forms

    E_ij = Σ_h c_{i,h}ᴴ c_{j,h}      (energy),
    H_ij = Σ_h h c_{i,h}ᴴ c_{j,h}    (harmonic index weighted by energy)

define the *mean harmonic* ``η(y) = yᴴHy / yᴴEy`` of the combination
``Σ y_i p_i``.  The generalized eigenvectors of ``H y = η E y`` are the
stationary points of η: when the eigenspace is spanned by shapes of
distinct single harmonics they are exactly those shapes (η = their
harmonic), and otherwise the combinations whose content is most
concentrated at the low and high ends.  Exponents of a cluster of nearly
equal multipliers are the diagonal of the cluster's operator in the new
basis, ``Y⁻¹ diag(λ) Y``, so their sum (and the Liouville check) is kept.

A time-invariant system is its own fast path: the modes are the
eigenvectors of A (``p(t) = v e^{jmω_p t}``, one harmonic each, so a shape
measured in the system's own coordinates has participation exactly 1).
"""

import warnings

import numpy as np
import scipy.linalg as la

__all__ = ['constant_part', 'constant_modes', 'separate_clusters', 'clusters']

# smallest mean-harmonic gap that still tells two modes of a cluster apart
_ETA_GAP = 0.5


def constant_part(A, rtol):
    """The constant matrix of a (numerically) time-invariant periodic matrix, or None.

    ``A`` is constant when its flag says so, or when its values at 33
    irregular instants of the period differ from their mean by at most
    ``rtol`` times their largest entry (a trigonometric polynomial of
    degree <= 16 that is constant at 33 points is constant).

    Examples
    --------
    >>> from ltpcontrol._analysis.mode_separation import constant_part
    >>> A = ltp.PeriodicMatrix.from_function(
    ...     lambda t: np.array([[-1.0 + 1e-11 * np.cos(t)]]), 2 * np.pi, (1, 1))
    >>> constant_part(A, 1e-9)
    array([[-1.]])
    >>> constant_part(A, 1e-13) is None
    True
    """
    if A.is_constant:
        return np.real_if_close(np.asarray(A(0.0)))
    probe = A.period * np.mod(0.1234 + 0.6180339887 * np.arange(33), 1.0)
    try:
        vals = np.asarray(A(probe))
    except ValueError:
        return None
    if not np.all(np.isfinite(vals)):
        return None
    mean = vals.mean(axis=0)
    scale = np.abs(vals).max(initial=0.0)
    if np.abs(vals - mean).max(initial=0.0) <= rtol * scale:
        return mean
    return None


def constant_modes(A0, period, times):
    """Eigen-decomposition of a constant A as Floquet data on the strip.

    Returns ``(strip, logmod, arg, on_samples, left)``: strip exponents
    ``λ - jmω_p`` (m the branch of λ), the logs of modulus and argument of
    the multipliers, the periodic vectors ``v e^{jmω_p t}`` at `times`
    (mode, time, state) and the left vectors (state, mode) with
    ``leftᴴ v = I``.

    Examples
    --------
    >>> from ltpcontrol._analysis.mode_separation import constant_modes
    >>> strip, logmod, arg, p, q = constant_modes(np.array([[0.0, 3.0], [-3.0, 0.0]]),
    ...                                           2 * np.pi, np.array([0.0, 1.0]))
    >>> np.sort(strip.imag).round(12)
    array([0., 0.])
    >>> bool(np.allclose(q.conj().T @ p[:, 0, :].T, np.eye(2)))
    True
    """
    lam, V = la.eig(A0)
    V = V / np.linalg.norm(V, axis=0)
    try:
        W = np.linalg.inv(V).conj().T
    except np.linalg.LinAlgError:
        W = np.full_like(V, np.nan)
    wp = 2 * np.pi / period
    m = np.round(lam.imag / wp)
    strip = lam - 1j * m * wp
    on_samples = V.T[:, None, :] * np.exp(1j * wp * np.outer(m, times))[:, :, None]
    logmod = strip.real * period
    arg = strip.imag * period
    return strip, logmod, arg, on_samples, W


def clusters(log_mu, tol):
    """Groups (size > 1) of modes whose multipliers agree within `tol` (relative).

    `log_mu` holds ``log μ = λT`` (continuous time) or the log of the
    multiplier over the period (discrete time); two modes belong together
    when ``|Δ log μ|`` (the argument compared on the unit circle) is at
    most ``tol · max(1, |log μ|)``.

    Examples
    --------
    >>> from ltpcontrol._analysis.mode_separation import clusters
    >>> clusters(np.array([1j, 1j + 1e-9, -1j, 0.3]), 1e-6)
    [[0, 1]]
    """
    n = len(log_mu)
    lt = np.asarray(log_mu, complex)
    done = ~np.isfinite(lt)
    out = []
    for i in range(n):
        if done[i]:
            continue
        d_re = np.abs(lt.real - lt[i].real)
        d_im = np.abs(np.angle(np.exp(1j * (lt.imag - lt[i].imag))))
        close = (np.hypot(d_re, d_im) <= tol * max(1.0, abs(lt[i]))) & ~done
        members = [int(j) for j in np.flatnonzero(close)]
        done[members] = True
        if len(members) > 1:
            out.append(members)
    return out


def separate_clusters(strip, on_samples, left, coeffs, harmonics, groups):
    """Split each cluster's eigenspace by harmonic content (in place).

    Parameters
    ----------
    strip : ndarray of complex, shape (n,)
        Strip exponents (updated for clusters of unequal ones).
    on_samples : ndarray, shape (n, S, nstates)
        Periodic vectors at the sample instants (mixed in place).
    left : ndarray, shape (nstates, n)
        Left vectors (``leftᴴ on_samples[:, 0].T = I``, kept).
    coeffs : ndarray, shape (r, n, H)
        Fourier coefficients of the framed shapes (mixed in place).
    harmonics : ndarray of int, shape (H,)
        Harmonic index of each column of `coeffs`.
    groups : list of list of int
        The clusters.

    Returns
    -------
    list of tuple
        ``(modes, mean harmonics)`` of the clusters whose modes the
        harmonic content does not tell apart (mean harmonics closer than
        1/2 but not equal).

    Examples
    --------
    Three copies of one oscillator seen in coordinates that rotate the
    copies' content to harmonics -1, 0, 1: any mixture is split back.

    >>> from ltpcontrol._analysis.mode_separation import separate_clusters
    >>> c = np.zeros((3, 3, 3), complex)             # (r, mode, harmonic)
    >>> c[0, 0, 0] = c[1, 1, 1] = c[2, 2, 2] = 1.0    # pure harmonics -1, 0, 1
    >>> mix = np.linalg.qr(np.random.default_rng(0).standard_normal((3, 3)))[0]
    >>> c = np.einsum('rih,ij->rjh', c, mix)
    >>> p = mix.T[:, None, :].astype(complex)        # their vectors at t = 0
    >>> bad = separate_clusters(np.zeros(3, complex), p, mix.astype(complex), c,
    ...                         np.array([-1, 0, 1]), [[0, 1, 2]])
    >>> (np.abs(c).max(axis=0) > 1e-12).sum(axis=1)   # one harmonic per mode again
    array([1, 1, 1])
    >>> bad
    []
    """
    ambiguous = []
    h = harmonics.astype(float)
    for g in groups:
        C = coeffs[:, g, :]                                    # (r, g, H)
        if not np.all(np.isfinite(C)):
            continue
        E = np.einsum('rih,rjh->ij', np.conj(C), C)
        Hm = np.einsum('rih,rjh,h->ij', np.conj(C), C, h)
        E, Hm = (E + E.conj().T) / 2, (Hm + Hm.conj().T) / 2
        try:
            eta, Y = la.eigh(Hm, E)
        except (la.LinAlgError, ValueError):
            continue
        # unit-norm vectors at t = 0
        P0 = on_samples[g, 0, :].T @ Y
        Y = Y / np.linalg.norm(P0, axis=0)
        try:
            Yinv = np.linalg.inv(Y)
        except np.linalg.LinAlgError:
            continue
        on_samples[g] = np.einsum('ij,itn->jtn', Y, on_samples[g])
        coeffs[:, g, :] = np.einsum('ij,rih->rjh', Y, C)
        left[:, g] = left[:, g] @ Yinv.conj().T
        lam = strip[g]
        if np.ptp(lam.real) > 0 or np.ptp(lam.imag) > 0:
            strip[g] = np.diag(Yinv @ np.diag(lam) @ Y)
        gaps = np.abs(eta[:, None] - eta[None, :])
        close = (gaps < _ETA_GAP) & (gaps > 1e-6)
        if np.any(close):
            ambiguous.append(([g[i] for i in np.flatnonzero(close.any(axis=0))],
                              eta[close.any(axis=0)]))
    return ambiguous


def warn_ambiguous(ambiguous, strip, stacklevel=3):
    """One warning naming the clusters the harmonic content cannot split.

    Parameters
    ----------
    ambiguous : list of (list of int, ndarray)
        The clusters `separate_clusters` could not split: the indices of
        their modes and the modes' mean harmonics.
    strip : ndarray of complex
        Exponents of all modes (the cluster's first one is printed).
    stacklevel : int
        Of the warning (the caller of the public function).

    Examples
    --------
    >>> import warnings
    >>> from ltpcontrol._analysis.mode_separation import warn_ambiguous
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter('always')
    ...     warn_ambiguous([([0, 1], np.array([0.49, 0.51]))], np.array([-0.1 + 2j, -0.1 + 2j]))
    >>> message = str(caught[0].message)
    >>> message.startswith('repeated multipliers whose modes cannot be separated')
    True
    >>> message.split('content: ')[1].split(')')[0]
    '2 modes at exponent -0.1+2j (mean harmonics [0.49, 0.51]'
    >>> warn_ambiguous([], np.array([]))          # nothing to report: no warning
    """
    if not ambiguous:
        return
    parts = [f"{len(modes)} modes at exponent {strip[modes[0]]:.4g} (mean harmonics "
             f"{np.round(eta, 2).tolist()})" for modes, eta in ambiguous]
    warnings.warn("repeated multipliers whose modes cannot be separated by their harmonic "
                  "content: " + "; ".join(parts) + ". Their shapes are mixtures and their "
                  "principal harmonics are uncertain; measure the content in other "
                  "coordinates (frame=)", UserWarning, stacklevel=stacklevel)
