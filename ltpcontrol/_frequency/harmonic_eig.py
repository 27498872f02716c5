"""Marking of the eigenvalues of a truncated harmonic state matrix.

The classification behind `harmonic_modes` and the marks carried by the
result of `harmonic_ss` (module notes of `harmonic_modes`): one
eigendecomposition of ``F = 𝒜 - 𝒩`` and the Floquet exponents, computed
once, give the truncation-edge eigenvalues, the Floquet-consistent ones
and one mode per Floquet exponent.
"""

from dataclasses import dataclass

import numpy as np

from .._core.floquet import floquet_exponents
from .._core.periodic_matrix import as_periodic

__all__ = ['HarmonicModes']


@dataclass(frozen=True, repr=False)
class HarmonicModes:
    """Result of `harmonic_modes` (and the ``modes`` attribute of `harmonic_ss`).

    Attributes
    ----------
    eigenvalues : ndarray of complex
        All eigenvalues of the truncated harmonic state matrix.
    edge : ndarray of bool
        True for truncation-edge eigenvalues (module notes): not to be
        read as exponents of the system.
    floquet_consistent : ndarray of bool
        True where the eigenvalue is a Floquet exponent modulo ``jω_p``.
    edge_energy : ndarray
        Share of each eigenvector's energy in the outermost blocks.
    dominant_harmonic : ndarray of int
        Harmonic block with the largest share of each eigenvector.
    exponents : ndarray of complex
        One physical exponent per mode (``λ + j n_d ω_p``), by decreasing
        real part.
    floquet : ndarray of complex
        The Floquet exponents of the system, in the order of `exponents`.
    participation : ndarray, shape (n, modes)
        Participation factor of each state in each mode (columns sum to 1).
    harmonic_participation : ndarray, shape (2K_i+1, modes)
        Share of each harmonic -K_i..K_i in each mode (columns sum to 1).
    omega_p : float
        Fundamental frequency.
    state_labels : list of str

    Examples
    --------
    >>> A = lambda t: np.array([[0.0, 1.0], [-(2 + 3 * np.cos(t)), -0.3]])
    >>> sys = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi)
    >>> modes = ltp.harmonic_modes(sys)
    >>> bool(np.any(modes.eigenvalues.real > 0))        # truncation artefacts ...
    True
    >>> bool(np.all(modes.edge[modes.eigenvalues.real > 0]))   # ... all marked
    True
    >>> np.round(modes.exponents.real, 6)
    array([-0.15, -0.15])
    """

    eigenvalues: np.ndarray
    edge: np.ndarray
    floquet_consistent: np.ndarray
    edge_energy: np.ndarray
    dominant_harmonic: np.ndarray
    exponents: np.ndarray
    floquet: np.ndarray
    participation: np.ndarray
    harmonic_participation: np.ndarray
    omega_p: float
    state_labels: list

    @property
    def stable(self):
        """True when every mode has a negative real part."""
        return bool(np.all(self.exponents.real < 0))

    def frequency(self, Hz=False, *, hz=None):
        """Physical frequencies ``|Im λ|`` of the modes (rad/s, or Hz).

        Parameters
        ----------
        Hz : bool
            In Hz (python-control's keyword) instead of rad/s.
        hz : bool, optional
            Former spelling of `Hz`, still accepted.

        Returns
        -------
        ndarray

        Examples
        --------
        >>> sys = ltp.ltpss(ct.ss([[0.0, 1.0], [-4.0, 0.0]], [[0.0], [1.0]],
        ...                       [[1.0, 0.0]], 0), period=1.0)
        >>> np.round(ltp.harmonic_modes(sys).frequency(Hz=True), 6)
        array([0.31831, 0.31831])
        """
        f = np.abs(self.exponents.imag)
        return f / (2 * np.pi) if (Hz if hz is None else hz) else f

    @property
    def damping(self):
        """Damping ratios ``-Re λ / |λ|`` of the modes (1 for a real decay at 0)."""
        mag = np.abs(self.exponents)
        with np.errstate(invalid='ignore', divide='ignore'):
            return np.where(mag > 0, -self.exponents.real / np.where(mag > 0, mag, 1), 1.0)

    def table(self, Hz=False, *, hz=None):
        """Frequency/damping table of the modes, with each mode's leading state.

        Parameters
        ----------
        Hz : bool
            Frequencies in Hz instead of rad/s (python-control's keyword).
        hz : bool, optional
            Former spelling of `Hz`, still accepted.

        Returns
        -------
        str

        Examples
        --------
        >>> sys = ltp.ltpss(ct.ss([[-1.0, 0.0], [1.0, -3.0]], [[0.0], [1.0]],
        ...                       [[1.0, 0.0]], 0), period=1.0)
        >>> print(ltp.harmonic_modes(sys).table(Hz=True))     # doctest: +NORMALIZE_WHITESPACE
        mode  real part   frequency [Hz]  damping  leading state (share)
           0         -1                0        1  x[0] (1)
           1         -3                0        1  x[1] (1)
        """
        Hz = Hz if hz is None else hz
        unit = 'Hz' if Hz else 'rad/s'
        rows = [f"mode  real part   frequency [{unit}]  damping  leading state (share)"]
        f = self.frequency(Hz)
        for j, lam in enumerate(self.exponents):
            k = int(np.argmax(self.participation[:, j]))
            rows.append(f"{j:4d}  {lam.real:9.5g}  {f[j]:15.5g}  {self.damping[j]:7.4g}  "
                        f"{self.state_labels[k]} ({self.participation[k, j]:.3g})")
        return "\n".join(rows)

    def sensitivity(self, dA):
        """First-order change of each mode's exponent for a change ``dA(t)`` of A.

        ``dλ = wᴴ 𝒜' v / (wᴴ v)`` with v, w the right and left eigenvectors
        of the mode and 𝒜' the Toeplitz matrix of ``dA``: the derivative
        of the exponents with respect to a parameter p when ``dA = ∂A/∂p``.

        Parameters
        ----------
        dA : PeriodicMatrix, callable or array_like
            The change of the state matrix (n x n).

        Returns
        -------
        ndarray of complex
            In the order of `exponents`.

        Examples
        --------
        LTI check: the eigenvalue -1 of ``[[-1]]`` moves by dA:

        >>> sys = ltp.ltpss(ct.ss([[-1.0]], [[1.0]], [[1.0]], 0), period=1.0)
        >>> ltp.harmonic_modes(sys).sensitivity([[0.5]]).real
        array([0.5])
        """
        V, W = self._vectors
        n = len(self.state_labels)
        T = 2 * np.pi / self.omega_p
        dA = as_periodic(dA, T, 'dA', (n, n))
        Ki = self._Ki
        coeffs = dA.fourier(2 * Ki)
        harm = np.arange(-Ki, Ki + 1)
        blocks = coeffs[harm[:, None] - harm[None, :] + 2 * Ki]
        dAT = blocks.transpose(0, 2, 1, 3).reshape((2 * Ki + 1) * n, (2 * Ki + 1) * n)
        num = np.einsum('ij,ik,kj->j', W.conj(), dAT, V)
        return num / np.einsum('ij,ij->j', W.conj(), V)

    def __repr__(self):
        marked = int(np.count_nonzero(self.edge))
        rhp = int(np.count_nonzero(self.eigenvalues.real > 0))
        rhp_edge = int(np.count_nonzero((self.eigenvalues.real > 0) & self.edge))
        return (f"<HarmonicModes: {len(self.exponents)} modes, {len(self.eigenvalues)} "
                f"harmonic eigenvalues ({marked} at the truncation edge; {rhp} in the "
                f"right half plane, {rhp_edge} of them at the edge), "
                f"stable={self.stable}>")


