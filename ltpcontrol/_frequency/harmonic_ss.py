"""Harmonic state space of an LTP system: construction, evaluation, real form.

The truncated HTF (Conventions page) is evaluated from a harmonic state
space ``(F, G, H, J)`` with ``H(x) = H (xI - F)^{-1} G + J``:

* continuous time, ``F = 𝒜 - 𝒩`` with Toeplitz blocks ``(𝒜)_{n,m} = A_{n-m}``
  truncated at ``K_i >= K`` harmonics, ``𝒩 = blkdiag(jnω_p I)``, and the
  central 2K+1 block rows of 𝒞 and columns of ℬ;
* discrete time (N steps per period), the exact frequency lifting
  ``F = Λ^{-1}𝒜``, ``G = Λ^{-1}ℬ`` over all N harmonics, built by the lifting
  module (`lift`) so that both share one construction.

F is diagonalised once when that pays off (in Floquet form it is block
diagonal, so one eigendecomposition of A suffices), after which each
frequency costs a diagonal solve.  `harmonic_ss` returns the real form
``V_y^H H(s) V_u`` (real basis of the lifting module: columns ``c_0 = e_0``,
``c_n = (e_n + e_{-n})/√2``, ``s_n = j(e_n − e_{-n})/√2``), in which every
matrix is real since the Fourier coefficients of a real matrix are
conjugate-symmetric and ``V^H 𝒩 V`` is the real rotation generator.
"""

import warnings

import numpy as np
import control as ct
import scipy.linalg as sla
from scipy import sparse
from scipy.linalg.lapack import zgbsv
from tqdm.auto import tqdm

from .. import config
from .._core.lifting import _frequency_lift, _full_harmonics, _harmonic_labels, _real_basis
from .harmonic_eig import classify
from .._core.coerce import as_ltp
from .._core.floquet import floquet_exponents
from .._core.validation import check_positive_int

__all__ = ['harmonic_ss']


