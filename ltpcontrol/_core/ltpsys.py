"""Linear time-periodic state-space systems.

Continuous time (``dt = 0``)::

    ẋ(t) = A(t) x(t) + B(t) u(t),   y(t) = C(t) x(t) + D(t) u(t)

Discrete time (``dt > 0``, ``N = period/dt`` steps per period)::

    x[k+1] = A[k] x[k] + B[k] u[k],   y[k] = C[k] x[k] + D[k] u[k]

with ``A(t + T) = A(t)`` (``A[k + N] = A[k]``) and likewise for B, C, D.
`LTPStateSpace` is a `control.NonlinearIOSystem` (so it simulates and
interconnects with python-control), never an LTI system.
"""

import numbers

import warnings

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension
from control.iosys import _process_iosys_keywords
from control.nlsys import NonlinearIOSystem

from .display import html, text
from .periodic_matrix import PeriodicMatrix, as_periodic
from .refusals import refusal, refusal_error
from .registry import aliased, overridden
from .wellposed import check_well_posed
from .validation import (check_period, check_positive, commensurate, index_list, real_array,
                         steps_per_period)

__all__ = ['LTPStateSpace', 'ltpss', 'series', 'parallel', 'feedback',
           'append', 'negate']


class LTPStateSpace(NonlinearIOSystem):
    """Linear time-periodic system in state-space form.

    ``ẋ = A(t)x + B(t)u, y = C(t)x + D(t)u`` with T-periodic matrices
    (continuous time) or ``x[k+1] = A[k]x[k] + B[k]u[k]`` with N-periodic
    matrices (discrete time, ``N = period/dt``).  Create systems with
    `ltpss`, which documents every parameter.

    Parameters
    ----------
    A, B, C, D : array_like, PeriodicMatrix or callable
        System matrices.
    period : float
        Period T in seconds (discrete time: ``N dt``).
    dt : float, optional
        Sampling time; 0 (default) for continuous time.

    Attributes
    ----------
    A, B, C, D : PeriodicMatrix
        System matrices as periodic matrices of period T.
    period : float
        The period T.
    omega_p : float
        Fundamental frequency ``2π/T``.
    nsteps : int or None
        Steps per period ``N`` for discrete-time systems.

    Examples
    --------
    >>> A = ltp.PeriodicMatrix.from_function(
    ...     lambda t: np.array([[0.0, 1.0], [-4 - np.cos(t), -0.5]]), 2 * np.pi)
    >>> sys = ltp.ltpss(A, [[0], [1]], [[1, 0]], 0, period=2 * np.pi, name='mathieu')
    >>> sys
    <LTPStateSpace mathieu: ['u[0]'] -> ['y[0]'], period=6.28319>
    """

    def __init__(self, A, B, C, D, period, *, dt=0, **kwargs):
        period = check_period(period)
        if isinstance(dt, (bool, np.bool_)) or not isinstance(dt, (numbers.Real, np.number)):
            raise ValueError(f"dt must be 0 (continuous) or a positive sampling time, got {dt!r}")
        dt = 0.0 if dt == 0 else check_positive(dt, 'dt')
        nsteps = steps_per_period(period, dt) if dt > 0 else None
        A = _system_matrix(A, period, 'A', nsteps)
        n = A.shape[0]
        if A.shape != (n, n):
            raise ControlDimension(f"A must be square, got shape {A.shape}")
        B = _system_matrix(B, period, 'B', nsteps, rows=n)
        C = _system_matrix(C, period, 'C', nsteps, cols=n)
        m, p = B.shape[1], C.shape[0]
        D = _system_matrix(D, period, 'D', nsteps, rows=p, cols=m, zero_ok=True)
        if n == 0 and B.shape[0] != 0:
            raise ControlDimension("B must have zero rows for a system without states")
        self.A, self.B, self.C, self.D = A, B, C, D
        self.period, self.nsteps = period, nsteps

        name, inputs, outputs, states, _ = _process_iosys_keywords(
            kwargs, {'inputs': m, 'outputs': p, 'states': n})
        super().__init__(self._updfcn, self._outfcn, name=name, inputs=inputs,
                         outputs=outputs, states=states, dt=dt, **kwargs)
        for what, count, size in (('inputs', self.ninputs, m), ('outputs', self.noutputs, p),
                                  ('states', self.nstates, n)):
            if count != size:
                raise ControlDimension(f"{what} has {count} labels but the matrices "
                                       f"imply {size}")

    # right-hand sides used by python-control's simulation and interconnection
    def _updfcn(self, t, x, u, params=None):
        return self.A(t) @ np.asarray(x, float) + self.B(t) @ np.atleast_1d(u)

    def _outfcn(self, t, x, u, params=None):
        return self.C(t) @ np.asarray(x, float) + self.D(t) @ np.atleast_1d(u)

    #
    # Descriptive properties
    #

    @property
    def omega_p(self):
        """Fundamental (pumping) frequency ``ω_p = 2π/T`` in rad/s."""
        return 2 * np.pi / self.period

    @property
    def is_floquet_form(self):
        """True when A is constant (Floquet form, thesis eq. 4.31)."""
        return self.A.is_constant

    @property
    def is_lti(self):
        """True when all four matrices are constant."""
        return all(M.is_constant for M in (self.A, self.B, self.C, self.D))

    def _repr_info_(self, html=False):
        text = (f"<LTPStateSpace {self.name}: {self.input_labels} -> "
                f"{self.output_labels}, period={self.period:g}"
                + (f", dt={self.dt:g}>" if self.isdtime() else ">"))
        return text if not html else text.replace('<', '&lt;').replace('>', '&gt;')

    def __repr__(self):
        return self._repr_info_()

    def __str__(self):
        return text(self)

    def _repr_html_(self):
        """Info line and LaTeX equations (python-control's notebook display).

        As for `control.StateSpace`, ``_repr_latex_`` returns None so that
        Jupyter uses this form, and None is returned when the system is
        larger than ``ct.config.defaults['statesp.latex_maxsize']``.
        """
        return html(self)

    #
    # Conversions
    #

    def to_ss(self, **kwargs):
        """Return the equivalent `control.StateSpace` of a system with constant matrices.

        Raises
        ------
        ValueError
            If any matrix depends on time.

        Examples
        --------
        >>> sys = ltp.ltpss(ct.rss(2, 1, 1, strictly_proper=True), period=1.0)
        >>> sys.to_ss().nstates
        2
        """
        if not self.is_lti:
            raise ValueError("to_ss: the system has time-varying matrices; "
                             "use htf(), lift() or linearize(t) instead")
        kwargs.setdefault('name', self.name + '$converted')
        kwargs.setdefault('inputs', self.input_labels)
        kwargs.setdefault('outputs', self.output_labels)
        kwargs.setdefault('states', self.state_labels)
        t0 = 0.0
        return ct.ss(self.A(t0), self.B(t0), self.C(t0), self.D(t0), self.dt, **kwargs)

    def linearize(self, x0=None, u0=None, t=0.0, params=None, **kwargs):
        """Frozen-time `control.StateSpace` ``(A(t), B(t), C(t), D(t))``.

        The signature is python-control's (`control.linearize`); a linear
        system is its own linearization about any ``(x0, u0)``, so only the
        time matters.

        Parameters
        ----------
        x0, u0 : array_like, optional
            Operating point (checked for size, otherwise unused).
        t : float
            Time at which the matrices are frozen.
        params : None
            An LTP system has no parameters.
        **kwargs
            Keywords of the result (``name``, ``inputs``, ...).

        Returns
        -------
        control.StateSpace

        Examples
        --------
        >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
        >>> sys.linearize(t=0.25).A
        array([[-1.]])
        >>> ct.linearize(sys, 0, 0, t=0.25).A
        array([[-1.]])
        """
        if params:
            raise ControlArgument("linearize: an LTPStateSpace has no parameters (params)")
        for val, count, what in ((x0, self.nstates, 'x0'), (u0, self.ninputs, 'u0')):
            if val is not None and np.size(val) not in (1, count):
                raise ControlDimension(f"linearize: {what} must have {count} elements, "
                                       f"got {np.size(val)}")
        t = float(real_array(t, 't', ndim=0))
        kwargs.pop('copy_names', None)
        kwargs.setdefault('name', self.name + '$frozen')
        for key in ('inputs', 'outputs', 'states'):
            kwargs.setdefault(key, getattr(self, key[:-1] + '_labels'))
        return ct.ss(self.A(t), self.B(t), self.C(t), self.D(t), self.dt, **kwargs)

    def _update_params(self, params):
        # python-control calls this before it integrates the system itself
        warnings.warn(
            f"python-control simulates the LTPStateSpace {self.name!r} as a generic "
            "nonlinear system (an ODE solver at its tolerances), not by ltpcontrol's exact "
            "simulation: use ltp.forced_response (or ltp.interop.enable())", UserWarning,
            stacklevel=3)
        super()._update_params(params)

    def __call__(self, *args, **kwargs):
        raise refusal_error("evaluation sys(s) of a transfer function",
                       "ltp.htf(sys, nharmonics)(s), the harmonic transfer function")

    def average(self, **kwargs):
        """Averaged LTI system with the mean matrices ``A_0, B_0, C_0, D_0``.

        Returns
        -------
        control.StateSpace

        Examples
        --------
        >>> A = ltp.PeriodicMatrix([[[0.5]], [[-2.0]], [[0.5]]], 1.0)
        >>> ltp.ltpss(A, [[1.0]], [[1.0]], 0, period=1.0).average().A
        array([[-2.]])
        """
        kwargs.setdefault('name', self.name + '$averaged')
        if self.isdtime():
            mats = [M.sample(self.nsteps).mean(axis=0) for M in (self.A, self.B, self.C, self.D)]
        else:
            mats = [M.fourier(0)[0].real for M in (self.A, self.B, self.C, self.D)]
        return ct.ss(*mats, self.dt, **kwargs)

    #
    # Analysis (implemented in other modules)
    #

    def monodromy(self, **kwargs):
        """State transition matrix over one period, ``Φ(T, 0)``; see `ltpcontrol.monodromy`."""
        return aliased('monodromy')(self, **kwargs)

    def floquet_multipliers(self, **kwargs):
        """Characteristic multipliers; see `ltpcontrol.floquet_multipliers`."""
        return aliased('floquet_multipliers')(self, **kwargs)

    def floquet_exponents(self, **kwargs):
        """Characteristic exponents; see `ltpcontrol.floquet_exponents`."""
        return aliased('floquet_exponents')(self, **kwargs)

    def poles(self):
        """Poles of the system: the Floquet (characteristic) exponents.

        For a continuous-time system these are the exponents λ with
        multipliers ``μ = e^{λT}`` (imaginary parts in the strip of
        `ltpcontrol.floquet_exponents`); an LTI system gives the
        eigenvalues of A.  See `ltpcontrol.floquet_exponents` for the
        discrete-time convention.
        """
        return self.floquet_exponents()

    # -- LTI-only requests: a clear pointer to the LTP counterpart --
    def frequency_response(self, omega=None, squeeze=None):
        """Not defined for an LTP system: its frequency response is the HTF (`ltpcontrol.htf`)."""
        raise refusal('frequency_response')

    def dcgain(self, warn_infinite=False):
        """Not defined for an LTP system; see `ltpcontrol.htf`."""
        raise refusal('dcgain')

    def zeros(self, nharmonics=None, *, rtol=1e-8):
        """Transmission zeros; see `ltpcontrol.zeros` (so `control.zeros` works)."""
        return aliased('zeros')(self, nharmonics, rtol=rtol)

    def is_stable(self, **kwargs):
        """True when all Floquet multipliers lie inside the unit circle."""
        return aliased('is_stable')(self, **kwargs)

    def htf(self, nharmonics, **kwargs):
        """Harmonic transfer function truncated to K harmonics; see `ltpcontrol.htf`."""
        return aliased('htf')(self, nharmonics, **kwargs)

    def sample(self, Ts, method='zoh', alpha=None, prewarp_frequency=None,
               name=None, copy_names=True, **kwargs):
        """Discretize the system; see `ltpcontrol.sample_system`."""
        return aliased('sample_system')(self, Ts, method=method, alpha=alpha,
                             prewarp_frequency=prewarp_frequency, name=name,
                             copy_names=copy_names, **kwargs)

    #
    # Block-diagram algebra (results stay LTP)
    #

    def __neg__(self):
        return negate(self)

    def __add__(self, other):
        other = _to_ltp_or_none(other, self, 'add')
        return NotImplemented if other is None else _parallel(self, other)

    def __radd__(self, other):
        other = _to_ltp_or_none(other, self, 'add')
        return NotImplemented if other is None else _parallel(other, self)

    def __sub__(self, other):
        other = _to_ltp_or_none(other, self, 'add')
        return NotImplemented if other is None else _parallel(self, negate(other))

    def __rsub__(self, other):
        other = _to_ltp_or_none(other, self, 'add')
        return NotImplemented if other is None else _parallel(other, negate(self))

    def __mul__(self, other):
        # sys * other: other acts first (python-control convention)
        other = _to_ltp_or_none(other, self, 'input')
        return NotImplemented if other is None else _series(other, self)

    def __rmul__(self, other):
        other = _to_ltp_or_none(other, self, 'output')
        return NotImplemented if other is None else _series(self, other)

    def feedback(self, other=1, sign=-1, params=None):
        """Feedback interconnection with ``other`` in the return path; see `ltpcontrol.feedback`."""
        return feedback(self, other, sign)

    def __getitem__(self, key):
        if not isinstance(key, tuple) or len(key) != 2:
            raise ControlArgument("index a system as sys[outputs, inputs], got "
                                  f"{key!r}")
        rows, cols = key
        outs = index_list(rows, self.output_labels, 'output')
        ins = index_list(cols, self.input_labels, 'input')
        return LTPStateSpace(self.A, self.B[:, ins], self.C[outs, :], self.D[outs, :][:, ins],
                             self.period, dt=self.dt, name=self.name + '$indexed',
                             inputs=[self.input_labels[i] for i in ins],
                             outputs=[self.output_labels[i] for i in outs],
                             states=self.state_labels)


