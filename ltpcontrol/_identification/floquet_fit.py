"""Structured least-squares fit of a Floquet-form LTP model to harmonic data.

A continuous LTP in Floquet form (constant A, periodic ``B(t)``, ``C(t)``,
``D(t)`` with Fourier coefficients ``B_m``, ``C_l``, ``D_n``) has, with
``R_m(Ω) = (j(Ω + mω_p) I - A)^{-1}``, the harmonic response to the input
harmonic 0 (an ``ny x nu`` matrix for ``nu`` inputs)

    G_n(jΩ) = Σ_{m=-H..H} C_{n-m} R_m(Ω) B_m + D_n,        n = -K..K,

truncated to the input harmonics ``|m| <= H`` of a model whose B has H >= K
harmonics, C has 2K and D has K (``C_l = 0`` for ``|l| > 2K``).  A plant
whose A(t) is periodic has B_m for all m in Floquet form: the terms
``|m| > K`` omitted by H = K bias the fitted exponents, H = K + 1 captures
most of them.  C stops at 2K for every H: a ``C_l`` with ``|l| > 2K`` meets
the data only in products with a ``B_m``, ``|m| > K``, so where those
vanish (a plant with at most K harmonics in Floquet form) it is not
determined by the data, yet it enters the harmonics ``|n| > K`` the model
predicts.  It is
linear in D, linear in B for fixed (A, C) and in C for fixed (A, B), and
``dR_m = R_m dA R_m``.  The parameters are real: ``Re P_0, Re P_h, Im P_h``
(h > 0) of every coefficient series, so that ``P_{-h} = conj P_h`` and the
model is real.  The similarity ``x -> S x`` leaves G unchanged; a
Gauss-Newton step of minimum norm does not move along these ``n_p^2`` flat
directions.  Arrays of harmonic responses have the shape ``(nu, 2K+1, ny,
M)``: entry ``[j, n + K, :, w]`` is ``G_n(jΩ_w)`` of input j.
"""

import numpy as np
import scipy.linalg
from tqdm.auto import tqdm

from .._core.lifting import _real_basis
from .._core.ltpsys import LTPStateSpace
from .._core.periodic_matrix import PeriodicMatrix

__all__ = []


def _resolvents(A, omega, wp, K):
    """``R_m(Ω) = (j(Ω + mω_p) I - A)^{-1}``, shape (M, 2K+1, n, n)."""
    n = A.shape[0]
    s = 1j * (omega[:, None] + wp * np.arange(-K, K + 1)[None, :])
    return np.linalg.inv(s[..., None, None] * np.eye(n) - A)


def _cnm(Cc, K, H):
    """``C_{n-m}`` for n = -K..K, m = -H..H, shape (2K+1, 2H+1, ny, nx)."""
    n, m = np.arange(-K, K + 1), np.arange(-H, H + 1)
    return Cc[(n[:, None] - m[None, :]) + K + H]


def _model_response(R, Bc, Cc, Dc, K, H):
    """``G_n = Σ_m C_{n-m} R_m B_m + D_n`` for n = -K..K, shape (nu, 2K+1, ny, M)."""
    X = np.einsum('wmij,mjq->wmiq', R, Bc)                        # R_m B_m
    return (np.einsum('nmoi,wmiq->qnow', _cnm(Cc, K, H), X)
            + Dc.transpose(2, 0, 1)[..., None])


def _harmonic_response(sys, omega, K):
    """Continuous harmonic response G_n(jΩ), n = -K..K, of a Floquet-form model
    (all harmonics of its B, at least K), shape (nu, 2K+1, ny, M)."""
    H = max(K, sys.B.nharmonics or 0)
    R = _resolvents(sys.A(0.0), omega, 2 * np.pi / sys.period, H)
    Bc, Cc, Dc = _coefficients(sys, K, H)
    return _model_response(R, Bc, Cc, Dc, K, H)


def _harmonic_data(frdata, K, N, ny):
    """Continuous harmonic data ``G_n(jΩ)``, n = -K..K, shape (nu, 2K+1, ny, M), from the
    real lifted response ``frdata`` ((2K_d+1) ny, nu, M), K_d >= K: ``(V ⊗ I) frdata``."""
    V, _ = _real_basis(np.arange(-K, K + 1), N)
    H, nu, M = 2 * K + 1, frdata.shape[1], frdata.shape[2]
    Gc = np.einsum('ab,bjw->jaw', np.kron(V, np.eye(ny)), frdata[:H * ny])
    return Gc.reshape(nu, H, ny, M)


