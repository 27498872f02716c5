"""Closed-loop frequency functions of periodic loops and two-ports.

With negative feedback ``u = r - y``, ``y = L u``, the sensitivity
``S = (I + L)^{-1}`` and complementary sensitivity ``T = L (I + L)^{-1}``
are LTP systems themselves: their HTFs are exact (Conventions page) and
``Ŝ = (I + L̂)^{-1}``, ``T̂ = I - Ŝ`` in the untruncated limit.

The SISO-equivalent loop closes every harmonic but the central one:
with the central block ``0`` and the rest ``r``,

    L_eq(jω) = L̂_00 - L̂_0r (I + L̂_rr)^{-1} L̂_r0,

so that ``det(I + L_eq) = det(I + L̂) / det(I + L̂_rr)`` (Schur
complement): the loop seen at the fundamental harmonic by a designer who
treats the others as closed.

A two-port (voltage in, current out) LTP model has the harmonic
admittance ``Ŷ`` (its HTF) and the harmonic impedance ``Ẑ = Ŷ^{-1}``,
exact when the admittance has an invertible feedthrough (the inverse
system ``(A - B D^{-1} C, B D^{-1}, -D^{-1} C, D^{-1})``).
"""

import numpy as np
import control as ct
from control.exception import ControlDimension

from .htf import HTFModel, default_omega
from .loop import LoopHTF, as_loop
from .._core.ltpsys import LTPStateSpace, feedback, ltpss
from .._core.periodic_matrix import PeriodicMatrix
from .._core.coerce import as_ltp
from .._core.validation import index_list, real_array

__all__ = ['sensitivity_htf', 'complementary_sensitivity_htf', 'siso_equivalent',
           'harmonic_admittance', 'harmonic_impedance']


def sensitivity_htf(L, nharmonics, *, period=None, internal_harmonics=None):
    """HTF of the sensitivity ``S = (I + L)^{-1}`` of a periodic loop.

    Parameters
    ----------
    L : LTPStateSpace, control.StateSpace or sequence of systems
        The continuous-time square loop (see `nyquist_htf`).
    nharmonics : int
        Harmonics -K..K of the HTF.
    period : float, optional
        Period of an LTI loop.
    internal_harmonics : int, optional
        See `htf`.

    Returns
    -------
    HTFModel
        Named ``'S'``; `bode_htf` plots it.

    Examples
    --------
    >>> L = ltp.ltpss(ct.tf([2], [1, 1]), period=1.0)
    >>> S = ltp.sensitivity_htf(L, 2)
    >>> complex(np.round(S(0.0)[2, 2], 6))         # 1/(1 + L(0)) = 1/3
    (0.333333+0j)
    """
    L = as_loop(L, 'L', period, 'sensitivity_htf')
    m = L.ninputs
    S = feedback(np.eye(m), L, name='S')
    return HTFModel(S, nharmonics, internal_harmonics=internal_harmonics)


def complementary_sensitivity_htf(L, nharmonics, *, period=None, internal_harmonics=None):
    """HTF of the complementary sensitivity ``T = L (I + L)^{-1}``.

    Parameters
    ----------
    L : LTPStateSpace, control.StateSpace or sequence of systems
        The continuous-time square loop (see `nyquist_htf`).
    nharmonics : int
        Harmonics -K..K of the HTF.
    period : float, optional
        Period of an LTI loop.
    internal_harmonics : int, optional
        See `htf`.

    Returns
    -------
    HTFModel
        Named ``'T'``.

    Examples
    --------
    >>> L = ltp.ltpss(ct.tf([2], [1, 1]), period=1.0)
    >>> T = ltp.complementary_sensitivity_htf(L, 2)
    >>> complex(np.round(T(0.0)[2, 2], 6))          # L(0)/(1 + L(0)) = 2/3
    (0.666667+0j)
    """
    L = as_loop(L, 'L', period, 'complementary_sensitivity_htf')
    T = feedback(L, np.eye(L.ninputs), name='T')
    return HTFModel(T, nharmonics, internal_harmonics=internal_harmonics)


def siso_equivalent(L, nharmonics, omega=None, *, period=None, internal_harmonics=None):
    """SISO-equivalent loop: every harmonic but the central one closed.

    ``L_eq(jω) = L̂_00 - L̂_0r (I + L̂_rr)^{-1} L̂_r0`` (module notes); for
    an LTI loop ``L_eq = L``.

    Parameters
    ----------
    L : LTPStateSpace, control.StateSpace or sequence of systems
        The continuous-time square loop (see `nyquist_htf`).
    nharmonics : int
        Truncation N >= 1 of the loop HTF.
    omega : array_like, optional
        Frequencies in rad/s (default grid of `htf_response`).
    period : float, optional
        Period of an LTI loop.
    internal_harmonics : int, optional
        See `htf`.

    Returns
    -------
    control.FrequencyResponseData
        ``m x m``; ``ct.nyquist_plot`` and ``ct.bode_plot`` draw it.

    Examples
    --------
    >>> G = ct.tf([2], [1, 1])
    >>> Leq = ltp.siso_equivalent(ltp.ltpss(G, period=1.0), 3, [0.5, 2.0])
    >>> bool(np.allclose(Leq.frdata[0, 0], G(1j * np.array([0.5, 2.0]))))
    True
    """
    L = as_loop(L, 'L', period, 'siso_equivalent')
    loop = LoopHTF(L, nharmonics, internal_harmonics)
    w = (default_omega(loop) if omega is None
         else real_array(omega, 'omega', ndim=(0, 1)).reshape(-1))
    Lh = loop(1j * w)
    m, N = loop.m, loop.N
    c = np.arange(N * m, (N + 1) * m)                    # central block
    r = np.setdiff1d(np.arange(loop.size), c)
    L00, L0r = Lh[:, c][:, :, c], Lh[:, c][:, :, r]
    Lr0, Lrr = Lh[:, r][:, :, c], Lh[:, r][:, :, r]
    eq = L00 - L0r @ np.linalg.solve(np.eye(len(r)) + Lrr, Lr0)
    return ct.frd(np.moveaxis(eq, 0, -1), w, name=f'{L.name}$eq',
                  inputs=L.input_labels, outputs=L.output_labels)


