"""Campbell diagrams from OpenFAST linearizations at several operating points.

OpenFAST writes, for every operating point (a wind speed with its rotor
speed), one ``.lin`` file per azimuth, ``<name>.<k>.lin``.  A study is a
folder of such files (or a tree of folders, one per operating point).  At
every operating point the files are read (`read_lin`), transformed to
multi-blade coordinates (`mbc`, blade groups from the descriptions) and
analysed either as MBC3 and its ports do — the azimuth average of the
multi-blade model and its eigenvalues — or by Floquet theory of the
periodic multi-blade model; the modes are tracked over the operating
points by shape (`campbell`) and named from the degrees of freedom that
participate (`mode_labels`).
"""

import collections
import pathlib
import re
from dataclasses import replace

import numpy as np
from control.exception import ControlArgument

from .._core.ltpsys import ltpss
from .campbell import campbell
from .mbc import mbc
from .mode_labels import mode_labels
from .read_lin import lin_files, read_lin

__all__ = ['campbell_lin', 'operating_points']

_AZIMUTH_INDEX = re.compile(r'^(.*?)(?:\.(\d+))?\.lin$', re.I)


def operating_points(source):
    """The ``.lin`` files of a study grouped by operating point.

    Parameters
    ----------
    source : str, path or sequence
        A folder (searched recursively), a glob pattern, a sequence of
        files, or a sequence of sequences (one per operating point).
        Files ``<name>.<k>.lin`` of one folder with the same ``<name>`` are
        the azimuths of one operating point.

    Returns
    -------
    list of list of pathlib.Path

    Examples
    --------
    >>> import pathlib
    >>> from ltpcontrol._rotors.campbell_lin import operating_points
    >>> data = pathlib.Path(ltp.__file__).parents[1] / 'tests' / 'data'
    >>> [[p.name for p in op] for op in operating_points(str(data / 'ws03.0.*.lin'))]
    [['ws03.0.1.lin', 'ws03.0.13.lin', 'ws03.0.34.lin']]
    """
    if not isinstance(source, (str, pathlib.PurePath)) and not hasattr(source, '__fspath__'):
        try:
            items = list(source)
        except TypeError:
            raise ControlArgument("source must be a folder, a glob pattern or a sequence of "
                                  f"files, got {type(source).__name__}") from None
        if items and all(not isinstance(i, (str, pathlib.PurePath)) for i in items):
            return [lin_files(i) for i in items]
        files = lin_files(items)
    else:
        path = pathlib.Path(source)
        if path.is_dir():
            files = sorted(path.rglob('*.lin'))
            if not files:
                raise ValueError(f"the folder {path} holds no .lin file")
        else:
            files = lin_files(source)
    groups = collections.OrderedDict()
    for f in files:
        m = _AZIMUTH_INDEX.match(f.name)
        groups.setdefault((str(f.parent), m.group(1)), []).append(f)
    return list(groups.values())


