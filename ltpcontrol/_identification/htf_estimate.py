"""Nonparametric estimation of harmonic transfer functions from data.

Implements the least-squares HTF estimator with curvature regularisation
reviewed in thesis §3.3.3 (Siddiqi's method, eqs. 3.28-3.35).  The output
spectrum of an LTP system obeys (thesis eq. 3.27)

    Y(jω) = Σ_{k=-K..K} G_k(jω) U(jω - jkω_p).

Each record (or segment of a record) is cut to an integer number L of
periods, so that on its DFT grid ``ω_i = 2π i / (L T)`` a shift by ω_p is
exactly L bins.  With the regressor
``φ_r(i) = [U_r(i + KL), ..., U_r(i), ..., U_r(i - KL)]`` the extended
spectra are ``Φ_UU(i) = Σ_r conj(φ_r) φ_rᵀ`` and ``Φ_UY(i) = Σ_r conj(φ_r) Y_r``.
A component ``G_k`` is identifiable at ``ω_i`` only when its shifted input
``U(i - kL)`` is excited: otherwise ``G_k(jω_i) U(jω_i - jkω_p)`` adds nothing
to ``Y(jω_i)``.  Unexcited regressor columns are therefore dropped, and per
frequency ``ĝ_E = Φ_UU,E⁻¹ Φ_UY,E`` over the excited set E(i) (eq. 3.31).
The regularised estimate solves all frequencies jointly (eq. 3.35),

    (blkdiag_i Φ_UU(i) + α s D₂ᵀD₂ ⊗ I) g = [Φ_UY(i)]_i,

where ``D₂`` is the second difference along frequency and ``s``, the mean
diagonal of ``Φ_UU`` over the identified (component, frequency) pairs
(``mean_i tr Φ_UU(i) / P`` for a fully excited design), makes ``α``
independent of the input scale.  ``Φ_UU(i)`` and ``Φ_UY(i)`` hold the
excited columns only, so where its shifted input is not excited a component
is set by the curvature penalty alone.
"""

from dataclasses import dataclass

import warnings

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.sparse as sp
import scipy.stats
from control.exception import ControlDimension
from tqdm.auto import tqdm

from .._frequency.htf import HTFData
from .records import as_records
from .._core.validation import (check_period, check_positive_int,
                          real_array, steps_per_period)

__all__ = ['estimate_htf', 'HTFEstimateInfo']

# Φ_UU condition number above which the per-frequency solve is flagged
_COND_WARN = 1e8
# relative α grid searched by generalised cross-validation
_GCV_GRID = np.logspace(-8, 6, 15)
#: Residual degrees of freedom below which a fit counts as interpolating (GCV undefined).
_GCV_MIN_DOF = 1e-3
# unmodelled-harmonics test: significance level and the smallest noise-variance
# inflation (variance ratio) worth a warning
_HARMONIC_PVALUE = 1e-3
_HARMONIC_RATIO = 1.1


@dataclass(frozen=True)
class HTFEstimateInfo:
    """Diagnostics of `estimate_htf` (``return_info=True``).

    ``success`` and ``message`` follow `scipy.optimize.OptimizeResult`.
    The arrays are indexed like the components of the returned `HTFData`
    (shape (2K+1, ny, nu, F), frequency last) or by its frequencies.

    Attributes
    ----------
    success : bool
        False when the unregularised solve is doubtful: ``Φ_UU`` is
        ill-conditioned at some frequency (the windows do not separate the
        components).
    message : str
        Description of the outcome; it also names detected unmodelled
        harmonics (a shortcoming of the model order, not of the solve).
    identified : ndarray of bool, shape (2K+1, ny, nu, F)
        True where the shifted input ``U(ω - kω_p)`` of input j is excited,
        i.e. where the data determine ``G_k(jω)``.
    cond : ndarray, shape (F,)
        Condition number of ``Φ_UU`` restricted to the identified
        components at each frequency (NaN where none is identified).
    residual : ndarray, shape (ny,)
        Root-mean-square residual ``|Y - Ŷ|`` per output over all equations.
    noise_var : ndarray, shape (ny,)
        Estimated variance of one output DFT coefficient (NaN without
        residual degrees of freedom); when unmodelled harmonics are
        detected, that of the fit with ``G_{±(K+1)}`` modelled.
    alpha : float
        Relative curvature weight used (chosen by GCV for ``alpha='gcv'``).
    dof : float
        Residual degrees of freedom ``n - tr H``.
    gcv : float
        Generalised cross-validation score ``n |Y - Ŷ|² / (n - tr H)²``.
    nrecords : int
        Number of analysed windows R.
    harmonic_test : dict or None
        Test for unmodelled harmonics (`estimate_htf`, Notes):
        ``statistic``, ``pvalue`` and ``variance_ratio`` (noise variance
        without over with ``G_{±(K+1)}``; 0, 1, 1 for an exact fit); None
        when too few windows.

    Examples
    --------
    >>> T = 1.0
    >>> exc = ltp.chirp_replicas(T, 6, 8.0, 0.1, 20.0, dt=0.01)
    >>> y = (1 + np.cos(2 * np.pi * exc.time / T)) * exc.inputs
    >>> _, info = ltp.estimate_htf((exc.time, exc.inputs, y), T, 1,
    ...                            segments=exc.segments, return_info=True)
    >>> info.message, info.nrecords, info.alpha
    ('estimate computed', 6, 0.0)
    """

    success: bool
    message: str
    identified: np.ndarray
    cond: np.ndarray
    residual: np.ndarray
    noise_var: np.ndarray
    alpha: float
    dof: float
    gcv: float
    nrecords: int
    harmonic_test: dict | None


