r"""Frequency-domain maximum-likelihood refinement of Floquet-form LTP models.

Model.  A continuous-time LTP system in Floquet form, ``ẋ = A x + B(t) u``,
``y = C(t) x + D(t) u`` with constant A and trigonometric polynomials
``B(t) = Σ_m B_m e^{jmω_p t}`` (|m| <= K_B), ``C`` (|l| <= K_C), ``D``
(|k| <= K_D), has the HTF components (Conventions page; output frequency ω,
input frequency ``Ω = ω - kω_p``)

    G_k(jω) = Σ_m C_{k-m} (j(Ω + mω_p) I - A)^{-1} B_m + D_k.

In the complex modal coordinates ``x = V q`` of ``A = V Λ V^{-1}`` the
resolvent is diagonal:

    G_k(jω) = Σ_m Σ_i C̃_{k-m}[:, i] B̃_m[i, :] / (j(Ω + mω_p) - λ_i) + D_k,

``B̃_m = V^{-1} B_m``, ``C̃_l = C_l V``.  Complex modes come in conjugate
pairs ``(λ_i, λ̄_i)`` with ``B̃_m[ī] = conj B̃_{-m}[i]``; a real mode has
``B̃_{-m}[i] = conj B̃_m[i]``.

Parametrisation.  The real parameters are the eigenvalues (λ of a real
mode; Re λ, Im λ of a pair), the free real and imaginary parts of ``B̃``,
``C̃`` and ``D``.  A state scaling ``q_i -> d_i q_i`` (d real for a real
mode, complex for a pair) leaves every G_k unchanged; it is fixed by a
pivot: for every mode the largest ``B̃_m[i, j]`` of the starting model (a
real part for a real mode) is held at 1.  The remaining parametrisation is
locally one-to-one for a model with distinct eigenvalues, so its Fisher
information is regular.  The returned model is in the real modal basis
(A block diagonal with blocks ``λ`` and ``[[σ, ω], [-ω, σ]]``).

Likelihood.  The estimate ``Ĝ_k`` is complex Gaussian about ``G_k(θ)``
with ``E|Ĝ - G|² = s²`` (the `HTF.std` of `estimate_htf`), independent over
entries.  The negative log-likelihood is ``Σ |Ĝ - G(θ)|²/s²`` up to a
constant, so the ML estimate is the weighted nonlinear least squares fit
with residuals ``f = √2 [Re e; Im e]/s`` (unit variance each).  Its Fisher
information is ``F = JᵀJ`` (J the Jacobian of f), the Cramér-Rao bound
``F⁻¹``.  Without standard deviations all weights are equal and ``s²`` is
estimated as ``Σ f²/(n - p)`` (p parameters, n real residuals).
"""

import warnings
from dataclasses import dataclass, field

import numpy as np
import control as ct
import scipy.optimize
import scipy.sparse as sp
from control.exception import ControlArgument, ControlDimension

from .floquet_fit import _harmonic_data
from .._frequency.htf import HTF, HTFData
from .._core.ltpsys import LTPStateSpace
from .._core.periodic_matrix import PeriodicMatrix
from .._core.coerce import as_ltp
from .._core.validation import check_positive_int, real_array, steps_per_period

__all__ = ['refine_ltp', 'RefineInfo']

# largest condition number of the eigenvector matrix of A accepted (modal form)
_COND_MODAL = 1e8
# |Im λ| below this fraction of |λ| (or ω_p) counts as a real eigenvalue
_REAL_TOL = 1e-9
# Fisher information condition number above which parameters are unidentifiable
_COND_FISHER = 1e12
# Re λ is kept above -_FAST times the largest frequency of the data
_FAST = 1e4


