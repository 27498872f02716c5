"""Higher-harmonic control (HHC) of an N/rev disturbance, as a periodic compensator.

The quasi-static T-matrix model (Johnson 1982) relates the cosine and sine
amplitudes of an N/rev input ``u = θ_c cos ωt + θ_s sin ωt`` (ω = NΩ) to
those of the N/rev output ``y = z_c cos ωt + z_s sin ωt`` in steady state,
``z = z_0 + T θ``.  From the HTF of a T_p-periodic plant with ``ω = N ω_p``
the output line at ω collects the input lines at ±ω:
``Y(ω) = G_0(jω) U(ω) + G_{2N}(jω) U(-ω)``, so with ``A_0 = G_0(jω)``,
``A_2 = G_{2N}(jω)`` (LTI plant: ``A_2 = 0``),

    T = [[Re(A_0 + A_2),  Im(A_0 - A_2)],
         [-Im(A_0 + A_2), Re(A_0 - A_2)]].

The once-per-revolution update ``θ ← θ - α M z``, ``M = (TᵀWT + R)⁻¹TᵀW``,
is, in continuous time, the periodic compensator of Hall & Wereley: the
output demodulated at ω, integrated with the rate γ = α/T_update and
remodulated,

    θ' = γ M [2 cos(ωt) I; 2 sin(ωt) I] e,   w = [cos(ωt) I, sin(ωt) I] θ,

with ``u = -w`` (negative feedback on the measurement e).  Averaged over a
period of ω, ``θ' = γ M z``; in steady state the average of θ' vanishes,
so ``M z = 0``: the N/rev output is driven to zero when M has full rank.
The loop ``L = P K`` is an LTP loop that `nyquist_htf` and
`harmonic_margins` analyse.
"""

import numpy as np
from control.exception import ControlDimension

from .._core.ltpsys import LTPStateSpace
from .._core.periodic_matrix import PeriodicMatrix
from .._core.coerce import as_ltp
from .._core.validation import check_positive, check_positive_int, real_array
from .._frequency.htf import HTFModel

__all__ = ['hhc_tmatrix', 'hhc_controller']


def hhc_tmatrix(plant, nrev, *, period=None, internal_harmonics=None):
    """T-matrix of a plant at the N/rev frequency ``ω = N ω_p``.

    Parameters
    ----------
    plant : LTPStateSpace or control.StateSpace
        Stable continuous-time plant (an LTI plant needs `period`, the
        rotor period).
    nrev : int
        Harmonic N of the rotor frequency to control.
    period : float, optional
        Rotor period of an LTI plant.
    internal_harmonics : int, optional
        See `htf`.

    Returns
    -------
    ndarray, shape (2p, 2m)
        ``z = T θ`` with ``θ = [θ_c; θ_s]`` (m inputs) and
        ``z = [z_c; z_s]`` (p outputs).

    Examples
    --------
    An LTI plant: T is the rotation-scaling of ``G(jω)``:

    >>> G = ct.tf([1], [1, 1])
    >>> T = ltp.hhc_tmatrix(G, 1, period=2 * np.pi)       # ω = 1
    >>> g = complex(G(1j))
    >>> bool(np.allclose(T, [[g.real, g.imag], [-g.imag, g.real]]))
    True
    """
    P = as_ltp(plant, 'plant', period=period if not isinstance(plant, LTPStateSpace)
               else None, discrete=False)
    N = check_positive_int(nrev, 'nrev')
    if not P.is_stable():
        raise ValueError("hhc_tmatrix: the plant is unstable, so it has no steady-state "
                         "N/rev response (stabilize it first)")
    w = N * P.omega_p
    H = HTFModel(P, 2 * N, internal_harmonics=internal_harmonics)
    _, G = H.components([w])
    A0, A2 = G[2 * N, :, :, 0], G[4 * N, :, :, 0]          # G_0 and G_{2N}
    return np.block([[(A0 + A2).real, (A0 - A2).imag],
                     [-(A0 + A2).imag, (A0 - A2).real]])


def hhc_controller(T, omega, gain, *, W=None, R=None, name='hhc'):
    """Higher-harmonic controller for an N/rev disturbance as a periodic compensator.

    Parameters
    ----------
    T : array_like, shape (2p, 2m)
        T-matrix at ω (`hhc_tmatrix`, or measured).
    omega : float
        Controlled frequency ``ω = N Ω`` in rad/s.
    gain : float
        Integration rate γ > 0 of the harmonic amplitudes (1/s); the
        once-per-revolution update with relaxation α corresponds to
        ``γ = α Ω / 2π``.
    W, R : array_like, optional
        Weights of the quadratic cost ``zᵀWz + θᵀRθ`` (default ``W = I``,
        ``R = 0``).
    name : str
        Name of the compensator.

    Returns
    -------
    LTPStateSpace
        K, with 2m states θ, p inputs (the measured outputs) and m outputs
        w, period ``2π/ω``, for the negative-feedback loop ``u = -w``
        (``L = P K``, module notes).

    Raises
    ------
    ValueError
        If ``TᵀWT + R`` is singular.

    Examples
    --------
    >>> G = ct.tf([1], [1, 1])
    >>> T = ltp.hhc_tmatrix(G, 1, period=2 * np.pi)
    >>> K = ltp.hhc_controller(T, 1.0, 0.2)
    >>> K.nstates, K.period == 2 * np.pi
    (2, True)
    """
    T = real_array(T, 'T', ndim=2)
    if T.shape[0] % 2 or T.shape[1] % 2:
        raise ControlDimension(f"T must have shape (2p, 2m), got {T.shape}")
    p, m = T.shape[0] // 2, T.shape[1] // 2
    w = check_positive(abs(float(real_array(omega, 'omega', ndim=0))), 'omega')
    gamma = check_positive(gain, 'gain')
    W = np.eye(2 * p) if W is None else real_array(W, 'W', ndim=2)
    R = np.zeros((2 * m, 2 * m)) if R is None else real_array(R, 'R', ndim=2)
    if W.shape != (2 * p, 2 * p) or R.shape != (2 * m, 2 * m):
        raise ControlDimension(f"W must be {2 * p}x{2 * p} and R {2 * m}x{2 * m}")
    H = T.T @ W @ T + R
    if np.linalg.cond(H) > 1e12:
        raise ValueError("hhc_controller: TᵀWT + R is singular (the N/rev output is not "
                         "controllable through T); add a weight R > 0")
    M = np.linalg.solve(H, T.T @ W)                       # (2m, 2p)
    period = 2 * np.pi / w
    # demodulation [2cos I; 2sin I] and remodulation [cos I, sin I]: harmonics ±1
    cos = np.array([0.5, 0.0, 0.5])
    sin = np.array([0.5j, 0.0, -0.5j])
    demod = np.array([np.vstack([2 * c * np.eye(p), 2 * s * np.eye(p)])
                      for c, s in zip(cos, sin)])
    remod = np.array([np.hstack([c * np.eye(m), s * np.eye(m)]) for c, s in zip(cos, sin)])
    B = PeriodicMatrix(gamma * M @ demod, period)
    C = PeriodicMatrix(remod, period)
    states = [f'theta_c[{i}]' for i in range(m)] + [f'theta_s[{i}]' for i in range(m)]
    return LTPStateSpace(np.zeros((2 * m, 2 * m)), B, C, np.zeros((m, p)), period,
                         name=name, states=states)

