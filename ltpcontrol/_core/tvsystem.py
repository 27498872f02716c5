"""Discrete periodic systems whose dimensions vary over the period.

``x[k+1] = A_k x[k] + B_k u[k]``, ``y[k] = C_k x[k] + D_k u[k]`` with
``A_k`` of shape ``n_{k+1} x n_k``, ``B_k`` ``n_{k+1} x m_k``, ``C_k``
``p_k x n_k`` and ``D_k`` ``p_k x m_k``, all N-periodic (``n_N = n_0``).
Such models arise from minimal realizations (a periodic system is minimal
with an order that changes with k), from multirate sampling (a channel that
is sampled at some steps only) and from lifting.

Characteristic multipliers.  The cyclic product ``Φ_k = A_{k+N-1} ...
A_k`` is ``n_k x n_k``; its nonzero eigenvalues do not depend on k, and at
most ``n_min = min_j n_j`` of them are nonzero.  These ``n_min`` core
multipliers, sorted by decreasing modulus, are followed by ``n_k - n_min``
zeros (the convention of the periodic systems toolbox of Varga, whose
``pseig`` pads the core eigenvalues with zeros to the dimension at the
starting step).

Sub-periods.  The four sequences may have different lengths; the system
is built on their least common multiple (`subperiods.common_steps`) and the
dimension chain is then checked around the whole period.
"""

import numbers

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension

from .registry import override
from .subperiods import common_steps
from .validation import check_positive, real_array

__all__ = ['DiscreteLTPSystem', 'dltpss']