def ltpss(*args, period=None, **kwargs):
    """Create a linear time-periodic state-space system.

    ``ltpss(A, B, C, D, period[, dt])`` builds ``ẋ = A(t)x + B(t)u,
    y = C(t)x + D(t)u``; ``ltpss(sys, period)`` converts a python-control
    LTI system (`StateSpace` or `TransferFunction`) into an LTP system
    with constant matrices and the given period; ``ltpss(K)`` makes the
    static periodic gain ``y = K(t) u`` of a `PeriodicMatrix` K (a block for
    `interconnect`, period ``K.period`` unless given).

    Parameters
    ----------
    A, B, C, D : array_like, PeriodicMatrix or callable
        System matrices.  A 2D array is a constant matrix; a callable
        ``f(t)`` returning a 2D array is a smooth periodic matrix; a
        `PeriodicMatrix` may have any period that divides ``period``.  For
        discrete-time systems an array of shape ``(N, rows, cols)`` gives
        the N matrices of one period (or of a sub-period: N_i matrices with
        N_i dividing N repeat), and continuous-time matrices are
        sampled at ``t = k dt``.  ``D`` may be the scalar 0.
    period : float
        Period T > 0 in seconds.
    dt : float, optional
        0 (default) for continuous time; the sampling time otherwise,
        which must divide the period into an integer number of steps.
    name : str, optional
        System name.
    inputs, outputs, states : int, str or list of str, optional
        Signal counts or names, as in `control.ss`.

    Returns
    -------
    LTPStateSpace

    Raises
    ------
    ControlDimension
        If the matrix shapes are inconsistent.
    ControlArgument
        If a matrix is complex or of the wrong type.
    ValueError
        For a non-positive period, a callable that is not periodic, or a
        sampling time that does not divide the period.

    Examples
    --------
    The Mathieu-type system of the thesis (eq. 4.115):

    >>> wp, wn, z = 4 * np.pi, 2 * np.pi, 0.3
    >>> B = ltp.PeriodicMatrix.from_function(
    ...     lambda t: np.array([[0.0], [1 + 0.4 * np.cos(wp * t)]]), 0.5)
    >>> C = lambda t: np.array([[1 + 0.2 * np.cos(wp * t), 0.0]])
    >>> sys = ltp.ltpss([[0, 1], [-wn**2, -2 * z * wn]], B, C, 0, period=0.5)
    >>> sys.nstates, sys.ninputs, sys.noutputs, sys.period
    (2, 1, 1, 0.5)
    """
    if len(args) == 1 and isinstance(args[0], PeriodicMatrix):
        K = args[0]
        p, m = K.shape
        return LTPStateSpace(np.zeros((0, 0)), np.zeros((0, m)), np.zeros((p, 0)), K,
                             K.period if period is None else period, **kwargs)
    if period is not None:
        if len(args) not in (1, 4):
            raise ControlArgument("ltpss: period given both by position and by keyword")
        args = args + (period,)
    if len(args) == 2 and isinstance(args[0], (ct.StateSpace, ct.TransferFunction)):
        lti, period = args
        lti = ct.ss(lti) if isinstance(lti, ct.TransferFunction) else lti
        kwargs.setdefault('dt', lti.dt if lti.dt else 0)
        kwargs.setdefault('name', lti.name)
        kwargs.setdefault('inputs', lti.input_labels)
        kwargs.setdefault('outputs', lti.output_labels)
        kwargs.setdefault('states', lti.state_labels)
        return LTPStateSpace(lti.A, lti.B, lti.C, lti.D, period, **kwargs)
    if len(args) == 6:
        args, kwargs['dt'] = args[:5], args[5]
    if len(args) != 5:
        raise ControlArgument("ltpss expects (A, B, C, D, period[, dt]) or (sys, period); "
                              f"got {len(args)} positional arguments")
    return LTPStateSpace(*args, **kwargs)


