"""Frequency-domain subspace identification of LTP systems (thesis §4.2).

Pipeline
--------
1. *Lifted frequency response* (eqs. 4.54-4.58, 4.74-4.79, errata):
   `ltpcontrol.lifted_frequency_response` (``_lifted_response``), the
   frequency response of the real lifted LTI system from the ``c0``
   coordinate of every input.
2. *Subspace step* (eqs. 4.80-4.98): `ltpcontrol.fdsubspace` with order
   ``(2K+1) n_p`` (Remark 8) and ``q`` block rows.
3. *Floquet realization* (eqs. 4.99-4.112): a similarity that gives the
   lifted model the parametric structure of a Floquet-form DT LTP system
   (`ltpcontrol.floquet_realization`).
4. *Continuous time*: inverse Tustin (eq. 4.104), the matrix logarithm of the
   exactly sampled ``A_d`` (``A = log(A_d)/Ts``), or that ``A`` followed by a
   least-squares refit of ``B(t), C(t), D(t)`` on the continuous harmonic
   response (see `identify_ltp` and ``refit.py``).

Sampled data of a continuous system identify the exactly sampled Floquet
multipliers ``e^{λ Ts}``, so inverse Tustin biases ``A`` by about
``λ² Ts²/12`` (thesis-errata page); the refit route removes this bias.
"""

import warnings
from dataclasses import replace

import numpy as np
import control as ct

from .fdsubspace import fdsubspace
from .floquet_fit import _harmonic_data, _harmonic_response
from .._frequency.htf import HTF
from .lifted_response import lifted_frequency_response
from .realization import floquet_realization
from .refine import _harmonics, refine_ltp
from .refit import _refit, _to_continuous
from .subspace_info import LTPSubspaceInfo
from .record_check import RecordCheck, record_check, verdict
from .ident_data import (_assumed_hold, _check_lifted_data, _enough_lines, _from_excitation,
                         _lifted_data)
from .holdout import (_checked_noise, _model_share, _noise_nrmse, _nrmse, _produced_harmonics,
                      _quality)
from .._core.validation import check_period, check_positive, check_positive_int

__all__ = ['lifted_frequency_response', 'identify_ltp', 'LTPSubspaceInfo']

_CONVERSIONS = ('refit', 'log', 'tustin')
_HOLDS = ('auto', 'foh', 'zoh', None)
#: a free-bin content that is not noise is reported when its level would have been
#: this share of the held-out NRMSE (below, subtracting it would change nothing)
_NOT_NOISE_SHARE = 0.3
#: a valid model whose held-out share exceeds this many times the noise's (and a
#: tenth of validation_tol) is reported as underfitting
_UNDERFIT = 3.0


