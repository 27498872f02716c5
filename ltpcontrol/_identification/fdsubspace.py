"""Frequency-domain subspace identification of LTI state-space models.

Implements the arbitrary-frequency algorithm of McKelvey, Akçay and Ljung
(1996): the extended observability matrix is read off the column space of
frequency-response data after the input part has been projected out, A and C
follow from its shift structure, and B and D from a linear least-squares fit to
the data.  Continuous-time data are handled through an exact bilinear map of the
frequency axis.

References
----------
T. McKelvey, H. Akçay, L. Ljung, "Subspace-based multivariable system
identification from frequency response data", IEEE Trans. Automatic Control
41(7):960-979, 1996.
"""

import numbers
import warnings
from dataclasses import dataclass

import control as ct
import numpy as np
from control.exception import ControlArgument, ControlDimension

from .._core.validation import check_positive, check_positive_int, real_array

__all__ = ["fdsubspace", "FDSubspaceInfo"]

# Largest order tried by the automatic order choice unless `max_order` is given.
_DEFAULT_MAX_ORDER = 10


@dataclass(frozen=True)
class FDSubspaceInfo:
    """Diagnostics returned by :func:`fdsubspace` with ``return_info=True``.

    Attributes
    ----------
    order : int
        Order of the identified model.
    q : int
        Number of block rows of the data matrices.
    singular_values : ndarray
        Singular values of the projected data matrix, in decreasing order.  A
        sharp drop after the ``order``-th value indicates a well-determined order.
    residual : float
        Weighted fit error ``sqrt(sum |w (G - G_hat)|^2)`` over all outputs,
        inputs and frequencies.
    relative_residual : float
        `residual` divided by ``sqrt(sum |w G|^2)``.
    timescale : float or None
        Time scale ``T`` of the bilinear frequency map for continuous-time data,
        ``None`` for discrete-time data.
    success : bool
        True when the fit residual is finite (the method is non-iterative).
    message : str
        Description of the outcome.
    nfev : int
        Number of model evaluations of an iterative search: 0.

    Examples
    --------
    >>> sys = ct.ss([[0.5]], [[1.]], [[1.]], [[0.]], True)
    >>> data = ct.frd(sys, np.linspace(0.1, 3, 20))
    >>> model, info = fdsubspace(data, order=1, return_info=True)
    >>> info.order, info.q, info.relative_residual < 1e-12, info.success
    (1, 2, True, True)
    """

    order: int
    q: int
    singular_values: np.ndarray
    residual: float
    relative_residual: float
    timescale: float | None
    success: bool = True
    message: str = ''
    nfev: int = 0