def _coefficients(sys, K, H):
    """Fourier coefficients B_m (|m| <= H), C_l (|l| <= K+H), D_n (|n| <= K)."""
    def central(P, h):
        c = P.fourier(max(h, P.nharmonics or 0, 1))
        J = c.shape[0] // 2
        return c[J - h:J + h + 1]
    return central(sys.B, H), central(sys.C, K + H), central(sys.D, K)


def _conj_map(H, size):
    """Real parameters → complex coefficients ``P_h``, h = -H..H, P_{-h} = conj(P_h)."""
    # real vector [Re P_0, Re P_1, Im P_1, ..., Re P_H, Im P_H] (each `size` long)
    T = np.zeros(((2 * H + 1) * size, (2 * H + 1) * size), complex)
    eye = np.eye(size)
    T[H * size:(H + 1) * size, :size] = eye
    for h in range(1, H + 1):
        re, im = slice((2 * h - 1) * size, 2 * h * size), slice(2 * h * size, (2 * h + 1) * size)
        for sign in (1, -1):
            rows = slice((H + sign * h) * size, (H + sign * h + 1) * size)
            T[rows, re] = eye
            T[rows, im] = sign * 1j * eye
    return T


def _apply_conj_map(J, H, size):
    """``J @ _conj_map(H, size)`` by additions: the columns of ``Re P_h`` are those
    of ``P_h`` plus those of ``P_{-h}``, the columns of ``Im P_h`` j times their
    difference."""
    J = J.reshape(J.shape[0], 2 * H + 1, size)
    out = np.empty(J.shape, complex)
    out[:, 0] = J[:, H]
    pos, neg = J[:, H + 1:], J[:, H - 1::-1]              # P_h and P_{-h}, h = 1..H
    out[:, 1::2] = pos + neg
    out[:, 2::2] = 1j * (pos - neg)
    return out.reshape(J.shape[0], -1)


def _conj_combine(x, H, axis):
    """`_apply_conj_map` along one `axis` (harmonics -H..H) of `x`: ``P_0``, then
    ``P_h + P_{-h}`` and ``j (P_h - P_{-h})`` for h = 1..H, on the factor of a
    Jacobian before it is expanded by identity matrices (the same values)."""
    x = np.moveaxis(x, axis, 0)
    out = np.empty(x.shape, complex)
    out[0] = x[H]
    pos, neg = x[H + 1:], x[H - 1::-1]
    out[1::2] = pos + neg
    out[2::2] = 1j * (pos - neg)
    return np.moveaxis(out, 0, axis)


def _zero_pad(x, pad):
    """``np.pad(x, pad)`` (zeros) for pads along the first axis only, without
    `numpy.pad`'s general machinery (the refit unpacks at every evaluation)."""
    p = pad[0][0]
    if p < 0 or pad[0][1] != p or any(q != (0, 0) for q in pad[1:]):
        return np.pad(x, pad)
    out = np.zeros((x.shape[0] + 2 * p,) + x.shape[1:], x.dtype)
    out[p:p + x.shape[0]] = x
    return out


