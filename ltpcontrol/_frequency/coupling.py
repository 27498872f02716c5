"""HTFs of three-phase systems in the abc, αβ, dq and sequence domains.

A change of frame of the inputs and outputs, ``u = T_in(t) u'``,
``y' = T_out(t) y``, by memoryless periodic matrices (Park's rotation at
the grid speed ω_1, Clarke's constant matrix, the complex sequence
vectors) multiplies the HTF by their block-Toeplitz HTFs,

    Ĥ'(s) = 𝒯_out Ĥ(s) 𝒯_in,      (𝒯)_{n,m} = T_{n-m},

with ``T_k`` the Fourier coefficients of T(t) at the harmonics of ω_1
(period ``2π/ω_1``).  The transforms have harmonics up to ±2, so the
central 2N+1 blocks of the result are exact when Ĥ is evaluated with N + 2
harmonics: `frame_htf` does so.  A dq-frame model that is LTI but not
symmetric (a PLL or a dc-link loop makes ``Y_dd ≠ Y_qq``) becomes
periodic in αβ: the frequency ``s`` of the positive-sequence vector
``x_p = x_α + j x_β`` is coupled with ``s - 2jω_1`` of the negative one
``x_n = x_α - j x_β`` — the *mirror frequency coupling* that the blocks
``(n, n ∓ 2)`` of the 'pn' HTF hold.

Frames (amplitude-invariant, d aligned with phase a at ``θ = ω_1 t + θ_0``):
'abc' (3 signals), 'ab' (α, β), 'ab0' (α, β, 0), 'dq', 'dq0', and 'pn'
(complex ``x_p = x_α + j x_β``, ``x_n = x_α - j x_β``).  A 2-signal frame
seen from 'abc' drops the zero sequence.
"""

import numpy as np

from .htf import HTF, HTFModel, HTFData, htf
from .impedance import LTIHTF
from .._core.frames import clarke_matrix
from .._core.ltpsys import LTPStateSpace
from .._core.validation import check_positive_int, real_array

__all__ = ['frame_htf', 'FrameHTF']

_FRAMES = {'abc': 3, 'ab': 2, 'ab0': 3, 'dq': 2, 'dq0': 3, 'pn': 2}
# harmonics of ω_1 in a composed transform (rotation times rotation)
_BAND = 2


def frame_htf(H, source, target, omega1, *, theta0=0.0, nharmonics=None, name=None):
    """The HTF of a three-phase system with its inputs and outputs in another frame.

    Parameters
    ----------
    H : LTPStateSpace, HTFModel, LTIHTF or control LTI system
        The system in the frame `source` (square in signals: 2 or 3 inputs
        and outputs as the frame has).  A periodic model must have a period
        dividing ``2π/|ω_1|``.
    source, target : {'abc', 'ab', 'ab0', 'dq', 'dq0', 'pn'}
        Frames of the given and of the returned HTF (module notes).
    omega1 : float
        Angular speed of the synchronous frame (rad/s), nonzero.
    theta0 : float
        Angle of the d axis at t = 0.
    nharmonics : int, optional
        Harmonics -N..N of the result (default: those of `H` for an HTF,
        else 2).
    name : str, optional
        Name of the result.

    Returns
    -------
    FrameHTF
        Period ``2π/|ω_1|``; complex signals for 'pn'.

    Raises
    ------
    ValueError
        For an unknown frame, a signal count that does not fit the frame,
        a period that does not divide ``2π/|ω_1|``, or a measured HTF.

    Examples
    --------
    A balanced R-L line is ``R + sL`` per phase in αβ, and in dq the
    rotation couples d and q; back in αβ it is diagonal again, exactly:

    >>> w1 = 2 * np.pi * 50
    >>> Zdq = ltp.rlc_impedance(0.1, 2e-3, period=0.02, nharmonics=2, omega1=w1)
    >>> Zab = ltp.frame_htf(Zdq, 'dq', 'ab', w1)
    >>> s = 30j + 0.5
    >>> H = Zab(s)
    >>> bool(np.isclose(H[4, 4], 0.1 + 2e-3 * s) and abs(H[4, 5]) < 1e-12)
    True
    """
    if source not in _FRAMES or target not in _FRAMES:
        raise ValueError(f"source and target must be frames among {sorted(_FRAMES)}, got "
                         f"{source!r} and {target!r}")
    w1 = float(real_array(omega1, 'omega1', ndim=0))
    if w1 == 0:
        raise ValueError("omega1 must be nonzero (the speed of the synchronous frame)")
    th0 = float(real_array(theta0, 'theta0', ndim=0))
    T1 = 2 * np.pi / abs(w1)
    inner = _inner(H, T1)
    n = _FRAMES[source]
    if inner.ninputs != n or inner.noutputs != n:
        raise ValueError(f"a system in the frame {source!r} has {n} inputs and {n} outputs; "
                         f"H has {inner.ninputs} and {inner.noutputs}")
    N = (getattr(H, 'nharmonics', 2) if nharmonics is None
         else check_positive_int(nharmonics, 'nharmonics', minimum=0))
    # y' = T_out(t) y (source -> target), u = T_in(t) u' (target -> source)
    t = np.arange(8) * T1 / 8
    Tout = _coefficients(np.array([_map(source, target, w1 * tk + th0) for tk in t]))
    Tin = _coefficients(np.array([_map(target, source, w1 * tk + th0) for tk in t]))
    return FrameHTF(inner, Tout, Tin, T1, N, name=name or f'{getattr(H, "name", "H")}@{target}',
                    frame=target)


