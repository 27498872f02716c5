"""Floquet-form LTP realization of an identified lifted LTI model.

Thesis Sections 4.2.7-4.2.8 with the corrections of the research notes
(``thesis-errata.md`` items 5-7).  A discrete-time LTP in Floquet form
``x[k+1] = A_F x[k] + B[k] u[k]``, ``y[k] = C[k] x[k] + D[k] u[k]`` lifted
with harmonics n = -K..K (``ltpcontrol.lift``) has, in complex harmonic
coordinates (``w = e^{j2π/N}``),

    𝒜 = blkdiag(w^{-n} A_F),   ℬ_{n,m} = w^{-n} B_{(n-m) mod N},
    𝒞_{n,m} = C_{(n-m) mod N},  𝒟_{n,m} = D_{(n-m) mod N},

and in the real coordinates of ``lift`` the matrices ``V^H (.) V``.  An
identified model ``(Â, B̂, Ĉ, D̂)`` equals that real model up to an unknown
real similarity T: ``Ã = T^{-1} Â T``, ``B̃ = T^{-1} B̂``, ``C̃ = Ĉ T``
(eq. 4.101).  With the blocks ``Ã_{nm}``, ``B̃_{nm}``, ``C̃_{nm}`` of
``V Ã V^H``, ``V B̃ V_u^H``, ``V_y C̃ V^H`` the structure is measured by
(eqs. 4.105-4.112 corrected)

    Ā = (1/(2K+1)) Σ_n w^{n} Ã_{nn}                        (4.106, item 5)
    d_A = ‖Im Ā‖² + Σ_n ‖w^{n} Ã_{nn} - Re Ā‖² + Σ_{n≠m} ‖Ã_{nm}‖²  (4.107, item 6)
    d_B = ‖Im B̃_{00}‖² + Σ_{n≠0} ‖(B̃_{n0} - conj B̃_{-n,0})/2‖²    (4.108)
          [+ Σ ‖w^{n} B̃_{nm} - B̄_{(n-m) mod N}‖² with all input harmonics]
    d_C = Σ ‖C̃_{nm} - C̄_{(n-m) mod N}‖²                     (4.109-4.112, item 7)

where ``B̄_l``, ``C̄_l`` average a whole (wrapped) block diagonal.  The
corrected distance divides d_A by ``Σ|λ(Â)|²`` (invariant under T; dividing
by ``‖Ã‖²`` lets an ill-conditioned T shrink the ratio) and d_B, d_C by
``‖B̃‖², ‖C̃‖²`` so that it is invariant to ``T -> cT`` (otherwise
shrinking T drives d_C to zero).  Because a distance minimised over T can
still exploit ill-conditioned T, success also requires the T-independent
fit of the realization's lifted model to the given one.
The literal distance uses ``Σ_k Ã_kk e^{-j2kπ/N}`` (k = 1..2K+1), omits
the per-block diagonal error and is not normalised; its C term is the
corrected one, since the printed (4.110) divides by zero at n = 2K.  It
does not vanish at the true structure: there ``Ã_kk = w^{-(k-K-1)} A_F``
and the printed factors leave ``Ā = (1/(2K+1)) Σ_k w^{-(2k-K-1)} A_F``,
which is not real, so it is offered to reproduce the thesis, not to certify.

The realization is read from the transformed model: ``A_F = Re Ā``,
``B_l``, ``C_l``, ``D_l`` the diagonal averages, ``B[k] = Σ_l B_l w^{lk}``.

Method 'direct' finds T without search.  The eigenvalues of Â are the
ladders ``μ_i w^{-n}`` (thesis eq. 4.91), found by optimal matching of
the eigenvalues to the ideal ladders of candidate centres (`_ladders`); in the modal coordinates
``q = Ŵ^{-1} x̂`` the identified output matrix is ``Ĉ_{r,(n,i)} = d_{n,i}
γ_{r-n,i}`` (``γ_{l,i} = C_l W_i``) with unknown eigenvector scales, so
consecutive ratios follow from ``Ĉ_{r+1,(n+1,i)} = (d_{n+1,i}/d_{n,i})
Ĉ_{r,(n,i)}`` and, with all input harmonics, ``w^{n+1} B̂_{(n+1,i),m+1}
d_{n+1,i} = w^{n} B̂_{(n,i),m} d_{n,i}``.  Method 'pso' is the thesis's
particle swarm over the real entries of T, refined by Nelder-Mead.
"""

import numbers
import warnings
from dataclasses import dataclass, field

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension
from scipy.optimize import linear_sum_assignment, minimize
from tqdm.auto import tqdm

from .._core.lifting import _real_basis, lift
from .._core.ltpsys import LTPStateSpace, ltpss
from .._core.validation import check_period, check_positive, check_positive_int

__all__ = ['floquet_realization', 'FloquetRealization']

# Cost returned for (nearly) singular similarity candidates during the search.
_SINGULAR_COST = 1e6
_SINGULAR_COND = 1e8