class _FloquetFit:
    """Real parameter vector θ = (B, C, D coefficients[, A]) of a model with H
    harmonics in B, 2K in C and K in D fitted to the data harmonics |n| <= Kd."""

    def __init__(self, nx, ny, nu, K, H, period, estimate_d, fit_a, Kd=None):
        self.nx, self.ny, self.nu, self.K, self.H = nx, ny, nu, K, H
        self.Kd = K if Kd is None else Kd
        self.wp, self.fit_a = 2 * np.pi / period, fit_a
        Tb, Tc, Td = _conj_map(H, nx * nu), _conj_map(2 * K, ny * nx), _conj_map(K, ny * nu)
        self.nb, self.nc, self.nd = Tb.shape[0], Tc.shape[0], Td.shape[0]
        T = np.zeros((self.nb + self.nc + self.nd,) * 2, complex)
        nb, nc = self.nb, self.nc
        T[:nb, :nb], T[nb:nb + nc, nb:nb + nc], T[nb + nc:, nb + nc:] = Tb, Tc, Td
        self.T = T if estimate_d else T[:, :nb + nc]
        # (harmonics, size) of the coefficient series of θ, for `_apply_conj_map`
        self.series = [(H, nx * nu), (2 * K, ny * nx)] + ([(K, ny * nu)] if estimate_d else [])
        self.ncoef = self.T.shape[1]
        Kd = self.Kd
        self.cpad = ((Kd + H - 2 * K,) * 2, (0, 0), (0, 0))   # C_l = 0 for 2K < |l| <= Kd+H
        self.dpad = ((Kd - K,) * 2, (0, 0), (0, 0))           # D_n = 0 for K < |n| <= Kd
        self._last = None                 # (θ, A, Ω, then A, B, C, D, R, G) of the last response
        self._jd = None                   # (lines, Jacobian of the D coefficients)

    def pack(self, sys):
        K, H = self.K, self.H
        Bc, Cc, Dc = _coefficients(sys, K, H)
        c = np.concatenate([Bc.ravel(), Cc[H - K:H + 3 * K + 1].ravel(), Dc.ravel()])
        theta = np.linalg.lstsq(self.T, c, rcond=None)[0].real
        return np.concatenate([theta, sys.A(0.0).ravel()]) if self.fit_a else theta

    def unpack(self, theta, A=None):
        K, H, nx, ny, nu, nb, nc = self.K, self.H, self.nx, self.ny, self.nu, self.nb, self.nc
        c = self.T @ theta[:self.ncoef]
        if self.fit_a:
            A = theta[self.ncoef:].reshape(nx, nx)
        return (A, c[:nb].reshape(2 * H + 1, nx, nu),
                _zero_pad(c[nb:nb + nc].reshape(4 * K + 1, ny, nx), self.cpad),
                _zero_pad(c[nb + nc:].reshape(2 * K + 1, ny, nu), self.dpad))

    def response_and_jacobian(self, theta, omega, A=None, jac=True):
        """Harmonic response (nu, 2Kd+1, ny, M) and its Jacobian (nu (2Kd+1) ny M, len θ)."""
        K, H, nx, ny, nu, Kd = self.K, self.H, self.nx, self.ny, self.nu, self.Kd
        last = self._last
        if (last is not None and last[1] is A and last[2] is omega
                and last[0].shape == theta.shape and np.array_equal(last[0], theta)):
            # the point of the last call (a step the fit accepted): its response as it was
            A, Bc, Cc, Dc, R, G = last[3:]
        else:
            given = A
            A, Bc, Cc, Dc = self.unpack(theta, A)
            R = _resolvents(A, omega, self.wp, H)
            G = _model_response(R, Bc, Cc, Dc, Kd, H)
            self._last = (theta.copy(), given, omega, A, Bc, Cc, Dc, R, G)
        if not jac:
            return G, None
        M, m = omega.size, np.arange(-H, H + 1)
        CR = np.einsum('nmoi,wmij->nowmj', _cnm(Cc, Kd, H), R)    # C_{n-m} R_m
        X = np.einsum('wmij,mjq->wmiq', R, Bc)                     # R_m B_m, (w, m, i, q)
        # J @ self.T, one series at a time (T is 0, 1 and ±j in blocks): the
        # harmonics of a series are combined on the factor of its block, before
        # the expansion by identity matrices (`_apply_conj_map` on the block)
        nb, nc = self.nb, self.nc
        J = np.empty((G.size, self.ncoef + (nx * nx if self.fit_a else 0)), complex)
        # rows (q, n, o, w) of G;  dG_n = Σ_m C_{n-m} R_m dB_m
        eu, ey = np.eye(nu), np.eye(ny)
        J[:, :nb] = np.einsum('nowmi,qr->qnowmir', _conj_combine(CR, H, 3),
                              eu).reshape(G.size, nb)
        # dG_n = Σ_l dC_l X_{n-l}, |n-l| <= H, |l| <= 2K
        L = Kd + H
        Xsel = np.zeros((2 * Kd + 1, 2 * L + 1, M, nx, nu), complex)
        for a, n in enumerate(range(-Kd, Kd + 1)):
            Xsel[a, n - m + L] = X.transpose(1, 0, 2, 3)
        J[:, nb:nb + nc] = np.einsum('oz,nlwiq->qnowlzi', ey, _conj_combine(
            Xsel[:, L - 2 * K:L + 2 * K + 1], 2 * K, 1)).reshape(G.size, nc)
        if len(self.series) == 3:
            # dG_n = dD_n, |n| <= K: constant, made once for a number of lines
            if self._jd is None or self._jd[0] != M:
                JD = np.einsum('qr,na,oz,w->qnowazr', eu, np.eye(2 * Kd + 1, 2 * K + 1, K - Kd),
                               ey, np.ones(M))
                self._jd = (M, _apply_conj_map(JD.reshape(G.size, -1), K, ny * nu))
            J[:, nb + nc:self.ncoef] = self._jd[1]
        if self.fit_a:
            # dR_m = R_m dA R_m:  dG_n = Σ_m C_{n-m} R_m dA R_m B_m
            J[:, self.ncoef:] = np.einsum('nowmi,wmjq->qnowij', CR, X).reshape(G.size, nx * nx)
        return G, J


