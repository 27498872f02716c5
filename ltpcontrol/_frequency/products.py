"""Products of harmonic objects realized exactly as one periodic system.

A loop made of a converter model and a network impedance, ``L = Z Y``,
is counted exactly by `nyquist_htf` when it is one `LTPStateSpace`.  The
product ``F_1 F_2 ... F_k`` (``F_k`` acts first) of periodic systems, their
HTF models (`htf`), LTI systems and `LTIHTF` impedances is realized here:
proper factors in series, and the polynomial part of an improper LTI factor
``Z(s) = Z_p(s) + Σ_{j>=1} P_j s^j`` absorbed by a neighbouring periodic
factor, without approximation:

* on the left of ``Y = (A, B, C, D)`` (``Z Y``): ``s^j Y`` is the j-th
  derivative of the output, ``y^(j) = C_j x + D_j u`` with
  ``C_{i+1} = Ċ_i + C_i A``, ``D_{i+1} = C_i B`` (``C_0 = C``), which
  needs ``D_i = 0`` for i < j (Y of relative degree >= j);
* on the right (``Y Z``): ``Y s^j`` differentiates the input; with
  ``B_{i+1} = A B_i - Ḃ_i``, ``D_{i+1} = C B_i`` (``B_0 = B``) the same
  condition.

The derivatives of C(t), B(t) are exact for constant matrices and exact
Fourier forms.  A product that stays improper (an impedance ``sL`` times a
biproper admittance) has no state space: it is refused, naming the
factor.  Estimated HTFs (`HTFData`) are not models; see
`impedance_nyquist`.
"""

import numbers

import numpy as np
import control as ct
from control.exception import ControlArgument

from .htf import HTF, HTFModel, HTFData
from .impedance import LTIHTF, as_lti
from .._core.ltpsys import LTPStateSpace, series
from .._core.periodic_matrix import PeriodicMatrix
from .._core.validation import commensurate

__all__ = ['harmonic_product']


def harmonic_product(*factors, period=None, name=None):
    """Exact periodic realization of a product of harmonic objects.

    Parameters
    ----------
    *factors : LTPStateSpace, HTFModel, LTIHTF, control LTI system or float
        ``F_1, ..., F_k`` of the product ``F_1 F_2 ... F_k`` (``F_k`` acts
        first), e.g. ``(Z_g, Y)`` for a grid impedance and a converter
        admittance.  LTI factors may be improper when a neighbouring
        periodic factor absorbs their polynomial part (module notes).
    period : float, optional
        Period, needed only when no factor has one.
    name : str, optional
        Name of the result (default 'L').

    Returns
    -------
    LTPStateSpace
        Continuous-time; its HTF is the product of the factors' HTFs.

    Raises
    ------
    ValueError
        For an `HTFData` factor (data are not a model: use
        `impedance_nyquist` / `impedance_margins`), a product that stays
        improper, incommensurate periods, or a derivative of a matrix
        without an exact Fourier form.
    ControlArgument
        For a factor of another type.

    Examples
    --------
    The grid inductance ``sL`` times an admittance ``1/(L_f s + R)``,
    here written as periodic: the product is biproper, ``L/L_f`` at
    infinity.

    >>> Y = ltp.ltpss(ct.tf([1], [2e-3, 0.1]), period=0.02)
    >>> Zg = ltp.rlc_impedance(L=5e-3, period=0.02, nharmonics=3)
    >>> L = ltp.harmonic_product(Zg, Y)
    >>> float(L.D(0.0)[0, 0])
    2.5
    >>> s = 7j
    >>> bool(np.isclose(ltp.htf(L, 3)(s)[3, 3], 5e-3 * s / (2e-3 * s + 0.1)))
    True
    """
    if not factors:
        raise ControlArgument("harmonic_product needs at least one factor")
    items = [_classify(f, i) for i, f in enumerate(factors)]
    periods = [p for _, _, p in items if p is not None]
    if period is not None:
        periods.append(period)
    if not periods:
        raise ValueError("harmonic_product: no factor has a period; pass period=")
    T = periods[0]
    for p in periods[1:]:
        try:
            T = commensurate(T, p)
        except ValueError:
            raise ValueError(f"harmonic_product: the periods {T:g} and {p:g} of the "
                             "factors are not commensurate") from None
    # (kind, payload, index): 'ss' with an LTPStateSpace; 'poly' with (P_j list, proper)
    parts = []
    for (kind, obj, _), i in zip(items, range(len(items))):
        if kind == 'ss':
            parts.append(['ss', obj, i])
        else:
            poly, proper = _split(obj)
            sys = LTPStateSpace(proper.A, proper.B, proper.C, proper.D, T,
                                name=f'F{i + 1}')
            parts.append(['poly', (poly, proper), i] if poly else ['ss', sys, i])
    while any(p[0] == 'poly' for p in parts):
        j = next(k for k, p in enumerate(parts) if p[0] == 'poly')
        poly, proper = parts[j][1]
        right = parts[j + 1] if j + 1 < len(parts) and parts[j + 1][0] == 'ss' else None
        left = parts[j - 1] if j > 0 and parts[j - 1][0] == 'ss' else None
        merged = None
        if right is not None:
            merged = _absorb_left(poly, proper, right[1])
            if merged is not None:
                parts[j:j + 2] = [['ss', merged, parts[j][2]]]
                continue
        if left is not None:
            merged = _absorb_right(poly, proper, left[1])
            if merged is not None:
                parts[j - 1:j + 1] = [['ss', merged, parts[j][2]]]
                continue
        raise ValueError(
            f"harmonic_product: factor {parts[j][2] + 1} is improper (degree "
            f"{len(poly)} polynomial part) and no neighbouring periodic factor has the "
            f"relative degree to absorb it: the product is improper and has no state "
            "space (its HTF is still exact: evaluate the factors' HTFs and multiply)")
    systems = [p[1] for p in parts]
    out = systems[0] if len(systems) == 1 else series(*reversed(systems))
    return LTPStateSpace(out.A, out.B, out.C, out.D, out.period, name=name or 'L',
                         inputs=systems[-1].input_labels, outputs=systems[0].output_labels)