def identify_ltp(data, period, nstates, nharmonics=1, *, q=None, conversion='refit',
                 realization='direct', realization_options=None, refit_a=True,
                 refit_harmonics='auto', refine=None, refine_options=None,
                 estimate_d=True, frequencies=None, transient=None, input_hold='auto',
                 hold_step=None, batch_size=None, seed=None, holdout=4,
                 validation_tol=0.05, std=None, excitation=None, progress=False,
                 return_info=False, name=None):
    r"""Identify a continuous-time LTP model from sine experiments (thesis §4.2).

    Runs the whole frequency-domain subspace pipeline: lifted frequency
    response → LTI subspace model of order ``(2K+1) n_p`` (Remark 8) →
    Floquet realization → continuous-time LTP system in Floquet form
    (constant A).

    Parameters
    ----------
    data : control.FrequencyResponseData, control.TimeResponseData, tuple or HTFData
        Either the real lifted response of `lifted_frequency_response`
        (with ``2K+1`` harmonics per output, one column per input), the
        experiments themselves (anything `lifted_frequency_response`
        accepts, single- or multi-input), or a data HTF of `estimate_htf`
        (e.g. from chirps), whose lifted response is taken on its grid.
    period : float
        Period T of the system.
    nstates : int
        Number ``n_p`` of states of the LTP system.
    nharmonics : int, optional
        Number K of harmonics of the lifting (default 1).
    q : int, optional
        Block rows of the subspace data matrices (eq. 4.80), ``q > (2K+1)
        n_p``.  It matters: ``q ≈ 20`` reproduces the thesis's accuracy on
        its Mathieu example, larger values average better (thesis-errata
        page).  Default: that of `ltpcontrol.fdsubspace`.
    conversion : {'refit', 'log', 'tustin'}, optional
        Continuous-time model from the discrete realization
        ``(A_d, B_d[k], C_d[k], D_d[k])``:

        * 'tustin': inverse bilinear map, eq. (4.104) (the thesis route);
        * 'log': ``A = log(A_d)/Ts`` (sampled data identify the exactly
          sampled multipliers ``e^{λ Ts}``) and ``B``, ``C``, ``D`` by
          inverting a zero-order hold (`ltpcontrol.d2c` with 'log');
        * 'refit' (default): the 'log' ``A`` and a Gauss-Newton
          least-squares refit of the Fourier coefficients of ``B(t)``
          (harmonics -H..H, see `refit_harmonics`), ``C(t)`` (-2K..2K) and
          ``D(t)`` (-K..K) to the continuous harmonic response (see Notes),
          started from 'log'.

        'refit' is the default because it is the most accurate on the
        thesis example (see the Mathieu gallery example): inverse Tustin
        leaves an ``O(λ² Ts²)`` bias, 'log' an ``O(ω Ts)`` one in B and C.
    realization : {'direct', 'pso'}, optional
        Method of `ltpcontrol.floquet_realization` (default 'direct').
    realization_options : dict, optional
        Further keywords of `ltpcontrol.floquet_realization` (``tol``,
        ``ladder_tol``, ``distance``, ``pso_options``, ...).
    refit_a : bool, optional
        With ``conversion='refit'``, refit the constant ``A`` together with
        ``B``, ``C``, ``D`` (default True, which makes the result independent
        of `q`); False keeps the 'log' ``A`` and refits ``B``, ``C``, ``D``
        given ``A`` only.
    refit_harmonics : int or 'auto', optional
        With ``conversion='refit'``, number H >= K of harmonics of ``B(t)``
        in the refitted model (``C(t)`` has 2K, ``D(t)`` K).  'auto'
        (default) refits with H = K and with H = K + 1 and keeps K + 1 only
        if it earns its place: it must lower the Bayesian information
        criterion ``N log(SSE/N) + p log N`` (N real residuals, p
        parameters; ``B_{±(K+1)}`` add ``2 n_p m``) and be determined by the
        data (see Notes).  A plant whose A(t) is periodic has infinitely
        many harmonics in Floquet form; the input harmonics K + 1 remove
        most of the truncation bias of the exponents.  On 60 random plants
        with periodic A, B, C (identification guide) 'auto' chooses K + 1
        and, at K = 3, brings every exponent within 1e-3 (with H = K: 25 of
        30 single-input plants), at 1.5 to 2.1 times the run time of H = K;
        on the thesis's Mathieu example (B, C with one harmonic, K = 1) it
        keeps H = K and its result.  With ``refine='ml'`` and the
        harmonics of B given in `refine_options`, 'auto' takes those (at
        least K).
    refine : {None, 'ml'}, optional
        'ml': finish with `ltpcontrol.refine_ltp` on the lifted data (the
        maximum-likelihood fit of the Floquet-form model, equal weights
        unless ``refine_options`` gives ``std``), or, when `data` is an
        HTF, on all its components weighted by its ``std``; default None.
    refine_options : dict, optional
        Keywords of `ltpcontrol.refine_ltp` (``std``, ``stable``,
        ``harmonics``, ...).
    estimate_d : bool, optional
        Estimate a feedthrough (default True); False forces ``D = 0``.
    frequencies, transient : optional
        Time records only: passed to `lifted_frequency_response` (defaults
        there: lines detected, no transient).  Lines at multiples of
        ``ω_p/2`` are skipped with a warning.
    input_hold : {'auto', 'foh', 'zoh', None}, optional
        Time records only: how the recorded input samples were applied to
        the plant (`lifted_frequency_response`): 'foh' (linear
        interpolation, as `ltpcontrol.forced_response` applies inputs),
        'zoh' (held between samples) or None (samples of a continuous
        input).  'auto' (default): 'foh', with a warning when a zero-order
        hold would change the data by more than 1 % at the records' highest
        input frequency (``|1 - e^{-jωTs/2}/sinc(ωTs/2π)| ≈ ωTs/2``).  The
        hold cannot be inferred from the records: a hold's gain and
        half-step delay look like plant dynamics, and a model fitted under
        the wrong hold can fit them better than under the right one (a
        modulated first-order plant from ZOH records: relative residual
        1.2e-3 taken as 'foh', 3.6e-3 as 'zoh', yet fresh ZOH records
        predicted with NRMSE 0.23 and 0.009).  (`lifted_frequency_response`
        defaults to None: as an estimator it reports the samples' response;
        see there.)  With an `input_hold` and 'refit', the
        data are recomputed with the fitted ``D(t)`` as their `feedthrough`
        and refitted once, which removes the hold's bias on the direct
        term.
    hold_step, batch_size : optional
        Time records only: passed to `lifted_frequency_response` (defaults
        there: ``Ts``, 64).
    seed : int, optional
        Seed of the 'pso' realization search (reproducibility).
    holdout : int or None, optional
        Validation on held-out lines (default 4): every `holdout`-th line
        (starting with the second) is kept out of the identification; the
        model identified from the other lines predicts them, and its
        normalized RMS error ``info.holdout_nrmse``, less the share of the
        noise (``info.holdout_error``), decides ``success`` (see Notes).
        The returned model is then refitted on all lines from the
        validated one ('refit'; identified again from all lines for 'log',
        'tustin' and ``refit_a=False``, whose A is that of the
        realization).  None (or too few lines for the subspace step
        without them, with a warning) skips the validation.
    validation_tol : float, optional
        Largest held-out model error ``info.holdout_error`` of a successful
        model (default 0.05): the held-out NRMSE with the share of the noise
        removed when the noise is known (time records, or `std`; see Notes).
    std : array_like, optional
        Lifted frequency-response data only: standard deviation of the
        errors of its entries, a scalar or an array that broadcasts to
        ``data.frdata.shape`` (lifted outputs, inputs, lines).  It sets the
        noise share of the held-out NRMSE; the noise of time records is
        estimated from their DFT.  Default: the ``noise_std`` attribute of
        data lifted from records by `lifted_frequency_response`, if any.
    excitation : Excitation, optional
        Time records only: the design (`sine_experiments`, `multisine`) the
        records were made with.  Its analysis window gives the default
        `transient` (the settling periods) and its lines the default
        `frequencies`.  Chirp replicas are refused: estimate their HTF with
        `estimate_htf` (``segments=exc.segments``) and identify from it.
    progress : bool, optional
        Show progress bars (experiment batches, realization, refit; default
        False).
    return_info : bool, optional
        Also return an `LTPSubspaceInfo` (``success``, ``message``,
        ``nfev`` and the intermediate results).
    name : str, optional
        Name of the identified system (default ``'ltp_subspace'``).

    Returns
    -------
    sys : LTPStateSpace
        Continuous-time model in Floquet form (constant A) with the inputs
        and outputs of the data.
    info : LTPSubspaceInfo
        Only with ``return_info=True``.

    Raises
    ------
    ValueError
        If there are too few frequencies for the order ``(2K+1) n_p`` and
        `q`, the data do not have ``2K+1`` harmonics per output, an option
        is unknown, no lifted model of harmonics -k..k (k <= K) has a
        Floquet realization (repeated eigenvalues), or for the data errors
        of `lifted_frequency_response`; if `std` is negative or not finite.
    ControlArgument
        If `data` has the wrong type or is not discrete-time.
    ControlDimension
        If `std` does not broadcast to the shape of `data`.
    TypeError
        For unknown keyword arguments, or the time-record options
        (`frequencies`, `transient`, ...) given with frequency-response data,
        or `std` given with time records or an HTF.

    Warns
    -----
    UserWarning
        If the model's share of its held-out error exceeds
        `validation_tol` (the warning names ``holdout_error`` and
        ``holdout_nrmse``); if the data (lifted response or HTF) hold fewer
        output harmonics than the model produces; if the noise level exceeds
        the held-out NRMSE (the model's share is then unknown, NaN); if the
        free DFT bins of the records hold a transient or lines rather than
        noise; if a valid model's share exceeds 3 times the noise's (and a
        tenth of `validation_tol`: the structure underfits); with
        ``input_hold='auto'`` when the assumed hold matters; if the model
        simulated on the held-out records misses them by more than its
        held-out lines show (see Notes).  With
        'refit': if the returned model misses the data by more than
        the realization's ``fit_tol`` (default 0.05, relative residual less
        the noise's share) or the refit stops before converging without a
        validation on held-out lines.  With 'log' or 'tustin': if the
        realization does not find the Floquet structure or had to use
        fewer harmonics.  Lines of time records at multiples of ``ω_p/2``
        are skipped with a warning.  If the returned model is unstable
        (steady-state frequency data come from a stable plant; noise can
        push a lightly damped fit across), with ``success=False``: with
        'refit', an unstable fit is first restarted from the other
        realizations (harmonics K-1, K-2) and the stable fit of lowest
        cost is returned if there is one.

    Notes
    -----
    With ``R_m(Ω) = (j(Ω + mω_p) I - A)^{-1}``, the continuous harmonic
    response of a Floquet-form model to the input harmonic 0 is

    .. math::

        G_n(jΩ) = \sum_{m=-K}^{K} C_{n-m} R_m(Ω) B_m + D_n,
        \qquad n = -K..K,

    (``ny x nu`` for ``nu`` inputs), bilinear in (B, C) and linear in D.  'refit' minimises
    ``Σ |G_n - Ĝ_n|²`` over all lines and harmonics by Levenberg-Marquardt
    steps (minimum-norm Gauss-Newton steps absorb the similarity freedom).
    The pipeline is robust to imperfect lifted models: the eigenvalue
    ladders are found by optimal matching with members weighted by their
    contribution (`ltpcontrol.floquet_realization`), and if the K-harmonic
    lifted model has no ladders at all (its outermost members absorb the
    truncation error of a plant with periodic A(t)) the data of fewer
    harmonics are realized and the refit restores all K.  A plant whose
    A(t) is periodic has infinitely many harmonics in Floquet form; the
    truncation error of a K-harmonic model decays quickly with K (see the
    identification guide).

    The harmonic ``B_{±(K+1)}`` of ``refit_harmonics='auto'`` is
    determined by the data when its terms ``C_{n-m} R_m B_m``, ``m =
    ±(K+1)``, are seen in the measured harmonics ``|n| <= K`` through the
    harmonics of C.  Where C(t) has none (a plant with at most K harmonics in
    Floquet form and a constant C), ``B_{±(K+1)}`` can fit errors of the data
    through a vanishing ``C_{±l}`` and become arbitrarily large, yet it
    drives the unmeasured harmonics ``G_{±(K+1)} ∋ C_0 R_{±(K+1)} B_{±(K+1)}``
    that the model predicts.  H = K + 1 is therefore kept only if these
    terms are at most 1000 times larger in ``G_{±(K+1)}`` than in the
    measured harmonics (measured: at most 10.4 on the random plants, 10 on
    the Mathieu example, above 6e5 for a constant-C plant identified from
    time records).

    Every output harmonic the model produces is fitted.  A Floquet-form
    model with H harmonics in B, 2K in C and K in D responds to a line Ω at
    the output frequencies ``Ω + nω_p``, ``|n| <= 2K + H``.  From time
    records, the lifted data are therefore analysed at the harmonics
    ``|n| <= K_d = 2K + H`` (H = K + 1 for ``refit_harmonics='auto'``;
    at most ``(N-1)/2`` for N samples per period): the subspace step and the
    realization use the harmonics ``|n| <= K``, the refit and the ML
    refinement all of them.  A harmonic the model produces but the data
    do not hold is not determined by the data, yet it enters every
    prediction (on a plant with periodic A(t) its error can exceed the
    plant's own harmonic 100-fold).  Lifted data given as
    `control.FrequencyResponseData` are used with the harmonics they hold
    (their output labels ``'<y>_c0'``, ``'<y>_c1'``, ... tell how many),
    HTFs with the most harmonics known together on their grid.  When these
    are fewer than the model produces, the model is not trustworthy
    whatever its held-out error on the harmonics the data hold (on a hopper
    leg with periodic stiffness, lifted data of K = 2 harmonics validate a
    model at 4e-3 that predicts a fresh broadband record with NRMSE 0.1):
    ``success`` is False, with a warning naming the missing harmonics.
    Lift records with ``2K + H`` harmonics (``3K + 1`` for the default
    'auto') for `identify_ltp` to fit and validate all of them.

    Validation.  ``holdout_nrmse = ‖Ĝ - G‖ / ‖G‖`` over the held-out
    lines, all inputs, outputs and harmonics ``|n| <= K_d`` of the data.
    By Parseval this is the normalized RMS error ``‖ŷ - y‖ / ‖y‖`` of the
    model's steady-state output in the time domain, for the held-out
    single-sine records of equal amplitude (or one multisine of the
    held-out lines): the whole output the model predicts, since it has no
    harmonics beyond ``K_d``.

    Noise in the held-out data raises the NRMSE of a perfect model.  When
    the noise is known, ``holdout_noise = sqrt(Σ σ²) / ‖G‖`` is the NRMSE
    of the noise alone over the same entries and ``holdout_error =
    sqrt(holdout_nrmse² - holdout_noise²)`` the model's share, which
    decides ``success``; with the noise level above ``holdout_nrmse`` the
    share is unknown (NaN, with a warning; never 0) and ``holdout_nrmse``,
    which bounds it, decides.  Time records give σ² themselves: in
    the analysis window of P periods ω_p is P DFT bins and the response to
    a line at bin l occupies only the bins ``±l + mP`` (and ``mP``); the
    mean power of the nearest four free bins around each output frequency
    is the variance of its coefficient (``σ²/L`` for white noise), carried
    through the least-squares solution of every line.  For lifted data
    give `std`; without it (and for HTFs) ``holdout_error =
    holdout_nrmse``.  The held-out noise was not fitted, so
    ``holdout_nrmse >= holdout_noise`` up to the spread of the estimate: a
    level above 1.5 times it is not noise (a transient left in the window,
    or too large a `std`) and is not used, with a warning.  The free bins
    of time records must also hold noise: a content that is not stationary
    over the window (a transient) or that has lines (nonlinear or event
    distortion) is not used (module ``noise_check``; broadband stationary
    distortion passes as noise: simulate the model on fresh records with
    `validate_ltp`).

    From time records the held-out figure is also checked in the time
    domain: the model identified without the held-out lines is simulated
    from rest (`forced_response`, the records' input hold) on the records
    whose every line is held out, and ``info.record_nrmse`` is its NRMSE in
    their analysis windows, ``info.record_error`` its share less the noise's
    (free DFT bins, ``info.record_noise``).  It sees the whole output:
    harmonics beyond ``K_d``, a transient, inputs off the DFT grid.  A
    share above ``validation_tol`` makes ``success`` False; one above twice
    ``holdout_error`` (plus ``validation_tol``/10) is reported with a warning;
    both only beyond three standard deviations of the noise estimate.  The
    cost is one simulation of a quarter of the records (none for multisine
    records, which hold out no whole experiment, nor for ``input_hold=None``,
    whose samples of a continuous input cannot be replayed exactly).  The relative residual is compared with the
    realization's ``fit_tol`` the same way, less the noise's share over
    all lines (a residual below the noise counts as 0 there: the fitted
    lines absorb part of their noise).

    With ``refine='ml'`` the refined model is kept only if it predicts the
    held-out lines at least as well as its start; otherwise the start is
    returned and ``info.message`` says so.

    The identified model and the true system are related by a periodic
    change of state: compare them with `ltpcontrol.compare_ltp` (HTFs and
    Floquet exponents modulo ``jω_p``).  `ltpcontrol.to_canonical` removes
    only constant similarities, so it also depends on the branch of the
    exponents.

    Examples
    --------
    A first-order system with a modulated input gain, identified from
    single-sine experiments (lines off the multiples of ``ω_p/2``):

    >>> sys = ltp.ltpss([[-2.0]], lambda t: np.array([[1 + 0.5 * np.cos(4 * np.pi * t)]]),
    ...                 [[1.0]], 0, period=0.5)
    >>> w = np.pi / 2 * np.array([k for k in range(1, 16) if k % 4])
    >>> exc = ltp.sine_experiments(w, 0.5, dt=0.0125, nperiods=8, settle=12)
    >>> resp = ltp.forced_response(sys, exc.time, exc.inputs)
    >>> model = ltp.identify_ltp(resp, 0.5, 1, q=10, transient=6.0, input_hold='foh')
    >>> np.round(model.A(0.0), 4)
    array([[-2.]])
    >>> B = model.B.fourier(1)[:, 0, 0]           # B_1/B_0 = 0.25
    >>> round(float((B[2] / B[1]).real), 4)
    0.25
    """
    if input_hold not in _HOLDS:
        raise ValueError(f"input_hold must be one of {_HOLDS}, got {input_hold!r}")
    lifted = isinstance(data, (ct.FrequencyResponseData, HTF))
    if excitation is not None:
        if lifted:
            raise TypeError("identify_ltp: excitation only applies to time records")
        frequencies, transient = _from_excitation(excitation, frequencies, transient)
    if not lifted:
        args = dict(nharmonics=nharmonics, q=q, conversion=conversion,
                    realization=realization, realization_options=realization_options,
                    refit_a=refit_a, refit_harmonics=refit_harmonics, refine=refine,
                    refine_options=refine_options, estimate_d=estimate_d,
                    frequencies=frequencies, transient=transient, hold_step=hold_step,
                    batch_size=batch_size, seed=seed, holdout=holdout,
                    validation_tol=validation_tol, std=std, progress=progress, name=name)
        return _identify_checked_hold(data, period, nstates, input_hold, return_info, args)
    if input_hold not in (None, 'auto'):
        raise TypeError("identify_ltp: ['input_hold'] only apply to time records, not to "
                        "frequency-response data")
    return _identify(data, period, nstates, input_hold=None, return_info=return_info,
                     nharmonics=nharmonics, q=q, conversion=conversion,
                     realization=realization, realization_options=realization_options,
                     refit_a=refit_a, refit_harmonics=refit_harmonics, refine=refine,
                     refine_options=refine_options, estimate_d=estimate_d,
                     frequencies=frequencies, transient=transient, hold_step=hold_step,
                     batch_size=batch_size, seed=seed, holdout=holdout,
                     validation_tol=validation_tol, std=std, progress=progress, name=name)