def fit_floquet(sys, Gc, omega, K, *, harmonics=None, estimate_d=True, fit_a=True,
                maxiter=50, rtol=1e-8, progress=False, **labels):
    """Least-squares Floquet-form model fitted to ``G_n(jΩ)``, n = -Kd..Kd, with
    `harmonics` H >= K harmonics in B (default K), 2K in C, K in D.

    `Gc` has the shape (nu, 2Kd+1, ny, M) of `_harmonic_response`, Kd >= K
    the data harmonics.  The model produces the output harmonics ``|n| <=
    2K + H``: with ``Kd >= 2K + H`` every one of them is fitted.

    Starts from the Floquet-form LTPStateSpace `sys` and minimises
    ``Σ |G_n(jΩ) - Ĝ_n|²`` over the lines Ω (rad/s) and n = -K..K (module
    notes) by Levenberg-Marquardt steps: Gauss-Newton (minimum-norm, on
    column-scaled Jacobians) while the cost falls, damped otherwise.
    Returns ``(model, relative residual, converged, number of residual
    evaluations)``.

    Examples
    --------
    Fitted to the exact response of ``ẋ = -2x + (1 + cos t) u``, a start at
    ``A = -1.5`` recovers the exponent:

    >>> from ltpcontrol._identification.floquet_fit import fit_floquet, _harmonic_response
    >>> B = ltp.PeriodicMatrix(np.array([[[0.5]], [[1.0]], [[0.5]]]), 2 * np.pi)
    >>> omega = np.linspace(0.1, 3.0, 8)
    >>> Gc = _harmonic_response(ltp.ltpss([[-2.0]], B, [[1.0]], 0, period=2 * np.pi), omega, 1)
    >>> start = ltp.ltpss([[-1.5]], B, [[1.0]], 0, period=2 * np.pi)
    >>> model, res, converged, nfev = fit_floquet(start, Gc, omega, 1)
    >>> round(float(model.A(0.0)[0, 0]), 8), bool(res < 1e-10), converged
    (-2.0, True, True)
    """
    nu, ny, nx = Gc.shape[0], Gc.shape[2], sys.nstates
    H = K if harmonics is None else harmonics
    Kd = (Gc.shape[1] - 1) // 2
    if Kd < K:
        raise ValueError(f"the data have {Kd} harmonics, fewer than the model's {K}")
    fit = _FloquetFit(nx, ny, nu, K, H, sys.period, estimate_d, fit_a, Kd)
    A0 = sys.A(0.0)
    scale = max(np.linalg.norm(Gc), np.finfo(float).tiny)

    nfev = 0

    def cost(theta, jac=False):
        nonlocal nfev
        nfev += 1
        G, J = fit.response_and_jacobian(theta, omega, A0, jac)
        r = (G - Gc).ravel() / scale
        r = np.concatenate([r.real, r.imag])
        return (r, np.vstack([J.real, J.imag]) / scale) if jac else r

    theta = fit.pack(sys)
    r, J = cost(theta, True)
    f = r @ r
    mu, converged = 0.0, False
    bar = tqdm(total=maxiter, desc="refit", disable=not progress, leave=False)
    for _ in range(maxiter):
        bar.update(1)
        # column scaling, floored so that (nearly) uninfluential parameters stay put
        colnorm = np.linalg.norm(J, axis=0)
        colnorm = np.maximum(colnorm, 1e-8 * max(colnorm.max(), np.finfo(float).tiny))
        # one SVD per iteration: the damped step -V diag(s/(s²+μ)) U^T r for any μ
        # (the scaled Jacobian written beside r in LAPACK's layout)
        Jr = np.empty((J.shape[0], J.shape[1] + 1), order='F')
        np.divide(J, colnorm, out=Jr[:, :-1])
        Jr[:, -1] = r
        Utr, sv, Vt = _stacked_projected_svd(Jr)
        if Utr is None:
            break                                 # a Jacobian the SVD cannot take: stop
        sv = np.where(sv > max(J.shape) * np.finfo(float).eps * sv[0], sv, 0.0)
        while True:
            with np.errstate(divide='ignore', invalid='ignore'):
                gain = np.where(sv > 0, sv / (sv ** 2 + mu), 0.0)
            step = -(Vt.T @ (gain * Utr)) / colnorm
            with np.errstate(all='ignore'):
                r_new = cost(theta + step)
            f_new = r_new @ r_new
            if np.isfinite(f_new) and f_new < f:
                break
            mu = max(10 * mu, 1e-8)
            if mu > 1e8:
                break
        if not (np.isfinite(f_new) and f_new < f):
            converged = True                      # no descent left: a (local) minimum
            break
        theta, decrease, f = theta + step, f - f_new, f_new
        mu = mu / 10 if mu > 1e-7 else 0.0
        if decrease <= rtol * max(f, np.finfo(float).tiny) or f < 1e-30:
            converged = True
            break
        r, J = cost(theta, True)
    bar.close()
    A, Bc, Cc, Dc = fit.unpack(theta, A0)
    period = sys.period
    L = Kd + H
    Cc = Cc[L - 2 * K:L + 2 * K + 1]                              # harmonics -2K..2K
    Dc = Dc[Kd - K:Kd + K + 1]                                    # harmonics -K..K
    model = LTPStateSpace(A, PeriodicMatrix(Bc, period), PeriodicMatrix(Cc, period),
                          PeriodicMatrix(Dc, period), period, states=sys.state_labels,
                          **labels)
    return model, float(np.sqrt(f)), converged, nfev


