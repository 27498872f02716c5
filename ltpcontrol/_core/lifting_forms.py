"""Time-lifted forms of discrete periodic systems, dimensions allowed to vary.

For ``x_{k+1} = A_k x_k + B_k u_k``, ``y_k = C_k x_k + D_k u_k`` with N
steps per period (``A_k``: ``n_{k+1} x n_k``), the input and output of
period p are stacked, ``U_p = [u_{pN}; ...; u_{pN+N-1}]`` and likewise
``Y_p``.

* standard (Meyer-Burrus), ``method='time'``: state ``x_{pN}`` (``n_0``),
  ``x_{(p+1)N} = Φ x_{pN} + Γ U_p``, ``Y_p = 𝒞 x_{pN} + 𝒟 U_p`` with the
  monodromy ``Φ = A_{N-1}...A_0``, ``Γ = [Φ(N,1)B_0, ..., B_{N-1}]``,
  ``𝒞`` block k ``C_kΦ(k,0)`` and the block lower triangular ``𝒟``
  (``C_kΦ(k,j+1)B_j`` below the diagonal, ``D_k`` on it).  It runs once
  per period (``dt = N dt_sys``).
* stacked (Grasselli-Longhi), ``method='stacked'``: the descriptor system
  ``E z_{p+1} = 𝒜 z_p + ℬ U_p``, ``Y_p = 𝒞 z_p + 𝒟 U_p`` with
  ``z_p = [x_{pN}; ...; x_{pN+N-1}]`` (size ``Σ n_k``), ``E = blkdiag(I_{n_0},
  0, ..., 0)``; block row 0 is ``x_{(p+1)N} = A_{N-1}x_{pN+N-1} +
  B_{N-1}u_{pN+N-1}`` and block row k >= 1 the constraint ``0 = A_{k-1}
  x_{pN+k-1} - x_{pN+k} + B_{k-1}u_{pN+k-1}``; ``𝒞 = blkdiag(C_k)``,
  ``𝒟 = blkdiag(D_k)``.  Its transfer function ``𝒞(zE - 𝒜)⁻¹ℬ + 𝒟`` is
  that of the standard form; no product of matrices is formed, so it suits
  long periods (``sparse=True``) and the computation of zeros.
* cyclic (Flamm), ``method='cyclic'``: the LTI system at the base rate with
  state ``Σ n_k``, ``𝒜`` holding ``A_k`` in block (k+1 mod N, k), ``ℬ``
  holding ``B_k`` in block (k+1 mod N, k), ``𝒞 = blkdiag(C_k)``, ``𝒟 =
  blkdiag(D_k)``; its eigenvalues are the N-th roots of the core
  multipliers (and zeros), and its transfer function block (i, j) is
  ``z^{j-i} H_ij(z^N)`` with H the standard lifted one.

`unlift` goes back: the stacked and cyclic forms return the original
matrices; a standard-form LTI system ``(Φ, Γ, 𝒞, 𝒟)`` (𝒟 block lower
triangular) returns the periodic realization with state
``[x_{pN}; u_{pN}; ...; u_{pN+k-1}]`` at step k, whose standard lifting is
the given system exactly (its order varies with k; `ltpcontrol.minreal`
reduces it).
"""

import numpy as np
import scipy.sparse as sps
import control as ct
from control.exception import ControlArgument

from .tvsystem import DiscreteLTPSystem, dltpss
from .validation import check_positive, check_positive_int, real_array

__all__ = ['unlift']

_FORMS = ('time', 'stacked', 'cyclic')


