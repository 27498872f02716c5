"""Step transition matrices of ``ẋ = A(t)x + B(t)u`` with held inputs.

For a step ``[t0, t0 + h]`` and an input that is linear in the step,
``u(τ) = u0 + σ (u1 - u0)`` with ``σ = (τ - t0)/h`` (first-order hold), the
exact solution is

    x(t0 + h) = Φ x(t0) + Γ0 u0 + Γ1 (u1 - u0),

where ``[[Φ, Γ0, Γ1], [0, I, 0], [0, 0, I]]`` is the transition matrix of the
augmented system ``ż = M(τ) z``, ``M = [[A, B, σB], [0, 0, 0], [0, 0, 0]]``.
It is computed with the fourth-order Magnus integrator

    Ω = δ/2 (M1 + M2) + √3/12 δ² [M2, M1],   M_i = M(τ + c_i δ),
    c_{1,2} = 1/2 ∓ √3/6,

on m sub-steps of each smooth piece (switching instants split a step), with m
doubled until two resolutions agree (the Richardson-extrapolated value is
returned).  Without input, when A is constant between its switching
instants (its form says so), each segment is exactly ``e^{A h}``: one
matrix exponential, no sub-steps.  Everything is vectorised over steps.
"""

import warnings

import numpy as np

__all__ = []

_C1, _C2 = 0.5 - np.sqrt(3) / 6, 0.5 + np.sqrt(3) / 6


def step_transitions(A, B, t0, h, rtol=1e-12, max_substeps=4096, info=None):
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
        largest error estimate with two sub-steps (against four) relative
        to the accepted error (0 for exact exponentials; the error of a
        fourth-order step scales as its length to the fifth).

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
    n, m = A.shape[0], 0 if B is None else B.shape[1]
    d = n + 2 * m
    nsub = 2
    prev = None
    excess = None
    while True:
        E = _magnus(A, B, a, b, step_t0, step_h, nsub, n, m, d)
        if prev is not None:
            err = np.abs(E - prev).max(axis=(1, 2))
            scale = np.maximum(1.0, np.abs(E).max(axis=(1, 2)))
            # fourth-order method: the error of E is about (E - prev)/15
            ratio = err / 15 / (rtol * scale)
            if excess is None:
                excess = float(ratio.max()) if ratio.size else 0.0
            if np.all(ratio <= 1):
                return E + (E - prev) / 15, nsub, excess
        if nsub >= max_substeps:
            warnings.warn("transition matrices did not reach the requested accuracy "
                          f"with {nsub} sub-steps per step; use a finer time grid",
                          UserWarning, stacklevel=4)
            return E, nsub, excess or 0.0
        prev = E
        nsub *= 2


def _magnus(A, B, a, b, step_t0, step_h, nsub, n, m, d):
    nseg = len(a)
    delta = (b - a) / nsub                                   # (S,)
    starts = a[:, None] + delta[:, None] * np.arange(nsub)   # (S, nsub)
    nodes = np.stack([starts + _C1 * delta[:, None], starts + _C2 * delta[:, None]], -1)
    tflat = nodes.ravel()
    if m:
        Mt = np.zeros((tflat.size, d, d))
        Mt[:, :n, :n] = A._eval(tflat)
        Bt = B._eval(tflat)
        sigma = ((nodes - step_t0[:, None, None]) / step_h[:, None, None]).ravel()
        Mt[:, :n, n:n + m] = Bt
        Mt[:, :n, n + m:] = sigma[:, None, None] * Bt
    else:
        Mt = A._eval(tflat)
    Mt = Mt.reshape(nseg, nsub, 2, d, d)
    M1, M2 = Mt[:, :, 0], Mt[:, :, 1]
    dl = delta[:, None, None, None]
    Omega = 0.5 * dl * (M1 + M2) + (np.sqrt(3) / 12) * dl ** 2 * (M2 @ M1 - M1 @ M2)
    Esub = expm_batch(Omega.reshape(-1, d, d)).reshape(nseg, nsub, d, d)
    E = Esub[:, 0]
    for j in range(1, nsub):
        E = Esub[:, j] @ E
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
