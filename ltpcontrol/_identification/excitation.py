"""Input signals for identifying harmonic transfer functions from data.

Three experiment designs are provided:

* `chirp_replicas`: phase-shifted replicas of one linear chirp, concatenated
  in a single input (thesis eqs. 3.40, 3.48, 3.57-3.58).  Replica ``r`` is
  started ``r T/R`` later in the cycle than replica 0, so that with
  ``R >= 2K+1`` replicas the extended power spectrum ``Φ_UU`` is diagonal and
  every HTF component up to order K is identifiable at each frequency.
* `multisine`: periodic multisines on the DFT grid of an integer number of
  periods, with ``R`` experiments time-shifted by ``T/R`` (same property).
* `sine_experiments`: single sinusoids, one per experiment, for validation
  (thesis §3.7.4) or sine-by-sine identification.

With ``ninputs = m`` the sinusoidal designs excite m inputs jointly: every
line is applied in m experiments ``i = 0..m-1`` with input j phase-shifted by
``2π i j / m``, so that the input phasors of a line form the unitary DFT
matrix and `lifted_frequency_response` separates the inputs by least squares
at every line (as in LTI MIMO frequency-response measurement).

Every design returns the analysis windows (``segments``) of an integer number
of periods that `estimate_htf` expects.  Frequencies at multiples of
``ω_p/2`` are flagged: there an input at ``ω`` and its mirror ``-ω`` produce
output at the same frequencies, and neighbouring components cannot be
separated with sinusoidal inputs.
"""

import numbers
import warnings
from typing import Callable, NamedTuple

import numpy as np
from control.exception import ControlArgument

from .._core.validation import (check_period, check_positive, check_positive_int,
                          real_array, steps_per_period)

__all__ = ['chirp_replicas', 'multisine', 'sine_experiments', 'Excitation']


class Excitation(NamedTuple):
    """Sampled excitation returned by the experiment design functions.

    Attributes
    ----------
    time : ndarray, shape (nt,)
        Sample times, starting at 0 (the phase reference of the period).
    inputs : ndarray, shape (ninputs, nexp, nt), or (nt,) for chirp replicas
        Input samples in the one axis order of the library: channels,
        experiments, time, as `ltpcontrol.forced_response` and the
        identification functions take them (``ninputs`` is 1 unless given).
        `chirp_replicas` is one record of one input: shape (nt,).  (A single
        input used to give (nexp, nt): ``exc.inputs[0]`` is that array.)
    segments : ndarray of int, shape (nseg, 2)
        ``[start, stop)`` sample indices of the analysis windows, each an
        integer number of periods long.  Pass them to `estimate_htf`.
    signal : callable
        ``signal(t)`` evaluates the continuous-time input (shape like
        `inputs` with the time axis replaced by the shape of ``t``, none
        for a scalar ``t``); use it with variable-step simulators.
    frequencies : ndarray or None
        Excited frequencies in rad/s for sinusoidal designs (for
        `sine_experiments`, the line of every experiment), else None.

    Examples
    --------
    >>> t, u, segments, signal, _ = ltp.chirp_replicas(1.0, 3, 2.0, 0.0, 5.0, dt=0.01)
    >>> segments.shape, bool(np.allclose(signal(t), u))
    ((3, 2), True)
    """

    time: np.ndarray
    inputs: np.ndarray
    segments: np.ndarray
    signal: Callable
    frequencies: np.ndarray = None


def _check_dt(dt, period):
    dt = check_positive(dt, "dt")
    return dt, steps_per_period(period, dt, "dt")


def _check_frequency(value, name, allow_zero=True):
    value = real_array(value, name, ndim=0)
    value = float(value)
    if value < 0 or (value == 0 and not allow_zero):
        raise ValueError(f"{name} must be {'>=' if allow_zero else '>'} 0, got {value}")
    return value


def _warn_half_multiples(omega, period, tol, what):
    """Warn when any of `omega` lies within `tol` of a multiple of ω_p/2."""
    half = np.pi / period                     # ω_p / 2
    q = omega / half
    bad = np.abs(q - np.round(q)) * half <= tol
    if np.any(bad):
        warnings.warn(
            f"{what} {np.round(omega[bad], 6).tolist()} rad/s are multiples of "
            f"omega_p/2 = {half:.6g} rad/s: the responses to +omega and -omega "
            "fall on the same output frequencies there and adjacent HTF "
            "components cannot be separated", UserWarning, stacklevel=3)
    return bad