def _identify_checked_hold(data, period, nstates, input_hold, return_info, args):
    """`_identify` on time records with the input hold given, or 'foh' for 'auto' with
    a warning when the hold matters for these records."""
    hold = _assumed_hold(data, input_hold, args['hold_step'])
    sysc, info = _identify(data, period, nstates, input_hold=hold, return_info=True, **args)
    info = replace(info, input_hold=hold)
    return (sysc, info) if return_info else sysc


def _identify(data, period, nstates, nharmonics=1, *, q=None, conversion='refit',
              realization='direct', realization_options=None, refit_a=True,
              refit_harmonics='auto', refine=None, refine_options=None,
              estimate_d=True, frequencies=None, transient=None, input_hold=None,
              hold_step=None, batch_size=None, seed=None, holdout=4,
              validation_tol=0.05, std=None, progress=False, return_info=False,
              name=None):
    """`identify_ltp` with a given input hold."""
    period = check_period(period)
    nstates = check_positive_int(nstates, 'nstates')
    K = check_positive_int(nharmonics, 'nharmonics', minimum=0)
    if conversion not in _CONVERSIONS:
        raise ValueError(f"conversion must be one of {_CONVERSIONS}, got {conversion!r}")
    if refine not in (None, 'ml'):
        raise ValueError(f"refine must be None or 'ml', got {refine!r}")
    if not (isinstance(refit_harmonics, str) and refit_harmonics == 'auto'):
        refit_harmonics = check_positive_int(refit_harmonics, 'refit_harmonics', minimum=K)
    elif refine == 'ml' and (refine_options or {}).get('harmonics') is not None:
        # the refinement fixes the harmonics of B: the refit starts it with them
        refit_harmonics = max(K, _harmonics(refine_options['harmonics'], None, K)[0])
    if holdout is not None:
        holdout = check_positive_int(holdout, 'holdout', minimum=2)
    validation_tol = check_positive(validation_tol, 'validation_tol')
    # 1. lifted frequency response, with every output harmonic the model produces
    Hb = K + 1 if refit_harmonics == 'auto' and K > 0 else (
        K if refit_harmonics == 'auto' else refit_harmonics)
    record_options = dict(frequencies=frequencies, transient=transient,
                          input_hold=input_hold, hold_step=hold_step, batch_size=batch_size)
    G, noise_var, not_noise = _lifted_data(data, period, 2 * K + Hb, progress,
                                           record_options, K, std)
    ny, N, Kd = _check_lifted_data(G, period, K, nstates, q)
    name = 'ltp_subspace' if name is None else name
    labels = dict(name=name, inputs=[lab.rsplit('_', 1)[0] for lab in G.input_labels],
                  outputs=[lab.rsplit('_', 1)[0] for lab in G.output_labels[:ny]])
    M = G.omega.size
    held = np.zeros(M, bool)
    if holdout is not None:
        held[1::holdout] = True
        if not _enough_lines(M - int(held.sum()), K, nstates, q):
            warnings.warn(f"{M} lines are too few to hold every {holdout}-th out for "
                          "validation: the model is not validated (holdout_nrmse is NaN)",
                          UserWarning, stacklevel=2)
            held[:] = False
    ctx = dict(data=data, period=period, K=K, Kd=Kd, N=N, ny=ny, nstates=nstates, q=q,
               conversion=conversion, refit_harmonics=refit_harmonics,
               estimate_d=estimate_d, refit_a=refit_a, labels=labels,
               input_hold=input_hold, record_options=record_options, refine=refine,
               refine_options=refine_options, realization=realization, seed=seed,
               progress=progress, realization_options=realization_options)
    holdout_nrmse, holdout_noise, fallback, nfev = np.nan, np.nan, False, 0
    check = RecordCheck()
    if held.any():
        # 2-6 without the held-out lines; their prediction validates the structure
        val = _identify_lines(G, ~held, ctx, htf=None)
        nfev += val['nfev']
        holdout_nrmse = _nrmse(val['sys'], G, held, Kd, N, ny)
        holdout_noise = _noise_nrmse(noise_var, G, held, Kd, N, ny)
        if val['ml'] is not None:
            before = _nrmse(val['start'], G, held, Kd, N, ny)
            if holdout_nrmse > before:
                # the refinement must not predict worse than its start
                fallback, holdout_nrmse = True, before
        if not isinstance(data, (ct.FrequencyResponseData, HTF)) and input_hold is not None:
            # the same model simulated on the held-out records themselves (held inputs:
            # samples of a continuous input cannot be replayed exactly)
            check = record_check(val['start'] if fallback else val['sys'], data, period,
                                 G.omega[held], **{k: record_options[k] for k in (
                                     'frequencies', 'transient', 'input_hold')})
        if conversion == 'refit' and refit_a:
            # the validated model, refitted on all lines
            ctx_all = dict(ctx, refine=None if fallback else refine)
            start = val['start'] if fallback else val['sys']
            fit = _fit_and_refine(start, G=G, lines=np.ones(M, bool), htf=data, **_fit_args(
                ctx_all))
            res = dict(val, sys=fit[0], converged=fit[1], ml=fit[3], start=fit[6])
            nfev += fit[2]
        else:
            # A is that of the realization: identified again from all lines
            res = _identify_lines(G, np.ones(M, bool), dict(
                ctx, refine=None if fallback else refine), htf=data)
            nfev += res['nfev']
    else:
        res = _identify_lines(G, np.ones(M, bool), ctx, htf=data)
        nfev += res['nfev']
    sysc, converged, ml, Kr = res['sys'], res['converged'], res['ml'], res['Kr']
    real = res['realization']
    if not_noise is not None and noise_var is not None and (
            not held.any() or holdout_noise > _NOT_NOISE_SHARE * holdout_nrmse):
        # the free bins hold no noise: their level is no share of the held-out error
        # (a small content changes that share by at most 5 %: kept as the level)
        warnings.warn(f"the DFT bins free of the response hold {not_noise}: their "
                      "level is not used as the noise's share of the held-out error",
                      UserWarning, stacklevel=2)
        holdout_noise, noise_var = np.nan, None
    holdout_noise = _checked_noise(holdout_nrmse, holdout_noise)
    if not np.isfinite(holdout_noise):
        noise_var = None
    holdout_error = _model_share(holdout_nrmse, holdout_noise)
    # a refit that stopped early is doubtful unless the held-out lines validate it;
    # with the model's share unknown (NaN), the held-out NRMSE bounds it
    validated = bool(held.any() and (holdout_nrmse if np.isnan(holdout_error)
                                     else holdout_error) <= validation_tol)
    if conversion == 'refit' and not converged and not validated:
        warnings.warn("the least-squares refit did not converge", UserWarning, stacklevel=2)
    Gc = _harmonic_data(G.frdata, Kd, N, ny)
    relres = float(np.linalg.norm(_harmonic_response(sysc, G.omega, Kd) - Gc)
                   / np.linalg.norm(Gc))
    # the noise's share of the residual, as for the held-out lines
    noise = _noise_nrmse(noise_var, G, np.ones(M, bool), Kd, N, ny)
    success, message = _quality(real, Kr, K, conversion, relres, converged, ml,
                                realization_options, validated, noise)
    produced = _produced_harmonics(sysc, K, conversion)
    if Kd < produced:
        # harmonics the model produces but the data do not hold are free: neither
        # fitted nor validated, yet they enter every prediction
        success = False
        missing = (f"the data hold the output harmonics |n| <= {Kd}, the model produces "
                   f"|n| <= {produced}: the harmonics {Kd + 1}..{produced} are neither "
                   "fitted nor validated")
        message += "; " + missing
        warnings.warn(f"{missing}; give data with {produced} harmonics "
                      f"(lifted_frequency_response(..., {produced}) or estimate_htf(..., "
                      f"{produced})), or the time records themselves", UserWarning,
                      stacklevel=2)
    if fallback:
        message += ("; the ML refinement predicted the held-out lines worse than its "
                    "start, which is kept")
    if held.any():
        noise = (f", of which noise {holdout_noise:.3g}: model error {holdout_error:.3g}"
                 if np.isfinite(holdout_noise) else "")
        if np.isnan(holdout_error):
            noise = ": the model's share is unknown (noise estimate above it)"
        message += (f"; held-out NRMSE {holdout_nrmse:.3g}{noise} (validation_tol "
                    f"{validation_tol:g})")
        if not validated:
            success = False
            figure = (f"holdout_error {holdout_error:.3g} (holdout_nrmse "
                      f"{holdout_nrmse:.3g}, noise {holdout_noise:.3g})"
                      if np.isfinite(holdout_error) and np.isfinite(holdout_noise)
                      else f"holdout_nrmse {holdout_nrmse:.3g}")
            warnings.warn(f"the identified model does not predict its held-out lines: "
                          f"{figure} > validation_tol {validation_tol:g}; try other "
                          "nstates, nharmonics or more data", UserWarning, stacklevel=2)
    figure = holdout_nrmse if np.isnan(holdout_error) else holdout_error
    disagrees, fails = verdict(check, figure, validation_tol)
    if disagrees or fails:
        # simulated on the records, the model misses them by more than the harmonics show
        message += (f"; simulated on the {check.nrecords} held-out records: NRMSE "
                    f"{check.nrmse:.3g}, model error {check.error:.3g}")
        success = success and not fails
    if disagrees or (fails and validated):
        warnings.warn(f"the model simulated on the {check.nrecords} held-out records "
                      f"misses them by NRMSE {check.nrmse:.3g} (noise {check.noise:.3g}, "
                      f"model error {check.error:.3g}{' > validation_tol' if fails else ''})"
                      f", more than its held-out lines show ({figure:.3g}): the records "
                      "hold output the analysed harmonics do not (harmonics beyond "
                      f"|n| <= {Kd}, a transient, inputs off the DFT grid)", UserWarning,
                      stacklevel=2)
    if success and np.isfinite(holdout_error) and np.isfinite(holdout_noise) and \
            holdout_error > max(_UNDERFIT * holdout_noise, validation_tol / 10):
        # valid, but the data determine more than the structure explains
        message += "; the model error is far above the noise: the structure underfits"
        warnings.warn(f"the model's share of its held-out error ({holdout_error:.3g}) is "
                      f"{holdout_error / max(holdout_noise, 1e-300):.3g} times the noise's "
                      f"({holdout_noise:.3g}): the data determine more than nstates="
                      f"{nstates}, nharmonics={K} explain; a larger structure may predict "
                      "better (select_structure)", UserWarning, stacklevel=2)
    if not sysc.is_stable():
        # steady-state responses exist only for a stable plant: an unstable fit is doubtful
        growth = float(np.max(np.linalg.eigvals(sysc.A(0.0)).real))
        success, message = False, message + f"; unstable model (exponent {growth:.3g})"
        warnings.warn(f"the identified model is unstable (largest real part of its Floquet "
                      f"exponents {growth:.3g}), while steady-state frequency data come from "
                      "a stable plant; with noisy data try refine='ml' with "
                      "refine_options={'stable': True}", UserWarning, stacklevel=2)
    if not return_info:
        return sysc
    return sysc, LTPSubspaceInfo(
        success=success, message=message, nfev=nfev, data=G, lifted=res['lifted'],
        subspace=res['subspace'], realization=real, conversion=conversion,
        relative_residual=relres, realized_harmonics=Kr, refinement=ml,
        holdout_nrmse=float(holdout_nrmse), holdout_noise=float(holdout_noise),
        holdout_error=float(holdout_error), holdout_lines=G.omega[held],
        data_harmonics=Kd, refine_fallback=fallback, record_nrmse=check.nrmse,
        record_noise=check.noise, record_error=check.error)


