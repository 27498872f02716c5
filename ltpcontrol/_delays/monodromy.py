"""Monodromy operator of a periodic delay-differential equation by spectral elements.

For ``ẋ(t) = A(t) x(t) + Σ_j A_j(t) x(t - τ_j)`` (period T, ``τ_max =
max τ_j``) the state is the segment ``φ(θ) = x(θ)``, ``θ ∈ [-τ_max, 0]``,
and the monodromy operator maps it to ``x(T + θ)``.  Its nonzero
eigenvalues are the characteristic multipliers.

Discretization (pseudospectral collocation on elements, in the spirit of
Breda, Maset and Vermiglio and of the spectral-element method of Khasawneh
and Mann): the window ``[-τ_max, T]`` is cut into elements whose edges
contain every instant where a coefficient switches (the tooth entering or
leaving the cut), its images under the delays and the period, so that the
Floquet solutions are smooth inside every element.  On each element x is
the polynomial of degree p through its values at the Chebyshev-Lobatto
nodes (neighbouring elements share their end node, so x is continuous).
The history nodes ``θ ≤ 0`` carry φ; the nodes in ``(0, T]`` are unknown
and fixed by collocating the equation at the p Chebyshev-Gauss points of
each element of ``[0, T]``, the delayed values ``x(t_c - τ_j)``
interpolated in the element holding ``t_c - τ_j``.  Reading x at ``T +
θ_k`` for every history node ``θ_k`` gives the matrix of the operator.  Only
history coordinates that some delayed term reads (or that the shift by T
carries, when ``τ_max > T``) can make a nonzero multiplier; the others give
zero columns and are dropped, which makes milling (delayed term active in
the cut only) cheap.

Convergence is exponential in p for coefficients smooth between the
element edges.  The accuracy estimate compares the dominant multipliers
from degree p and from degree ``p + 8``.
"""

import functools
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as la
from control.exception import ControlArgument

from .._core.registry import method_alias
from .._core.validation import check_positive_int
from . import terms as tm
from .ltpdsys import LTPDelayStateSpace

__all__ = ['delay_monodromy', 'DelayMonodromy']

# default polynomial degree per element, and the increase of the check
_ORDER = 16
_REFINE = 8
# element length times the frozen coefficients' spectral radius
_H_NORM = 4.0
# largest number of history nodes before the discretization is refused
_MAX_NODES = 6000


@dataclass(frozen=True)
class DelayMonodromy:
    """Discretized monodromy operator of a periodic delay-differential equation.

    Returned by `delay_monodromy`.

    Attributes
    ----------
    matrix : ndarray, shape (N, N)
        The discretized operator on the history coordinates it acts on.
    multipliers : ndarray of complex
        Its eigenvalues sorted by decreasing modulus (zero ones left out).
    error : float
        Estimated absolute error of the dominant multipliers: the largest
        change of the 2n largest multipliers (n states) between degree
        ``order - 8`` and ``order``.
    order : int
        Polynomial degree per element of the returned discretization.
    elements : int
        Number of elements over ``[-τ_max, T]``.
    converged : bool
        True when `error` is at most the requested tolerance.

    Examples
    --------
    >>> sys = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[0.5]])])
    >>> M = ltp.delay_monodromy(sys)
    >>> M.converged, M.multipliers.shape[0] > 1
    (True, True)
    """

    matrix: np.ndarray
    multipliers: np.ndarray
    error: float
    order: int
    elements: int
    converged: bool

    def __repr__(self):
        return (f"<DelayMonodromy: {self.matrix.shape[0]} coordinates, |mu|max="
                f"{abs(self.multipliers[0]) if self.multipliers.size else 0:.6g}, "
                f"error~{self.error:.1e}, order={self.order}>")


