"""Time responses of LTP systems with delays, from a given history.

The solution is marched element by element by the same collocation as the
monodromy operator (`ltpcontrol._delays.monodromy`): on each element x is
the polynomial of degree p through its Chebyshev-Lobatto nodes, and the
equation is collocated at p Chebyshev-Gauss points.  The element edges
contain every time point (so the held input is a polynomial on each
element), every time point shifted by each input delay, every switching
instant of the matrices and the instants ``t_0 + kτ_j`` where the jump
between the history and the initial state reappears in the derivatives;
no element is longer than the shortest delay, so every delayed value
comes from a finished element or from the history, and the march is
explicit from element to element.  Between those edges the solution is
smooth and the collocation converges spectrally: the response is exact to
rounding when the polynomial reproduces it and otherwise accurate to the
tolerance checked by a second march at degree ``p + 4``.
"""

import warnings

import numpy as np
import control as ct

from .._core.registry import override
from .._core.timeresp import forced_arguments, forced_result
from .._core.validation import check_kwargs, real_array
from . import terms as tm
from .ltpdsys import LTPDelayStateSpace
from .monodromy import _H_NORM, _edges, _locate, _rules, _gauss

__all__ = []

_ORDER = 12


def _simulate(sys, t, u, x0, history, hold, order):
    """States at `t` and outputs: arrays (n, ntr, L) and (p, ntr, L)."""
    n, ntr = sys.nstates, u.shape[1]
    t0, T = t[0], sys.period
    terms = sys.terms
    Aterms = [(0.0, sys.A)] + tm.delayed(terms['A'])
    Bterms = sorted(terms['B'].items())
    taus = np.array([a for a, _ in Aterms[1:]])
    all_delays = np.array(sys.delays) if sys.delays else np.zeros(0)
    # element edges
    pts = [t]
    for a in all_delays:
        pts.append(t + a)
    for a in taus:
        k = np.arange(1, 4)
        pts.append(t0 + np.add.outer(k * a, [0.0]).ravel())
    bps = np.unique(np.concatenate([M.breakpoints for X in terms.values() for M in X.values()]
                                   + [np.zeros(0)]))
    if bps.size:
        kk = np.arange(np.floor(t0 / T), np.ceil(t[-1] / T) + 1)
        pts.append((bps[None, :] + T * kk[:, None]).ravel())
    probe = np.linspace(0, T, 33)[:-1]
    vals = [M(probe) for _, M in Aterms]
    plus = sum(vals)
    scale = max(np.max(np.abs(np.linalg.eigvals(S)), initial=0.0)
                for S in (plus, 2 * vals[0] - plus))
    hmax = min(_H_NORM / scale if scale > 0 else np.inf, *(taus if taus.size else [np.inf]),
               max(t[-1] - t0, 1e-300))
    edges = _edges(np.concatenate(pts), t0, t[-1], hmax)
    ne = len(edges) - 1
    p = order
    z, w, Ic, Dc = _rules(p)
    h = np.diff(edges)
    tc = (edges[:-1, None] + (_gauss(p)[None, :] + 1) / 2 * h[:, None]).ravel()
    A = Aterms[0][1](tc).reshape(ne, p, n, n)

    def uval(times):
        """Held input at `times` (zero before t0): (m, ntr, len)."""
        out = np.zeros((u.shape[0], ntr, len(times)))
        ok = times >= t0 - 1e-12 * max(1.0, abs(t0))
        tt = np.clip(times[ok], t0, t[-1])
        if hold == 'foh':
            i = np.clip(np.searchsorted(t, tt, side='right') - 1, 0, len(t) - 2)
            f = (tt - t[i]) / (t[i + 1] - t[i])
            out[:, :, ok] = u[:, :, i] * (1 - f) + u[:, :, i + 1] * f
        else:
            i = np.clip(np.searchsorted(t, tt * (1 + 1e-14) + 1e-300, side='right') - 1,
                        0, len(t) - 1)
            out[:, :, ok] = u[:, :, i]
        return out

    # forcing: inputs (all delays) and the history's contribution to the delayed states
    force = np.zeros((ne * p, n, ntr))
    for a, Bm in Bterms:
        force += np.einsum('krm,mtk->krt', Bm(tc), uval(tc - a))
    reads = []
    for a, M in Aterms[1:]:
        Mv = M(tc)
        past = tc - a
        early = past < t0
        if np.any(early):
            force[early] += np.einsum('krc,kct->krt', Mv[early], _history(history, past[early],
                                                                         t0, n, ntr))
        idx, L = _locate(edges, z, w, np.maximum(past, t0))
        L = np.where(early[:, None], 0.0, L)
        reads.append((idx.reshape(ne, p, p + 1), L.reshape(ne, p, p + 1),
                      Mv.reshape(ne, p, n, n)))
    force = force.reshape(ne, p, n, ntr)
    V = np.zeros((ne * p + 1, n, ntr))
    V[0] = x0
    I = np.eye(n)
    for e in range(ne):
        own = (Dc * (2 / h[e]))[:, None, :, None] * I[None, :, None, :] \
            - Ic[:, None, :, None] * A[e][:, :, None, :]
        rhs = force[e] - np.einsum('lrc,ct->lrt', own[:, :, 0, :], V[e * p])
        for idx, L, Mv in reads:
            past = np.einsum('li,lict->lct', L[e], V[idx[e]])
            rhs += np.einsum('lrc,lct->lrt', Mv[e], past)
        V[e * p + 1:e * p + p + 1] = np.linalg.solve(
            own[:, :, 1:, :].reshape(p * n, p * n), rhs.reshape(p * n, ntr)).reshape(p, n, ntr)

    def xval(times):
        """States at `times` (history before t0): (n, ntr, len)."""
        out = np.zeros((n, ntr, len(times)))
        early = times < t0
        if np.any(early):
            out[:, :, early] = np.moveaxis(_history(history, times[early], t0, n, ntr), 0, -1)
        idx, L = _locate(edges, z, w, np.clip(times[~early], t0, t[-1]))
        out[:, :, ~early] = np.einsum('ki,kict->ctk', L, V[idx])
        return out

    x = xval(t)
    y = np.zeros((sys.noutputs, ntr, len(t)))
    for a, Cm in terms['C'].items():
        y += np.einsum('krc,ctk->rtk', Cm(t), x if a == 0 else xval(t - a))
    for a, Dm in terms['D'].items():
        y += np.einsum('krm,mtk->rtk', Dm(t), uval(t - a))
    return x, y