def lift_form(sys, method, *, start=0, sparse=False, name=None, nharmonics=None):
    """`ltpcontrol.lift` for the time-domain forms and `DiscreteLTPSystem` (module notes).

    Examples
    --------
    >>> from ltpcontrol._core.lifting_forms import lift_form
    >>> sys = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                  [[[1.0, 0.0]], [[1.0]]], 0)
    >>> lift_form(sys, 'time').nstates, lift_form(sys, 'time', start=1).nstates
    (2, 1)
    >>> [M.shape for M in lift_form(sys, 'stacked')]           # A, E, B, C, D
    [(3, 3), (3, 3), (3, 2), (2, 3), (2, 2)]
    """
    if method not in _FORMS:
        raise ValueError(f"method must be one of {_FORMS} for this system, got {method!r}")
    if nharmonics is not None:
        raise ValueError("nharmonics only applies to method='frequency'")
    if not isinstance(sparse, (bool, np.bool_)):
        raise ControlArgument(f"sparse must be True or False, got {sparse!r}")
    if isinstance(sys, DiscreteLTPSystem):
        tv = sys
    else:
        if not (hasattr(sys, 'nsteps') and sys.isdtime(strict=True)):
            raise ValueError("sysd must be a discrete-time periodic system")
        tv = dltpss(sys)
    start = check_positive_int(start, 'start', minimum=0)
    if start >= tv.nsteps:
        raise ValueError(f"start={start} must be a step of the period, 0..{tv.nsteps - 1}")
    tv = tv.shifted(start) if start else tv
    name = (tv.name + '$lifted') if name is None else name
    if method == 'time':
        if sparse:
            raise ValueError("sparse applies to the 'stacked' and 'cyclic' forms only")
        mats = tv_time_lift(tv)
        return ct.ss(*mats, tv.period, name=name)
    if method == 'stacked':
        return _stacked(tv, sparse)
    mats = _cyclic(tv, sparse)
    return mats if sparse else ct.ss(*mats, tv.dt, name=name)


def tv_time_lift(sys):
    """Standard (Meyer-Burrus) lifting ``(Φ, Γ, 𝒞, 𝒟)`` of a `DiscreteLTPSystem`.

    Examples
    --------
    >>> from ltpcontrol._core.lifting_forms import tv_time_lift
    >>> sys = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                  [[[1.0, 0.0]], [[1.0]]], 0)
    >>> A, B, C, D = tv_time_lift(sys)
    >>> A                      # the monodromy A_1 A_0 at step 0
    array([[1. , 2. ],
           [0.5, 1. ]])
    >>> D                      # y_1 = C_1 B_0 u_0
    array([[0., 0.],
           [1., 0.]])
    """
    N = sys.nsteps
    n0 = sys.nstates[0]
    m, p = sys.ninputs, sys.noutputs
    moff = np.concatenate([[0], np.cumsum(m)]).astype(int)
    poff = np.concatenate([[0], np.cumsum(p)]).astype(int)
    Phi = np.eye(n0)
    G = np.zeros((n0, moff[-1]))          # x_k = Phi x_0 + G U
    C = np.zeros((poff[-1], n0))
    D = np.zeros((poff[-1], moff[-1]))
    for k in range(N):
        C[poff[k]:poff[k + 1]] = sys.C[k] @ Phi
        D[poff[k]:poff[k + 1]] = sys.C[k] @ G
        D[poff[k]:poff[k + 1], moff[k]:moff[k + 1]] = sys.D[k]
        Phi = sys.A[k] @ Phi
        G = sys.A[k] @ G
        G[:, moff[k]:moff[k + 1]] = sys.B[k]
    return Phi, G, C, D


def _offsets(sizes):
    return np.concatenate([[0], np.cumsum(sizes)]).astype(int)


def _stacked(sys, sparse):
    N, n = sys.nsteps, sys.nstates
    no, mo, A, B, C, D = _step_blocks(sys)
    E = sps.lil_matrix(A.shape)
    E[:n[0], :n[0]] = np.eye(n[0])
    # row 0: x_{(p+1)N} = A_{N-1} x_{N-1} + B_{N-1} u_{N-1}
    A[:n[0], no[N - 1]:no[N]] = sys.A[N - 1]
    B[:n[0], mo[N - 1]:mo[N]] = sys.B[N - 1]
    for k in range(1, N):
        # row k: 0 = A_{k-1} x_{k-1} - x_k + B_{k-1} u_{k-1}
        A[no[k]:no[k + 1], no[k - 1]:no[k]] = sys.A[k - 1]
        A[no[k]:no[k + 1], no[k]:no[k + 1]] = -np.eye(n[k])
        B[no[k]:no[k + 1], mo[k - 1]:mo[k]] = sys.B[k - 1]
    return _finished((A, E, B, C, D), sparse)


