"""Validation of an identified LTP model on time records (fresh or held out).

The prediction question users ask of a model is how well it reproduces a
record it has not seen: `validate_ltp` simulates the model on the records'
inputs (`ltpcontrol.forced_response`, from rest, with the records' input
hold) and reports the normalized RMS error of its output after a
transient.  The hold is part of the records, not of the model: the same
samples held constant (ZOH) or interpolated linearly (FOH) are different
inputs, and a model identified under the wrong assumption carries a
half-step delay it does not have.  With ``input_hold='check'`` both holds
are simulated and the better one reported.
"""

import warnings
from dataclasses import dataclass

import numpy as np

from .._core.ltpsys import LTPStateSpace
from .._core.timeresp import forced_response
from .._core.validation import real_array
from .records import as_records, refuse_ambiguous

__all__ = ['validate_ltp', 'LTPValidation']

_HOLDS = ('foh', 'zoh', 'check')
#: an input hold that predicts this many times better than the given one is reported
_HOLD_RATIO = 2.0


@dataclass(frozen=True)
class LTPValidation:
    """Result of `validate_ltp`.

    Attributes
    ----------
    nrmse : float
        ``‖ŷ - y‖ / ‖y‖`` over all records, outputs and samples after the
        transient (ŷ the model's simulated output).
    record_nrmse : ndarray
        The same for every record (trace), in the order of the data.
    input_hold : str
        The input hold of the simulation ('foh' or 'zoh').
    hold_nrmse : dict
        ``nrmse`` for every hold simulated.
    outputs : list of ndarray
        The simulated outputs ``(ny, L)`` of every record.

    Examples
    --------
    >>> LTPValidation(0.1, np.array([0.1]), 'foh', {'foh': 0.1}, []).nrmse
    0.1
    """

    nrmse: float
    record_nrmse: np.ndarray
    input_hold: str
    hold_nrmse: dict
    outputs: list


def validate_ltp(model, data, *, transient=0.0, input_hold='foh'):
    """Normalized RMS error of a model's simulated output on time records.

    Parameters
    ----------
    model : LTPStateSpace
        Continuous-time model (e.g. of `identify_ltp`), period T; the
        records' ``t = 0`` is the phase reference of its period.
    data : control.TimeResponseData, tuple or list
        Records, as `identify_ltp` takes them: ``(t, u, y)`` with ``u`` of
        shape ``(nu, L)`` or ``(nu, nexp, L)``, a `control.TimeResponseData`
        (each trace a record) or a list of those.  Records from a plant at
        rest at their start (or give a `transient`).
    transient : float, optional
        Time (s) at the start of every record left out of the error (the
        model is simulated from rest; default 0).
    input_hold : {'foh', 'zoh', 'check'}, optional
        How the recorded input samples were applied to the plant: 'foh'
        (default, the hold of `ltpcontrol.forced_response`), 'zoh', or
        'check': both are simulated and the one with the smaller error is
        reported.  With 'foh' or 'zoh' the other hold is simulated as well
        and a warning is given if it predicts more than twice as well.

    Returns
    -------
    LTPValidation

    Raises
    ------
    ControlArgument
        If `model` is not a continuous-time LTPStateSpace, or for data of a
        wrong type.
    ControlDimension
        If the records' channels do not match the model's.
    ValueError
        If `input_hold` is unknown, `transient` is negative or leaves no
        sample of a record.

    Warns
    -----
    UserWarning
        If the other input hold predicts the records more than twice as
        well as the given one.

    Examples
    --------
    >>> plant = ltp.ltpss([[-2.0]], lambda t: np.array([[1 + 0.5 * np.cos(4 * np.pi * t)]]),
    ...                   [[1.0]], 0, period=0.5)
    >>> t = np.arange(400) * 0.0125
    >>> u = np.random.default_rng(0).standard_normal(400)
    >>> y = ltp.forced_response(plant, t, u, input_hold='zoh').outputs
    >>> res = ltp.validate_ltp(plant, (t, u, y), input_hold='check')
    >>> res.input_hold, bool(res.nrmse < 1e-10)
    ('zoh', True)
    """
    from control.exception import ControlArgument, ControlDimension
    if not isinstance(model, LTPStateSpace) or not model.isctime():
        raise ControlArgument("model must be a continuous-time LTPStateSpace")
    if input_hold not in _HOLDS:
        raise ValueError(f"input_hold must be one of {_HOLDS}, got {input_hold!r}")
    transient = float(real_array(transient, 'transient', ndim=0))
    if not transient >= 0:
        raise ValueError(f"transient must be >= 0, got {transient}")
    refuse_ambiguous(data, 'data', 'validate_ltp')
    records = as_records(data, 'data')
    for i, rec in enumerate(records):
        if rec.u.shape[0] != model.ninputs or rec.y.shape[0] != model.noutputs:
            raise ControlDimension(
                f"data[{i}] has {rec.u.shape[0]} inputs and {rec.y.shape[0]} outputs, the "
                f"model {model.ninputs} and {model.noutputs}")
        if not np.any(rec.t - rec.t[0] >= transient - 1e-12 * rec.dt):
            raise ValueError(f"transient={transient} leaves no sample of data[{i}]")
    holds = ('foh', 'zoh')
    results = {hold: _simulate(model, records, transient, hold) for hold in holds}
    nrmse = {hold: res[0] for hold, res in results.items()}
    if input_hold == 'check':
        chosen = min(holds, key=lambda h: nrmse[h])
    else:
        chosen = input_hold
        other = 'zoh' if chosen == 'foh' else 'foh'
        if nrmse[other] * _HOLD_RATIO < nrmse[chosen]:
            warnings.warn(f"the records are predicted better with input_hold={other!r} "
                          f"(NRMSE {nrmse[other]:.3g}) than with {chosen!r} "
                          f"({nrmse[chosen]:.3g}): the input of the records was probably "
                          f"held with {other!r}", UserWarning, stacklevel=2)
    total, per, outputs = results[chosen]
    return LTPValidation(float(total), per, chosen, nrmse, outputs)


def _simulate(model, records, transient, hold):
    """``(nrmse over all, nrmse per record, simulated outputs)`` with the hold `hold`."""
    err = ref = 0.0
    per, outputs = [], []
    for rec in records:
        sim = np.asarray(forced_response(model, rec.t, rec.u,
                                         input_hold=hold).outputs).reshape(rec.y.shape)
        keep = rec.t - rec.t[0] >= transient - 1e-12 * rec.dt
        e = np.sum((sim[:, keep] - rec.y[:, keep]) ** 2)
        r = np.sum(rec.y[:, keep] ** 2)
        err, ref = err + e, ref + r
        per.append(np.sqrt(e / r) if r > 0 else np.inf)
        outputs.append(sim)
    total = np.sqrt(err / ref) if ref > 0 else np.inf
    return total, np.asarray(per), outputs
