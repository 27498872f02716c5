"""Lifted frequency response of an LTP system from sine experiments (thesis §4.2, step 1).

For a real input line ``u = a cos(Ωt + φ)`` the input coefficient is
``U(Ω) = (1/L) Σ_k u[k] e^{-jΩ t_k} = a e^{jφ}/2`` and the output holds the
harmonics ``Y_n = (1/L) Σ_k y[k] e^{-j(Ω + nω_p) t_k}`` (DFT over an integer
number of periods of the steady state), thesis eqs. 4.54-4.58, 4.74-4.79
and errata.  The lifted response to the ``U_0`` input column is ``G_n(e^{jΩTs})
= Y_n / U(Ω)``, which for a unit cosine is twice the DFT coefficient.  The
real form is ``V^H [G_{-K}; ...; G_K]`` with the unitary V of
`ltpcontrol.lift`, so the data are the frequency response of the real lifted
LTI system from its ``c0`` inputs to all its outputs.

Several inputs.  The real lifted system of m inputs has (2K+1) m inputs, but
its columns of input harmonic k follow from those of harmonic 0,
``H_{n,k}(jΩ) = H_{n-k,0}(jΩ + jkω_p)``: the data are the m ``c0`` columns.
Experiment e gives ``Y_n^{(e)}(Ω) = Σ_j G_{n,j}(Ω) U_j^{(e)}(Ω)`` at each of its
lines (no other line of the experiment reaches ``Ω + nω_p``, checked); the
experiments exciting a line give ``G_n`` by least squares (`_solve_lines`).
"""

import warnings

import numpy as np
import control as ct
from control.exception import ControlArgument, ControlDimension
from tqdm.auto import tqdm

from .._frequency.htf import HTF, HTFData
from .._core.lifting import _harmonic_labels, _real_basis
from .._core.periodic_matrix import PeriodicMatrix, as_periodic
from .noise_check import _free_bin_check
from .records import as_records, common_grid, refuse_ambiguous
from .._core.validation import (check_period, check_positive, check_positive_int,
                          real_array, steps_per_period)

__all__ = ['lifted_frequency_response']

# Input lines are DFT bins whose magnitude exceeds this fraction of the largest.
_LINE_RTOL = 1e-3
# Energy outside the detected lines (relative) above which leakage is reported.
_LEAKAGE_RTOL = 1e-8
# Smallest/largest eigenvalue of the normalised input Gram matrix of a line below
# which the experiments cannot separate the inputs (error) or separate them poorly
# (warning, condition number of the input phasors > 100).
_SEPARATION_RTOL = 1e-10
_SEPARATION_WARN = 1e-4
_HOLDS = (None, 'foh', 'zoh')
#: the advice for records whose input depends on the output
_CLOSED_LOOP = (". Closed-loop records (the input computed from the output by a "
                "controller) hold the loop's response and noise in the input: this "
                "open-loop method cannot use them; give the reference as the input "
                "(records (t, r, y) identify the closed loop from r to y), excite the "
                "plant in open loop, or, for the plant from closed-loop records, "
                "estimate the HTF from r to [y; u] (estimate_htf on (t, r, [y; u])) and "
                "take the plant from it with joint_io_htf (joint input-output)")