@dataclass(frozen=True)
class RefineInfo:
    """Diagnostics of `refine_ltp` (``return_info=True``).

    Field names follow `scipy.optimize.OptimizeResult`.

    Attributes
    ----------
    success : bool
        The optimiser met a convergence criterion.
    message : str
        Description of the outcome.
    nfev, njev : int
        Numbers of residual and Jacobian evaluations.
    x : ndarray
        Minimal real parameters θ at the estimate (see `names`).
    cov : ndarray
        Covariance of `x`: the inverse Fisher information, i.e. the
        Cramér-Rao bound evaluated at the estimate (with the estimated
        noise scale when the data carry no standard deviations).
    std : ndarray
        ``sqrt(diag(cov))``.
    fisher : ndarray
        Fisher information of `x`.
    names : list of str
        Parameter names: ``'lambda[i]'`` (real mode), ``'lambda[i].re'``,
        ``'lambda[i].im'`` (pair), ``'B[m][i,j].re'``, ... in complex
        modal coordinates.
    cost : float
        ``½ Σ f²`` at the estimate (weighted residuals, module notes).
    initial_cost : float
        ``½ Σ f²`` of the starting model.
    noise_scale : float
        ``Σ f² / (n - p)``: about 1 when the data's standard deviations are
        right (with std), the estimated ``s²`` (without).
    dof : int
        Residual degrees of freedom ``n - p``.
    exponents : ndarray
        Floquet exponents (eigenvalues of A) of the refined model.
    active : bool
        True when the stability constraint holds some exponent at its bound.
    realize : callable
        ``realize(x)`` is the model at the parameters `x` (same basis and
        labels as the returned one), e.g. for parameters drawn from
        ``N(x, cov)`` to propagate the covariance to a prediction.

    Examples
    --------
    >>> sorted(RefineInfo.__dataclass_fields__)[:4]
    ['active', 'cost', 'cov', 'dof']
    """

    success: bool
    message: str
    nfev: int
    njev: int
    x: np.ndarray = field(repr=False)
    cov: np.ndarray = field(repr=False)
    std: np.ndarray = field(repr=False)
    fisher: np.ndarray = field(repr=False)
    names: list = field(repr=False)
    cost: float
    initial_cost: float
    noise_scale: float
    dof: int
    exponents: np.ndarray
    active: bool
    realize: object = field(default=None, repr=False, compare=False)


class _Realizer:
    """Parameters θ → refined model (picklable; `RefineInfo.realize`)."""

    def __init__(self, par, kinds, period, labels):
        self.par, self.kinds, self.period, self.labels = par, kinds, period, labels

    def __call__(self, x):
        x = real_array(x, 'x', ndim=1)
        if x.size != self.par.theta0.size:
            raise ControlDimension(f"x must have {self.par.theta0.size} parameters, "
                                   f"got {x.size}")
        return _real_modal(*self.par.unpack(x), self.kinds, self.period, **self.labels)


# ------------------------------------------------------------------ data
def _data_points(data, period, ny, nu, std=None):
    """Harmonic index k, input frequency Ω, values (P, ny, nu), std or None, K."""
    if std is not None and not isinstance(data, ct.FrequencyResponseData):
        raise ControlArgument("std applies to lifted frequency-response data; an HTF "
                              "carries its own std")
    if isinstance(data, HTF):
        if not isinstance(data, HTFData):
            raise ControlArgument("data must be a data HTF (from estimate_htf) or lifted "
                                  "frequency-response data, got a model HTF")
        if not np.isclose(data.period, period, rtol=1e-9, atol=0):
            raise ValueError(f"data period {data.period} differs from the model's {period}")
        _, G = data.components()
        std = data.std
        K, F = data.nharmonics, data.omega.size
        k = np.repeat(np.arange(-K, K + 1), F)
        Om = (data.omega[None, :] - np.arange(-K, K + 1)[:, None] * 2 * np.pi / period).ravel()
        vals = np.transpose(G, (0, 3, 1, 2)).reshape(-1, *G.shape[1:3])
        if std is not None:
            std = np.transpose(std, (0, 3, 1, 2)).reshape(vals.shape)
    elif isinstance(data, ct.FrequencyResponseData):
        if not data.dt or data.dt is True or data.noutputs % ny:
            raise ControlArgument(
                "frequency-response data must be the discrete-time real lifted response "
                "of lifted_frequency_response ((2K+1) outputs per model output)")
        H, M = data.noutputs // ny, data.omega.size
        K = (H - 1) // 2
        N = steps_per_period(period, float(data.dt), 'the sampling time of data')
        Gc = _harmonic_data(data.frdata, K, N, ny)                  # (nu, H, ny, M)
        k = np.repeat(np.arange(-K, K + 1), M)
        Om = np.tile(data.omega, H)
        vals = np.transpose(Gc, (1, 3, 2, 0)).reshape(-1, ny, data.ninputs)
        if std is not None:
            # one std per (harmonic, output, line), shared by the inputs, or per input
            std = real_array(std, 'std', ndim=(0, 1, 2, 3, 4))
            shape = (H, ny, data.ninputs, M)
            try:
                std = np.broadcast_to(std[..., None, :] if 1 <= std.ndim <= 3 else std,
                                      shape)
            except ValueError:
                raise ControlDimension(f"std of shape {std.shape} does not broadcast to "
                                       f"(2K+1, ny, nlines) = {(H, ny, M)} or (2K+1, ny, "
                                       f"ninputs, nlines) = {shape}") from None
            std = np.transpose(std, (0, 3, 1, 2)).reshape(vals.shape)
    else:
        raise ControlArgument("data must be an HTF (estimate_htf) or the "
                              "FrequencyResponseData of lifted_frequency_response, got "
                              f"{type(data).__name__}")
    if vals.shape[1:] != (ny, nu):
        raise ControlDimension(f"data have {vals.shape[1]} outputs and {vals.shape[2]} "
                               f"inputs, the model {ny} and {nu}")
    return k, Om, vals, std, K


