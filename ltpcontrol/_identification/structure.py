"""Choice of the harmonics K and the order n_p of an identified LTP model.

Every candidate ``(n_p, K)`` is identified with `identify_ltp` (every
`holdout`-th line held out) and scored on

* the held-out lines: ``info.holdout_nrmse = ‖Ĝ - G‖ / ‖G‖`` of the model
  identified without them, over all harmonics of the data: the
  normalized RMS error of its steady-state output in the time domain
  (Parseval), the prediction that matters,
* an information criterion on all lines, ``AIC = M_r log(SSE/M_r)
  + 2 d`` with ``M_r`` real residuals and ``d = (2H+1) n_p m + (4K+1) p n_p +
  (2K+1) p m`` free parameters (B, C, D harmonics for m inputs and p
  outputs, H = K or K + 1 the harmonics of the refitted B; A is fixed by the
  similarity up to its ``n_p`` exponents, which are added).

The singular values of the subspace step at the largest candidate order
show the lifted order ``(2K+1) n_p`` as a gap.  A plant whose A(t) is
periodic has infinitely many harmonics in Floquet form; the validation
error of a K-harmonic model then falls geometrically with K until it
reaches the data's own error.
"""

import warnings
from dataclasses import dataclass

import matplotlib.pyplot as plt
import numpy as np
import control as ct
from control.exception import ControlArgument
from tqdm.auto import tqdm

from .._core.lifting import _real_basis
from .floquet_fit import _harmonic_data, _harmonic_response
from .._frequency.htf import HTF
from .lifted_response import lifted_frequency_response
from .holdout import _produced_harmonics
from .ltp_subspace import identify_ltp
from .records import as_records, refuse_ambiguous
from .._core.validation import check_period, check_positive_int, steps_per_period

__all__ = ['select_structure', 'StructureSelection']

#: held-out errors below this count as equal when ranking by validation
_TIE = 1e-3


@dataclass(frozen=True)
class StructureSelection:
    """Result of `select_structure`.

    Attributes
    ----------
    nstates : ndarray of int
        Candidate orders n_p (rows of the tables).
    nharmonics : ndarray of int
        Candidate harmonics K (columns of the tables).
    validation_error : ndarray, shape (len(nstates), len(nharmonics))
        Held-out time-domain NRMSE (``holdout_nrmse`` of `identify_ltp`;
        NaN where identification failed).
    aic : ndarray, same shape
        Information criterion on all lines.
    singular_values : ndarray
        Singular values of the subspace step for the largest candidate.
    best : tuple of int
        ``(n_p, K)`` chosen by the `criterion`.
    criterion : str
        'validation' or 'aic'.

    Examples
    --------
    >>> sel = StructureSelection(np.array([1]), np.array([0, 1]),
    ...                          np.array([[0.1, 0.01]]), np.array([[5.0, 2.0]]),
    ...                          np.ones(3), (1, 1), 'validation')
    >>> sel.best
    (1, 1)
    """

    nstates: np.ndarray
    nharmonics: np.ndarray
    validation_error: np.ndarray
    aic: np.ndarray
    singular_values: np.ndarray
    best: tuple
    criterion: str

    def plot(self, ax=None):
        """Validation error versus K for every n_p, and the singular values.

        Parameters
        ----------
        ax : array of two matplotlib Axes, optional

        Returns
        -------
        control.ControlPlot

        Examples
        --------
        >>> sel = StructureSelection(np.array([1]), np.array([0, 1]),
        ...                          np.array([[0.1, 0.01]]), np.array([[5.0, 2.0]]),
        ...                          np.ones(3), (1, 1), 'validation')
        >>> sel.plot().axes.shape
        (1, 2)
        """
        if ax is None:
            fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
        ax = np.asarray(ax, dtype=object).reshape(1, 2)
        fig = ax[0, 0].figure
        lines = np.empty((1, 2), dtype=object)
        lines[0, 0] = [ax[0, 0].semilogy(self.nharmonics, err, 'o-', label=f"$n_p$ = {n}")[0]
                       for n, err in zip(self.nstates, self.validation_error)]
        ax[0, 0].set_xlabel("harmonics K")
        ax[0, 0].set_ylabel("validation error")
        ax[0, 0].set_xticks(self.nharmonics)
        ax[0, 0].legend()
        ax[0, 0].set_title(f"best ($n_p$, K) = {self.best} ({self.criterion})")
        sv = self.singular_values
        lines[0, 1] = ax[0, 1].semilogy(np.arange(1, sv.size + 1), sv, '.')
        ax[0, 1].set_xlabel("index")
        ax[0, 1].set_ylabel("singular value")
        ax[0, 1].set_title("subspace step, largest candidate")
        fig.tight_layout()
        return ct.ControlPlot(lines, ax, fig)


