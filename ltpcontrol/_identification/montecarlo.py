"""Parallel Monte-Carlo studies through joblib.

Every draw gets its own generator from ``SeedSequence(seed).spawn(ndraws)``,
so the results do not depend on the number of workers, the backend or the
order in which draws finish.  The backend is joblib's: the default process
pool on one machine, or any backend made active with
``joblib.parallel_config`` (for example Dask's on a cluster).
"""

import multiprocessing
import os
from dataclasses import dataclass, field

import numpy as np
from joblib import Parallel, delayed
from joblib.parallel import get_active_backend
from tqdm.auto import tqdm

from .._core.validation import check_positive_int

__all__ = ['monte_carlo', 'MonteCarloResult']


@dataclass(frozen=True)
class MonteCarloResult:
    """Result of `monte_carlo`.

    Attributes
    ----------
    samples : ndarray, shape (ndraws, ...)
        The value returned by each draw, in draw order.
    mean : ndarray
        Sample mean over the draws.
    cov : ndarray, shape (size, size)
        Sample covariance (``ddof=1``) of the flattened values (real and
        imaginary parts of complex values are not separated: ``E[(x -
        x̄)(x - x̄)ᴴ]``).
    sem : ndarray
        Standard error of the mean, ``sqrt(diag(cov) / ndraws)``, shaped
        like `mean`.
    seed : int
        Entropy of the root `numpy.random.SeedSequence`: passing it as
        `seed` repeats the study (also when it was drawn at random).

    Examples
    --------
    >>> res = ltp.monte_carlo(lambda rng: rng.standard_normal(2), 50, seed=1)
    >>> res.samples.shape, res.cov.shape
    ((50, 2), (2, 2))
    """

    samples: np.ndarray = field(repr=False)
    mean: np.ndarray
    cov: np.ndarray = field(repr=False)
    sem: np.ndarray
    seed: int


def _draw(func, index, seq, args, kwargs):
    """One draw: ``func(rng, *args, **kwargs)`` with the draw's own generator."""
    try:
        return func(np.random.default_rng(seq), *args, **kwargs)
    except Exception as exc:
        raise RuntimeError(f"monte_carlo: draw {index} raised "
                           f"{type(exc).__name__}: {exc}") from exc


def _checked(value, i, first):
    """Draw i's value as an array, checked against draw 0."""
    value = np.asarray(value)
    if value.dtype.kind not in 'biufc':
        raise ValueError(f"draw {i} returned {value.dtype} values; func must return "
                         "numbers (an array of fixed shape)")
    if first is not None and value.shape != first.shape:
        raise ValueError(f"draw {i} returned shape {value.shape}, draw 0 returned "
                         f"{first.shape}: every draw must return the same shape")
    if not np.all(np.isfinite(value)):
        raise ValueError(f"draw {i} returned non-finite values")
    return value


