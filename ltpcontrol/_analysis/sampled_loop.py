"""Sampled-data loops: a digital controller around a continuous periodic plant.

The plant ``ẋ = A(t)x + B(t)u, y = C(t)x + D(t)u`` (period T) is driven
through a zero-order hold and its output sampled every ``T_s`` (``T =
N T_s``); the discrete controller K (period ``N_K T_s``) computes the next
input, which a computation delay of k sampling periods holds back:
``u[j] = v[j - k]``.  Between samples the loop is exactly the discrete
periodic system

    L_d = z^{-k} K P_d,     P_d = ZOH sampling of the plant (`sample_system`),

closed by negative feedback ``v = -K(y)`` (`sampled_loop`), with period
``lcm(N, N_K) T_s``.  Its time lifting (`lift`, method 'time') is an LTI
system over one period whose closed-loop eigenvalues are the multipliers
of the sampled closed loop; the continuous state between samples follows
from the held input, so the hybrid loop is asymptotically stable exactly
when they lie inside the unit circle.

`lifted_nyquist` is the generalized Nyquist criterion of the lifted loop:
with ``f(z) = det(I + L_L(z))``, whose zeros are the closed-loop
multipliers and poles the open-loop ones, the counter-clockwise turns of
f around the origin along ``|z| = 1`` count

    encirclements = P - Z,

P and Z the open- and closed-loop multipliers outside the unit circle (a
multiplier on the circle, e.g. an integrator's, is passed on the outside:
the contour is ``|z| = 1 + ε``, and it is not counted in P).  The points
``z = e^{jωT_L}`` carry the frequency ``ω`` in ``(-π/T_L, π/T_L]`` of the
lifted period ``T_L``.  The gain and phase margins are those of
`lifted_margins`.
"""

from dataclasses import dataclass
import math
import warnings

import numpy as np
import control as ct
import matplotlib.pyplot as plt
from control.exception import ControlArgument, ControlDimension
from scipy.optimize import linear_sum_assignment

from .._core.coerce import as_ltp
from .._core.discretize import sample_system
from .._core.lifting import lift
from .._core.ltpsys import LTPStateSpace, series
from .._core.validation import check_positive, check_positive_int

__all__ = ['sampled_loop', 'lifted_nyquist', 'LiftedNyquistResponse']

# refine while the phase of f turns more than this between points
_MAX_TURN = np.pi / 4
_MAX_POINTS = 50_000


def sampled_loop(plant, controller, Ts, *, delay=0, name=None):
    """Discrete loop gain of a sampled-data loop (ZOH, sampler, delay, controller).

    Parameters
    ----------
    plant : LTPStateSpace or control.StateSpace / TransferFunction
        Continuous-time plant (an LTI plant takes the period of the
        controller, or Ts).
    controller : LTPStateSpace, control.StateSpace, TransferFunction or array_like
        Discrete-time controller with ``dt = Ts`` (periodic or LTI), or a
        static gain matrix; it reads the sampled plant output and produces
        the plant input.
    Ts : float
        Sampling period; the plant's period must be an integer multiple.
    delay : int
        Computation delay k >= 0 in sampling periods: the input computed
        at step j is applied at step j + k.
    name : str, optional
        Name of the result (default 'L').

    Returns
    -------
    LTPStateSpace
        Discrete-time loop gain ``z^{-k} K P_d`` (square: plant inputs to
        plant inputs), closed by negative feedback; ``feedback(L, I)`` is
        the sampled closed loop.  States: the plant's, the delay line's
        (``k`` per input), the controller's.

    Raises
    ------
    ValueError
        If the plant is discrete-time, Ts does not divide its period, the
        controller's dt is not Ts, or the delay is negative.
    ControlDimension
        If the controller does not map the plant outputs to its inputs.

    Examples
    --------
    A first-order plant with a sampled PI controller and one period of
    computation delay (python-control's ``ct.c2d`` gives the same loop):

    >>> P = ct.tf([1], [0.1, 1])
    >>> K = ct.c2d(ct.tf([2, 20], [1, 0]), 0.01, 'tustin')
    >>> L = ltp.sampled_loop(ltp.ltpss(P, period=0.02), K, 0.01, delay=1)
    >>> L.nstates, L.dt, L.period
    (3, 0.01, 0.02)
    >>> Lct = K * ct.tf([1], [1, 0], 0.01) * ct.c2d(P, 0.01)
    >>> gm, pm, _ = ltp.lifted_margins(L)
    >>> want = ct.stability_margins(Lct)
    >>> bool(np.isclose(gm, want[0], rtol=1e-7)), bool(np.isclose(pm, want[1], rtol=1e-7))
    (True, True)
    """
    Ts = check_positive(Ts, 'Ts')
    k = check_positive_int(delay, 'delay', minimum=0)
    if isinstance(plant, LTPStateSpace):
        if plant.isdtime():
            raise ValueError("plant must be a continuous-time system (it is sampled "
                             "through a zero-order hold)")
        P = plant
    else:
        period = controller.period if isinstance(controller, LTPStateSpace) else Ts
        P = as_ltp(plant, 'plant', period=period)
        if P.isdtime():
            raise ValueError("plant must be a continuous-time system")
    Pd = sample_system(P, Ts, 'zoh', name='plant')
    K = _controller(controller, Ts, P)
    m = P.ninputs
    # u[j] = v[j - k]: the delay acts on the controller's output (a periodic K
    # does not commute with it)
    chain = [Pd, K] + ([_delay_line(m, k, Ts)] if k else [])
    L = chain[0]
    for sys in chain[1:]:
        L = series(L, sys)
    return LTPStateSpace(L.A, L.B, L.C, L.D, L.period, dt=Ts, name=name or 'L',
                         inputs=P.input_labels, outputs=[f'{u}_cmd' for u in P.input_labels])


