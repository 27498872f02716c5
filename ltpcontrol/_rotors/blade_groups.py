"""Blade groups of an OpenFAST model, from the descriptions of its states.

OpenFAST names every blade quantity with its blade number, in a form that
depends on the module: ElastoDyn ``1st flapwise bending-mode DOF of blade 2
(internal DOF index = DOF_BF(2,1)), m``, BeamDyn ``BD_2 finite element node
3 ... translational displacement in X, m``, AeroDyn's blade-node states
``AD x4 blade 2, node 3, -`` (unsteady aerodynamics), ``AD vind (axial) at
blade 2, node 1, m/s`` (dynamic inflow) or ``B2N005...``, ServoDyn's blade
structural controls ``SrvD Blade 2 StC 1 local displacement state X  m``.
Descriptions that agree once the blade number is removed form one group of
N blades, ordered by blade number whatever the order of the modules and of
their states.  A second-order degree of freedom appears twice: its
displacement and its rate, whose description is ``First time derivative
of`` the displacement's (the unit gets ``/s``), or for ServoDyn's
structural controls the displacement's with ``dX/dt`` for ``X``; rates are
paired with their displacements by description.
"""

import re

import numpy as np

__all__ = ['blade_key', 'infer_blade_groups', 'check_groups', 'derivative_orders']

# where a description names its blade (the first pattern that matches)
_BLADE = [re.compile(p) for p in (r'[Bb]lade\s*(\d+)', r'\bBD_(\d+)\b', r'\bA?B(\d+)N\d',
                                  r'\bBld(\d+)', r'\bBStC(\d+)', r'PitchBearing(\d+)',
                                  r'\bB(\d+)(?=[A-Z_ ])', r'(\d)(?=\D*$)')]
_INTERNAL = re.compile(r'\s*\(internal DOF index = [^()]*(?:\([^()]*\))?[^()]*\)')
_RATE = re.compile(r'First time derivative of\s+', re.I)
_STC_RATE = re.compile(r'\bd([XYZ])/dt\b')        # ServoDyn StC: 'state dX/dt  m/s'
_UNIT = re.compile(r'(?:,\s*[^,]*|\s{2,}\S+)$')     # ', m' or (StC) '  m'


def _rate_free(text):
    """``(is_rate, text)``: the description of the displacement a rate is of."""
    rate = bool(_RATE.search(text)) or bool(_STC_RATE.search(text))
    return rate, _STC_RATE.sub(r'\1', _RATE.sub('', text))


def blade_key(text, loose=True):
    """``(key, blade)``: the description without its blade number, and the number.

    ``(None, None)`` when the description names no blade.  The key of a
    rate is that of its displacement prefixed by ``'d/dt '``.  `loose`
    takes, when no blade pattern matches, the last digit of the name
    (``TipDxb2``, ``BldPitch3``).

    Examples
    --------
    >>> from ltpcontrol._rotors.blade_groups import blade_key
    >>> blade_key('ED 1st flapwise bending-mode DOF of blade 2 '
    ...           '(internal DOF index = DOF_BF(2,1)), m')
    ('ED 1st flapwise bending-mode DOF of blade #', 2)
    >>> blade_key('BD_3 First time derivative of finite element node 2 rotational '
    ...           'displacement in X, rad/s')
    ('d/dt BD_# finite element node 2 rotational displacement in X', 3)
    >>> blade_key('AD AB2N001UA_Flag, (-)')                # an AeroDyn output
    ('AD AB#N001UA_Flag', 2)
    >>> blade_key('SrvD Blade 3 StC 1 local displacement state dY/dt  m/s')
    ('d/dt SrvD Blade # StC 1 local displacement state Y', 3)
    """
    rate, text = _rate_free(_INTERNAL.sub('', text))
    text = _UNIT.sub('', text).strip()
    for pattern in _BLADE if loose else _BLADE[:-1]:
        m = pattern.search(text)
        if m:
            key = text[:m.start(1)] + '#' + text[m.end(1):]
            return ('d/dt ' if rate else '') + key, int(m.group(1))
    return None, None