def harmonic_ss(sys, nharmonics, *, internal_harmonics=None, edge='warn', name=None):
    """Real harmonic state space of a continuous-time LTP system.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous-time LTP system (discrete time: use `lift`, whose
        frequency lifting is the exact discrete harmonic state space).
    nharmonics : int
        Harmonics -K..K of the inputs and outputs.
    internal_harmonics : int, optional
        Truncation ``K_i >= K`` of the states (default as in `htf`).
    edge : {'warn', 'ignore', 'drop'}
        What to do with the truncation-edge eigenvalues of a periodic A:
        'warn' (default) marks them in ``modes`` and warns when eigenvalues
        in the closed right half plane are not Floquet exponents of `sys`;
        'ignore' only marks them; 'drop' returns the state space without
        their modal part (exact modal truncation, see Notes).
    name : str, optional
        Name of the result (default: the name of `sys` with '$harmonic').

    Returns
    -------
    control.StateSpace
        ``(2K_i+1) n`` states, ``(2K+1) m`` inputs and ``(2K+1) p`` outputs,
        harmonic-major, named ``'<label>_c<n>'`` and ``'<label>_s<n>'`` (see
        the module notes); its frequency response at s is
        ``V_y^H H(s) V_u`` with H the truncated HTF.  Its attribute
        ``modes`` is the `HarmonicModes` of its state matrix (as from
        `harmonic_modes` with the same `internal_harmonics`):
        ``modes.eigenvalues`` are its poles (``ct.poles``, up to order and
        rounding), ``modes.edge`` marks the truncation-edge eigenvalues,
        ``modes.floquet_consistent`` those equal to a Floquet exponent
        modulo ``jω_p``, and ``modes.exponents`` are the system's modes.
        The attribute is not carried over by operations on the result.
        With ``edge='drop'`` the result has the states of the kept modes
        (named ``'x[i]'``) and ``modes`` still describes the full
        truncation.

    Raises
    ------
    ValueError
        If `sys` is discrete-time, or `edge` is not 'warn', 'ignore' or
        'drop'.

    Warns
    -----
    UserWarning
        With ``edge='warn'``, naming the right-half-plane eigenvalues that
        are not Floquet exponents; Floquet exponents the truncation does
        not resolve; when `sys` is unstable; when the truncation of the
        response has not converged; with ``edge='drop'``, when the dropped
        modes change the response by more than 1e-6 (relative).

    Notes
    -----
    For a periodic A the state matrix is truncated: besides shifted copies
    ``λ - jkω_p`` of the Floquet exponents, its eigenvalues include
    truncation-edge artefacts (eigenvectors reaching the outermost
    harmonics), which may lie in the right half plane of a stable system:
    the poles of the result and LTI stability verdicts on them
    (``ct.poles``, ``is_stable`` of a feedback built on it) do not decide
    the stability of `sys`; `floquet_exponents` and `nyquist_htf` do.  The
    marks cost one eigendecomposition of the state matrix and one Floquet
    computation; a constant A has no artefact.

    ``edge='drop'`` orders the real Schur form of the state matrix with the
    kept eigenvalues first, ``[[T11, T12], [0, T22]]``, decouples the two
    blocks exactly by the solution X of ``T11 X - X T22 + T12 = 0`` and
    returns ``(T11, B1 - X B2, C1, D)`` in these coordinates: its poles are
    exactly the unmarked eigenvalues, and its response differs from the
    truncated HTF by the dropped modes' part, which is checked at two
    frequencies (for the Mathieu example below, about 1e-10 relative).

    Examples
    --------
    The HTF of an LTI system has the diagonal blocks ``G(s + jnω_p)``; the
    cosine channel of harmonic 0 is G itself:

    >>> G = ct.tf([1], [1, 1])
    >>> Hs = ltp.harmonic_ss(ltp.ltpss(G, period=1.0), 2)
    >>> Hs.ninputs, Hs.input_labels[:3]
    (5, ['u[0]_c0', 'u[0]_c1', 'u[0]_s1'])
    >>> bool(np.isclose(Hs(0.5j)[0, 0], G(0.5j)))
    True

    A stable Mathieu system: the right-half-plane poles of its truncation
    are marked as edge artefacts (and warned about unless ``edge='ignore'``):

    >>> A = lambda t: np.array([[0.0, 1.0], [-(2 + 3 * np.cos(t)), -0.3]])
    >>> sys = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi)
    >>> Hs = ltp.harmonic_ss(sys, 1, edge='ignore')
    >>> rhp = Hs.modes.eigenvalues.real > 0
    >>> bool(rhp.any()), bool(Hs.modes.edge[rhp].all()), Hs.modes.stable
    (True, True, True)

    Dropping them leaves the shifted copies of the Floquet exponents only:

    >>> Hd = ltp.harmonic_ss(sys, 1, edge='drop')
    >>> Hd.nstates, float(np.round(ct.poles(Hd).real.max(), 8))
    (26, -0.15)
    """
    sys = as_ltp(sys, 'sys')
    if sys.isdtime():
        raise ValueError("harmonic_ss: sys is discrete-time; lift(sys) is its exact "
                         "(frequency-lifted) harmonic state space")
    K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
    if edge not in ('warn', 'ignore', 'drop'):
        raise ValueError(f"edge must be 'warn', 'ignore' or 'drop', got {edge!r}")
    hss = build(sys, K, internal_harmonics, 'auto', 'harmonic_ss', warn_unstable=False)
    return marked_ss(sys, hss, edge, name, stacklevel=3)