@dataclass(frozen=True, repr=False)
class LiftedNyquistResponse:
    """Result of `lifted_nyquist`: generalized Nyquist criterion of a lifted loop.

    Attributes
    ----------
    encirclements : int
        Counter-clockwise turns of ``det(I + L_L(z))`` around 0 along the
        circle.
    open_loop_unstable : int
        P: open-loop multipliers outside the unit circle.
    multipliers : ndarray of complex
        The closed loop's multipliers (eigenvalues of the lifted closed
        loop), computed directly.
    omega : ndarray
        Frequencies ``ω`` (rad/s) of the points ``z = e^{jωT_L}``, in
        ``[-π/T_L, π/T_L]``.
    contour : ndarray of complex
        The points z.
    det : ndarray of complex
        ``det(I + L_L(z))`` on the contour.
    eigenloci : ndarray of complex
        Eigenvalues of ``L_L(z)`` (one per lifted channel), tracked.
    min_distance : float
        Smallest singular value of ``I + L_L(z)`` on the contour.
    period : float
        The lifted period ``T_L``.
    sysname : str
        Name of the loop.

    Examples
    --------
    >>> L = ltp.ltpss(ct.ss(ct.tf([0.5], [1, -1.2], 0.1)), period=0.2)    # pole 1.2
    >>> resp = ltp.lifted_nyquist(L)
    >>> resp.open_loop_unstable, resp.encirclements, resp.stable
    (1, 1, True)
    """

    encirclements: int
    open_loop_unstable: int
    multipliers: np.ndarray
    omega: np.ndarray
    contour: np.ndarray
    det: np.ndarray
    eigenloci: np.ndarray
    min_distance: float
    period: float
    sysname: str

    @property
    def count(self):
        """Clockwise encirclements (`control.nyquist_response` convention)."""
        return -self.encirclements

    @property
    def closed_loop_unstable(self):
        """Verdict Z = P - encirclements."""
        return self.open_loop_unstable - self.encirclements

    @property
    def stable(self):
        """True when no closed-loop multiplier lies outside the unit circle."""
        return self.closed_loop_unstable == 0

    def __repr__(self):
        return (f"<LiftedNyquistResponse {self.sysname}: encirclements="
                f"{self.encirclements}, P={self.open_loop_unstable}, "
                f"Z={self.closed_loop_unstable}, spectral radius "
                f"{np.abs(self.multipliers).max(initial=0.0):.4g}>")

    def plot(self, *, ax=None, title=None, max_curve_magnitude=20.0, **kwargs):
        """Eigenloci of the lifted loop with the critical point -1.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw into.
        title : str, optional
            Figure title.
        max_curve_magnitude : float
            View radius around the origin.
        **kwargs
            Matplotlib line properties.

        Returns
        -------
        control.ControlPlot

        Examples
        --------
        >>> L = ltp.ltpss(ct.ss(ct.tf([0.5], [1, 0.5], 0.1)), period=0.2)
        >>> type(ltp.lifted_nyquist(L).plot()).__name__
        'ControlPlot'
        """
        R = check_positive(max_curve_magnitude, 'max_curve_magnitude')
        if ax is None:
            _, ax = plt.subplots()
        lines = []
        color = kwargs.pop('color', None)
        for z in self.eigenloci.T:
            if np.all(np.abs(z) < 1e-6):
                continue
            line, = ax.plot(z.real, z.imag, color=color or 'C0', **kwargs)
            lines.append(line)
        lines.append(ax.plot([-1.0], [0.0], 'r+', markersize=10)[0])
        span = max(1.5, 1.1 * np.abs(self.eigenloci[np.abs(self.eigenloci) <= R]).max(
            initial=0.0))
        ax.set_xlim(-span, span)
        ax.set_ylim(-span, span)
        ax.set_aspect('equal', adjustable='box')
        ax.grid(True, alpha=0.3)
        ax.set_xlabel("Real axis")
        ax.set_ylabel("Imaginary axis")
        ax.set_title(title or f"Lifted Nyquist plot of {self.sysname}: "
                     f"{self.encirclements} encirclement(s), P={self.open_loop_unstable}")
        arr = np.empty((1, 1), dtype=object)
        arr[0, 0] = lines
        return ct.ControlPlot(arr, np.array([[ax]]), ax.figure)


