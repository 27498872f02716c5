"""Linear time-periodic systems with delays (periodic delay-differential equations).

Continuous time, T-periodic matrices, delays ``τ_j > 0``::

    ẋ(t) = A(t) x(t) + Σ_j A_j(t) x(t - τ_j) + B(t) u(t) + Σ_j B_j(t) u(t - τ_j)
    y(t) = C(t) x(t) + Σ_j C_j(t) x(t - τ_j) + D(t) u(t) + Σ_j D_j(t) u(t - τ_j)

The state at time t is the history segment ``x(t + θ)``, ``θ ∈ [-τ_max, 0]``
(infinite dimensional); the characteristic multipliers are the nonzero
eigenvalues of the monodromy operator mapping one period's starting segment
to the next (see `ltpcontrol._delays.monodromy`).  Input and output delays
(B_j, C_j, D_j) arise when systems are connected through delay elements.
"""

import numbers

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension
from control.iosys import _process_iosys_keywords

from .._core.ltpsys import LTPStateSpace, _system_matrix
from .._core.periodic_matrix import PeriodicMatrix
from .._core.refusals import refusal_error
from .._core.registry import aliased, overridden
from .._core.validation import check_period
from . import terms as tm

__all__ = ['LTPDelayStateSpace', 'ltpdss']