def lifted_frequency_response(response, period, nharmonics=None, *, frequencies=None,
                              transient=0.0, input_hold=None, hold_step=None,
                              feedthrough=None, real=True, unusable='raise', batch_size=64,
                              progress=False, name=None):
    r"""Lifted frequency response of an LTP system from sine experiments.

    Each experiment applies real sinusoids (single sines) or sums of
    sinusoids (multisines) to the inputs of an LTP system of known period
    T.  After discarding a transient, the last whole periods of every
    record are Fourier analysed at the input lines ``Ω`` and at the output
    harmonics ``Ω + nω_p``, n = -K..K.  The result is the frequency
    response of the real lifted LTI system (`ltpcontrol.lift`) from the
    ``c0`` coordinate of every input, i.e. the data of thesis eqs.
    (4.78)-(4.79).  With several inputs, every line must be excited in at
    least as many experiments as there are inputs, with input phasors that
    separate the inputs (`sine_experiments` and `multisine` with
    ``ninputs``); the response is their least-squares solution per line.

    A data HTF (`estimate_htf`, e.g. from chirps) gives the same response
    on its own grid: ``G_n(jΩ)`` is its component n at the output frequency
    ``Ω + nω_p`` (see Notes).

    Parameters
    ----------
    response : control.TimeResponseData, tuple or HTFData
        The experiments, all on one time grid: a `control.TimeResponseData`
        (a response of `ltpcontrol.forced_response` with several traces, or
        one built by hand), a tuple ``(timepts, inputs, outputs)`` with
        ``inputs`` of shape ``(ninputs, nexp, L)`` and ``outputs`` of shape
        ``(noutputs, nexp, L)`` (channels first, time last; ``(L,)`` for
        one channel and one experiment), or a list of such records.  ``timepts``
        (length L, uniform step ``Ts``) are absolute times: ``t = 0`` is
        the phase reference of the period.  Or a data HTF (`ltpcontrol.estimate_htf`); the record
        options (`frequencies`, `transient`, `input_hold`, `hold_step`,
        `batch_size`) then do not apply.
    period : float
        Period T of the system; ``N = T/Ts`` must be an integer.
    nharmonics : int, optional
        Number K of output harmonics kept (``2K+1 <= N``).  For
        `identify_ltp` with K_m harmonics at least ``3 K_m + 1``: every output
        harmonic its model produces (fewer leave the model unvalidated,
        ``success=False``).  Default: every harmonic the data hold, ``(N-1)/2``
        for records (so that `identify_ltp` fits and validates whatever its
        model produces and counts the plant's output beyond it as model
        error), for an HTF the most harmonics it knows together on its grid.
    frequencies : array_like, optional
        Input lines in rad/s, shape ``(nexp,)`` (one line per experiment)
        or ``(nexp, nlines)``.  By default the lines are the DFT bins of
        each experiment's input window whose magnitude (largest over the
        inputs) exceeds ``1e-3`` of the largest.
    transient : float, optional
        Time (s) discarded at the start of every record (default 0).  The
        analysis window is the largest integer number of periods at the
        end of the remaining record.
    input_hold : {None, 'foh', 'zoh'}, optional
        How the applied input relates to its samples.  None (default): the
        samples are those of the continuous input.  'foh'/'zoh': the input
        was interpolated linearly / held between samples (as
        `ltpcontrol.forced_response` does with ``input_hold``); the input
        coefficient is then that of the interpolated signal,
        ``U sinc²(ΩTs/2)`` or ``U sinc(ΩTs/2) e^{-jΩTs/2}``, which removes the
        hold's gain and phase from the response (its spectral images remain
        as a small error).
        The default differs from `identify_ltp`'s ``'auto'`` on purpose: this
        estimator, like `estimate_htf`, reports what the recorded samples
        say and assumes nothing about the signal between them (exact for
        the samples of a continuous input, and for a static or direct path,
        whose output samples see the input samples, as in the examples
        below), while `identify_ltp` fits and simulates a continuous-time
        plant and must decide what input it saw.  For records of
        `ltpcontrol.forced_response` (linear interpolation) pass
        ``input_hold='foh'`` (and `feedthrough` when D ≠ 0) to get the
        data `identify_ltp` fits.
    hold_step : float, optional
        Step (s) of the input hold; default the step ``Ts`` of `timepts`.
        Give it when the records were decimated from a finer simulation
        (for example ``Ts/4``) or the input is updated faster than sampled.
    feedthrough : array_like, PeriodicMatrix or callable, optional
        The system's direct term ``D(t)`` (period `period`, shape
        ``(noutputs, ninputs)``; the scalar 0 for a strictly proper
        system), when known.  With `input_hold`, the sampled output
        ``y(t_k) = C x(t_k) + D(t_k) u_k`` sees the samples ``u_k``, not the
        held signal: the hold correction applies to ``y - D u`` only, and
        the direct term is added back exactly.  Without it, a system with
        ``D ≠ 0`` gets a bias ``(1/h(Ω) - 1) D_n`` (h the hold gain above);
        ignored when `input_hold` is None.
    real : bool, optional
        True (default): real lifted coordinates ``V^H G`` with output
        labels ``'<y>_c0', '<y>_c1', '<y>_s1', ...`` as in `ltpcontrol.lift`.
        False: the complex harmonics ``G_n``, n = -K..K (labels
        ``'<y>_h<n>'``).
    unusable : {'raise', 'skip'}, optional
        What to do with lines within one DFT bin of a multiple of ``ω_p/2``
        (the responses to ``±Ω`` share their output frequencies there):
        'raise' (default) a ValueError, or 'skip' them with a warning.
    batch_size : int, optional
        Number of (experiment, line) pairs analysed at once; bounds the
        memory use (default 64).
    progress : bool, optional
        Show a progress bar over the batches (default False).
    name : str, optional
        Name of the result.

    Returns
    -------
    control.FrequencyResponseData
        Discrete-time (``dt = Ts``) response of shape ``((2K+1) noutputs,
        ninputs, M)`` on the M distinct lines ``Ω`` (increasing, rad/s);
        input j is the ``c0`` (``h0``) coordinate of input j.  Lines
        excited in several experiments are solved in the least-squares
        sense (averaged, for one input).  From records whose free DFT bins
        give a noise level at every entry (and pass the tests of noise of
        `identify_ltp`), its attribute ``noise_std``
        (shape of ``frdata``) holds the standard deviation of each entry;
        `identify_ltp` uses it as its `std`.

    Raises
    ------
    ValueError
        If ``T/Ts`` is not an integer, the time points are not uniform, the
        window is shorter than one period, the lines of an input window
        are not on its DFT grid and `frequencies` is not given, a line lies within one DFT bin
        of a multiple of ``ω_p/2`` (with ``unusable='raise'``; the
        responses to ``±Ω`` then share their output frequencies), no
        usable line is left, two lines of one experiment produce
        overlapping harmonics, a line is not below the Nyquist frequency,
        an experiment has no line, or the experiments cannot separate the
        inputs at some line (fewer experiments than inputs, or dependent
        input phasors).
    ControlDimension
        If inputs, outputs, time points or frequencies have inconsistent
        shapes (experiment counts or lengths).
    ControlArgument
        For a response of the wrong type.

    Warns
    -----
    UserWarning
        If a given frequency is off the DFT grid of the window (leakage
        biases the response), when lines are skipped (``unusable='skip'``),
        or when the experiments separate the inputs only poorly at some
        line (condition number of the input phasors above 100).

    Notes
    -----
    With ``U(Ω)`` and ``Y_n`` as in the module notes, ``G_n = Y_n/U(Ω)``.
    For ``u = cos(Ωt)``, ``U = 1/2`` and ``G_n`` is twice the DFT
    coefficient of the output at ``Ω + nω_p`` (thesis-errata page).  The
    real form uses the unitary ``V`` with columns ``c_0 = e_0``, ``c_n =
    (e_n + e_{-n})/√2``, ``s_n = j(e_n - e_{-n})/√2`` (errata items 3-4).
    With m inputs, experiment e gives ``Y_n^{(e)} = G_n U^{(e)}`` (``G_n``
    of size ``ny x m``, ``U^{(e)}`` the m input coefficients at Ω); the
    experiments exciting Ω give ``G_n`` by least squares, each weighted by
    ``1/‖U^{(e)}‖²`` (Conventions page, multi-input identification).

    *From an HTF estimate.*  The lines are the frequencies ``Ω > 0`` of the
    HTF's grid, except multiples of ``ω_p/2``, at which all 2K+1 values
    ``G_n(jΩ)`` (component n at ``Ω + nω_p``; for ``Ω + nω_p < 0``
    ``conj G_{-n}`` at ``-(Ω + nω_p)``) are known, i.e. the input
    frequencies the estimate's data excited.  The grid of `estimate_htf`
    holds every ``Ω + nω_p`` of its points.  The sampling step of the
    result is ``Ts = T/N`` with N the smallest even number above ``2K+1``
    and ``2Ω_max/ω_p`` (every line below the Nyquist frequency).

    Examples
    --------
    Two unit cosines through a static gain ``1 + cos(ω_p t)``:

    >>> sys = ltp.ltpss(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)),
    ...                 lambda t: np.array([[1 + np.cos(4 * np.pi * t)]]), 0.5)
    >>> exc = ltp.sine_experiments([1.0, 3.0], 0.5, dt=0.05, nperiods=8)
    >>> resp = ltp.forced_response(sys, exc.time, exc.inputs)
    >>> G = ltp.lifted_frequency_response(resp, 0.5, 1, real=False)
    >>> np.round(G.frdata[:, 0, 0].real, 6)            # G_{-1}, G_0, G_1
    array([0.5, 1. , 0.5])
    >>> G.output_labels[:2]
    ['y[0]_h-1', 'y[0]_h0']

    Two inputs excited jointly, two experiments per line with phases
    ``(0, 0)`` and ``(0, π)``:

    >>> D = lambda t: np.array([[1 + np.cos(4 * np.pi * t), 2.0]])
    >>> sys2 = ltp.ltpss(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((1, 0)), D, 0.5)
    >>> exc = ltp.sine_experiments([1.0, 3.0], 0.5, dt=0.05, nperiods=8, ninputs=2)
    >>> exc.inputs.shape                              # (inputs, experiments, samples)
    (2, 4, 80)
    >>> resp = ltp.forced_response(sys2, exc.time, exc.inputs)
    >>> G = ltp.lifted_frequency_response(resp, 0.5, 1, real=False)
    >>> np.round(G.frdata[:, :, 0].real, 6) + 0.0     # rows G_{-1}, G_0, G_1
    array([[0.5, 0. ],
           [1. , 2. ],
           [0.5, 0. ]])
    """
    if nharmonics is None:
        nharmonics = _data_harmonics(response, period)
    G, var, not_noise = _lifted_records(response, period, nharmonics, frequencies=frequencies,
                                transient=transient, input_hold=input_hold,
                                hold_step=hold_step, feedthrough=feedthrough, real=real,
                                unusable=unusable, batch_size=batch_size, progress=progress,
                                name=name)
    if var is not None and not_noise is None and np.all(np.isfinite(var)):
        G.noise_std = _entry_std(var, G, real)
    return G


