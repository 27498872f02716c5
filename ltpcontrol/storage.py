"""Portable files of systems, periodic matrices and HTFs (`save`, `load`).

A file is a NumPy ``.npz`` archive without pickled objects: it loads with
``np.load(path, allow_pickle=False)``, so reading a file never executes
code.  It holds

* ``format`` = ``'ltpcontrol'`` and ``version`` (an integer, `FORMAT_VERSION`);
* ``tree``: a JSON description of the object, in which every array is a
  reference ``{"array": "a<i>"}`` to the archive member ``a<i>``;
* the arrays, stored exactly (floats in JSON are written by ``repr``, which
  round-trips), so a loaded object equals the saved one bit for bit.

Object kinds: `PeriodicMatrix` in the Fourier, switching (sampled with
``kind='hold'`` included) and data-backed callable forms (the solutions and
gains of `care` and `lqr`, Floquet transforms) and their pointwise
combinations by the library's operations; `LTPStateSpace` (continuous and
discrete time, identified models included); `DiscreteLTPSystem` (its
matrices step by step, dimensions varying with k); `HTFData`; `HTFModel` (stored
as its system and options and rebuilt on load); `CampbellDiagram` (its
tracks, labels and crossings, without the modes of every value).  A matrix defined by an
arbitrary Python function cannot be stored: sample it first.
"""

import json
import os
import zipfile

import numpy as np

from ._core import pm_ops
from ._core.ltpsys import LTPStateSpace
from ._core.tvsystem import DiscreteLTPSystem
from ._core.periodic_matrix import PeriodicMatrix
from ._frequency.htf import HTFData, HTFModel
from ._rotors.campbell import CampbellDiagram

__all__ = ['save', 'load', 'FORMAT_VERSION']

#: Version of the file format written by `save`; `load` reads this and older.
FORMAT_VERSION = 1


def save(path, obj):
    """Write a system, periodic matrix or HTF to a portable ``.npz`` file.

    Parameters
    ----------
    path : str or os.PathLike
        File name (``.npz`` is appended by NumPy when missing).
    obj : LTPStateSpace, DiscreteLTPSystem, PeriodicMatrix, HTFData, HTFModel or CampbellDiagram
        Object to store (a Campbell diagram without the Floquet modes of
        its values).

    Raises
    ------
    TypeError
        If `obj` is of another kind, or is (or contains) a periodic matrix
        defined by an arbitrary Python function, which cannot be stored
        without code: sample it, e.g.
        ``PeriodicMatrix.from_samples(P.sample(N), P.period)``.

    See Also
    --------
    load

    Examples
    --------
    >>> import os, tempfile
    >>> sys = ltp.ltpss([[-1.0]], [[1.0]], [[1.0]], 0, period=1.0, name='plant')
    >>> path = os.path.join(tempfile.mkdtemp(), 'plant.npz')
    >>> ltp.save(path, sys)
    >>> ltp.load(path)
    <LTPStateSpace plant: ['u[0]'] -> ['y[0]'], period=1>
    """
    arrays = {}
    tree = _encode(obj, arrays)
    members = {'format': np.array('ltpcontrol'), 'version': np.array(FORMAT_VERSION),
               'tree': np.array(json.dumps(tree))}
    members.update(arrays)
    np.savez(path, **members)


def load(path):
    """Read an object written by `save`.

    The file is read with ``allow_pickle=False``: no code is executed.

    Parameters
    ----------
    path : str or os.PathLike
        File name.

    Returns
    -------
    LTPStateSpace, DiscreteLTPSystem, PeriodicMatrix, HTFData, HTFModel or CampbellDiagram

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        If the file is corrupt or truncated, is not an ltpcontrol file, or
        was written by a newer format version.

    Examples
    --------
    >>> import os, tempfile
    >>> P = ltp.PeriodicMatrix([[[0.5]], [[1.0]], [[0.5]]], period=2.0)
    >>> path = os.path.join(tempfile.mkdtemp(), 'P.npz')
    >>> ltp.save(path, P)
    >>> Q = ltp.load(path)
    >>> bool(np.array_equal(Q.fourier(1), P.fourier(1)))
    True
    """
    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"no such file: {path!r}")
    try:
        with np.load(path, allow_pickle=False) as data:
            members = {k: data[k] for k in data.files}
    except (zipfile.BadZipFile, EOFError, OSError, ValueError, KeyError) as exc:
        raise ValueError(f"{path!r} is not a readable ltpcontrol file (corrupt or "
                         f"truncated): {exc}") from None
    if 'format' not in members or str(members['format']) != 'ltpcontrol':
        raise ValueError(f"{path!r} is not an ltpcontrol file (no 'format' member)")
    try:
        version = int(members['version'])
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{path!r} has no valid format version") from None
    if version > FORMAT_VERSION:
        raise ValueError(f"{path!r} was written in format version {version}; this "
                         f"ltpcontrol reads versions up to {FORMAT_VERSION}: upgrade "
                         "ltpcontrol to read it")
    if version < 1:
        raise ValueError(f"{path!r} has an invalid format version {version}")
    try:
        tree = json.loads(str(members['tree']))
        return _decode(tree, members)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise ValueError(f"{path!r} is corrupt: its contents do not describe a valid "
                         f"object ({type(exc).__name__}: {exc})") from None