#
# Interconnections
#

def series(*systems, **kwargs):
    """series(sys1, sys2[, ..., sysn])

    Series connection: the output of each system drives the next, ``y = sys2(sys1(u))``.

    Parameters
    ----------
    *systems : LTPStateSpace, control.StateSpace, TransferFunction, PeriodicMatrix or array_like
        Systems in signal-flow order (a `PeriodicMatrix` or array is a
        static gain); at least one must be periodic.
    name : str, optional
        Name of the result.

    Returns
    -------
    LTPStateSpace
        States ``[x1; x2]``: ``A = [[A1, 0], [B2 C1, A2]]``,
        ``B = [B1; B2 D1]``, ``C = [D2 C1, C2]``, ``D = D2 D1``.

    Examples
    --------
    >>> P = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> ltp.series(P, ct.tf([1], [1, 2])).nstates
    2
    """
    if (own := overridden('series', *systems)) is not None:    # delay elements
        return own(*systems, **kwargs)
    return _chain(_series, systems, kwargs)


def _series(sys1, sys2, **kwargs):
    s1, s2, period, dt = _common(sys1, sys2)
    if s1.noutputs != s2.ninputs:
        raise ControlDimension(f"series: sys1 has {s1.noutputs} outputs but sys2 has "
                               f"{s2.ninputs} inputs")
    n1, n2 = s1.nstates, s2.nstates
    A = PeriodicMatrix.block([[s1.A, np.zeros((n1, n2))], [s2.B @ s1.C, s2.A]])
    B = PeriodicMatrix.block([[s1.B], [s2.B @ s1.D]])
    C = PeriodicMatrix.block([[s2.D @ s1.C, s2.C]])
    D = s2.D @ s1.D
    return LTPStateSpace(A, B, C, D, period, dt=dt, inputs=s1.input_labels,
                         outputs=s2.output_labels, **kwargs)