def _data_harmonics(response, period):
    """The harmonics the data hold: ``(N-1)/2`` for records of N samples per period,
    the most an HTF knows together at some frequencies."""
    period = check_period(period)
    if isinstance(response, HTF):
        for k in range(response.nharmonics, 0, -1):
            try:
                _htf_lifted(response, period, k, True, None)
                return k
            except ValueError:
                continue
        return 0
    dt = as_records(response, 'response')[0].dt
    return (steps_per_period(period, dt, 'the time step of timepts') - 1) // 2


def _entry_std(var, G, real):
    """Standard deviation of every entry of the lifted response G (its frdata's
    shape) from the variance ``(M, (2K+1) ny, nu)`` of the complex harmonics: for the
    real coordinates ``V^H G`` the variances mix as ``|V|²``."""
    if real:
        ny = sum(1 for lab in G.output_labels if lab.endswith('_c0'))
        H = G.noutputs // ny
        K = (H - 1) // 2
        V, _ = _real_basis(np.arange(-K, K + 1), 2 * K + 2)
        W = np.kron(np.abs(V) ** 2, np.eye(ny))
        var = np.einsum('ba,mbj->maj', W, var)
    return np.sqrt(var.transpose(1, 2, 0))


def _lifted_records(response, period, nharmonics, *, frequencies=None, transient=0.0,
                    input_hold=None, hold_step=None, feedthrough=None, real=True,
                    unusable='raise', batch_size=64, progress=False, name=None):
    """`lifted_frequency_response`, the noise variance of the complex lifted
    response, ``(M, (2K+1) ny, nu)`` (rows harmonic-major; None for an HTF, NaN where
    no DFT bin near an output frequency is free of the response; `_output_noise`), and
    why the free bins do not hold noise (None if they do; `_free_bin_check`)."""
    period = check_period(period)
    if isinstance(response, HTF):
        K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
        return _htf_lifted(response, period, K, real, name), None, None
    t, dt, u, y, ylabels, ulabels = _parse_response(response)
    N = steps_per_period(period, dt, 'the time step of timepts')
    K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
    if 2 * K + 1 > N:
        raise ValueError(f"nharmonics={K} needs 2K+1 <= N = {N} samples per period")
    if input_hold not in _HOLDS:
        raise ValueError(f"input_hold must be None, 'foh' or 'zoh', got {input_hold!r}")
    if not isinstance(real, (bool, np.bool_)):
        raise ControlArgument(f"real must be True or False, got {real!r}")
    hold_step = dt if hold_step is None else check_positive(hold_step, 'hold_step')
    batch_size = check_positive_int(batch_size, 'batch_size')
    if unusable not in ('raise', 'skip'):
        raise ValueError(f"unusable must be 'raise' or 'skip', got {unusable!r}")
    transient = float(real_array(transient, 'transient', ndim=0))
    if transient < 0:
        raise ValueError(f"transient must be >= 0, got {transient}")

    tw, uw, yw = _analysis_window(t, u, y, dt, N, transient)
    window = tw.size * dt
    lines = _lines(uw, frequencies, window, dt, period, unusable == 'skip')
    var_y = _output_noise(yw, lines, N, K, dt)
    not_noise = _free_bin_check(yw, lines, N, K, dt)
    direct = input_hold is not None and feedthrough is not None
    if direct:
        # y = y_dyn + D(t_k) u_k: analyse both parts, the direct one without the hold
        D = _feedthrough(feedthrough, period, (yw.shape[0], uw.shape[0]))
        yd = np.einsum('koj,jek->oek', D(tw), uw)
        yw = np.concatenate([yw - yd, yd])
    omega, U, Y = _line_spectra(tw, uw, yw, lines, N, K, period, batch_size, progress)
    hold = _hold_factor(omega, hold_step, input_hold)[:, None]
    if direct:
        # harmonic-major rows of Y: (2K+1) blocks of [dynamic outputs, direct outputs]
        Y = Y.reshape(Y.shape[0], 2 * K + 1, 2, -1)
        lines, G, var = _solve_lines(omega, U * hold, Y[:, :, 0].reshape(Y.shape[0], -1),
                                     window, var_y)
        G = G + _solve_lines(omega, U, Y[:, :, 1].reshape(Y.shape[0], -1), window)[1]
    else:
        lines, G, var = _solve_lines(omega, U * hold, Y, window, var_y)
    return _lifted_frd(G, lines, dt, K, N, real, ylabels, ulabels, name), var, not_noise