def _history(history, times, t0, n, ntr):
    """History values at `times` < t0: (len, n, ntr)."""
    if history is None:
        return np.zeros((len(times), n, ntr))
    vals = np.stack([np.asarray(history(float(s)), float) for s in times])
    if vals.shape[1:] == (n,):
        vals = np.repeat(vals[:, :, None], ntr, axis=2)
    if vals.shape[1:] != (n, ntr) or not np.all(np.isfinite(vals)):
        raise ValueError(f"history(t) must return finite values of shape ({n},) or "
                         f"({n}, {ntr}), got {vals.shape[1:]}")
    return vals


def _check_history(history, t0, tau):
    """A callable t -> x(t) for t < t0, or None; arrays (times, values) must cover tau."""
    if history is None or callable(history):
        return history
    if isinstance(history, (tuple, list)) and len(history) == 2:
        ht = real_array(history[0], 'history times', ndim=1)
        hv = real_array(history[1], 'history values', ndim=(1, 2, 3))
        if ht.size < 2 or np.any(np.diff(ht) <= 0):
            raise ValueError("history times must be increasing (at least two)")
        if ht[0] > t0 - tau + 1e-12 * max(1.0, abs(t0)) or ht[-1] < t0 - 1e-12 * max(1, abs(t0)):
            raise ValueError(f"the history covers [{ht[0]:g}, {ht[-1]:g}] but the delay "
                             f"{tau:g} needs [{t0 - tau:g}, {t0:g}]")
        if hv.shape[-1] != ht.size:
            raise ValueError(f"history values must have {ht.size} samples on the last axis, "
                             f"got shape {hv.shape}")

        def interp(s):
            i = int(np.clip(np.searchsorted(ht, s, side='right') - 1, 0, ht.size - 2))
            f = (s - ht[i]) / (ht[i + 1] - ht[i])
            return hv[..., i] * (1 - f) + hv[..., i + 1] * f
        return interp
    raise ValueError("history must be None, a callable t -> x(t) (t before the first time "
                     "point) or a pair (times, values)")