# ------------------------------------------------------------- modal form
def _modal(A):
    """Eigenvalues and eigenvectors ordered: real modes, then pairs (λ, λ̄)."""
    lam, E = np.linalg.eig(A)
    scale = max(np.abs(lam).max(initial=0.0), 1.0)
    real = np.abs(lam.imag) <= _REAL_TOL * scale
    order, kinds = [], []
    for i in np.nonzero(real)[0][np.argsort(lam[real].real)]:
        v = E[:, i] * np.exp(-1j * np.angle(E[np.argmax(np.abs(E[:, i])), i]))
        order.append((lam[i].real + 0j, v.real.astype(complex)))
        kinds.append('r')
    upper = np.nonzero(~real & (lam.imag > 0))[0]
    for i in upper[np.argsort(lam[upper].imag)]:
        order += [(lam[i], E[:, i]), (np.conj(lam[i]), np.conj(E[:, i]))]
        kinds += ['c', 'c̄']
    if len(order) != A.shape[0]:
        raise ValueError("A has complex eigenvalues without conjugate partners")
    lam = np.array([o[0] for o in order])
    V = np.stack([o[1] for o in order], axis=1)
    gap = np.abs(lam[:, None] - lam[None, :]) + np.diag(np.full(lam.size, np.inf))
    if lam.size > 1 and gap.min() <= 1e-8 * scale:
        raise ValueError("A has repeated eigenvalues: the modal parametrisation needs "
                         "distinct eigenvalues")
    if np.linalg.cond(V) > _COND_MODAL:
        raise ValueError("A is (nearly) defective: its eigenvector matrix has condition "
                         f"number {np.linalg.cond(V):.2g}; the modal parametrisation needs "
                         "distinct eigenvalues")
    return lam, V, kinds


def _normalise(Bt, Ct, kinds):
    """Scale every mode so that its pivot coefficient of B̃ equals 1 (in place)."""
    for i, kind in enumerate(kinds):
        if kind == 'r':
            h, q, part = _real_pivot(Bt[:, i, :])
            K = Bt.shape[0] // 2
            s = getattr(Bt[K + h, i, q], 'real' if part == 're' else 'imag')
            Bt[:, i, :] /= s
            Ct[:, :, i] *= s
        elif kind == 'c':
            m, q = np.unravel_index(np.argmax(np.abs(Bt[:, i, :])), Bt[:, i, :].shape)
            s = Bt[m, i, q]
            Bt[:, i, :] /= s
            Ct[:, :, i] *= s
            Bt[:, i + 1, :] /= np.conj(s)
            Ct[:, :, i + 1] *= np.conj(s)


def _real_pivot(row):
    """Pivot ``(h, q, part)`` of a real mode's B̃ row (2K+1, nu): largest real parameter."""
    K = row.shape[0] // 2
    best, piv = -1.0, None
    for h in range(K + 1):
        for q in range(row.shape[1]):
            for part, val in (('re', row[K + h, q].real), ('im', row[K + h, q].imag)):
                if (h or part == 're') and abs(val) > best:
                    best, piv = abs(val), (h, q, part)
    return piv