def _feedthrough(value, period, shape):
    """The direct term D(t) as a PeriodicMatrix of the given shape (scalar 0: zeros)."""
    if not isinstance(value, PeriodicMatrix) and not callable(value) \
            and np.ndim(value) == 0 and real_array(value, 'feedthrough', ndim=0) == 0:
        value = np.zeros(shape)
    return as_periodic(value, period, 'feedthrough', shape)


def _parse_response(response):
    """``(t, Ts, u (nu, nexp, L), y (ny, nexp, L), output labels, input labels)``."""
    refuse_ambiguous(response, 'response', 'lifted_frequency_response')
    records = as_records(response, 'response')
    t, dt, u, y = common_grid(records, 'response')
    rec = records[0]
    ylabels = list(rec.output_labels or [f'y[{i}]' for i in range(y.shape[0])])
    ulabels = list(rec.input_labels or [f'u[{j}]' for j in range(u.shape[0])])
    return t, dt, u, y, ylabels, ulabels


def _analysis_window(t, u, y, dt, N, transient):
    """The last P whole periods (P N samples) of every record after the transient."""
    L = t.size
    skip = int(np.ceil(transient / dt - 1e-9))
    P = (L - skip) // N
    if P < 1:
        raise ValueError(f"the records ({L} samples) hold no whole period ({N} samples) "
                         f"after the transient of {transient} s")
    start = L - P * N
    return t[start:], u[:, :, start:], y[:, :, start:]