#
# Encoding
#

def _array(value, arrays):
    key = f"a{len(arrays)}"
    arrays[key] = np.asarray(value)
    return {'array': key}


def _encode(obj, arrays):
    # exact types: a subclass would come back as its base class
    if type(obj) is PeriodicMatrix:
        return _encode_matrix(obj, arrays)
    if type(obj) is LTPStateSpace:
        return {'kind': 'LTPStateSpace', 'period': obj.period, 'dt': float(obj.dt),
                'name': obj.name, 'inputs': list(obj.input_labels),
                'outputs': list(obj.output_labels), 'states': list(obj.state_labels),
                **{k: _encode_matrix(getattr(obj, k), arrays) for k in 'ABCD'}}
    if type(obj) is DiscreteLTPSystem:      # the matrices of every step, any shapes
        return {'kind': 'DiscreteLTPSystem', 'dt': float(obj.dt), 'name': obj.name,
                **{k: [_array(M, arrays) for M in getattr(obj, k)] for k in 'ABCD'}}
    if type(obj) is HTFData:
        return {'kind': 'HTFData', 'period': obj.period, 'name': obj.name,
                'inputs': list(obj.input_labels), 'outputs': list(obj.output_labels),
                'components': _array(obj._components, arrays),
                'omega': _array(obj.omega, arrays),
                'std': None if obj.std is None else _array(obj.std, arrays)}
    if type(obj) is HTFModel:
        sys, internal, method = obj._source
        return {'kind': 'HTFModel', 'nharmonics': obj.nharmonics,
                'internal_harmonics': internal, 'method': method,
                'sys': _encode(sys, arrays)}
    if type(obj) is CampbellDiagram:
        # the tracks and their data; the Floquet modes of every value are not stored
        node = {'kind': 'CampbellDiagram', 'labels': [str(x) for x in obj.labels],
                'xlabel': obj.xlabel, 'frame': obj.frame,
                'crossings': [[int(t), int(n), float(v), float(f)]
                              for t, n, v, f in obj.crossings]}
        for key in _CAMPBELL_ARRAYS:
            value = getattr(obj, key)
            node[key] = None if value is None else _array(value, arrays)
        return node
    raise TypeError(f"save: cannot store a {type(obj).__name__}; supported are "
                    "LTPStateSpace, DiscreteLTPSystem, PeriodicMatrix, HTFData, HTFModel and "
                    "CampbellDiagram")


_CAMPBELL_ARRAYS = ('values', 'exponents', 'frequency', 'damped_frequency', 'damping',
                    'principal_harmonic', 'mac', 'rotor_speed', 'indices', 'wind_speed')


def _encode_matrix(P, arrays):
    node = {'kind': 'PeriodicMatrix', 'period': P.period, 'shape': list(P.shape),
            'breakpoints': _array(P.breakpoints, arrays)}
    form, data = P._parts()
    if form == 'fourier':
        node.update(form='fourier', coeffs=_array(data, arrays))
    elif form == 'switching':
        node.update(form='switching', times=_array(data[1], arrays),
                    pieces=[_encode_matrix(p, arrays) for p in data[0]])
    elif form == 'function':
        portable = getattr(data, '_portable', None)
        if portable is None:
            name = getattr(data, '__qualname__', type(data).__name__)
            raise TypeError(
                f"save: the periodic matrix is defined by the Python function {name}, "
                "which cannot be stored without code; sample it first, e.g. "
                "PeriodicMatrix.from_samples(P.sample(N), P.period) (Fourier "
                "interpolant) or kind='hold'")
        name, params, data = portable()
        node.update(form='function', name=name, params=params,
                    data={k: _array(v, arrays) for k, v in data.items()})
    else:
        op, operands = data
        found = pm_ops.portable_op(op)
        if found is None:
            name = getattr(op, '__qualname__', type(op).__name__)
            raise TypeError(
                f"save: the periodic matrix combines others by the Python function "
                f"{name}, which cannot be stored without code; sample it first, e.g. "
                "PeriodicMatrix.from_samples(P.sample(N), P.period)")
        node.update(form='combine', op=found[0], params=found[1],
                    operands=[_encode_matrix(o, arrays) for o in operands])
    return node