class DiscreteLTPSystem:
    """Discrete periodic system with time-varying dimensions.

    Create it with `dltpss`.  The matrices of step k are ``A[k]``,
    ``B[k]``, ``C[k]``, ``D[k]`` (tuples of N arrays).

    Parameters
    ----------
    A, B, C, D : list of array_like, or array_like
        The matrices of one period (see `dltpss`).
    dt : float
        Sampling time.
    name : str, optional
        System name.

    Attributes
    ----------
    A, B, C, D : tuple of ndarray
        The N matrices of one period of each kind.
    nsteps : int
        N, the number of steps of the period.
    dt : float
        Sampling time; ``period = N dt``.
    nstates, ninputs, noutputs : tuple of int
        ``n_k``, ``m_k`` and ``p_k`` for k = 0..N-1.
    name : str

    Examples
    --------
    The reference toolbox's example of factors 1x2, 2x1 (states 2, 1):

    >>> sys = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                  [[[1.0, 0.0]], [[1.0]]], 0)
    >>> sys.nstates, sys.nsteps
    ((2, 1), 2)
    >>> sys
    <DiscreteLTPSystem sys[0]: states (2, 1), inputs (1, 1), outputs (1, 1), N=2, dt=1>
    """

    # make numpy defer to our reflected operators (ndarray * DiscreteLTPSystem)
    __array_ufunc__ = None

    def __init__(self, A, B, C, D, dt=1.0, *, name=None):
        self.dt = check_positive(dt, 'dt')
        A = _sequence(A, 'A')
        B = _sequence(B, 'B')
        C = _sequence(C, 'C')
        D = None if _is_zero(D) else _sequence(D, 'D')
        seqs = [A, B, C] + ([D] if D is not None else [])
        names = ['A', 'B', 'C', 'D'][:len(seqs)]
        N = common_steps([len(s) for s in seqs], names)
        A, B, C = (tuple(s[k % len(s)] for k in range(N)) for s in (A, B, C))
        n = tuple(check_chain(A, 'A'))
        for k in range(N):
            if B[k].shape[0] != A[k].shape[0]:
                raise ControlDimension(f"B[{k}] must have {A[k].shape[0]} rows (n_{k + 1}), "
                                       f"got shape {B[k].shape}")
            if C[k].shape[1] != n[k]:
                raise ControlDimension(f"C[{k}] must have {n[k]} columns (n_{k}), got "
                                       f"shape {C[k].shape}")
        if D is None:
            D = tuple(np.zeros((C[k].shape[0], B[k].shape[1])) for k in range(N))
        else:
            D = tuple(D[k % len(D)] for k in range(N))
            for k in range(N):
                if D[k].shape != (C[k].shape[0], B[k].shape[1]):
                    raise ControlDimension(f"D[{k}] must have shape "
                                           f"{(C[k].shape[0], B[k].shape[1])}, got "
                                           f"{D[k].shape}")
        self.A, self.B, self.C, self.D = A, B, C, D
        self.nsteps = N
        self.nstates = n
        self.ninputs = tuple(b.shape[1] for b in B)
        self.noutputs = tuple(c.shape[0] for c in C)
        self.name = 'sys[0]' if name is None else str(name)

    # -- properties ---------------------------------------------------------

    @property
    def period(self):
        """The period ``N dt``."""
        return self.nsteps * self.dt

    @property
    def has_constant_dimensions(self):
        """True when n_k, m_k and p_k are the same at every step."""
        return all(len(set(d)) == 1 for d in (self.nstates, self.ninputs, self.noutputs))

    def __repr__(self):
        def fmt(d):
            return '(' + ', '.join(map(str, d)) + ')'
        return (f"<DiscreteLTPSystem {self.name}: states {fmt(self.nstates)}, inputs "
                f"{fmt(self.ninputs)}, outputs {fmt(self.noutputs)}, N={self.nsteps}, "
                f"dt={self.dt:g}>")

    def __str__(self):
        lines = [f"DiscreteLTPSystem {self.name}: period {self.nsteps} steps of dt = "
                 f"{self.dt:g}"]
        for k in range(self.nsteps):
            lines.append(f"step {k}: A {self.A[k].shape[0]}x{self.A[k].shape[1]}, "
                         f"B {self.B[k].shape[0]}x{self.B[k].shape[1]}, "
                         f"C {self.C[k].shape[0]}x{self.C[k].shape[1]}, "
                         f"D {self.D[k].shape[0]}x{self.D[k].shape[1]}")
            for label, M in (('A', self.A[k]), ('B', self.B[k]), ('C', self.C[k]),
                             ('D', self.D[k])):
                if M.size:
                    body = np.array2string(M, precision=4, suppress_small=True)
                    lines.append(f"  {label} = " + body.replace('\n', '\n      '))
        return '\n'.join(lines)

    # -- conversions --------------------------------------------------------

    def to_ltpss(self):
        """The same system as an `LTPStateSpace` (constant dimensions only).

        Examples
        --------
        >>> sys = ltp.dltpss([[[0.5]], [[0.2]]], [[[1.0]]], [[[1.0]]], 0)
        >>> sys.to_ltpss().nsteps
        2
        """
        if not self.has_constant_dimensions:
            raise ControlDimension("the dimensions vary over the period: the system has no "
                                   "LTPStateSpace form")
        from .ltpsys import LTPStateSpace
        return LTPStateSpace(np.array(self.A), np.array(self.B), np.array(self.C),
                             np.array(self.D), self.period, dt=self.dt, name=self.name)

    def shifted(self, start):
        """The system seen from step `start`: matrices ``A[start + k]``, ...

        Examples
        --------
        >>> sys = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
        ...                  [[[1.0, 0.0]], [[1.0]]], 0)
        >>> sys.shifted(1).nstates
        (1, 2)
        """
        N = self.nsteps
        if not isinstance(start, numbers.Integral):
            raise ControlArgument(f"start must be an integer step, got {start!r}")
        idx = [(start + k) % N for k in range(N)]
        return DiscreteLTPSystem(*([M[i] for i in idx] for M in (self.A, self.B, self.C,
                                                                 self.D)),
                                 dt=self.dt, name=self.name)

    # -- Floquet theory -----------------------------------------------------

    def floquet_multipliers(self, start=0):
        """Characteristic multipliers at step `start` (module notes).

        Returns the ``n_min = min_k n_k`` core multipliers by decreasing
        modulus, followed by ``n_start - n_min`` zeros.

        Examples
        --------
        >>> sys = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
        ...                  [[[1.0, 0.0]], [[1.0]]], 0)
        >>> sys.floquet_multipliers()        # core 1*1 + 2*0.5 = 2, padded
        array([2.+0.j, 0.+0.j])
        """
        return cyclic_multipliers(self.A, start)

    def is_stable(self, tol=1e-10):
        """True when every core multiplier lies inside the unit circle.

        Examples
        --------
        >>> sys = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
        ...                  [[[1.0, 0.0]], [[1.0]]], 0)
        >>> sys.is_stable(), sys.feedback(0.4).is_stable()
        (False, True)
        """
        return _is_stable(self, tol)

    def poles(self):
        """Per-step poles ``μ^{1/N}`` of the core multipliers (zeros are kept)."""
        mu = self.floquet_multipliers()
        return mu.astype(complex) ** (1.0 / self.nsteps)

    # -- simulation ---------------------------------------------------------

    def forced_response(self, U, x0=None):
        """Response to the inputs ``U[k]`` for k = 0..K-1.

        Parameters
        ----------
        U : array_like, shape (K, m), or list of K vectors
            Input at each step (vectors of length ``m_{k mod N}``).
        x0 : array_like, optional
            Initial state, length ``n_0`` (default zero).

        Returns
        -------
        y : ndarray (K, p) or list
            Outputs (an array when the output dimension is constant).
        x : list of ndarray
            States ``x[0] .. x[K]``.

        Examples
        --------
        >>> sys = ltp.dltpss([[[0.5]]], [[[1.0]]], [[[1.0]]], 0)
        >>> y, x = sys.forced_response(np.ones((3, 1)))
        >>> y[:, 0]
        array([0. , 1. , 1.5])
        """
        N = self.nsteps
        if isinstance(U, (list, tuple)) and any(np.ndim(u) != np.ndim(U[0]) or
                                                np.shape(u) != np.shape(U[0]) for u in U):
            U = [real_array(u, f'U[{k}]', ndim=(0, 1)).reshape(-1) for k, u in enumerate(U)]
        else:
            U = real_array(U, 'U', ndim=(1, 2))
            U = U[:, None] if U.ndim == 1 else U
        x = np.zeros(self.nstates[0]) if x0 is None else \
            real_array(x0, 'x0', ndim=(1,))
        if x.shape[0] != self.nstates[0]:
            raise ControlDimension(f"x0 must have {self.nstates[0]} entries, got {x.shape[0]}")
        xs, ys = [x], []
        for j in range(len(U)):
            k = j % N
            u = np.asarray(U[j], float).reshape(-1)
            if u.shape[0] != self.ninputs[k]:
                raise ControlDimension(f"U[{j}] must have {self.ninputs[k]} entries "
                                       f"(m_{k}), got {u.shape[0]}")
            ys.append(self.C[k] @ x + self.D[k] @ u)
            x = self.A[k] @ x + self.B[k] @ u
            xs.append(x)
        if len(set(self.noutputs)) == 1:
            ys = np.array(ys).reshape(len(ys), self.noutputs[0])
        return ys, xs

    # -- interconnection ----------------------------------------------------

    def __mul__(self, other):
        """Series connection ``self * other`` (other's output drives self)."""
        return series_tv(other, self)

    def __rmul__(self, other):
        """``other * self``: a static gain (matrix) or system after `self`."""
        return series_tv(self, other)

    def __add__(self, other):
        return parallel_tv(self, other)

    def __neg__(self):
        return DiscreteLTPSystem(self.A, self.B, [-c for c in self.C], [-d for d in self.D],
                                 self.dt, name=self.name)

    def __sub__(self, other):
        return parallel_tv(self, -as_tv(other, self))

    def feedback(self, other=None, sign=-1):
        """Feedback ``u = r + sign * other(y)`` (static gains or a system).

        Examples
        --------
        >>> P = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
        ...                [[[1.0, 0.0]], [[1.0]]], 0)
        >>> L = P.feedback(0.4)                 # u = r - 0.4 y
        >>> L.nstates, round(float(L.floquet_multipliers()[0].real), 12)
        ((2, 1), 0.8)
        """
        return feedback_tv(self, other, sign)