def _line_spectra(tw, uw, yw, lines, N, K, period, batch_size, progress):
    """Input and output coefficients of every (experiment, line) pair.

    Returns the pair's line Ω (rad/s), ``U (pairs, nu)`` with
    ``U_j = (1/L) Σ_k u_j[k] e^{-jΩt_k}`` and ``Y (pairs, (2K+1) ny)`` with
    ``Y_n = (1/L) Σ_k y[k] e^{-jΩt_k} e^{-jnω_p t_k}`` (harmonic-major rows);
    the second factor of Y repeats every period (N samples).
    """
    wp = 2 * np.pi / period
    harm = np.arange(-K, K + 1)
    Eh = np.exp(-1j * wp * harm[:, None] * tw[None, :N])          # (2K+1, N)
    ny, Lw = yw.shape[0], tw.size
    P = Lw // N
    exp_index = np.concatenate([np.full(Om.size, e) for e, Om in enumerate(lines)])
    omega = np.concatenate(lines)
    U, Y = [], []
    for b0 in tqdm(range(0, omega.size, batch_size), desc="lifted FR", leave=False,
                   disable=(not progress) or None):
        Om, ex = omega[b0:b0 + batch_size], exp_index[b0:b0 + batch_size]
        Ein = np.exp(-1j * Om[:, None] * tw[None, :])              # (b, Lw)
        U.append(np.einsum('bk,jbk->bj', Ein, uw[:, ex]) / Lw)
        # Σ over periods of y e^{-jΩt}, then the periodic harmonic factor
        Z = (yw[:, ex] * Ein).reshape(ny, Om.size, P, N).sum(2)  # (ny, b, N)
        Y.append(np.einsum('obk,hk->bho', Z, Eh).reshape(Om.size, -1) / Lw)
    return omega, np.concatenate(U), np.concatenate(Y)


