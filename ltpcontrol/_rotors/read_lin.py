"""OpenFAST linearization files (``.lin``) as a rotor model.

OpenFAST linearizes a periodic operating point at several azimuths and
writes one text file per azimuth: a header (rotor speed Ω, azimuth ψ, wind
speed, numbers of states, inputs and outputs), the tables "Order of
continuous states", "... inputs", "... outputs" (operating point, rotating
frame flag T/F, derivative order, description) and the matrices ``A: n x n``,
``B``, ``C``, ``D``.  With S files at uniform azimuths ``ψ_s = ψ_0 + 2πs/S``
the periodic model is the trigonometric interpolant of the samples in
``t = (ψ - ψ_0)/Ω`` (exact for matrices band-limited below S/2 harmonics),
or a zero-order hold.
"""

import glob
import os
import pathlib
import re

import numpy as np
from control.exception import ControlArgument

from .blade_groups import derivative_orders
from .rotor_model import RotorStateSpace, sampled_matrix

__all__ = ['read_lin']

_HEADER = {'rotor_speed': r'Rotor Speed:\s*(\S+)', 'azimuth': r'Azimuth:\s*(\S+)',
           'wind_speed': r'Wind Speed:\s*(\S+)',
           'nstates': r'Number of continuous states:\s*(\d+)',
           'ninputs': r'Number of inputs:\s*(\d+)', 'noutputs': r'Number of outputs:\s*(\d+)'}
_TABLES = {'states': 'Order of continuous states:', 'inputs': 'Order of inputs:',
           'outputs': 'Order of outputs:'}
_ROW = re.compile(r'^\s*(\d+)\s+(.*?)\s+([TF])\s+(?:(\d+)\s+)?(.*?)\s*$')
_MATRIX = re.compile(r'^\s*([A-Za-z]\w*):\s*(\d+)\s*x\s*(\d+)\s*$')


def lin_files(files):
    """The ``.lin`` files named by a path, a folder, a glob pattern or a sequence.

    Examples
    --------
    >>> import pathlib
    >>> from ltpcontrol._rotors.read_lin import lin_files
    >>> data = pathlib.Path(ltp.__file__).parents[1] / 'tests' / 'data'
    >>> [p.name for p in lin_files(str(data / 'ws03.0.*.lin'))]
    ['ws03.0.1.lin', 'ws03.0.13.lin', 'ws03.0.34.lin']
    """
    if isinstance(files, (str, os.PathLike)):
        path = pathlib.Path(files)
        if path.is_dir():
            found = sorted(path.glob('*.lin'), key=_natural)
            if not found:
                raise ValueError(f"the folder {path} holds no .lin file")
            return found
        if any(c in str(files) for c in '*?['):
            found = sorted((pathlib.Path(f) for f in glob.glob(str(files))), key=_natural)
            if not found:
                raise ValueError(f"no file matches {str(files)!r}")
            return found
        return [path]
    try:
        out = [pathlib.Path(f) for f in files]
    except TypeError:
        raise ControlArgument("files must be a path, a folder, a glob pattern or a sequence "
                              f"of paths, got {type(files).__name__}") from None
    if not out:
        raise ValueError("files must name at least one .lin file")
    return out


def _natural(path):
    """Sort key: numbers in the name by value (Main.2.lin before Main.10.lin)."""
    return [int(t) if t.isdigit() else t for t in re.split(r'(\d+)', str(path))]