def dltpss(A, B=None, C=None, D=0, dt=1.0, *, name=None):
    """Create a discrete periodic system, dimensions allowed to vary with k.

    Parameters
    ----------
    A, B, C, D : list of array_like, or array_like
        The matrices of one period: a list of ``N_i`` 2D arrays (shapes may
        vary with k: ``A[k]`` is ``n_{k+1} x n_k``), a 3D array (constant
        shapes), or one 2D array (the same at every step).  The lengths may
        differ: the system has period ``lcm(N_A, N_B, N_C, N_D)``.  ``D = 0``
        is a zero feedthrough.
    dt : float
        Sampling time (default 1).
    name : str, optional
        System name.

    Returns
    -------
    DiscreteLTPSystem

    Raises
    ------
    ControlDimension
        If the dimension chain ``A[k]: n_k -> n_{k+1}`` does not close or the
        shapes of B, C, D do not fit it (the message names the matrix and
        step).

    Notes
    -----
    ``dltpss(sys)`` converts a discrete-time `LTPStateSpace`.

    Examples
    --------
    A of period 3 and B of period 2 give a period of 6 steps:

    >>> A = [[[0.5]], [[0.2]], [[-0.3]]]
    >>> sys = ltp.dltpss(A, [[[1.0]], [[0.0]]], [[1.0]], 0)
    >>> sys.nsteps
    6
    """
    if B is None and C is None:
        sys = A
        if not (hasattr(sys, 'nsteps') and sys.isdtime(strict=True)):
            raise ControlArgument("dltpss(sys) needs a discrete-time LTPStateSpace")
        N = sys.nsteps
        mats = [list(M.sample(N)) for M in (sys.A, sys.B, sys.C, sys.D)]
        return DiscreteLTPSystem(*mats, dt=sys.dt, name=sys.name if name is None else name)
    if B is None or C is None:
        raise ControlArgument("dltpss expects (A, B, C, D[, dt]) or (sys)")
    return DiscreteLTPSystem(A, B, C, D, dt, name=name)