def _solve_lines(omega, U, Y, window, var_y=None):
    """Lines, lifted response ``G (M, (2K+1) ny, nu)`` on the M distinct lines
    (increasing) and its noise variance (None without `var_y`).

    Each pair e gives ``Y^{(e)} = G U^{(e)}``; the pairs of one line give G by
    least squares with weights ``1/‖U^{(e)}‖²``:  ``G Σ_e U U^H/‖U‖² =
    Σ_e Y U^H/‖U‖²`` (for one input the mean of ``Y/U``).  With independent
    errors of variance ``var_y`` in Y, ``G = Σ_e Y^{(e)} w_e^T/‖U^{(e)}‖`` with
    ``w_e = (U^{(e)H} Gram^{-1})^T/‖U^{(e)}‖`` has the variance
    ``Σ_e var_y^{(e)} |w_e|²/‖U^{(e)}‖²``.
    """
    key, inverse = np.unique(np.round(omega * window / (2 * np.pi), 6), return_inverse=True)
    Un = U / np.linalg.norm(U, axis=1, keepdims=True)
    Yn = Y / np.linalg.norm(U, axis=1, keepdims=True)
    nu = U.shape[1]
    gram = np.zeros((key.size, nu, nu), complex)
    rhs = np.zeros((key.size, Y.shape[1], nu), complex)
    np.add.at(gram, inverse, Un[:, :, None] * Un[:, None, :].conj())
    np.add.at(rhs, inverse, Yn[:, :, None] * Un[:, None, :].conj())
    eig = np.linalg.eigvalsh(gram)                                   # ascending
    ratio = eig[:, 0] / eig[:, -1]
    lines = key * 2 * np.pi / window
    if np.any(ratio < _SEPARATION_RTOL):
        bad = lines[ratio < _SEPARATION_RTOL]
        raise ValueError(
            f"the experiments cannot separate the {nu} inputs at the lines "
            f"{np.round(bad[:5], 6).tolist()}{' ...' if bad.size > 5 else ''} rad/s: every "
            f"line needs at least {nu} experiments with independent input phasors (see "
            "sine_experiments and multisine with ninputs)")
    poor = int(np.sum(ratio < _SEPARATION_WARN))
    if poor:
        warnings.warn(f"the experiments separate the inputs poorly at {poor} "
                      f"lines (condition number of the input phasors up to "
                      f"{np.sqrt(1 / ratio.min()):.3g}): noise is amplified there",
                      UserWarning, stacklevel=3)
    # G gram = rhs  <=>  gram^T G^T = rhs^T (gram Hermitian)
    G = np.linalg.solve(gram.conj(), rhs.transpose(0, 2, 1)).transpose(0, 2, 1)
    if var_y is None:
        return lines, G, None
    w = np.einsum('ej,ejk->ek', Un.conj(), np.linalg.inv(gram)[inverse])
    norm2 = np.sum(np.abs(U) ** 2, axis=1)
    var = np.zeros(G.shape)
    np.add.at(var, inverse, var_y[:, :, None] * (np.abs(w) ** 2 / norm2[:, None])[:, None, :])
    return lines, G, var