@method_alias
def delay_monodromy(sys, *, tol=1e-10, order=None, max_order=48):
    """Monodromy operator of a delayed LTP system, discretized by spectral elements.

    The characteristic multipliers of ``ẋ = A(t)x + Σ_j A_j(t) x(t - τ_j)``
    are the nonzero eigenvalues of the operator; the discretization (see
    the module notes) converges exponentially for coefficients smooth
    between their switching instants, which it treats exactly.  The degree
    is raised until two resolutions agree to `tol`; a result that cannot
    reach it says so by a warning and ``converged=False``.

    Parameters
    ----------
    sys : LTPDelayStateSpace
        Continuous-time system with delays (input and output delays do not
        change the multipliers).
    tol : float, optional
        Requested absolute accuracy of the dominant multipliers (default
        1e-10).
    order : int, optional
        Fixed polynomial degree per element (no refinement loop; the error
        is still estimated against ``order - 8``).
    max_order : int, optional
        Largest degree tried by the refinement (default 48).

    Returns
    -------
    DelayMonodromy

    Examples
    --------
    ``ẋ = -x + 0.5 x(t - 1)``: the real root λ of ``λ + 1 = 0.5 e^{-λ}``
    gives the dominant multiplier ``e^{λ}`` (period 1):

    >>> from scipy.optimize import brentq
    >>> lam = brentq(lambda l: l + 1 - 0.5 * np.exp(-l), -1, 0)
    >>> sys = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[0.5]])])
    >>> M = ltp.delay_monodromy(sys)
    >>> bool(abs(M.multipliers[0] - np.exp(lam)) < 1e-10)
    True
    """
    if not isinstance(sys, LTPDelayStateSpace):
        raise ControlArgument(f"sys must be an LTPDelayStateSpace, got {type(sys).__name__}")
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating)) \
            or not 0 < tol < 1:
        raise ValueError(f"tol must be a number in (0, 1), got {tol!r}")
    max_order = check_positive_int(max_order, 'max_order', minimum=_REFINE + 2)
    prob = _Problem(sys)
    if order is not None:
        order = check_positive_int(order, 'order', minimum=_REFINE + 2)
        degrees = [order]
    else:
        degrees = list(range(_ORDER, max_order + 1, _REFINE)) or [max_order]
    coarse = prob.multipliers(degrees[0] - _REFINE)
    for p in degrees:
        U = prob.matrix(p)
        fine = _eig(U)
        err = _change(coarse, fine, 2 * sys.nstates)
        if err <= tol:
            break
        coarse = fine
    converged = err <= tol
    if not converged:
        warnings.warn(f"delay_monodromy: the dominant multipliers reach an estimated "
                      f"accuracy of {err:.1e} at degree {p}, above tol={tol:g}",
                      UserWarning, stacklevel=2)
    return DelayMonodromy(matrix=U, multipliers=fine, error=float(err), order=p,
                          elements=prob.elements, converged=converged)


def _eig(U):
    if U.size == 0:
        return np.zeros(0, complex)
    mu = la.eigvals(U, check_finite=False)
    mu = mu[np.abs(mu) > 0]
    return mu[np.argsort(-np.abs(mu), kind='stable')]


def _change(coarse, fine, count):
    """Largest distance from one of the `count` dominant fine multipliers to a coarse one."""
    if fine.size == 0:
        return 0.0
    if coarse.size == 0:
        return float(np.abs(fine[0]))
    big = fine[:count]
    return float(np.max(np.min(np.abs(big[:, None] - coarse[None, :]), axis=1)))


class _Problem:
    """Element mesh and coefficient access of one system (independent of the degree)."""

    def __init__(self, sys):
        T = sys.period
        self.T, self.n = T, sys.nstates
        self.terms = [(0.0, sys.A)] + tm.delayed(sys.terms['A'])
        self.delays = np.array([a for a, _ in self.terms[1:]])
        self.tau = float(self.delays.max()) if self.delays.size else 0.0
        # coefficient scale for the element length
        probe = np.concatenate([np.linspace(0, T, 33)[:-1]]
                               + [M.breakpoints for _, M in self.terms])
        # (spectral radius of the frozen coefficients, delayed terms with either sign)
        vals = [M(probe) for _, M in self.terms]
        plus = sum(vals)
        minus = 2 * vals[0] - plus
        scale = max(np.max(np.abs(np.linalg.eigvals(S)), initial=0.0) for S in (plus, minus))
        self.hmax = min(_H_NORM / scale if scale > 0 else np.inf, T, *(self.delays if
                        self.delays.size else [T]))
        # breakpoints inside the period: switches and their images under the delays
        bps = np.concatenate([M.breakpoints for _, M in self.terms] + [[0.0]])
        bps = np.concatenate([bps] + [np.mod(bps + a, T) for a in self.delays])
        bps = np.unique(np.mod(bps, T))
        sol = _edges(np.concatenate([bps, [T]]), 0.0, T, self.hmax)
        if self.tau > 0:
            k = np.arange(1, int(np.ceil(self.tau / T)) + 1)
            hist = (bps[None, :] - T * k[:, None]).ravel()
            hist = hist[(hist > -self.tau) & (hist < 0)]
            hist = _edges(np.concatenate([hist, [0.0]]), -self.tau, 0.0, self.hmax)
        else:
            hist = np.array([0.0])
        self.edges = np.concatenate([hist[:-1], sol])
        self.nhist_el = len(hist) - 1
        self.elements = len(self.edges) - 1
        self._cache = {}

    def multipliers(self, p):
        return _eig(self.matrix(p))

    def matrix(self, p):
        if p in self._cache:
            return self._cache[p]
        n, T, edges = self.n, self.T, self.edges
        ne, neh = self.elements, self.nhist_el
        nn, nh = ne * p + 1, neh * p + 1
        if nh > _MAX_NODES:
            raise ValueError(f"the delay spans {nh} history nodes (more than {_MAX_NODES}); "
                             "the delay is too long for the coefficient scale")
        z, w, Ic, Dc = _rules(p)
        h = np.diff(edges)
        tnodes = np.append((edges[:-1, None] + (z[None, :-1] + 1) / 2 * h[:, None]).ravel(),
                           edges[-1])
        els = np.arange(neh, ne)
        tc = (edges[els, None] + (_gauss(p)[None, :] + 1) / 2 * h[els, None]).ravel()
        coef = [M(tc).reshape(len(els), p, n, n) for _, M in self.terms]
        reads = [_locate(edges, z, w, tc - a) for a, _ in self.terms[1:]]
        reads = [(idx.reshape(len(els), p, p + 1), L.reshape(len(els), p, p + 1))
                 for idx, L in reads]
        back = _locate(edges, z, w, T + tnodes[:nh])
        # history coordinates (node, component) that the equations or the shift read
        used = np.zeros((nh, n), bool)
        used[nh - 1] = True                               # x(0) starts the solution
        for (idx, L), M in zip(reads, coef[1:]):
            col = np.any(M != 0, axis=2)                  # (els, p, n): columns read
            hit = (idx < nh) & (L != 0)
            e_, l_, i_ = np.nonzero(hit)
            np.logical_or.at(used, idx[e_, l_, i_], col[e_, l_])
        bidx, bL = back
        hit = (bidx < nh) & (bL != 0)
        used[bidx[hit]] = True
        active = np.flatnonzero(used.ravel())
        na = len(active)
        V = np.zeros((nn, n, na))
        V.reshape(nn * n, na)[active, np.arange(na)] = 1.0
        I = np.eye(n)
        for k, e in enumerate(els):
            A = coef[0][k]                                # (p, n, n)
            # own block: (D ⊗ I - I_c ⊗ A(t_c)) acting on the element's nodes
            own = (Dc * (2 / h[e]))[:, None, :, None] * I[None, :, None, :] \
                - Ic[:, None, :, None] * A[:, :, None, :]  # (p, n, p+1, n)
            rhs = -np.einsum('lrc,ca->lra', own[:, :, 0, :], V[e * p])
            for (idx, L), M in zip(reads, coef[1:]):
                past = np.einsum('li,lica->lca', L[k], V[idx[k]])
                rhs += np.einsum('lrc,lca->lra', M[k], past)
            lhs = own[:, :, 1:, :].reshape(p * n, p * n)
            V[e * p + 1:e * p + p + 1] = np.linalg.solve(lhs, rhs.reshape(p * n, na)
                                                         ).reshape(p, n, na)
        new = np.einsum('ki,kica->kca', bL, V[bidx])      # x(T + θ_k)
        U = new.reshape(nh * n, na)[active]
        self._cache[p] = U
        return U