def check_chain(A, name='A'):
    """Dimensions ``n_k`` of a closed chain ``A_k: n_k -> n_{k+1}`` (ControlDimension if open).

    Examples
    --------
    >>> from ltpcontrol._core.tvsystem import check_chain
    >>> check_chain([np.ones((1, 2)), np.ones((2, 1))])
    [2, 1]
    >>> check_chain([np.ones((1, 2)), np.ones((3, 1))])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    control.exception.ControlDimension: A[1] has 3 rows but A[0] has 2 columns: ...
    """
    N = len(A)
    n = [a.shape[1] for a in A]
    for k in range(N):
        if A[k].shape[0] != n[(k + 1) % N]:
            raise ControlDimension(f"{name}[{k}] has {A[k].shape[0]} rows but "
                                   f"{name}[{(k + 1) % N}] has {n[(k + 1) % N]} columns: the "
                                   "dimension chain n_(k+1) x n_k does not close")
    return n


def as_tv(sys, like=None, name='sys'):
    """Return `sys` as a `DiscreteLTPSystem` (LTPStateSpace, static gain allowed).

    A discrete-time `LTPStateSpace` or `control.StateSpace` is converted; a
    number or matrix becomes a static gain with the sampling time of `like`.

    Examples
    --------
    >>> from ltpcontrol._core.tvsystem import as_tv
    >>> sysd = ltp.ltpss(np.array([[[0.5]], [[0.2]]]), [[1.0]], [[1.0]], 0,
    ...                  period=2.0, dt=1.0)
    >>> as_tv(sysd).nstates, as_tv([[2.0, 1.0]], like=as_tv(sysd)).nstates
    ((1, 1), (0,))
    """
    if isinstance(sys, DiscreteLTPSystem):
        return sys
    if hasattr(sys, 'nsteps') and hasattr(sys, 'isdtime') and sys.isdtime(strict=True):
        return dltpss(sys)
    if isinstance(sys, ct.StateSpace) and sys.isdtime(strict=True):
        return DiscreteLTPSystem([sys.A], [sys.B], [sys.C], [sys.D],
                                 like.dt if like is not None else sys.dt)
    if like is not None and isinstance(sys, (numbers.Real, np.ndarray, list)):
        K = np.atleast_2d(np.asarray(sys, float))
        return DiscreteLTPSystem([np.zeros((0, 0))], [np.zeros((0, K.shape[1]))],
                                 [np.zeros((K.shape[0], 0))], [K], like.dt)
    raise ControlArgument(f"{name} must be a discrete periodic system, got "
                          f"{type(sys).__name__}")