def marked_ss(sys, hss, edge, name, stacklevel=3):
    """Real form of `hss` with its truncation-edge eigenvalues marked in ``.modes``
    (warned about or dropped as `edge` says); shared by `harmonic_ss` and
    `HTFModel.to_ss`.  `stacklevel` counts the frames from here to the user's
    call (3 from a public function that calls this one).

    Examples
    --------
    >>> from ltpcontrol._frequency.harmonic_ss import build, marked_ss
    >>> sys = ltp.ltpss(ct.ss([[-1.0]], [[1.0]], [[1.0]], 0), period=1.0)
    >>> Hs = marked_ss(sys, build(sys, 1, None, 'auto', 'x'), 'warn', None)
    >>> Hs.nstates, Hs.modes.stable
    (3, True)
    """
    if edge not in ('warn', 'ignore', 'drop'):
        raise ValueError(f"edge must be 'warn', 'ignore' or 'drop', got {edge!r}")
    # the Floquet exponents once: for the stability remark and the marks
    fl = floquet_exponents(sys) if sys.nstates else np.zeros(0, complex)
    fl = np.atleast_1d(np.asarray(fl, complex))
    if np.any(np.abs(np.exp(fl * (2 * np.pi / sys.omega_p))) >= 1 - 1e-10):
        _warn_unstable(sys, stacklevel)
    modes, missing = classify(sys, hss.F, hss.Ki, floquet=fl, strict=False,
                              where='harmonic_ss')
    if edge != 'ignore':
        _warn_edge(modes, missing, hss.Ki, rhp=edge == 'warn', stacklevel=stacklevel + 1)
    out = real_ss(hss, name or f'{sys.name}$harmonic', sys.input_labels,
                  sys.output_labels, sys.state_labels)
    if edge == 'drop' and modes.edge.any():
        out = _drop_edge(out, modes, sys.omega_p, stacklevel + 1)
    out.modes = modes
    return out


def _drop_edge(Hs, modes, wp, stacklevel=3):
    """Exact modal truncation of the marked eigenvalues of the real form `Hs`."""
    lam, keep = modes.eigenvalues, ~modes.edge

    def kept(re, im=None):
        z = re if im is None else re + 1j * im
        return bool(keep[np.argmin(np.abs(lam - z))])

    T, Z, k = sla.schur(Hs.A, output='real', sort=kept)
    if k != np.count_nonzero(keep):   # the marks split a conjugate pair: cannot happen
        raise RuntimeError("harmonic_ss: the ordered Schur form does not separate "
                           "the marked eigenvalues")   # pragma: no cover
    X = sla.solve_sylvester(T[:k, :k], -T[k:, k:], -T[:k, k:])
    ZB, CZ = Z.T @ Hs.B, Hs.C @ Z
    out = ct.ss(T[:k, :k], ZB[:k] - X @ ZB[k:], CZ[:, :k], Hs.D, name=Hs.name,
                inputs=Hs.input_labels, outputs=Hs.output_labels)
    # the dropped part of the response, at two frequencies inside the band
    n = Hs.nstates
    err = 0.0
    for s in 1j * wp * np.array([0.137, 0.61]):
        full = Hs.C @ np.linalg.solve(s * np.eye(n) - Hs.A, Hs.B) + Hs.D
        red = out.C @ np.linalg.solve(s * np.eye(k) - out.A, out.B) + out.D
        err = max(err, np.abs(full - red).max() / max(np.abs(full).max(), 1e-300))
    if err > 1e-6:
        warnings.warn(f"harmonic_ss: dropping the {n - k} truncation-edge modes changes the "
                      f"response by {err:.1e} (relative); increase internal_harmonics",
                      UserWarning, stacklevel=stacklevel)
    return out


def _warn_unstable(sys, stacklevel):
    warnings.warn(f"{sys.name} is unstable: its HTF is defined wherever the harmonic "
                  "resolvent exists, but on the imaginary axis it describes no "
                  "steady-state response", UserWarning, stacklevel=stacklevel + 1)


def _warn_edge(modes, missing, Ki, rhp=True, stacklevel=3):
    """Warn about right-half-plane eigenvalues that are no Floquet exponents."""
    lam = modes.eigenvalues
    # with the marked ones dropped, only the unmarked ones remain to be named
    bad = (lam.real >= 0) & ~modes.floquet_consistent & (rhp | ~modes.edge)
    msgs = []
    if bad.any():
        order = np.argsort(-lam[bad].real)
        shown = ", ".join(f"{z:.4g}" for z in lam[bad][order][:6])
        more = f" and {bad.sum() - 6} more" if bad.sum() > 6 else ""
        msgs.append(
            f"{int(bad.sum())} eigenvalues of the truncated harmonic state matrix in the "
            f"closed right half plane are not Floquet exponents of the system "
            f"({int(np.count_nonzero(bad & modes.edge))} of them marked at the truncation "
            f"edge): {shown}{more}; they are artefacts of the truncation at "
            f"internal_harmonics={Ki} (marked in .modes)")
    if missing.size:
        msgs.append("the Floquet exponents " + ", ".join(f"{z:.4g}" for z in missing)
                    + f" have no eigenvalue of the truncation at internal_harmonics={Ki}; "
                    "increase internal_harmonics")
    if msgs:
        warnings.warn("harmonic_ss: " + "; ".join(msgs) + ". Judge stability by "
                      "ltp.floquet_exponents(sys) or ltp.harmonic_modes(sys), not by "
                      "ct.poles of the harmonic state space (edge='ignore' silences this)",
                      UserWarning, stacklevel=stacklevel)


