"""Harmonic state space of a continuous-time LTP system as a `control.StateSpace`.

The truncated HTF (Conventions page) is ``H(s) = 𝒞 [sI − (𝒜 − 𝒩)]⁻¹ ℬ + 𝒟``
with complex Toeplitz matrices.  In the real basis of the lifting module
(columns ``c_0 = e_0``, ``c_n = (e_n + e_{-n})/√2``, ``s_n = j(e_n −
e_{-n})/√2``, a unitary V) every one of them is real, since the Fourier
coefficients of a real matrix are conjugate-symmetric and ``V^H 𝒩 V`` is the
real rotation generator; the returned system has the frequency response
``V_y^H H(s) V_u``.  The internal truncation ``K_i >= K`` of `htf` is kept
for the states, so the central blocks converge as in `htf`.
"""

import numpy as np
import control as ct
from control.exception import ControlArgument

from ._lifting import _harmonic_labels, _real_basis
from ._validation import check_positive_int

__all__ = ['harmonic_ss']


def harmonic_ss(sys, nharmonics, *, internal_harmonics=None, name=None):
    """Real harmonic state space of a continuous-time LTP system.

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous-time LTP system (discrete time: use `lift`, whose
        frequency lifting is the exact discrete harmonic state space).
    nharmonics : int
        Harmonics -K..K of the inputs and outputs.
    internal_harmonics : int, optional
        Truncation ``K_i >= K`` of the states (default as in `htf`).
    name : str, optional
        Name of the result (default: the name of `sys` with '$harmonic').

    Returns
    -------
    control.StateSpace
        ``(2K_i+1) n`` states, ``(2K+1) m`` inputs and ``(2K+1) p`` outputs,
        harmonic-major, named ``'<label>_c<n>'`` and ``'<label>_s<n>'`` (see
        the module notes); its frequency response at s is
        ``V_y^H H(s) V_u`` with H the truncated HTF.

    Raises
    ------
    ValueError
        If `sys` is discrete-time.

    Examples
    --------
    The HTF of an LTI system has the diagonal blocks ``G(s + jnω_p)``; the
    cosine channel of harmonic 0 is G itself:

    >>> G = ct.tf([1], [1, 1])
    >>> Hs = ltp.harmonic_ss(ltp.ltpss(G, period=1.0), 2)
    >>> Hs.ninputs, Hs.input_labels[:3]
    (5, ['u[0]_c0', 'u[0]_c1', 'u[0]_s1'])
    >>> bool(np.isclose(Hs(0.5j)[0, 0], G(0.5j)))
    True
    """
    from ._htf import htf
    from ._ltpsys import LTPStateSpace
    if not isinstance(sys, LTPStateSpace):
        raise ControlArgument(f"sys must be an LTPStateSpace, got {sys.__class__.__name__}")
    if sys.isdtime():
        raise ValueError("harmonic_ss: sys is discrete-time; lift(sys) is its exact "
                         "(frequency-lifted) harmonic state space")
    K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
    return _to_ss(htf(sys, K, internal_harmonics=internal_harmonics), name,
                  sys.state_labels)


def htf_to_ss(H, name=None, states=None):
    """`HTF.to_ss`: the real harmonic state space of a model HTF."""
    if H._hss is None:
        raise ValueError("to_ss: this HTF holds data on a frequency grid; only an HTF "
                         "computed from a model (ltp.htf) has a state space")
    if H.isdtime():
        raise ValueError("to_ss: the HTF is discrete-time; lift() the system instead")
    return _to_ss(H, name, states)


def _to_ss(H, name, states):
    hss = H._hss
    K, Ki = hss.K, hss.Ki
    n = hss.F.shape[0] // (2 * Ki + 1)
    Vs, tags_s = _real_basis(np.arange(-Ki, Ki + 1), 2 * Ki + 2)   # no wrap-around
    Vio, tags = _real_basis(np.arange(-K, K + 1), 2 * K + 2)
    Vx = np.kron(Vs, np.eye(n))
    Vu, Vy = np.kron(Vio, np.eye(hss.nu)), np.kron(Vio, np.eye(hss.ny))
    mats = (Vx.conj().T @ hss.F @ Vx, Vx.conj().T @ hss.G @ Vu,
            Vy.conj().T @ hss.Hc @ Vx, Vy.conj().T @ hss.J @ Vu)
    scale = max(1.0, max(np.abs(M).max(initial=0.0) for M in mats))
    assert max(np.abs(M.imag).max(initial=0.0) for M in mats) <= 1e-10 * scale
    if states is None:
        states = [f'x[{i}]' for i in range(n)]
    return ct.ss(*(M.real for M in mats), name=name or f'{H.name}$harmonic',
                 inputs=_harmonic_labels(H.input_labels, tags),
                 outputs=_harmonic_labels(H.output_labels, tags),
                 states=_harmonic_labels(states, tags_s))
