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
"progressive" in order of frequency.  Where a single state clearly
dominates both rules agree (31 of the 37 modes it names on its test files
Standstill_ForID_ED, StandstillSemi_ForID_EDHD and the rotating NREL 5 MW
files, with BW/FW for its regressive/progressive).  They differ on purpose
where its measure misleads: eigenvector magnitudes depend on the states'
units and favour low frequencies (a HydroDyn radiation mode is named a
flap mode, tower modes flap and edge modes), and list order or a guess
decides (a drivetrain mode is named edge-collective and the reverse).
There the participation factors name the degree of freedom whose stiffness
the frequency depends on most.
"""

import re

import numpy as np

from .blade_groups import blade_key

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


def mode_labels(modes, sys):
    """A name for every mode of `modes` (a `FloquetModes` of `sys`).

    Parameters
    ----------
    modes : FloquetModes
        Modes of `sys` (e.g. ``floquet_modes(nr)``).
    sys : RotorStateSpace
        The model, with state descriptions; in multi-blade coordinates
        (from `mbc`) the blade modes are named collective, FW, BW or
        cyclic.

    Returns
    -------
    list of str

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
    """
    desc = list(getattr(sys, 'state_descriptions', sys.state_labels))
    names = [dof_name(d) for d in desc]
    multiblade = getattr(sys, 'frame', None) == 'multiblade'
    coords = [(_COORD.search(lab).group(1) if multiblade and _COORD.search(lab) else None)
              for lab in sys.state_labels]
    families = sorted(set(names), key=names.index)
    index = {f: np.array([i for i, n in enumerate(names) if n == f]) for f in families}
    V, W = modes.vectors, modes.left_vectors
    out = []
    for i in range(V.shape[1]):
        v, w, lam = V[:, i], W[:, i], modes.exponents[i]
        part = np.abs(np.conj(w) * v)
        if not np.all(np.isfinite(part)) or part.sum() == 0:
            out.append('unidentified')
            continue
        part = part / part.sum()
        share = {f: part[idx].sum() for f, idx in index.items()}
        best = max(share, key=share.get)
        label = best
        members = index[best]
        cs = [c for c in (coords[j] for j in members) if c is not None]
        if cs:
            collective = part[[j for j in members if coords[j] == '0']].sum()
            if collective >= 0.5 * share[best]:
                label += ' collective'
            else:
                label += ' ' + _whirl(v, lam, members, coords, part)
        out.append(label)
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