def build(sys, K, internal_harmonics, method, where, stacklevel=2, warn_unstable=True):
    """The checked harmonic state space of `sys` with K harmonics.

    `stacklevel` is that of the user's call as seen from the caller of `build`;
    `warn_unstable=False` skips the stability remark (and its Floquet
    computation) for callers to whom an unstable system is no misuse.

    Examples
    --------
    >>> from ltpcontrol._frequency.harmonic_ss import build
    >>> sys = ltp.ltpss(ct.tf([1], [1, 1]), period=1.0)
    >>> hss = build(sys, 2, None, 'auto', 'harmonic_ss')
    >>> hss.K, hss.F.shape                      # harmonics -2..2 of one state
    (2, (5, 5))
    >>> build(sys, 2, None, 'fast', 'harmonic_ss')
    Traceback (most recent call last):
    ...
    ValueError: method must be 'auto', 'modal' or 'solve', got 'fast'
    """
    if method not in ('auto', 'modal', 'solve'):
        raise ValueError(f"method must be 'auto', 'modal' or 'solve', got {method!r}")
    if warn_unstable and not sys.is_stable():
        _warn_unstable(sys, stacklevel + 1)
    if sys.isdtime():
        N = sys.nsteps
        if 2 * K + 1 > N:
            raise ValueError(f"nharmonics={K} exceeds the {N} harmonics of a discrete "
                             f"system with {N} steps per period (need 2K+1 <= N)")
        _check_setup_memory(N * sys.nstates, 0, where)
        return _HarmonicStateSpace.discrete(sys, K, method)
    Ki = _internal_order(sys, K, internal_harmonics)
    checked = internal_harmonics is None and not sys.A.is_constant
    _check_setup_memory((2 * Ki + 1) * sys.nstates,
                        (2 * Ki + 17) * sys.nstates if checked else 0, where)
    hss = _HarmonicStateSpace.continuous(sys, K, Ki, method)
    if internal_harmonics is None and not hss.exact:
        _check_truncation(sys, K, Ki, hss, method, stacklevel + 2)
    return hss


def real_ss(hss, name, inputs, outputs, states):
    """Real form ``V^H (F, G, H, J) V`` of a continuous harmonic state space.

    Examples
    --------
    >>> from ltpcontrol._frequency.harmonic_ss import build, real_ss
    >>> G = ct.tf([1], [1, 1])
    >>> sys = ltp.ltpss(G, period=1.0)
    >>> Hs = real_ss(build(sys, 2, None, 'auto', 'harmonic_ss'), 'H',
    ...              sys.input_labels, sys.output_labels, sys.state_labels)
    >>> Hs.input_labels[:3], bool(np.isclose(Hs(0.5j)[0, 0], G(0.5j)))
    (['u[0]_c0', 'u[0]_c1', 'u[0]_s1'], True)
    """
    K, Ki = hss.K, hss.Ki
    n = hss.F.shape[0] // (2 * Ki + 1)
    Vs, tags_s = _real_basis(np.arange(-Ki, Ki + 1), 2 * Ki + 2)   # no wrap-around
    Vio, tags = _real_basis(np.arange(-K, K + 1), 2 * K + 2)
    Vx = np.kron(Vs, np.eye(n))
    Vu, Vy = np.kron(Vio, np.eye(hss.nu)), np.kron(Vio, np.eye(hss.ny))
    mats = (Vx.conj().T @ hss.F @ Vx, Vx.conj().T @ hss.G @ Vu,
            Vy.conj().T @ hss.Hc @ Vx, Vy.conj().T @ hss.J @ Vu)
    scale = max(1.0, max(np.abs(M).max(initial=0.0) for M in mats))
    assert max(np.abs(M.imag).max(initial=0.0) for M in mats) <= 1e-10 * scale
    return ct.ss(*(M.real for M in mats), name=name,
                 inputs=_harmonic_labels(inputs, tags),
                 outputs=_harmonic_labels(outputs, tags),
                 states=_harmonic_labels(states, tags_s))