def _replicas(nreplicas, nharmonics, plant_harmonics, what):
    """Number R of time-shifted replicas; warn when components alias.

    Replica r shifts the cycle phase by r T/R, which multiplies the HTF
    component ``G_k`` by ``e^{-j2πkr/R}``: components whose indices differ
    by a multiple of R cannot be separated.  Components ``|k| <= K`` are
    free of the plant's harmonics ``|k'| <= K_p`` when ``R >= K + K_p + 1``.
    """
    K = None if nharmonics is None else check_positive_int(nharmonics, "nharmonics",
                                                          minimum=0)
    Kp = None if plant_harmonics is None else check_positive_int(
        plant_harmonics, "plant_harmonics", minimum=0)
    if nreplicas is None:
        if K is None:
            raise ValueError(f"{what}: give the number of replicas or nharmonics")
        Kp = 2 * K if Kp is None else max(Kp, K)
        return K + Kp + 1
    R = check_positive_int(nreplicas, what)
    if K is not None:
        Kp = K if Kp is None else max(Kp, K)
        aliased = sorted({k for k in range(-K, K + 1) for kk in range(-Kp, Kp + 1)
                          if kk != k and (kk - k) % R == 0})
        if aliased:
            warnings.warn(f"{what}={R} leaves the HTF components {aliased} aliased with "
                          f"plant harmonics up to {Kp}; use at least {K + Kp + 1}",
                          UserWarning, stacklevel=3)
    return R


def chirp_replicas(period, nreplicas, duration, f0, f1, *, dt,
                   amplitude=1.0, gap=0.0, nharmonics=None, plant_harmonics=None):
    """Phase-shifted replicas of a linear chirp for HTF identification.

    Replica ``r = 0..R-1`` occupies its own record window
    ``[r L T, (r+1) L T)`` of ``L`` whole periods and is the chirp

    ``c(τ) = amplitude · sin(2π (f0 τ + (f1 - f0) τ² / (2 D)))``, ``0 <= τ < D``

    started at ``t = r L T + r T / R``, i.e. shifted by ``T/R`` in the cycle
    phase relative to the previous replica (thesis eqs. 3.48, 3.57-3.58).
    Each record ends with at least `gap` seconds of zero input, so that the
    response settles before the next replica starts; L is the smallest
    integer with ``L T >= (R-1) T / R + D + gap``.

    Parameters
    ----------
    period : float
        Period T of the system (s).
    nreplicas : int or None
        Number R of replicas; ``R >= 2K+1`` identifies K harmonics of a
        plant without further harmonics, ``R >= K + K_p + 1`` keeps the
        plant's harmonics up to ``K_p`` from aliasing into them.  None:
        ``K + K_p + 1`` from `nharmonics` and `plant_harmonics`.
    duration : float
        Chirp duration D (s).
    f0, f1 : float
        Start and end frequencies of the sweep (Hz), ``0 <= f0 < f1``; f1
        must be below the Nyquist frequency ``1/(2 dt)``.
    dt : float
        Sample time; ``period/dt`` must be an integer.
    amplitude : float, optional
        Chirp amplitude (default 1).
    gap : float, optional
        Minimum quiet time after each chirp (s, default 0).  Choose several
        settling times of the system for leakage-free estimates.
    nharmonics : int, optional
        Harmonics K to be estimated.  With it, a warning names the
        components that `nreplicas` leaves aliased.
    plant_harmonics : int, optional
        Harmonics ``K_p`` the plant's HTF is expected to hold (default
        ``2K`` when `nreplicas` is None, else K).

    Returns
    -------
    Excitation
        ``(time, inputs, segments, signal, frequencies)``; ``inputs`` has
        shape (nt,), ``segments`` (R, 2) holds the record windows.

    Notes
    -----
    The instantaneous frequency is ``f0 + (f1 - f0) τ / D``.  Eq. 3.48 of the
    thesis follows this form; eqs. 3.40 and 3.57 as printed sweep to twice
    the stated end frequency.  When ``T / (R dt)`` is an integer the sampled
    replicas are exact delayed copies of each other, which makes the sampled
    ``Φ_UU`` exactly diagonal; otherwise the decoupling holds up to the
    aliasing of the chirp's switching edges.

    Examples
    --------
    >>> exc = ltp.chirp_replicas(1.0, 3, 4.0, 0.0, 2.0, dt=0.01, gap=1.0)
    >>> exc.segments.tolist()
    [[0, 600], [600, 1200], [1200, 1800]]
    >>> exc.time.shape, exc.inputs.shape
    ((1800,), (1800,))
    >>> float(np.round(exc.signal(np.array([600 * 0.01 + 1 / 3]))[0], 12))
    0.0
    """
    period = check_period(period)
    nrep = _replicas(nreplicas, nharmonics, plant_harmonics, "nreplicas")
    duration = check_positive(duration, "duration")
    dt, nper = _check_dt(dt, period)
    f0 = _check_frequency(f0, "f0")
    f1 = _check_frequency(f1, "f1", allow_zero=False)
    if f1 <= f0:
        raise ValueError(f"f1 must exceed f0, got f0={f0}, f1={f1}")
    if f1 >= 0.5 / dt:
        raise ValueError(f"f1={f1} Hz is not below the Nyquist frequency "
                         f"{0.5 / dt} Hz of dt={dt}")
    amplitude = float(real_array(amplitude, "amplitude", ndim=0))
    gap = float(real_array(gap, "gap", ndim=0))
    if gap < 0:
        raise ValueError(f"gap must be >= 0, got {gap}")

    # record length: L whole periods holding shift + chirp + gap
    need = (nrep - 1) * period / nrep + duration + gap
    nrec = int(np.ceil(need / period - 1e-9))
    length = nrec * period
    starts = np.arange(nrep) * (length + period / nrep)   # r L T + r T/R
    sweep = (f1 - f0) / (2 * duration)

    def signal(t):
        t = np.asarray(t, dtype=float)
        # replica index from the record window, local chirp time τ
        r = np.clip(np.floor(t / length).astype(int), 0, nrep - 1)
        tau = t - starts[r]
        on = (tau >= 0) & (tau < duration) & (t >= 0) & (t < nrep * length)
        return np.where(on, amplitude * np.sin(2 * np.pi * (f0 + sweep * tau) * tau), 0.0)

    nsamp = nrec * nper
    time = np.arange(nrep * nsamp) * dt
    segments = np.column_stack([np.arange(nrep) * nsamp,
                                np.arange(1, nrep + 1) * nsamp])
    return Excitation(time, signal(time), segments, signal, None)