def infer_blade_groups(descriptions, rotating, order, N, what='states'):
    """Groups of N blades (and the rates of second-order ones) from descriptions.

    Parameters
    ----------
    descriptions : list of str
    rotating : array of bool
        Rotating-frame flags.
    order : array of int or None
        Derivative orders (states only): 2 marks a displacement or rate of
        a second-order degree of freedom, 1 a first-order state.
    N : int
        Number of blades.
    what : str
        'states', 'inputs' or 'outputs' (for messages).

    Returns
    -------
    groups : list of list of int
        Displacement groups (and first-order groups, and for inputs and
        outputs all groups), each ordered blade 1..N.
    rates : list of (list of int or None)
        The rate group of each displacement group (None for first-order
        states and for signals).
    left : list of int
        Rotating items that form no group.

    Raises
    ------
    ValueError
        When the descriptions name a different number of blades than N,
        or a rate has no displacement (naming the states).

    Examples
    --------
    >>> from ltpcontrol._rotors.blade_groups import infer_blade_groups
    >>> desc = ['flap blade 3, m', 'flap blade 1, m', 'flap blade 2, m',
    ...         'First time derivative of flap blade 1, m/s',
    ...         'First time derivative of flap blade 2, m/s',
    ...         'First time derivative of flap blade 3, m/s']
    >>> infer_blade_groups(desc, [True] * 6, [2] * 6, 3)
    ([[1, 2, 0]], [[3, 4, 5]], [])
    """
    rotating = np.asarray(rotating, bool)
    keyed, left = {}, []
    for i in np.flatnonzero(rotating):
        key, blade = blade_key(descriptions[i])
        if key is None:
            left.append(int(i))
            continue
        kind = 1 if order is None else int(order[i])
        keyed.setdefault((kind, key), []).append((blade, int(i)))
    counts = {max(b for b, _ in items) for items in keyed.values()}
    if keyed and N not in counts and len(counts) == 1:
        M = counts.pop()
        example = descriptions[next(iter(keyed.values()))[0][1]]
        raise ValueError(f"the rotating {what} describe {M} blades (e.g. {example!r}), "
                         f"not nblades = {N}")
    groups, rates, complete = [], [], {}
    for (kind, key), items in keyed.items():
        blades = sorted(b for b, _ in items)
        if blades != list(range(1, N + 1)):
            left += [i for _, i in items]
            continue
        complete[(kind, key)] = [i for _, i in sorted(items)]
    for (kind, key), g in complete.items():
        if key.startswith('d/dt ') and kind == 2:
            if (2, key[5:]) not in complete:
                raise ValueError(f"the rotating rates {[descriptions[i] for i in g]} have no "
                                 "displacements among the states")
            continue
        groups.append(g)
        rates.append(complete.get((2, 'd/dt ' + key)) if kind == 2 else None)
        if kind == 2 and rates[-1] is None:
            raise ValueError(f"the rotating displacements {[descriptions[i] for i in g]} have "
                             "no rates ('First time derivative of ...') among the states")
    # keep the model's order of groups
    perm = np.argsort([g[0] for g in groups], kind='stable')
    return [groups[k] for k in perm], [rates[k] for k in perm], sorted(left)


def derivative_orders(descriptions):
    """Derivative orders of states from their descriptions (files without them).

    A state whose rate (``First time derivative of`` it) is also a state,
    and that rate, are second-order (2); the others first-order (1).

    Examples
    --------
    >>> from ltpcontrol._rotors.blade_groups import derivative_orders
    >>> derivative_orders(['ED tower, m', 'HD x1', 'ED First time derivative of tower, m/s'])
    array([2, 1, 2])
    """
    keys = [(r, _UNIT.sub('', t).strip())
            for r, t in (_rate_free(_INTERNAL.sub('', d)) for d in descriptions)]
    rates = {k for r, k in keys if r}
    disps = {k for r, k in keys if not r}
    return np.array([2 if (k in rates and k in disps) else 1 for _, k in keys], int)


def check_groups(groups, rates, descriptions, what='rotating'):
    """Blade order and rate pairing of given groups, checked on descriptions.

    Raises `ValueError` naming the states when a group's descriptions name
    the blades in another order than 1..N, or a rate is not the
    derivative of the displacement it is paired with.

    Examples
    --------
    >>> from ltpcontrol._rotors.blade_groups import check_groups
    >>> desc = ['flap blade 1', 'flap blade 2', 'flap blade 3']
    >>> check_groups([[2, 1, 0]], [None], desc)
    Traceback (most recent call last):
    ...
    ValueError: rotating: the group ['flap blade 3', 'flap blade 2', 'flap blade 1'] names blades [3, 2, 1]; the members must be blades 1..3 in order
    """
    for g, r in zip(groups, rates):
        keys = [blade_key(descriptions[i], loose=False) for i in g]
        blades = [b for _, b in keys]
        if all(b is not None for b in blades) and blades != list(range(1, len(g) + 1)):
            raise ValueError(f"{what}: the group {[descriptions[i] for i in g]} names blades "
                             f"{blades}; the members must be blades 1..{len(g)} in order")
        if r is None:
            continue
        for i, j in zip(g, r):
            ki, kj = blade_key(descriptions[i], False), blade_key(descriptions[j], False)
            if ki[0] is None or kj[0] is None:
                continue
            if not (kj[0] == 'd/dt ' + ki[0] and kj[1] == ki[1]):
                raise ValueError(f"rates: {descriptions[j]!r} is not the rate of "
                                 f"{descriptions[i]!r}")