def fdsubspace(data, omega=None, order=None, *, q=None, dt=None, weights=None,
               estimate_d=True, max_order=None, timescale=None,
               return_info=False, name=None, inputs=None, outputs=None, states=None):
    r"""Identify an LTI state-space model from frequency-response data.

    Frequency-domain subspace identification of McKelvey, Akçay and Ljung
    [McKelvey1996]_, algorithm for arbitrarily spaced frequencies.  It is non-iterative
    and exact on noise-free data of a system of the identified order.

    Parameters
    ----------
    data : FrequencyResponseData or array_like
        Frequency response.  Either a :class:`control.FrequencyResponseData`
        (its ``frdata``, ``omega`` and ``dt`` are used) or a complex array of
        shape ``(noutputs, ninputs, nomega)``; a 1-D array is taken as a SISO
        response.
    omega : array_like, optional
        Frequencies in rad/s, shape ``(nomega,)``, distinct and positive (below
        the Nyquist frequency ``pi/dt`` for discrete time).  Required for array
        `data`, not allowed with a ``FrequencyResponseData``.
    order : int, optional
        Model order.  If omitted it is chosen from the largest gap
        ``sigma_i / sigma_{i+1}``, ``i = 1..max_order``, of the singular values.
    q : int, optional
        Number of block rows of the data matrices, ``q > order`` (``q >
        max_order`` when the order is chosen automatically).  Default
        ``2 * order`` (or ``2 * max_order``), reduced if the data are too few.
        Larger `q` averages noise better at a higher cost.
    dt : None, True or float, optional
        Timebase of the data: 0 for continuous time, ``True`` or a positive
        sampling time for discrete time.  Defaults to ``data.dt`` for
        frequency-response data and to 0 for arrays.
    weights : array_like, optional
        Non-negative weights of shape ``(nomega,)`` or ``(noutputs, ninputs,
        nomega)``; the B, D fit minimises ``sum |w (G - G_hat)|^2``.  Use
        ``1/sigma`` for noise of standard deviation ``sigma``.  The subspace step
        scales the data at each frequency and input by the root mean square of
        the weights over the outputs.  Default: all ones.
    estimate_d : bool, optional
        If False, the model is strictly proper (``D = 0``).  Default True.
    max_order : int, optional
        Largest order considered by the automatic order choice (default
        ``min(10, q - 1, largest order the data support)``).  Only used when
        `order` is omitted.
    timescale : float, optional
        Time scale ``T > 0`` (seconds) of the bilinear frequency map used for
        continuous-time data; the frequency ``2/T`` is mapped to ``z = j``.
        Default ``T = 2 / exp(mean(log(omega)))``, so that the data spread
        around the upper unit half-circle.  Ignored for discrete-time data.
    return_info : bool, optional
        Also return an :class:`FDSubspaceInfo` with the singular values and the
        fit residual.
    name, inputs, outputs, states : str or list of str, optional
        Names and signal labels of the returned system, as in
        :func:`control.ss`.  The input and output labels of a
        ``FrequencyResponseData`` are copied by default.

    Returns
    -------
    sys : StateSpace
        Identified real-valued model, with the timebase of the data.
    info : FDSubspaceInfo
        Only if `return_info` is True.

    Raises
    ------
    ControlArgument
        If `data` or another argument has the wrong type.
    ControlDimension
        If `data`, `omega` or `weights` have inconsistent shapes.
    ValueError
        For non-finite data, frequencies outside the admissible range, too few
        frequencies for the requested `order` and `q`, or ``q <= order``.
    TypeError
        For unknown keyword arguments.

    Warns
    -----
    UserWarning
        If the discrete-time model of continuous-time data has a pole near
        ``z = -1`` (an almost infinitely fast continuous-time pole).

    See Also
    --------
    control.frd, control.FrequencyResponseData

    Notes
    -----
    *Discrete time.*  With ``z_k = exp(j omega_k dt)``, the response
    ``G_k = C (z_k I - A)^{-1} B + D`` satisfies, for ``W_q(z) = [1, z, ...,
    z^{q-1}]^T``,

    .. math::

        \mathcal G = \mathcal O_q \mathcal X + \Gamma_q \mathcal W, \quad
        \mathcal G = [W_q(z_k) \otimes G_k]_k, \quad
        \mathcal W = [W_q(z_k) \otimes I]_k,

    with the extended observability matrix ``O_q = [C; CA; ...; CA^{q-1}]``,
    ``X = [(z_k I - A)^{-1} B]_k`` and the lower block-Toeplitz matrix
    ``Gamma_q`` of Markov parameters (D on its diagonal).  A real model is
    enforced by using ``[Re G, Im G]`` and ``[Re W, Im W]``.  The LQ
    factorisation ``[W; G] = [L11 0; L21 L22] [Q1; Q2]`` projects out the
    input term: the ``order`` dominant left singular vectors ``U_n`` of
    ``L22`` span the range of ``O_q``.  With ``O = U_n Sigma_n^{1/2}``,

    .. math::

        \hat A = (J_1 O)^\dagger J_2 O, \qquad \hat C = J_3 O,

    where ``J_1``/``J_2`` drop the last/first block row and ``J_3`` keeps the
    first.  B and D are the real least-squares solution of
    ``min sum_k ||w (G_k - C (z_k I - A)^{-1} B - D)||_F^2``.  With
    ``estimate_d=False`` the last block row of ``W`` is dropped and D = 0.

    *Continuous time.*  The bilinear map ``z = (1 + sT/2) / (1 - sT/2)``
    sends ``s = j omega`` to ``z = exp(j omega_d)`` with ``omega_d = 2
    arctan(omega T / 2)`` in ``(0, pi)``.  A and C are identified in discrete
    time on the mapped frequencies and mapped back exactly,

    .. math::

        A_c = \tfrac{2}{T} (I + A_d)^{-1} (A_d - I), \qquad
        C_c = \tfrac{2}{\sqrt T} C_d (I + A_d)^{-1},

    which preserves values: ``C_c (j omega I - A_c)^{-1} B_c + D_c =
    G_d(exp(j omega_d))`` for the matching ``B_c``, ``D_c``.  B and D are then
    fitted directly on ``s = j omega`` (identical to fitting ``B_d``, ``D_d``,
    which map linearly to them, and imposing ``D_c = 0`` exactly when
    ``estimate_d=False``).

    *Accuracy.*  On noise-free data of a system of order ``n`` the
    ``(n+1)``-th singular value vanishes and the model is exact.  McKelvey et
    al. prove strong consistency of this algorithm only under restrictive noise
    assumptions (covariance known up to a scalar); in general, for small noise
    the model error is of the order of the noise level.  Stability of the model
    is not enforced.

    *Data requirements.*  ``M`` distinct frequencies and ``m`` inputs need
    ``2 M m >= q m + order`` (``+1`` with automatic order choice) and
    ``2 M p >= order + p`` for ``p`` outputs.

    *Complexity.*  Building the real data matrix of size ``q (m + p)`` by
    ``2 M m`` costs ``O(q (m + p) M m)``; its QR factorisation
    ``O(M m q^2 (m + p)^2)``; the SVD ``O(q^3 p^3)``; the B, D fit
    ``O(M n^3 + m M p (n + p)^2)``.  All steps are vectorised over frequencies.

    Examples
    --------
    Recover a second-order discrete-time system from 30 frequency points:

    >>> sys = ct.ss([[0.6, 0.3], [-0.3, 0.6]], [[1.], [0.]], [[1., 1.]],
    ...             [[0.5]], 0.1)
    >>> data = ct.frd(sys, np.linspace(0.5, 30, 30))
    >>> model = fdsubspace(data)
    >>> model.nstates, model.dt
    (2, 0.1)
    >>> np.sort_complex(model.poles()).round(6)
    array([0.6-0.3j, 0.6+0.3j])

    Continuous-time data given as an array, with diagnostics:

    >>> sysc = ct.tf([1.], [1., 0.4, 4.])
    >>> w = np.logspace(-1, 1, 40)
    >>> G = sysc(1j * w)
    >>> model, info = fdsubspace(G, w, 2, return_info=True)
    >>> np.sort_complex(model.poles()).round(6)
    array([-0.2-1.989975j, -0.2+1.989975j])
    >>> bool(info.singular_values[2] < 1e-10 * info.singular_values[0])
    True
    """
    G, omega, dt, labels = _parse_data(data, omega, dt)
    ny, nu, nw = G.shape
    w = _parse_weights(weights, G.shape)
    if not isinstance(estimate_d, (bool, np.bool_)):
        raise ControlArgument(f"estimate_d must be a bool, got {estimate_d!r}")
    if not np.any(G):
        raise ValueError("data is identically zero; there is nothing to identify")
    if not np.any(w * G):
        raise ValueError("weights are zero wherever data is non-zero")

    # Points on the unit circle where the discrete-time model is fitted.
    continuous = dt == 0
    if continuous:
        T = _parse_timescale(timescale, omega)
        zd = np.exp(2j * np.arctan(omega * T / 2))
    else:
        T = None
        zd = np.exp(1j * omega * (1.0 if dt is True else dt))

    order, q, max_order = _choose_sizes(order, q, max_order, nw, ny, nu)
    sv, Ur = _projected_svd(G, zd, w, q, estimate_d or continuous)
    if order is None:
        order = _gap_order(sv, max_order)

    # Extended observability matrix O = U_n Sigma_n^{1/2}; A, C from shift invariance.
    O = Ur[:, :order] * np.sqrt(sv[:order])
    A = np.linalg.lstsq(O[:-ny], O[ny:], rcond=None)[0]
    C = O[:ny]
    if continuous:
        A, C = _bilinear_ac_to_ct(A, C, T)
        zfit = 1j * omega
    else:
        zfit = zd
    B, D = _fit_bd(A, C, zfit, G, w, estimate_d)

    sys = ct.ss(A, B, C, D, dt, name=name, states=states,
                inputs=labels[0] if inputs is None else inputs,
                outputs=labels[1] if outputs is None else outputs)
    if not return_info:
        return sys
    # Weighted residual of the fitted model on the data.
    err = w * (_eval_ss(A, B, C, D, zfit) - G)
    residual = float(np.linalg.norm(err))
    relative = residual / float(np.linalg.norm(w * G))
    info = FDSubspaceInfo(order=order, q=q, singular_values=sv, residual=residual,
                          relative_residual=relative, timescale=T,
                          success=bool(np.isfinite(residual)),
                          message=f"order-{order} model from {q} block rows, relative "
                                  f"residual {relative:.3g}")
    return sys, info