class LTPDelayStateSpace(ct.InputOutputSystem):
    """Linear time-periodic system with delays in its states, inputs or outputs.

    ``ẋ = A(t)x + Σ_j A_j(t) x(t-τ_j) + B(t)u + Σ_j B_j(t) u(t-τ_j)``,
    ``y = C(t)x + Σ_j C_j(t) x(t-τ_j) + D(t)u + Σ_j D_j(t) u(t-τ_j)``, all
    matrices T-periodic, continuous time.  Create systems with `ltpdss`
    (state delays) or by connecting LTP systems through `delay` elements.

    Parameters
    ----------
    terms : dict
        ``{'A': {τ: PeriodicMatrix}, 'B': ..., 'C': ..., 'D': ...}``, the
        key 0 holding the undelayed matrix.
    period : float
        Period T.
    name, inputs, outputs, states : optional
        Signal names, as for `LTPStateSpace`.

    Attributes
    ----------
    A, B, C, D : PeriodicMatrix
        The undelayed matrices.
    state_delays : list of (float, PeriodicMatrix)
        The terms ``(τ_j, A_j)``.
    delays : tuple of float
        Every distinct delay of the system, increasing.
    period : float
        The period T.

    Examples
    --------
    >>> sys = ltp.ltpdss([[0.0, 1.0], [-1.0, -0.1]], [[0.0], [1.0]], [[1.0, 0.0]], 0,
    ...                  period=1.0, delays=[(0.5, [[0.0, 0.0], [-0.2, 0.0]])], name='turn')
    >>> sys
    <LTPDelayStateSpace turn: ['u[0]'] -> ['y[0]'], period=1, delays=(0.5,)>
    """

    def __init__(self, terms, period, *, name=None, inputs=None, outputs=None, states=None):
        self.period = check_period(period)
        shape = {k: next(iter(terms[k].values())).shape for k in 'ABCD'}
        self._terms = {}
        for k in 'ABCD':
            X = {float(a): M for a, M in terms[k].items()}
            X.setdefault(0.0, PeriodicMatrix.constant(np.zeros(shape[k]), self.period))
            self._terms[k] = tm.clean(X)
        n, m, p = shape['A'][0], shape['B'][1], shape['C'][0]
        for k, shape in zip('ABCD', ((n, n), (n, m), (p, n), (p, m))):
            for a, M in self._terms[k].items():
                if M.shape != shape:
                    raise ControlDimension(f"{k} term of delay {a:g} has shape {M.shape}, "
                                           f"expected {shape}")
                if not np.isclose(M.period, self.period, rtol=1e-12):
                    raise ValueError(f"{k} term of delay {a:g} has period {M.period}, "
                                     f"expected {self.period}")
        name, inputs, outputs, states, _ = _process_iosys_keywords(
            dict(name=name, inputs=inputs, outputs=outputs, states=states),
            {'inputs': m, 'outputs': p, 'states': n})
        super().__init__(name=name, inputs=inputs, outputs=outputs, states=states, dt=0)
        for what, count, size in (('inputs', self.ninputs, m), ('outputs', self.noutputs, p),
                                  ('states', self.nstates, n)):
            if count != size:
                raise ControlDimension(f"{what} has {count} labels but the matrices "
                                       f"imply {size}")

    # -- descriptive properties --
    A = property(lambda self: self._terms['A'][0.0], doc="Undelayed A(t).")
    B = property(lambda self: self._terms['B'][0.0], doc="Undelayed B(t).")
    C = property(lambda self: self._terms['C'][0.0], doc="Undelayed C(t).")
    D = property(lambda self: self._terms['D'][0.0], doc="Undelayed D(t).")

    @property
    def terms(self):
        """Copy of the delay polynomials ``{'A': {τ: M_τ}, ...}`` (τ = 0: undelayed)."""
        return {k: dict(v) for k, v in self._terms.items()}

    @property
    def state_delays(self):
        """The state-delay terms ``[(τ_j, A_j), ...]`` by increasing delay."""
        return tm.delayed(self._terms['A'])

    @property
    def delays(self):
        """Every distinct delay of the system, increasing."""
        keys = []
        for X in self._terms.values():
            for a in X:
                if a > 0 and tm.key(a, keys) not in keys:
                    keys.append(a)
        return tuple(sorted(keys))

    @property
    def omega_p(self):
        """Fundamental frequency ``2π/T`` in rad/s."""
        return 2 * np.pi / self.period

    @property
    def is_lti(self):
        """True when every matrix of every term is constant."""
        return all(M.is_constant for X in self._terms.values() for M in X.values())

    def _repr_info_(self, html=False):
        text = (f"<LTPDelayStateSpace {self.name}: {self.input_labels} -> "
                f"{self.output_labels}, period={self.period:g}, "
                f"delays={tuple(float(f'{a:.6g}') for a in self.delays)}>")
        return text if not html else text.replace('<', '&lt;').replace('>', '&gt;')

    def __repr__(self):
        return self._repr_info_()

    def __str__(self):
        lines = [self._repr_info_(), f"states: {self.state_labels}"]
        for k, what in zip('ABCD', ('state', 'input', 'state in output', 'input in output')):
            for a, M in tm.delayed(self._terms[k]):
                kind = 'constant' if M.is_constant else 'periodic'
                lines.append(f"  {k} term, {what} delayed by {a:g}: {kind} {M.shape}")
        return "\n".join(lines)

    def undelayed(self, *, name=None):
        """The `LTPStateSpace` with every delay set to zero (``e^{-sτ} = 1``).

        Parameters
        ----------
        name : str, optional
            Name of the result (default ``'<name>$undelayed'``).

        Returns
        -------
        LTPStateSpace

        Examples
        --------
        >>> sys = ltp.ltpdss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, delays=[(0.3, [[0.5]])])
        >>> sys.undelayed().A(0.0)
        array([[-0.5]])
        """
        mats = []
        for k in 'ABCD':
            X = self._terms[k]
            total = X[0.0]
            for _, M in tm.delayed(X):
                total = total + M
            mats.append(total)
        return LTPStateSpace(*mats, self.period, name=name or self.name + '$undelayed',
                             inputs=self.input_labels, outputs=self.output_labels,
                             states=self.state_labels)

    # -- analysis: see ltpcontrol._delays.monodromy and friends --
    def monodromy(self):
        """Discretized monodromy operator; see `ltpcontrol.monodromy`."""
        return aliased('monodromy')(self)

    def floquet_multipliers(self):
        """Characteristic multipliers; see `ltpcontrol.floquet_multipliers`."""
        return aliased('floquet_multipliers')(self)

    def floquet_exponents(self):
        """Characteristic exponents; see `ltpcontrol.floquet_exponents`."""
        return aliased('floquet_exponents')(self)

    def poles(self):
        """The dominant characteristic exponents (see `floquet_exponents`)."""
        return self.floquet_exponents()

    def is_stable(self, tol=1e-10):
        """True when every characteristic multiplier lies inside the unit circle."""
        return aliased('is_stable')(self, tol)

    def htf(self, nharmonics, *, internal_harmonics=None):
        """Harmonic transfer function with exact ``e^{-sτ}``; see `ltpcontrol.htf`."""
        return aliased('htf')(self, nharmonics, internal_harmonics=internal_harmonics)

    def __call__(self, *args, **kwargs):
        raise refusal_error("evaluation sys(s) of a transfer function",
                            "ltp.htf(sys, nharmonics)(s), the harmonic transfer function")

    # -- block-diagram algebra --
    # (python-control's convention: ``G2 * G1`` is G1 followed by G2; the connections
    # are those that ltpcontrol.series and parallel use for systems with delays)
    def __mul__(self, other):
        return overridden('series', self)(other, self)

    def __rmul__(self, other):
        return overridden('series', self)(self, other)

    def __add__(self, other):
        return overridden('parallel', self)(self, other)

    __radd__ = __add__

    def __neg__(self):
        return self._negated()

    def __sub__(self, other):
        return overridden('parallel', self)(self, -other)

    def __rsub__(self, other):
        return overridden('parallel', self)(other, self._negated())

    def _negated(self):
        t = self.terms
        t['C'] = tm.scale(t['C'], -1.0)
        t['D'] = tm.scale(t['D'], -1.0)
        return LTPDelayStateSpace(t, self.period, inputs=self.input_labels,
                                  outputs=self.output_labels, states=self.state_labels)