@dataclass
class FloquetRealization:
    """Diagnostics of `floquet_realization` with ``return_info=True``.

    Attributes
    ----------
    success : bool
        True when the corrected distance is at most `tol` and the lifted
        model of `sys` reproduces the given model within `fit_tol` (and,
        for 'direct', the eigenvalues form ladders).
    message : str
        Description of the outcome.
    distance : float
        Distance d = d_A + d_B + d_C of the chosen kind (module notes).
    terms : dict
        The terms ``{'A': d_A, 'B': d_B, 'C': d_C}`` of `distance`.
    corrected_distance : float
        The normalised corrected distance, which decides `success`.
    fit_error : float
        ``max_z ‖G(z) - Ĝ(z)‖_F / max_z ‖Ĝ(z)‖_F`` over 64 points of the
        unit circle, Ĝ the given model and G the lifted model of `sys`;
        unlike the distance it does not depend on T.
    transform : ndarray or None
        Real similarity T with ``x̂ = T x̃``: ``T^{-1} Â T`` is the real
        lifted model of `sys`.
    method : str
        'direct' or 'pso'.
    nfev : int
        Number of distance evaluations (0 for 'direct').
    ladder_mismatch : float or None
        'direct' only: largest distance of a ladder member from its ideal
        place ``μ w^{-n}``, in ladder steps ``2|μ| sin(π/N)``, weighted by
        the member's contribution to the response relative to the largest
        of its ladder (weakly excited outer members count little).

    Examples
    --------
    >>> sysd = ltp.ltpss([[0.5]], [[1.0]], [[1.0]], 0, period=1.0, dt=0.25)
    >>> _, res = floquet_realization(ltp.lift(sysd, nharmonics=1), 1, 4, return_info=True)
    >>> res.success, res.method, res.corrected_distance < 1e-20, res.fit_error < 1e-12
    (True, 'direct', True, True)
    """

    success: bool
    message: str
    distance: float
    terms: dict = field(default_factory=dict)
    corrected_distance: float = np.inf
    fit_error: float = np.inf
    transform: np.ndarray | None = None
    method: str = 'direct'
    nfev: int = 0
    ladder_mismatch: float | None = None


