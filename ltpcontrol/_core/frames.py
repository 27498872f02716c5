"""Three-phase reference frames: Clarke (αβ0), Park (dq0) and sequence components.

Amplitude-invariant transforms (a balanced set of amplitude X maps to
``|x_αβ| = X``, ``x_d = X`` when aligned):

    T_αβ0 = (2/3) [[1, -1/2, -1/2], [0, √3/2, -√3/2], [1/2, 1/2, 1/2]],

    T_dq0(θ) = (2/3) [[cos θ, cos(θ - 2π/3), cos(θ + 2π/3)],
                      [-sin θ, -sin(θ - 2π/3), -sin(θ + 2π/3)],
                      [1/2, 1/2, 1/2]],      θ = ω t + θ_0.

A change of frame of an LTP system, new state ``z = T(t) x``, new input
``u' = T_u(t) u``, new output ``y' = T_y(t) y``, is

    A' = (T A + Ṫ) T⁻¹,  B' = T B T_u⁻¹,  C' = T_y C T⁻¹,  D' = T_y D T_u⁻¹;

the Park transform of a balanced (phase-symmetric) three-phase LTI system
is LTI: the rotation ``Ṫ T⁻¹`` is the constant coupling ``ω [[0, 1],
[-1, 0]]`` of d and q.  Symmetrical (Fortescue) components of phasors:
``[X_0, X_+, X_-] = (1/3) [[1, 1, 1], [1, a, a²], [1, a², a]] X_abc``,
``a = e^{j2π/3}``.
"""

import numpy as np
from control.exception import ControlArgument, ControlDimension

from .ltpsys import LTPStateSpace
from .periodic_matrix import PeriodicMatrix
from .coerce import as_ltp
from .validation import commensurate, real_array

__all__ = ['clarke_matrix', 'park_matrix', 'frame_transform', 'park', 'clarke',
           'sequence_components']

_PHASES = np.array([0.0, 2 * np.pi / 3, -2 * np.pi / 3])


def clarke_matrix(zero_sequence=True):
    """Amplitude-invariant Clarke matrix ``T_αβ0`` (3x3), or ``T_αβ`` (2x3).

    Parameters
    ----------
    zero_sequence : bool
        Keep the zero-sequence row (default; then the matrix is invertible).

    Returns
    -------
    ndarray

    Examples
    --------
    >>> t = 0.3
    >>> abc = np.cos(t - np.array([0, 2 * np.pi / 3, -2 * np.pi / 3]))
    >>> np.round(ltp.clarke_matrix() @ abc - [np.cos(t), np.sin(t), 0], 12) + 0.0
    array([0., 0., 0.])
    """
    T = (2 / 3) * np.array([[1.0, -0.5, -0.5],
                            [0.0, np.sqrt(3) / 2, -np.sqrt(3) / 2],
                            [0.5, 0.5, 0.5]])
    return T if zero_sequence else T[:2]


def park_matrix(omega, theta0=0.0, *, inverse=False):
    """Park matrix ``T_dq0(ωt + θ_0)`` as a `PeriodicMatrix` of period ``2π/|ω|``.

    Parameters
    ----------
    omega : float
        Angular speed of the frame (rad/s, nonzero; negative for a frame
        rotating backwards).
    theta0 : float
        Frame angle at t = 0.
    inverse : bool
        Return ``T_dq0⁻¹`` instead.

    Returns
    -------
    PeriodicMatrix
        Exact Fourier form (harmonics -1..1).

    Examples
    --------
    A balanced set ``cos(ωt - φ_b)`` is the constant ``d = 1, q = 0``:

    >>> T = ltp.park_matrix(2.0)
    >>> t = 0.7
    >>> np.round(T(t) @ np.cos(2.0 * t - np.array([0, 2, -2]) * np.pi / 3), 12) + 0.0
    array([1., 0., 0.])
    """
    w = float(real_array(omega, 'omega', ndim=0))
    if w == 0:
        raise ValueError("omega must be nonzero (a Park frame rotates); use "
                         "clarke_matrix for a stationary frame")
    theta0 = float(real_array(theta0, 'theta0', ndim=0))
    s = 0 if w > 0 else 1                   # index of harmonic sign(ω) in (+1, -1)
    # cos(θ - φ) and -sin(θ - φ) have the coefficient e^{j(θ0 - φ)}/2 and
    # j e^{j(θ0 - φ)}/2 at the harmonic sign(ω), conjugates at -sign(ω)
    e = np.exp(1j * (theta0 - _PHASES)) / 2
    plus = np.array([e, 1j * e, np.zeros(3)])                     # rows d, q, 0
    c = np.zeros((3, 3, 3), complex)
    c[2 - 2 * s], c[2 * s] = plus, np.conj(plus)
    c[1, 2] = 0.5
    c *= 2 / 3
    if inverse:
        # T⁻¹ = [[cos(θ - φ_a), -sin(θ - φ_a), 1]]: (3/2) T^T with the last column 1
        c = 1.5 * c.transpose(0, 2, 1)
        c[1, :, 2] = 1.0
    return PeriodicMatrix(c, 2 * np.pi / abs(w))


