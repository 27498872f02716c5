"""Interconnection of LTP, LTI and static blocks by signal names.

python-control's `control.interconnect` resolves the signal-name semantics
(``connections``, ``inplist``, ``outlist``, automatic connection of equal
names, summing junctions, gains such as ``'-sys.y'``) into three constant
matrices: with the stacked block inputs ``v``, outputs ``w`` and external
input ``u``,

    v = M w + N u,      y = P_w w + P_v v.

With the appended blocks ``ẋ = A x + B v, w = C x + D v`` (periodic), the
loop gives ``v = F (M C x + N u)``, ``F = (I - M D)^{-1}`` (pointwise in
time; singular F is an algebraic loop), hence

    ẋ = (A + B F M C) x + B F N u,
    y = (P_w (C + D F M C) + P_v F M C) x + (P_w D + P_v) F N u.
"""

import numpy as np
import control as ct
from control.exception import ControlArgument

from .ltpsys import LTPStateSpace, _loop_inverse, _period_and_dt, _to_ltp, append
from .registry import overridden

__all__ = ['interconnect']


def interconnect(syslist, connections=None, inplist=None, outlist=None, **kwargs):
    """Interconnect LTP, LTI and static blocks with named signals.

    Same arguments and signal-name semantics as `control.interconnect`
    (which is also routed here when a block is an `LTPStateSpace`); the
    result is one `LTPStateSpace` whose period is the common period of the
    blocks.

    Parameters
    ----------
    syslist : list
        Blocks: `LTPStateSpace`, `control.StateSpace`,
        `control.TransferFunction` (with signal names) or static gains
        (`PeriodicMatrix`, array or number, given default names
        ``'sys[i]'``); at least one block must be an `LTPStateSpace` or a
        `PeriodicMatrix`.
    connections : list or None, optional
        Connections as in `control.interconnect`; None connects signals of
        equal names.
    inplist, outlist : list, optional
        External inputs and outputs as in `control.interconnect`.
    **kwargs
        Other keywords of `control.interconnect` (``name``, ``inputs``,
        ``outputs``, ``states``, ``check_unused``, ``add_unused``,
        ``ignore_inputs``, ``ignore_outputs``, ``warn_duplicate``,
        ``debug``).

    Returns
    -------
    LTPStateSpace

    Raises
    ------
    ValueError
        For incommensurate periods or an algebraic loop ``I - M D(t)``
        that is singular.

    Examples
    --------
    A periodic plant under PI-free integral control with a periodic gain:

    >>> P = ltp.ltpss([[-1.0]], lambda t: np.array([[1 + 0.5 * np.cos(2 * np.pi * t)]]),
    ...               [[1.0]], 0, period=1.0, name='P', inputs='u', outputs='y')
    >>> C = ct.tf([1.0], [1.0, 0.0], name='C', inputs='e', outputs='v')
    >>> G = ltp.ltpss(ltp.PeriodicMatrix([[[0.2]], [[1.0]], [[0.2]]], 1.0),
    ...               name='G', inputs='v', outputs='u')
    >>> err = ct.summing_junction(['r', '-y'], 'e')
    >>> loop = ltp.interconnect([P, C, G, err], inplist='r', outlist='y')
    >>> loop.nstates, loop.period
    (2, 1.0)
    """
    if (own := overridden('interconnect', *(syslist if isinstance(syslist, (list, tuple))
                                              else ()))) is not None:  # delay elements
        return own(syslist, connections, inplist, outlist, **kwargs)
    if params := kwargs.pop('params', None):
        raise ControlArgument(f"interconnect: LTP blocks have no parameters, got {params!r}")
    if not isinstance(syslist, (list, tuple)):
        raise ControlArgument("interconnect: syslist must be a list of systems")
    period, dt = _period_and_dt(syslist, "interconnect")
    blocks = []
    for i, s in enumerate(syslist):
        if isinstance(s, ct.TransferFunction):
            s = ct.ss(s, name=s.name)
        if not isinstance(s, ct.InputOutputSystem):
            gain = _to_ltp(s, period, dt)
            s = LTPStateSpace(gain.A, gain.B, gain.C, gain.D, period, dt=dt, name=f"sys[{i}]")
        elif isinstance(s, LTPStateSpace) and not s.nstates and s.dt != dt:
            s = LTPStateSpace(s.A, s.B, s.C, s.D, s.period, dt=dt, name=s.name,
                              inputs=s.input_labels, outputs=s.output_labels)
        elif not isinstance(s, (LTPStateSpace, ct.StateSpace)):
            raise ControlArgument(f"interconnect: block {i} is a {type(s).__name__}; only "
                                  "LTP, LTI and static blocks give an LTPStateSpace (use "
                                  "control.interconnect for nonlinear blocks)")
        blocks.append(s)
    ic = _control_interconnect()(blocks, connections=connections, inplist=inplist,
                                  outlist=outlist, **kwargs)
    ltp_blocks = [_to_ltp(s, period, dt) for s in ic.syslist]
    big = append(*ltp_blocks)
    nw = big.noutputs
    M, N = ic.connect_map, ic.input_map
    Pw, Pv = ic.output_map[:, :nw], ic.output_map[:, nw:]
    F = _loop_inverse(np.eye(M.shape[0]) - M @ big.D, "interconnect")
    Ux = F @ (M @ big.C)                  # v = Ux x + Uu u
    Uu = F @ N
    A = big.A + big.B @ Ux
    B = big.B @ Uu
    C = Pw @ (big.C + big.D @ Ux) + Pv @ Ux
    D = (Pw @ big.D + Pv) @ Uu
    return LTPStateSpace(A, B, C, D, period, dt=dt, name=ic.name, inputs=ic.input_labels,
                         outputs=ic.output_labels, states=ic.state_labels)


def _control_interconnect():
    """python-control's own `control.interconnect` (unwrapped if the bridge wraps it)."""
    fn = ct.interconnect
    return getattr(fn, '__wrapped__', fn)
