"""Step transition matrices of ``ẋ = A(t)x + B(t)u`` with held inputs.

For a step ``[t0, t0 + h]`` and an input that is linear in the step,
``u(τ) = u0 + σ (u1 - u0)`` with ``σ = (τ - t0)/h`` (first-order hold), the
exact solution is

    x(t0 + h) = Φ x(t0) + Γ0 u0 + Γ1 (u1 - u0),

where ``[[Φ, Γ0, Γ1], [0, I, 0], [0, 0, I]]`` is the transition matrix of the
augmented system ``ż = M(τ) z``, ``M = [[A, B, σB], [0, 0, 0], [0, 0, 0]]``.
It is computed with the sixth-order Magnus integrator (Blanes, Casas and Ros)

    α1 = δ M2,  α2 = √15/3 δ (M3 - M1),  α3 = 10/3 δ (M3 - 2 M2 + M1),
    C1 = [α1, α2],  C2 = -[α1, 2 α3 + C1]/60,
    Ω = α1 + α3/12 + [-20 α1 - α3 + C1, α2 + C2]/240,
    M_i = M(τ + c_i δ),  c_{1,2,3} = 1/2 - √15/10, 1/2, 1/2 + √15/10,

on m sub-steps of each smooth piece (switching instants split a step), with m
doubled until two resolutions agree (the Richardson-extrapolated value is
returned).  Without input, when A is constant between its switching
instants (its form says so), each segment is exactly ``e^{A h}``: one
matrix exponential, no sub-steps.  Everything is vectorised over steps.
"""

import warnings

import numpy as np
import scipy.linalg as la

from .memory import check_allocation
from .threads import small_blas

__all__ = []

#: Gauss-Legendre nodes of the sixth-order Magnus sub-step
_NODES = np.array([0.5 - np.sqrt(15) / 10, 0.5, 0.5 + np.sqrt(15) / 10])
#: sixth order: halving the sub-steps divides the error by 2^6; the error of
#: the finer of two resolutions is about their difference / (2^6 - 1)
_RICHARDSON = 2 ** 6 - 1


def step_transitions(A, B, t0, h, rtol=1e-12, max_substeps=2 ** 16, info=None):
    """Transition data of many steps ``[t0[k], t0[k] + h[k]]``.

    Parameters
    ----------
    A : PeriodicMatrix
        State matrix.
    B : PeriodicMatrix or None
        Input matrix (None or zero columns: no input).
    t0, h : ndarray
        Step starts and lengths (1D, same length).
    rtol : float
        Relative accuracy target.
    info : dict, optional
        Receives ``'substeps'``, the number of Magnus sub-steps per segment
        that met `rtol` (1 for exact exponentials), and ``'excess'``, the
        largest error estimate with one sub-step (against two) relative
        to the accepted error (0 for exact exponentials; the error of a
        sixth-order step scales as its length to the seventh).

    Returns
    -------
    Phi : ndarray, shape (S, n, n)
    Gamma0, Gamma1 : ndarray, shape (S, n, m)

    Examples
    --------
    >>> from ltpcontrol._core.transition import step_transitions
    >>> A = ltp.PeriodicMatrix.constant([[-1.0]], 1.0)
    >>> B = ltp.PeriodicMatrix.constant([[1.0]], 1.0)
    >>> Phi, G0, G1 = step_transitions(A, B, np.array([0.0]), 0.5)
    >>> bool(np.isclose(Phi[0, 0, 0], np.exp(-0.5)))
    True
    """
    t0 = np.asarray(t0, float)
    h = np.broadcast_to(np.asarray(h, float), t0.shape)
    n, m = A.shape[0], 0 if B is None else B.shape[1]
    # split every step at the switching instants that fall inside it
    bps = A.breakpoints if B is None else np.concatenate([A.breakpoints, B.breakpoints])
    seg_step, seg_a, seg_b = _segments(t0, h, np.unique(np.mod(bps, A.period)), A.period)
    if m == 0 and A._piecewise_constant:
        # A is constant on every segment: the transition is e^{A h}
        E = expm_batch((seg_b - seg_a)[:, None, None] * A._eval(0.5 * (seg_a + seg_b)))
        nsub, excess = 1, 0.0
    else:
        E, nsub, excess = _segment_transitions(A, B, seg_a, seg_b, t0[seg_step], h[seg_step],
                                               rtol, max_substeps)
    if info is not None:
        info['substeps'], info['excess'] = nsub, excess
    if len(seg_step) > len(t0):
        # compose the segments of each step in time order: E_last ... E_first
        d = n + 2 * m
        out = np.broadcast_to(np.eye(d), (len(t0), d, d)).copy()
        counts = np.bincount(seg_step, minlength=len(t0))
        pos = np.arange(len(seg_step)) - np.repeat(np.cumsum(counts) - counts, counts)
        for j in range(int(pos.max()) + 1):
            sel = pos == j
            out[seg_step[sel]] = E[sel] @ out[seg_step[sel]]
        E = out
    return E[:, :n, :n], E[:, :n, n:n + m], E[:, :n, n + m:]