def frame_transform(sys, states=None, inputs=None, outputs=None, *, name=None):
    """Change the frames of the states, inputs and outputs of an LTP system.

    Parameters
    ----------
    sys : LTPStateSpace or control.StateSpace
        Continuous-time system (an LTI system takes the period of the
        transforms).
    states, inputs, outputs : PeriodicMatrix or array_like, optional
        Invertible transforms ``z = T x``, ``u' = T_u u``, ``y' = T_y y``
        (None: unchanged), or pairs ``(T, T⁻¹)`` when the inverse is known
        in closed form.  A time-varying state transform needs an exact
        Fourier form (e.g. `park_matrix`), whose derivative enters A.
    name : str, optional
        Name of the result.

    Returns
    -------
    LTPStateSpace
        Period: the common period of `sys` and the transforms.  Matrices
        whose harmonics cancel (to 1e-12 relative) are returned constant,
        so a balanced three-phase LTI system in the Park frame is LTI.

    Examples
    --------
    A balanced R-L line, ``L di/dt = -R i + v`` per phase, in the dq0 frame
    of the grid (ω = 100π): ``A' = -R/L I + ω [[0, 1, 0], [-1, 0, 0], [0, 0, 0]]``.

    >>> R, Lh, w = 0.1, 1e-3, 100 * np.pi
    >>> line = ct.ss(-R / Lh * np.eye(3), np.eye(3) / Lh, np.eye(3), 0)
    >>> T = ltp.park_matrix(w)
    >>> dq = ltp.frame_transform(line, states=T, inputs=T, outputs=T)
    >>> dq.is_lti
    True
    >>> want = -R / Lh * np.eye(3) + w * np.array([[0, 1, 0], [-1, 0, 0], [0, 0, 0]])
    >>> bool(np.allclose(dq.A(0.0), want))
    True
    """
    mats = [M[0] if isinstance(M, tuple) else M for M in (states, inputs, outputs)]
    mats = [M for M in mats if isinstance(M, PeriodicMatrix)]
    if not isinstance(sys, LTPStateSpace):
        if not mats:
            raise ControlArgument("frame_transform of an LTI system needs at least one "
                                  "periodic transform (e.g. ltp.park_matrix)")
        sys = as_ltp(sys, 'sys', period=mats[0].period)
    if sys.isdtime():
        raise ValueError("frame_transform: sys must be a continuous-time system")
    period = sys.period
    for M in mats:
        try:
            period = commensurate(period, M.period)
        except ValueError:
            raise ValueError(f"the transform's period {M.period:g} and the system's "
                             f"{sys.period:g} are incommensurate") from None
    A, B, C, D = (M.with_period(period) for M in (sys.A, sys.B, sys.C, sys.D))
    if states is not None:
        T, Tinv, Tdot = _transform(states, sys.nstates, 'states', period)
        A = (T @ A + Tdot) @ Tinv
        B, C = T @ B, C @ Tinv
    if inputs is not None:
        _, Tinv, _ = _transform(inputs, sys.ninputs, 'inputs', period)
        B, D = B @ Tinv, D @ Tinv
    if outputs is not None:
        T, _, _ = _transform(outputs, sys.noutputs, 'outputs', period)
        C, D = T @ C, T @ D
    return LTPStateSpace(*(_simplify(M) for M in (A, B, C, D)), period,
                         name=name or f'{sys.name}$frame')