def select_structure(data, period, nstates, nharmonics, *, holdout=4, criterion='validation',
                     q=None, transient=0.0, input_hold='foh', progress=False):
    """Choose the order n_p and the harmonics K of an LTP model from data.

    Parameters
    ----------
    data : control.FrequencyResponseData, HTFData or time records
        Real lifted response (`lifted_frequency_response`) with at least
        ``max(nharmonics)`` harmonics, one column per input; or a data HTF
        (`estimate_htf`) or the sine records themselves, which are lifted
        here with every output harmonic the largest candidate produces,
        ``3 max(nharmonics) + 1`` (as far as the HTF holds them or the
        sampling allows).  A candidate producing output harmonics beyond
        those of the data is not scored (NaN, with a warning): its
        unfitted harmonics enter every prediction, yet its held-out error
        does not see them.
    period : float
        Period T of the system.
    nstates, nharmonics : array_like of int
        Candidate orders n_p and harmonics K.
    holdout : int, optional
        Every `holdout`-th line (starting with the second) is held out for
        validation (default 4; `identify_ltp` with this `holdout`).
    criterion : {'validation', 'aic'}, optional
        Score that picks `best` (default the held-out error; ties within
        10 % or below 1e-3 go to the smaller model).
    q : int, optional
        Block rows of the subspace step (`identify_ltp`).
    transient, input_hold : optional
        Time records only: as in `lifted_frequency_response` (defaults no
        transient and 'foh', the hold of `ltpcontrol.forced_response`).
    progress : bool, optional
        Show a progress bar over the candidates (default False).

    Returns
    -------
    StructureSelection
        Tables of both scores, the singular values and the choice; its
        ``plot()`` method draws them.

    Raises
    ------
    ControlArgument
        If `data` is frequency-response data that is not discrete-time.
    ValueError
        If the data have fewer than ``max(nharmonics)`` harmonics, a
        candidate list is empty, or `criterion` is unknown.
    TypeError
        For unknown keyword arguments.

    Examples
    --------
    >>> sys = ltp.ltpss([[-2.0]], lambda t: np.array([[1 + 0.5 * np.cos(4 * np.pi * t)]]),
    ...                 [[1.0]], 0, period=0.5)
    >>> w = np.pi / 2 * np.array([k for k in range(1, 24) if k % 4])
    >>> exc = ltp.sine_experiments(w, 0.5, dt=0.0125, nperiods=8, settle=12)
    >>> resp = ltp.forced_response(sys, exc.time, exc.inputs)
    >>> sel = ltp.select_structure(resp, 0.5, [1, 2], [0, 1, 2], transient=6.0)
    >>> sel.best
    (1, 1)

    Lifted data with fewer harmonics than a candidate produces leave it
    unscored:

    >>> G = ltp.lifted_frequency_response(resp, 0.5, 2, transient=6.0, input_hold='foh')
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter('always')
    ...     sel = ltp.select_structure(G, 0.5, [1], [0, 1, 2])
    >>> sel.validation_error.round(3)
    array([[0.354,   nan,   nan]])
    """
    period = check_period(period)
    Kmax0 = max(check_positive_int(k, 'nharmonics', minimum=0)
                for k in np.atleast_1d(nharmonics)) if np.size(nharmonics) else 0
    if isinstance(data, HTF):
        data = _htf_lifted_most(data, period, 3 * Kmax0 + 1, Kmax0)
    elif not isinstance(data, ct.FrequencyResponseData):
        refuse_ambiguous(data, 'data', 'select_structure')
        dt = as_records(data, 'data')[0].dt
        Kd = min(3 * Kmax0 + 1, (int(round(period / dt)) - 1) // 2)
        data = lifted_frequency_response(data, period, Kd, transient=transient,
                                         input_hold=input_hold, unusable='skip')
    if not data.dt or data.dt is True:
        raise ControlArgument("data must be discrete-time lifted frequency-response data "
                              "(from lifted_frequency_response)")
    ns = np.unique([check_positive_int(n, 'nstates') for n in np.atleast_1d(nstates)])
    Ks = np.unique([check_positive_int(k, 'nharmonics', minimum=0)
                    for k in np.atleast_1d(nharmonics)])
    if ns.size == 0 or Ks.size == 0:
        raise ValueError("nstates and nharmonics must not be empty")
    if criterion not in ('validation', 'aic'):
        raise ValueError(f"criterion must be 'validation' or 'aic', got {criterion!r}")
    holdout = check_positive_int(holdout, 'holdout', minimum=2)
    N = steps_per_period(period, float(data.dt), 'the sampling time of data')
    Kmax = int(Ks.max())
    rows = data.noutputs
    # the labels '<y>_c0', '<y>_c1', ... of lifted_frequency_response tell the outputs
    ny = sum(1 for lab in data.output_labels if lab.endswith('_c0'))
    Kdata = None
    if ny and rows % ny == 0 and (rows // ny) % 2 == 1 and rows // ny >= 2 * Kmax + 1:
        Kdata = (rows // ny - 1) // 2
    if Kdata is None:
        ny = rows // (2 * Kmax + 1) if rows % (2 * Kmax + 1) == 0 else 0
        Kdata = next((k for k in range(N) if (2 * k + 1) * ny == rows), None) if ny else None
    if Kdata is None:
        # the data hold (2K_d+1) p rows for some K_d >= Kmax
        Kdata = next((k for k in range(Kmax, N // 2 + 1)
                      if rows % (2 * k + 1) == 0), None)
        if Kdata is None:
            raise ValueError(f"the data ({rows} lifted outputs) do not hold "
                             f"max(nharmonics) = {Kmax} harmonics")
        ny = rows // (2 * Kdata + 1)
    M = data.omega.size
    held = np.zeros(M, bool)
    held[1::holdout] = True
    Gc = _harmonic_data(data.frdata, Kdata, N, ny)             # (m, 2K_d+1, ny, M)
    # labels '<y>_c0', '<y>_c1', ...: identify_ltp fits all K_d harmonics
    _, tags = _real_basis(np.arange(-Kdata, Kdata + 1), N)
    full = ct.frd(data.frdata[:(2 * Kdata + 1) * ny], data.omega, data.dt,
                  outputs=[f'y[{o}]_{tag}' for tag in tags for o in range(ny)],
                  inputs=[f'u[{j}]_c0' for j in range(data.ninputs)])
    nu = data.ninputs
    val = np.full((ns.size, Ks.size), np.nan)
    aic = np.full((ns.size, Ks.size), np.nan)
    bar = tqdm(total=val.size, desc="structures", disable=not progress, leave=False)
    sv, unscored = None, []
    for i, n in enumerate(ns):
        for j, K in enumerate(Ks):
            bar.set_postfix(n_p=int(n), K=int(K))
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter('ignore')
                    model, info = identify_ltp(full, period, int(n), int(K), q=q,
                                               holdout=holdout, return_info=True)
            except ValueError:
                bar.update(1)
                continue
            if n == ns[-1] and K == Ks[-1]:
                sv = info.subspace.singular_values
            # time-domain NRMSE of the model identified without the held-out lines,
            # scored only when the data hold every harmonic the model produces
            if _produced_harmonics(model, int(K), 'refit') > Kdata:
                unscored.append((int(n), int(K)))
            else:
                val[i, j] = info.holdout_nrmse
            err = _harmonic_response(model, data.omega, Kdata) - Gc
            sse = np.sum(np.abs(err) ** 2)
            mr = 2 * err.size
            Hb = max(K, model.B.nharmonics or 0)                  # K or K + 1 (refit)
            d = (2 * Hb + 1) * n * nu + (4 * K + 1) * ny * n + (2 * K + 1) * ny * nu + n
            aic[i, j] = mr * np.log(max(sse, np.finfo(float).tiny) / mr) + 2 * d
            bar.update(1)
    bar.close()
    if unscored:
        warnings.warn(f"the candidates (n_p, K) {unscored} produce output harmonics beyond "
                      f"the |n| <= {Kdata} of the data and are not scored; give data with "
                      f"{3 * Kmax + 1} harmonics (or the records)", UserWarning, stacklevel=2)
    aic[np.isnan(val)] = np.nan
    score = val if criterion == 'validation' else aic
    if np.all(np.isnan(score)):
        raise ValueError("no candidate structure could be identified from the data")
    if criterion == 'validation':
        # smallest model (n_p first, then K) within 10 % of the best error, or below
        # _TIE (errors a hold's or the data's own imperfection can make)
        ok = score <= max(1.1 * np.nanmin(score), _TIE)
    else:
        ok = score == np.nanmin(score)
    i, j = np.argwhere(ok)[0]
    return StructureSelection(ns, Ks, val, aic, np.asarray(sv if sv is not None else []),
                              (int(ns[i]), int(Ks[j])), criterion)


def _htf_lifted_most(H, period, Kd, K):
    """The lifted response of the data HTF `H` with the most harmonics (at most `Kd`,
    at least `K`) known together on its grid."""
    for k in range(min(Kd, H.nharmonics), K, -1):
        try:
            return lifted_frequency_response(H, period, k)
        except ValueError:
            continue
    return lifted_frequency_response(H, period, K)