def lifted_nyquist(loop, *, omega_num=401, name=None):
    """Generalized Nyquist criterion of a discrete periodic loop, through its lifting.

    Parameters
    ----------
    loop : LTPStateSpace
        Discrete-time square loop gain (e.g. from `sampled_loop`), closed
        by negative feedback.
    omega_num : int
        Initial points on the circle (refined wherever the phase of the
        determinant turns by more than π/4 between points).
    name : str, optional
        Name in the result (default: the loop's).

    Returns
    -------
    LiftedNyquistResponse

    Raises
    ------
    ValueError
        For a continuous-time loop.
    ControlDimension
        For a loop that is not square.

    Warns
    -----
    UserWarning
        When the count contradicts the closed-loop multipliers (a
        multiplier at rounding distance from the circle: the loop is at a
        stability boundary).

    Examples
    --------
    An LTI loop written as periodic counts as python-control does:

    >>> G = ct.c2d(ct.tf([3], [1, 2, 1]), 0.1)
    >>> resp = ltp.lifted_nyquist(ltp.ltpss(ct.ss(G), period=0.3))
    >>> resp.stable, resp.count == ct.nyquist_response(G).count
    (True, True)
    """
    loop = as_ltp(loop, 'loop', discrete=True)
    if loop.ninputs != loop.noutputs:
        raise ControlDimension(f"loop must be square, got {loop.noutputs} outputs and "
                               f"{loop.ninputs} inputs")
    num = check_positive_int(omega_num, 'omega_num', minimum=8)
    Ll = lift(loop, method='time')
    A, B, C, D = (np.asarray(M, float) for M in (Ll.A, Ll.B, Ll.C, Ll.D))
    n, M = A.shape[0], D.shape[0]
    I = np.eye(M)
    if np.linalg.svd(I + D, compute_uv=False)[-1] <= 1e-12 * max(1.0, np.abs(D).max()):
        raise ValueError("the sampled closed loop is ill-posed: I + D of the lifted loop "
                         "is singular (an algebraic loop through the feedthrough)")
    ol = np.linalg.eigvals(A) if n else np.zeros(0, complex)
    on_circle = np.abs(np.abs(ol) - 1) <= 1e-9
    P = int(np.count_nonzero((np.abs(ol) > 1) & ~on_circle))
    radius = 1.0 + (1e-6 if on_circle.any() else 0.0)
    Acl = A - B @ np.linalg.solve(I + D, C) if n else A
    mult = np.linalg.eigvals(Acl) if n else np.zeros(0, complex)
    TL = loop.period

    def evaluate(theta):
        z = radius * np.exp(1j * theta)
        if n:
            R = np.linalg.solve(z[:, None, None] * np.eye(n) - A,
                                np.broadcast_to(B, (len(z),) + B.shape))
            Lz = C @ R + D
        else:
            Lz = np.broadcast_to(D, (len(z), M, M)).astype(complex)
        sign, logabs = np.linalg.slogdet(I + Lz)
        return z, Lz, np.angle(sign), logabs

    theta = np.linspace(-np.pi, np.pi, num)
    z, Lz, ph, la = evaluate(theta)
    while True:
        bad = (np.abs(_wrap(np.diff(ph))) > _MAX_TURN) | (np.abs(np.diff(la)) > 0.5)
        bad &= np.diff(theta) > 1e-12
        if not bad.any() or len(theta) + bad.sum() > _MAX_POINTS:
            break
        tn = 0.5 * (theta[:-1][bad] + theta[1:][bad])
        zn, Ln, pn, ln = evaluate(tn)
        order = np.argsort(np.concatenate([theta, tn]), kind='stable')
        theta = np.concatenate([theta, tn])[order]
        z = np.concatenate([z, zn])[order]
        Lz = np.concatenate([Lz, Ln])[order]
        ph = np.concatenate([ph, pn])[order]
        la = np.concatenate([la, ln])[order]
    enc = int(np.round(float(_wrap(np.diff(ph)).sum()) / (2 * np.pi)))
    dist = float(np.linalg.svd(I + Lz, compute_uv=False)[:, -1].min())
    Zm = int(np.count_nonzero(np.abs(mult) > radius))
    if Zm != P - enc:
        warnings.warn(f"lifted_nyquist: the count (Z = {P - enc}) contradicts the closed "
                      f"loop's multipliers (Z = {Zm}): a multiplier lies at rounding "
                      "distance from the unit circle (stability boundary)", UserWarning,
                      stacklevel=2)
    with np.errstate(over='ignore', under='ignore'):
        det = np.exp(la + 1j * ph)
    return LiftedNyquistResponse(
        encirclements=enc, open_loop_unstable=P, multipliers=mult, omega=theta / TL,
        contour=z, det=det, eigenloci=_track(np.linalg.eigvals(Lz)), min_distance=dist,
        period=TL, sysname=name or loop.name)