def _output_noise(yw, lines, N, K, dt, nbins=4):
    """Noise variance of the output coefficients ``Y_n`` of every (experiment, line)
    pair, ``(pairs, (2K+1) ny)`` in the order of `_line_spectra`.

    In the window of P periods, ω_p is P DFT bins; the response of an
    experiment with lines at bins l occupies the bins ``±l + mP`` and ``mP``
    (a periodic operating point).  The other bins hold noise only (in
    steady state): ``var Y_n`` is the mean of ``|Y_b|²`` over the `nbins`
    free bins nearest to ``l + nP`` (``E|Y_b|² = σ²/L`` for white noise of
    variance σ², the same as that of ``Y_n``).  NaN where no bin is free or
    a line is off the DFT grid.
    """
    ny, nexp, Lw = yw.shape
    P = Lw // N
    binw = 2 * np.pi / (Lw * dt)
    harm = np.arange(-K, K + 1)
    out = []
    for e, Om in enumerate(lines):
        var = np.full((Om.size, 2 * K + 1, ny), np.nan)
        idx = Om / binw
        if Om.size and np.all(np.abs(idx - np.round(idx)) < 1e-6):
            idx = np.round(idx).astype(int)
            occupied = np.zeros(P, bool)
            occupied[0] = True
            occupied[idx % P] = occupied[-idx % P] = True
            if not occupied.all():
                spec = np.abs(np.fft.fft(yw[:, e], axis=-1)) ** 2 / Lw ** 2     # (ny, Lw)
                # offsets to the nearest free bins; the same for every harmonic n
                # (within ±nbins P: every free residue appears twice per period)
                offsets = np.concatenate([[d, -d] for d in range(1, nbins * P + 1)])
                for r in np.unique(idx % P):
                    d = offsets[~occupied[(r + offsets) % P]][:nbins]
                    on = idx % P == r
                    # bins (lines, 2K+1, nbins) near l + nP
                    bins = (idx[on, None, None] + harm[:, None] * P + d) % Lw
                    var[on] = spec[:, bins].mean(-1).transpose(1, 2, 0)
        out.append(var.reshape(Om.size, (2 * K + 1) * ny))
    return np.concatenate(out)


def _htf_lifted(H, period, K, real, name):
    """Lifted response (see Notes) on the grid of the data HTF `H`."""
    if not isinstance(H, HTFData):
        raise ControlArgument("response must be a data HTF (estimate_htf), got a model HTF")
    if not np.isclose(H.period, period, rtol=1e-9, atol=0):
        raise ValueError(f"the HTF's period {H.period} differs from period={period}")
    if K > H.nharmonics:
        raise ValueError(f"nharmonics={K} exceeds the HTF's {H.nharmonics} harmonics")
    om, (_, G) = H.omega, H.components()
    wp, Kh = 2 * np.pi / period, H.nharmonics
    tol = 1e-6 * np.min(np.diff(om), initial=wp)
    half = np.abs(2 * om / wp - np.round(2 * om / wp)) * wp / 2 <= tol
    cand = np.nonzero((om > tol) & ~half)[0]
    n = np.arange(-K, K + 1)
    w = om[cand, None] + n[None, :] * wp                   # output frequencies (lines, n)
    pos = np.searchsorted(om, np.abs(w) - tol).clip(0, om.size - 1)
    ongrid = np.abs(om[pos] - np.abs(w)) <= tol
    # G_n(jΩ) = component n at Ω + nω_p, or conj G_{-n} at -(Ω + nω_p)
    comp = np.where(w >= 0, Kh + n, Kh - n)
    vals = G[comp, :, :, pos]                                # (lines, 2K+1, ny, nu)
    vals = np.where((w < 0)[..., None, None], np.conj(vals), vals)
    keep = ongrid.all(axis=1) & np.all(np.isfinite(vals), axis=(1, 2, 3))
    if not keep.any():
        raise ValueError(f"no frequency of the HTF has all {2 * K + 1} components "
                         "G_n(jΩ) known: use fewer harmonics")
    omega, vals = om[cand[keep]], vals[keep]
    N = 2 * int(max(K + 1, np.floor(omega.max() / wp) + 1))
    ny, nu = vals.shape[2:]
    return _lifted_frd(vals.reshape(omega.size, -1, nu), omega, period / N, K, N, real,
                       list(H.output_labels), list(H.input_labels), name or H.name)


def _lifted_frd(G, omega, dt, K, N, real, ylabels, ulabels, name):
    """FrequencyResponseData of the lifted response G (M, (2K+1) ny, nu): real or complex."""
    harm = np.arange(-K, K + 1)
    ny = len(ylabels)
    data = G.transpose(1, 2, 0)
    if real:
        V, tags = _real_basis(harm, N)
        data = np.einsum('ba,bjw->ajw', np.kron(V, np.eye(ny)).conj(), data)
        outputs = _harmonic_labels(ylabels, tags)
        inputs = [f'{lab}_c0' for lab in ulabels]
    else:
        outputs = _harmonic_labels(ylabels, [f'h{n}' for n in harm])
        inputs = [f'{lab}_h0' for lab in ulabels]
    return ct.frd(data, omega, dt, name=name, inputs=inputs, outputs=outputs)


