"""BLAS threads inside loops of small matrix products.

A multithreaded BLAS (OpenBLAS, MKL) wakes its thread pool for every
product.  For the small products of the library's inner loops (step
transitions of a few states, QR sweeps, harmonic blocks) the start-up and
synchronisation of the pool cost far more than the product itself, and
on a loaded machine a product of microseconds can wait milliseconds for
busy cores.  `small_blas` runs such a loop with one BLAS thread when the
matrices are small, and leaves BLAS alone for large matrices, whose
products do gain from threads.  The limit is set with threadpoolctl and
restored on exit; it applies to the calling process only.

Users need not set ``OMP_NUM_THREADS``/``OPENBLAS_NUM_THREADS``; an
explicit ``threadpoolctl.threadpool_limits`` around a call still applies
outside the library's hot loops.
"""

import contextlib
import threading

__all__ = []

#: matrices of at most this dimension run their products on one BLAS thread
SMALL_DIM = 96

_CONTROLLER = None
_STATE = threading.local()


def _controller():
    global _CONTROLLER
    if _CONTROLLER is None:
        try:
            from threadpoolctl import ThreadpoolController
            _CONTROLLER = ThreadpoolController()
        except Exception:          # threadpoolctl missing or failing: no limit
            _CONTROLLER = False
    return _CONTROLLER


@contextlib.contextmanager
def small_blas(dim=0):
    """Context in which BLAS runs on one thread when ``dim <= SMALL_DIM``.

    Nested uses enter the limit once (the outermost applies it).

    Parameters
    ----------
    dim : int
        Largest matrix dimension of the products in the block.

    Examples
    --------
    >>> from ltpcontrol._core.threads import small_blas
    >>> with small_blas(4):
    ...     x = np.ones((4, 4)) @ np.ones((4, 4))
    >>> float(x[0, 0])
    4.0
    """
    depth = getattr(_STATE, 'depth', 0)
    ctl = _controller() if dim <= SMALL_DIM and depth == 0 else False
    if not ctl:
        _STATE.depth = depth + 1
        try:
            yield
        finally:
            _STATE.depth = depth
        return
    _STATE.depth = depth + 1
    try:
        with ctl.limit(limits=1, user_api='blas'):
            yield
    finally:
        _STATE.depth = depth