def floquet_realization(sys, nharmonics, nsteps, *, period=None, method='direct',
                        input_harmonics='all', distance='corrected', tol=1e-4,
                        fit_tol=0.05, ladder_tol=0.1, seed=None, progress=False, pso_options=None,
                        minimize_options=None, return_info=False, name=None):
    """Floquet-form LTP realization of an identified lifted LTI model.

    Finds a real similarity T that gives the identified model the
    structure of a frequency-lifted LTP in Floquet form (thesis eq. 4.101)
    and reads off the constant ``A_F`` and the periodic ``B[k]``, ``C[k]``,
    ``D[k]`` (thesis Sections 4.2.7-4.2.8, research-notes errata 5-7).

    Parameters
    ----------
    sys : control.StateSpace
        Discrete-time LTI model in the real lifted coordinates of
        `ltpcontrol.lift` (e.g. identified by `ltpcontrol.fdsubspace` from
        the real lifted frequency response), order ``(2K+1) n_p``, with
        ``(2K+1) p`` outputs.
    nharmonics : int
        Number K of harmonics of the lifting (harmonics -K..K).
    nsteps : int
        Steps N per period of the LTP, ``2K+1 <= N``.
    period : float, optional
        Period T in seconds; default ``N * sys.dt``.  Required when
        ``sys.dt`` is True.
    method : {'direct', 'pso'}
        'direct' (default): deterministic eigenvalue-ladder construction
        (module notes); needs distinct eigenvalues.  'pso': particle swarm
        over the ``n^2`` real entries of T (``n^2`` particles, n the lifted
        order) followed by Nelder-Mead, as in the thesis.
    input_harmonics : {'all', 'zero'}
        'all' (default): the inputs of `sys` are all ``(2K+1) m`` real
        lifted input coordinates, as produced by `lift`.  'zero': only the
        m coordinates of the zeroth harmonic ``U_0`` (the column B̄, D̄ of
        thesis eqs. 4.78-4.79); B and D are then recovered up to harmonic K
        only.
    distance : {'corrected', 'literal'}
        Distance to report and, for 'pso', to minimise (module notes).
        The literal one (printed eqs. 4.106-4.108) is nonzero at the true
        structure; `success` is always judged on the corrected distance.
    tol : float
        Success threshold on the corrected (normalised) distance, a sum of
        squared relative structure errors (default 1e-4, about 1 %).
    fit_tol : float
        Success threshold on the relative mismatch between the lifted model
        of the realization and `sys` (default 0.05).
    ladder_tol : float
        'direct' only: largest weighted ladder mismatch (`FloquetRealization`)
        for `success` (default 0.1; a spectrum without ladders gives O(1)).
        A larger mismatch still gives a realization, flagged unsuccessful.
    seed : int, optional
        Seed of the swarm ('pso'); the global NumPy random state is not used.
    progress : bool
        Show tqdm progress bars during the search ('pso'; default False).
    pso_options : dict, optional
        'pso' settings: ``iters`` (default 500), ``particles`` (default
        ``n^2``), ``c1`` (0.5), ``c2`` (0.3), ``w`` (0.9) and ``bound``
        (1.0: T is searched in ``[-bound, bound]^{n^2}``).
    minimize_options : dict, optional
        Options of the Nelder-Mead refinement (`scipy.optimize.minimize`);
        default ``{'maxfev': 200 n^2, 'xatol': 1e-12, 'fatol': 1e-16,
        'adaptive': True}``.
    return_info : bool, optional
        Also return the diagnostics (default False).
    name : str, optional
        Name of the realization (default: the name of `sys` with
        '$floquet').

    Returns
    -------
    realization : LTPStateSpace or None
        Discrete-time LTP in Floquet form (constant A), ``dt = period/N``.
        None only with ``return_info=True`` when no realization can be
        formed (see ``info.message``).
    info : FloquetRealization
        Only with ``return_info=True``.  Its ``success`` flag tells whether
        the structure was reached: a search may end in a local minimum,
        and 'direct' flags imperfect ladders; a realization that misses the
        tolerances is still returned, with a warning when `info` is not
        requested.

    Raises
    ------
    ControlArgument
        If `sys` is not a `control.StateSpace` or an option has the wrong type.
    ControlDimension
        If the sizes of `sys` do not match `nharmonics` and `input_harmonics`.
    ValueError
        If `sys` is continuous-time, ``2K+1 > N``, `period` disagrees with
        ``sys.dt`` or an option value is unknown; without ``return_info``,
        also when no realization can be formed: repeated eigenvalues, or
        eigenvalues that cannot be grouped into ``nstates``
        conjugate-closed ladders ('direct'), or a singular similarity
        ('pso').
    TypeError
        For unknown keyword arguments.

    Warns
    -----
    UserWarning
        'direct' with ill-conditioned eigenvectors (cond > 1e8); without
        ``return_info``, a realization that misses the tolerances.

    Notes
    -----
    On the thesis's Mathieu example the lifted eigenvalues of neighbouring
    harmonic blocks are only 0.0057 rad apart; the distance then has
    near-degenerate minima that mix modes, and the swarm succeeds only for
    some seeds (research notes).  'direct' resolves the ladders from the
    exact ratio ``w^{-1}`` of their members.

    Examples
    --------
    >>> B = np.array([[[1.0 + 0.5 * np.cos(2 * np.pi * k / 8)]] for k in range(8)])
    >>> sysd = ltp.ltpss([[0.6]], B, [[1.0]], 0, period=1.0, dt=0.125)
    >>> L = ltp.lift(sysd, nharmonics=1)
    >>> S = np.array([[1.0, 0.3, 0.0], [0.2, 2.0, 0.1], [0.0, 0.5, 1.0]])
    >>> ident = ct.similarity_transform(L, S)          # arbitrary coordinates
    >>> real, info = floquet_realization(ident, 1, 8, return_info=True)
    >>> info.success, round(float(real.A(0)[0, 0]), 10)
    (True, 0.6)
    >>> np.round(real.B.sample(8)[:3, 0, 0] / real.B.sample(8)[0, 0, 0], 4)
    array([1.    , 0.9024, 0.6667])
    """
    problem = _Problem.from_system(sys, nharmonics, nsteps, period, input_harmonics)
    if method not in ('direct', 'pso'):
        raise ValueError(f"method must be 'direct' or 'pso', got {method!r}")
    if distance not in ('corrected', 'literal'):
        raise ValueError(f"distance must be 'corrected' or 'literal', got {distance!r}")
    tol = check_positive(tol, 'tol')
    fit_tol = check_positive(fit_tol, 'fit_tol')
    ladder_tol = check_positive(ladder_tol, 'ladder_tol')
    if not isinstance(progress, (bool, np.bool_)):
        raise ControlArgument(f"progress must be True or False, got {progress!r}")
    if seed is not None and (isinstance(seed, (bool, np.bool_))
                             or not isinstance(seed, (numbers.Integral, np.integer))):
        raise ControlArgument(f"seed must be an integer or None, got {seed!r}")
    name = (sys.name + '$floquet') if name is None else name
    literal = distance == 'literal'
    mismatch, nfev = None, 0
    if method == 'direct':
        if pso_options is not None or minimize_options is not None:
            raise ValueError("pso_options and minimize_options only apply to method='pso'")
        T, mismatch, message = _direct_transform(problem)
    else:
        pso = _options(pso_options, 'pso_options', _pso_defaults(problem))
        nm = _options(minimize_options, 'minimize_options', _nm_defaults(problem))
        T, nfev = _pso_transform(problem, literal, seed, progress, pso, nm)
        message = ('' if np.linalg.cond(T) < _SINGULAR_COND else
                   'the search ended at a singular similarity; try another seed')
    if message:
        if not return_info:
            raise ValueError(f"no Floquet realization can be formed: {message}")
        return None, FloquetRealization(False, message, np.inf, {}, np.inf, np.inf, None,
                                        method, nfev, mismatch)
    d_corr = float(problem.distance(T[np.newaxis])[0][0])
    d, terms = problem.distance(T[np.newaxis], literal)
    terms = {key: float(val[0]) for key, val in terms.items()}
    realization = problem.realize(T, name)
    fit = problem.fit_error(realization)
    success = d_corr <= tol and fit <= fit_tol
    summary = (f"corrected distance {d_corr:.3g} (tol {tol:g}), "
               f"fit error {fit:.3g} (fit_tol {fit_tol:g})")
    if method == 'direct':
        success = success and mismatch <= ladder_tol
        summary += f", ladder mismatch {mismatch:.3g} (ladder_tol {ladder_tol:g})"
    if success:
        message = "Floquet structure reached: " + summary
    else:
        message = ("no Floquet structure within tolerance: " + summary
                   + ("; try another seed or more iterations" if method == 'pso' else
                      "; the model is not (close to) a lifted Floquet-form LTP"))
    info = FloquetRealization(bool(success), message, float(d[0]), terms, d_corr, fit, T,
                              method, nfev, mismatch)
    if return_info:
        return realization, info
    if not success:
        warnings.warn(message, UserWarning, stacklevel=2)
    return realization