#
# Floquet analysis through the public functions (``ltp.floquet_multipliers(sys)``...)
#

def _no_nsteps(nsteps):
    if nsteps is not None:
        raise ControlArgument("nsteps applies to continuous-time systems only; a "
                              "discrete-time system has N = period/dt steps")


@override('floquet_multipliers', DiscreteLTPSystem)
def _floquet_multipliers(sys, nsteps=None):
    """`ltpcontrol.floquet_multipliers` with time-varying dimensions (module notes).

    Examples
    --------
    >>> sys = ltp.dltpss([[[1.0, 0.0]], [[1.0], [1.0]]], [[[1.0]], [[1.0], [1.0]]],
    ...                  [[[1.0, 1.0]], [[1.0]]], [[1.0]])
    >>> ltp.floquet_multipliers(sys)        # core multiplier [1 0][1; 1] = 1, padded
    array([1.+0.j, 0.+0.j])
    """
    _no_nsteps(nsteps)
    return sys.floquet_multipliers()


@override('floquet_exponents', DiscreteLTPSystem)
def _floquet_exponents(sys, nsteps=None):
    """`ltpcontrol.floquet_exponents`: the per-step values ``μ^{1/N}`` (see `poles`).

    Examples
    --------
    >>> sys = ltp.dltpss([[[4.0, 0.0]], [[1.0], [1.0]], [[2.0, 0.0], [0.0, 1.0]]],
    ...                  [[[1.0]], [[1.0], [1.0]], [[1.0], [2.0]]],
    ...                  [[[1.0, 1.0]], [[1.0]], [[1.0, 0.0]]], [[1.0]])
    >>> np.round(ltp.floquet_exponents(sys).real, 12)       # cube root of 8, and 0
    array([2., 0.])
    """
    _no_nsteps(nsteps)
    return sys.poles()


@override('monodromy', DiscreteLTPSystem)
def _monodromy(sys, nsteps=None):
    """`ltpcontrol.monodromy`: the cyclic product ``A_{N-1} ... A_0`` (``n_0 x n_0``).

    Examples
    --------
    >>> sys = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                  [[[1.0, 0.0]], [[1.0]]], 0)
    >>> ltp.monodromy(sys)
    array([[1. , 2. ],
           [0.5, 1. ]])
    """
    _no_nsteps(nsteps)
    P = np.eye(sys.nstates[0])
    for a in sys.A:
        P = a @ P
    return P


@override('is_stable', DiscreteLTPSystem)
def _is_stable(sys, tol=1e-10, nsteps=None, *, autonomous=False):
    """`ltpcontrol.is_stable`: every core multiplier inside ``|μ| < 1 - tol``.

    Examples
    --------
    >>> sys = ltp.dltpss([[[1.0, 0.0]], [[0.5], [1.0]]], [[[1.0]], [[1.0], [1.0]]],
    ...                  [[[1.0, 1.0]], [[1.0]]], 0)
    >>> ltp.is_stable(sys), ltp.is_stable(sys, autonomous=True)
    (True, True)
    """
    _no_nsteps(nsteps)
    if isinstance(tol, (bool, np.bool_)) or not isinstance(tol, numbers.Real) \
            or not 0 <= tol < 1:
        raise ValueError(f"tol must be a number in [0, 1), got {tol!r}")
    mu = cyclic_multipliers(sys.A, int(np.argmin(sys.nstates)))     # the core ones
    if autonomous:
        if mu.size == 0:
            raise ValueError("autonomous=True needs at least one multiplier (the phase one)")
        mu = np.delete(mu, np.argmin(np.abs(mu - 1)))
    return bool(np.all(np.abs(mu) < 1 - tol))