def is_harmonic_sequence(L):
    """True for a sequence of factors with a harmonic object among them.

    Examples
    --------
    >>> from ltpcontrol._frequency.products import is_harmonic_sequence
    >>> Z = ltp.rlc_impedance(L=1e-3, period=1.0, nharmonics=1)
    >>> is_harmonic_sequence((Z, ct.tf([1], [1, 1]))), is_harmonic_sequence(Z)
    (True, False)
    """
    return isinstance(L, (list, tuple)) and any(isinstance(f, HTF) for f in L)


#
# Helpers
#

def _classify(f, i):
    where = f"factor {i + 1}"
    if isinstance(f, HTFData):
        raise ValueError(f"harmonic_product: {where} is sampled data (an HTFData), not a "
                         "model; analyse a loop with measured factors with "
                         "ltp.impedance_nyquist / ltp.impedance_margins")
    if isinstance(f, LTIHTF):
        return 'lti', f.sys, f.period
    if isinstance(f, HTFModel):
        sys = f._source[0]
        return 'ss', sys, sys.period
    if isinstance(f, HTF):
        raise ControlArgument(f"harmonic_product: {where} is a {type(f).__name__}, which "
                              "has no periodic state space")
    if isinstance(f, LTPStateSpace):
        if f.isdtime():
            raise ValueError(f"harmonic_product: {where} is discrete-time")
        return 'ss', f, f.period
    if isinstance(f, (ct.TransferFunction, ct.StateSpace)) or isinstance(f, numbers.Real) \
            or isinstance(f, (np.ndarray, list)):
        return 'lti', as_lti(f, where), None
    raise ControlArgument(f"harmonic_product: {where} must be a system or a harmonic "
                          f"object, got {type(f).__name__}")


