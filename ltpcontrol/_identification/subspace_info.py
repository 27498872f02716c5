"""The diagnostics `identify_ltp` returns with ``return_info=True``."""

from dataclasses import dataclass

import numpy as np
import control as ct

from .fdsubspace import FDSubspaceInfo
from .realization import FloquetRealization
from .refine import RefineInfo

__all__ = ['LTPSubspaceInfo']


@dataclass(frozen=True)
class LTPSubspaceInfo:
    """Diagnostics returned by `identify_ltp` with ``return_info=True``.

    The first fields follow `scipy.optimize.OptimizeResult`.

    Attributes
    ----------
    success : bool
        The model is trustworthy: it predicts its held-out lines
        (``holdout_error <= validation_tol``; with validation); with
        'refit', its relative residual (less the noise's share when the
        noise is known) is at most the realization's ``fit_tol``
        (default 0.05) and the least-squares refit converged
        or was validated; with 'log' or 'tustin', the Floquet realization
        succeeded with all K harmonics; with ``refine='ml'`` also the
        refinement converged or was validated; the model is stable.
    message : str
        Description of the outcome.
    nfev : int
        Model evaluations of the refit and the refinement (0 for 'log' and
        'tustin' without refinement).
    data : control.FrequencyResponseData
        Real lifted frequency response used for identification.
    lifted : control.StateSpace
        Identified real lifted LTI model (discrete time, order ``(2K+1) n_p``).
    subspace : FDSubspaceInfo
        Diagnostics of the subspace step (singular values, q, residual).
    realization : FloquetRealization
        Diagnostics of `ltpcontrol.floquet_realization` on `lifted`: the
        structure distance (eq. 4.105), the similarity and the ``success``
        flag.
    conversion : str
        Continuous-time conversion used ('refit', 'log' or 'tustin').
    relative_residual : float
        ``‖G - Ĝ‖ / ‖G‖`` of the continuous-time model on the continuous
        harmonic response ``G_n(jΩ)`` (all lines, inputs and harmonics
        -K..K; those of the model for 'log' and 'tustin').
    realized_harmonics : int
        Harmonics of the realized lifted model: K, or fewer when the
        K-harmonic model had no eigenvalue ladders.
    refinement : RefineInfo or None
        With ``refine='ml'``: the `RefineInfo` of the refinement
        (parameters, covariance, ``realize``; e.g. for `sample_models`).
    holdout_nrmse : float
        Normalized RMS error of the model identified without the held-out
        lines on those lines (time-domain steady-state output, all
        harmonics of the data; see `identify_ltp`); NaN without validation.
    holdout_noise : float
        NRMSE of the noise alone on the held-out entries (see
        `identify_ltp`); NaN when the noise is unknown.
    holdout_error : float
        The model's share of the held-out NRMSE, ``sqrt(holdout_nrmse² -
        holdout_noise²)`` (``holdout_nrmse`` when the noise is unknown; NaN
        when the noise level exceeds ``holdout_nrmse``): compared with
        ``validation_tol``.
    holdout_lines : ndarray
        The held-out lines (rad/s); empty without validation.
    data_harmonics : int
        Harmonics ``K_d`` of the data fitted by the refit and refinement.
    refine_fallback : bool
        True when the ML refinement predicted the held-out lines worse than
        its start and the start was kept.
    input_hold : str or None
        The input hold of the records used (time records; None for lifted
        data or an HTF).
    record_nrmse : float
        Time records: NRMSE ``‖ŷ - y‖ / ‖y‖`` of the model identified without
        the held-out lines, simulated from rest (`forced_response`, the
        records' input hold) on the held-out records (the experiments whose
        every line is held out), in their analysis windows; NaN when no
        experiment is held out as a whole (multisines), for
        ``input_hold=None`` or for lifted data.
    record_noise : float
        The noise's NRMSE over the same samples (free DFT bins).
    record_error : float
        The model's share ``sqrt(record_nrmse² - record_noise²)``: the
        time-domain counterpart of ``holdout_error`` (see `identify_ltp`).

    Examples
    --------
    >>> LTPSubspaceInfo.__dataclass_fields__.keys() >= {'success', 'lifted', 'realization'}
    True
    """

    success: bool
    message: str
    nfev: int
    data: ct.FrequencyResponseData
    lifted: ct.StateSpace
    subspace: FDSubspaceInfo
    realization: FloquetRealization
    conversion: str
    relative_residual: float
    realized_harmonics: int
    refinement: RefineInfo = None
    holdout_nrmse: float = np.nan
    holdout_noise: float = np.nan
    holdout_error: float = np.nan
    holdout_lines: np.ndarray = None
    data_harmonics: int = 0
    refine_fallback: bool = False
    input_hold: str = None
    record_nrmse: float = np.nan
    record_noise: float = np.nan
    record_error: float = np.nan