def parallel(*systems, **kwargs):
    """parallel(sys1, sys2[, ..., sysn])

    Parallel connection: the outputs of all systems are summed, ``y = sys1(u) + sys2(u)``.

    Parameters
    ----------
    *systems : LTPStateSpace, control.StateSpace, TransferFunction, PeriodicMatrix or array_like
        Systems with the same numbers of inputs and outputs (a
        `PeriodicMatrix` or array is a static gain).
    name : str, optional
        Name of the result.

    Returns
    -------
    LTPStateSpace

    Examples
    --------
    >>> P = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> (P + 2).D(0.0)
    array([[2.]])
    """
    if (own := overridden('parallel', *systems)) is not None:  # delay elements
        return own(*systems, **kwargs)
    return _chain(_parallel, systems, kwargs)


def _parallel(sys1, sys2, **kwargs):
    s1, s2, period, dt = _common(sys1, sys2)
    if s1.shape != s2.shape:
        raise ControlDimension(f"parallel: systems have shapes {s1.shape} and {s2.shape}")
    n1, n2 = s1.nstates, s2.nstates
    A = PeriodicMatrix.block([[s1.A, np.zeros((n1, n2))], [np.zeros((n2, n1)), s2.A]])
    B = PeriodicMatrix.block([[s1.B], [s2.B]])
    C = PeriodicMatrix.block([[s1.C, s2.C]])
    return LTPStateSpace(A, B, C, s1.D + s2.D, period, dt=dt, inputs=s1.input_labels,
                         outputs=s1.output_labels, **kwargs)


