"""Eigen-analysis of the harmonic state space that cannot mislead.

The truncated harmonic state matrix ``F = 𝒜 - 𝒩`` (module `harmonic_ss`)
has ``(2K_i+1) n`` eigenvalues.  Those whose eigenvectors are centred in
the harmonics are shifted copies ``λ - jkω_p`` of the Floquet exponents;
those whose eigenvectors reach the truncation edge are artefacts of the
truncation and may sit anywhere, also in the right half plane of a
stable system.  `harmonic_modes` marks every eigenvalue:

* ``edge`` — the eigenvector carries more than `edge_tol` of its energy
  in the outermost ``max(1, K_i/5)`` harmonic blocks on either side (an
  eigenvector of the untruncated operator decays away from its dominant
  harmonic);
* ``floquet_consistent`` — it equals a Floquet exponent of the system
  (from the monodromy, computed once) modulo ``jω_p`` to `tol`.

For each Floquet exponent the most central consistent eigenvalue gives
the *mode*: its physical exponent ``λ + j n_d ω_p`` with ``n_d`` the
dominant harmonic of the eigenvector (Peters & Lieb's choice of the
physical frequency), frequency, damping ratio, participation factors per
state and per harmonic (``|v_i w_i|`` of the right and left eigenvectors,
normalised), and first-order sensitivities ``dλ = wᴴ 𝒜' v / wᴴ v`` to a
change ``A'(t)`` of the state matrix.
"""

from .harmonic_eig import HarmonicModes, classify
from .harmonic_ss import build
from .._core.coerce import as_ltp
from .._core.validation import check_positive, check_positive_int

__all__ = ['harmonic_modes', 'HarmonicModes']


def harmonic_modes(sys, internal_harmonics=None, *, edge_tol=1e-3, tol=1e-6,
                   floquet_steps=None):
    """Eigenvalues of the harmonic state space, marked, and the system's modes.

    Parameters
    ----------
    sys : LTPStateSpace or control.StateSpace
        Continuous-time system (an LTI system needs a period: use
        ``ltpss(sys, period=...)``).
    internal_harmonics : int, optional
        Truncation ``K_i`` of the harmonic state space (default as in
        `htf` with no output harmonics: 10 for a periodic A).
    edge_tol : float
        Share of an eigenvector's energy in the outermost blocks above
        which its eigenvalue is marked as a truncation-edge eigenvalue.
    tol : float
        Relative distance (to ``max(ω_p, |λ|)``) within which an
        eigenvalue equals a Floquet exponent modulo ``jω_p``.
    floquet_steps : int, optional
        Steps per period of the Floquet computation (see `monodromy`).

    Returns
    -------
    HarmonicModes

    Raises
    ------
    ValueError
        For a discrete-time system (its lifting is exact: use
        ``ct.poles(ltp.lift(sys))``), or when a Floquet exponent has no
        consistent harmonic eigenvalue (increase `internal_harmonics`).

    Examples
    --------
    >>> A = lambda t: np.array([[0.0, 1.0], [-(2 + 3 * np.cos(t)), -0.3]])
    >>> sys = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi)
    >>> modes = ltp.harmonic_modes(sys)
    >>> bool(np.allclose(np.sort_complex(modes.floquet),
    ...                  np.sort_complex(ltp.floquet_exponents(sys)), atol=1e-9))
    True
    """
    sys = as_ltp(sys, 'sys')
    if sys.isdtime():
        raise ValueError("harmonic_modes: sys is discrete-time; its frequency lifting is "
                         "exact: use ct.poles(ltp.lift(sys))")
    edge_tol = check_positive(edge_tol, 'edge_tol')
    tol = check_positive(tol, 'tol')
    if internal_harmonics is not None:
        internal_harmonics = check_positive_int(internal_harmonics, 'internal_harmonics',
                                                minimum=1)
    hss = build(sys, 0, internal_harmonics, 'solve', 'harmonic_modes',
                warn_unstable=False)
    return classify(sys, hss.F, hss.Ki, edge_tol, tol, floquet_steps)[0]