class _Parametrisation:
    """Affine map ``v = M θ + v_c`` from real parameters to complex coefficients.

    ``v = [λ (n), B̃ (2K_B+1, n, nu), C̃ (2K_C+1, ny, n), D (2K_D+1, ny, nu)]``
    of a model normalised by `_normalise`; the pivots are held at 1.
    """

    def __init__(self, lam, Bt, Ct, D, kinds, fit_a, fit_d):
        self.shapes = [lam.shape, Bt.shape, Ct.shape, D.shape]
        self.offsets = np.concatenate([[0], np.cumsum([int(np.prod(s))
                                                       for s in self.shapes])])
        v0 = np.concatenate([lam, Bt.ravel(), Ct.ravel(), D.ravel()])
        self.vc = np.zeros(v0.size, complex)
        rows, cols, vals, names, theta = [], [], [], [], []
        self.decay = []                       # parameters that are Re λ
        KB, KC, KD = Bt.shape[0] // 2, Ct.shape[0] // 2, D.shape[0] // 2

        def index(block, *idx):
            return self.offsets[block] + np.ravel_multi_index(idx, self.shapes[block])

        def add(name, entries, free=True):
            """One real parameter entering v[i] with coefficient c for (i, c) in entries."""
            value = (v0[entries[0][0]] / entries[0][1]).real
            if not free:
                for i, c in entries:
                    self.vc[i] += c * value
                return
            for i, c in entries:
                rows.append(i)
                cols.append(len(theta))
                vals.append(c)
            names.append(name)
            theta.append(value)

        def conj_family(block, K, combos, label, pivot=None):
            """P_h, h = -K..K, with P_{-h} = conj P_h, for each index tuple in combos."""
            for h in range(K + 1):
                for rest in combos:
                    ip, im = index(block, K + h, *rest), index(block, K - h, *rest)
                    add(f"{label}[{h}][{rest[0]},{rest[1]}].re",
                        [(ip, 1.0)] + ([(im, 1.0)] if h else []),
                        free=pivot != (h, rest, 're'))
                    if h:
                        add(f"{label}[{h}][{rest[0]},{rest[1]}].im", [(ip, 1j), (im, -1j)],
                            free=pivot != (h, rest, 'im'))

        def pair_family(block, K, combos, partner, label, pivot=None):
            """Free complex P_h, h = -K..K, of mode i; its partner holds conj P_{-h}."""
            for h in range(2 * K + 1):
                for rest, prest in zip(combos, partner):
                    a, b = index(block, h, *rest), index(block, 2 * K - h, *prest)
                    fixed = pivot == (h, rest)
                    add(f"{label}[{h - K}][{rest[0]},{rest[1]}].re", [(a, 1.0), (b, 1.0)],
                        free=not fixed)
                    add(f"{label}[{h - K}][{rest[0]},{rest[1]}].im", [(a, 1j), (b, -1j)],
                        free=not fixed)

        nu, ny = Bt.shape[2], Ct.shape[1]
        for i, kind in enumerate(kinds):
            brow = [(i, q) for q in range(nu)]
            ccol = [(o, i) for o in range(ny)]
            if kind == 'r':
                if fit_a:
                    self.decay.append(len(theta))
                add(f"lambda[{i}]", [(index(0, i), 1.0)], free=fit_a)
                h, q, part = _real_pivot(Bt[:, i, :])
                conj_family(1, KB, brow, 'B', pivot=(h, (i, q), part))
                conj_family(2, KC, ccol, 'C')
            elif kind == 'c':
                if fit_a:
                    self.decay.append(len(theta))
                j = i + 1
                add(f"lambda[{i}].re", [(index(0, i), 1.0), (index(0, j), 1.0)], free=fit_a)
                add(f"lambda[{i}].im", [(index(0, i), 1j), (index(0, j), -1j)], free=fit_a)
                m, q = np.unravel_index(np.argmax(np.abs(Bt[:, i, :])), Bt[:, i, :].shape)
                pair_family(1, KB, brow, [(j, q) for q in range(nu)], 'B',
                            pivot=(m, (i, q)))
                pair_family(2, KC, ccol, [(o, j) for o in range(ny)], 'C')
        if fit_d:
            conj_family(3, KD, [(o, q) for o in range(ny) for q in range(nu)], 'D')
        else:
            self.vc[self.offsets[3]:] = D.ravel()
        self.names, self.theta0 = names, np.array(theta)
        self.M = sp.csr_matrix((np.array(vals, complex), (rows, cols)),
                               shape=(v0.size, len(theta)))

    def unpack(self, theta):
        """(λ, B̃, C̃, D) at the real parameters `theta`."""
        v = self.M @ theta + self.vc
        return [v[a:b].reshape(s) for a, b, s in
                zip(self.offsets[:-1], self.offsets[1:], self.shapes)]