class FrameHTF(HTF):
    """HTF of a system whose inputs and outputs changed frame (see `frame_htf`).

    Parameters
    ----------
    inner : callable
        ``inner(K)`` returns the HTF of the system in its own frame with K
        harmonics.
    Tout, Tin : ndarray of complex, shape (5, rows, cols)
        Fourier coefficients (harmonics -2..2) of the output and input
        transforms.
    period : float
        Period ``2π/|ω_1|``.
    nharmonics : int
        Harmonics of the result.
    name : str, optional
        Name.
    frame : str, optional
        Frame of the result (signal names).

    Examples
    --------
    >>> w1 = 100.0
    >>> Z = ltp.frame_htf(ltp.rlc_impedance(1.0, 0.01, period=1.0, nharmonics=1,
    ...                   omega1=w1), 'dq', 'pn', w1)
    >>> type(Z).__name__, Z.input_labels
    ('FrameHTF', ['u_p', 'u_n'])
    """

    def __init__(self, inner, Tout, Tin, period, nharmonics, *, name=None, frame='ab'):
        K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
        labels = {'abc': ['a', 'b', 'c'], 'ab': ['alpha', 'beta'],
                  'ab0': ['alpha', 'beta', '0'], 'dq': ['d', 'q'], 'dq0': ['d', 'q', '0'],
                  'pn': ['p', 'n']}.get(frame, None)
        p, q = Tout.shape[1], Tin.shape[2]
        self._set_signals(period, K, p, q, 0.0, name,
                          [f'u_{x}' for x in labels] if labels and len(labels) == q else None,
                          [f'y_{x}' for x in labels] if labels and len(labels) == p else None)
        self._inner, self._Tout, self._Tin = inner, Tout, Tin

    def _evaluate(self, s, progress):
        K = self.nharmonics
        Kb = K + _BAND
        Hb = _as_points(self._inner(Kb)(s))
        left = _toeplitz(self._Tout, np.arange(-K, K + 1), np.arange(-Kb, Kb + 1))
        right = _toeplitz(self._Tin, np.arange(-Kb, Kb + 1), np.arange(-K, K + 1))
        return left @ Hb @ right

    def _components_on(self, omega, ks, progress=None):
        from .htf import default_omega
        omega = (default_omega(self) if omega is None
                 else real_array(omega, 'omega', ndim=(0, 1)).reshape(-1))
        M = self._evaluate(1j * omega, progress)
        K, p, q = self.nharmonics, self.noutputs, self.ninputs
        G = np.empty((len(ks), p, q, len(omega)), complex)
        for i, k in enumerate(ks):
            b = -k + K
            G[i] = M[:, K * p:(K + 1) * p, b * q:(b + 1) * q].transpose(1, 2, 0)
        return omega, G