def read_lin(files, *, interpolation='auto', overflow='raise', atol_azimuth=1e-3,
             remove_states=None, drop_near_tower=None, nblades=3, name=None):
    """Read OpenFAST ``.lin`` files (one per azimuth) into a rotor model.

    Parameters
    ----------
    files : str, path or sequence of them
        The linearization files of one operating point, in any order: a
        file, a folder (all its ``*.lin``), a glob pattern, or a sequence.
    interpolation : {'auto', 'fourier', 'hold', 'samples'}
        How the periodic matrices are formed from uniform azimuth samples:
        'fourier' (trigonometric interpolation), 'hold' (each sample held
        until the next azimuth).  'samples' keeps only the samples (no
        periodic model: evaluating the matrices raises `ValueError`, but
        `mbc` and ``average(method='samples')`` work).  'auto' (default) is
        'fourier' for a uniform complete set and 'samples' otherwise
        (e.g. 3 of 36 azimuths), and a constant model for a rotor at
        standstill.
    overflow : 'raise' or float
        Fields printed as ``****`` (overflow of OpenFAST's format): raise
        a `ValueError` naming file, matrix and entry (default), or
        substitute this value.
    atol_azimuth : float
        Tolerance (rad) on the uniform spacing of the azimuths (OpenFAST
        prints them with 4 decimals).
    remove_states : str, optional
        Regular expression: the states whose descriptions match it are
        removed (rows and columns of A, rows of B, columns of C), as
        MBC3's ``removeStatesPattern``.
    drop_near_tower : float, optional
        Half-width (degrees) of the azimuth ranges around the tower passage
        of a blade (blade b at 180°: ``ψ = 180° - 360°(b-1)/nblades``)
        whose files are left out, as MBC3's ``removeTwrAzimuth`` (4° around
        60°, 180°, 300° for three blades).  The remaining azimuths are
        not uniform: the model keeps samples only (``average(method=
        'samples')``).
    nblades : int
        Number of blades, for `drop_near_tower`.
    name : str, optional
        Name of the model.

    Returns
    -------
    RotorStateSpace
        Period ``2π/Ω``, time origin at the first azimuth (``azimuth0``);
        the rotor speed, azimuths, samples, descriptions, rotating-frame
        flags and derivative orders are attributes.  States, inputs and
        outputs are labelled ``x[i]``, ``u[i]``, ``y[i]``; their
        descriptions are in ``state_descriptions`` etc.

    Raises
    ------
    ValueError
        If a file cannot be parsed, the files describe different models
        (state, input or output tables) or operating points (rotor or wind
        speed), two files have the same azimuth, or ``interpolation`` is
        'fourier' or 'hold' and the azimuths are not uniform.

    Examples
    --------
    >>> import pathlib
    >>> data = pathlib.Path(ltp.__file__).parents[1] / 'tests' / 'data'
    >>> lin = ltp.read_lin(sorted(data.glob('ws03.0.*.lin')))
    >>> lin.nstates, round(lin.rotor_speed, 4), lin.interpolation
    (30, 0.7301, None)
    >>> lin.derivative_order[:3], lin.rotating_states[6:9]
    (array([2, 2, 2]), array([ True,  True,  True]))
    """
    files = lin_files(files)
    if interpolation not in ('auto', 'fourier', 'hold', 'samples'):
        raise ValueError("interpolation must be 'auto', 'fourier', 'hold' or 'samples', got "
                         f"{interpolation!r}")
    if overflow != 'raise':
        try:
            overflow = float(overflow)
        except (TypeError, ValueError):
            raise ControlArgument(f"overflow must be 'raise' or a number, got {overflow!r}") \
                from None
    parsed = [_parse(f, overflow) for f in files]
    if drop_near_tower is not None:
        files, parsed = _drop_near_tower(files, parsed, drop_near_tower, nblades)
    first = parsed[0]
    for f, d in zip(files[1:], parsed[1:]):
        for key in ('nstates', 'ninputs', 'noutputs'):
            if d[key] != first[key]:
                raise ValueError(f"{f} and {files[0]} are linearizations of different models "
                                 f"({key}: {d[key]} and {first[key]})")
        for key in ('states', 'inputs', 'outputs'):
            if [r[2:] for r in d[key]] != [r[2:] for r in first[key]]:
                raise ValueError(f"{f} and {files[0]} are linearizations of different models "
                                 f"(their tables of {key} differ)")
        for key in ('rotor_speed', 'wind_speed'):
            a, b = d[key], first[key]
            if not (np.isnan(a) and np.isnan(b)) and not abs(a - b) <= 1e-3 * max(1.0, abs(b)):
                raise ValueError(f"{f} and {files[0]} are at different operating points "
                                 f"({key}: {a} and {b})")
    omega = float(np.mean([d['rotor_speed'] for d in parsed]))
    psi = np.array([d['azimuth'] for d in parsed])
    order = np.argsort(np.mod(psi - psi.min(), 2 * np.pi), kind='stable')
    parsed, psi = [parsed[i] for i in order], psi[order]
    S = len(psi)
    gaps = np.diff(np.append(psi, psi[0] + 2 * np.pi))
    if S > 1 and np.min(np.abs(gaps)) < atol_azimuth:
        k = int(np.argmin(np.abs(gaps)))
        raise ValueError(f"two files have the same azimuth {psi[k]:.4f} rad: duplicate "
                         "linearizations")
    uniform = bool(np.all(np.abs(gaps - 2 * np.pi / S) <= atol_azimuth))
    standstill = omega == 0
    single = S == 1 and not standstill
    if single and interpolation in ('fourier', 'hold'):
        raise ValueError(f"one azimuth at rotor speed {omega:.4g} rad/s defines no periodic "
                         "model: a constant model would assume the rotating-frame matrices "
                         "do not depend on the azimuth; use mbc and average(method='samples') "
                         "(exact for an isotropic rotor), or linearize at more azimuths")
    if interpolation == 'auto':
        interp = 'fourier' if uniform and not standstill and not single else None
    elif interpolation == 'samples':
        interp = None
    else:
        if not uniform:
            raise ValueError(f"the {S} azimuths {np.round(psi, 4).tolist()} are not uniform "
                             f"over a revolution: no periodic model by {interpolation!r} "
                             "interpolation (use interpolation='samples' and "
                             "average(method='samples'))")
        if standstill:
            raise ValueError("the rotor is at standstill (rotor speed 0): no periodic model")
        interp = interpolation
    samples = tuple(np.array([d[key] for d in parsed]) for key in 'ABCD')
    tables = {key: first[key] for key in ('states', 'inputs', 'outputs')}
    if remove_states is not None:
        samples, tables = _remove_states(samples, tables, remove_states)
    # time axis: ψ(t) = ψ_0 + Ω t; a rotor at standstill is time-invariant
    if standstill:
        period = 2 * np.pi
        if S > 1:
            raise ValueError("several files of a rotor at standstill: their azimuths do not "
                             "follow a time axis")
        mats = [sampled_matrix(M, psi, psi[0], period, 'hold', nm) for M, nm in
                zip(samples, 'ABCD')]
        interp = 'hold'
    else:
        period = 2 * np.pi / omega
        mats = [sampled_matrix(M, psi, psi[0], period, interp, nm)
                for M, nm in zip(samples, 'ABCD')]
    rotor = dict(
        precision=min(d['precision'] for d in parsed),
        sample_speeds=np.array([d['speed_op'][0] for d in parsed]),
        sample_accelerations=np.array([d['speed_op'][1] for d in parsed]),
        rotor_speed=omega, azimuth0=float(psi[0]), azimuths=psi, samples=samples,
        interpolation=interp, frame='rotating',
        state_descriptions=[r[4] for r in tables['states']],
        input_descriptions=[r[4] for r in tables['inputs']],
        output_descriptions=[r[4] for r in tables['outputs']],
        rotating_states=np.array([r[2] for r in tables['states']], bool),
        rotating_inputs=np.array([r[2] for r in tables['inputs']], bool),
        rotating_outputs=np.array([r[2] for r in tables['outputs']], bool),
        derivative_order=_orders(tables['states']),
        wind_speed=None if np.isnan(first['wind_speed']) else first['wind_speed'])
    label = name or os.path.basename(str(files[0])).split('.')[0]
    return RotorStateSpace(*mats, period, rotor=rotor, name=label)