class _HarmonicStateSpace:
    """``H(x) = Hc (xI - F)^{-1} G + J`` with the central 2K+1 block rows/cols."""

    def __init__(self, F, G, Hc, J, K, Ki, ny, nu, method, exact, floquet_A=None,
                 band=None):
        self.F, self.G, self.Hc, self.J = F, G, Hc, J
        self.K, self.Ki, self.ny, self.nu = K, Ki, ny, nu
        self.exact = exact
        self.modal = None
        self._schur = None
        self._residues = {}
        # block-banded F (A(t) with few harmonics): (l, u) and -F in band storage
        self.band = None
        if band is not None and method in ('auto', 'solve'):
            self.band = (band, band, _band_storage(-F, band, band))
        # (no states: a static gain J, nothing to diagonalise)
        if floquet_A is not None and floquet_A[0].size and method in ('auto', 'modal'):
            # Floquet form: F = blkdiag(A - jnω_p I) has eigenvalues λ_i - jnω_p
            # and eigenvectors blkdiag(W) from ONE eigendecomposition A = W Λ W^{-1}
            A, w = floquet_A
            lamA, W = np.linalg.eig(A)
            if method == 'modal' or np.linalg.cond(W) < 1e8:
                n, nb = A.shape[0], F.shape[0] // A.shape[0]
                harm = np.arange(nb) - nb // 2
                lam = (lamA[None, :] - 1j * w * harm[:, None]).ravel()
                Winv = np.linalg.inv(W)
                HV = (Hc.reshape(Hc.shape[0], nb, n) @ W).reshape(Hc.shape[0], -1)
                VG = (Winv @ G.reshape(nb, n, -1)).reshape(nb * n, -1)
                self.modal = (lam, HV, VG)
        self.method = method

    def _ensure_modal(self, npoints):
        """Diagonalise F once when it pays off (or when asked to)."""
        if self.modal is not None or self.method == 'solve':
            return
        if self.method == 'auto' and (npoints < _MODAL_BREAK_EVEN or self.band is not None):
            # a few dense solves are cheaper than eig(F); banded solves, O(n_F b^2)
            # each, are cheaper than its O(n_F^3) for any number of points
            return
        lam, V = np.linalg.eig(self.F)
        if self.method == 'modal' or np.linalg.cond(V) < 1e8:
            Vinv = np.linalg.solve(V, np.eye(len(lam)))
            self.modal = (lam, self.Hc @ V, Vinv @ self.G)
        else:
            self.method = 'solve'   # ill-conditioned eigenvectors: stay with solves

    @classmethod
    def continuous(cls, sys, K, Ki, method):
        n, ny, nu = sys.nstates, sys.noutputs, sys.ninputs
        w = sys.omega_p
        harm = np.arange(-Ki, Ki + 1)
        A_T = _toeplitz(sys.A.fourier(2 * Ki), Ki)
        B_T = _toeplitz(sys.B.fourier(2 * Ki), Ki)
        C_T = _toeplitz(sys.C.fourier(2 * Ki), Ki)
        D_T = _toeplitz(sys.D.fourier(2 * Ki), Ki)
        # F = A_T - N,  N = blkdiag(jnω_p I)
        F = A_T
        F[np.diag_indices_from(F)] -= 1j * w * np.repeat(harm, n)
        rows = _central(Ki, K, ny)
        cols = _central(Ki, K, nu)
        exact = sys.A.is_constant and _bandlimited(sys, Ki - K)
        floquet_A = (sys.A(0.0), w) if sys.A.is_constant else None
        hA = sys.A.nharmonics
        band = None
        if not sys.A.is_constant and hA is not None:
            b = (min(hA, 2 * Ki) + 1) * n - 1          # element bandwidth of 𝒜
            if F.shape[0] >= _BAND_MIN and 3 * b + 1 <= F.shape[0] / 4:
                band = b
        return cls(F, B_T[:, cols], C_T[rows], D_T[np.ix_(rows, cols)], K, Ki, ny, nu,
                   method, exact, floquet_A, band)

    @classmethod
    def discrete(cls, sys, K, method):
        N, ny, nu = sys.nsteps, sys.noutputs, sys.ninputs
        # exact: all N harmonics, the frequency lifting (zΛ - 𝒜)^{-1} = (zI - Λ^{-1}𝒜)^{-1} Λ^{-1}
        harm = _full_harmonics(N)
        mats = (sys.A, sys.B, sys.C, sys.D)
        F, G, C_T, D_T = _frequency_lift([M.sample(N) for M in mats], harm,
                                         [M.is_constant for M in mats])
        k0 = N // 2                                  # position of harmonic 0
        rows, cols = _central(k0, K, ny), _central(k0, K, nu)
        return cls(F, G[:, cols], C_T[rows], D_T[np.ix_(rows, cols)], K, None, ny, nu,
                   method, True)

    def evaluate(self, x, rows=None, cols=None, progress=None):
        """H(x) for points x; `rows`/`cols` select block harmonics (-K..K).

        The points are processed in chunks whose working memory stays
        within ``ltp.config.defaults['htf.max_memory']``.
        """
        K, ny, nu = self.K, self.ny, self.nu
        r = np.arange(self.Hc.shape[0]) if rows is None else np.concatenate(
            [np.arange((k + K) * ny, (k + K + 1) * ny) for k in rows])
        c = np.arange(self.G.shape[1]) if cols is None else np.concatenate(
            [np.arange((k + K) * nu, (k + K + 1) * nu) for k in cols])
        self._ensure_modal(len(x))
        chunk, use_residues = self._plan(len(x), len(r), len(c))
        J = self.J[np.ix_(r, c)]
        out = np.empty((len(x), len(r), len(c)), complex)
        starts = range(0, len(x), chunk)
        for a in tqdm(starts, desc="HTF", unit="chunk", leave=False,
                      disable=not config._get('htf.progress', progress) or len(starts) < 2):
            sl = slice(a, a + chunk)
            if self.modal is not None:
                out[sl] = self._modal_chunk(x[sl], r, c, rows, cols, use_residues)
            elif self.band is not None:
                out[sl] = self._banded_chunk(x[sl], r, c)
            else:
                out[sl] = self._solve_chunk(x[sl], r, c)
            if J.any():
                out[sl] += J
        return out

    def _plan(self, npoints, nr, nc):
        """Chunk length and modal variant that keep the working memory in budget."""
        budget = float(config.defaults['htf.max_memory'])
        nF = self.F.shape[0]
        out_bytes = _BYTES * npoints * nr * nc
        use_residues = False
        if self.modal is not None:
            # residue matrix R_{q,(ij)} = HV_iq VG_qj, formed once, when it fits
            use_residues = _BYTES * nF * nr * nc <= budget / 2
            fixed = _BYTES * nF * nr * nc if use_residues else 0
            per_point = _BYTES * (2 * nF + 2 * nr * nc + (0 if use_residues else nr * nF))
        elif self.band is not None:
            fixed = 0
            rows_ab = self.band[2].shape[0] + self.band[0]
            per_point = _BYTES * (rows_ab * nF + 2 * nF * nc + 2 * nr * nc)
        else:
            # Schur form, its transformed inputs/outputs and one shifted copy
            fixed = _BYTES * (2 * nF ** 2 + nF * (nr + nc))
            per_point = _BYTES * (2 * nF * min(nr, nc) + 2 * nr * nc)
        room = budget - fixed - out_bytes
        if room < per_point:
            raise MemoryError(
                f"evaluating the HTF at {npoints} points needs about "
                f"{_size(fixed + out_bytes + per_point)} (result {_size(out_bytes)}, "
                f"harmonic state space of {nF} states), more than "
                f"ltp.config.defaults['htf.max_memory'] = {_size(budget)}; evaluate fewer "
                "points or components, or raise the limit")
        return max(1, int(room // per_point)), use_residues

    def _modal_chunk(self, x, r, c, rows, cols, use_residues):
        # H(x)_{ij} = Σ_q HV_iq VG_qj / (x - λ_q)
        lam, HV, VG = self.modal
        gap = x[:, None] - lam[None, :]
        if np.any(np.abs(gap) <= 1e-13 * np.maximum(1.0, np.abs(lam))):
            raise ValueError("the HTF is not defined at a Floquet exponent "
                             "(evaluation point is a pole)")
        inv_gap = 1.0 / gap
        if not use_residues:
            return (HV[r][None] * inv_gap[:, None, :]) @ VG[:, c]
        key = (None if rows is None else tuple(rows), None if cols is None else tuple(cols))
        if key not in self._residues:
            self._residues[key] = _residue_matrix(HV[r], VG[:, c])
        flat, shape = self._residues[key]
        prod = (flat.T @ inv_gap.T).T if sparse.issparse(flat) else inv_gap @ flat
        return prod.reshape((len(x),) + shape)

    def _banded_chunk(self, x, r, c):
        # (xI - F) X = G by banded LU (LAPACK gbsv): O(n_F b^2 + n_F b n_c) per point
        l, u, ab = self.band
        Gc = np.asfortranarray(self.G[:, c])
        Hr = self.Hc[r]
        work = np.zeros((2 * l + u + 1, ab.shape[1]), complex, order='F')
        out = np.empty((len(x), len(r), len(c)), complex)
        for i, xi in enumerate(x):
            work[:l] = 0
            work[l:] = ab
            work[l + u] += xi
            _, _, X, info = zgbsv(l, u, work, Gc.copy(order='F'), overwrite_ab=1,
                                  overwrite_b=1)
            if info > 0:
                raise ValueError("the HTF is not defined at a pole of the harmonic "
                                 "state space (singular resolvent)")
            out[i] = Hr @ X
        return out

    def _solve_chunk(self, x, r, c):
        # dense path: the complex Schur form F = Z T Zᴴ once, then per point one
        # triangular solve of (xI - T) with the fewer of the requested rows (from
        # the left) or columns (from the right): O(nF²) per point, O(nF²) memory
        if self._schur is None:
            T, Z = sla.schur(np.asarray(self.F, complex), output='complex')
            self._schur = (T, Z.conj().T @ self.G, self.Hc @ Z)
        T, ZG, HZ = self._schur
        idx = np.arange(T.shape[0])
        left = len(r) < len(c)
        rhs = HZ[r].T if left else ZG[:, c]
        out = np.empty((len(x), len(r), len(c)), complex)
        a = np.empty_like(T)
        for p, xp in enumerate(x):
            np.negative(T, out=a)
            a[idx, idx] += xp
            try:
                if not np.all(a[idx, idx]):
                    raise np.linalg.LinAlgError
                sol = sla.solve_triangular(a, rhs, trans='T' if left else 'N',
                                           check_finite=False)
            except np.linalg.LinAlgError:
                raise ValueError("the HTF is not defined at a pole of the harmonic "
                                 "state space (singular resolvent)") from None
            out[p] = sol.T @ ZG[:, c] if left else HZ[r] @ sol
        return out


#
# Helpers
#

_BYTES = 16                 # one complex128
# eig(F) costs about as much as 25-35 dense resolvent solves of the same size
# (measured for 100 to 800 harmonic states), plus the inverse eigenvectors
_MODAL_BREAK_EVEN = 40
# banded solves for harmonic state spaces of at least this many states
_BAND_MIN = 64


def _band_storage(M, l, u):
    """LAPACK band storage ``ab[u + i - j, j] = M[i, j]`` of a banded matrix.

    Examples
    --------
    >>> from ltpcontrol._frequency.harmonic_ss import _band_storage
    >>> _band_storage(np.array([[1.0, 2.0, 0.0], [3.0, 4.0, 5.0], [0.0, 6.0, 7.0]]), 1, 1)
    array([[0., 2., 5.],
           [1., 4., 7.],
           [3., 6., 0.]])
    """
    n = M.shape[0]
    ab = np.zeros((l + u + 1, n), M.dtype)
    for k in range(-l, u + 1):
        d = np.diagonal(M, k)
        if k >= 0:
            ab[u - k, k:] = d
        else:
            ab[u - k, :n + k] = d
    return ab


def _size(nbytes):
    return f"{nbytes / 1e9:.3g} GB" if nbytes >= 1e8 else f"{nbytes / 1e6:.3g} MB"


def _check_setup_memory(nF, nF_check, where):
    """Refuse a harmonic state space whose construction cannot fit the budget."""
    # F, its Toeplitz parts and eigenvectors V, V^{-1} (6 nF^2); the
    # truncation check builds one more of nF_check states (3 nF_check^2)
    need = _BYTES * (6 * nF ** 2 + 3 * nF_check ** 2)
    budget = float(config.defaults['htf.max_memory'])
    if need > budget:
        raise MemoryError(
            f"{where}: the harmonic state space has {nF} states and needs about "
            f"{_size(need)}, more than ltp.config.defaults['htf.max_memory'] = "
            f"{_size(budget)}; lower nharmonics or internal_harmonics, or raise the limit")


def _residue_matrix(HV, VG):
    """Residues ``R_{q,(ij)} = HV_iq VG_qj`` of the modal form, sparse when mostly zero.

    In Floquet form with band-limited B and C most residues vanish, and the
    evaluation ``H(x) = (1/(x - λ)) R`` is then a sparse product.
    """
    flat = (HV.T[:, :, None] * VG[:, None, :]).reshape(HV.shape[1], -1)
    big = np.abs(flat) > 1e-15 * np.abs(flat).max(initial=0.0)
    if np.count_nonzero(big) < 0.2 * flat.size:
        flat = sparse.csr_matrix(np.where(big, flat, 0))
    return flat, (HV.shape[0], VG.shape[1])


def _toeplitz(coeffs, Ki):
    """Block Toeplitz ``[P_{n-m}]``, n, m = -Ki..Ki, from coefficients -2Ki..2Ki."""
    harm = np.arange(-Ki, Ki + 1)
    idx = harm[:, None] - harm[None, :] + 2 * Ki
    blocks = coeffs[idx]                          # (2Ki+1, 2Ki+1, r, c)
    r, c = coeffs.shape[1:]
    return blocks.transpose(0, 2, 1, 3).reshape((2 * Ki + 1) * r, (2 * Ki + 1) * c)


def _central(center, K, size):
    """Indices of the blocks -K..K when harmonic 0 is block `center`."""
    return np.arange((center - K) * size, (center + K + 1) * size)


def _bandlimited(sys, margin):
    """True when B, C, D have exact Fourier series with at most `margin` harmonics."""
    for M in (sys.B, sys.C, sys.D):
        if M.nharmonics is None or M.nharmonics > margin:
            return False
    return sys.B.nharmonics + sys.C.nharmonics <= margin


def _internal_order(sys, K, internal):
    if internal is not None:
        Ki = check_positive_int(internal, 'internal_harmonics', minimum=0)
        if Ki < K:
            raise ValueError(f"internal_harmonics={Ki} must be >= nharmonics={K}")
        return Ki
    hb = [M.nharmonics for M in (sys.B, sys.C)]
    if sys.A.is_constant and None not in hb:
        return K + hb[0] + hb[1]
    return K + 10 + max(h if h is not None else 0 for h in hb)


def _check_truncation(sys, K, Ki, hss, method, stacklevel):
    probe = 1j * sys.omega_p * np.array([0.137, 0.61, 1.93])
    ref = _HarmonicStateSpace.continuous(sys, K, Ki + 8, method)
    try:
        a, b = hss.evaluate(probe), ref.evaluate(probe)
    except ValueError:
        return
    err = np.abs(a - b).max() / max(np.abs(b).max(), 1e-300)
    if err > 1e-6:
        warnings.warn(f"HTF truncation at internal_harmonics={Ki} has not converged "
                      f"(relative change {err:.1e} with {Ki + 8}); increase "
                      "internal_harmonics", UserWarning, stacklevel=stacklevel)


