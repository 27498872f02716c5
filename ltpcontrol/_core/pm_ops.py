"""Named pointwise operations of periodic matrices (picklable and storable).

A `PeriodicMatrix` that combines others pointwise keeps the operation as a
callable; the library's own operations are the module-level functions and
small classes below, so that such matrices pickle and can be written by
`ltpcontrol.save`.  Each has a name and JSON parameters (`portable_op`); other
modules register theirs with `register_op`.  Data-backed callables of the
callable form (an interpolant, for example) register with `register_func`
and provide ``_portable() -> (name, params, arrays)`` and a class method
``_from_portable(params, arrays)``.
"""

import numpy as np

__all__ = []

_OPS = {}          # name -> function or class of a pointwise operation
_FUNCS = {}        # name -> class of a data-backed callable


def register_op(name, op):
    """Register a module-level pointwise operation (function or class) under `name`.

    >>> from ltpcontrol._core.pm_ops import register_op, portable_op, _OPS
    >>> register_op('negate', np.negative) is np.negative
    True
    >>> portable_op(np.negative)
    ('negate', {})
    >>> _ = _OPS.pop('negate')
    """
    _OPS[name] = op
    return op


def register_func(name, cls):
    """Register a data-backed callable class under `name`.

    >>> from ltpcontrol._core.pm_ops import register_func, func_class, _FUNCS
    >>> class Table:
    ...     pass
    >>> register_func('table', Table) is Table, func_class('table') is Table
    (True, True)
    >>> _ = _FUNCS.pop('table')
    """
    _FUNCS[name] = cls
    return cls


def portable_op(op):
    """``(name, params)`` of a registered operation, or None.

    >>> from ltpcontrol._core.pm_ops import portable_op, Scale
    >>> portable_op(Scale(2.0)), portable_op(np.add), portable_op(print)
    (('scale', {'c': 2.0}), ('add', {}), None)
    """
    for name, known in _OPS.items():
        if op is known:
            return name, {}
        if isinstance(known, type) and type(op) is known:
            return name, op.params()
    return None


def op_from_portable(name, params):
    """The operation stored as ``(name, params)``.

    >>> from ltpcontrol._core.pm_ops import op_from_portable
    >>> float(op_from_portable('scale', {'c': 3.0})(2.0))
    6.0
    >>> op_from_portable('nope', {})
    Traceback (most recent call last):
    ...
    ValueError: unknown pointwise operation 'nope' in the file
    """
    if name not in _OPS:
        raise ValueError(f"unknown pointwise operation {name!r} in the file")
    op = _OPS[name]
    return op.from_params(params) if isinstance(op, type) else op


def func_class(name):
    """Class of a data-backed callable stored under `name`.

    >>> from ltpcontrol._core.pm_ops import func_class
    >>> func_class('chebyshev').__name__
    'PiecewiseChebyshev'
    """
    if name not in _FUNCS:
        raise ValueError(f"unknown callable form {name!r} in the file")
    return _FUNCS[name]


class Identity:
    """``x -> x`` (a matrix viewed with a multiple of its period)."""

    def __call__(self, x):
        return x

    def params(self):
        return {}

    @classmethod
    def from_params(cls, params):
        return cls()


class Scale:
    """``x -> c x``."""

    def __init__(self, c):
        self.c = float(c)

    def __call__(self, x):
        return self.c * x

    def params(self):
        return {'c': self.c}

    @classmethod
    def from_params(cls, params):
        return cls(params['c'])


class Transpose:
    """``x -> xᵀ`` (per time point)."""

    def __call__(self, x):
        return np.swapaxes(x, 1, 2)

    def params(self):
        return {}

    @classmethod
    def from_params(cls, params):
        return cls()


class Index:
    """``x -> x[:, rows, cols]`` with slices or integer lists."""

    def __init__(self, rows, cols):
        self.rows, self.cols = rows, cols

    def __call__(self, x):
        return x[:, self.rows, self.cols]

    def params(self):
        return {'rows': _encode_index(self.rows), 'cols': _encode_index(self.cols)}

    @classmethod
    def from_params(cls, params):
        return cls(_decode_index(params['rows']), _decode_index(params['cols']))


class Block:
    """Block matrix of the operands, row by row, `widths` operands per row."""

    def __init__(self, widths):
        self.widths = [int(w) for w in widths]

    def __call__(self, *values):
        it = iter(values)
        return np.block([[next(it) for _ in range(w)] for w in self.widths])

    def params(self):
        return {'widths': self.widths}

    @classmethod
    def from_params(cls, params):
        return cls(params['widths'])


def add_series(a, b):
    """Fourier coefficients of a sum.

    Examples
    --------
    >>> from ltpcontrol._core.pm_ops import add_series
    >>> a = np.ones((3, 1, 1)); b = 2 * np.ones((1, 1, 1))      # K = 1 and K = 0
    >>> add_series(a, b)[:, 0, 0].real
    array([1., 3., 1.])
    """

    Ka, Kb = a.shape[0] // 2, b.shape[0] // 2
    K = max(Ka, Kb)
    out = np.zeros((2 * K + 1,) + a.shape[1:], complex)
    out[K - Ka:K + Ka + 1] += a
    out[K - Kb:K + Kb + 1] += b
    return out


def mul_series(a, b):
    """Fourier coefficients of a product.

    Examples
    --------
    (cos t)² = 1/2 + cos(2t)/2: coefficients 1/4, 0, 1/2, 0, 1/4

    >>> from ltpcontrol._core.pm_ops import mul_series
    >>> c = np.array([0.5, 0, 0.5]).reshape(3, 1, 1)
    >>> mul_series(c, c)[:, 0, 0].real
    array([0.25, 0.  , 0.5 , 0.  , 0.25])
    """

    # (PQ)_k = Σ_l P_l Q_{k-l}: a discrete convolution over harmonics
    Ka, Kb = a.shape[0] // 2, b.shape[0] // 2
    out = np.zeros((2 * (Ka + Kb) + 1, a.shape[1], b.shape[2]), complex)
    for i in range(2 * Ka + 1):
        out[i:i + 2 * Kb + 1] += np.einsum('ij,kjl->kil', a[i], b)
    return out


def _encode_index(ix):
    if isinstance(ix, slice):
        return {'slice': [ix.start, ix.stop, ix.step]}
    return {'list': np.asarray(ix, int).tolist()}


def _decode_index(spec):
    if 'slice' in spec:
        return slice(*spec['slice'])
    return np.asarray(spec['list'], int)


for _name, _op in (('add', np.add), ('matmul', np.matmul), ('identity', Identity),
                   ('scale', Scale), ('transpose', Transpose), ('index', Index),
                   ('block', Block)):
    register_op(_name, _op)