def _fit_args(ctx):
    """The keywords of `_fit_and_refine` in the context `ctx`."""
    keys = ('data', 'period', 'K', 'Kd', 'N', 'ny', 'conversion', 'refit_harmonics',
            'estimate_d', 'refit_a', 'labels', 'input_hold', 'record_options', 'refine',
            'refine_options', 'progress')
    return {key: ctx[key] for key in keys}


def _select_lines(G, lines, K, ny):
    """The lifted data of harmonics -K..K on the lines `lines` (bool mask)."""
    return ct.frd(G.frdata[:(2 * K + 1) * ny, :, lines], G.omega[lines], G.dt,
                  inputs=G.input_labels, outputs=G.output_labels[:(2 * K + 1) * ny])


def _identify_lines(G, lines, ctx, htf):
    """Steps 2-6 on the lines `lines` of the lifted data G (harmonics -Kd..Kd)."""
    K, Kd, N, ny = ctx['K'], ctx['Kd'], ctx['N'], ctx['ny']
    GK = _select_lines(G, lines, K, ny)
    GcK = _harmonic_data(GK.frdata, K, N, ny)
    # 2-4. subspace model, Floquet realization (fewer harmonics if better), continuous time
    candidates = _realize(GK, GcK, ctx['period'], K, N, ctx['nstates'], ny, ctx['q'],
                          ctx['estimate_d'], ctx['realization'], ctx['seed'], ctx['progress'],
                          ctx['realization_options'], ctx['conversion'], ctx['labels'])
    # 5-6. structured refit and optional maximum-likelihood refinement
    fit = dict(_fit_args(ctx), G=G, lines=lines, htf=htf)
    chosen, trial = 0, _fit_and_refine(candidates[0][-1], k0=candidates[0][-2], **fit)
    nfev = trial[2]
    if not trial[0].is_stable() and len(candidates) > 1:
        # steady-state data come from a stable plant: a local fit that left the
        # stable models is restarted from the other realizations; keep the stable
        # fit of lowest cost, if any
        best = None
        for i, cand in enumerate(candidates[1:], start=1):
            other = _fit_and_refine(cand[-1], k0=cand[-2], **fit)
            nfev += other[2]
            if other[0].is_stable():
                cost = _fit_cost(other, Kd, N, ny)
                if best is None or cost < best[0]:
                    best = (cost, i, other)
        if best is not None:
            chosen, trial = best[1], best[2]
    lifted, sinfo, real, Kr, _ = candidates[chosen]
    return dict(sys=trial[0], converged=trial[1], nfev=nfev, ml=trial[3], start=trial[6],
                lifted=lifted, subspace=sinfo, realization=real, Kr=Kr)