def park(sys, omega, theta0=0.0, *, states=True, inputs=True, outputs=True, name=None):
    """dq0 (Park) frame of a three-phase system.

    `frame_transform` with ``T_dq0`` (`park_matrix`) on every group of three
    signals (abc triples).

    Parameters
    ----------
    sys : LTPStateSpace or control.StateSpace
        Continuous-time system whose transformed signals come in abc triples.
    omega, theta0 : float
        Frame speed and angle (see `park_matrix`).
    states, inputs, outputs : bool
        Which signals to transform.
    name : str, optional
        Name of the result.

    Returns
    -------
    LTPStateSpace

    Examples
    --------
    >>> line = ct.ss(-100 * np.eye(3), 1000 * np.eye(3), np.eye(3), 0)
    >>> ltp.park(line, 100 * np.pi).is_lti
    True
    """
    T, Ti = park_matrix(omega, theta0), park_matrix(omega, theta0, inverse=True)
    return _three_phase(sys, T, Ti, states, inputs, outputs, name)


def clarke(sys, *, states=True, inputs=True, outputs=True, name=None, period=None):
    """αβ0 (Clarke) frame of a three-phase system (see `park`).

    Parameters
    ----------
    sys : LTPStateSpace or control.StateSpace
        Continuous-time system; an LTI one needs `period`.
    states, inputs, outputs : bool
        Which signals to transform.
    name : str, optional
        Name of the result.
    period : float, optional
        Period of an LTI `sys`.

    Returns
    -------
    LTPStateSpace

    Examples
    --------
    >>> line = ct.ss(-100 * np.eye(3), 1000 * np.eye(3), np.eye(3), 0)
    >>> ab = ltp.clarke(line, period=0.02)
    >>> np.allclose(ab.A(0.0), -100 * np.eye(3))
    True
    """
    if not isinstance(sys, LTPStateSpace):
        sys = as_ltp(sys, 'sys', period=period)
    T = PeriodicMatrix.constant(clarke_matrix(), sys.period)
    Ti = PeriodicMatrix.constant(np.linalg.inv(clarke_matrix()), sys.period)
    return _three_phase(sys, T, Ti, states, inputs, outputs, name)


def sequence_components(phasors, axis=-1, *, nharmonics=None):
    """Zero, positive and negative sequence components of three-phase phasors.

    Parameters
    ----------
    phasors : array_like of complex, or PeriodicMatrix
        Phase phasors ``X_a, X_b, X_c`` along `axis` (length 3); or a
        `PeriodicMatrix` with three rows (phases a, b, c), whose Fourier
        coefficients ``X_k`` are the phasors of harmonic k.
    axis : int
        The phase axis of an array.
    nharmonics : int, optional
        Harmonics -K..K of a `PeriodicMatrix` (default: its exact Fourier
        order, required otherwise).

    Returns
    -------
    ndarray of complex
        ``[X_0, X_+, X_-]`` along `axis`; for a `PeriodicMatrix`, shape
        ``(2K+1, 3, m)`` (harmonic, sequence, column).

    Examples
    --------
    A balanced positive-sequence set ``X_b = a² X_a``, ``X_c = a X_a``:

    >>> a = np.exp(2j * np.pi / 3)
    >>> np.round(ltp.sequence_components([1, a**2, a]), 12)
    array([0.+0.j, 1.+0.j, 0.+0.j])

    Three phase currents ``cos(ωt - φ_b)`` as a periodic matrix: harmonic +1
    is positive sequence, harmonic -1 its conjugate, negative sequence:

    >>> i_abc = ltp.park_matrix(1.0, inverse=True)[:, :1]     # cos(t - φ_b)
    >>> X = ltp.sequence_components(i_abc)
    >>> np.round(X[2, :, 0], 12), np.round(X[0, :, 0], 12)
    (array([0. +0.j, 0.5+0.j, 0. +0.j]), array([0. +0.j, 0. +0.j, 0.5+0.j]))
    """
    a = np.exp(2j * np.pi / 3)
    F = np.array([[1, 1, 1], [1, a, a * a], [1, a * a, a]]) / 3
    if isinstance(phasors, PeriodicMatrix):
        K = phasors.nharmonics if nharmonics is None else nharmonics
        if K is None:
            raise ControlArgument("sequence_components of a PeriodicMatrix without an exact "
                                  "Fourier form needs nharmonics")
        if phasors.shape[0] != 3:
            raise ControlDimension(f"the PeriodicMatrix must have 3 rows (phases a, b, c), "
                                   f"got {phasors.shape[0]}")
        return F @ phasors.fourier(K)
    X = np.moveaxis(real_array(phasors, 'phasors', allow_complex=True).astype(complex),
                    axis, -1)
    if X.shape[-1] != 3:
        raise ControlDimension(f"phasors must have 3 phases along axis {axis}, "
                               f"got {X.shape[-1]}")
    return np.moveaxis(X @ F.T, -1, axis)