# --------------------------------------------------------------- the model
def _response(lam, Bt, Ct, D, k, Om, wp, jac=False):
    """G_k at the points (k, Ω), shape (P, ny, nu); with `jac` also dG/dv (P·ny·nu, nv)."""
    KB, KC, KD = Bt.shape[0] // 2, Ct.shape[0] // 2, D.shape[0] // 2
    P, (ny, nu) = k.size, D.shape[1:]
    mb = np.arange(-KB, KB + 1)
    r = 1.0 / (1j * (Om[:, None, None] + mb[None, :, None] * wp) - lam)   # (P, m, i)
    ell = k[:, None] - mb[None, :]                                        # C index k - m
    valid = np.abs(ell) <= KC
    Csel = np.where(valid[..., None, None], Ct[np.clip(ell + KC, 0, 2 * KC)], 0)
    X = r[..., None] * Bt[None]                                           # r_i B̃_m[i, :]
    G = np.einsum('pmoi,pmij->poj', Csel, X)
    dk = np.abs(k) <= KD
    G[dk] += D[k[dk] + KD]
    if not jac:
        return G
    CR = Csel * r[:, :, None, :]
    J_lam = np.einsum('pmoi,pmij->poji', CR, X)                    # d r/dλ = r²
    J_B = np.einsum('pmoi,jq->pojmiq', CR, np.eye(nu))
    Xl = np.zeros((P, 2 * KC + 1) + X.shape[2:], complex)          # Σ_{m: k-m=l} X_m
    for a in range(mb.size):
        ok = np.nonzero(valid[:, a])[0]
        Xl[ok, ell[ok, a] + KC] += X[ok, a]
    J_C = np.einsum('plij,oq->pojlqi', Xl, np.eye(ny))
    J_D = np.zeros((P, ny, nu, 2 * KD + 1, ny, nu), complex)
    p = np.nonzero(dk)[0]
    for o in range(ny):
        for j in range(nu):
            J_D[p, o, j, k[p] + KD, o, j] = 1.0
    J = np.concatenate([a.reshape(P * ny * nu, -1) for a in (J_lam, J_B, J_C, J_D)], axis=1)
    return G, J


def _real_modal(lam, Bt, Ct, D, kinds, period, **kwargs):
    """Real LTPStateSpace in the real modal basis ``x = W q`` (module notes)."""
    W = np.eye(lam.size, dtype=complex)
    for i, kind in enumerate(kinds):
        if kind == 'c':
            W[i:i + 2, i:i + 2] = [[1, 1], [1j, -1j]]
    Winv = np.linalg.inv(W)
    A = (W * lam) @ Winv
    return LTPStateSpace(A.real, PeriodicMatrix(W @ Bt, period),
                         PeriodicMatrix(Ct @ Winv, period), PeriodicMatrix(D, period),
                         period, **kwargs)


def _harmonics(harmonics, sys, K):
    """Harmonic counts (K_B, K_C, K_D) of the refined model."""
    if harmonics is None:
        own = [M.nharmonics for M in (sys.B, sys.C, sys.D)]
        return tuple(d if h is None else h for h, d in zip(own, (K, 2 * K, K)))
    if np.ndim(harmonics) == 0:
        harmonics = (harmonics,) * 3
    if len(harmonics) != 3:
        raise ValueError(f"harmonics must be an int or (K_B, K_C, K_D), got {harmonics!r}")
    return tuple(check_positive_int(h, 'harmonics', minimum=0) for h in harmonics)