def ltpdss(*args, period=None, delays=(), name=None, inputs=None, outputs=None, states=None):
    """ltpdss(A, B, C, D, *, period, delays=[(tau_1, A_1), ...])

    Create a linear time-periodic system with state delays.

    ``ẋ(t) = A(t) x(t) + Σ_j A_j(t) x(t - τ_j) + B(t) u(t)``,
    ``y(t) = C(t) x(t) + D(t) u(t)``.

    Call forms: ``ltpdss(A, B, C, D, period=T, delays=...)``, or
    ``ltpdss(sys, delays=...)`` with an `LTPStateSpace` (or an LTI system
    and ``period``) whose A becomes the undelayed part.

    Parameters
    ----------
    *args : A, B, C, D or sys
        Matrices in any form `ltpss` accepts (arrays, `PeriodicMatrix`,
        callables ``t -> M(t)``), or one system.
    period : float
        Period T of the matrices (any T for constant matrices).
    delays : list of (float, matrix)
        State-delay terms ``(τ_j, A_j)``: ``τ_j > 0`` finite, shorter or
        longer than T, commensurate or not; ``A_j`` n×n in any form `ltpss`
        accepts.  Terms of equal delay are added.
    name, inputs, outputs, states : optional
        Signal names, as for `ltpss`.

    Returns
    -------
    LTPDelayStateSpace

    Raises
    ------
    ValueError
        For a delay that is not a finite positive number, or a non
        positive period.
    control.ControlDimension
        For matrices of inconsistent shapes.

    Examples
    --------
    Regenerative chatter of turning, ``x'' + 2ζx' + x = -w (x(t) - x(t - τ))``:

    >>> w, tau = 0.1, 2.0
    >>> A = [[0.0, 1.0], [-1.0 - w, -0.1]]
    >>> sys = ltp.ltpdss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=tau,
    ...                  delays=[(tau, [[0.0, 0.0], [w, 0.0]])])
    >>> sys.delays, sys.nstates
    ((2.0,), 2)
    >>> bool(ltp.is_stable(sys))
    True
    """
    kwargs = dict(name=name, inputs=inputs, outputs=outputs, states=states)
    if len(args) == 1 and isinstance(args[0], (LTPStateSpace, ct.StateSpace,
                                                   ct.TransferFunction)):
        sys = args[0]
        if isinstance(sys, LTPStateSpace):
            if period is not None:
                raise TypeError("ltpdss: the period is taken from the LTPStateSpace; "
                                "do not pass period")
            if sys.isdtime(strict=True):
                raise ValueError("ltpdss: sys must be a continuous-time system (a delay of "
                                 "a discrete-time system is a shift of whole steps)")
            period = sys.period
        else:
            if period is None:
                raise ControlArgument("ltpdss: pass period with an LTI system")
            sys = ct.ss(sys)
            if sys.isdtime(strict=True):
                raise ValueError("ltpdss: sys must be a continuous-time system")
        for key in ('inputs', 'outputs', 'states'):
            if kwargs[key] is None:
                kwargs[key] = getattr(sys, key[:-1] + '_labels')
        if kwargs['name'] is None:
            kwargs['name'] = sys.name
        args = (sys.A, sys.B, sys.C, sys.D)
    if len(args) != 4:
        raise ControlArgument("ltpdss expects (A, B, C, D) and period=, or (sys); got "
                              f"{len(args)} positional arguments")
    if period is None:
        raise ControlArgument("ltpdss: period is required")
    period = check_period(period)
    A = _system_matrix(args[0], period, 'A', None)
    n = A.shape[0]
    if A.shape != (n, n):
        raise ControlDimension(f"A must be square, got shape {A.shape}")
    B = _system_matrix(args[1], period, 'B', None, rows=n)
    C = _system_matrix(args[2], period, 'C', None, cols=n)
    D = _system_matrix(args[3], period, 'D', None, rows=C.shape[0], cols=B.shape[1],
                       zero_ok=True)
    Aterms = {0.0: A}
    for j, (tau, Aj) in enumerate(_delay_list(delays)):
        Aj = _system_matrix(Aj, period, f'delays[{j}] matrix', None, rows=n, cols=n)
        Aterms = tm.add(Aterms, {tau: Aj})
    return LTPDelayStateSpace({'A': Aterms, 'B': {0.0: B}, 'C': {0.0: C}, 'D': {0.0: D}},
                              period, **kwargs)


