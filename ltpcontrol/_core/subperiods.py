"""Components with different periods, combined on their least common multiple.

A discrete periodic problem may mix matrices of different step periods:
``A`` repeating every 3 steps and ``Q`` every 2 steps define a problem of
period 6, on which ``A[k] = A[k mod 3]`` and ``Q[k] = Q[k mod 2]``.  The
helpers here tile the per-step stacks (arrays of shape ``(N_i, r, c)``) to
the least common multiple of their step counts, and the periods of
continuous-time periodic matrices to their common period
(`validation.commensurate`).  The common step count is bounded by
``ltp.config.defaults['period.max_multiple']`` times the largest count, so
that a pair such as 997 and 991 steps (a period of 988027 steps) is reported
instead of being built silently.
"""

import math

import numpy as np
from control.exception import ControlDimension

from ..config import _get
from .validation import commensurate

__all__ = []


def common_steps(counts, names):
    """Least common multiple of the step counts `counts` of the arguments `names`.

    Examples
    --------
    >>> from ltpcontrol._core.subperiods import common_steps
    >>> common_steps([3, 2, 1], ['A', 'Q', 'R'])
    6
    """
    counts = [int(c) for c in counts]
    N = 1
    for c in counts:
        N = math.lcm(N, c)
    qmax = int(_get('period.max_multiple', None))
    if counts and N > qmax * max(counts):
        listed = ', '.join(f'{n} ({c} steps)' for n, c in zip(names, counts))
        raise ValueError(f"the step periods of {listed} have the common period {N}, more "
                         f"than {qmax} times the longest (see "
                         "ltp.config.defaults['period.max_multiple'])")
    return N