def classify(sys, F, Ki, edge_tol=1e-3, tol=1e-6, floquet_steps=None, *, floquet=None,
             strict=True, where='harmonic_modes'):
    """Marked eigenvalues of the harmonic state matrix F (``K_i`` harmonics) of `sys`.

    Returns the `HarmonicModes` and the Floquet exponents that have no
    consistent eigenvalue (an error instead when `strict`).  `floquet`
    passes exponents already computed.

    Examples
    --------
    >>> from ltpcontrol._frequency.harmonic_eig import classify
    >>> from ltpcontrol._frequency.harmonic_ss import build
    >>> sys = ltp.ltpss(ct.ss([[-1.0]], [[1.0]], [[1.0]], 0), period=1.0)
    >>> modes, missing = classify(sys, build(sys, 0, 2, 'solve', 'x').F, 2)
    >>> modes.exponents, missing.size, bool(modes.edge.any())
    (array([-1.+0.j]), 0, False)
    """
    n, wp = sys.nstates, sys.omega_p
    nb = 2 * Ki + 1
    lam, V = np.linalg.eig(F)
    W = np.linalg.inv(V).conj().T                  # left eigenvectors, wᴴ v = 1
    energy = (np.abs(V) ** 2).reshape(nb, n, len(lam)).sum(axis=1)     # (no states: empty)
    energy /= energy.sum(axis=0, keepdims=True)
    outer = max(1, Ki // 5)
    edge_energy = np.maximum(energy[:outer].sum(axis=0), energy[-outer:].sum(axis=0))
    dominant = np.argmax(energy, axis=0) - Ki
    # a constant A has an exactly block-diagonal F: no truncation artefact
    edge = edge_energy > edge_tol if not sys.A.is_constant else np.zeros(len(lam), bool)

    if floquet is None:
        floquet = floquet_exponents(sys, floquet_steps) if n else np.zeros(0, complex)
    fl = np.atleast_1d(np.asarray(floquet, complex))
    dist = np.full((len(lam), len(fl)), np.inf)
    for i, mu in enumerate(fl):
        d = lam - mu
        dist[:, i] = np.hypot(d.real, np.remainder(d.imag + wp / 2, wp) - wp / 2) \
            / max(wp, abs(mu))
    consistent = np.min(dist, axis=1, initial=np.inf) <= tol

    chosen, found = [], []
    for i in range(len(fl)):
        cand = np.nonzero((dist[:, i] <= tol) & ~np.isin(np.arange(len(lam)), chosen))[0]
        if not cand.size:
            if strict:
                raise ValueError(f"{where}: the Floquet exponent {fl[i]:.6g} has no "
                                 f"harmonic eigenvalue within tol={tol:g} at "
                                 f"internal_harmonics={Ki}; increase internal_harmonics")
            continue
        found.append(i)
        chosen.append(int(cand[np.argmin(edge_energy[cand] + 1e-3 * np.abs(dominant[cand]))]))
    missing = np.delete(fl, found)
    chosen, fl = np.array(chosen, int), fl[found]
    phys = lam[chosen] + 1j * dominant[chosen] * wp
    order = np.lexsort((-phys.imag, -np.round(phys.real, 12)))
    chosen, phys, fl = chosen[order], phys[order], fl[order]
    pf = np.abs(V[:, chosen] * W[:, chosen].conj()).reshape(nb, n, len(chosen))
    per_state = pf.sum(axis=0)
    per_harm = pf.sum(axis=1)
    with np.errstate(invalid='ignore'):
        per_state = per_state / per_state.sum(axis=0, keepdims=True)
        per_harm = per_harm / per_harm.sum(axis=0, keepdims=True)
    out = HarmonicModes(
        eigenvalues=lam, edge=edge, floquet_consistent=consistent, edge_energy=edge_energy,
        dominant_harmonic=dominant, exponents=phys, floquet=fl, participation=per_state,
        harmonic_participation=per_harm, omega_p=wp, state_labels=list(sys.state_labels))
    # what `sensitivity` needs: the modes' eigenvectors and the truncation
    object.__setattr__(out, '_vectors', (V[:, chosen], W[:, chosen]))
    object.__setattr__(out, '_Ki', Ki)
    return out, missing
