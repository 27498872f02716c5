"""The plant's HTF from closed-loop records: the joint input-output method.

In a loop the plant input u is computed from the measured output, so it
carries the loop's response to the measurement noise: an open-loop
estimate from (u, y) is biased.  The reference r is independent of the
noise.  Estimating the HTFs from r to the plant's output y and input u,
``y = G_yr r`` and ``u = G_ur r``, gives the plant from their harmonic
transfer matrices (HTMs),

.. math::

    \\mathcal{P}(j\\omega) = \\mathcal{G}_{yr}(j\\omega)\\,\\mathcal{G}_{ur}(j\\omega)^{-1},

with ``𝒢[n, m](jω) = G_{n-m}(jω + jnω_p)`` (components at the output
frequency, as `estimate_htf` gives them; the LTI identity
``P = G_yr / G_ur`` in the harmonic domain; a pseudo-inverse when there
are more references than plant inputs).  The component ``P_k(jω)`` is the
entry ``(0, -k)`` of 𝒫.  The HTMs are truncated to the harmonics ``|n|,
|m| <= K_t = K // 2`` for the K of the estimate, so that every entry
``|n - m| <= 2K_t`` is an estimated component; the truncation perturbs
mostly their outer rows and columns, and the result keeps the harmonics
``|k| <= nharmonics`` (default ``K_t``) of the central row.  The entry
``(n, m)`` needs the input excited at ``ω + mω_p``: the result is known
where ``ω ± K_t ω_p`` lie in the excited band.

Standard deviations (when the estimate has ``std``): to first order, with
``𝒢_y = 𝒫 𝒢_u`` at the true values, ``δ𝒫 = (δ𝒢_y − 𝒫 δ𝒢_u) 𝒢_u⁺``
(also for the pseudo-inverse: the term of ``δ(𝒢_u⁺)`` outside the range
of ``𝒢_u`` is multiplied by ``𝒢_y (I − 𝒢_u⁺𝒢_u) = 0``).  With
``A = [I, −𝒫]`` acting on the rows ``[y; u]`` and ``B = 𝒢_u⁺``, and the
HTM entries' errors taken as independent with variances ``σ²`` (the
``std`` of the estimate), ``var 𝒫[r, s] = Σ_ij |A_ri|² σ_ij² |B_js|²``.
Entries of `estimate_htf` at one frequency come from one least-squares
fit and may be correlated, so this is an estimate of the spread, like
the ``std`` it starts from.
"""

import numpy as np
from control.exception import ControlArgument

from .._frequency.htf import HTFData
from .._core.validation import check_positive_int

__all__ = ['joint_io_htf']