def cyclic_multipliers(A, start=0):
    """Core multipliers of the cyclic product of `A` at `start`, zero-padded.

    Examples
    --------
    >>> from ltpcontrol._core.tvsystem import cyclic_multipliers
    >>> cyclic_multipliers([np.array([[1.0, 1.0]]), np.array([[1.0], [0.0]])])
    array([1.+0.j, 0.+0.j])
    """
    N = len(A)
    n = [a.shape[1] for a in A]
    # form the product from the step of smallest dimension: its eigenvalues
    # are exactly the core multipliers (no spurious zeros to separate)
    j = int(np.argmin(n))
    mu = _rescaled(A, j)
    mu = mu[np.lexsort((-mu.imag, -np.abs(mu)))] if mu.size else mu.astype(complex)
    return np.concatenate([mu.astype(complex), np.zeros(n[start % N] - n[j], complex)])


def _rescaled(A, j):
    """Eigenvalues of the cyclic product from step j (rescaled against overflow)."""
    N = len(A)
    P = np.eye(A[j].shape[1])
    logscale = 0.0
    for i in range(N):
        P = A[(j + i) % N] @ P
        s = np.abs(P).max(initial=0.0)
        if s > 1e100 or (0 < s < 1e-100):
            P = P / s
            logscale += np.log(s)
    if logscale == 0.0:
        return np.linalg.eigvals(P) if P.size else np.zeros(0, complex)
    return np.linalg.eigvals(P) * np.exp(logscale)


#
# Interconnections
#

def series_tv(sys1, sys2):
    """``sys2 ∘ sys1``: the output of `sys1` drives `sys2` (state ``[x1; x2]``).

    Examples
    --------
    >>> from ltpcontrol._core.tvsystem import series_tv
    >>> P = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                [[[1.0, 0.0]], [[1.0]]], 0)
    >>> series_tv(P, 2.0).nstates, series_tv(P, P).nstates      # a gain, a system
    ((2, 1), (4, 2))
    """
    def step(k, a1, b1, c1, d1, a2, b2, c2, d2):
        if c1.shape[0] != b2.shape[1]:
            raise ControlDimension(f"step {k}: sys1 has {c1.shape[0]} outputs but sys2 "
                                   f"has {b2.shape[1]} inputs")
        return (np.block([[a1, np.zeros((a1.shape[0], a2.shape[1]))], [b2 @ c1, a2]]),
                np.vstack([b1, b2 @ d1]), np.hstack([d2 @ c1, c2]), d2 @ d1)
    return _stepwise(sys1, sys2, step)


def parallel_tv(sys1, sys2):
    """``sys1 + sys2`` (same inputs and outputs at every step).

    Examples
    --------
    >>> from ltpcontrol._core.tvsystem import parallel_tv
    >>> P = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                [[[1.0, 0.0]], [[1.0]]], 0)
    >>> S = parallel_tv(P, P)
    >>> S.nstates, bool(np.allclose(ltp.lift(S, method='time').D,
    ...                             2 * ltp.lift(P, method='time').D))
    ((4, 2), True)
    """
    def step(k, a1, b1, c1, d1, a2, b2, c2, d2):
        if d1.shape != d2.shape:
            raise ControlDimension(f"step {k}: the systems have input/output shapes "
                                   f"{d1.shape} and {d2.shape}")
        return (_blkdiag(a1, a2), np.vstack([b1, b2]), np.hstack([c1, c2]), d1 + d2)
    return _stepwise(sys1, sys2, step)