def refine_ltp(sys, data, *, std=None, harmonics=None, weighted=True, stable=False, refine_a=True,
               estimate_d=None, maxiter=200, tol=1e-10, return_info=False, name=None):
    r"""Maximum-likelihood refinement of a Floquet-form LTP model on frequency data.

    Fits a continuous-time LTP system in Floquet form (constant A,
    periodic B, C, D given by their Fourier coefficients) to an HTF
    estimate by weighted nonlinear least squares, the periodic counterpart
    of refining a subspace model by a prediction-error method.  With the
    standard deviations of `estimate_htf` as weights this is the maximum
    likelihood estimate under its Gaussian error model, and the inverse
    Fisher information is the parameter covariance.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous-time starting model with constant A (the Floquet form
        returned by `identify_ltp`, or `floquet_transform` of any model);
        A must have distinct eigenvalues.
    data : HTF or control.FrequencyResponseData
        A data HTF (`estimate_htf`): all components ``G_k(jω)`` that are not
        NaN are fitted, weighted by ``1/std`` when the HTF carries `std`.
        Or the real lifted response of `lifted_frequency_response` (as for
        `identify_ltp`, one column per input), weighted by `std` when given.
    std : array_like, optional
        Lifted frequency-response data only: standard deviations of the
        complex harmonic responses ``G_n(jΩ)`` (which the real lifted
        coordinates share), broadcastable to ``(2K+1, ny, nlines)`` (the
        same for every input; e.g. one value per line) or to ``(2K+1, ny,
        ninputs, nlines)``.
    harmonics : int or (int, int, int), optional
        Numbers ``(K_B, K_C, K_D)`` of harmonics of B, C and D in the
        refined model.  Default: those of `sys` (for matrices given as
        functions, ``(K, 2K, K)`` with K the data's harmonics).
    weighted : bool, optional
        Weight by ``1/std`` of the data (default True).  False, or data
        without `std`, fits with equal weights and estimates the noise
        scale from the residual.
    stable : bool or float, optional
        Constrain the Floquet exponents: False (default) no constraint,
        True ``Re λ < 0``, a float δ >= 0 ``Re λ <= -δ`` (a minimum decay
        rate).  In the modal parametrisation this bounds the real parts of
        the eigenvalues of A.
    refine_a : bool, optional
        Refine A (default True); False keeps the eigenvalues of `sys`.
    estimate_d : bool, optional
        Fit the feedthrough D (default: when `sys` has a non-zero D).
    maxiter : int, optional
        Largest number of residual evaluations (default 200); 0 evaluates
        the Fisher information of `sys` itself (e.g. the Cramér-Rao bound
        of the true system).
    tol : float, optional
        Relative tolerance on the cost, step and gradient (default 1e-10).
    return_info : bool, optional
        Also return a `RefineInfo`.
    name : str, optional
        Name of the refined system (default that of `sys`).

    Returns
    -------
    sys : LTPStateSpace
        The refined model in the real modal basis (A block diagonal).
    info : RefineInfo
        Only with ``return_info=True``: parameters, covariance, Fisher
        information, cost, optimiser status.

    Raises
    ------
    ControlArgument
        If `sys` is not a continuous-time LTPStateSpace or `data` has the
        wrong type.
    ControlDimension
        If the data and the model have different numbers of inputs or
        outputs.
    ValueError
        If A is not constant or has repeated (defective) eigenvalues, the
        periods differ, the data's standard deviations are not positive
        where components are given, or the stability constraint is
        infeasible (``refine_a=False`` with exponents outside the bound).

    Warns
    -----
    UserWarning
        When the stability constraint is active at the solution (the data
        favour a less stable model; the covariance ignores the bound), the
        Fisher information is singular (unidentifiable parameters), or the
        weighted residual is much larger than the data's standard
        deviations predict (model structure too poor or std too small).

    Notes
    -----
    See the module notes of ``ltpcontrol._identification.refine`` and the Identification
    with noise guide for the model, the minimal parametrisation (modal A,
    one pivot of B per mode held at 1) and the likelihood.  The Cramér-Rao
    bound at the true system is ``info.cov`` of ``refine_ltp(true_sys,
    data, maxiter=0, return_info=True)`` in the same parametrisation (same
    pivots).

    Examples
    --------
    A first-order system with a modulated input gain, its HTF estimated
    from five chirp replicas with output noise; the refinement starts from
    a perturbed model:

    >>> T = 1.0
    >>> true = ltp.ltpss([[-2.0]], ltp.PeriodicMatrix([[[0.25j]], [[1.0]], [[-0.25j]]], T),
    ...                  [[1.0]], 0, period=T)
    >>> exc = ltp.chirp_replicas(T, 6, 20.0, 0.0, 3.0, dt=0.01, gap=10.0)
    >>> y = ltp.forced_response(true, exc.time, exc.inputs).outputs
    >>> y = y + 1e-3 * np.random.default_rng(0).standard_normal(y.size)
    >>> H = ltp.estimate_htf((exc.time, exc.inputs, y), T, 1, segments=exc.segments)
    >>> start = ltp.ltpss([[-1.5]], ltp.PeriodicMatrix([[[0.3j]], [[1.2]], [[-0.3j]]], T),
    ...                   [[1.0]], 0, period=T)
    >>> model, info = ltp.refine_ltp(start, H, return_info=True)
    >>> bool(abs(model.A(0)[0, 0] + 2) < 4 * info.std[0])
    True
    >>> info.success, info.names[0]
    (True, 'lambda[0]')
    """
    if as_ltp(sys).isdtime():
        raise ControlArgument("sys must be a continuous-time LTPStateSpace, got a "
                              "discrete-time one")
    if sys.nstates == 0:
        raise ValueError("sys has no states: nothing to refine")
    Asamp = sys.A.sample(8)
    if np.max(np.abs(Asamp - Asamp[0])) > 1e-12 * max(1.0, np.abs(Asamp).max()):
        raise ValueError("refine_ltp needs the Floquet form (constant A); transform the "
                         "model with floquet_transform first")
    for flag, what in ((weighted, 'weighted'), (refine_a, 'refine_a')):
        if not isinstance(flag, (bool, np.bool_)):
            raise ControlArgument(f"{what} must be True or False, got {flag!r}")
    maxiter = check_positive_int(maxiter, 'maxiter', minimum=0)
    tol = float(real_array(tol, 'tol', ndim=0))
    if not 0 < tol < 1:
        raise ValueError(f"tol must lie in (0, 1), got {tol}")
    if isinstance(stable, (bool, np.bool_)):
        decay = 0.0 if stable else None
    else:
        decay = float(real_array(stable, 'stable', ndim=0))
        if decay < 0:
            raise ValueError(f"stable must be True, False or a decay rate >= 0, got {decay}")
    period, wp = sys.period, 2 * np.pi / sys.period
    k, Om, vals, std, K = _data_points(data, period, sys.noutputs, sys.ninputs, std)
    KB, KC, KD = _harmonics(harmonics, sys, K)
    if estimate_d is None:
        estimate_d = bool(np.any(sys.D.fourier(KD) != 0))

    # starting point in normalised complex modal coordinates
    lam, V, kinds = _modal(Asamp[0])
    Vinv = np.linalg.inv(V)
    Bt = Vinv @ sys.B.fourier(KB)
    Ct = sys.C.fourier(KC) @ V
    _normalise(Bt, Ct, kinds)
    par = _Parametrisation(lam, Bt, Ct, sys.D.fourier(KD), kinds, refine_a, estimate_d)

    # only the points (k, Ω) with some known entry enter the model evaluations
    given = np.isfinite(vals).any(axis=(1, 2))
    k, Om, vals = k[given], Om[given], vals[given]
    std = None if std is None else std[given]
    mask = np.isfinite(vals)
    if weighted and std is not None:
        bad = mask & ~(np.isfinite(std) & (std > 0))
        if np.any(bad):
            raise ValueError(f"data std must be positive and finite wherever a component "
                             f"is given ({int(bad.sum())} entries are not)")
        weight = np.sqrt(2) / np.where(mask, std, 1.0)
    else:
        weight = np.full(vals.shape, np.sqrt(2))
    known = weighted and std is not None
    rows = np.nonzero(mask.ravel())[0]
    target, weight = vals.ravel()[rows], weight.ravel()[rows]
    n, p = 2 * rows.size, par.theta0.size
    if n <= p:
        raise ValueError(f"{rows.size} complex data values cannot determine {p} real "
                         "parameters; use more frequencies or fewer harmonics")

    def residual(theta, jac=False):
        out = _response(*par.unpack(theta), k, Om, wp, jac=jac)
        G, J = out if jac else (out, None)
        e = (G.ravel()[rows] - target) * weight
        f = np.concatenate([e.real, e.imag])
        if not jac:
            return f
        Jz = (J[rows] @ par.M) * weight[:, None]
        return f, np.vstack([Jz.real, Jz.imag])

    # a mode much faster than the data is a feedthrough: bound Re λ from below
    lower = np.full(p, -np.inf)
    lower[par.decay] = -_FAST * max(np.abs(Om).max() + (KB + 1) * wp, np.abs(lam).max())
    upper = np.full(p, np.inf)
    theta0 = par.theta0.copy()
    if decay is not None:
        bound = -decay if decay > 0 else -1e-9 * wp
        if not refine_a:
            if np.any(lam.real > bound):
                raise ValueError(
                    f"the stability constraint is infeasible: refine_a=False keeps A, whose "
                    f"exponents have real parts up to {lam.real.max():.4g} > {bound:.4g}; "
                    "allow refine_a=True or relax stable")
        else:
            upper[par.decay] = bound
            theta0[par.decay] = np.minimum(theta0[par.decay], bound * (1 + 1e-3) - 1e-6 * wp)
    theta0 = np.maximum(theta0, lower * (1 - 1e-3))
    f0 = residual(theta0)
    if maxiter == 0:
        theta, nfev, njev, success, message = theta0, 1, 1, True, "evaluated, not refined"
    else:
        res = scipy.optimize.least_squares(
            lambda th: residual(th), theta0, jac=lambda th: residual(th, True)[1],
            bounds=(lower, upper), method='trf', x_scale='jac', xtol=tol, ftol=tol,
            gtol=tol, max_nfev=maxiter)
        theta, nfev, njev = res.x, int(res.nfev), int(res.njev)
        success, message = bool(res.status > 0), str(res.message)
    f, J = residual(theta, True)
    dof = n - p
    # floor: data fitted to rounding (noise-free) must not make J^T J / s² overflow
    floor = (np.finfo(float).eps * max(np.linalg.norm(target * weight), 1.0)) ** 2 / n
    scale = max(float(f @ f) / dof, floor)
    fisher = J.T @ J / (1.0 if known else scale)
    w_eig, U = np.linalg.eigh(fisher)
    if w_eig[0] <= w_eig[-1] / _COND_FISHER:
        # the condition number in logs: the ratio itself can overflow
        cond = (f"1e{np.log10(w_eig[-1]) - np.log10(w_eig[0]):.0f}" if w_eig[0] > 0
                else "infinite")
        warnings.warn(f"the Fisher information is singular (condition {cond}): "
                      "some parameters are not determined by the data; the covariance is "
                      "a pseudo-inverse", UserWarning, stacklevel=2)
    cov = (U / np.where(w_eig > w_eig[-1] / _COND_FISHER, w_eig, np.inf)) @ U.T
    if known and scale > 4:
        warnings.warn(f"the weighted residual is {scale:.3g} times its expected value: the "
                      "model structure (states, harmonics) does not explain the data or their "
                      "std is too small; the covariance is optimistic", UserWarning,
                      stacklevel=2)
    active = bool(decay is not None and refine_a
                  and np.any(theta[par.decay] >= upper[par.decay] - 1e-6 * wp))
    if active:
        warnings.warn("the stability constraint is active at the solution: the data favour "
                      "a less stable model; the covariance ignores the bound", UserWarning,
                      stacklevel=2)
    realize = _Realizer(par, kinds, period, dict(name=sys.name if name is None else name,
                                                 inputs=sys.input_labels,
                                                 outputs=sys.output_labels))
    model = realize(theta)
    if not return_info:
        return model
    info = RefineInfo(success=success, message=message, nfev=nfev, njev=njev, x=theta,
                      cov=cov, std=np.sqrt(np.diag(cov)), fisher=fisher, names=par.names,
                      cost=0.5 * float(f @ f), initial_cost=0.5 * float(f0 @ f0),
                      noise_scale=scale, dof=dof, exponents=par.unpack(theta)[0],
                      active=active, realize=realize)
    return model, info