def _parse(path, overflow):
    """Header, tables and matrices of one .lin file."""
    try:
        with open(path) as fh:
            lines = fh.read().splitlines()
    except OSError as exc:
        raise ValueError(f"cannot read {path}: {exc}") from None
    text = '\n'.join(lines[:40])
    out = {}
    for key, pattern in _HEADER.items():
        m = re.search(pattern, text)
        if m is None:
            if key == 'wind_speed':
                out[key] = np.nan
                continue
            raise ValueError(f"{path} is not an OpenFAST linearization file (no "
                             f"'{pattern.split(':')[0]}' in its header)")
        value = m.group(1)
        out[key] = int(value) if key.startswith('n') else _number(value, path, key, overflow)
    for key, title in _TABLES.items():
        out[key] = _table(lines, title, out['n' + key], path)
    out['speed_op'] = _operating_speed(lines, out, path, overflow)
    mats = {}
    i = 0
    while i < len(lines):
        m = _MATRIX.match(lines[i])
        if m and m.group(1) in 'ABCD':
            rows, cols = int(m.group(2)), int(m.group(3))
            data = [ln.split() for ln in lines[i + 1:i + 1 + rows]]
            if len(data) != rows or any(len(r) != cols for r in data):
                raise ValueError(f"{path}: matrix {m.group(1)} is not {rows} x {cols}")
            mats[m.group(1)] = np.array([[_number(v, path, f"{m.group(1)}[{r}, {c}]",
                                                  overflow) for c, v in enumerate(row)]
                                         for r, row in enumerate(data)]).reshape(rows, cols)
            i += rows
        i += 1
    n, nu, ny = out['nstates'], out['ninputs'], out['noutputs']
    if 'A' not in mats and n > 0:
        raise ValueError(f"{path} has no state matrix A")
    shapes = {'A': (n, n), 'B': (n, nu), 'C': (ny, n), 'D': (ny, nu)}
    # relative precision of the printed entries (half a unit of the last digit)
    digits = [len(re.sub(r'\D', '', t.split('E')[0].split('e')[0]).lstrip('0') or '0')
              for t in _text_digits(lines, 40)]
    out['precision'] = 0.5 * 10.0 ** (1 - max(1, min(digits))) if digits else np.nan
    for key, shape in shapes.items():
        M = mats.get(key, np.zeros(shape))
        if M.shape != shape:
            raise ValueError(f"{path}: {key} has shape {M.shape}, expected {shape}")
        out[key] = M
    return out