def _grid_frequencies(frequencies, window, name):
    """Snap frequencies (rad/s) to the DFT grid 2π i / window; return (omega, bins)."""
    omega = real_array(frequencies, name, ndim=(0, 1)).ravel()
    if omega.size == 0:
        raise ValueError(f"{name} must not be empty")
    if np.any(omega <= 0):
        raise ValueError(f"{name} must be positive (rad/s)")
    step = 2 * np.pi / window
    bins = np.round(omega / step).astype(int)
    if np.any(bins < 1):
        raise ValueError(f"{name} below the frequency resolution {step:.6g} rad/s "
                         "of the window; increase nperiods")
    bins = np.unique(bins)
    return bins * step, bins


#: samples x experiments up to which a sum-of-cosines signal is evaluated for all
#: lines at once (larger requests line by line, memory samples x experiments)
_BATCH = 64


def _periodic_design(omega, period, dt, nperiods, settle, nexp, phases, amplitude, what,
                     shifts=None):
    """Sum-of-cosines experiments; experiment r is delayed by r T / nexp (jointly
    on several inputs with `shifts`, see `_joint`)."""
    nper = steps_per_period(period, dt, "dt")
    if np.max(omega) >= np.pi / dt:
        raise ValueError(f"{what} reach the Nyquist frequency {np.pi / dt:.6g} rad/s "
                         f"of dt={dt}")
    _warn_half_multiples(omega, period, 1e-9 * np.max(omega), what)
    delays = np.arange(nexp) * period / nexp
    # broadcast views made once: a variable-step simulator calls `single` per step
    delay_col, omega3, phases3 = delays[:, None], omega[:, None, None], phases[:, None, None]
    omega2, phases2 = omega[:, None], phases[:, None]

    def single(t, shift=0.0):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        # u_r(t) = Σ_l a cos(ω_l (t - τ_r) + φ_l + shift), accumulated line by
        # line so that memory stays (experiments x samples)
        if t.size == 1:
            # one instant (what a variable-step simulator asks for): the same
            # operations on (lines, experiments), the lines added in sequence
            # as below, without the broadcasting and cumsum overhead
            terms = np.cos(omega2 * (t[0] - delays) + phases2 + shift)
            if nexp == 1:
                total = 0.0
                for term in terms.ravel().tolist():
                    total += term
                return np.array([[amplitude * total]])
            return amplitude * terms.cumsum(axis=0)[-1][:, None]
        shifted = t[None, :] - delay_col
        if shifted.size <= _BATCH:
            # few samples (a variable-step simulator asks for one at a time):
            # all lines at once, summed in the order of the loop below (cumsum
            # adds in sequence, so both paths give the same bits)
            arg = omega3 * shifted + phases3 + shift
            return amplitude * np.cumsum(np.cos(arg), axis=0)[-1]
        out = np.zeros(shifted.shape)
        for w, phi in zip(omega, phases):
            out += np.cos(w * shifted + phi + shift)
        return amplitude * out

    signal = _scalar_time(_one_input(single) if shifts is None else _joint(single, shifts))
    nsamp = (settle + nperiods) * nper
    time = np.arange(nsamp) * dt
    segments = np.array([[settle * nper, nsamp]])
    return time, signal, segments