#
# Lifted structure: distance and extraction
#

class _Problem:
    """Identified lifted model with the bases of its harmonic coordinates."""

    def __init__(self, A, B, C, D, K, N, period, nx, ny, nu, zero_inputs):
        self.A, self.B, self.C, self.D = A, B, C, D
        # Σ|λ(Â)|²: a T-invariant lower bound of ‖Ã‖_F², normaliser of d_A
        self.eig_scale = max(np.sum(np.abs(np.linalg.eigvals(A)) ** 2), np.finfo(float).tiny)
        self.K, self.N, self.period = K, N, period
        self.nx, self.ny, self.nu = nx, ny, nu
        self.H = 2 * K + 1
        self.zero_inputs = zero_inputs
        harmonics = np.arange(-K, K + 1)
        V, _ = _real_basis(harmonics, N)
        # real lifted coordinates -> complex harmonic coordinates: 𝒳 = Vx x
        self.Vx, self.Vy = np.kron(V, np.eye(nx)), np.kron(V, np.eye(ny))
        self.Vu = np.eye(nu) if zero_inputs else np.kron(V, np.eye(nu))
        self.w = np.exp(2j * np.pi / N)
        self.demod = self.w ** harmonics                       # w^{n}
        # wrapped diagonal classes (n - m) mod N and their averaging operator
        cls = (harmonics[:, None] - harmonics[None, :]) % N
        self.classes, inverse = np.unique(cls.ravel(), return_inverse=True)
        self.cls_index = inverse
        onehot = (inverse[None, :] == np.arange(len(self.classes))[:, None]).astype(float)
        self.average = onehot / onehot.sum(axis=1, keepdims=True)

    @classmethod
    def from_system(cls, sys, nharmonics, nsteps, period, input_harmonics):
        if not isinstance(sys, ct.StateSpace):
            raise ControlArgument(f"sys must be a control.StateSpace, got {type(sys).__name__}")
        if not sys.isdtime(strict=True):
            raise ValueError("sys must be a discrete-time model (the lifted LTI model of a "
                             "discrete-time LTP)")
        K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
        N = check_positive_int(nsteps, 'nsteps')
        H = 2 * K + 1
        if H > N:
            raise ValueError(f"nharmonics={K} needs 2K+1 <= nsteps = {N}")
        if sys.dt is True:
            if period is None:
                raise ValueError("period is required when sys.dt is True")
            period = check_period(period, 'period')
        elif period is None:
            period = N * float(sys.dt)
        else:
            period = check_period(period, 'period')
            if not np.isclose(period, N * sys.dt, rtol=1e-9, atol=0):
                raise ValueError(f"period={period} disagrees with nsteps * sys.dt = "
                                 f"{N * sys.dt}")
        if input_harmonics not in ('all', 'zero'):
            raise ValueError(f"input_harmonics must be 'all' or 'zero', got {input_harmonics!r}")
        zero = input_harmonics == 'zero'
        for what, size in (('nstates', sys.nstates), ('noutputs', sys.noutputs)):
            if size == 0 or size % H:
                raise ControlDimension(f"sys.{what} = {size} must be a positive multiple of "
                                       f"2K+1 = {H} (nharmonics={K})")
        if not zero and sys.ninputs % H:
            raise ControlDimension(f"sys.ninputs = {sys.ninputs} must be a multiple of "
                                   f"2K+1 = {H} with input_harmonics='all'")
        nu = sys.ninputs if zero else sys.ninputs // H
        if nu == 0:
            raise ControlDimension("sys must have at least one input")
        mats = [np.asarray(M, float) for M in (sys.A, sys.B, sys.C, sys.D)]
        return cls(*mats, K, N, period, sys.nstates // H, sys.noutputs // H, nu, zero)

    def harmonic_form(self, T):
        """Complex harmonic blocks of the model transformed by a batch of T."""
        P, n = T.shape[0], T.shape[1]
        H, nx, ny, nu = self.H, self.nx, self.ny, self.nu
        # Ã = T^{-1} Â T,  B̃ = T^{-1} B̂,  C̃ = Ĉ T
        TinvAB = np.linalg.solve(T, np.concatenate(
            [self.A @ T, np.broadcast_to(self.B, (P,) + self.B.shape)], axis=2))
        At, Bt = TinvAB[:, :, :n], TinvAB[:, :, n:]
        Ct = self.C @ T
        Vxh = self.Vx.conj().T
        Ac = (self.Vx @ At @ Vxh).reshape(P, H, nx, H, nx)
        Bc = self.Vx @ Bt @ self.Vu.conj().T
        Bc = Bc.reshape(P, H, nx, 1, nu) if self.zero_inputs else Bc.reshape(P, H, nx, H, nu)
        Cc = (self.Vy @ Ct @ Vxh).reshape(P, H, ny, H, nx)
        return Ac, Bc, Cc

    def _class_mean(self, blocks):
        """Diagonal averages ``M̄_c`` over (n - m) mod N = c; blocks (P, H, r, H, c)."""
        P, H, r, _, c = blocks.shape
        flat = blocks.transpose(0, 1, 3, 2, 4).reshape(P, H * H, r, c)
        mean = np.einsum('cq,pqij->pcij', self.average, flat)
        return flat, mean

    def _toeplitz_error(self, blocks):
        flat, mean = self._class_mean(blocks)
        return np.sum(np.abs(flat - mean[:, self.cls_index]) ** 2, axis=(1, 2, 3))

    def _diagonal(self, Ac):
        return np.einsum('pkikj->pkij', Ac)                   # Ã_nn, (P, H, nx, nx)

    def distance(self, T, literal=False):
        """Distance d and its terms for a batch of similarities T (P, n, n)."""
        Ac, Bc, Cc = self.harmonic_form(T)
        H, K = self.H, self.K
        diag = self._diagonal(Ac)
        blocks = np.sum(np.abs(Ac) ** 2, axis=(2, 4))           # ‖Ã_nm‖², (P, H, H)
        offdiag = np.sum(blocks * (1 - np.eye(H)), axis=(1, 2))
        if literal:
            # (4.106)-(4.107) as printed: Σ_k Ã_kk e^{-j2kπ/N}, k = 1..2K+1
            factor = np.exp(-2j * np.pi * np.arange(1, H + 1) / self.N)
            Abar = np.einsum('k,pkij->pij', factor, diag) / H
            dA = np.sum(Abar.imag ** 2, axis=(1, 2)) + offdiag
        else:
            # (4.106) with e^{+jθn} (item 5) plus the per-block error (item 6)
            demod = self.demod[None, :, None, None] * diag
            Abar = demod.mean(axis=1)
            dA = (np.sum(Abar.imag ** 2, axis=(1, 2)) + offdiag
                  + np.sum(np.abs(demod - Abar.real[:, None]) ** 2, axis=(1, 2, 3)))
        # (4.108) on the U_0 column: B_0 real, B_{-n} = conj(B_n)
        col = Bc[:, :, :, 0 if self.zero_inputs else K, :]
        asym = np.abs(col - col[:, ::-1].conj()) ** 2 / 4      # ‖(B_n - conj B_{-n})/2‖²
        asym[:, K] = 0.0
        dB = np.sum(col[:, K].imag ** 2, axis=(1, 2)) + np.sum(asym, axis=(1, 2, 3))
        if not (literal or self.zero_inputs):
            # Toeplitz structure of w^{n} B̃_{nm} over all input harmonics
            dB = dB + self._toeplitz_error(self.demod[None, :, None, None, None] * Bc)
        dC = self._toeplitz_error(Cc)
        if not literal:
            dA = dA / self.eig_scale
            dB = dB / np.sum(np.abs(Bc) ** 2, axis=(1, 2, 3, 4))
            dC = dC / np.sum(np.abs(Cc) ** 2, axis=(1, 2, 3, 4))
        return dA + dB + dC, {'A': dA, 'B': dB, 'C': dC}

    def realize(self, T, name):
        """LTP realization read from the model transformed by T."""
        Ac, Bc, Cc = self.harmonic_form(T[np.newaxis])
        K, N, H = self.K, self.N, self.H
        AF = (self.demod[:, None, None] * self._diagonal(Ac)[0]).mean(axis=0).real
        Dc = (self.Vy @ self.D @ self.Vu.conj().T)
        if self.zero_inputs:
            # B_l = w^{l} B̃_{l,0}, D_l = D̃_{l,0}, l = -K..K; symmetrised B_{-l} = conj(B_l)
            Bl = self.demod[:, None, None] * Bc[0, :, :, 0, :]
            Bl = (Bl + Bl[::-1].conj()) / 2
            Dl = Dc.reshape(H, self.ny, self.nu)
            Dl = (Dl + Dl[::-1].conj()) / 2
            classes = np.arange(-K, K + 1)
        else:
            Bl = self._class_mean(self.demod[None, :, None, None, None] * Bc)[1][0]
            Dl = self._class_mean(Dc.reshape(1, H, self.ny, H, self.nu))[1][0]
            classes = self.classes
        Cl = self._class_mean(Cc)[1][0]
        k = np.arange(N)

        def synthesize(coeffs, cls):
            # M[k] = Σ_c M_c w^{ck}
            return np.einsum('ck,cij->kij', self.w ** np.outer(cls, k), coeffs).real

        return ltpss(AF, synthesize(Bl, classes), synthesize(Cl, self.classes),
                     synthesize(Dl, classes), period=self.period, dt=self.period / N,
                     name=name)


    def fit_error(self, realization, npoints=64):
        """Relative mismatch of the lifted realization and the given model on |z| = 1."""
        L = lift(realization, nharmonics=self.K)
        mats = [np.asarray(M, float) for M in (L.A, L.B, L.C, L.D)]
        if self.zero_inputs:
            mats[1], mats[3] = mats[1][:, :self.nu], mats[3][:, :self.nu]
        z = np.exp(1j * np.pi * (np.arange(npoints) + 0.5) / npoints)
        G, Ghat = (_frequency_response(*M, z) for M in (mats, (self.A, self.B, self.C, self.D)))
        return float(np.linalg.norm(G - Ghat, axis=(1, 2)).max()
                     / max(np.linalg.norm(Ghat, axis=(1, 2)).max(), np.finfo(float).tiny))


def _frequency_response(A, B, C, D, z):
    """``C (zI - A)^{-1} B + D`` at the points z, shape (len(z), p, m)."""
    eye = np.eye(A.shape[0])
    with np.errstate(all='ignore'):
        return C @ np.linalg.solve(z[:, None, None] * eye - A, B) + D


#
# Method 'direct': eigenvalue ladders
#

def _direct_transform(problem):
    """Similarity T from the eigenvalue ladders, or (None, mismatch, reason)."""
    H, K, nx, N = problem.H, problem.K, problem.nx, problem.N
    lam, W = np.linalg.eig(problem.A)
    scale = max(np.abs(lam).max(), np.finfo(float).tiny)
    gaps = np.abs(lam[:, None] - lam[None, :]) + np.eye(len(lam)) * scale
    if gaps.min() <= 1e-10 * scale:
        return None, None, ("the lifted A has repeated eigenvalues; the direct method "
                            "needs distinct Floquet exponents (try method='pso')")
    if np.linalg.cond(W) > 1e8:
        warnings.warn("the eigenvectors of the lifted A are ill-conditioned "
                      f"(cond {np.linalg.cond(W):.2g}); the realization may be inaccurate",
                      UserWarning, stacklevel=3)
    Cc = problem.Vy @ problem.C                            # complex output harmonics
    Bc = problem.B @ problem.Vu.conj().T                   # complex input harmonics
    Winv = np.linalg.inv(W)
    # contribution of each mode to the response: ‖Ĉ w_a‖ ‖(W^{-1} B̂)_a‖ (scale free)
    cn = np.linalg.norm(Cc @ W, axis=0)
    bn = np.linalg.norm(Winv @ Bc, axis=1)
    chains, partner, mismatch = _ladders(lam, cn * bn, nx, H, N)
    if chains is None:
        return None, None, mismatch + ("; the model is not a lifted Floquet-form LTP of "
                                       "this N and K")
    # balance eigenvector scales: ‖Ĉ_mod column‖ = ‖B̂_mod row‖
    s = np.sqrt(np.where((cn > 0) & (bn > 0), bn / np.where(cn > 0, cn, 1), 1.0))
    W, Winv = W * s, Winv / s[:, None]
    Wnew = np.zeros((H * nx, H * nx), complex)        # columns (n, i), harmonic-major
    for i, j in enumerate(partner):
        if j < i:
            continue
        V = W[:, chains[i]]                             # eigenvectors of λ_{n,i}, n = -K..K
        if j == i:                                      # real ladder: v_{-n} = conj(v_n)
            v0 = V[:, K] * np.exp(-1j * np.angle(V[np.argmax(np.abs(V[:, K])), K]))
            V[:, K] = v0.real
            V[:, :K] = V[:, :K:-1].conj()
        # left eigenvectors for the (rescaled) columns V: rows with row_a v_a = 1
        Y = Winv[chains[i]]
        Y = Y / np.sum(Y * V.T, axis=1)[:, None]
        d = _chain_scales(problem, V, Y)
        if j == i:
            d = (d + d[::-1].conj()) / 2
        Wnew[:, np.arange(H) * nx + i] = V / d
        Wnew[:, np.arange(H) * nx + j] = (V / d)[:, ::-1].conj()
    # realify A_F: ξ_n = M X_n with conj(M) = (pair swap) M
    M = np.zeros((nx, nx), complex)
    for i, j in enumerate(partner):
        if i == j:
            M[i, i] = 1.0
        elif i < j:
            M[[i, j], i] = 1 / np.sqrt(2)
            M[[i, j], j] = 1j / np.sqrt(2), -1j / np.sqrt(2)
    # x̂ = Wnew ξ,  ξ = (I ⊗ M) 𝒳,  𝒳 = Vx x_r   =>   T = Wnew (I ⊗ M) Vx
    T = Wnew @ np.kron(np.eye(H), M) @ problem.Vx
    if np.abs(T.imag).max() > 1e-6 * np.abs(T).max():
        return None, mismatch, ("the ladder construction gave a complex similarity; the "
                                "eigenvalue pairing is inconsistent")
    return T.real, mismatch, ''


def _ladders(lam, weight, nx, H, N):
    """Ladders of ``H`` eigenvalues ``μ w^{-n}``, n = -K..K, by optimal matching.

    Returns ``(chains (nx, H), partner (nx,), mismatch)`` or ``(None, None,
    reason)``.  Ladders are formed one centre (or conjugate pair of
    centres) at a time: every unassigned eigenvalue is tried as centre μ,
    the ideal members ``μ w^{-n}`` are matched to the unassigned
    eigenvalues by `linear_sum_assignment` on their distance relative to
    the ladder step ``2|μ| sin(π/N)``, and the centre whose ladder matches
    best (distances capped at one step, ties to the member closest to the
    real axis, then to the largest `weight`) is kept.  A real centre takes
    conjugate members ``n, -n``; a complex one brings the conjugate ladder
    along, so the ladders always form a real realization.  The mismatch
    of a member is weighted by its `weight` (contribution to the response)
    relative to the largest of its ladder: weakly excited outer members,
    which absorb the truncation error, count little.
    """
    n, K = len(lam), (H - 1) // 2
    if H == 1:                                  # K = 0: every eigenvalue is a ladder
        chains = np.arange(n)[:, np.newaxis]
        return chains, _conjugates(lam)[chains[:, 0]], 0.0
    conj = _conjugates(lam)
    w = np.exp(2j * np.pi / N)
    shifts = w ** -np.arange(-K, K + 1)
    step = 2 * np.sin(np.pi / N)                    # ladder step relative to |μ|
    tiny = np.finfo(float).tiny
    free = np.ones(n, bool)
    chains, partner, mismatch = [], [], 0.0
    while free.any():
        cand = np.flatnonzero(free)
        best = None
        for a in cand:
            real = conj[a] == a
            if not real and not free[conj[a]]:
                continue
            slots, rel = _match(lam, free, lam[a] * shifts, a, conj, real, step * abs(lam[a]))
            if slots is None:
                continue
            score = np.minimum(rel, 1.0).sum()
            key = (round(score, 3), round(abs(lam[a].imag) / max(abs(lam[a]), tiny), 8),
                   -weight[a])
            if best is None or key < best[0]:
                best = (key, a, slots, rel)
        if best is None:
            return None, None, "the eigenvalues of the lifted A cannot be grouped into ladders"
        _, a, slots, rel = best
        chain = slots
        free[chain] = False
        w_rel = weight[chain] / max(weight[chain].max(), tiny)
        mismatch = max(mismatch, float(np.max(rel * w_rel)))
        if conj[a] == a:
            chains.append(chain)
            partner.append(len(chains) - 1)
        else:
            mate = conj[chain[::-1]]
            free[mate] = False
            chains += [chain, mate]
            partner += [len(chains) - 1, len(chains) - 2]
    if len(chains) != nx:
        return None, None, (f"the eigenvalues form {len(chains)} ladders, not nstates = {nx}")
    return np.array(chains), np.array(partner), mismatch


def _match(lam, free, targets, centre, conj, real, step):
    """Unassigned eigenvalues nearest to the ideal ladder `targets` (centre fixed).

    Members are drawn from conjugate classes ``{λ, conj λ}`` of unassigned
    complex eigenvalues, one member per class, so that the ladder and its
    conjugate (for a real centre: members n and -n) never share an
    eigenvalue.  Returns ``(indices (H,), distances in ladder steps (H,))``
    or ``(None, None)``.
    """
    H = len(targets)
    K = (H - 1) // 2
    pool = np.flatnonzero(free & (lam.imag > 0) & free[conj])
    pool = pool[(pool != centre) & (pool != conj[centre])]
    rows = np.arange(K + 1, H) if real else np.r_[0:K, K + 1:H]
    if len(pool) < len(rows):
        return None, None
    # slot cost: the nearer orientation λ or conj λ of each class
    up = np.abs(targets[rows][:, None] - lam[pool][None, :])
    down = np.abs(targets[rows][:, None] - lam[pool][None, :].conj())
    r, c = linear_sum_assignment(np.minimum(up, down))
    idx = np.empty(H, int)
    idx[K] = centre
    idx[rows[r]] = np.where(up[r, c] <= down[r, c], pool[c], conj[pool[c]])
    if real:
        idx[:K] = conj[idx[K + 1:]][::-1]
    return idx, np.abs(lam[idx] - targets) / step


def _conjugates(lam):
    """Index of the complex conjugate of every eigenvalue (itself when real)."""
    cost = np.abs(lam[:, None] - lam[None, :].conj())
    _, cols = linear_sum_assignment(cost)
    return cols


def _chain_scales(problem, V, Y):
    """Scales ``d_n`` (d_0 = 1) making the modal C (and B) of one ladder Toeplitz.

    V holds the right eigenvectors of the ladder (n = -K..K), Y the matching
    rows of the inverse modal matrix.
    """
    H, K, ny, nu = problem.H, problem.K, problem.ny, problem.nu
    Cm = (problem.Vy @ problem.C @ V).T.reshape(H, H, ny)          # [n, r, :]
    Bm = None
    if not problem.zero_inputs:
        Bm = (Y @ problem.B @ problem.Vu.conj().T).reshape(H, H, nu)   # [n, m, :]
    ratio = np.ones(H - 1, complex)
    for n in range(H - 1):
        # Ĉ_{r+1,(n+1)} = ρ Ĉ_{r,(n)};  w B̂_{(n+1),m+1} ρ = B̂_{(n),m}
        u, v = Cm[n, :-1].ravel(), Cm[n + 1, 1:].ravel()
        num, den = np.vdot(u, v), np.vdot(u, u)
        if Bm is not None:
            b, bp = Bm[n, :-1].ravel(), problem.w * Bm[n + 1, 1:].ravel()
            num, den = num + np.vdot(bp, b), den + np.vdot(bp, bp)
        ratio[n] = num / den if abs(den) > 0 else 1.0
    d = np.concatenate([[1.0], np.cumprod(ratio)])
    return d / d[K]


#
# Method 'pso': particle swarm + Nelder-Mead (thesis Section 4.2.7)
#

def _pso_defaults(problem):
    n = problem.H * problem.nx
    return {'iters': 500, 'particles': n * n, 'c1': 0.5, 'c2': 0.3, 'w': 0.9, 'bound': 1.0}


def _nm_defaults(problem):
    n = problem.H * problem.nx
    return {'maxfev': 200 * n * n, 'xatol': 1e-12, 'fatol': 1e-16, 'adaptive': True}


def _options(given, name, defaults):
    if given is None:
        return defaults
    if not isinstance(given, dict):
        raise ControlArgument(f"{name} must be a dict, got {type(given).__name__}")
    if name == 'pso_options':
        unknown = set(given) - set(defaults)
        if unknown:
            raise TypeError(f"{name}: unrecognized keyword(s): {sorted(unknown)}")
    return {**defaults, **given}


def _swarm(cost, dim, pso, rng, progress):
    """Global-best particle swarm in ``[-bound, bound]^dim``: best cost and position.

    Velocities follow ``v <- w v + c1 r1 (p - x) + c2 r2 (g - x)`` with
    uniform ``r1, r2`` per coordinate, ``p`` each particle's best and ``g``
    the swarm's best position; positions are clipped to the box.
    """
    nparticles, bound = int(pso['particles']), float(pso['bound'])
    x = rng.uniform(-bound, bound, (nparticles, dim))
    v = rng.uniform(-bound, bound, (nparticles, dim)) * 0.1
    pbest, pcost = x.copy(), cost(x)
    for _ in tqdm(range(int(pso['iters'])), desc='particle swarm', disable=not progress,
                  leave=False):
        g = pbest[np.argmin(pcost)]
        r1, r2 = rng.random((2, nparticles, dim))
        v = pso['w'] * v + pso['c1'] * r1 * (pbest - x) + pso['c2'] * r2 * (g - x)
        x = np.clip(x + v, -bound, bound)
        c = cost(x)
        better = c < pcost
        pbest[better], pcost[better] = x[better], c[better]
    i = np.argmin(pcost)
    return float(pcost[i]), pbest[i]


def _pso_transform(problem, literal, seed, progress, pso, nm):
    """Best T found by the swarm and Nelder-Mead, and the number of evaluations."""
    n = problem.H * problem.nx
    nfev = 0

    def cost(X):
        nonlocal nfev
        T = np.asarray(X, float).reshape(-1, n, n)
        nfev += len(T)
        out = np.full(len(T), _SINGULAR_COST)
        ok = np.linalg.cond(T) < _SINGULAR_COND
        if ok.any():
            with np.errstate(all='ignore'):
                out[ok] = np.nan_to_num(problem.distance(T[ok], literal)[0],
                                        nan=_SINGULAR_COST, posinf=_SINGULAR_COST)
        return out

    best, x = _swarm(cost, n * n, pso, np.random.default_rng(seed), progress)
    bar = tqdm(total=int(nm.get('maxfev', 0)) or None, desc='Nelder-Mead',
               disable=not progress, leave=False)

    def scalar(x):
        bar.update(1)
        return float(cost(x[np.newaxis])[0])

    with bar:
        res = minimize(scalar, x, method='Nelder-Mead', options=nm)
    x = res.x if res.fun <= best else x
    return x.reshape(n, n), nfev
