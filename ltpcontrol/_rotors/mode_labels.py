"""Names of wind-turbine modes from the degrees of freedom that participate.

The participation of state j in mode i is ``|w_jᴴ v_j|`` with the right and
left eigenvectors (Floquet vectors) v, w normalised by ``wᴴv = 1``; it is
free of units and sums to 1 over the states (for a non-defective mode).
The states are folded onto their degrees of freedom (displacement and rate
together), named from OpenFAST's descriptions (``1st tower fore-aft``,
``1st flapwise bending-mode DOF of blade 1``, ``Drivetrain``...), and the
mode takes the name of the degree of freedom family with the largest share.
Blade degrees of freedom in multi-blade coordinates are further told apart:
*collective* when the collective coordinate carries most of the blade
share, otherwise a whirl, *forward* (FW) when the cyclic pair
``(a_c, a_s)`` of a mode ``e^{λt}`` with ``Im λ > 0`` turns with the rotor
(``a_s = -j a_c``), *backward* (BW) when against it (``a_s = j a_c``), and
*cyclic* when it does not turn (a standing mode, e.g. at standstill).

Compared with openfast_toolbox's ``IdentifyModes``: that routine looks at
the magnitudes of the displacement and first-order entries of unit-norm
eigenvectors, takes for each state the mode where its magnitude peaks,
names a mode after such a state (in the order of its list of names when
several peak there, each name once), and guesses from the largest entries
when no state peaks at a mode; cyclic modes are "regressive" and
"progressive" in order of frequency.  ``mode_labels(..., rule='openfast')``
applies that rule (names equal to the toolbox's on every mode it names in
its test files).  Where a single state clearly dominates both rules agree
(31 of the 37 modes it names on its test files Standstill_ForID_ED,
StandstillSemi_ForID_EDHD and the rotating NREL 5 MW files, with BW/FW
for its regressive/progressive).  They differ on purpose where its
measure misleads: eigenvector magnitudes depend on the states' units and
favour low frequencies (a HydroDyn radiation mode is named a flap mode,
tower modes flap and edge modes), and list order or a guess decides (a
drivetrain mode is named edge-collective and the reverse).  There the
participation factors name the degree of freedom whose stiffness the
frequency depends on most.
"""

import re

import numpy as np

from .blade_groups import _rate_free, blade_key

__all__ = ['mode_labels', 'dof_name']

_FAMILIES = [
    (r'tower fore-aft', 'tower FA'), (r'tower side-to-side', 'tower SS'),
    (r'flapwise', 'flap'), (r'edgewise', 'edge'), (r'[Dd]rivetrain', 'drivetrain'),
    (r'[Gg]enerator', 'generator'), (r'[Nn]acelle yaw', 'nacelle yaw'),
    (r'[Pp]latform horizontal surge', 'platform surge'),
    (r'[Pp]latform horizontal sway', 'platform sway'),
    (r'[Pp]latform vertical heave', 'platform heave'), (r'[Pp]latform roll', 'platform roll'),
    (r'[Pp]latform pitch', 'platform pitch'), (r'[Pp]latform yaw', 'platform yaw'),
    (r'[Tt]eeter', 'teeter'), (r'^BD_', 'blade'), (r'^AD ', 'aerodynamics'),
    (r'^HD ', 'hydrodynamics'), (r'^SrvD', 'structural control'), (r'^MD ', 'mooring'),
]
_ORDER = re.compile(r'\b(1st|2nd|3rd|\dth)\b')
_COORD = re.compile(r'_(0|c1|s1|d|[cs]\d+)$')


def dof_name(description):
    """Degree-of-freedom family of a state, from its OpenFAST description.

    Examples
    --------
    >>> from ltpcontrol._rotors.mode_labels import dof_name
    >>> dof_name('ED First time derivative of 2nd flapwise bending-mode DOF of blade 3 '
    ...          '(internal DOF index = DOF_BF(3,2)), m/s')
    '2nd flap'
    >>> dof_name('ED 1st tower side-to-side bending mode DOF (internal DOF index = '
    ...          'DOF_TSS1), m')
    '1st tower SS'
    """
    for pattern, name in _FAMILIES:
        if re.search(pattern, description):
            m = _ORDER.search(description)
            return f'{m.group(1)} {name}' if m and name in ('tower FA', 'tower SS', 'flap',
                                                          'edge') else name
    key, _ = blade_key(description)
    text = re.sub(r'\s*\(internal DOF index = [^()]*(?:\([^()]*\))?[^()]*\)', '',
                  description)
    return (key or text).replace('First time derivative of ', '').split(',')[0].strip()