def feedback(sys1, sys2=1, sign=-1, **kwargs):
    """Feedback connection ``u1 = u + sign * sys2(y1)``, output ``y1``.

    Parameters
    ----------
    sys1 : LTPStateSpace, control.StateSpace, TransferFunction or array_like
        Forward system.
    sys2 : LTPStateSpace, control.StateSpace, TransferFunction, PeriodicMatrix or array_like
        Return-path system (default: unity); a `PeriodicMatrix` is a
        periodic static gain ``u1 = u + sign K(t) y1``.
    sign : {-1, 1}
        Feedback sign (default negative).
    name : str, optional
        Name of the result.

    Returns
    -------
    LTPStateSpace
        With ``F = (I - sign D1 D2)^{-1}``: ``y1 = F (C1 x1 + sign D1 C2 x2 + D1 u)``.

    Raises
    ------
    ValueError
        If ``I - sign D1(t) D2(t)`` is singular (algebraic loop).

    Examples
    --------
    >>> P = ltp.ltpss([[0.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> L = ltp.feedback(P, 2.0)
    >>> L.A(0.0)
    array([[-2.]])
    """
    if (own := overridden('feedback', sys1, sys2)) is not None:  # delay elements
        return own(sys1, sys2, sign, **kwargs)
    if sign not in (-1, 1):
        raise ValueError(f"sign must be -1 or 1, got {sign!r}")
    s1, s2, period, dt = _common(sys1, sys2)
    if s1.noutputs != s2.ninputs or s2.noutputs != s1.ninputs:
        raise ControlDimension("feedback: sys2 must map the outputs of sys1 to its inputs "
                               f"(sys1 {s1.shape}, sys2 {s2.shape})")
    n1, n2, p1 = s1.nstates, s2.nstates, s1.noutputs
    loop = np.eye(p1) - sign * (s1.D @ s2.D)
    check_well_posed(loop, "feedback", "I - sign D1(t) D2(t)")     # over the whole period
    F = _loop_inverse(loop, "feedback")
    # y1 = F (C1 x1 + s D1 C2 x2 + D1 u);  u1 = u + s (C2 x2 + D2 y1)
    Cy = PeriodicMatrix.block([[F @ s1.C, sign * (F @ s1.D @ s2.C)]])
    Dy = F @ s1.D
    B1 = s1.B
    A = PeriodicMatrix.block([[s1.A, sign * (B1 @ s2.C)], [np.zeros((n2, n1)), s2.A]]) \
        + PeriodicMatrix.block([[sign * (B1 @ s2.D)], [s2.B]]) @ Cy
    B = PeriodicMatrix.block([[B1], [np.zeros((n2, s1.ninputs))]]) \
        + PeriodicMatrix.block([[sign * (B1 @ s2.D)], [s2.B]]) @ Dy
    return LTPStateSpace(A, B, Cy, Dy, period, dt=dt, inputs=s1.input_labels,
                         outputs=s1.output_labels, **kwargs)