#
# Helpers
#

def _transform(T, n, what, period):
    """(T, T⁻¹, Ṫ) as periodic matrices of the common period."""
    if isinstance(T, tuple):                      # (T, T⁻¹) known in closed form
        T, Tinv = T
    else:
        Tinv = None
    if not isinstance(T, PeriodicMatrix):
        M = real_array(T, what, ndim=2)
        T = PeriodicMatrix.constant(M, period)
    if T.shape != (n, n):
        raise ControlDimension(f"the {what} transform must be {n}x{n}, got {T.shape}")
    if Tinv is None:
        if T.is_constant:
            Tinv = PeriodicMatrix.constant(_inverse(T(0.0), what), T.period)
        elif T.nharmonics is not None:
            Tinv = _fourier_inverse(T, what)
        else:
            raise ControlArgument(f"the {what} transform must be constant or have an exact "
                                  "Fourier form (PeriodicMatrix(coeffs, period))")
    if T.is_constant or T.nharmonics is None:
        Tdot = PeriodicMatrix.constant(np.zeros((n, n)), period)
        if not T.is_constant and what == 'states':
            raise ControlArgument("a time-varying state transform needs an exact Fourier "
                                  "form (its derivative enters A)")
    else:
        K = T.nharmonics
        c = T.fourier(K) * (1j * T.omega_p * np.arange(-K, K + 1))[:, None, None]
        Tdot = PeriodicMatrix(c, T.period)
    return tuple(M.with_period(period) for M in (T, Tinv, Tdot))


def _fourier_inverse(T, what):
    """T⁻¹ in Fourier form when it is band-limited (rotations are), else a callable."""
    K = T.nharmonics
    M = 16 * (K + 1) + 1
    tk = np.arange(M) * T.period / M
    inv = np.array([_inverse(T(t), what) for t in tk])
    c = np.fft.fft(inv, axis=0) / M
    Kmax = M // 2
    coeffs = np.concatenate([c[-Kmax:], c[:Kmax + 1]])            # -Kmax..Kmax
    keep = 2 * K
    tail = np.abs(np.delete(coeffs, np.s_[Kmax - keep:Kmax + keep + 1], axis=0)).max()
    if tail <= 1e-12 * max(1.0, np.abs(coeffs).max()):
        return PeriodicMatrix(coeffs[Kmax - keep:Kmax + keep + 1], T.period)
    n = T.shape[0]
    return PeriodicMatrix.from_function(lambda t: _inverse(T(t), what), T.period,
                                        shape=(n, n))


def _inverse(M, what):
    if np.linalg.cond(M) > 1e12:
        raise ValueError(f"the {what} transform is singular")
    return np.linalg.inv(M)


def _simplify(M):
    """A Fourier-form matrix without its harmonics that cancel (constant if all do)."""
    K = M.nharmonics
    if K is None or K == 0:
        return M
    c = M.fourier(K)
    small = np.abs(c).max(axis=(1, 2)) <= 1e-12 * max(1.0, np.abs(c).max())
    k = K
    while k > 0 and small[K - k] and small[K + k]:
        k -= 1
    if k == 0:
        return PeriodicMatrix.constant(c[K].real, M.period)
    return PeriodicMatrix(c[K - k:K + k + 1], M.period) if k < K else M


def _three_phase(sys, T, Ti, states, inputs, outputs, name):
    if not isinstance(sys, LTPStateSpace):
        sys = as_ltp(sys, 'sys', period=T.period)

    def blocks(count, what):
        # blkdiag(T, ..., T) over the abc triples, exact Fourier form
        if count % 3:
            raise ControlDimension(f"the {what} of sys must come in abc triples, got {count}")
        eye = np.eye(count // 3)
        return tuple(PeriodicMatrix(np.array([np.kron(eye, c) for c in M.fourier(
            M.nharmonics)]), M.period) for M in (T, Ti))
    args = {}
    for flag, what, count in ((states, 'states', sys.nstates), (inputs, 'inputs', sys.ninputs),
                              (outputs, 'outputs', sys.noutputs)):
        if flag and count:
            args[what] = blocks(count, what)
    return frame_transform(sys, name=name, **args)