# ---------------------------------------------------------------- data input
def _as_records(data):
    """Return a list of ``(t, u, y, labels)`` with u (nu, nt) and y (ny, nt)."""
    out = []
    for rec in as_records(data, 'data'):
        labels = {} if rec.output_labels is None else {"inputs": list(rec.input_labels),
                                                       "outputs": list(rec.output_labels)}
        out.append((rec.t, rec.u, rec.y, labels))
    return out


def _spectra(records, period, nharmonics, segments):
    """Integer-period DFTs of all windows: U (R, nu, Ns), Y (R, ny, Ns), L, dt."""
    dts = np.array([rec[0][1] - rec[0][0] for rec in records])
    dt = float(dts[0])
    if np.any(np.abs(dts - dt) > 1e-9 * dt):
        raise ValueError(f"all records must share one sample time, got {np.unique(dts)}")
    try:
        nper = steps_per_period(period, dt, "dt")
    except ValueError as exc:
        raise ValueError(
            f"{exc}; the estimator needs an integer number of samples per period "
            "(resample the data, e.g. with scipy.signal.resample, so that "
            "period/dt is an integer)") from None
    nu, ny = records[0][1].shape[0], records[0][2].shape[0]
    for i, (t, u, y, _) in enumerate(records):
        if u.shape[0] != nu or y.shape[0] != ny:
            raise ControlDimension(f"data[{i}] has {u.shape[0]} inputs and {y.shape[0]} "
                                   f"outputs, data[0] has {nu} and {ny}")
    windows = []                                   # (record, start, stop)
    for i, (t, _, _, _) in enumerate(records):
        if segments is None:
            windows.append((i, 0, t.size))
            continue
        for start, stop in segments:
            if not 0 <= start < stop <= t.size:
                raise ValueError(f"segments entry [{start}, {stop}) does not fit "
                                 f"data[{i}] with {t.size} samples")
            windows.append((i, start, stop))
    nperiods = np.array([(stop - start) // nper for _, start, stop in windows])
    if np.any(nperiods < 1):
        raise ValueError(f"a record or segment is shorter than one period "
                         f"({nper} samples of dt={dt}); period={period}")
    L = int(nperiods.min())
    if np.any(nperiods > L):
        warnings.warn(f"windows hold between {L} and {nperiods.max()} periods; all are "
                      f"cut to the common {L} periods (data discarded)",
                      UserWarning, stacklevel=4)
    ns = L * nper
    if ns <= 2 * nharmonics * L:
        raise ValueError(f"nharmonics={nharmonics} needs more than {2 * nharmonics} "
                         f"samples per period, got {nper}")
    omega = 2 * np.pi * np.fft.fftfreq(ns, dt)
    U = np.empty((len(windows), nu, ns), complex)
    Y = np.empty((len(windows), ny, ns), complex)
    for w, (i, start, _) in enumerate(windows):
        t, u, y, _ = records[i]
        # X(ω_i) = dt Σ_n x(t_n) e^{-jω_i t_n}, t_n absolute (phase reference t = 0)
        shift = np.exp(-1j * omega * t[start])
        U[w] = dt * np.fft.fft(u[:, start:start + ns], axis=-1) * shift
        Y[w] = dt * np.fft.fft(y[:, start:start + ns], axis=-1) * shift
    return U, Y, L, dt


def _output_bins(U, L, K, threshold):
    """Output bins m >= 0 and the mask (M, 2K+1, nu) of excited U_j(m - kL)."""
    ns = U.shape[-1]
    power = np.sum(np.abs(U) ** 2, axis=0)                      # (nu, Ns)
    silent = np.nonzero(power.max(axis=1) == 0)[0]
    if silent.size:
        raise ValueError(f"input(s) {silent.tolist()} are identically zero in every "
                         "window; nothing can be estimated for them")
    excited = power >= threshold * power.max(axis=1, keepdims=True)
    m = np.arange(ns // 2 - K * L) if ns // 2 > K * L else np.arange(0)
    k = np.arange(-K, K + 1)
    idx = m[:, None] - k[None, :] * L                           # (M, 2K+1)
    mask = np.transpose(excited[:, idx % ns], (1, 2, 0))        # (M, 2K+1, nu)
    return m, mask, excited


def _regressor(U, bins, L, K):
    """Φ_r(i) rows: (R, F, P) with column (k+K)·nu + j = U_{r,j}(i - kL)."""
    ns = U.shape[-1]
    k = np.arange(-K, K + 1)
    idx = (bins[:, None] - k[None, :] * L) % ns                 # (F, 2K+1)
    phi = U[:, :, idx]                                          # (R, nu, F, 2K+1)
    return np.transpose(phi, (0, 2, 3, 1)).reshape(U.shape[0], bins.size, -1)


# ------------------------------------------------------------- solvers
def _solve_bins(phi, Yb):
    """Per-frequency least squares (3.31): g, trace of the hat matrix, variances.

    ``Φ_UU⁺`` (pseudo-inverse) gives the minimum-norm solution where Φ_UU is
    singular; the caller warns about such frequencies.
    """
    puu = np.einsum('rfa,rfb->fab', phi.conj(), phi)
    puy = np.einsum('rfa,rfo->fao', phi.conj(), Yb)
    pinv = np.linalg.pinv(puu, rcond=1e-13, hermitian=True)
    g = pinv @ puy
    trace = float(np.real(np.einsum('fab,fba->', pinv, puu)))     # Σ_f rank Φ_UU(f)
    var = np.real(np.diagonal(pinv, axis1=1, axis2=2))             # (F, P)
    return g, trace, var


def _penalty(nfreq, nunk):
    """Curvature penalty D₂ᵀD₂ ⊗ I_P for frequency-major stacking (sparse)."""
    d2 = sp.diags([np.ones(nfreq - 2), -2 * np.ones(nfreq - 2), np.ones(nfreq - 2)],
                  [0, 1, 2], shape=(nfreq - 2, nfreq))
    return sp.kron(d2.T @ d2, sp.identity(nunk), format='csc')


def _factor_blocks(phi, puu):
    """Per-bin square roots ``B_f = L_f L_fᴴ`` with min(R, P) columns."""
    nrec, _, nunk = phi.shape
    if nrec <= nunk:
        return np.transpose(phi.conj(), (1, 2, 0))              # (F, P, R)
    lam, vec = np.linalg.eigh(puu)
    return vec * np.sqrt(np.clip(lam, 0, None))[:, None, :]


def _solve_joint(phi, Yb, alpha, penalty, scale, want_var, max_entries=2 ** 22):
    """Regularised joint solve (3.35); returns g, tr H and Var-diagonal or None."""
    nrec, nfreq, nunk = phi.shape
    puu = np.einsum('rfa,rfb->fab', phi.conj(), phi)
    puy = np.einsum('rfa,rfo->fao', phi.conj(), Yb)
    # blkdiag Φ_UU(f): entry (fP + a, fP + b)
    rows = (np.arange(nfreq)[:, None, None] * nunk + np.arange(nunk)[None, :, None])
    rows = np.broadcast_to(rows, puu.shape)
    cols = np.swapaxes(rows, 1, 2)
    blk = sp.coo_matrix((puu.ravel(), (rows.ravel(), cols.ravel())),
                        shape=(nfreq * nunk,) * 2)
    amat = (blk + alpha * scale * penalty).tocoo()
    # banded upper storage ab[u + i - j, j] = A[i, j] (bandwidth u = 3P - 1)
    upper = 3 * nunk - 1
    keep = amat.row <= amat.col
    ab = np.zeros((upper + 1, nfreq * nunk), complex)
    np.add.at(ab, (upper + amat.row[keep] - amat.col[keep], amat.col[keep]),
              amat.data[keep])
    try:
        chol = (scipy.linalg.cholesky_banded(ab), False)
    except np.linalg.LinAlgError:
        raise ValueError("the regularised normal equations are singular: the data "
                         "do not determine the components; increase alpha or the "
                         "excitation") from None

    def solve(rhs):
        return scipy.linalg.cho_solve_banded(chol, rhs)

    g = solve(puy.reshape(nfreq * nunk, -1)).reshape(nfreq, nunk, -1)
    if not want_var:
        # tr H = tr(A⁻¹ B) = Σ_f tr(Z_ff Φ_UU(f)), Z_ff the diagonal blocks of A⁻¹
        Zff = _inverse_diagonal_blocks(amat.tocsr(), nfreq, nunk)
        return g, float(np.real(np.einsum('fab,fba->', Zff, puu))), None
    # tr H = tr(A⁻¹ B) and diag(A⁻¹ B A⁻¹) with B = Σ_f L_f L_fᴴ, column by column
    lf = _factor_blocks(phi, puu)                               # (F, P, c)
    ncol = lf.shape[2]
    per = max(1, max_entries // (nfreq * nunk * ncol))      # bins per dense block
    trace, var = 0.0, np.zeros(nfreq * nunk)
    for f0 in range(0, nfreq, per):
        f1 = min(nfreq, f0 + per)
        rhs = np.zeros((nfreq * nunk, (f1 - f0) * ncol), complex)
        for f in range(f0, f1):
            rhs[f * nunk:(f + 1) * nunk, (f - f0) * ncol:(f - f0 + 1) * ncol] = lf[f]
        x = solve(rhs)
        trace += float(np.real(np.vdot(rhs, x)))
        if want_var:
            var += np.sum(np.abs(x) ** 2, axis=1)
    return g, trace, (var.reshape(nfreq, nunk) if want_var else None)


def _inverse_diagonal_blocks(A, nfreq, nunk):
    """Diagonal P x P blocks of A⁻¹ for the Hermitian positive definite A of (3.35).

    A couples bins f and f ± 2 only, so with super-blocks of two bins it is
    block tridiagonal.  Two sweeps of Schur complements (positive definite,
    hence stable) give the diagonal super-blocks of the inverse,

        L_s = A_ss - A_s,s-1 L_{s-1}⁻¹ A_s-1,s,   R_s = A_ss - A_s,s+1 R_{s+1}⁻¹ A_s+1,s,
        (A⁻¹)_ss = (L_s + R_s - A_ss)⁻¹,

    in O(F P³) instead of the O(F² P) of solving for every column.
    """
    P2 = 2 * nunk
    edges = list(range(0, nfreq * nunk, P2)) + [nfreq * nunk]
    S = len(edges) - 1
    diag = [A[a:b, a:b].toarray() for a, b in zip(edges[:-1], edges[1:])]
    upper = [A[a:b, b:c].toarray() for a, b, c in zip(edges[:-2], edges[1:-1], edges[2:])]
    left, right = [None] * S, [None] * S
    left[0], right[-1] = diag[0], diag[-1]
    for s in range(1, S):
        left[s] = diag[s] - upper[s - 1].conj().T @ np.linalg.solve(left[s - 1], upper[s - 1])
    for s in range(S - 2, -1, -1):
        right[s] = diag[s] - upper[s] @ np.linalg.solve(right[s + 1], upper[s].conj().T)
    blocks = np.empty((nfreq, nunk, nunk), complex)
    for s in range(S):
        Z = np.linalg.inv(left[s] + right[s] - diag[s])
        for j in range(Z.shape[0] // nunk):
            blocks[2 * s + j] = Z[j * nunk:(j + 1) * nunk, j * nunk:(j + 1) * nunk]
    return blocks


def _residual(phi, Yb, g):
    """Squared residual norm per output, Σ_{r,f} |Y_r - φ_rᵀ g|²."""
    e = Yb - np.einsum('rfa,fao->rfo', phi, g)
    return np.sum(np.abs(e) ** 2, axis=(0, 1))


def _gcv_search(phi, Yb, penalty, scale, progress):
    """Relative α minimising GCV(α) = n |Y - Ŷ_α|² / (n - tr H_α)²."""
    n = phi.shape[0] * phi.shape[1]

    def score(log_alpha):
        g, tr, _ = _solve_joint(phi, Yb, 10.0 ** log_alpha, penalty, scale, False)
        # an (almost) interpolating fit leaves n - tr H within rounding of 0: GCV is 0/0
        # there, so such α are not candidates
        if n - tr < _GCV_MIN_DOF:
            return np.inf
        return n * _residual(phi, Yb, g).sum() / (n - tr) ** 2

    logs = np.log10(_GCV_GRID)
    scores = np.array([score(a) for a in tqdm(logs, desc="GCV", leave=False,
                                             disable=(not progress) or None)])
    best = int(np.argmin(scores))
    if best in (0, logs.size - 1):
        warnings.warn(f"GCV minimum at the edge of the searched range "
                      f"(alpha={_GCV_GRID[best]:.1e}); the estimate may be over- or "
                      "under-smoothed", UserWarning, stacklevel=4)
        return float(_GCV_GRID[best])
    res = scipy.optimize.minimize_scalar(score, bounds=(logs[best - 1], logs[best + 1]),
                                         method='bounded', options={'xatol': 0.02})
    return float(10.0 ** (res.x if res.fun <= scores[best] else logs[best]))


def _harmonic_test(U, Y, bins, L, K, excited):
    """F test of the inputs shifted by ±(K+1)ω_p on the per-frequency residual.

    Per frequency the least-squares fit with the components |k| <= K (p₀
    excited columns) is compared with the fit that adds ``G_{±(K+1)}`` (q
    more excited columns), over the frequencies with more windows than
    ``p₀ + q``.  Without unmodelled harmonics and with white noise,
    ``F = ((RSS₀ - RSS₁)/Q) / (RSS₁/N₁) ~ F(2Q, 2N₁)`` (complex data),
    Q and N₁ summed over frequencies and outputs.  Returns None when no
    frequency has enough windows.

    ``noise_var`` (per output) is the residual variance of the extended
    per-frequency fit over every frequency with more windows than its
    excited columns, ``Σ_f RSS₁(f) / Σ_f (R - p₁(f))``: the noise with the
    ``G_{±(K+1)}`` terms modelled and free of any regularisation bias.
    """
    nrec, nu, ns = U.shape
    ks = np.arange(-K - 1, K + 2)
    idx = (bins[:, None] - ks[None, :] * L) % ns                 # (F, 2K+3)
    mask = np.transpose(excited[:, idx], (1, 2, 0)).reshape(bins.size, -1)
    phi = np.transpose(U[:, :, idx], (0, 2, 3, 1)).reshape(nrec, bins.size, -1) * mask
    outer = np.zeros(mask.shape[1], bool)
    outer[:nu], outer[-nu:] = True, True                        # k = ∓(K+1) columns
    p0 = (mask & ~outer).sum(axis=1)
    p1 = mask.sum(axis=1)
    use = (nrec > p1) & (p1 > p0)
    if not np.any(use):
        return None
    fits = nrec > p1                               # extended fit has residual dof
    Yf = np.transpose(Y[:, :, bins[fits]], (0, 2, 1))
    g, _, _ = _solve_bins(phi[:, fits] * mask[fits], Yf)
    noise_var = (np.sum(np.abs(Yf - np.einsum('rfa,fao->rfo', phi[:, fits] * mask[fits], g))
                        ** 2, axis=(0, 1)) / np.sum(nrec - p1[fits]))
    Yb = np.transpose(Y[:, :, bins[use]], (0, 2, 1))
    rss = []
    for cols in (mask[use] & ~outer, mask[use]):
        g, _, _ = _solve_bins(phi[:, use] * cols, Yb)
        rss.append(float(_residual(phi[:, use] * cols, Yb, g).sum()))
    if rss[0] <= 1e-24 * float(np.sum(np.abs(Yb) ** 2)):
        return {"statistic": 0.0, "pvalue": 1.0, "variance_ratio": 1.0,   # exact fit
                "noise_var": noise_var}
    ny = Y.shape[1]
    q = ny * int(np.sum(p1[use] - p0[use]))
    dof0 = ny * int(np.sum(nrec - p0[use]))
    dof1 = ny * int(np.sum(nrec - p1[use]))
    stat = (rss[0] - rss[1]) / q / (rss[1] / dof1)
    return {"statistic": float(stat),
            "pvalue": float(scipy.stats.f.sf(stat, 2 * q, 2 * dof1)),
            "variance_ratio": float((rss[0] / dof0) / (rss[1] / dof1)),
            "noise_var": noise_var}


# ------------------------------------------------------------- the estimator
def _estimate(data, period, nharmonics, segments, alpha, omega_limits, threshold,
              progress):
    """`estimate_htf` in named steps; returns (components, omega, std, labels, info)."""
    period, K, records, segments, alpha, threshold = _check_options(
        data, period, nharmonics, segments, alpha, threshold)
    U, Y, L, dt = _spectra(records, period, K, segments)
    wgrid = 2 * np.pi / (L * period)
    bins, mask, excited = _frequencies(U, L, K, threshold, omega_limits, alpha, wgrid)
    phi, Yb, cols, emask = _design(U, Y, bins, mask, L, K, alpha)
    puu = np.einsum('rfa,rfb->fab', phi.conj(), phi)
    cond, bad = _conditioning(puu, emask, bins, wgrid, alpha)
    if alpha == 0:
        g, trace, var = _solve_bins(phi, Yb)
    else:
        penalty = _penalty(bins.size, int(cols.sum()))
        # s: mean diagonal of Φ_UU over the identified (component, ω) pairs
        scale = float(np.sum(np.real(np.trace(puu, axis1=1, axis2=2)))) / emask.sum()
        if alpha == 'gcv':
            alpha = _gcv_search(phi, Yb, penalty, scale, progress)
        g, trace, var = _solve_joint(phi, Yb, alpha, penalty, scale, True)
    sq = _residual(phi, Yb, g)
    n = phi.shape[0] * bins.size
    dof = n - trace
    has_dof = dof > 1e-6 * n
    noise_var = sq / dof if has_dof else np.full(sq.shape, np.nan)
    test = _harmonic_test(U, Y, bins, L, K, excited)
    flagged = _check_harmonics(test, alpha, K, phi.shape[0], int(mask.sum(axis=1).max()),
                               U.shape[1])
    if flagged:
        # the residual holds Σ_{|k|>K} G_k U(ω - kω_p): std from the noise variance of
        # the fit with G_{±(K+1)} modelled
        noise_var = test["noise_var"]
    comps, std, identified = _assemble(g, var, noise_var, mask, emask, cols, alpha, K,
                                       U.shape[1])
    info = HTFEstimateInfo(
        success=not bad,
        message="; ".join(m for m, on in (
            ("Φ_UU is ill-conditioned at some frequencies", bad),
            ("unmodelled harmonics detected in the residual", flagged)) if on)
        or "estimate computed",
        identified=identified, cond=cond, residual=np.sqrt(sq / n), noise_var=noise_var,
        alpha=float(alpha), dof=float(dof),
        gcv=float(n * sq.sum() / dof ** 2) if has_dof else np.inf,
        nrecords=phi.shape[0], harmonic_test=test)
    labels = next((rec[3] for rec in records if rec[3]), {})
    return comps, bins * wgrid, std, labels, info


def _default_harmonics(data, period, segments, threshold, omega_limits):
    """The default K of `estimate_htf` (the most the windows hold with one more pair
    to test for unmodelled harmonics) and, if not given, the output band it reaches."""
    period = check_period(period)
    records = _as_records(data)
    segments = None if segments is None else np.asarray(segments)
    nwin = len(records) * (1 if segments is None else len(segments))
    nu = records[0][1].shape[0]
    U, _, L, dt = _spectra(records, period, 0, segments)
    nper = int(round(period / dt))
    K = int(min(max((nwin // nu - 3) // 2, 0), (nper - 1) // 2))
    if omega_limits is None:
        power = np.max(np.abs(U[..., :U.shape[-1] // 2 + 1]) ** 2, axis=(0, 1))
        power[0] = 0.0
        excited = np.flatnonzero(power >= float(threshold) * power.max())
        top = (excited.max() if excited.size else 0) * 2 * np.pi / (L * period)
        omega_limits = (0.0, top + K * 2 * np.pi / period)
    return K, omega_limits


def _check_options(data, period, nharmonics, segments, alpha, threshold):
    """Validated period, K, records, segments, alpha and threshold."""
    period = check_period(period)
    K = check_positive_int(nharmonics, "nharmonics", minimum=0)
    records = _as_records(data)
    if segments is not None:
        segments = np.asarray(segments)
        if segments.ndim != 2 or segments.shape[1] != 2 or segments.dtype.kind not in "iu":
            raise ControlDimension(f"segments must be an integer array of shape "
                                   f"(nseg, 2), got {segments.shape} {segments.dtype}")
    threshold = float(real_array(threshold, "threshold", ndim=0))
    if not 0 < threshold < 1:
        raise ValueError(f"threshold must lie in (0, 1), got {threshold}")
    if isinstance(alpha, str):
        if alpha != 'gcv':
            raise ValueError(f"alpha must be a non-negative number or 'gcv', got {alpha!r}")
    else:
        alpha = float(real_array(alpha, "alpha", ndim=0))
        if alpha < 0:
            raise ValueError(f"alpha must be >= 0, got {alpha}")
    return period, K, records, segments, alpha, threshold


def _frequencies(U, L, K, threshold, omega_limits, alpha, wgrid):
    """Output bins estimated, mask (F, P) of excited regressor columns, excited DFT bins.

    Without `omega_limits`: the bins at which every shifted input is excited.
    With them: the bins in the range with some excited shifted input, and
    for α > 0 the contiguous band from the first to the last of them.
    """
    nrec, nu, ns = U.shape
    m, mask, excited = _output_bins(U, L, K, threshold)
    if omega_limits is None:
        ok = mask.all(axis=(1, 2))          # every component identifiable at m
        if not np.any(ok):
            top = np.max(np.nonzero(excited.any(axis=0)[:ns // 2])[0], initial=0) * wgrid
            raise ValueError(
                f"nharmonics={K} is too large for the excited band: no output frequency "
                f"has all shifted inputs ω - kω_p, |k| <= {K}, excited (input excited up "
                f"to {top:.4g} rad/s, 2Kω_p = {2 * K * L * wgrid:.4g} rad/s); "
                "pass omega_limits to estimate each component where its shifted input is "
                "excited, reduce nharmonics, widen the excitation or lower threshold")
    else:
        ok = mask.any(axis=(1, 2))          # some component identifiable at m
        lim = real_array(omega_limits, "omega_limits", ndim=1)
        if lim.size != 2 or not 0 <= lim[0] < lim[1]:
            raise ValueError(f"omega_limits must be (wmin, wmax) with 0 <= wmin < wmax, "
                             f"got {lim}")
        inside = (m * wgrid >= lim[0]) & (m * wgrid <= lim[1])
        m, ok, mask = m[inside], ok[inside], mask[inside]
        if not np.any(ok):
            raise ValueError(
                f"no output frequency in omega_limits has an excited shifted input "
                f"ω - kω_p, |k| <= {K}; change omega_limits, widen the excitation or "
                "lower threshold")
        if not np.all(ok):
            # α > 0 bridges the gaps between the first and last identifiable frequency
            span = np.arange(ok.size)
            inner = (span > np.argmax(ok)) & (span < ok.size - 1 - np.argmax(ok[::-1]))
            nint = 0 if alpha == 0 else int(np.sum(inner & ~ok))
            warnings.warn(f"{np.sum(~ok)} frequencies in omega_limits have all shifted "
                          f"inputs ω - kω_p (|k| <= {K}) unexcited: {np.sum(~ok) - nint} "
                          f"dropped, {nint} interpolated", UserWarning, stacklevel=4)
    if alpha == 0:
        bins, mask = m[ok], mask[ok]
        need = int(mask.sum(axis=(1, 2)).max())
        if nrec < need:
            raise ValueError(
                f"alpha=0 with nharmonics={K} needs at least {need} records or segments "
                f"(the components identifiable at one frequency; at most (2K+1)·nu = "
                f"{(2 * K + 1) * nu}), got {nrec}; use phase-shifted replicas "
                "(chirp_replicas) or alpha > 0 / alpha='gcv'")
    else:
        # contiguous band: bins without any excited shifted input are bridged by the penalty
        first, last = np.nonzero(ok)[0][[0, -1]]
        bins, mask = m[first:last + 1], mask[first:last + 1]
        if bins.size < 3:
            raise ValueError("the curvature penalty needs at least 3 frequencies; "
                             "lengthen the records or widen the band")
    return bins, mask.reshape(bins.size, -1), excited   # column (k+K)·nu + j


def _design(U, Y, bins, mask, L, K, alpha):
    """Regressor φ (R, F, unknowns), outputs (R, F, ny), unknown columns, their mask.

    The unknowns are the components with data somewhere (α = 0), at two
    frequencies or more for α > 0 (the curvature penalty leaves a
    component's affine part free).  An unexcited (component, ω) has no
    data term: its regressor column U(ω - kω_p) is zeroed.
    """
    cols = mask.sum(axis=0) >= (1 if alpha == 0 else 2)
    emask = mask[:, cols]
    phi = _regressor(U, bins, L, K)[:, :, cols] * emask
    Yb = np.transpose(Y[:, :, bins], (0, 2, 1))
    return phi, Yb, cols, emask


def _conditioning(puu, emask, bins, wgrid, alpha):
    """cond of Φ_UU restricted to the identified set E, σ_1 / σ_|E|, per frequency.

    Returns it and whether it makes the unregularised (α = 0) solve doubtful.
    """
    sv = np.linalg.svd(puu, compute_uv=False)
    count = emask.sum(axis=1)
    low = sv[np.arange(bins.size), np.maximum(count, 1) - 1]
    cond = np.divide(sv[:, 0], low, out=np.full(bins.size, np.inf), where=low > 0)
    cond[count == 0] = np.nan
    bad = alpha == 0 and np.max(cond) > _COND_WARN
    if bad:
        need = int(count.max())
        where = bins[cond > _COND_WARN] * wgrid
        warnings.warn(
            f"Φ_UU is ill-conditioned at {where.size} frequencies (cond up to "
            f"{np.max(cond):.2g}, e.g. ω = {where[0]:.4g} rad/s): the records do not "
            f"separate the {need} components identifiable there; use >= {need} "
            "phase-shifted replicas or alpha > 0", UserWarning, stacklevel=4)
    return cond, bool(bad)


def _check_harmonics(test, alpha, K, nrec, need, nu):
    """Warn about unmodelled harmonics, or that they cannot be tested; True if found."""
    if test is not None and (test["pvalue"] < _HARMONIC_PVALUE
                             and test["variance_ratio"] > _HARMONIC_RATIO):
        warnings.warn(
            f"unmodelled harmonics: the inputs shifted by ±{K + 1}ω_p explain the "
            f"residual (F = {test['statistic']:.3g}, p = {test['pvalue']:.2g}), so the "
            f"plant has components G_k with |k| > {K}; std uses the noise variance of "
            f"the fit with G_{{±{K + 1}}} modelled (the residual's is "
            f"{test['variance_ratio']:.3g}× larger where they are excited), and where "
            f"U(ω ∓ {K + 1}ω_p) is excited the estimate may carry their alias; increase "
            f"nharmonics", UserWarning, stacklevel=4)
        return True
    if test is None and alpha == 0:
        warnings.warn(
            f"too few windows to test for unmodelled harmonics ({nrec} windows, "
            f"{need} components per frequency): components G_k with |k| > {K} would "
            f"alias undetected into the estimate (with {nrec} phase-shifted replicas "
            f"G_{K + 1} into G_{K + 1 - nrec} and G_{-K - 1} into G_{nrec - K - 1}); use at "
            f"least {need + 2 * nu + 1} windows to test for them",
            UserWarning, stacklevel=4)
    return False


def _assemble(g, var, noise_var, mask, emask, cols, alpha, K, nu):
    """Components, std and identified mask, shape (2K+1, ny, nu, F).

    Reported: the identified pairs (α = 0); for α > 0 also the penalty's
    bridge across gaps between a component's first and last identified
    frequency, not its linear extrapolation beyond them, which no data
    support.  The rest is NaN.
    """
    nfreq, nunk = mask.shape
    span = np.arange(nfreq)[:, None]
    inner = ((span >= np.argmax(emask, axis=0))
             & (span <= nfreq - 1 - np.argmax(emask[::-1], axis=0)))
    gfull = np.full((nfreq, nunk, noise_var.size), np.nan, complex)
    vfull = np.full((nfreq, nunk), np.nan)
    gfull[:, cols] = np.where((emask if alpha == 0 else inner)[..., None], g, np.nan)
    vfull[:, cols] = np.where(emask, var, np.nan)
    # Var Ĝ_k[o, j](ω_f) = σ_o² · var[f, (k+K)nu + j]
    std = np.sqrt(vfull[None, :, :] * noise_var[:, None, None])  # (ny, F, P)
    std = np.transpose(std.reshape(-1, nfreq, 2 * K + 1, nu), (2, 0, 3, 1))
    comps = np.transpose(gfull.reshape(nfreq, 2 * K + 1, nu, -1), (1, 3, 2, 0))
    identified = np.broadcast_to(
        np.transpose(mask.reshape(nfreq, 2 * K + 1, 1, nu), (1, 2, 3, 0)),
        comps.shape).copy()
    return comps, std, identified


# ------------------------------------------------------------- public API
def estimate_htf(data, period, nharmonics=None, *, segments=None, alpha=0.0,
                 omega_limits=None, threshold=1e-2, progress=False, return_info=False,
                 name=None):
    """Estimate harmonic transfer functions from input-output data.

    Nonparametric least-squares estimate of ``G_k(jω)``, k = -K..K, in
    ``Y(jω) = Σ_k G_k(jω) U(jω - jkω_p)`` (thesis eqs. 3.27-3.35, Siddiqi's
    estimator with curvature regularisation).

    Parameters
    ----------
    data : TimeResponseData, tuple or list
        One or more records: `control.TimeResponseData` objects (each trace
        is a record) or tuples ``(t, u, y)`` with ``u`` of shape (nt,) or
        (nu, nt) and ``y`` of shape (nt,) or (ny, nt).  Time must be
        uniformly sampled with ``period/dt`` an integer; ``t = 0`` is the
        phase reference of the periodic system.
    period : float
        Known period T of the system.
    nharmonics : int, optional
        Number K of harmonics on each side (2K+1 components).  For
        `identify_ltp` with K_m harmonics, at least ``3 K_m + 1`` (every
        output harmonic its model produces), with `omega_limits` reaching
        them.  Default: as many as the windows hold with the test for
        unmodelled harmonics, ``K = (n_w/nu - 3) // 2`` for n_w windows
        (records times segments; ``2K_h + 4`` replicas give ``K_h``), and
        then, without `omega_limits`, the output band ``[0, ω_u + Kω_p]`` up
        to the highest excited input frequency ``ω_u`` shifted by K
        harmonics (every component where its shifted input is excited).
    segments : array_like of int, shape (nseg, 2), optional
        ``[start, stop)`` sample windows applied to every record, e.g. the
        ``segments`` of `chirp_replicas`; default is the whole record.  Each
        window is cut to the largest integer number of periods common to all
        windows.
    alpha : float or 'gcv', optional
        Curvature weight relative to the mean diagonal of ``Φ_UU``.  0
        (default) solves each frequency separately (eq. 3.31) and needs at
        least as many windows as components identified at one frequency
        (``(2K+1)·nu`` when all are); ``alpha > 0`` solves eq. 3.35; ``'gcv'``
        picks α by generalised cross-validation.
    omega_limits : (float, float), optional
        Output frequency range (rad/s): every frequency in it at which at
        least one shifted input ``ω - kω_p``, ``|k| <= K``, is excited (for
        ``alpha > 0`` the band from the first to the last such frequency).
        At each frequency only the components ``G_k`` whose shifted input
        ``U(ω - kω_p)`` is excited are estimated: the others contribute
        nothing to ``Y(jω)`` there.  Use it when the excited band is
        narrower than ``2Kω_p``, so that no frequency excites all shifted
        inputs at once.  Default: the frequencies at which all shifted
        inputs are excited (every component identified).
    threshold : float, optional
        Input power, relative to its maximum, below which a DFT bin counts
        as unexcited (default 1e-2).
    progress : bool, optional
        Show a progress bar during the GCV search (default False).
    return_info : bool, optional
        Also return the diagnostics (`HTFEstimateInfo`).
    name : str, optional
        Name of the returned HTF.

    Returns
    -------
    HTFData
        The components on the estimated grid, with ``std`` (standard
        deviation of each component, NaN where the component is; None when
        the residual has no degrees of freedom, e.g. exactly ``(2K+1)·nu``
        windows).  A component that is not determined at a frequency is
        NaN: with ``alpha=0`` where it is not identified (its shifted input
        ``U(ω - kω_p)`` is not excited), with ``alpha > 0`` outside the range
        from its first to its last identified frequency (inside, the
        curvature penalty bridges unexcited gaps) and everywhere for a
        component identified at fewer than two frequencies.  It multiplies
        an input component that the data did not excite, so `HTF.predict`
        takes it as zero (and warns when the input to predict from does
        excite it); `fit_htf` and `estimate_delays` leave it out.
    info : HTFEstimateInfo
        Only with ``return_info=True``: identified components, conditioning,
        residual, noise variance, α, degrees of freedom, GCV score and the
        test for unmodelled harmonics.

    Warns
    -----
    UserWarning
        Ill-conditioned ``Φ_UU`` with ``alpha=0``; windows of unequal length;
        unexcited frequencies inside `omega_limits`; GCV minimum at the edge
        of the searched range; unmodelled harmonics (see Notes); with
        ``alpha=0``, too few windows to test for them (e.g. the minimum of
        ``2K+1`` replicas for one input), so that harmonics beyond K would
        alias into the estimate undetected (the message names them).

    Notes
    -----
    Output noise is assumed white when estimating ``std``; bins and
    windows are treated as independent.  The penalty acts on the grid
    ``2π/(L T)``, so α depends on the record length.

    *Unmodelled harmonics.*  A plant with components ``G_k``, ``|k| > K``,
    leaves ``Σ_{|k|>K} G_k U(ω - kω_p)`` in the residual, which the
    estimator counts as noise (``std`` too large) or, when the windows do
    not separate them, aliases into the estimate.  The per-frequency
    least-squares fit is therefore repeated with ``G_{±(K+1)}`` added,
    wherever there are enough windows, and an F test on the decrease of
    the residual (``info.harmonic_test``: statistic, p-value and
    the ratio of the two noise-variance estimates) warns when it is
    significant (p < 1e-3) and inflates the noise variance by more than
    10 %.

    Examples
    --------
    A memoryless periodic gain ``y = (1 + cos ω_p t) u`` has
    ``G_0 = 1`` and ``G_{±1} = 1/2``:

    >>> T, dt = 1.0, 0.01
    >>> exc = ltp.chirp_replicas(T, 6, 8.0, 0.1, 20.0, dt=dt)
    >>> y = (1 + np.cos(2 * np.pi * exc.time / T)) * exc.inputs
    >>> H = ltp.estimate_htf((exc.time, exc.inputs, y), T, 1,
    ...                      segments=exc.segments)
    >>> w, G = H.components()
    >>> np.round(G[:, 0, 0, 10].real, 6).tolist()
    [0.5, 1.0, 0.5]

    The diagnostics come with ``return_info=True``:

    >>> H, info = ltp.estimate_htf((exc.time, exc.inputs, y), T, 1,
    ...                            segments=exc.segments, return_info=True)
    >>> info.success, bool(info.identified.all())
    (True, True)
    """
    if nharmonics is None:
        nharmonics, omega_limits = _default_harmonics(data, period, segments, threshold,
                                                      omega_limits)
    comps, omega, std, labels, info = _estimate(
        data, period, nharmonics, segments, alpha, omega_limits, threshold, progress)
    # NaN marks components the data leave undetermined (U(ω - kω_p) not excited);
    # std is None only when the residual has no degrees of freedom
    if np.all(np.isnan(std[info.identified])):
        std = None
    H = HTFData(comps, omega, check_period(period), std=std, name=name,
                inputs=labels.get("inputs"), outputs=labels.get("outputs"))
    return (H, info) if return_info else H