def _cyclic(sys, sparse):
    N = sys.nsteps
    no, mo, A, B, C, D = _step_blocks(sys)
    for k in range(N):
        k1 = (k + 1) % N
        A[no[k1]:no[k1 + 1], no[k]:no[k + 1]] = sys.A[k]
        B[no[k1]:no[k1 + 1], mo[k]:mo[k + 1]] = sys.B[k]
    return _finished((A, B, C, D), sparse)


def _step_blocks(sys):
    """State and input offsets, empty state and input matrices of the stacked
    states (to be filled), and the block diagonal ``C = blkdiag(C_k)``, ``D``."""
    no, mo = _offsets(sys.nstates), _offsets(sys.ninputs)
    return (no, mo, sps.lil_matrix((no[-1], no[-1])), sps.lil_matrix((no[-1], mo[-1])),
            sps.block_diag(sys.C, format='csr'), sps.block_diag(sys.D, format='csr'))


def _finished(mats, sparse):
    mats = tuple(sps.csr_matrix(M) for M in mats)
    return mats if sparse else tuple(M.toarray() for M in mats)


def unlift(lifted, nsteps=None, *, method='time', ninputs=None, noutputs=None,
           nstates=None, dt=None, name=None):
    """The discrete periodic system of a time-lifted form (inverse of `lift`).

    Parameters
    ----------
    lifted : control.StateSpace or tuple
        The standard ('time') or cyclic form as a `control.StateSpace`
        (the 'cyclic' form also as the tuple ``(A, B, C, D)``, dense or
        sparse), or the stacked form as the tuple ``(A, E, B, C, D)``.
    nsteps : int
        N, the steps of the period.
    method : {'time', 'stacked', 'cyclic'}
    ninputs, noutputs : int or sequence of int, optional
        Inputs and outputs per step (default: equal shares of the lifted
        ones).
    nstates : sequence of int, optional
        'stacked' and 'cyclic': the state dimensions ``n_k`` (default:
        equal shares).
    dt : float, optional
        Sampling time of the result (default: ``lifted.dt / N`` for 'time',
        ``lifted.dt`` for 'cyclic', 1 otherwise).
    name : str, optional

    Returns
    -------
    DiscreteLTPSystem

    Raises
    ------
    ValueError
        If the standard form's 𝒟 is not block lower triangular (the lifted
        system is not causal per step), or the sizes do not split.

    Examples
    --------
    >>> sys = ltp.dltpss([[[1.0, 2.0]], [[1.0], [0.5]]], [[[1.0]], [[0.0], [1.0]]],
    ...                  [[[1.0, 0.0]], [[1.0]]], 0)
    >>> back = ltp.unlift(ltp.lift(sys, method='cyclic'), 2, method='cyclic',
    ...                   nstates=sys.nstates)
    >>> bool(all(np.array_equal(a, b) for a, b in zip(back.A, sys.A)))
    True
    >>> L = ltp.lift(sys, method='time')
    >>> L2 = ltp.lift(ltp.unlift(L, 2), method='time')
    >>> bool(np.allclose(L2.D, L.D) and np.allclose(L2.C @ L2.B, L.C @ L.B))
    True
    """
    N = check_positive_int(nsteps, 'nsteps')
    if method not in _FORMS:
        raise ValueError(f"method must be one of {_FORMS}, got {method!r}")
    if method == 'stacked':
        if not (isinstance(lifted, tuple) and len(lifted) == 5):
            raise ControlArgument("the stacked form is the tuple (A, E, B, C, D)")
        A, E, B, C, D = (_dense(M, nm) for M, nm in zip(lifted, 'AEBCD'))
        dt = 1.0 if dt is None else check_positive(dt, 'dt')
    elif isinstance(lifted, tuple):
        if method != 'cyclic' or len(lifted) != 4:
            raise ControlArgument("lifted must be a control.StateSpace (or, cyclic form, "
                                  "the tuple (A, B, C, D))")
        A, B, C, D = (_dense(M, nm) for M, nm in zip(lifted, 'ABCD'))
        dt = 1.0 if dt is None else check_positive(dt, 'dt')
    elif isinstance(lifted, ct.StateSpace):
        A, B, C, D = lifted.A, lifted.B, lifted.C, lifted.D
        base = lifted.dt if lifted.dt not in (None, True, 0) else N
        if dt is None:
            dt = base / N if method == 'time' else base
        dt = check_positive(dt, 'dt')
    else:
        raise ControlArgument(f"lifted must be a control.StateSpace or a tuple, got "
                              f"{type(lifted).__name__}")
    m = _split(B.shape[1], N, ninputs, 'ninputs')
    p = _split(C.shape[0], N, noutputs, 'noutputs')
    mo, po = _offsets(m), _offsets(p)
    if method == 'time':
        n0 = A.shape[0]
        for k in range(N):
            if np.abs(D[po[k]:po[k + 1], mo[k + 1]:]).max(initial=0.0) > 0:
                raise ValueError("the lifted D is not block lower triangular: output "
                                 f"step {k} depends on later inputs (not a lifted system)")
        As, Bs, Cs, Ds = [], [], [], []
        for k in range(N):
            nk = n0 + mo[k]
            if k < N - 1:
                As.append(np.vstack([np.eye(nk), np.zeros((m[k], nk))]))
                Bs.append(np.vstack([np.zeros((nk, m[k])), np.eye(m[k])]))
            else:
                As.append(np.hstack([A, B[:, :mo[k]]]))
                Bs.append(B[:, mo[k]:mo[k + 1]])
            Cs.append(np.hstack([C[po[k]:po[k + 1]], D[po[k]:po[k + 1], :mo[k]]]))
            Ds.append(D[po[k]:po[k + 1], mo[k]:mo[k + 1]])
        return DiscreteLTPSystem(As, Bs, Cs, Ds, dt, name=name)
    n = _split(A.shape[0], N, nstates, 'nstates')
    no = _offsets(n)
    Cs = [C[po[k]:po[k + 1], no[k]:no[k + 1]] for k in range(N)]
    Ds = [D[po[k]:po[k + 1], mo[k]:mo[k + 1]] for k in range(N)]
    if method == 'cyclic':
        rows = [(k + 1) % N for k in range(N)]
        As = [A[no[r]:no[r + 1], no[k]:no[k + 1]] for k, r in enumerate(rows)]
        Bs = [B[no[r]:no[r + 1], mo[k]:mo[k + 1]] for k, r in enumerate(rows)]
    else:
        As = [A[no[k + 1]:no[k + 2], no[k]:no[k + 1]] for k in range(N - 1)] + \
             [A[:n[0], no[N - 1]:no[N]]]
        Bs = [B[no[k + 1]:no[k + 2], mo[k]:mo[k + 1]] for k in range(N - 1)] + \
             [B[:n[0], mo[N - 1]:mo[N]]]
    return DiscreteLTPSystem(As, Bs, Cs, Ds, dt, name=name)


def _dense(M, name):
    if sps.issparse(M):
        M = M.toarray()
    return real_array(M, name, ndim=(2,))


def _split(total, N, sizes, name):
    if sizes is None:
        if total % N:
            raise ValueError(f"{total} lifted {name[1:]} do not split into {N} equal steps; "
                             f"give {name}")
        return [total // N] * N
    if np.ndim(sizes) == 0:
        sizes = [int(sizes)] * N
    sizes = [int(s) for s in sizes]
    if len(sizes) != N or sum(sizes) != total or min(sizes) < 0:
        raise ValueError(f"{name} must be N = {N} non-negative sizes summing to {total}, "
                         f"got {sizes}")
    return sizes