def check_delay(tau, name='tau'):
    """A delay as a finite positive float, or a ValueError naming `name`.

    Examples
    --------
    >>> from ltpcontrol._delays.ltpdsys import check_delay
    >>> check_delay(-1.0)
    Traceback (most recent call last):
    ...
    ValueError: tau must be a finite positive delay, got -1.0
    """
    if isinstance(tau, (bool, np.bool_)) or not isinstance(tau, (numbers.Real, np.number)) \
            or not np.isfinite(tau) or tau <= 0:
        raise ValueError(f"{name} must be a finite positive delay, got {tau!r}")
    return float(tau)


def _delay_list(delays):
    if isinstance(delays, tuple) and len(delays) == 2 and isinstance(delays[0], numbers.Real):
        delays = [delays]
    try:
        items = list(delays)
    except TypeError:
        raise ControlArgument("delays must be a list of (tau, A_tau) pairs, got "
                              f"{type(delays).__name__}") from None
    out = []
    for j, item in enumerate(items):
        if not isinstance(item, (tuple, list)) or len(item) != 2:
            raise ControlArgument(f"delays[{j}] must be a pair (tau, A_tau), got {item!r}")
        out.append((check_delay(item[0], f'delays[{j}] delay'), item[1]))
    return out


def as_delayed(obj, period=None, width=None):
    """`obj` as an `LTPDelayStateSpace` (LTP, LTI, gain or delayed system).

    `period` is the period given to an LTI system or a gain; `width` the
    size of the identity that a scalar gain stands for.

    Examples
    --------
    >>> from ltpcontrol._delays.ltpdsys import as_delayed
    >>> as_delayed(ct.tf([1.0], [1.0, 1.0]), period=2.0).period
    2.0
    >>> g = as_delayed(0.5, period=1.0, width=2)
    >>> g.nstates, g.D(0.0).tolist()
    (0, [[0.5, 0.0], [0.0, 0.5]])
    """
    if isinstance(obj, LTPDelayStateSpace):
        return obj
    if isinstance(obj, LTPStateSpace):
        if obj.isdtime(strict=True):
            raise ValueError("a continuous-time delayed system cannot be combined with a "
                             "discrete-time one")
        return LTPDelayStateSpace({'A': {0.0: obj.A}, 'B': {0.0: obj.B}, 'C': {0.0: obj.C},
                                   'D': {0.0: obj.D}}, obj.period, name=obj.name,
                                  inputs=obj.input_labels, outputs=obj.output_labels,
                                  states=obj.state_labels)
    if isinstance(obj, (ct.StateSpace, ct.TransferFunction)):
        s = ct.ss(obj)
        if s.isdtime(strict=True):
            raise ValueError("a continuous-time delayed system cannot be combined with a "
                             "discrete-time one")
        P = lambda M: PeriodicMatrix.constant(np.atleast_2d(M) if np.size(M) else
                                              np.zeros(np.shape(M)), period)
        return LTPDelayStateSpace({'A': {0.0: P(s.A)}, 'B': {0.0: P(s.B)},
                                   'C': {0.0: P(s.C)}, 'D': {0.0: P(s.D)}}, period,
                                  name=s.name, inputs=s.input_labels,
                                  outputs=s.output_labels, states=s.state_labels)
    if isinstance(obj, PeriodicMatrix):
        gain = obj
    elif isinstance(obj, (numbers.Real, np.number)) and width is not None:
        gain = float(obj) * np.eye(width)
    else:
        gain = np.atleast_2d(np.asarray(obj, float))
    G = gain if isinstance(gain, PeriodicMatrix) else PeriodicMatrix.constant(gain, period)
    p, m = G.shape
    Z = lambda r, c: PeriodicMatrix.constant(np.zeros((r, c)), period)
    return LTPDelayStateSpace({'A': {0.0: Z(0, 0)}, 'B': {0.0: Z(0, m)}, 'C': {0.0: Z(p, 0)},
                               'D': {0.0: G}}, period)