def monte_carlo(func, ndraws, *, seed=None, n_jobs=None, timeout=None, progress=False,
                args=(), kwargs=None):
    """Run a Monte-Carlo study, draws in parallel.

    Parameters
    ----------
    func : callable
        ``func(rng, *args, **kwargs)`` returns the outcome of one draw (an
        array of fixed shape, real or complex), using only the
        `numpy.random.Generator` ``rng`` for randomness.  With process-based
        backends it must be picklable by joblib (module-level functions
        always are).
    ndraws : int
        Number of draws.
    seed : int, optional
        Seed of the root `numpy.random.SeedSequence`; each draw uses a
        spawned child, so the samples are reproducible and independent of
        `n_jobs` and of the backend.
    n_jobs : int, optional
        Number of joblib workers (default: that of the active
        ``joblib.parallel_config``, i.e. 1 unless set; -1 uses all cores).
        With a local backend (processes or threads) it is capped to the
        cores this process may run on (``os.sched_getaffinity``), so that
        workers never outnumber the cores of a shared machine.
    timeout : float, optional
        Seconds after which a draw that has not finished raises
        `TimeoutError` (process backends), so a stuck worker does not hang
        the study.
    progress : bool, optional
        Show a progress bar over the draws (default False).
    args : tuple, optional
        Further positional arguments of `func`.
    kwargs : dict, optional
        Keyword arguments of `func`.

    Returns
    -------
    MonteCarloResult
        Samples, mean, covariance and standard error of the mean.

    Raises
    ------
    TypeError
        If `func` is not callable.
    ValueError
        If the draws return values of different shapes or non-finite
        values (the message names the first offending draw).
    RuntimeError
        If a draw raises; the message names the draw and the original
        exception is chained.

    Notes
    -----
    On a cluster, activate joblib's Dask backend around the same call
    (``dask.distributed`` installed, ``pip install ltpcontrol[cluster]``)::

        from dask.distributed import Client
        import joblib
        client = Client('scheduler-address:8786')
        with joblib.parallel_config(backend='dask'):
            res = ltp.monte_carlo(draw, 1000, seed=1, n_jobs=-1)

    Examples
    --------
    Mean and standard error of the sample variance of 10 Gaussian samples:

    >>> def draw(rng):
    ...     return np.var(rng.standard_normal(10), ddof=1)
    >>> res = ltp.monte_carlo(draw, 400, seed=0)
    >>> bool(abs(res.mean - 1) < 3 * res.sem)
    True
    """
    if not callable(func):
        raise TypeError(f"func must be callable, got {type(func).__name__}")
    ndraws = check_positive_int(ndraws, 'ndraws')
    n_jobs = local_workers(n_jobs)
    kwargs = {} if kwargs is None else dict(kwargs)
    root = np.random.SeedSequence(seed)
    tasks = (delayed(_draw)(func, i, seq, tuple(args), kwargs)
             for i, seq in enumerate(root.spawn(ndraws)))
    runner = Parallel(n_jobs=n_jobs, timeout=timeout, return_as='generator')
    values = []
    try:
        for value in tqdm(runner(tasks), total=ndraws, desc="Monte Carlo",
                          disable=(not progress) or None, leave=False):
            values.append(_checked(value, len(values), values[0] if values else None))
    except multiprocessing.TimeoutError:
        raise TimeoutError(f"monte_carlo: a draw did not finish within timeout={timeout} "
                           f"s ({len(values)} of {ndraws} draws collected)") from None
    samples = np.stack(values)
    flat = samples.reshape(ndraws, -1)
    mean = flat.mean(axis=0)
    dev = flat - mean
    cov = (dev.T @ dev.conj() / (ndraws - 1) if ndraws > 1
           else np.full((flat.shape[1],) * 2, np.nan))
    sem = np.sqrt(np.real(np.diag(cov)) / ndraws)
    shape = samples.shape[1:]
    return MonteCarloResult(samples=samples, mean=mean.reshape(shape), cov=cov,
                            sem=sem.reshape(shape), seed=root.entropy)


def available_cores():
    """Cores this process may run on (its CPU affinity where the OS reports it).

    Examples
    --------
    >>> import os
    >>> from ltpcontrol._identification.montecarlo import available_cores
    >>> 1 <= available_cores() <= (os.cpu_count() or 1)
    True
    """

    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:                       # macOS, Windows
        return max(1, os.cpu_count() or 1)


def local_workers(n_jobs):
    """`n_jobs` capped to `available_cores` when joblib's active backend is local.

    A distributed backend (Dask) keeps `n_jobs` as given; -1 means every
    available core, -2 all but one, as in joblib.

    Examples
    --------
    >>> from ltpcontrol._identification.montecarlo import available_cores, local_workers
    >>> local_workers(10 ** 6) == available_cores(), local_workers(-1) == available_cores()
    (True, True)
    >>> local_workers(None) is None
    True
    """
    if n_jobs is None:
        return None
    n_jobs = int(n_jobs)
    if n_jobs == 0:
        raise ValueError("n_jobs must be a nonzero integer (-1: every available core)")
    backend, _ = get_active_backend()
    if type(backend).__name__ not in _LOCAL_BACKENDS:
        return n_jobs
    cores = available_cores()
    if n_jobs < 0:
        return max(1, cores + 1 + n_jobs)
    return max(1, min(n_jobs, cores))


_LOCAL_BACKENDS = {'LokyBackend', 'MultiprocessingBackend', 'ThreadingBackend',
                   'SequentialBackend'}