#: probe steps that choose the common sub-step count of `uniform_transitions`
_PROBE_STEPS = 24


def uniform_transitions(A, t0, h, rtol=1e-12, max_substeps=2 ** 16):
    """Transition matrices of many steps of a smooth A, one sub-step count for all.

    For long runs of similar steps (the factors of a Floquet grid) the
    per-step doubling of `step_transitions` integrates every step at two
    or three resolutions.  Here the adaptive integration runs on probe
    steps spread over the run (and on the longest one); every step is then
    integrated once with the largest sub-step count the probes accepted,
    and a second, interleaved set of probes checks that count (error
    estimate from the half count, as in `step_transitions`).  If the check
    fails, every step is integrated adaptively.  Memory O(S n²).

    Parameters
    ----------
    A : PeriodicMatrix
    t0, h : ndarray
        Step starts and lengths (1D, same length).
    rtol : float
        Relative accuracy target.

    Returns
    -------
    Phi : ndarray, shape (S, n, n)

    Examples
    --------
    >>> from ltpcontrol._core.transition import uniform_transitions
    >>> A = ltp.PeriodicMatrix.from_function(
    ...     lambda t: np.array([[-1.0 + 0.5 * np.cos(2 * np.pi * t)]]), 1.0)
    >>> t = np.linspace(0, 1, 101)
    >>> Phi = uniform_transitions(A, t[:-1], np.diff(t))
    >>> bool(np.isclose(np.prod(Phi[:, 0, 0]), np.exp(-1.0)))
    True
    """
    t0 = np.asarray(t0, float)
    h = np.broadcast_to(np.asarray(h, float), t0.shape)
    S, n = len(t0), A.shape[0]
    if S <= 4 * _PROBE_STEPS or A._piecewise_constant or A.breakpoints.size or n == 0:
        return step_transitions(A, None, t0, h, rtol, max_substeps)[0]
    check_allocation((S, n, n), f"the transition matrices of {S} steps ({n} x {n})")
    spacing = (S - 1) / (_PROBE_STEPS - 1)
    probe = np.union1d(np.round(np.arange(_PROBE_STEPS) * spacing).astype(int),
                       [int(np.argmax(h))])
    with warnings.catch_warnings():
        warnings.simplefilter('error', UserWarning)
        try:
            _, nsub, _ = _segment_transitions(A, None, t0[probe], t0[probe] + h[probe],
                                              t0[probe], h[probe], rtol, max_substeps)
        except UserWarning:
            return step_transitions(A, None, t0, h, rtol, max_substeps)[0]
    scale = _balancing(A, n, n)
    out = np.empty((S, n, n))
    chunk = max(1, _CHUNK_ENTRIES // (n * n))
    check = np.unique(np.minimum(S - 1, np.round((np.arange(_PROBE_STEPS - 1) + 0.5)
                                                 * spacing).astype(int)))
    with small_blas(n):
        for c0 in range(0, S, chunk):
            sel = slice(c0, min(S, c0 + chunk))
            out[sel] = _magnus(A, None, t0[sel], t0[sel] + h[sel], t0[sel], h[sel], nsub,
                               n, 0, n, scale)
        if nsub >= 2:
            half = _magnus(A, None, t0[check], t0[check] + h[check], t0[check], h[check],
                           nsub // 2, n, 0, n, scale)
            E = out[check]
            err = np.abs(E - half).max(axis=(1, 2)) / _RICHARDSON
            if np.any(err > rtol * np.maximum(1.0, np.abs(E).max(axis=(1, 2)))):
                return step_transitions(A, None, t0, h, rtol, max_substeps)[0]
    if scale is not None:
        out *= scale[:, None] / scale[None, :]
    return out


def _segments(t0, h, bps, period):
    """Split each step at the switching instants ``bps + j T`` inside it.

    Returns the step index, start and end of every segment, steps in order
    and the segments of a step in time order.
    """
    nstep = len(t0)
    if bps.size == 0:
        idx = np.arange(nstep)
        return idx, t0.copy(), t0 + h
    b = t0 + h
    # candidates bps[i] + j T for the periods j0..j1 each step touches
    j0, j1 = np.floor(t0 / period), np.floor(b / period)
    count = ((j1 - j0 + 1) * bps.size).astype(int)
    step = np.repeat(np.arange(nstep), count)
    g = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    cand = bps[g % bps.size] + (j0[step] + g // bps.size) * period
    tol = 1e-12 * np.maximum(1.0, np.abs(b))
    inside = (cand > t0[step] + tol[step]) & (cand < b[step] - tol[step])
    # every step's points [t0, inner instants..., t0 + h], grouped by step
    key = np.concatenate([np.arange(nstep), step[inside], np.arange(nstep)])
    pts = np.concatenate([t0, cand[inside], b])
    order = np.argsort(key, kind='stable')
    key, pts = key[order], pts[order]
    same = key[:-1] == key[1:]
    return key[:-1][same], pts[:-1][same], pts[1:][same]


def _segment_transitions(A, B, a, b, step_t0, step_h, rtol, max_substeps):
    """Magnus transitions of the segments ``[a, b]``, refined segment by segment.

    Segments are processed in chunks whose working arrays fit a fixed
    budget; within a chunk each segment doubles its sub-steps until its own
    error estimate meets `rtol`, so the memory is O(S d²) whatever the
    number of sub-steps and the time is linear in the sub-steps.
    """
    n, m = A.shape[0], 0 if B is None else B.shape[1]
    d = n + 2 * m
    S = len(a)
    check_allocation((S, d, d), f"the transition matrices of {S} steps ({d} x {d})")
    out = np.empty((S, d, d))
    scale = _balancing(A, n, d)
    chunk = max(1, _CHUNK_ENTRIES // (d * d))
    nsub_max, excess, short = 1, 0.0, False
    with small_blas(d):
        for c0 in range(0, S, chunk):
            sel = np.arange(c0, min(S, c0 + chunk))
            nsub = 1
            prev = _magnus(A, B, a[sel], b[sel], step_t0[sel], step_h[sel], nsub, n, m, d,
                           scale)
            initial = True
            while sel.size:
                nsub *= 2
                E = _magnus(A, B, a[sel], b[sel], step_t0[sel], step_h[sel], nsub, n, m, d,
                            scale)
                err = np.abs(E - prev).max(axis=(1, 2))
                size = np.maximum(1.0, np.abs(E).max(axis=(1, 2)))
                ratio = err / _RICHARDSON / (rtol * size)
                if initial:
                    excess = max(excess, float(ratio.max()))
                    initial = False
                done = ratio <= 1
                if nsub >= max_substeps:
                    short = short or not np.all(done)
                    out[sel] = E
                    out[sel[done]] = E[done] + (E[done] - prev[done]) / _RICHARDSON
                    nsub_max = max(nsub_max, nsub)
                    break
                if np.any(done):
                    out[sel[done]] = E[done] + (E[done] - prev[done]) / _RICHARDSON
                    nsub_max = max(nsub_max, nsub)
                sel, prev = sel[~done], E[~done]
    if short:
        warnings.warn("transition matrices did not reach the requested accuracy "
                      f"with {max_substeps} sub-steps per step; use a finer time grid",
                      UserWarning, stacklevel=4)
    if scale is not None:
        out *= scale[:, None] / scale[None, :]
    return out, nsub_max, excess


#: entries (d² per matrix) of the working arrays of one chunk of the integrator
_CHUNK_ENTRIES = 2 ** 19
#: balance A when that divides its norm by more than this
_BALANCE_GAIN = 8.0
_BALANCE_PROBES = 16


def _balancing(A, n, d):
    """Diagonal scaling (powers of 2, exact) of badly scaled states, or None.

    Models in physical units (OpenFAST's metres, radians and their rates)
    can have ``‖A‖`` many orders above their eigenvalues; the similarity
    ``D⁻¹ A D`` that balances A (probed over the period) brings the norm,
    and with it the Magnus sub-steps needed, down to the scale of the
    dynamics.  Applied only when it divides the norm by more than 8, so
    well-scaled models are integrated unchanged.
    """
    if n < 2:
        return None
    T = A.period
    probe = np.concatenate([[0.0], A.breakpoints % T]) if A._piecewise_constant \
        else np.arange(_BALANCE_PROBES) * T / _BALANCE_PROBES
    At = np.abs(A._eval(probe)).max(axis=0)
    if not np.all(np.isfinite(At)):
        return None
    norm = np.abs(At).sum(axis=0).max()
    _, (s, _) = la.matrix_balance(At, permute=False, separate=True)
    balanced = (np.abs(At) * (s[None, :] / s[:, None])).sum(axis=0).max()
    if not balanced * _BALANCE_GAIN < norm:
        return None
    return np.concatenate([s, np.ones(d - n)])


def _tree_product(E):
    """``E[:, J-1] @ ... @ E[:, 0]`` for a stack (S, J, d, d), by pairwise products."""
    while E.shape[1] > 1:
        J = E.shape[1]
        pairs = E[:, 1:J - J % 2:2] @ E[:, 0:J - J % 2:2]
        E = np.concatenate([pairs, E[:, J - 1:]], axis=1) if J % 2 else pairs
    return E[:, 0]


def _rows_product(X, Y):
    """``X Y`` of stacks of first rows (..., n, d) (zero rows below): ``X[..., :n] @ Y``."""
    return X[..., :X.shape[-2]] @ Y


def _entries_product(X, Y):
    """The same for stacks stored entry by entry, (n, d, S): ``Σ_j X[:, j] Y[j]``.

    For a few states this is a few vector operations over the stack, where
    a batched matrix product pays a call per small matrix.
    """
    n = X.shape[0]
    out = X[:, 0, None] * Y[0]
    for j in range(1, n):
        out += X[:, j, None] * Y[j]
    return out


def _magnus6(M1, M2, M3, h, entrywise=False):
    """Sixth-order Magnus exponent from M at the three Gauss points of a step h.

    With ``α1 = h M2``, ``α2 = √15/3 h (M3 - M1)``, ``α3 = 10/3 h (M3 - 2 M2 + M1)``:
    ``Ω = α1 + α3/12 + [-20 α1 - α3 + C1, α2 + C2]/240``, ``C1 = [α1, α2]``,
    ``C2 = -[α1, 2 α3 + C1]/60`` (Blanes, Casas and Ros).

    The augmented M has zero rows below its first n (module notes), and so
    have all the α, commutators and Ω: the arguments and the result are
    those first n rows (shape (..., n, d), or (n, d, S) entry by entry with
    `entrywise`), and a product ``X Y`` of two such matrices is
    ``X[:, :n] Y`` (n²d instead of d³ multiplications).
    """
    product = _entries_product if entrywise else _rows_product

    def comm(X, Y):
        return product(X, Y) - product(Y, X)

    a1 = h * M2
    a2 = (np.sqrt(15) / 3) * h * (M3 - M1)
    a3 = (10 / 3) * h * (M3 - 2 * M2 + M1)
    C1 = comm(a1, a2)
    C2 = comm(a1, 2 * a3 + C1) / -60
    return a1 + a3 / 12 + comm(C1 - 20 * a1 - a3, a2 + C2) / 240


def _magnus(A, B, a, b, step_t0, step_h, nsub, n, m, d, scale=None):
    """Product of `nsub` sixth-order Magnus sub-steps on each segment, in blocks.

    Blocks of sub-steps whose node values fit the chunk budget are
    evaluated and exponentiated together and multiplied into the running
    product; no array holds all the sub-steps.
    """
    nseg = len(a)
    delta = (b - a) / nsub                                   # (S,)
    block = int(max(1, min(nsub, _CHUNK_ENTRIES // max(1, 3 * nseg * d * d))))
    ratio = None if scale is None else (scale[None, :] / scale[:, None])[:n]
    E = None
    for j0 in range(0, nsub, block):
        J = min(block, nsub - j0)
        starts = a[:, None] + delta[:, None] * np.arange(j0, j0 + J)   # (S, J)
        nodes = starts[..., None] + _NODES * delta[:, None, None]      # (S, J, 3)
        tflat = nodes.ravel()
        # M's first n rows (the rows below are zero, and so are Ω's)
        if m:
            Mt = np.empty((tflat.size, n, d))
            Mt[:, :, :n] = A._eval(tflat)
            Bt = B._eval(tflat)
            sigma = ((nodes - step_t0[:, None, None]) / step_h[:, None, None]).ravel()
            Mt[:, :, n:n + m] = Bt
            Mt[:, :, n + m:] = sigma[:, None, None] * Bt
        else:
            Mt = A._eval(tflat)
        if ratio is not None:
            Mt = Mt * ratio
        Mt = Mt.reshape(nseg, J, 3, n, d)
        rows = _magnus6(Mt[:, :, 0], Mt[:, :, 1], Mt[:, :, 2], delta[:, None, None, None])
        del Mt
        Omega = np.zeros((nseg * J, d, d))
        Omega[:, :n] = rows.reshape(nseg * J, n, d)
        del rows
        P = _tree_product(expm_batch(Omega).reshape(nseg, J, d, d))
        E = P if E is None else P @ E
    return E


# Padé [m/m] coefficients and Higham's 1-norm bounds θ_m (degrees 3, 5, 7, 9, 13):
# below θ_m the degree-m approximant is exact to double precision without scaling
_PADE = {
    3: np.array([120., 60., 12., 1.]),
    5: np.array([30240., 15120., 3360., 420., 30., 1.]),
    7: np.array([17297280., 8648640., 1995840., 277200., 25200., 1512., 56., 1.]),
    9: np.array([17643225600., 8821612800., 2075673600., 302702400., 30270240., 2162160.,
                 110880., 3960., 90., 1.]),
    13: np.array([64764752532480000., 32382376266240000., 7771770303897600.,
                  1187353796428800., 129060195264000., 10559470521600., 670442572800.,
                  33522128640., 1323241920., 40840800., 960960., 16380., 182., 1.]),
}
_THETA = {3: 1.495585217958292e-2, 5: 2.539398330063230e-1, 7: 9.504178996162932e-1,
          9: 2.097847961257068, 13: 5.371920351148152}


def expm_batch(X):
    """Matrix exponential of a stack of small matrices, shape (S, d, d).

    Higham's scaling and squaring, vectorised over the stack: each matrix
    gets the lowest Padé degree m in (3, 5, 7, 9) with ``‖X‖₁ <= θ_m``;
    the others ``e^X = (r13(X / 2^s))^{2^s}`` with ``‖X‖₁ / 2^s <= θ13``.

    Examples
    --------
    >>> from ltpcontrol._core.transition import expm_batch
    >>> E = expm_batch(np.array([[[0.0, 1.0], [0.0, 0.0]]]))
    >>> E[0]
    array([[1., 1.],
           [0., 1.]])
    """
    X = np.asarray(X, float)
    norms = np.abs(X).sum(axis=-2).max(axis=-1)
    E = np.empty_like(X)
    degree = np.full(len(X), 13)
    for m in (9, 7, 5, 3):
        degree[norms <= _THETA[m]] = m
    if len(X) and np.all(degree == degree[0]):
        return _pade(X, norms, int(degree[0]))
    for m in (3, 5, 7, 9, 13):
        sel = np.flatnonzero(degree == m)
        if sel.size:
            E[sel] = _pade(X[sel], norms[sel], m)
    return E


def _pade(X, norms, m):
    """r_m(X / 2^s)^(2^s); s = 0 unless m = 13."""
    d = X.shape[-1]
    s = np.zeros(len(X), int)
    if m == 13:
        s = np.maximum(0, np.ceil(np.log2(np.maximum(norms, 1e-300) / _THETA[13]))).astype(int)
        X = X / (2.0 ** s)[:, None, None]
    b = _PADE[m]
    ident = np.broadcast_to(np.eye(d), X.shape)
    X2 = X @ X
    if m == 13:
        X4 = X2 @ X2
        X6 = X4 @ X2
        U = X @ (X6 @ (b[13] * X6 + b[11] * X4 + b[9] * X2)
                 + b[7] * X6 + b[5] * X4 + b[3] * X2 + b[1] * ident)
        V = X6 @ (b[12] * X6 + b[10] * X4 + b[8] * X2) \
            + b[6] * X6 + b[4] * X4 + b[2] * X2 + b[0] * ident
    else:
        # U = X Σ b_{2j+1} X^{2j},  V = Σ b_{2j} X^{2j}
        powers = [ident, X2]
        while len(powers) < (m + 1) // 2:
            powers.append(powers[-1] @ X2)
        U = X @ sum(b[2 * j + 1] * P for j, P in enumerate(powers))
        V = sum(b[2 * j] * P for j, P in enumerate(powers))
    E = np.linalg.solve(V - U, V + U)
    for j in range(int(s.max()) if len(s) else 0):
        sel = s > j
        E[sel] = E[sel] @ E[sel]
    return E