def _parse_data(data, omega, dt):
    """Return data as ``(G, omega, dt, (input_labels, output_labels))``."""
    if isinstance(data, ct.FrequencyResponseData):
        if omega is not None:
            raise ControlArgument(
                "omega must not be given with FrequencyResponseData data (its "
                "own frequencies are used); pass the model order as order=...")
        G = np.asarray(data.frdata, dtype=complex)
        omega = np.asarray(data.omega, dtype=float)
        if not np.all(np.isfinite(G)):
            raise ValueError("data contains NaN or inf")
        data_dt = 0 if data.dt is None else data.dt
        if dt is None:
            dt = data_dt
        elif not _same_timebase(_parse_dt(dt), data_dt):
            raise ValueError(f"dt={dt!r} contradicts the timebase of data (dt={data.dt!r})")
        labels = (list(data.input_labels), list(data.output_labels))
    else:
        if isinstance(data, ct.LTI):
            raise ControlArgument(
                "data must be frequency-response data, got a "
                f"{type(data).__name__}; use control.frd(sys, omega) first")
        G = real_array(data, "data", ndim=(1, 3), allow_complex=True).astype(complex)
        if G.ndim == 1:
            G = G[None, None, :]
        if omega is None:
            raise ControlArgument("omega is required when data is an array")
        omega = real_array(omega, "omega", ndim=1)
        if omega.size != G.shape[2]:
            raise ControlDimension(
                f"omega has {omega.size} frequencies but data has {G.shape[2]} "
                "(last axis)")
        dt = 0 if dt is None else dt
        labels = (None, None)
    dt = _parse_dt(dt)
    if G.shape[0] < 1 or G.shape[1] < 1 or G.shape[2] < 1:
        raise ControlDimension(f"data must not be empty, got shape {G.shape}")
    if np.unique(omega).size != omega.size:
        raise ValueError("omega contains repeated frequencies")
    if not np.all(omega > 0):
        raise ValueError("omega must be positive (frequencies in rad/s, DC excluded)")
    if dt != 0:
        nyquist = np.pi / (1.0 if dt is True else dt)
        if not np.all(omega < nyquist):
            raise ValueError(
                f"omega must lie in (0, pi/dt) = (0, {nyquist:g}) for discrete-time "
                f"data, got max(omega) = {omega.max():g}")
    return G, omega, dt, labels