def _scalar_time(signal):
    """`signal` (time last) that also takes a scalar time, giving its value there
    (for variable-step simulators)."""
    def wrapped(t):
        t = np.asarray(t, dtype=float)
        out = signal(t.reshape(-1))
        return out[..., 0] if t.ndim == 0 else out.reshape(out.shape[:-1] + t.shape)
    return wrapped


def _separable(bins, nperiods):
    """The bins of `bins` (in order) whose output harmonics ``±l + m P`` do not meet
    those of an earlier kept bin (P = `nperiods` bins per ω_p): one experiment then
    gives the lifted response at every line (`lifted_frequency_response`).

    >>> _separable(np.array([1, 3, 5, 7]), 4).tolist()
    [1]
    >>> _separable(np.array([b for b in range(1, 20) if b % 5]), 10).tolist()
    [1, 2, 3, 4]
    """
    used, kept = {0}, []                       # residue 0: a periodic operating point
    for b in bins:
        res = {int(b) % nperiods, int(-b) % nperiods}
        if not res & used:
            used |= res
            kept.append(b)
    return np.asarray(kept, dtype=bins.dtype)


def _check_seed(seed, name="seed"):
    """Return a numpy Generator from `seed` (None, a non-negative int or a Generator)."""
    if seed is None or isinstance(seed, (np.random.Generator, np.random.BitGenerator,
                                         np.random.SeedSequence)):
        return np.random.default_rng(seed)
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (numbers.Integral,
                                                                   np.integer)):
        raise ControlArgument(f"{name} must be None, a non-negative int or a "
                              f"numpy.random.Generator, got {seed!r}")
    if seed < 0:
        raise ValueError(f"{name} must be a non-negative int, got {seed}")
    return np.random.default_rng(int(seed))


def _check_common(period, dt, nperiods, settle):
    period = check_period(period)
    dt = check_positive(dt, "dt")
    nperiods = check_positive_int(nperiods, "nperiods")
    settle = check_positive_int(settle, "settle", minimum=0)
    return period, dt, nperiods, settle


def _input_phases(ninputs):
    """Phase shifts ``2π i j / m`` (experiments i, inputs j), or None for one input."""
    if ninputs is None:
        return None
    m = check_positive_int(ninputs, "ninputs")
    return 2 * np.pi * np.outer(np.arange(m), np.arange(m)) / m


def _one_input(signal):
    """`signal(t)` of shape (nexp, len(t)) as one input channel: (1, nexp, len(t))."""
    return lambda t: signal(t)[None]


def _joint(signal, shifts):
    """Signal of m jointly excited inputs: experiment (e, i), input j gets the
    experiment e of `signal` with its phases shifted by ``shifts[i, j]``.

    `signal(t, phase)` returns (nexp, len(t)); the result has shape
    (m, nexp m, len(t)), experiments ordered e-major.
    """
    def joint(t):
        t = np.asarray(t, dtype=float)
        m = shifts.shape[0]
        out = np.stack([np.stack([signal(t, shifts[i, j]) for i in range(m)], axis=1)
                        for j in range(m)])                     # (m, nexp, m, nt)
        return out.reshape(m, -1, t.size)
    return joint