@override('forced_response', LTPDelayStateSpace)
def forced_response(sys, timepts=None, inputs=0.0, initial_state=0.0, *, method='transition',
                    input_hold='foh', rtol=1e-12, compute_states=True, return_states=False,
                    squeeze=None, transpose=False, history=None, **kwargs):
    """`ltpcontrol.forced_response` of a system with delays (see the module notes).

    ``history`` gives the state before the first time point: None (zero,
    the default), a callable ``t -> x(t)`` (shape ``(n,)`` or ``(n,
    ntraces)``), or a pair ``(times, values)`` interpolated linearly, which
    must cover the longest state delay.  Inputs before the first time point
    are zero.  The response is marched at two collocation degrees and a
    warning reports a difference above ``max(rtol, 1e-10)`` times the
    largest output.

    Examples
    --------
    ``ẋ = -x(t - 1)`` from the constant history 1 (method of steps:
    ``x(t) = 1 - t`` on [0, 1], ``x(2) = -1/2``):

    >>> sys = ltp.ltpdss([[0.0]], [[0.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[-1.0]])])
    >>> t = np.linspace(0, 2, 9)
    >>> r = ltp.forced_response(sys, t, 0.0, 1.0, history=lambda s: [1.0])
    >>> float(r.outputs[-1].round(12))
    -0.5
    """
    check_kwargs(kwargs, 'forced_response')
    t, u, ntr, x0 = forced_arguments(sys, timepts, inputs, initial_state, method,
                                     ('transition', 'collocation'), input_hold, rtol)
    taus = [a for a, _ in sys.state_delays]
    hist = _check_history(history, t[0], max(taus) if taus else 0.0)
    x, y = _simulate(sys, t, u, x0, hist, input_hold, _ORDER)
    _, y2 = _simulate(sys, t, u, x0, hist, input_hold, _ORDER + 4)
    err = float(np.max(np.abs(y - y2), initial=0.0))
    big = max(float(np.max(np.abs(y2), initial=0.0)), 1e-300)
    if err > max(rtol, 1e-10) * big:
        warnings.warn(f"forced_response: the response of the system with delays is "
                      f"accurate to about {err / big:.1e} (relative)", UserWarning,
                      stacklevel=3)
    y = y2
    return forced_result(sys, t, x if compute_states else None, y, u, inputs, transpose,
                         return_states, squeeze)


@override('initial_response', LTPDelayStateSpace)
def initial_response(sys, timepts=None, initial_state=0.0, output_indices=None, *,
                     method='transition', input_hold='foh', rtol=1e-12,
                     return_states=False, squeeze=None, transpose=False, history=None,
                     **kwargs):
    """`ltpcontrol.initial_response` of a system with delays, from a history.

    Examples
    --------
    >>> sys = ltp.ltpdss([[0.0]], [[0.0]], [[1.0]], 0, period=1.0, delays=[(1.0, [[-1.0]])])
    >>> r = ltp.initial_response(sys, np.linspace(0, 1, 5), 1.0, history=lambda s: [1.0])
    >>> r.outputs.round(12) + 0.0
    array([1.  , 0.75, 0.5 , 0.25, 0.  ])
    """
    resp = forced_response(sys, timepts, 0.0, initial_state, method=method,
                           input_hold=input_hold, rtol=rtol, return_states=return_states,
                           squeeze=squeeze, transpose=transpose, history=history, **kwargs)
    if output_indices is None:
        return resp
    outs = np.atleast_1d(np.arange(sys.noutputs)[output_indices])
    y = np.asarray(resp.outputs).reshape(sys.noutputs, -1)[outs]
    return ct.TimeResponseData(resp.time, y if len(outs) > 1 else y[0], resp.states,
                               None, issiso=len(outs) == 1,
                               output_labels=[sys.output_labels[i] for i in outs],
                               state_labels=sys.state_labels, sysname=sys.name,
                               title="Initial response for " + sys.name,
                               return_x=return_states, squeeze=squeeze)