def feedback_tv(sys1, sys2=None, sign=-1):
    """``u1 = r + sign y2``, ``u2 = y1``; closed loop from r to y1.

    Examples
    --------
    >>> from ltpcontrol._core.tvsystem import feedback_tv
    >>> P = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                [[[1.0, 0.0]], [[1.0]]], 0)
    >>> np.round(feedback_tv(P, 0.4).floquet_multipliers().real, 12)   # 2 - 0.4 * 3
    array([0.8, 0. ])
    """
    if sys2 is None:
        sys2 = np.eye(sys1.noutputs[0]) if len(set(sys1.noutputs)) == 1 else None
        if sys2 is None:
            raise ControlArgument("feedback: give the feedback system when the output "
                                  "dimension varies")

    def step(k, a1, b1, c1, d1, a2, b2, c2, d2):
        m1, p1 = d1.shape[1], d1.shape[0]
        if d2.shape != (m1, p1):
            raise ControlDimension(f"step {k}: the feedback system must map {p1} outputs "
                                   f"to {m1} inputs, got shape {d2.shape}")
        # u1 = r + sign (c2 x2 + d2 y1), y1 = c1 x1 + d1 u1
        try:
            Einv = np.linalg.inv(np.eye(m1) - sign * d2 @ d1)
        except np.linalg.LinAlgError:
            raise ValueError(f"feedback: the algebraic loop is singular at step {k}") from None
        # u1 = Einv (r + sign d2 c1 x1 + sign c2 x2)
        Fu = Einv @ np.hstack([sign * d2 @ c1, sign * c2])
        Ax = np.block([[a1, np.zeros((a1.shape[0], a2.shape[1]))], [b2 @ c1, a2]])
        Bx = np.vstack([b1, b2 @ d1])
        return (Ax + Bx @ Fu, Bx @ Einv,
                np.hstack([c1, np.zeros((p1, a2.shape[1]))]) + d1 @ Fu, d1 @ Einv)
    return _stepwise(sys1, sys2, step, name=sys1.name + '$feedback', other='other')


def _stepwise(sys1, sys2, step, name=None, other='sys2'):
    """The system of the step matrices ``step(k, A1, B1, C1, D1, A2, B2, C2, D2)``
    of two systems (gains allowed) on their common period."""
    sys1 = as_tv(sys1, sys2 if isinstance(sys2, DiscreteLTPSystem) else None, 'sys1')
    sys2 = as_tv(sys2, sys1, other)
    s1, s2, N, dt = _common(sys1, sys2)
    mats = [step(k, *(M[k] for M in (s1.A, s1.B, s1.C, s1.D, s2.A, s2.B, s2.C, s2.D)))
            for k in range(N)]
    return DiscreteLTPSystem(*(list(M) for M in zip(*mats)), dt=dt, name=name)


def _common(s1, s2):
    if abs(s1.dt - s2.dt) > 1e-12 * max(s1.dt, s2.dt):
        raise ValueError(f"the systems have different sampling times {s1.dt} and {s2.dt}")
    N = common_steps([s1.nsteps, s2.nsteps], ['sys1', 'sys2'])
    return _repeat(s1, N), _repeat(s2, N), N, s1.dt


def _repeat(sys, N):
    if sys.nsteps == N:
        return sys
    r = N // sys.nsteps
    return DiscreteLTPSystem(*(list(M) * r for M in (sys.A, sys.B, sys.C, sys.D)),
                             dt=sys.dt, name=sys.name)


def _blkdiag(a, b):
    out = np.zeros((a.shape[0] + b.shape[0], a.shape[1] + b.shape[1]))
    out[:a.shape[0], :a.shape[1]] = a
    out[a.shape[0]:, a.shape[1]:] = b
    return out


def _is_zero(D):
    return isinstance(D, numbers.Real) and float(D) == 0.0


def _sequence(M, name):
    """A list of N 2D float arrays from a list, a 3D array or a 2D array."""
    if isinstance(M, (list, tuple)) and len(M) and all(np.ndim(m) == 2 for m in M) \
            and len({np.shape(m) for m in M}) > 1:
        return [real_array(m, f'{name}[{k}]', ndim=(2,)) for k, m in enumerate(M)]
    if isinstance(M, (list, tuple)) and len(M) == 0:
        raise ValueError(f"{name} must hold at least one matrix")
    arr = real_array(M, name, ndim=(0, 1, 2, 3))
    if arr.ndim < 2:
        arr = np.atleast_2d(arr)
    if arr.ndim == 2:
        return [arr]
    return [arr[k] for k in range(arr.shape[0])]