def mode_labels(modes, sys, rule='participation', *, blade_length=None, tower_length=None):
    """A name for every mode of `modes` (a `FloquetModes` of `sys`).

    Parameters
    ----------
    modes : FloquetModes
        Modes of `sys` (e.g. ``floquet_modes(nr)``).
    sys : RotorStateSpace
        The model, with state descriptions; in multi-blade coordinates
        (from `mbc`) the blade modes are named collective, FW, BW or
        cyclic.
    rule : {'participation', 'openfast'}
        'participation' (default): the degree of freedom with the largest
        participation factor names the mode (the module's description).
        'openfast': openfast_toolbox's ``IdentifyModes`` rule (see Notes),
        for names equal to those of OpenFAST's Campbell tools.
    blade_length, tower_length : float, optional
        ``rule='openfast'`` only: the toolbox divides the eigenvector
        entries of blade states (but rotational ones) by the blade length
        and those of tower states by the tower height before it ranks the
        states of a mode (its ``BladeLen = TipRad - HubRad`` and ``TowerLen
        = TowerHt`` of ElastoDyn); None: no scaling, as ``IdentifyModes``
        of unscaled data.

    Returns
    -------
    list of str
        One name per mode; a complex pair has one name.
        ``'unidentified'`` where the rule names nothing.

    Raises
    ------
    ValueError
        If `rule` is unknown, a length is not positive and finite, or
        `modes` has another number of states than `sys`.

    Notes
    -----
    With ``rule='participation'`` an N-blade family of n collective
    states has n collective eigenvalues: when more modes would be named
    collective (at standstill or on a floating platform the collective and
    a cyclic coordinate mix), those with the largest collective share keep
    the name and the others are named by their cyclic part.  'cyclic', BW
    and FW can name several modes of a family.

    With ``rule='openfast'`` the modes are named as openfast_toolbox's
    ``IdentifyModes`` names them: among the modes of ``Im λ > 0`` ordered
    by natural frequency, from the magnitudes of their unit-norm
    eigenvectors on the displacement and first-order states (as the
    toolbox, leaving out the first first-order state), every state peaks
    at one mode; (1) a mode where a single state peaks takes the first
    free name of the toolbox's list that the state's description matches
    (AeroDyn states: the mode is skipped); (2) each free name, in the
    list's order, goes to the lowest mode with a matching peaking state
    (of its 7 largest, ElastoDyn's then BeamDyn's first), and modes whose
    peaking states matched nothing are skipped; (3) each free name still
    goes to the lowest mode whose 5 largest entries match it.  Modes
    below 1e-5 Hz or damped more than 98 % are skipped; each name is
    given once; the blade names need the multi-blade model of three
    blades (`mbc`).  Its names in ours:

    ==============================  =======================
    IdentifyModes                   ``mode_labels``
    ==============================  =======================
    Generator DOF (not shown)       generator
    Platform surge (sway, ...)      platform surge (sway, ...)
    1st Tower FA (SS), 2nd ...      1st tower FA (SS), 2nd ...
    1st Blade Flap (Regressive)     1st flap BW
    1st Blade Flap (Collective)     1st flap collective
    1st Blade Flap (Progressive)    1st flap FW
    1st Blade Edge (...)            1st edge BW / collective / FW
    1st Drivetrain Torsion          drivetrain
    2nd Blade Flap (...)            2nd flap BW / collective / FW
    Nacelle Yaw (not shown)         nacelle yaw
    ==============================  =======================

    Regressive and progressive are the lower and higher frequency of a
    cyclic pair, named BW and FW also at standstill.  The states are
    those of `sys` with its ``derivative_order``: the toolbox reads a file
    of the format without derivative orders as first-order states (all
    rows, rates included), `read_lin` infers the orders from the
    descriptions; set ``derivative_order`` to ones for its reading.

    Examples
    --------
    Three uncoupled blades with an edgewise degree of freedom, in
    multi-blade coordinates: the backward whirl, collective and forward
    whirl modes.

    >>> Ab = np.array([[0.0, 1.0], [-4.0, -0.2]])
    >>> desc = [f'ED 1st edgewise bending-mode DOF of blade {b}, m' for b in (1, 2, 3)]
    >>> desc += [d.replace('ED ', 'ED First time derivative of ') + '/s' for d in desc]
    >>> A = ltp.PeriodicMatrix.constant(np.kron(Ab, np.eye(3)), 2 * np.pi)
    >>> rot = ltp.RotorStateSpace(A, np.zeros((6, 0)), np.zeros((0, 6)), np.zeros((0, 0)),
    ...     2 * np.pi, rotor=dict(rotor_speed=1.0, state_descriptions=desc,
    ...                           rotating_states=np.ones(6, bool),
    ...                           derivative_order=np.full(6, 2)))
    >>> nr, _ = ltp.mbc(rot, 3)
    >>> modes = ltp.floquet_modes(nr)
    >>> [(round(float(f), 4), lab) for f, lab in zip(modes.damped_frequency,
    ...                                              ltp.mode_labels(modes, nr)) if f > 0]
    [(0.9975, '1st edge BW'), (1.9975, '1st edge collective'), (2.9975, '1st edge FW')]

    The toolbox's rule on its own standstill file, scaled by its lengths
    (its test's 40 m and 55 m): the lowest modes by natural frequency.

    >>> import pathlib, warnings
    >>> data = pathlib.Path(ltp.__file__).parents[1] / 'tests' / 'data'
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter('ignore')
    ...     nr, _ = ltp.mbc(ltp.read_lin(str(data / 'Standstill_ForID_ED.1.lin')), 3)
    >>> avg = nr.average(method='samples')
    >>> modes = ltp.floquet_modes(ltp.ltpss(avg.A, avg.B, avg.C, avg.D, period=2 * np.pi))
    >>> labels = ltp.mode_labels(modes, nr, 'openfast', blade_length=40, tower_length=55)
    >>> [labels[i] for i in np.argsort(np.abs(modes.exponents))
    ...  if modes.exponents[i].imag > 0][:4]
    ['1st tower SS', '1st tower FA', '1st edge collective', '1st flap BW']
    """
    if rule not in ('participation', 'openfast'):
        raise ValueError(f"rule must be 'participation' or 'openfast', got {rule!r}")
    for name, value in (('blade_length', blade_length), ('tower_length', tower_length)):
        if value is not None and not (np.isscalar(value) and np.isreal(value)
                                      and np.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive number, got {value!r}")
    desc = list(getattr(sys, 'state_descriptions', sys.state_labels))
    if len(desc) != np.shape(modes.vectors)[0]:
        raise ValueError(f"modes have {np.shape(modes.vectors)[0]} states, sys has "
                         f"{len(desc)}: modes must be the modes of sys")
    multiblade = getattr(sys, 'frame', None) == 'multiblade'
    coords = [(_COORD.search(lab).group(1) if multiblade and _COORD.search(lab) else None)
              for lab in sys.state_labels]
    if rule == 'openfast':
        return _openfast_rule(modes, sys, coords, blade_length, tower_length)
    names = [dof_name(d) for d in desc]
    families = sorted(set(names), key=names.index)
    index = {f: np.array([i for i, n in enumerate(names) if n == f]) for f in families}
    V, W, lam = modes.vectors, modes.left_vectors, np.asarray(modes.exponents)
    out, collective = [], {}
    for i in range(V.shape[1]):
        v, w = V[:, i], W[:, i]
        part = np.abs(np.conj(w) * v)
        if not np.all(np.isfinite(part)) or part.sum() == 0:
            out.append('unidentified')
            continue
        part = part / part.sum()
        share = {f: part[idx].sum() for f, idx in index.items()}
        best = max(share, key=share.get)
        label = best
        members = index[best]
        if any(coords[j] is not None for j in members):
            share0 = part[[j for j in members if coords[j] == '0']].sum() / share[best]
            if share0 >= 0.5:
                label += ' collective'
                collective.setdefault(best, []).append((share0, i, part))
            else:
                label += ' ' + _whirl(v, lam[i], members, coords, part)
        out.append(label)
    # a family has as many collective eigenvalues as collective states
    for f, cands in collective.items():
        budget = sum(coords[j] == '0' for j in index[f])
        keep = set()
        for share0, i, part in sorted(cands, key=lambda c: -c[0]):
            if i in keep:
                continue
            pair = [c[1] for c in cands if c[1] != i and lam[i].imag != 0
                    and abs(lam[c[1]] - np.conj(lam[i])) <= 1e-6 * abs(lam[i])][:1]
            unit = {i, *pair}
            if len(unit) <= budget:
                keep |= unit
                budget -= len(unit)
        for share0, i, part in cands:
            if i not in keep:
                out[i] = f + ' ' + _whirl(V[:, i], lam[i], index[f], coords, part)
    return out


def _whirl(v, lam, members, coords, part):
    """'FW', 'BW' or 'cyclic' from the cyclic pair of the strongest blade coordinate."""
    c_idx = [j for j in members if coords[j] == 'c1']
    s_idx = [j for j in members if coords[j] == 's1']
    if not c_idx or not s_idx or len(c_idx) != len(s_idx):
        return 'cyclic'
    # the cosine/sine pair with the largest participation
    k = int(np.argmax([part[a] + part[b] for a, b in zip(c_idx, s_idx)]))
    ac, as_ = v[c_idx[k]], v[s_idx[k]]
    if lam.imag < 0:
        ac, as_ = np.conj(ac), np.conj(as_)
    scale = abs(ac) ** 2 + abs(as_) ** 2
    if scale == 0:
        return 'cyclic'
    # Im(conj(a_c) a_s) / (|a_c|² + |a_s|²): -1/2 forward, +1/2 backward, 0 standing
    turn = float(np.imag(np.conj(ac) * as_)) / scale
    if abs(turn) < 0.05 or abs(lam.imag) == 0:
        return 'cyclic'
    return 'FW' if turn < 0 else 'BW'


# openfast_toolbox's IdentifyModes: its list of names in its order (in our words, the table
# of `mode_labels`), each with a substring that some state description must hold for the
# name to be in the list (None: always) and the regular expressions (case-insensitive) of
# the state descriptions the name is given after.
_FLAP, _EDGE = 'flapwise bending-mode DOF of blade', 'edgewise bending-mode DOF of blade'
_NODE = r'Blade {} finite element node \d rotational displacement in {}, rad'
_OPENFAST_LIST = [
    ('generator', None, ['ED Variable speed generator DOF, rad']),
    ('platform surge', 'surge', ['ED Platform horizontal surge translation DOF, m']),
    ('platform sway', 'sway', ['ED Platform horizontal sway translation DOF, m']),
    ('platform heave', 'heave', ['ED Platform vertical heave translation DOF, m']),
    ('platform roll', 'platform roll tilt', ['ED Platform roll tilt rotation DOF, rad']),
    ('platform pitch', 'platform pitch tilt', ['ED Platform pitch tilt rotation DOF, rad']),
    ('platform yaw', 'platform yaw', ['ED Platform yaw rotation DOF, rad']),
    ('1st tower FA', None, ['ED 1st tower fore-aft bending mode DOF, m']),
    ('1st tower SS', None, ['ED 1st tower side-to-side bending mode DOF, m']),
    ('1st flap BW', None, [f'ED 1st {_FLAP} (sine|cosine), m',
                           _NODE.format('(sine|cosine)', 'Y')]),
    ('1st flap collective', None, [f'ED 1st {_FLAP} collective, m',
                                   _NODE.format('collective', 'Y')]),
    ('1st flap FW', None, [f'ED 1st {_FLAP} (sine|cosine), m']),
    ('1st edge BW', None, [f'ED 1st {_EDGE} (sine|cosine), m',
                           _NODE.format('(sine|cosine)', 'X')]),
    ('1st edge collective', f'1st {_EDGE} collective'.lower(),
     [f'ED 1st {_EDGE} collective, m']),
    ('1st edge FW', None, [f'ED 1st {_EDGE} (sine|cosine), m']),
    ('drivetrain', None, ['ED Drivetrain rotational-flexibility DOF, rad']),
    ('2nd tower FA', None, ['ED 2nd tower fore-aft bending mode DOF, m']),
    ('2nd tower SS', None, ['ED 2nd tower side-to-side bending mode DOF, m']),
    ('2nd flap BW', None, [f'ED 2nd {_FLAP} (sine|cosine), m']),
    ('2nd flap collective', None, [f'ED 2nd {_FLAP} collective, m',
                                   _NODE.format('collective', 'Y')]),
    ('2nd flap FW', None, [f'ED 2nd {_FLAP} (sine|cosine), m']),
    ('nacelle yaw', None, ['ED Nacelle yaw DOF, rad']),
]
_BLADE_NO = re.compile(r'\b(?:BD_|[Bb]lade\s*)\d+')
_MB_WORD = {'0': 'collective', 'c1': 'cosine', 's1': 'sine'}


def _toolbox_description(description, coord):
    """A state's description as the toolbox matches it.

    The blade number becomes the multi-blade coordinate (``blade
    collective``, ``cosine``, ``sine``) and the parenthesised part is cut:
    what precedes its first ``(`` joined to what follows its second ``)``
    (its only one when there is one).
    """
    if coord in _MB_WORD:
        description = _BLADE_NO.sub('blade ' + _MB_WORD[coord], description, count=1)
    if '(' in description and ')' in description:
        tail = description.split(')', 2)[-1]
        description = description.split('(', 1)[0].strip() + tail
    return description


def _openfast_rule(modes, sys, coords, blade_length, tower_length):
    """Labels by openfast_toolbox's IdentifyModes (see `mode_labels`)."""
    desc = list(getattr(sys, 'state_descriptions', sys.state_labels))
    n = len(desc)
    order = np.asarray(getattr(sys, 'derivative_order', np.zeros(n, int)))
    rate = np.array([_rate_free(d)[0] for d in desc])
    rows = np.flatnonzero(((order == 2) | (order == 0)) & ~rate | (order == 1))
    first_order = np.flatnonzero(order == 1)
    if len(first_order):                 # the toolbox leaves out its first first-order state
        rows = rows[rows != first_order[0]]
    text = [_toolbox_description(desc[j], coords[j]) for j in rows]
    lam = np.asarray(modes.exponents)
    V = np.asarray(modes.vectors)
    V = V / np.linalg.norm(V, axis=0)
    upper = np.flatnonzero(lam.imag > 0)
    upper = upper[np.argsort(np.abs(lam[upper]), kind='stable')]
    out = ['unidentified'] * len(lam)
    if len(upper) == 0 or len(rows) == 0:
        return out
    M = np.abs(V[np.ix_(rows, upper)])
    peak = np.argmax(M, axis=1)                          # the mode where each state peaks
    scale = np.ones(len(rows))
    for r, t in enumerate(text):
        if tower_length is not None and re.search('tower', t, re.I):
            scale[r] = 1 / tower_length
        elif blade_length is not None and re.search('blade', t, re.I) and \
                'rotational' not in t:
            scale[r] = 1 / blade_length
    ranked = [np.argsort(-(M[:, k] * scale), kind='stable') for k in range(len(upper))]
    peaks = [[r for r in ranked[k] if peak[r] == k] for k in range(len(upper))]
    others = [[r for r in ranked[k] if peak[r] != k] for k in range(len(upper))]
    low = [t.lower() for t in text]
    names = [(name, [re.compile(p, re.I) for p in pats]) for name, when, pats in _OPENFAST_LIST
             if when is None or any(when in t for t in low)]
    fn = np.abs(lam[upper]) / (2 * np.pi)
    skipped = list((fn < 1e-5) | (-lam[upper].real / np.abs(lam[upper]) > 0.98))
    named = [None] * len(upper)                          # mode -> index into names
    given = {}                                           # name index -> mode

    def match(i, t):
        return any(p.search(t) for p in names[i][1])

    def give(i, k):
        named[k], given[i] = i, k

    # level 1: a mode where a single state peaks, after the first free name it matches
    for k in range(len(upper)):
        if skipped[k] or len(peaks[k]) != 1:
            continue
        t = text[peaks[k][0]]
        if t.startswith('AD'):
            skipped[k] = True
            continue
        i = next((i for i in range(len(names)) if i not in given and match(i, t)), None)
        if i is not None:
            give(i, k)
    # level 2: each free name, in list order, to the first mode (by frequency) with a
    # peaking state that matches it (its 7 largest, ElastoDyn's then BeamDyn's first)
    for i in range(len(names)):
        if i in given:
            continue
        for k in range(len(upper)):
            if named[k] is not None or skipped[k]:
                continue
            top = [text[r] for r in peaks[k][:7]]
            top = [t for pre in ('ED', 'BD') for t in top if t.startswith(pre)] + \
                [t for t in top if not t.startswith(('ED', 'BD', 'AD'))]
            if any(match(i, t) for t in top):
                give(i, k)
                break
    for k in range(len(upper)):          # a peaking state that matched no name: skipped
        if named[k] is None and peaks[k]:
            skipped[k] = True
    # level 3: each free name to the first mode whose 5 largest entries (of states peaking
    # elsewhere, AeroDyn's left out unless they are all five) match it
    for i in range(len(names)):
        if i in given:
            continue
        for k in range(len(upper)):
            if named[k] is not None or skipped[k]:
                continue
            top = [text[r] for r in others[k]]
            if sum(t.startswith('AD') for t in top[:5]) < 5:
                top = [t for t in top if not t.startswith('AD')][:5]
                if any(match(i, t) for t in top):
                    give(i, k)
                    break
    for k, i in enumerate(named):
        if i is not None:
            out[upper[k]] = names[i][0]
    # the conjugate of a named mode has its name
    for j in np.flatnonzero(lam.imag < 0):
        out[j] = out[upper[np.argmin(np.abs(lam[upper] - np.conj(lam[j])))]]
    return out
