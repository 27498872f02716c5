"""Harmonic transfer function of an LTP system with delays, exact in ``e^{-sτ}``.

A delay is exact in the harmonic domain: the harmonic n of ``v(t - τ)`` is
``V_n(s) e^{-(s + jnω_p)τ}``.  With the harmonic Toeplitz operators
``𝒯(M)`` (blocks ``M_{k-l}``) and ``𝒩(s) = diag((s + jkω_p) I)``, every
delay polynomial ``X(t, σ) = Σ_a X_a(t) σ^a`` becomes

    𝒳(s) = Σ_a 𝒯(X_a) diag(e^{-(s + jlω_p) a}),

and ``H(s) = 𝒞(s) (𝒩(s) - 𝒜(s))^{-1} ℬ(s) + 𝒟(s)``, solved at every point
(no Padé approximation, no state for the delays).  The state operator is
truncated at ``internal_harmonics`` like `ltpcontrol.htf`; for constant
matrices it is exact at any truncation.
"""

import numpy as np

from .._core.registry import override
from .._core.validation import check_positive_int
from .._frequency.htf import HTF, _harmonic
from .ltpdsys import LTPDelayStateSpace

__all__ = ['DelayHTF']


class DelayHTF(HTF):
    """Harmonic transfer function of an `LTPDelayStateSpace` (built by `ltpcontrol.htf`).

    Parameters
    ----------
    sys : LTPDelayStateSpace
        The system.
    nharmonics : int
        Number K >= 0 of harmonics of the result.
    internal_harmonics : int, optional
        Truncation ``K_i >= K`` of the harmonic operators (default K for
        constant matrices, where the result is exact, else ``K + 10 +``
        the bandwidth of B and C).

    Examples
    --------
    >>> P = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(0.2, [[0.3]])],
    ...                name='P')
    >>> H = ltp.htf(P, 1)
    >>> H
    <DelayHTF P: ['u[0]'] -> ['y[0]'], K=1, period=1>
    >>> s = 0.5j
    >>> bool(np.isclose(H(s)[1, 1], 1 / (s + 1 - 0.3 * np.exp(-0.2 * s))))
    True
    """

    def __init__(self, sys, nharmonics, *, internal_harmonics=None):
        K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
        self._set_signals(sys.period, K, sys.noutputs, sys.ninputs, 0.0, sys.name,
                          sys.input_labels, sys.output_labels)
        if internal_harmonics is None:
            band = 0
            for X in sys.terms.values():
                for M in X.values():
                    if not M.is_constant:
                        band = max(band, 10 + (M.nharmonics or 0))
            Ki = K + band
        else:
            Ki = check_positive_int(internal_harmonics, 'internal_harmonics', minimum=K)
        self._Ki = Ki
        self._n = sys.nstates
        # Toeplitz blocks of every term, (2Ki+1)*rows x (2Ki+1)*cols
        self._ops = {k: [(a, _toeplitz(M, Ki)) for a, M in sys.terms[k].items()]
                     for k in 'ABCD'}

    def _operator(self, which, s):
        """The harmonic operator of block `which` at the points `s`: (len(s), rows, cols)."""
        Ki = self._Ki
        l = np.arange(-Ki, Ki + 1)
        out = 0
        for a, Top in self._ops[which]:
            if a == 0:
                out = out + Top[None]
            else:
                cols = Top.shape[1] // (2 * Ki + 1)
                phase = np.repeat(np.exp(-(s[:, None] + 1j * l[None, :] * self.omega_p) * a),
                                  cols, axis=1)
                out = out + Top[None] * phase[:, None, :]
        return np.broadcast_to(out, (len(s),) + self._shape(which)) if np.ndim(out) == 3 \
            else np.zeros((len(s),) + self._shape(which), complex)

    def _shape(self, which):
        Ki, n = self._Ki, self._n
        rows = {'A': n, 'B': n, 'C': self.noutputs, 'D': self.noutputs}[which]
        cols = {'A': n, 'B': self.ninputs, 'C': n, 'D': self.ninputs}[which]
        return ((2 * Ki + 1) * rows, (2 * Ki + 1) * cols)

    def _evaluate(self, s, progress):
        Ki, K, n = self._Ki, self.nharmonics, self._n
        ny, nu = self.noutputs, self.ninputs
        s = np.atleast_1d(np.asarray(s, complex))
        ks = np.arange(-Ki, Ki + 1)
        keep_y = ((ks[:, None] + Ki)[np.abs(ks) <= K] * ny + np.arange(ny)).ravel()
        keep_u = ((ks[:, None] + Ki)[np.abs(ks) <= K] * nu + np.arange(nu)).ravel()
        out = np.empty((len(s), (2 * K + 1) * ny, (2 * K + 1) * nu), complex)
        size = (2 * Ki + 1) * max(n, ny, nu, 1)
        chunk = max(1, int(2 ** 22 // size ** 2))          # ~64 MB of complex operators
        diag = np.repeat(1j * ks * self.omega_p, n)
        for i in range(0, len(s), chunk):
            si = s[i:i + chunk]
            C = self._operator('C', si)[:, keep_y, :]
            H = self._operator('D', si)[:, keep_y][:, :, keep_u]
            if n:
                A = -self._operator('A', si)
                idx = np.arange(A.shape[1])
                A[:, idx, idx] += si[:, None] + diag[None, :]
                B = self._operator('B', si)[:, :, keep_u]
                H = H + C @ np.linalg.solve(A, B)
            out[i:i + chunk] = H
        return out

    def _components_on(self, omega, ks, progress=None):
        from .._frequency.htf import default_omega
        from .._core.validation import real_array
        omega = (default_omega(self) if omega is None
                 else real_array(omega, 'omega', ndim=(0, 1)).reshape(-1))
        H = self._evaluate(1j * omega, progress)
        K, ny, nu = self.nharmonics, self.noutputs, self.ninputs
        # G_k = H_{0,-k}: central block row, block column -k
        G = np.stack([H[:, K * ny:(K + 1) * ny, (K - _harmonic(k, K)) * nu:
                        (K - k + 1) * nu] for k in ks])
        return omega, G.transpose(0, 2, 3, 1)


def _toeplitz(M, Ki):
    """Harmonic Toeplitz operator of a periodic matrix: block (k, l) = M_{k-l}."""
    r, c = M.shape
    F = M.fourier(2 * Ki)                                  # -2Ki..2Ki
    k = np.arange(-Ki, Ki + 1)
    blocks = F[(k[:, None] - k[None, :]) + 2 * Ki]        # (2Ki+1, 2Ki+1, r, c)
    return blocks.transpose(0, 2, 1, 3).reshape((2 * Ki + 1) * r, (2 * Ki + 1) * c)


@override('htf', LTPDelayStateSpace)
def htf(sys, nharmonics, *, internal_harmonics=None, method='auto', period=None):
    """`ltpcontrol.htf` of a system with delays: a `DelayHTF`.

    Examples
    --------
    >>> P = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(0.2, [[0.3]])])
    >>> type(ltp.htf(P, 2)).__name__
    'DelayHTF'
    """
    if period is not None:
        raise TypeError("the period is taken from the LTPDelayStateSpace sys; do not pass "
                        "period")
    if method not in ('auto', 'solve'):
        raise ValueError(f"method must be 'auto' or 'solve' for a system with delays, got "
                         f"{method!r}")
    return DelayHTF(sys, nharmonics, internal_harmonics=internal_harmonics)