def _parse_dt(dt):
    """Return `dt` as 0, True or a positive float."""
    if dt is True or (isinstance(dt, numbers.Real) and not isinstance(dt, bool)
                      and dt == 0):
        return dt if dt is True else 0
    return check_positive(dt, "dt")


def _same_timebase(dt1, dt2):
    """True if two timebases (0, True or a sampling time) are the same."""
    if (dt1 is True) or (dt2 is True):
        return dt1 is dt2
    return bool(np.isclose(float(dt1), float(dt2)))


def _parse_weights(weights, shape):
    """Return weights broadcast to `shape` = (ny, nu, nomega)."""
    if weights is None:
        return np.ones(shape)
    w = real_array(weights, "weights", ndim=(1, 3))
    if w.shape not in ((shape[2],), shape):
        raise ControlDimension(
            f"weights must have shape ({shape[2]},) or {shape}, got {w.shape}")
    if np.any(w < 0):
        raise ValueError("weights must be non-negative")
    return np.broadcast_to(w, shape)


def _parse_timescale(timescale, omega):
    """Bilinear time scale T: user value, or 2/(geometric mean of omega)."""
    if timescale is None:
        return 2.0 / float(np.exp(np.mean(np.log(omega))))
    return check_positive(timescale, "timescale")


def _choose_sizes(order, q, max_order, nw, ny, nu):
    """Validate `order`, `q`, `max_order` against the amount of data."""
    # Real data matrices have 2*nw*nu columns; qm of them are used by the input
    # projection, the rest must carry `order` (+1 to see a gap) state directions.
    ncols = 2 * nw * nu
    if q is not None:
        q = check_positive_int(q, "q")
    if order is not None:
        order = check_positive_int(order, "order")
        if max_order is not None:
            raise ControlArgument("give either order or max_order, not both")
        nref, extra = order, 0
    else:
        if max_order is None:
            # Largest order with a visible (order+1)-th singular value, for the
            # given q or else for q = order + 1.
            limit = (ncols // (nu + 1) - 1 if q is None else
                     min(q - 1, ncols - q * nu - 1))
            max_order = min(_DEFAULT_MAX_ORDER, limit, 2 * nw * ny - ny)
            if max_order < 1:
                raise ValueError(
                    f"too few frequencies ({nw})"
                    f"{'' if q is None else f' for q={q}'} to identify any model")
        else:
            max_order = check_positive_int(max_order, "max_order")
        nref, extra = max_order, 1
    name = "order" if order is not None else "max_order"
    if 2 * nw * ny < nref + ny:
        raise ValueError(
            f"too few frequencies ({nw}) for {name}={nref}: the B, D fit "
            f"needs 2*nomega*noutputs >= {name} + noutputs")
    if q is None:
        # Default 2*order, capped by the data: q*nu + nref + extra <= ncols.
        q = max(min(2 * nref, (ncols - nref - extra) // nu), nref + 1)
    elif q <= nref:
        raise ValueError(f"q must be greater than {name} ({nref}), got q={q}")
    if q * nu + nref + extra > ncols:
        raise ValueError(
            f"too few frequencies ({nw}) for {name}={nref} and q={q}: need "
            f"2*nomega*ninputs >= q*ninputs + {name}"
            f"{' + 1' if extra else ''}; lower q or {name}, or add frequencies")
    return order, q, max_order


def _projected_svd(G, z, w, q, with_d):
    """Singular values and left vectors of the data with the input part removed."""
    ny, nu, nw = G.shape
    # Per (frequency, input) column weight: rms of the weights over the outputs.
    wcol = np.sqrt(np.mean(w ** 2, axis=0)).T                      # (nw, nu)
    zpow = z[None, :] ** np.arange(q)[:, None]                       # (q, nw)
    # Block (i, k) of the data matrices: z_k^i G_k and z_k^i I.
    Gm = zpow[:, None, :, None] * G.transpose(0, 2, 1)[None] * wcol
    Wm = zpow[:, None, :, None] * np.eye(nu)[:, None, :] * wcol
    Gm = Gm.reshape(q * ny, nw * nu)
    Wm = Wm.reshape(q * nu, nw * nu)
    if not with_d:
        # D = 0: the last block column of Gamma_q vanishes.
        Wm = Wm[:-nu]
    H = np.vstack([Wm, Gm])
    H = np.hstack([H.real, H.imag])
    # LQ factorisation [W; G] = L Q; L22 spans range(O_q) for noise-free data.
    L = np.linalg.qr(H.T, mode="r").T
    nwrows = Wm.shape[0]
    L22 = L[nwrows:, nwrows:]
    U, sv, _ = np.linalg.svd(L22, full_matrices=False)
    return sv, U


def _gap_order(sv, max_order):
    """Order at the largest ratio sigma_i / sigma_{i+1}, i = 1..max_order."""
    if sv[0] == 0:
        raise ValueError("the projected data matrix is zero; data carry no dynamics")
    floor = sv[0] * np.finfo(float).eps
    s = np.maximum(sv[:max_order + 1], floor)
    return int(np.argmax(s[:-1] / s[1:])) + 1


def _bilinear_ac_to_ct(Ad, Cd, T):
    """A, C of the continuous-time model ``s = (2/T)(z - 1)/(z + 1)``."""
    n = Ad.shape[0]
    IpA = np.eye(n) + Ad
    # Near-singular I + A_d relative to the size of A_d.
    if np.linalg.svd(IpA, compute_uv=False)[-1] <= 1e-10 * (1 + np.linalg.norm(Ad, 2)):
        warnings.warn(
            "the discrete-time model has a pole near z = -1; the continuous-time "
            "model has a very fast pole (the data may be improper; otherwise try "
            "another timescale)", UserWarning,
            stacklevel=3)
    # A_c = (2/T)(I + A_d)^{-1}(A_d - I),  C_c = (2/sqrt T) C_d (I + A_d)^{-1}
    try:
        Ac = (2.0 / T) * np.linalg.solve(IpA, Ad - np.eye(n))
        Cc = (2.0 / np.sqrt(T)) * np.linalg.solve(IpA.T, Cd.T).T
    except np.linalg.LinAlgError:
        raise ValueError("the discrete-time model has a pole at z = -1 and has no "
                         "continuous-time counterpart; try another timescale") from None
    return Ac, Cc


def _fit_bd(A, C, z, G, w, estimate_d):
    """Real least-squares B, D: min sum |w (G_k - C (z_k I - A)^{-1} B - D)|^2."""
    ny, nu, nw = G.shape
    n = A.shape[0]
    # Phi_k = C (z_k I - A)^{-1}, batched over frequencies: (nw, ny, n).
    Zk = z[:, None, None] * np.eye(n) - A
    Phi = np.linalg.solve(Zk.transpose(0, 2, 1),
                          np.broadcast_to(C.T, (nw, n, ny))).transpose(0, 2, 1)
    # Regressor rows (k, i) for unknowns [b_j; d_j]: [Phi_k[i, :], e_i].
    reg = Phi.reshape(nw * ny, n)
    if estimate_d:
        eye = np.broadcast_to(np.eye(ny), (nw, ny, ny)).reshape(nw * ny, ny)
        reg = np.hstack([reg, eye])
    B = np.empty((n, nu))
    D = np.zeros((ny, nu))
    for j in range(nu):  # one least-squares problem per input column
        wj = w[:, j, :].T.reshape(-1, 1)                             # rows (k, i)
        rhs = G[:, j, :].T.reshape(-1) * wj[:, 0]
        M = reg * wj
        M = np.vstack([M.real, M.imag])
        rhs = np.concatenate([rhs.real, rhs.imag])
        # Column scaling for a well-conditioned solve.
        scale = np.linalg.norm(M, axis=0)
        scale[scale == 0] = 1.0
        theta = np.linalg.lstsq(M / scale, rhs, rcond=None)[0] / scale
        B[:, j] = theta[:n]
        if estimate_d:
            D[:, j] = theta[n:]
    return B, D


def _eval_ss(A, B, C, D, z):
    """Frequency response ``C (z I - A)^{-1} B + D`` as (ny, nu, nz)."""
    n = A.shape[0]
    X = np.linalg.solve(z[:, None, None] * np.eye(n) - A,
                        np.broadcast_to(B, (z.size,) + B.shape))
    return (C @ X + D).transpose(1, 2, 0)