#
# Helpers
#

def _inner(H, T1):
    """``K -> HTF with K harmonics`` of H at the period T1."""
    if isinstance(H, HTFData):
        raise ValueError("frame_htf: a measured HTF (HTFData) is known on its grid only; "
                         "change the frame of the signals before estimating it")
    if isinstance(H, LTIHTF):
        sys = H.sys
        out = lambda K: LTIHTF(sys, T1, K)
        out.ninputs, out.noutputs = sys.ninputs, sys.noutputs
        return out
    if isinstance(H, HTFModel):
        H = H._source[0]
    if isinstance(H, HTF):
        raise ValueError(f"frame_htf: a {type(H).__name__} cannot be re-evaluated with more "
                         "harmonics; pass the system")
    if isinstance(H, LTPStateSpace):
        ratio = T1 / H.period
        if abs(ratio - round(ratio)) > 1e-9 * ratio or round(ratio) < 1:
            raise ValueError(f"frame_htf: the period {H.period:g} of H does not divide "
                             f"2π/|ω_1| = {T1:g}")
        sys = LTPStateSpace(H.A, H.B, H.C, H.D, T1, name=H.name)
        out = lambda K: htf(sys, K)
        out.ninputs, out.noutputs = sys.ninputs, sys.noutputs
        return out
    lti = LTIHTF(H, T1, 0)
    return _inner(lti, T1)


def _as_points(M):
    """HTF values with the points first."""
    M = np.asarray(M, complex)
    return np.moveaxis(M, -1, 0) if M.ndim == 3 else M[None]


def _to_ab(frame, theta):
    """Matrix from the frame's signals to (α, β[, 0])."""
    c, s = np.cos(theta), np.sin(theta)
    if frame in ('ab', 'ab0'):
        return np.eye(_FRAMES[frame])
    if frame == 'abc':
        return clarke_matrix()
    if frame == 'dq':
        return np.array([[c, -s], [s, c]])
    if frame == 'dq0':
        return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    # pn: x_α = (x_p + x_n)/2, x_β = (x_p - x_n)/(2j)
    return np.array([[0.5, 0.5], [-0.5j, 0.5j]])


def _from_ab(frame, theta):
    """Matrix from (α, β[, 0]) to the frame's signals."""
    c, s = np.cos(theta), np.sin(theta)
    if frame in ('ab', 'ab0'):
        return np.eye(_FRAMES[frame])
    if frame == 'abc':
        return np.linalg.inv(clarke_matrix())
    if frame == 'dq':
        return np.array([[c, s], [-s, c]])
    if frame == 'dq0':
        return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1.0]])
    return np.array([[1.0, 1j], [1.0, -1j]])


def _map(source, target, theta):
    """Matrix taking signals in `source` to `target` at the frame angle θ."""
    a = _to_ab(source, theta)
    b = _from_ab(target, theta)
    # 2- and 3-signal αβ: drop or add the zero sequence
    if a.shape[0] == 3 and b.shape[1] == 2:
        a = a[:2]
    elif a.shape[0] == 2 and b.shape[1] == 3:
        a = np.vstack([a, np.zeros((1, a.shape[1]))])
    return b @ a


def _coefficients(samples):
    """Fourier coefficients -2..2 of a trigonometric polynomial of degree <= 2
    from 8 uniform samples (exact)."""
    F = np.fft.fft(samples, axis=0) / len(samples)
    return np.stack([F[k % len(samples)] for k in range(-_BAND, _BAND + 1)])


def _toeplitz(coeffs, rows, cols):
    """Block matrix with blocks ``T_{n-m}`` (zero beyond ±2), n in rows, m in cols."""
    p, q = coeffs.shape[1:]
    out = np.zeros((len(rows) * p, len(cols) * q), complex)
    for a, n in enumerate(rows):
        for b, m in enumerate(cols):
            k = n - m
            if abs(k) <= _BAND:
                out[a * p:(a + 1) * p, b * q:(b + 1) * q] = coeffs[k + _BAND]
    return out