def _projected_svd(J, r):
    """``(U^T r, s, V^T)`` of the thin SVD ``J = U diag(s) V^T``, without `U`.

    A Householder QR of ``[J r]`` (R factor only) brings the tall ``m x p``
    Jacobian to ``(p+1) x p`` with ``Q^T r`` beside it, whose SVD has the
    singular values and right vectors of `J` (``U = Q U_R``); that is about
    half the work of the SVD of `J` with its ``m x p`` left vectors.
    The factor has ``m`` rows, zero below the triangle: when LAPACK's SVD
    would factor a matrix of its shape by a QR first (``m >= 11 p / 6``; that
    QR leaves the triangle as it is), the SVD is taken of the ``p x p``
    triangle alone, the same result bit for bit at a fraction of the work,
    and only that triangle is copied out of LAPACK's factor.
    ``(None, None, None)`` when `J` is not finite or the SVD fails
    (`_robust_svd`).
    """
    Jr = np.empty((J.shape[0], J.shape[1] + 1), order='F')   # LAPACK's layout
    Jr[:, :-1], Jr[:, -1] = J, r
    return _stacked_projected_svd(Jr)


def _stacked_projected_svd(Jr):
    """`_projected_svd` of ``J, r`` given as ``Jr = [J r]`` in Fortran order
    (overwritten by the QR), so that LAPACK takes it without a copy."""
    if not np.all(np.isfinite(Jr[:, :-1])):
        return None, None, None
    m, p = Jr.shape[0], Jr.shape[1] - 1
    qr = _householder_qr(Jr)
    if m < int(p * 11 / 6):                   # LAPACK takes the factor as it is
        R = np.triu(qr)
        Ur, s, Vt = _robust_svd(R[:, :p])
        if Ur is None:
            return None, None, None
        return Ur.T @ R[:, p], s, Vt
    Ur, s, Vt = _robust_svd(np.triu(qr[:p, :p]))
    if Ur is None:
        return None, None, None
    Qtr = np.zeros(m)
    Qtr[:p + 1] = qr[:p + 1, p]               # the last column of R: Q^T r
    U = np.zeros((m, Ur.shape[1]))           # U = [U_R; 0]
    U[:p] = Ur
    return U.T @ Qtr, s, Vt


def _householder_qr(a):
    """LAPACK's ``geqrf`` of the Fortran-ordered `a` in place (R in its upper
    triangle, the reflectors below), with the optimal workspace, as
    `scipy.linalg.qr` calls it; without the copy of the whole triangle."""
    geqrf, = scipy.linalg.get_lapack_funcs(('geqrf',), (a,))
    lwork = geqrf(a, lwork=-1, overwrite_a=True)[2][0].real.astype(np.int_)
    qr, _, _, info = geqrf(a, lwork=lwork, overwrite_a=True)
    if info < 0:
        raise ValueError(f"illegal value in {-info}th argument of internal geqrf")
    return qr


def _robust_svd(J):
    """Thin SVD of `J`; LAPACK's divide and conquer may not converge on badly
    scaled Jacobians: then the slower QR iteration ('gesvd'), and ``(None, None,
    None)`` if `J` is not finite or neither converges (the refit stops there)."""
    if not np.all(np.isfinite(J)):
        return None, None, None
    try:
        return np.linalg.svd(J, full_matrices=False)
    except np.linalg.LinAlgError:
        try:
            return scipy.linalg.svd(J, full_matrices=False, lapack_driver='gesvd')
        except (np.linalg.LinAlgError, ValueError):
            return None, None, None