def tile_steps(arrays, names):
    """Tile per-step stacks ``(N_i, r, c)`` to their common step count.

    Entries that are not 3D arrays (2D matrices, ``None``) are returned
    unchanged.

    Examples
    --------
    >>> from ltpcontrol._core.subperiods import tile_steps
    >>> A, Q = tile_steps([np.zeros((3, 2, 2)), np.ones((2, 2, 2))], ['A', 'Q'])
    >>> A.shape, Q.shape
    ((6, 2, 2), (6, 2, 2))
    """
    stacks = [(a, n) for a, n in zip(arrays, names) if _is_stack(a)]
    if len({a.shape[0] for a, _ in stacks}) <= 1:
        return list(arrays)
    N = common_steps([a.shape[0] for a, _ in stacks], [n for _, n in stacks])
    out = []
    for a in arrays:
        if _is_stack(a):
            a = np.asarray(a)
            a = np.tile(a, (N // a.shape[0], 1, 1))
        out.append(a)
    return out


def tile_to(array, nsteps, name):
    """Tile a stack of ``N_i`` matrices to `nsteps` steps (``N_i`` must divide it).

    Examples
    --------
    >>> from ltpcontrol._core.subperiods import tile_to
    >>> tile_to(np.arange(2.0).reshape(2, 1, 1), 4, 'B')[:, 0, 0]
    array([0., 1., 0., 1.])
    """
    array = np.asarray(array)
    if nsteps % array.shape[0]:
        raise ControlDimension(f"{name} has {array.shape[0]} matrices, which is not a "
                               f"sub-period of the {nsteps} steps of the period")
    return np.tile(array, (nsteps // array.shape[0], 1, 1))


def common_period(periods, names):
    """Common period of continuous periods (ValueError naming the arguments).

    Examples
    --------
    >>> from ltpcontrol._core.subperiods import common_period
    >>> common_period([3.0, 2.0], ['A', 'Q'])
    6.0
    """
    T = periods[0]
    for p, n in zip(periods[1:], names[1:]):
        try:
            T = commensurate(T, p)
        except ValueError as exc:
            raise ValueError(f"{n}: {exc}") from None
    return T


def _is_stack(a):
    return a is not None and not callable(a) and not hasattr(a, 'sample') \
        and not isinstance(a, (list, tuple)) and np.ndim(a) == 3 \
        or (isinstance(a, (list, tuple)) and _uniform_list(a))


def _uniform_list(a):
    try:
        arr = np.asarray(a, dtype=float)
    except (ValueError, TypeError):
        return False
    return arr.ndim == 3


def align_period(sys, weights):
    """A discrete `LTPStateSpace` re-expressed on the common period of its weights.

    `weights` maps argument names to weights (2D arrays, stacks of
    ``N_i`` matrices, periodic matrices or None).  When a stack's ``N_i`` or a
    periodic matrix's period does not divide the period of `sys`, the system
    is returned with the matrices of ``lcm`` steps (same ``dt``); otherwise
    `sys` itself.

    Examples
    --------
    >>> from ltpcontrol._core.subperiods import align_period
    >>> sys = ltp.ltpss(np.array([[[0.5]], [[0.1]], [[0.2]]]), [[1.0]], [[1.0]], 0,
    ...                 period=3.0, dt=1.0)
    >>> align_period(sys, {'Q': np.ones((2, 1, 1))}).nsteps
    6
    """
    if not (hasattr(sys, 'nsteps') and sys.nsteps):
        return sys
    N, dt = sys.nsteps, sys.dt
    counts, names = [N], ['sys']
    for name, W in weights.items():
        if W is None or callable(W) and not hasattr(W, 'period'):
            continue
        if hasattr(W, 'period') and hasattr(W, 'sample'):
            T = common_period([sys.period, W.period], ['sys', name])
            counts.append(int(round(T / dt)))
            names.append(name)
        elif _is_stack(W):
            counts.append(np.shape(W)[0])
            names.append(name)
    L = common_steps(counts, names)
    if L == N:
        return sys
    from .ltpsys import LTPStateSpace
    return LTPStateSpace(*(M.sample(N)[np.arange(L) % N] for M in (sys.A, sys.B, sys.C, sys.D)),
                         L * dt, dt=dt, inputs=sys.input_labels, outputs=sys.output_labels,
                         states=sys.state_labels, name=sys.name)


def on_common_period(mats):
    """Periodic matrices of different periods viewed on their common period.

    `mats` maps argument names to values; the `PeriodicMatrix` values (those
    with ``with_period``) are returned with the common period, the others
    unchanged.  Incommensurate periods raise ValueError naming the argument.

    Examples
    --------
    >>> from ltpcontrol._core.subperiods import on_common_period
    >>> A = ltp.PeriodicMatrix.constant(-np.eye(1), 3.0)
    >>> Q = ltp.PeriodicMatrix([[[0.5]], [[1.0]], [[0.5]]], 2.0)
    >>> [M.period for M in on_common_period({'A': A, 'Q': Q}).values()]
    [6.0, 6.0]
    """
    periodic = {k: v for k, v in mats.items() if hasattr(v, 'with_period') and
                hasattr(v, 'period')}
    if len({v.period for v in periodic.values()}) <= 1:
        return dict(mats)
    T = common_period([v.period for v in periodic.values()], list(periodic))
    return {k: (v.with_period(T) if k in periodic else v) for k, v in mats.items()}


def align_weights(sys, weights):
    """`align_period`, then every stack of weights tiled to the system's steps.

    Examples
    --------
    >>> from ltpcontrol._core.subperiods import align_weights
    >>> sys = ltp.ltpss(np.array([[[0.5]], [[0.1]], [[0.2]]]), [[1.0]], [[1.0]], 0,
    ...                 period=3.0, dt=1.0)
    >>> sys6, (Q, R) = align_weights(sys, {'Q': np.ones((2, 1, 1)), 'R': [[1.0]]})
    >>> sys6.nsteps, Q.shape
    (6, (6, 1, 1))
    """
    sys = align_period(sys, weights)
    out = []
    for name, W in weights.items():
        if _is_stack(W) and np.shape(W)[0] != sys.nsteps:
            W = tile_to(np.asarray(W, float), sys.nsteps, name)
        out.append(W)
    return sys, out