def sine_experiments(frequencies, period, *, dt, nperiods, settle=0,
                     amplitude=1.0, unusable='warn', ninputs=None):
    """One sinusoid per experiment, on the DFT grid of the analysis window.

    Experiment ``e`` is ``amplitude · cos(ω_e t)`` for
    ``(settle + nperiods)`` periods; the analysis window is the last
    `nperiods` periods.  Each ``ω_e`` is rounded to the nearest multiple of
    ``2π / (nperiods T)`` so that the window holds whole periods of both the
    system and the input (leakage-free steady state).  Frequencies at
    multiples of ``ω_p/2`` cannot identify neighbouring HTF components;
    they are kept with a warning or dropped (`unusable`).

    Parameters
    ----------
    frequencies : array_like
        Requested frequencies (rad/s), positive.
    period : float
        System period T (s).
    dt : float
        Sample time; ``period/dt`` must be an integer.
    nperiods : int
        Number of periods in the analysis window.
    settle : int, optional
        Periods simulated before the window to let transients decay.
    amplitude : float, optional
        Amplitude of each sinusoid.
    unusable : {'warn', 'drop'}, optional
        Keep frequencies at multiples of ``ω_p/2`` with a UserWarning
        (default) or drop them (also with a warning).
    ninputs : int, optional
        Number m of inputs excited jointly: every frequency is applied in m
        experiments, experiment i giving input j the phase ``2π i j / m``
        (module notes).  Default: a single input.

    Returns
    -------
    Excitation
        ``inputs`` has shape (1, nexp, nt), or (m, m nexp, nt) with
        `ninputs` (experiments frequency-major); ``frequencies`` holds the
        rounded frequency of every experiment (duplicates after rounding
        are removed).

    Examples
    --------
    >>> exc = ltp.sine_experiments([1.3, 2.2], 2 * np.pi, dt=np.pi / 50,
    ...                            nperiods=4, settle=2)
    >>> exc.frequencies.tolist(), exc.inputs.shape, exc.segments.tolist()
    ([1.25, 2.25], (1, 2, 600), [[200, 600]])
    """
    period, dt, nperiods, settle = _check_common(period, dt, nperiods, settle)
    amplitude = float(real_array(amplitude, "amplitude", ndim=0))
    omega, _ = _grid_frequencies(frequencies, nperiods * period, "frequencies")
    nper = steps_per_period(period, dt, "dt")
    if np.max(omega) >= np.pi / dt:
        raise ValueError(f"frequencies reach the Nyquist frequency {np.pi / dt:.6g} "
                         f"rad/s of dt={dt}")
    if unusable not in ('warn', 'drop'):
        raise ValueError(f"unusable must be 'warn' or 'drop', got {unusable!r}")
    bad = _warn_half_multiples(omega, period, 1e-9 * np.max(omega), "frequencies")
    if unusable == 'drop' and bad.any():
        omega = omega[~bad]
        warnings.warn(f"dropped {int(bad.sum())} frequencies at multiples of omega_p/2",
                      UserWarning, stacklevel=2)
        if omega.size == 0:
            raise ValueError("no frequency is left after dropping the multiples of "
                             "omega_p/2")

    def single(t, shift=0.0):
        t = np.asarray(t, dtype=float)
        return amplitude * np.cos(omega[:, None] * t[None, :] + shift)

    shifts = _input_phases(ninputs)
    signal = _scalar_time(_one_input(single) if shifts is None else _joint(single, shifts))
    lines = omega if shifts is None else np.repeat(omega, shifts.shape[0])
    time = np.arange((settle + nperiods) * nper) * dt
    segments = np.array([[settle * nper, time.size]])
    return Excitation(time, signal(time), segments, signal, lines)