def append(*systems, **kwargs):
    """Block-diagonal combination: inputs and outputs are stacked.

    Parameters
    ----------
    *systems : LTPStateSpace, control.StateSpace, TransferFunction or array_like
        Systems to combine (at least one LTP).
    name : str, optional
        Name of the result.

    Returns
    -------
    LTPStateSpace

    Examples
    --------
    >>> P = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0)
    >>> ltp.append(P, P).shape
    (2, 2)
    """
    if not systems:
        raise ValueError("append needs at least one system")
    period, dt = _period_and_dt(systems, "append")
    systems = [_to_ltp(s, period, dt) for s in systems]
    out = systems[0]
    for s in systems[1:]:
        n1, n2 = out.nstates, s.nstates
        Z = np.zeros
        A = PeriodicMatrix.block([[out.A, Z((n1, n2))], [Z((n2, n1)), s.A]])
        B = PeriodicMatrix.block([[out.B, Z((n1, s.ninputs))], [Z((n2, out.ninputs)), s.B]])
        C = PeriodicMatrix.block([[out.C, Z((out.noutputs, n2))], [Z((s.noutputs, n1)), s.C]])
        D = PeriodicMatrix.block([[out.D, Z((out.noutputs, s.ninputs))],
                                  [Z((s.noutputs, out.ninputs)), s.D]])
        out = LTPStateSpace(A, B, C, D, period, dt=dt)
    if kwargs:
        out = LTPStateSpace(out.A, out.B, out.C, out.D, period, dt=dt, **kwargs)
    return out