#
# Decoding (validated: a corrupt file gives ValueError)
#

def _get(ref, members):
    if not isinstance(ref, dict) or 'array' not in ref:
        raise ValueError("an array reference is malformed")
    key = ref['array']
    if key not in members:
        raise ValueError(f"the array member {key!r} is missing")
    return members[key]


def _decode(node, members):
    kind = node['kind']
    if kind == 'PeriodicMatrix':
        return _decode_matrix(node, members)
    if kind == 'LTPStateSpace':
        mats = [_decode_matrix(node[k], members) for k in 'ABCD']
        return LTPStateSpace(*mats, float(node['period']), dt=float(node['dt']),
                             name=node['name'], inputs=node['inputs'],
                             outputs=node['outputs'], states=node['states'])
    if kind == 'DiscreteLTPSystem':         # the constructor checks the dimension chain
        mats = [[np.asarray(_get(ref, members), float) for ref in node[k]] for k in 'ABCD']
        if any(M.ndim != 2 for seq in mats for M in seq) or not mats[0]:
            raise ValueError("a discrete periodic system's matrices are not 2D")
        return DiscreteLTPSystem(*mats, dt=float(node['dt']), name=node['name'])
    if kind == 'HTFData':
        std = None if node['std'] is None else _get(node['std'], members)
        return HTFData(_get(node['components'], members), _get(node['omega'], members),
                       float(node['period']), std=std, name=node['name'],
                       inputs=node['inputs'], outputs=node['outputs'])
    if kind == 'HTFModel':
        return HTFModel(_decode(node['sys'], members), int(node['nharmonics']),
                        internal_harmonics=node['internal_harmonics'], method=node['method'])
    if kind == 'CampbellDiagram':
        arrays = {key: None if node[key] is None else _get(node[key], members)
                  for key in _CAMPBELL_ARRAYS}
        K, n = arrays['frequency'].shape
        if arrays['values'].shape != (K,) or arrays['exponents'].shape != (K, n):
            raise ValueError("a Campbell diagram's arrays do not match")
        return CampbellDiagram(**arrays, modes=(), labels=tuple(node['labels']),
                               xlabel=node['xlabel'], frame=node['frame'],
                               crossings=[(int(t), int(n_), float(v), float(f))
                                          for t, n_, v, f in node['crossings']])
    raise ValueError(f"unknown object kind {kind!r}")


def _decode_matrix(node, members):
    if node.get('kind') != 'PeriodicMatrix':
        raise ValueError("a periodic matrix node is malformed")
    period = float(node['period'])
    shape = tuple(int(s) for s in node['shape'])
    if len(shape) != 2 or min(shape) < 0 or not period > 0:
        raise ValueError("a periodic matrix has an invalid shape or period")
    bps = np.asarray(_get(node['breakpoints'], members), float)
    form = node['form']
    if form == 'fourier':
        coeffs = _get(node['coeffs'], members)
        if coeffs.ndim != 3 or coeffs.shape[1:] != shape or coeffs.shape[0] % 2 != 1 \
                or not np.iscomplexobj(coeffs):
            raise ValueError("Fourier coefficients of invalid shape or type")
        return PeriodicMatrix._assemble(period, shape, bps, 'fourier', coeffs)
    if form == 'switching':
        times = np.asarray(_get(node['times'], members), float)
        pieces = [_decode_matrix(p, members) for p in node['pieces']]
        if len(pieces) != len(times) or any(p.shape != shape for p in pieces):
            raise ValueError("switching pieces do not match their times or shape")
        return PeriodicMatrix._assemble(period, shape, bps, 'switching', (pieces, times))
    if form == 'function':
        cls = pm_ops.func_class(node['name'])
        data = {k: _get(v, members) for k, v in node['data'].items()}
        func = cls._from_portable(node['params'], data)
        return PeriodicMatrix._assemble(period, shape, bps, 'function', func)
    if form == 'combine':
        op = pm_ops.op_from_portable(node['op'], node['params'])
        operands = [_decode_matrix(o, members) for o in node['operands']]
        return PeriodicMatrix._assemble(period, shape, bps, 'combine', (op, operands))
    raise ValueError(f"unknown periodic matrix form {form!r}")