def campbell_lin(source, nblades=3, *, method='average', x='auto', per_rev=(1, 2, 3),
                 remove_states=None, nharmonics=None, label_rule='participation',
                 blade_length=None, tower_length=None):
    """Campbell diagram of OpenFAST linearizations at several operating points.

    Parameters
    ----------
    source : str, path or sequence
        The study: a folder (searched recursively; ``<name>.<k>.lin`` files
        of one folder are the azimuths of one operating point), a glob
        pattern, a sequence of files, or a sequence of sequences of files
        (one per operating point).
    nblades : int
        Number of blades.
    method : {'average', 'floquet'}
        'average' (default): eigenvalues of the azimuth average of the
        multi-blade model over the linearized azimuths, as MBC3 and its
        ports compute them (exact for an isotropic rotor).  'floquet':
        Floquet modes of the periodic multi-blade model (needs uniform
        azimuths over a revolution at every operating point; a model that
        is time-invariant to the data's precision is solved by ``eig``).
    x : {'auto', 'rotor_speed', 'wind_speed'}
        Sweep axis: rotor speed (rad/s) or wind speed (m/s); 'auto' takes
        the wind speed when the operating points have distinct ones.
    per_rev : sequence of int
        The nP lines of the diagram and its crossings.
    remove_states : str, optional
        Regular expression of state descriptions to remove (see
        `read_lin`).
    nharmonics : int, optional
        Passed to `floquet_modes` (``method='floquet'``).
    label_rule : {'participation', 'openfast'}
        How the modes are named (`mode_labels`' `rule`): by the degrees of
        freedom that participate, or as openfast_toolbox's
        ``IdentifyModes`` names them.
    blade_length, tower_length : float, optional
        ``label_rule='openfast'``: the lengths the toolbox scales the
        eigenvectors by (see `mode_labels`).

    Returns
    -------
    CampbellDiagram
        Sorted along `x`, with ``labels`` naming each track (``'1st tower
        FA'``, ``'1st flap BW'``, ``'drivetrain'``, ...: the most frequent
        name of its modes), the rotor and wind speeds, and the multi-blade
        frame.  ``plot(x='rpm', frequency_unit='Hz', damping='percent')``,
        ``to_dataframe()`` and ``to_csv()`` give the usual views.

    Raises
    ------
    ValueError
        If two operating points share the axis value, an operating point
        has no periodic model for ``method='floquet'``, or the models have
        different states, or `label_rule` is unknown.

    Examples
    --------
    >>> import pathlib
    >>> data = pathlib.Path(ltp.__file__).parents[1] / 'tests' / 'data'
    >>> cd = ltp.campbell_lin(str(data / 'ws0*.lin'))    # standstill and 3 m/s
    >>> cd.values, cd.xlabel
    (array([0., 3.]), 'wind speed [m/s]')
    >>> t = cd.table()
    >>> at3 = t['value'] == 3.0
    >>> [(lab, round(float(f), 4)) for lab, f in zip(t['label'][at3],
    ...                                               t['frequency_hz'][at3])][2:5]
    [('1st tower SS', 0.314), ('1st tower FA', 0.3314), ('drivetrain', 0.6263)]

    Named as OpenFAST's Campbell tools name them (the NREL 5 MW blade and
    tower lengths): the 0.63 Hz mode, whose frequency depends most on the
    drivetrain's stiffness, is their 1st edge collective.

    >>> cd = ltp.campbell_lin(str(data / 'ws0*.lin'), label_rule='openfast',
    ...                       blade_length=61.5, tower_length=87.6)
    >>> t = cd.table()
    >>> at3 = t['value'] == 3.0
    >>> [(lab, round(float(f), 4)) for lab, f in zip(t['label'][at3],
    ...                                               t['frequency_hz'][at3])][2:5]
    [('1st tower SS', 0.314), ('1st tower FA', 0.3314), ('1st edge collective', 0.6263)]
    """
    if label_rule not in ('participation', 'openfast'):
        raise ValueError(f"label_rule must be 'participation' or 'openfast', got {label_rule!r}")
    if method not in ('average', 'floquet'):
        raise ValueError(f"method must be 'average' or 'floquet', got {method!r}")
    if x not in ('auto', 'rotor_speed', 'wind_speed'):
        raise ValueError(f"x must be 'auto', 'rotor_speed' or 'wind_speed', got {x!r}")
    ops = operating_points(source)
    models, frames = [], []
    for files in ops:
        lin = read_lin(files, remove_states=remove_states)
        if np.any(lin.rotating_states):
            nr, _ = mbc(lin, nblades=nblades)
        else:
            nr = lin
        models.append((lin, nr))
        frames.append(nr.frame)
    speeds = np.array([lin.rotor_speed for lin, _ in models])
    winds = np.array([np.nan if lin.wind_speed is None else lin.wind_speed
                      for lin, _ in models])
    if x == 'auto':
        x = 'wind_speed' if np.all(np.isfinite(winds)) and \
            len(np.unique(winds)) == len(winds) and len(winds) > 1 else 'rotor_speed'
    axis = winds if x == 'wind_speed' else speeds
    if x == 'wind_speed' and not np.all(np.isfinite(winds)):
        raise ValueError("x='wind_speed': some files have no wind speed")
    order = np.argsort(axis, kind='stable')
    axis = axis[order]
    same = np.flatnonzero(np.diff(axis) == 0)
    if len(same):
        a, b = ops[order[same[0]]][0], ops[order[same[0] + 1]][0]
        raise ValueError(f"the operating points of {a} and {b} have the same {x} "
                         f"{axis[same[0]]:g}: give them separately or sweep the other axis")
    systems = []
    for k in order:
        lin, nr = models[k]
        period = 2 * np.pi / lin.rotor_speed if lin.rotor_speed > 0 else 2 * np.pi
        if method == 'average':
            av = nr.average(method='samples')
            systems.append(ltpss(av.A, av.B, av.C, av.D, period=period))
        else:
            if nr.interpolation is None:
                raise ValueError(f"the operating point of {ops[k][0]} has "
                                 f"{len(lin.azimuths)} azimuth(s), not uniform over a "
                                 "revolution: no periodic model for method='floquet' (use "
                                 "method='average')")
            systems.append(nr)
    sizes = {s.nstates for s in systems}
    if len(sizes) != 1:
        raise ValueError(f"the operating points have different numbers of states {sizes}")
    values = axis.astype(float)
    lookup = dict(zip(values.tolist(), systems))
    if len(values) == 1:
        raise ValueError("source holds a single operating point: a Campbell diagram needs "
                         "at least two (use floquet_modes for one)")
    # multi-blade (or averaged) models: the principal harmonic is the physical branch
    cd = campbell(lookup.__getitem__, values, rotor_speed=speeds[order], per_rev=per_rev,
                  nharmonics=nharmonics, n_jobs=1, branch='principal')
    names = [mode_labels(m, models[k][1], label_rule, blade_length=blade_length,
                         tower_length=tower_length) for m, k in zip(cd.modes, order)]
    labels = []
    for track in range(cd.frequency.shape[1]):
        seen = collections.Counter(names[i][cd.indices[i, track]] for i in range(len(values)))
        # the most frequent name; a whirl direction is preferred to a standing 'cyclic',
        # a name to none
        labels.append(max(seen, key=lambda lab: (seen[lab], lab != 'unidentified',
                                                 not lab.endswith('cyclic'))))
    frame = frames[0] if len(set(frames)) == 1 else None
    return replace(cd, labels=tuple(labels), wind_speed=winds[order],
                   xlabel='wind speed [m/s]' if x == 'wind_speed' else 'rotor speed [rad/s]',
                   frame=frame)