def negate(sys, **kwargs):
    """Negative of a system, ``y = -sys(u)``.

    Parameters
    ----------
    sys : LTPStateSpace
        System to negate.
    name : str, optional
        Name of the result.

    Returns
    -------
    LTPStateSpace

    Examples
    --------
    >>> P = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0.5, period=1.0)
    >>> (-P).D(0.0)
    array([[-0.5]])
    """
    if not isinstance(sys, LTPStateSpace):
        raise ControlArgument(f"sys must be an LTPStateSpace, got {type(sys).__name__}")
    kwargs.setdefault('inputs', sys.input_labels)
    kwargs.setdefault('outputs', sys.output_labels)
    kwargs.setdefault('states', sys.state_labels)
    return LTPStateSpace(sys.A, sys.B, -sys.C, -sys.D, sys.period, dt=sys.dt, **kwargs)


#
# Private helpers
#

def _system_matrix(M, period, name, nsteps, rows=None, cols=None, zero_ok=False):
    """Convert a user matrix to a PeriodicMatrix of the system period."""
    if nsteps is not None and not isinstance(M, PeriodicMatrix) and not callable(M):
        arr = real_array(M, name, ndim=(0, 1, 2, 3))
        if arr.ndim == 3:
            if arr.shape[0] != nsteps and arr.shape[0] and nsteps % arr.shape[0] == 0:
                arr = np.tile(arr, (nsteps // arr.shape[0], 1, 1))   # a sub-period
            if arr.shape[0] != nsteps:
                raise ControlDimension(f"{name} has {arr.shape[0]} matrices but the period "
                                       f"has {nsteps} steps")
            M = PeriodicMatrix.from_samples(arr, period, kind='hold')
    elif not isinstance(M, PeriodicMatrix) and not callable(M):
        arr = real_array(M, name, ndim=(0, 1, 2, 3))
        if arr.ndim == 3:
            raise ControlDimension(f"{name}: a 3D array is only meaningful for discrete-time "
                                   "systems; use PeriodicMatrix.from_samples")
    if zero_ok and not isinstance(M, PeriodicMatrix) and not callable(M) \
            and np.ndim(M) == 0 and float(M) == 0:
        M = np.zeros((rows, cols))
    P = as_periodic(M, period, name)
    if rows is not None and P.shape[0] != rows:
        raise ControlDimension(f"{name} must have {rows} rows, got shape {P.shape}")
    if cols is not None and P.shape[1] != cols:
        raise ControlDimension(f"{name} must have {cols} columns, got shape {P.shape}")
    if nsteps is not None and not P.is_constant:
        # discrete time: keep the value at t = k dt on [k dt, (k+1) dt)
        if P.switching_times is None or len(P.switching_times) != nsteps:
            P = PeriodicMatrix.from_samples(P.sample(nsteps), period, kind='hold')
    return P


def _chain(pair, systems, kwargs):
    """Fold a binary connection over two or more systems."""
    if len(systems) < 2:
        raise ControlArgument(f"{pair.__name__[1:]} needs at least two systems, "
                              f"got {len(systems)}")
    out = systems[0]
    for s in systems[1:-1]:
        out = pair(out, s)
    return pair(out, systems[-1], **kwargs)


def _loop_inverse(loop, where):
    """``loop(t)^{-1}`` of an algebraic loop ``I - ...`` (periodic or constant)."""
    def inv(values):
        if np.any(np.abs(np.linalg.det(values)) < 1e-12):
            raise ValueError(f"{where}: the algebraic loop is singular (I - D-loop gain "
                             "is not invertible)")
        return np.linalg.inv(values)
    if loop.is_constant:
        return PeriodicMatrix.constant(inv(loop(0.0)[None])[0], loop.period)
    return PeriodicMatrix.pointwise(inv, [loop], loop.shape)


def _merge_period(p1, p2):
    try:
        return commensurate(p1, p2)
    except ValueError:
        raise ValueError(f"systems have incommensurate periods {p1} and {p2}") from None


def _to_ltp(obj, period, dt):
    if isinstance(obj, LTPStateSpace):
        if obj.dt != dt and obj.nstates:      # a static gain fits any timebase
            raise ValueError(f"systems have incompatible timebases (dt={obj.dt} and dt={dt})")
        if obj.period == period and obj.dt == dt:
            return obj
        return LTPStateSpace(obj.A, obj.B, obj.C, obj.D, period, dt=dt,
                             inputs=obj.input_labels, outputs=obj.output_labels,
                             states=obj.state_labels, name=obj.name)
    if isinstance(obj, ct.TransferFunction):
        obj = ct.ss(obj)
    if isinstance(obj, ct.StateSpace):
        if ct.common_timebase(obj.dt, dt) != dt and not _unspecified(obj.dt):
            raise ValueError(f"systems have incompatible timebases (dt={obj.dt} and dt={dt})")
        return LTPStateSpace(obj.A, obj.B, obj.C, obj.D, period, dt=dt,
                             inputs=obj.input_labels, outputs=obj.output_labels,
                             states=obj.state_labels)
    if isinstance(obj, ct.InputOutputSystem):
        raise ControlArgument(f"cannot combine an LTPStateSpace with {type(obj).__name__}")
    if isinstance(obj, PeriodicMatrix):
        gain = obj.with_period(period)
    else:
        gain = np.atleast_2d(real_array(obj, 'gain', ndim=(0, 1, 2)))
    return LTPStateSpace(np.zeros((0, 0)), np.zeros((0, gain.shape[1])),
                         np.zeros((gain.shape[0], 0)), gain, period, dt=dt)


def _to_ltp_or_none(obj, ref, role):
    """Operand of an arithmetic operator as an LTP system, or None if unsupported.

    A scalar is, as in python-control, added to every entry of D (`role`
    'add') or a gain on every input ('input') or output ('output') channel.
    """
    if isinstance(obj, LTPStateSpace):
        return obj
    if isinstance(obj, (int, float, np.number)) and not isinstance(obj, bool):
        gain = (np.full(ref.shape, float(obj)) if role == 'add' else
                float(obj) * np.eye(ref.ninputs if role == 'input' else ref.noutputs))
        return _to_ltp(gain, ref.period, ref.dt)
    if isinstance(obj, PeriodicMatrix):
        return _to_ltp(obj, _merge_period(ref.period, obj.period), ref.dt)
    if isinstance(obj, (ct.StateSpace, ct.TransferFunction, np.ndarray, list)):
        return _to_ltp(obj, ref.period, ref.dt)
    return None


def _period_and_dt(systems, where):
    """Common period of the periodic operands and timebase of the dynamic ones."""
    periodic = [s for s in systems if isinstance(s, (LTPStateSpace, PeriodicMatrix))]
    if not periodic:
        raise ControlArgument(f"{where}: at least one system must be an LTPStateSpace or a "
                              "PeriodicMatrix gain")
    period = periodic[0].period
    for s in periodic[1:]:
        period = _merge_period(period, s.period)
    # static operands (no states) fit any timebase
    dts = {s.dt for s in systems if isinstance(s, ct.InputOutputSystem)
           and not _unspecified(s.dt) and s.nstates}
    if len(dts) > 1:
        raise ValueError(f"{where}: systems have incompatible timebases {sorted(dts)}")
    return period, (dts.pop() if dts else 0.0)


def _unspecified(dt):
    """python-control's unspecified timebases: None, or True (discrete, any step).

    By identity: ``dt in (None, True)`` would also match a sampling time of 1.0.
    """
    return dt is None or dt is True


def _common(sys1, sys2):
    period, dt = _period_and_dt((sys1, sys2), "block diagram")
    s1 = _to_ltp(sys1, period, dt)
    s2 = _to_ltp(sys2, period, dt)
    if isinstance(sys2, (int, float)) and s1.noutputs != 1:
        s2 = _to_ltp(float(sys2) * np.eye(s1.noutputs), period, dt)
    return s1, s2, period, dt