def multisine(frequencies, period, *, dt, nperiods, nexperiments=None, settle=0,
              amplitude=1.0, phases='schroeder', seed=None, nharmonics=None,
              plant_harmonics=None, ninputs=None):
    """Multisine experiments time-shifted by fractions of the period.

    All experiments share the multisine
    ``s(t) = amplitude · Σ_l cos(ω_l t + φ_l)`` with lines ``ω_l`` on the DFT
    grid ``2π i / (nperiods T)``; experiment ``r`` applies ``s(t - r T/R)``
    with ``R = nexperiments``.  With ``R >= 2K+1`` the extended power
    spectrum is diagonal wherever the lines are dense (as for
    `chirp_replicas`).

    Parameters
    ----------
    frequencies : array_like or tuple
        Line frequencies (rad/s), or ``('band', w0, w1)`` for every grid line
        in ``[w0, w1]`` except multiples of ``ω_p/2``.  With one experiment
        (the default `nexperiments`), only the lines whose output harmonics
        ``Ω + nω_p`` do not meet those of a lower line are kept (at most
        `nperiods`/2 lines), so that `lifted_frequency_response` and
        `identify_ltp` can separate them; several time-shifted experiments
        (for `estimate_htf`) keep every line.
    period : float
        System period T (s).
    dt : float
        Sample time; ``period/dt`` must be an integer.
    nperiods : int
        Number of periods in the analysis window.
    nexperiments : int, optional
        Number R of time-shifted experiments.  Default: ``K + K_p + 1``
        when `nharmonics` is given (see `chirp_replicas`), else 1.
    settle : int, optional
        Periods applied before the window to reach steady state.
    amplitude : float, optional
        Amplitude of each line.
    phases : {'schroeder', 'random'} or array_like, optional
        Line phases: Schroeder's low-crest-factor phases
        ``φ_l = -π l (l - 1) / F``, uniform random phases, or given values.
    seed : int or numpy.random.Generator, optional
        Random source for ``phases='random'``: None (fresh entropy), a
        non-negative int, or a `numpy.random.Generator` (a `BitGenerator`
        or `SeedSequence` is accepted as well).
    nharmonics, plant_harmonics : int, optional
        Harmonics K to be estimated and ``K_p`` expected in the plant, as
        for `chirp_replicas`: they set the default `nexperiments` and a
        warning names the components a given `nexperiments` leaves aliased.
    ninputs : int, optional
        Number m of inputs excited jointly: every experiment is repeated m
        times, repetition i giving input j the line phases ``φ_l + 2π i j /
        m`` (module notes).  Default: a single input.

    Returns
    -------
    Excitation
        ``inputs`` has shape (1, R, nt), or (m, m R, nt) with `ninputs`
        (experiments shift-major); ``frequencies`` holds the lines.

    Examples
    --------
    >>> exc = ltp.multisine(('band', 0.5, 1.5), 2 * np.pi, dt=np.pi / 20,
    ...                     nperiods=4, nexperiments=3)
    >>> exc.frequencies.tolist()           # multiples of ω_p/2 = 0.5 skipped
    [0.75, 1.25]
    >>> exc.inputs.shape                   # (inputs, experiments, samples)
    (1, 3, 160)
    """
    period, dt, nperiods, settle = _check_common(period, dt, nperiods, settle)
    nexp = _replicas(1 if nexperiments is None and nharmonics is None else nexperiments,
                     nharmonics, plant_harmonics, "nexperiments")
    amplitude = float(real_array(amplitude, "amplitude", ndim=0))
    rng = _check_seed(seed)
    window = nperiods * period
    if isinstance(frequencies, tuple) and len(frequencies) == 3 \
            and isinstance(frequencies[0], str):
        if frequencies[0] != 'band':
            raise ValueError(f"frequencies: unknown specification {frequencies[0]!r}")
        w0 = _check_frequency(frequencies[1], "frequencies[1]")
        w1 = _check_frequency(frequencies[2], "frequencies[2]", allow_zero=False)
        step = 2 * np.pi / window
        bins = np.arange(max(1, int(np.ceil(w0 / step - 1e-9))),
                         int(np.floor(w1 / step + 1e-9)) + 1)
        # drop lines at multiples of ω_p/2 (every nperiods/2 bins)
        keep = (2 * bins) % nperiods != 0
        bins = bins[keep]
        if nexp == 1:
            bins = _separable(bins, nperiods)
        if bins.size == 0:
            raise ValueError(f"frequencies: no grid line in [{w0}, {w1}] rad/s "
                             f"(resolution {step:.6g} rad/s)")
        omega = bins * step
    else:
        omega, bins = _grid_frequencies(frequencies, window, "frequencies")
    nline = omega.size
    if isinstance(phases, str):
        if phases == 'schroeder':
            ell = np.arange(1, nline + 1)
            phi = -np.pi * ell * (ell - 1) / nline
        elif phases == 'random':
            phi = rng.uniform(0, 2 * np.pi, nline)
        else:
            raise ValueError(f"phases must be 'schroeder', 'random' or an array, "
                             f"got {phases!r}")
    else:
        phi = real_array(phases, "phases", ndim=1)
        if phi.size != nline:
            raise ValueError(f"phases has {phi.size} entries for {nline} lines")
    time, signal, segments = _periodic_design(
        omega, period, dt, nperiods, settle, nexp, phi, amplitude, "frequencies",
        _input_phases(ninputs))
    return Excitation(time, signal(time), segments, signal, omega)