def _table(lines, title, count, path):
    """Rows ``(index, operating point, rotating, order, description)`` of a table."""
    if count == 0:
        return []
    try:
        start = next(i for i, ln in enumerate(lines) if ln.strip() == title)
    except StopIteration:
        raise ValueError(f"{path} has no table '{title}'") from None
    rows = []
    for ln in lines[start + 3:start + 3 + count]:
        m = _ROW.match(ln)
        if m is None:
            raise ValueError(f"{path}: cannot read the row {ln.strip()!r} of '{title}'")
        rows.append((int(m.group(1)), m.group(2), m.group(3) == 'T',
                     int(m.group(4)) if m.group(4) else 0, m.group(5)))
    if len(rows) != count:
        raise ValueError(f"{path}: '{title}' has {len(rows)} rows, expected {count}")
    return rows


def _number(text, path, where, overflow):
    if '*' in text:
        if overflow == 'raise':
            raise ValueError(f"{path}: {where} overflowed OpenFAST's output format "
                             f"({text!r}); increase the output precision or pass "
                             "overflow=<value>")
        return overflow
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"{path}: cannot read {where} = {text!r} as a number") from None


def _orders(rows):
    """Derivative orders of the states; inferred from the descriptions in old files."""
    order = np.array([r[3] for r in rows], int)
    if len(order) and np.all(order == 0):
        # files of OpenFAST before v2.2 have no 'Derivative Order' column
        order = derivative_orders([r[4] for r in rows])
    return order


