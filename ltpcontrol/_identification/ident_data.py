"""The data of `identify_ltp`: the records' design and input hold, the lifted
response with its noise level, and their checks."""

import warnings

import numpy as np
import control as ct
from control.exception import ControlArgument

from .._frequency.htf import HTF
from .holdout import _data_variance
from .lifted_response import _hold_factor, _lifted_records, lifted_frequency_response
from .records import as_records, refuse_ambiguous
from .._core.validation import steps_per_period

#: relative change of the data between a zero- and a first-order hold above which
#: input_hold='auto' warns that the assumed hold matters
_HOLD_EFFECT = 0.01


def _from_excitation(exc, frequencies, transient):
    """The `frequencies` and `transient` of the design `exc` (where not given)."""
    if not (hasattr(exc, 'segments') and hasattr(exc, 'time') and hasattr(exc, 'inputs')):
        raise ControlArgument(f"excitation must be an Excitation (sine_experiments, "
                              f"multisine), got {type(exc).__name__}")
    segments = np.asarray(exc.segments)
    if segments.shape[0] != 1 or exc.frequencies is None:
        raise ValueError("excitation: identify_ltp takes sine or multisine experiments with "
                         "one analysis window; for chirp replicas estimate the HTF "
                         "(estimate_htf(..., segments=exc.segments)) and identify from it")
    time = np.asarray(exc.time, float)
    if transient is None:
        transient = float(time[segments[0, 0]] - time[0]) if segments[0, 0] < time.size \
            else 0.0
    if frequencies is None:
        inputs = np.asarray(exc.inputs)
        nexp = 1 if inputs.ndim == 1 else inputs.shape[-2]
        lines = np.asarray(exc.frequencies, float)
        # one line per experiment (sine_experiments), or every line in each (multisine)
        frequencies = lines if lines.size == nexp else np.broadcast_to(lines, (nexp, lines.size))
    return frequencies, transient


def _assumed_hold(data, input_hold, hold_step):
    """The input hold of time records: `input_hold`, or 'foh' for 'auto' with a
    warning when a zero-order hold would change the data by more than _HOLD_EFFECT."""
    if input_hold != 'auto':
        return input_hold
    refuse_ambiguous(data, 'data', 'identify_ltp')
    effect, wmax = _hold_effect(as_records(data, 'data'), hold_step)
    if effect > _HOLD_EFFECT:
        warnings.warn(f"input_hold not given: the records are taken as held by first-order "
                      f"interpolation ('foh', as forced_response applies inputs); a "
                      f"zero-order hold would change the data by up to {effect:.2g} (at "
                      f"{wmax:.3g} rad/s), which the model cannot tell apart from the "
                      "plant: give input_hold='zoh' for inputs held between samples or "
                      "None for samples of a continuous input", UserWarning, stacklevel=4)
    return 'foh'


def _hold_effect(records, hold_step):
    """``(|1 - h_zoh/h_foh|, ω)`` at the highest input frequency ω of the records
    (DFT bins within 1e-3 of the largest)."""
    wmax = 0.0
    for rec in records:
        spec = np.abs(np.fft.rfft(rec.u, axis=-1)).max(axis=0)
        spec[0] = 0.0
        band = np.flatnonzero(spec >= 1e-3 * spec.max()) if spec.max() > 0 else []
        if len(band):
            wmax = max(wmax, band.max() * 2 * np.pi / (rec.u.shape[-1] * rec.dt))
    step = records[0].dt if hold_step is None else hold_step
    w = np.array([wmax])
    return float(np.abs(1 - _hold_factor(w, step, 'zoh')[0] / _hold_factor(w, step, 'foh')[0])), wmax


def _lifted_data(data, period, Kd, progress, options, K=0, std=None):
    """Step 1: the real lifted response, given or computed from time records (with
    the harmonics -Kd..Kd, at most (N-1)/2; from an HTF at least K), and the noise
    variance of its entries ``(M, rows, inputs)`` (from `std` for lifted data, estimated
    for time records, None when unknown)."""
    given = {key: val for key, val in options.items() if val is not None}
    if isinstance(data, (ct.FrequencyResponseData, HTF)):
        if given:
            raise TypeError(f"identify_ltp: {sorted(given)} only apply to time "
                            "records, not to frequency-response data")
        if isinstance(data, HTF):
            if std is not None:
                raise TypeError("identify_ltp: std applies to lifted frequency-response "
                                "data; an HTF carries its own std")
            # the most harmonics known together at some frequencies (band-limited
            # chirps know few); the ML refinement fits all components of the HTF
            for k in range(min(Kd, data.nharmonics), K, -1):
                try:
                    return lifted_frequency_response(data, period, k), None, None
                except ValueError:
                    continue
            return lifted_frequency_response(data, period, K), None, None
        if std is None:
            # lifted from records: the noise level of lifted_frequency_response
            std = getattr(data, 'noise_std', None)
            if std is not None and np.shape(std) != data.frdata.shape:
                std = None
        return data, None if std is None else _data_variance(std, data), None
    if std is not None:
        raise TypeError("identify_ltp: std applies to lifted frequency-response data; "
                        "the noise of time records is estimated from them")
    # time records: parsed once here, so that errors name this function's argument
    refuse_ambiguous(data, 'data', 'identify_ltp')
    dt = as_records(data, 'data')[0].dt
    Kd = min(Kd, (int(round(period / dt)) - 1) // 2)
    return _lifted_records(data, period, Kd, progress=progress, unusable='skip', **given)


def _check_lifted_data(G, period, K, nstates, q):
    """Validate the lifted data; return (outputs, steps per period, data harmonics)."""
    H = 2 * K + 1
    if not G.dt or G.dt is True:
        raise ControlArgument("data must be discrete-time frequency-response data "
                              "with a numeric sampling time (from "
                              "lifted_frequency_response)")
    # the labels '<y>_c0', '<y>_c1', ... of lifted_frequency_response tell the harmonics
    ny = sum(1 for lab in G.output_labels if lab.endswith('_c0'))
    if not (ny and G.noutputs % ny == 0 and (G.noutputs // ny) % 2 == 1
            and G.noutputs // ny >= H):
        if G.noutputs % H:
            raise ValueError(f"data must have (2K+1) = {H} lifted outputs per system "
                             f"output, got shape {G.frdata.shape[:2]}")
        ny = G.noutputs // H
    Kd = (G.noutputs // ny - 1) // 2
    N = steps_per_period(period, float(G.dt), 'the sampling time of data')
    order, M = H * nstates, G.omega.size
    # fdsubspace needs 2M >= q + order with q > order: at least order + 1 lines.
    if not _enough_lines(M, K, nstates, q):
        raise ValueError(
            f"too few frequencies: {M} lines for the lifted order (2K+1)*nstates = "
            f"{order}{'' if q is None else f' and q={q}'}; need at least "
            f"{order + 1 if q is None else -(-(q + order) // 2)} distinct lines")
    return ny, N, Kd


def _enough_lines(M, K, nstates, q):
    """The subspace step of order (2K+1) n_p with `q` block rows can use M lines."""
    order = (2 * K + 1) * nstates
    return 2 * M >= 2 * order + 1 and (q is None or 2 * M >= q + order)