def _fit_and_refine(start, *, data, period, G, lines, htf, K, Kd, N, ny, conversion,
                    refit_harmonics, estimate_d, refit_a, labels, input_hold,
                    record_options, refine, refine_options, progress, k0=None):
    """Steps 5-6 from the realization `start` (of `k0` harmonics, default K) on the
    lines `lines` of G: ``(model, converged, nfev, ml, G, Gc, model before refinement)``."""
    sysc, nfev, converged = start, 0, True
    Gl = _select_lines(G, lines, Kd, ny)
    Gc = _harmonic_data(Gl.frdata, Kd, N, ny)
    if conversion == 'refit':
        sysc, converged, nfev = _refit(sysc, Gc, Gl.omega, K, refit_harmonics, estimate_d,
                                       refit_a, labels, progress, k0)
        if estimate_d and input_hold is not None and not isinstance(
                data, (ct.FrequencyResponseData, HTF)):
            # the direct term sees the samples, not the held input: redo the
            # hold correction with the fitted D(t) and refit once more
            options = dict(record_options, feedthrough=sysc.D)
            Gall = _lifted_data(data, period, Kd, False, options)[0]
            Gl = _select_lines(Gall, np.isin(Gall.omega, Gl.omega), Kd, ny)
            Gc = _harmonic_data(Gl.frdata, Kd, N, ny)
            sysc, converged, more = _refit(sysc, Gc, Gl.omega, K, refit_harmonics, True,
                                           refit_a, labels, progress)
            nfev += more
    before, ml = sysc, None
    if refine == 'ml':
        target = htf if isinstance(htf, HTF) else Gl
        options = dict(refine_options or {})
        std = options.get('std')
        if std is not None and not isinstance(htf, HTF) and np.ndim(std) >= 1 \
                and np.shape(std)[-1] == lines.size:
            options['std'] = np.asarray(std)[..., lines]        # std of the lines used
        sysc, ml = refine_ltp(sysc, target, return_info=True, **options)
        nfev += ml.nfev
    return sysc, converged, nfev, ml, Gl, Gc, before