def _lines(uw, frequencies, window, dt, period, skip=False):
    """Input lines (rad/s) of every experiment, validated (unusable ones skipped)."""
    bin_ = 2 * np.pi / window
    nexp, Lw = uw.shape[1:]
    if frequencies is None:
        # a line: a bin where some input exceeds _LINE_RTOL of the experiment's peak
        spec = np.abs(np.fft.rfft(uw, axis=-1)) / Lw
        spec[..., 0] = 0.0                                # DC is no line
        if Lw % 2 == 0:
            spec[..., -1] = 0.0                           # nor is Nyquist
        peak = spec.max(axis=(0, 2))
        if np.any(peak == 0):
            raise ValueError(f"the input of experiment {int(np.argmin(peak))} has no "
                             "spectral line in the analysis window")
        on = spec.max(axis=0) >= _LINE_RTOL * peak[:, None]
        lines = [np.flatnonzero(row) * bin_ for row in on]
        total = np.sum(uw ** 2, axis=(0, 2))
        inline = 2 * Lw * np.sum(np.where(on, spec, 0.0) ** 2, axis=(0, 2))
        if np.any(total - inline > _LEAKAGE_RTOL * total):
            raise ValueError("an input window is not a sum of sinusoids on the DFT grid "
                             "of the window (leakage), so its lines cannot be detected; "
                             "choose the record length or pass frequencies=" + _CLOSED_LOOP)
    else:
        f = real_array(frequencies, 'frequencies', ndim=(1, 2))
        if f.shape[0] != nexp:
            raise ControlDimension(f"frequencies has {f.shape[0]} rows for {nexp} "
                                   "experiments")
        f = f.reshape(nexp, -1)
        off = np.abs(f / bin_ - np.round(f / bin_))
        if np.any(off > 1e-6):
            warnings.warn("some frequencies are not on the DFT grid 2π/window = "
                          f"{bin_:.6g} rad/s of the analysis window: leakage biases "
                          "the response", UserWarning, stacklevel=3)
        lines = list(f)
    half = np.pi / period                                 # ω_p / 2
    skipped = []
    for e, Om in enumerate(lines):
        if np.any(Om <= 0) or np.any(Om >= np.pi / dt):
            raise ValueError(f"frequencies of experiment {e} must lie in (0, π/Ts) = "
                             f"(0, {np.pi / dt:.6g}) rad/s")
        # ±Ω share output frequencies when 2Ω ≡ 0 (mod ω_p); lines l, l' when
        # Ω_l ± Ω_l' ≡ 0 (mod ω_p).
        dist = np.abs(Om - np.round(Om / half) * half)
        if skip and np.any(dist < 0.49 * bin_):
            skipped.extend(Om[dist < 0.49 * bin_])
            Om = lines[e] = Om[dist >= 0.49 * bin_]
        elif np.any(dist < 0.49 * bin_):
            raise ValueError(
                f"frequencies {np.round(Om[dist < 0.49 * bin_], 6).tolist()} rad/s of "
                f"experiment {e} are multiples of omega_p/2 = {half:.6g} rad/s (within "
                "one DFT bin): the responses to +Ω and -Ω fall on the same output "
                "frequencies")
        wp = 2 * half
        for s in (-1, 1):
            d = Om[:, None] + s * Om[None, :]
            d = np.abs(d - np.round(d / wp) * wp)
            np.fill_diagonal(d, np.inf)
            if np.any(d < 0.49 * bin_):
                raise ValueError(f"two lines of experiment {e} differ or sum to a "
                                 "multiple of omega_p: their output harmonics overlap"
                                 + _CLOSED_LOOP)
    if skipped:
        warnings.warn(f"skipped the lines {np.round(np.unique(skipped), 6).tolist()} rad/s "
                      f"at multiples of omega_p/2 = {half:.6g} rad/s: the responses to +Ω "
                      "and -Ω fall on the same output frequencies there",
                      UserWarning, stacklevel=4)
        if not any(Om.size for Om in lines):
            raise ValueError("no usable line is left after skipping the multiples of "
                             "omega_p/2")
    return lines


def _hold_factor(omega, dt, hold):
    """Gain of the input hold at ω: 1, sinc²(ωTs/2) or sinc(ωTs/2) e^{-jωTs/2}."""
    if hold is None:
        return np.ones_like(omega)
    x = np.sinc(omega * dt / (2 * np.pi))                  # np.sinc(x) = sin(πx)/(πx)
    return x ** 2 if hold == 'foh' else x * np.exp(-0.5j * omega * dt)