def _text_digits(lines, count):
    """Up to `count` mantissa strings of nonzero entries of the matrix A."""
    out = []
    for i, ln in enumerate(lines):
        if re.match(r'^\s*A:\s*\d+\s*x\s*\d+', ln):
            for row in lines[i + 1:]:
                for tok in row.split():
                    try:
                        if float(tok) != 0:
                            out.append(tok)
                    except ValueError:
                        return out
                    if len(out) >= count:
                        return out
            break
    return out


def _remove_states(samples, tables, pattern):
    """Samples and tables without the states whose descriptions match `pattern`."""
    try:
        regex = re.compile(pattern)
    except (re.error, TypeError):
        raise ControlArgument(f"remove_states must be a regular expression, got "
                              f"{pattern!r}") from None
    keep = np.array([not regex.search(r[4]) for r in tables['states']])
    if not np.any(~keep):
        raise ValueError(f"remove_states {pattern!r} matches no state description")
    A, B, C, D = samples
    samples = (A[:, keep][:, :, keep], B[:, keep], C[:, :, keep], D)
    tables = dict(tables, states=[r for r, k in zip(tables['states'], keep) if k])
    return samples, tables


def _operating_speed(lines, out, path, overflow):
    """Ω and Ω̇ of the operating point, as MBC3 takes them.

    The time derivatives at the operating point of the generator azimuth
    (``DOF_GeAz``) and of its rate, plus those of the drivetrain torsion
    (``DOF_DrTr``); the header's rotor speed and Ω̇ = 0 when the file has no
    such states (or no table of state derivatives).
    """
    omega, domega = out['rotor_speed'], 0.0
    n = out['nstates']
    title = 'Order of continuous state derivatives:'
    if n == 0 or not any(ln.strip() == title for ln in lines):
        return omega, domega
    try:
        rows = _table(lines, title, n, path)
        xdop = [_number(r[1].split()[0], path, 'an operating point', overflow)
                if r[1].split() else 0.0 for r in rows]
    except ValueError:
        return omega, domega
    desc = [r[4] for r in out['states']]
    n2 = sum(1 for r in out['states'] if r[3] == 2)
    half = n2 // 2
    for i in range(half):
        if 'DOF_GeAz' in desc[i]:
            omega, domega = xdop[i], xdop[i + half]
            break
    for i in range(half):
        if 'DOF_DrTr' in desc[i]:
            omega, domega = omega + xdop[i], domega + xdop[i + half]
            break
    return float(omega), float(domega)


def _drop_near_tower(files, parsed, width, nblades):
    """The files whose azimuth is farther than `width` degrees from a tower passage."""
    try:
        width = float(width)
    except (TypeError, ValueError):
        raise ControlArgument(f"drop_near_tower must be a number of degrees, got "
                              f"{width!r}") from None
    if not 0 <= width < 180:
        raise ValueError(f"drop_near_tower must be in [0, 180) degrees, got {width}")
    N = int(nblades)
    passages = np.mod(180.0 - 360.0 * np.arange(N) / N, 360.0)
    keep = []
    for f, d in zip(files, parsed):
        psi = np.mod(np.degrees(d['azimuth']), 360.0)
        gap = np.abs(np.mod(psi - passages + 180.0, 360.0) - 180.0)
        keep.append(bool(np.all(gap >= width)))
    if not any(keep):
        raise ValueError(f"drop_near_tower={width}: every file is within {width} degrees of "
                         "a tower passage")
    return ([f for f, k in zip(files, keep) if k], [d for d, k in zip(parsed, keep) if k])