def _fit_cost(fit, Kd, N, ny):
    """The cost a fit minimised: the ML cost, else the harmonic residual norm."""
    sysc, _, _, ml, G, Gc, _ = fit
    if ml is not None:
        return ml.cost
    return float(np.linalg.norm(_harmonic_response(sysc, G.omega, Kd) - Gc))


def _realize(G, Gc, period, K, N, nstates, ny, q, estimate_d, method, seed, progress,
             options, conversion, labels):
    """Steps 2-4: subspace model of order (2k+1) n_p, Floquet realization, continuous time.

    The outermost ladder members of a K-harmonic lifted model absorb the
    truncation error of a plant with periodic A(t); its ladders may then be
    poor or missing.  For the refit, the realizations of the data of
    harmonics -k..k, k = K, K-1, K-2, are therefore all formed and the one
    whose continuous model fits the K-harmonic data best starts the refit.
    Otherwise k = K, with k < K only when K has no realization.  Returns
    the candidates ``(lifted, info, realization, k, model)``, best first.
    """
    candidates, real = [], None
    for k in range(K, -1, -1):
        Gk = G if k == K else ct.frd(G.frdata[:(2 * k + 1) * ny], G.omega, G.dt)
        order = (2 * k + 1) * nstates
        if 2 * Gk.omega.size < (q or order + 1) + order:
            continue
        lifted, sinfo = fdsubspace(Gk, order=order, q=q, estimate_d=estimate_d,
                                   return_info=True)
        sysd, real = floquet_realization(lifted, k, N, period=period, method=method,
                                         input_harmonics='zero', seed=seed, progress=progress,
                                         return_info=True, **(options or {}))
        if sysd is None:
            continue
        sysc = _to_continuous(sysd, conversion, labels)
        if sysc is None:
            continue
        with np.errstate(all='ignore'):
            miss = np.linalg.norm(_harmonic_response(sysc, G.omega, K) - Gc)
        miss = miss if np.isfinite(miss) else np.inf
        candidates.append((miss, lifted, sinfo, real, k, sysc))
        if conversion != 'refit' or k <= K - 2:
            break
    if not candidates:
        raise ValueError(f"the Floquet realization failed: {real.message}"
                         if real is not None else "no realization could be converted "
                         "to continuous time")
    return [c[1:] for c in sorted(candidates, key=lambda c: c[0])]