def joint_io_htf(htf, inputs, nharmonics=None, *, name=None):
    """HTF of a plant from the HTF of a closed loop from its reference.

    Parameters
    ----------
    htf : HTFData
        Estimate (`estimate_htf`) from the reference ``r`` to the stacked
        plant outputs and inputs, e.g. from records ``(t, r, [y; u])``.
        Its grid must hold the frequencies ``ω + mω_p`` (as the grid of
        `estimate_htf`, ``2π / (L T)``, does wherever they were estimated).
    inputs : int or list of int
        Indices of the outputs of `htf` that are the plant inputs u; the
        other outputs are the plant outputs y.  At least as many references
        as plant inputs are needed.
    nharmonics : int, optional
        Harmonics of the result, at most ``K // 2`` (the default) for the K
        of `htf` (see the module notes).
    name : str, optional
        Name of the result.

    Returns
    -------
    HTFData
        ``P_k(jω)``, ``|k| <= nharmonics``, on the frequencies of `htf` at
        which every shifted component the HTMs need is known (NaN
        elsewhere), with the input and output labels of `htf`'s outputs;
        ``std`` propagated to first order from that of `htf` (module
        notes), None when `htf` has none.

    Raises
    ------
    ControlArgument
        If `htf` is not an HTFData.
    ValueError
        For input indices out of range or repeated, none left for y, fewer
        references than plant inputs, or `nharmonics` above K.

    Examples
    --------
    A plant ``ẋ = -2x + b(t) u`` in the loop ``u = r - y`` (``y = x``):

    >>> T = 1.0
    >>> b = lambda t: np.array([[1 + 0.5 * np.cos(2 * np.pi * t)]])
    >>> loop = ltp.ltpss(lambda t: -2 - b(t), b, [[1.0], [-1.0]], [[0.0], [1.0]], period=T)
    >>> exc = ltp.chirp_replicas(T, 12, 8.0, 0.0, 6.0, dt=0.01, gap=4.0)
    >>> z = ltp.forced_response(loop, exc.time, exc.inputs).outputs     # [y; u]
    >>> H = ltp.estimate_htf((exc.time, exc.inputs, z), T, segments=exc.segments)
    >>> P = ltp.joint_io_htf(H, inputs=1)
    >>> plant = ltp.ltpss([[-2.0]], b, [[1.0]], 0, period=T)
    >>> w = P.omega[20]
    >>> _, truth = ltp.htf(plant, P.nharmonics).components([w])
    >>> bool(np.allclose(P.components([w])[1], truth, atol=2e-3))
    True
    """
    if not isinstance(htf, HTFData):
        raise ControlArgument(f"htf must be an HTFData (estimate_htf), got "
                              f"{type(htf).__name__}")
    nz, nr, K = htf.noutputs, htf.ninputs, htf.nharmonics
    idx = np.atleast_1d(np.asarray(inputs))
    if idx.dtype.kind not in 'iu' or idx.ndim != 1 or np.any(idx < 0) or \
            np.any(idx >= nz) or np.unique(idx).size != idx.size:
        raise ValueError(f"inputs must be distinct output indices of htf in [0, {nz}), "
                         f"got {inputs!r}")
    yidx = np.setdiff1d(np.arange(nz), idx)
    if yidx.size == 0:
        raise ValueError("inputs must leave at least one output of htf for y")
    if nr < idx.size:
        raise ValueError(f"{idx.size} plant inputs need at least as many references; "
                         f"htf has {nr}")
    Kt = K // 2
    Kp = Kt if nharmonics is None else check_positive_int(nharmonics, 'nharmonics',
                                                          minimum=0)
    if Kp > Kt:
        raise ValueError(f"nharmonics={Kp} exceeds K // 2 = {Kt} for the {K} harmonics "
                         "of htf")
    omega, comps = htf.components()
    step = np.min(np.diff(omega)) if omega.size > 1 else None
    if step is None:
        raise ValueError("htf needs at least two frequencies")
    L = int(round(htf.omega_p / step))
    if not np.isclose(L * step, htf.omega_p, rtol=1e-9):
        raise ValueError("the grid of htf must hold ω + mω_p (a step dividing ω_p)")
    bins = np.round(omega / step).astype(int)
    where = {b: i for i, b in enumerate(bins)}
    ny, nu = yidx.size, idx.size
    out = np.full((2 * Kp + 1, ny, nu, omega.size), np.nan + 0j)
    std = None if htf.std is None else np.full(out.shape, np.nan)
    harm = np.arange(-Kt, Kt + 1)
    H = 2 * Kt + 1
    # the central row's columns m = -k, k = -Kp..Kp
    cols = slice(Kt + Kp, Kt - Kp - 1 if Kt - Kp else None, -1)
    for i, b in enumerate(bins):
        # G_k(j(ω + nω_p)) for every n: the grid at b + nL, or conj G_{-k} at -(b + nL)
        at, sd = [], []
        for n in harm:
            c = b + n * L
            j = where.get(abs(c))
            if j is None:
                break
            at.append(comps[:, :, :, j] if c >= 0 else np.conj(comps[::-1, :, :, j]))
            if std is not None:
                sd.append(htf.std[:, :, :, j] if c >= 0 else htf.std[::-1, :, :, j])
        if len(at) < harm.size:
            continue
        G = _htm(at, harm, K, nz, nr)
        if not np.all(np.isfinite(G)):
            continue
        rows = G.reshape(H, nz, -1)
        Gy = rows[:, yidx].reshape(H * ny, -1)
        Gu = rows[:, idx].reshape(H * nu, -1)
        Gui = np.linalg.pinv(Gu)
        P = Gy @ Gui                                       # H ny x H nu
        centre = P[Kt * ny:(Kt + 1) * ny].reshape(ny, H, nu)     # columns m = -k
        out[..., i] = centre[:, cols].transpose(1, 0, 2)
        if std is not None:
            # δ𝒫 = A δ𝒢 B, A = [I, -𝒫] on the rows [y; u], B = 𝒢_u⁺ (module notes)
            S2 = _htm(sd, harm, K, nz, nr) ** 2
            A = _row_map(P, H, ny, nu, nz, yidx, idx)[Kt * ny:(Kt + 1) * ny]
            var = (np.abs(A) ** 2) @ S2 @ (np.abs(Gui) ** 2)       # ny x H nu
            std[..., i] = np.sqrt(var.reshape(ny, H, nu)[:, cols].transpose(1, 0, 2).real)
    labels = list(htf.output_labels)
    return HTFData(out, omega, htf.period, std=std, name=name or f"{htf.name}_plant",
                   inputs=[labels[j] for j in idx], outputs=[labels[j] for j in yidx])


def _htm(at, harm, K, nz, nr):
    """Harmonic transfer matrix ``𝒢[n, m] = at[n][n - m + K]`` (blocks nz x nr)."""
    H = harm.size
    G = np.zeros((H * nz, H * nr), np.result_type(*at))
    for a, n in enumerate(harm):
        for c, m in enumerate(harm):
            G[a * nz:(a + 1) * nz, c * nr:(c + 1) * nr] = at[a][n - m + K]
    return G


def _row_map(P, H, ny, nu, nz, yidx, idx):
    """``A = S_y − 𝒫 S_u`` (H ny x H nz): the rows y of the HTM minus 𝒫 times its rows u."""
    Sy = np.zeros((H, ny, H, nz))
    Su = np.zeros((H, nu, H, nz))
    for a in range(H):
        Sy[a, np.arange(ny), a, yidx] = 1.0
        Su[a, np.arange(nu), a, idx] = 1.0
    return Sy.reshape(H * ny, H * nz) - P @ Su.reshape(H * nu, H * nz)