def harmonic_admittance(sys, nharmonics, *, voltage=None, current=None,
                        internal_harmonics=None):
    """Harmonic admittance of a two-port LTP model (voltages in, currents out).

    Parameters
    ----------
    sys : LTPStateSpace
        Continuous-time model, e.g. a converter linearized about its
        periodic steady state.
    nharmonics : int
        Harmonics -K..K.
    voltage, current : list of int or str, optional
        Input (voltage) and output (current) channels (default: all);
        there must be as many of each.
    internal_harmonics : int, optional
        See `htf`.

    Returns
    -------
    HTFModel
        ``Ŷ(s)``, named ``'<name>$Y'``.

    Examples
    --------
    A resistor-inductor branch ``i = v/(Ls + R)`` written as periodic:

    >>> Y = ltp.harmonic_admittance(ltp.ltpss(ct.tf([1], [0.01, 1]), period=0.02), 1)
    >>> complex(np.round(Y(0.0)[1, 1], 6))
    (1+0j)
    """
    port = _port(sys, voltage, current)
    port = ltpss(port.A, port.B, port.C, port.D, port.period, name=f'{sys.name}$Y',
                 inputs=port.input_labels, outputs=port.output_labels)
    return HTFModel(port, nharmonics, internal_harmonics=internal_harmonics)


def harmonic_impedance(sys, nharmonics, *, voltage=None, current=None,
                       internal_harmonics=None):
    """Harmonic impedance ``Ẑ = Ŷ^{-1}`` of a two-port LTP model.

    Exact through the inverse system of the admittance, which needs an
    invertible feedthrough ``D(t)`` at every t.

    Parameters
    ----------
    sys, nharmonics, voltage, current, internal_harmonics
        As `harmonic_admittance`.

    Returns
    -------
    HTFModel
        ``Ẑ(s)``, named ``'<name>$Z'`` (currents in, voltages out).

    Raises
    ------
    ValueError
        If the admittance's feedthrough is singular (a strictly proper
        admittance has an improper impedance: evaluate
        ``np.linalg.inv`` of the admittance HTF at the points needed).

    Examples
    --------
    A resistor ``R = 2`` in parallel with a capacitor: ``Y = 1/2 + Cs``,
    here as the proper admittance ``1/2 + s/(s/100 + 1)``:

    >>> Y = ct.tf([1, 0], [0.01, 1]) + 0.5
    >>> Z = ltp.harmonic_impedance(ltp.ltpss(Y, period=1.0), 1)
    >>> complex(np.round(Z(0.0)[1, 1], 6))
    (2+0j)
    """
    port = _port(sys, voltage, current)
    n, m = port.nstates, port.ninputs
    Dn = port.D.sample(64)
    if np.min(np.linalg.svd(Dn, compute_uv=False)) <= 1e-12 * max(1.0, np.abs(Dn).max()):
        raise ValueError("harmonic_impedance: the admittance's feedthrough D(t) is "
                         "singular, so the impedance is improper; evaluate "
                         "np.linalg.inv(harmonic_admittance(...)(s)) at the points needed")
    D = port.D
    Dinv = (PeriodicMatrix.constant(np.linalg.inv(D(0.0)), port.period) if D.is_constant
            else PeriodicMatrix.from_function(lambda t: np.linalg.inv(D(t)), port.period,
                                              shape=(m, m)))
    A = port.A - port.B @ Dinv @ port.C if n else port.A
    B = port.B @ Dinv if n else port.B
    C = -(Dinv @ port.C) if n else port.C
    Z = LTPStateSpace(A, B, C, Dinv, port.period, name=f'{sys.name}$Z',
                      inputs=port.output_labels, outputs=port.input_labels)
    return HTFModel(Z, nharmonics, internal_harmonics=internal_harmonics)


def _port(sys, voltage, current):
    sys = as_ltp(sys, 'sys', discrete=False)
    ins = list(range(sys.ninputs)) if voltage is None else index_list(
        voltage, sys.input_labels, 'voltage')
    outs = list(range(sys.noutputs)) if current is None else index_list(
        current, sys.output_labels, 'current')
    if len(ins) != len(outs):
        raise ControlDimension(f"a two-port needs as many voltages as currents; got "
                               f"{len(ins)} voltage and {len(outs)} current channels")
    return sys[outs, ins]