def _split(sys):
    """(``[P_1, ..., P_d]``, proper StateSpace) with ``G = proper + Σ P_j s^j``."""
    if isinstance(sys, ct.StateSpace):
        return [], sys
    ny, nu = sys.noutputs, sys.ninputs
    d = 0
    quot = [[None] * nu for _ in range(ny)]
    rem = [[None] * nu for _ in range(ny)]
    for i in range(ny):
        for j in range(nu):
            num = np.atleast_1d(np.asarray(sys.num[i][j], float))
            den = np.atleast_1d(np.asarray(sys.den[i][j], float))
            q, r = np.polydiv(num, den) if len(num) >= len(den) else (np.zeros(1), num)
            quot[i][j], rem[i][j] = q, (r, den)
            d = max(d, len(q) - 1)
    poly = []
    for k in range(1, d + 1):
        P = np.zeros((ny, nu))
        for i in range(ny):
            for j in range(nu):
                q = quot[i][j]
                if len(q) - 1 >= k:
                    P[i, j] = q[len(q) - 1 - k]
        poly.append(P)
    while poly and not np.any(poly[-1]):
        poly.pop()
    num = [[np.polyadd(np.polymul([quot[i][j][-1]], rem[i][j][1]), rem[i][j][0])
            for j in range(nu)] for i in range(ny)]
    den = [[rem[i][j][1] for j in range(nu)] for i in range(ny)]
    proper = ct.ss(ct.tf(num, den))
    return poly, proper


def _derivative(M):
    """Ṁ of a constant or exact-Fourier `PeriodicMatrix`, else None."""
    if M.is_constant:
        return PeriodicMatrix.constant(np.zeros(M.shape), M.period)
    K = M.nharmonics
    if K is None:
        return None
    c = M.fourier(K) * (1j * M.omega_p * np.arange(-K, K + 1))[:, None, None]
    return PeriodicMatrix(c, M.period)


def _is_zero(M):
    if M.nharmonics is not None:
        c = M.fourier(M.nharmonics)
        return not np.any(np.abs(c) > 0)
    return not np.any(M.sample(64))


def _absorb_left(poly, proper, Y):
    """``(Z_p + Σ P_j s^j) Y`` as one system, or None when Y cannot absorb it."""
    d = len(poly)
    Cs, Ds = [Y.C], [Y.D]
    for _ in range(d):
        Cdot = _derivative(Cs[-1])
        if Cdot is None or not _is_zero(Ds[-1]):
            return None
        Cs.append(Cdot + Cs[-1] @ Y.A)
        Ds.append(Cs[-2] @ Y.B)
    # outputs [y; y'; ...; y^(d)], then [Z_p, P_1, ..., P_d] on them
    C = PeriodicMatrix.block([[c] for c in Cs])
    D = PeriodicMatrix.block([[x] for x in Ds])
    ext = LTPStateSpace(Y.A, Y.B, C, D, Y.period, inputs=Y.input_labels)
    a, b, c, dd = _matrices(proper)
    mix = ct.ss(a, np.hstack([b] + [np.zeros((len(a), Y.noutputs))] * d), c,
                np.hstack([dd] + list(poly)))
    return series(ext, mix)


def _absorb_right(poly, proper, Y):
    """``Y (Z_p + Σ P_j s^j)`` as one system, or None when Y cannot absorb it."""
    d = len(poly)
    Bs, Ds = [Y.B], [Y.D]
    for _ in range(d):
        Bdot = _derivative(Bs[-1])
        if Bdot is None or not _is_zero(Ds[-1]):
            return None
        Bs.append(Y.A @ Bs[-1] - Bdot)
        Ds.append(Y.C @ Bs[-2])
    B = PeriodicMatrix.block([Bs])
    D = PeriodicMatrix.block([Ds])
    ext = LTPStateSpace(Y.A, B, Y.C, D, Y.period, outputs=Y.output_labels)
    a, b, c, dd = _matrices(proper)
    stack = ct.ss(a, b, np.vstack([c] + [np.zeros((Y.ninputs, len(a)))] * d),
                  np.vstack([dd] + list(poly)))
    return series(stack, ext)


def _matrices(sys):
    """(A, B, C, D) of an LTI state space as 2D arrays, also without states."""
    n, ny, nu = sys.nstates, sys.noutputs, sys.ninputs
    return (np.asarray(sys.A, float).reshape(n, n), np.asarray(sys.B, float).reshape(n, nu),
            np.asarray(sys.C, float).reshape(ny, n), np.asarray(sys.D, float).reshape(ny, nu))