@functools.lru_cache(maxsize=16)
def _rules(p):
    """Lobatto nodes, weights, and interpolation/differentiation at the Gauss points."""
    z, w = _lobatto(p)
    Ic, Dc = _bary(z, w, _gauss(p))
    return z, w, Ic, Dc


def _gauss(p):
    """Chebyshev-Gauss points on [-1, 1] (increasing): the collocation points."""
    return -np.cos(np.pi * (2 * np.arange(p) + 1) / (2 * p))


def _edges(points, lo, hi, hmax):
    """Sorted edges from lo to hi through `points`, no element longer than hmax."""
    pts = np.unique(np.concatenate([[lo, hi], points[(points > lo) & (points < hi)]]))
    scale = max(abs(lo), abs(hi), 1e-300)
    pts = pts[np.concatenate([[True], np.diff(pts) > 1e-12 * scale])]
    pts[-1] = hi
    out = [pts[:1]]
    for a, b in zip(pts[:-1], pts[1:]):
        k = max(1, int(np.ceil((b - a) / hmax - 1e-9)))
        out.append(a + (b - a) * np.arange(1, k + 1) / k)
    return np.concatenate(out)


def _lobatto(p):
    """Chebyshev-Lobatto nodes on [-1, 1] (increasing) and barycentric weights."""
    z = -np.cos(np.pi * np.arange(p + 1) / p)
    w = (-1.0) ** np.arange(p + 1)
    w[0] *= 0.5
    w[-1] *= 0.5
    return z, w


def _bary(z, w, y):
    """Interpolation and differentiation matrices from nodes z to points y (y ∉ z)."""
    d = y[:, None] - z[None, :]
    q = w[None, :] / d
    S = q.sum(axis=1, keepdims=True)
    L = q / S
    dS = -(q / d).sum(axis=1, keepdims=True)
    dL = (-q / d * S - q * dS) / S**2
    return L, dL


def _locate(edges, z, w, t):
    """Global node indices (len(t), p+1) and interpolation weights of x at times t."""
    p = len(z) - 1
    ne = len(edges) - 1
    el = np.clip(np.searchsorted(edges, t, side='right') - 1, 0, ne - 1)
    a, b = edges[el], edges[el + 1]
    y = np.clip(2 * (t - a) / (b - a) - 1, -1.0, 1.0)
    d = y[:, None] - z[None, :]
    hit = np.abs(d) <= 1e-13
    d = np.where(hit, 1.0, d)
    q = w[None, :] / d
    L = q / q.sum(axis=1, keepdims=True)
    rows = np.any(hit, axis=1)
    L[rows] = hit[rows].astype(float)
    return el[:, None] * p + np.arange(p + 1)[None, :], L