#
# Helpers
#

def _controller(K, Ts, P):
    if isinstance(K, LTPStateSpace):
        if not K.isdtime() or not math.isclose(K.dt, Ts, rel_tol=1e-9):
            raise ValueError(f"controller must be discrete-time with dt = Ts = {Ts:g}")
    elif isinstance(K, (ct.StateSpace, ct.TransferFunction)):
        if not K.isdtime(strict=True) or not math.isclose(K.dt, Ts, rel_tol=1e-9):
            raise ValueError(f"controller must be discrete-time with dt = Ts = {Ts:g}")
        K = as_ltp(K, 'controller', period=Ts)
    else:
        G = np.atleast_2d(np.asarray(K, float))
        if G.ndim != 2 or not np.all(np.isfinite(G)):
            raise ControlArgument("controller must be a discrete-time system or a finite "
                                  "gain matrix")
        K = LTPStateSpace(np.zeros((0, 0)), np.zeros((0, G.shape[1])),
                          np.zeros((G.shape[0], 0)), G, Ts, dt=Ts)
    if K.ninputs != P.noutputs or K.noutputs != P.ninputs:
        raise ControlDimension(f"controller must map the {P.noutputs} plant outputs to its "
                               f"{P.ninputs} inputs; it has {K.ninputs} inputs and "
                               f"{K.noutputs} outputs")
    return K


def _delay_line(m, k, Ts):
    """``z^{-k}`` on m channels: k registers per channel."""
    n = m * k
    A = np.zeros((n, n))
    A[m:, :-m] = np.eye(n - m)
    B = np.zeros((n, m))
    B[:m] = np.eye(m)
    C = np.zeros((m, n))
    C[:, -m:] = np.eye(m)
    return LTPStateSpace(A, B, C, np.zeros((m, m)), Ts, dt=Ts, name='delay')


def _track(eig):
    out = np.array(eig, copy=True)
    for i in range(1, len(out)):
        cost = np.abs(out[i - 1][:, None] - out[i][None, :])
        _, col = linear_sum_assignment(cost)
        out[i] = out[i][col]
    return out


def _wrap(x):
    return np.remainder(x + np.pi, 2 * np.pi) - np.pi
