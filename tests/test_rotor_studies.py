"""Rotor studies: repeated multipliers, blade groups, Campbell diagrams from files.

Independent truths: eigenvalues of multi-blade models by numpy (the
closed form ``√(k - c²/4) ± Ω`` for uncoupled blades), a multi-blade
transform written out by hand for three blades (examples/rotor_models.py),
openfast_toolbox's expected frequencies, damping ratios and `IdentifyModes`
labels on its own files (tests/data/README.md), and files written in
OpenFAST's format.
"""

import copy
import csv
import pathlib
import re
import warnings

import numpy as np
import pytest
from scipy.linalg import block_diag

import ltpcontrol as ltp
from examples.rotor_models import (turbine_A, turbine_descriptions, turbine_mbc_A, write_lin,
                                   write_turbine_study)

DATA = pathlib.Path(__file__).parent / 'data'
AB = np.array([[0.0, 1.0], [-4.0, -0.2]])            # one blade's lag: 1.9975 rad/s


def uncoupled_blades():
    return ltp.ltpss(np.kron(AB, np.eye(3)), np.zeros((6, 0)), np.zeros((0, 6)), 0,
                     period=2 * np.pi)


#
# Trustworthy modes
#

def test_guide_isotropic_rotor_modes_are_separated():
    rot = uncoupled_blades()
    nr, T = ltp.mbc(rot, [[0, 1, 2]], 3, rates=[[3, 4, 5]])
    wd = np.sqrt(4 - 0.01)                            # closed form, Ω = 1
    truth = np.sort(np.repeat([wd - 1, wd, wd + 1], 2))
    Tinv = ltp.PeriodicMatrix.from_function(lambda t: np.linalg.inv(T(t)), T.period, (6, 6))
    framed = ltp.floquet_modes(rot, frame=Tinv)
    assert np.allclose(np.sort(np.abs(framed.damped_frequency)), truth, atol=1e-10)
    assert np.allclose(framed.damping, 0.1 / 2 / np.abs(framed.exponents) * 2, atol=1e-10)
    # the multi-blade model: one harmonic per mode, participation exactly 1
    modes = ltp.floquet_modes(nr)
    assert np.allclose(np.sort(np.abs(modes.damped_frequency)), truth, atol=1e-10)
    assert np.all(np.abs(modes.participation.max(axis=1) - 1) < 1e-12)
    assert modes.frame == 'multiblade' and 'multiblade' in repr(modes)
    # right and left vectors stay bi-orthonormal eigenvectors of A
    A = nr.A(0.0)
    V, W = modes.vectors, modes.left_vectors
    assert np.abs(A @ V - V * modes.exponents).max() < 1e-12
    assert np.allclose(W.conj().T @ V, np.eye(6), atol=1e-12)


def test_periodic_rotor_repeated_multipliers_split_by_harmonic_content():
    # rotating frame of the 16-state turbine: the cyclic flap modes share a multiplier
    # with each other; measured in multi-blade coordinates they are the eigenvalues of
    # the hand-made multi-blade model
    Omega = 3.0
    rot = ltp.ltpss(lambda t: turbine_A(t, Omega), np.zeros((16, 0)), np.zeros((0, 16)), 0,
                    period=2 * np.pi / Omega)
    _, P = ltp.mbc(rot, [[2, 3, 4], [5, 6, 7]], 3, rates=[[10, 11, 12], [13, 14, 15]])
    Pinv = ltp.PeriodicMatrix.from_function(lambda t: np.linalg.inv(P(t)), P.period,
                                            (16, 16))
    modes = ltp.floquet_modes(rot, frame=Pinv)
    truth = np.linalg.eigvals(turbine_mbc_A(Omega))
    gap = [np.abs(truth - lam).min() for lam in modes.exponents]
    assert max(gap) < 1e-8 * np.abs(truth).max()
    assert np.all(modes.participation.max(axis=1) > 1 - 1e-8)


def test_identical_blades_need_no_separation():
    # two identical blades in their own coordinates share an exponent with the same
    # (single) harmonic: any basis is right, no warning, participation 1
    A = np.kron(AB, np.eye(2))
    sys = ltp.ltpss(A, np.zeros((4, 0)), np.zeros((0, 4)), 0, period=2 * np.pi)
    with _no_warning():
        modes = ltp.floquet_modes(sys)
    assert np.allclose(modes.participation.max(axis=1), 1)
    assert np.allclose(np.abs(modes.damped_frequency), np.sqrt(4 - 0.01))


def test_constant_path_detects_time_invariance_to_data_precision(tmp_path):
    # an isotropic rotor written with 10 digits: the multi-blade model varies at the
    # printed precision only, and is solved as time-invariant
    Omega, desc = 1.2, turbine_descriptions()
    rotating = ['blade' in d for d in desc]
    files = []
    for k in range(12):
        psi = 2 * np.pi * k / 12
        f = tmp_path / f'iso.{k + 1}.lin'
        write_lin(f, turbine_A(psi / Omega, Omega), Omega, psi, 8.0, desc, rotating,
                  [2] * 16)
        files.append(f)
    lin = ltp.read_lin(files)
    assert 1e-11 < lin.precision < 1e-9
    nr, _ = ltp.mbc(lin, 3)
    assert not nr.A.is_constant                       # rounding: not exactly constant
    modes = ltp.floquet_modes(nr)
    assert np.all(modes.participation.max(axis=1) == pytest.approx(1, abs=1e-12))
    truth = np.linalg.eigvals(turbine_mbc_A(Omega))
    assert max(np.abs(truth - lam).min() for lam in modes.exponents) < 1e-7


def test_isotropic_turbine_flap_tracks_keep_their_shape():
    desc = turbine_descriptions()

    cache = {}

    def model(Omega):
        if Omega in cache:
            return cache[Omega]
        rot = ltp.ltpss(lambda t: turbine_A(t, Omega), np.zeros((16, 0)),
                        np.zeros((0, 16)), 0, period=2 * np.pi / Omega)
        rotor = dict(rotor_speed=Omega, state_descriptions=desc,
                     rotating_states=np.array(['blade' in d for d in desc]),
                     derivative_order=np.full(16, 2))
        rot = ltp.RotorStateSpace(rot.A, rot.B, rot.C, rot.D, rot.period, rotor=rotor)
        cache[Omega] = ltp.mbc(rot, 3)[0]
        return cache[Omega]
    speeds = np.linspace(0.3, 1.6, 6)
    cd = ltp.campbell(model, speeds, n_jobs=1, branch='principal')
    labels = [ltp.mode_labels(cd.modes[k], model(speeds[k])) for k in range(len(speeds))]
    flap = [j for j in range(16) if 'flap' in labels[0][cd.indices[0, j]]]
    assert len(flap) == 6
    assert cd.mac[:, flap].min() >= 0.99
    # each track keeps its name, and its frequency is the hand-made model's
    for j in range(16):
        assert len({labels[k][cd.indices[k, j]] for k in range(len(speeds))}) == 1
    for k, Om in enumerate(speeds):
        truth = np.linalg.eigvals(turbine_mbc_A(Om))
        assert max(np.abs(truth - lam).min() for lam in cd.exponents[k]) < 1e-9
    names = {labels[0][cd.indices[0, j]] for j in flap}
    assert names == {'1st flap BW', '1st flap collective', '1st flap FW'}


#
# Blade groups and misuse
#

def test_toolbox_files_grouped_and_averaged_like_the_toolbox():
    expected = {   # openfast_toolbox linearization/tests/test_campbell_data.py
        'BAR_URC_EDBD.1.lin': ([0.18549539, 0.18727956, 1.12675789, 1.25491926, 9.03091505,
                                9.05584944, 9.31045707, 9.36779001, 11.30081115,
                                13.78922866],
                               [0.40656628, 0.40815288, 0.64834856, 0.75063003, 6.02032061,
                                8.60631293, 6.29886588, 8.37207306, 9.96489352, 9.70093435]),
        'StandstillSemi_ForID_EDHD.1.lin': (
            [0.00852735, 0.00865675, 0.01333642, 0.03147209, 0.03544405, 0.03550137,
             0.04915103, 0.07296769, 0.07801498, 0.08493981],
            [0.16886295, 3.43729876, 25.10525282, 56.73819059, 2.56872571, 2.45772964,
             0.18473601, 23.22413272, 11.67420729, 24.10895804]),
    }
    for name, (freq, damp) in expected.items():
        with _no_warning():
            lin = ltp.read_lin(DATA / name)
            nr, _ = ltp.mbc(lin, 3)
        ev = np.linalg.eigvals(nr.average(method='samples').A)
        ev = ev[ev.imag > 0]
        ev = ev[np.argsort(np.abs(ev))][:10]
        assert np.allclose(np.abs(ev) / (2 * np.pi), freq, atol=5e-5)
        assert np.allclose(-100 * ev.real / np.abs(ev), damp, atol=5e-5)
    # the file format without derivative orders (toolbox: 0.427, 0.449, 0.667 Hz and
    # log decrements 1.9497, 2.1162, 5.0113 %)
    with pytest.warns(UserWarning, match="RootFxc1"):
        nr, _ = ltp.mbc(ltp.read_lin(DATA / 'Standstill_old.1.lin'), 3)
    ev = np.linalg.eigvals(nr.average(method='samples').A)
    ev = ev[ev.imag > 0]
    ev = ev[np.argsort(np.abs(ev))][:3]
    assert np.allclose(np.abs(ev) / (2 * np.pi), [0.427, 0.449, 0.667], atol=5e-4)
    assert np.allclose(-ev.real / np.abs(ev) * 100 * 2 * np.pi, [1.9497, 2.1162, 5.0113],
                       atol=5e-4)


class _no_warning:
    def __enter__(self):
        import warnings
        self._c = warnings.catch_warnings()
        self._c.__enter__()
        warnings.simplefilter('error')

    def __exit__(self, *exc):
        return self._c.__exit__(*exc)


def test_beamdyn_blades_grouped_in_openfast_order():
    lin = ltp.read_lin(DATA / 'BAR_URC_EDBD.1.lin')
    nr, _ = ltp.mbc(lin, 3)
    # BeamDyn writes blade by blade (displacements, rates): the first group is node 2's
    # X translation of blades 1, 2, 3 and its rates
    desc = lin.state_descriptions
    assert [desc[i][:4] for i in (8, 20, 32)] == ['BD_1', 'BD_2', 'BD_3']
    assert nr.state_labels[8] == 'x[8]_0' and nr.state_labels[20] == 'x[8]_c1'
    assert nr.state_labels[32] == 'x[8]_s1'


def test_any_module_order_gives_the_same_multiblade_model(tmp_path):
    # the turbine written with blade-major (AeroDyn-like) order of its blade states
    Omega, desc = 1.0, turbine_descriptions()
    perm = [0, 1, 8, 9, 2, 10, 5, 13, 3, 11, 6, 14, 4, 12, 7, 15]
    for k in range(6):
        psi = 2 * np.pi * k / 6
        A = turbine_A(psi / Omega, Omega)
        write_lin(tmp_path / f'a.{k + 1}.lin', A, Omega, psi, 8.0, desc,
                  ['blade' in d for d in desc], [2] * 16, digits=16)
        write_lin(tmp_path / f'b.{k + 1}.lin', A[np.ix_(perm, perm)], Omega, psi, 8.0,
                  [desc[i] for i in perm], ['blade' in desc[i] for i in perm], [2] * 16,
                  digits=16)
    a = ltp.mbc(ltp.read_lin(str(tmp_path / 'a.*.lin')), 3)[0]
    b = ltp.mbc(ltp.read_lin(str(tmp_path / 'b.*.lin')), 3)[0]
    ea = np.linalg.eigvals(a.average(method='samples').A)
    eb = np.linalg.eigvals(b.average(method='samples').A)
    truth = np.linalg.eigvals(turbine_mbc_A(Omega))
    assert max(np.abs(ea - lam).min() for lam in eb) < 1e-10
    assert max(np.abs(truth - lam).min() for lam in ea) < 1e-9


def test_misuse_is_refused_naming_the_states(tmp_path):
    files = sorted(DATA.glob('ws03.0.*.lin'))
    lin = ltp.read_lin(files)
    # blades given in reverse order
    with pytest.raises(ValueError, match=r"blade 3 .* names blades \[3, 2, 1\]"):
        ltp.mbc(lin, [[8, 7, 6]], 3, rates=[[23, 22, 21]])
    # rates of another degree of freedom
    with pytest.raises(ValueError, match="is not the rate of 'ED 1st flapwise"):
        ltp.mbc(lin, [[6, 7, 8]], 3, rates=[[24, 25, 26]])
    # a model in multi-blade coordinates already
    nr, _ = ltp.mbc(lin, 3)
    with pytest.raises(ValueError, match="already in multi-blade coordinates"):
        ltp.mbc(nr, 3)
    # no rotating states
    tower = ltp.read_lin(files, remove_states='blade')
    with pytest.raises(ValueError, match="no rotating states"):
        ltp.mbc(tower, 3)
    # a wrong blade count
    with pytest.raises(ValueError, match="describe 3 blades"):
        ltp.mbc(lin, 4)
    # a single azimuth of a turning rotor is no periodic model
    one = ltp.read_lin(files[0])
    with pytest.raises(ValueError, match="single azimuth"):
        ltp.floquet_modes(one)
    with pytest.raises(ValueError, match="defines no periodic model"):
        ltp.read_lin(files[0], interpolation='fourier')
    # ... but averaging in multi-blade coordinates works, as MBC3's
    nr1, _ = ltp.mbc(one, 3)
    assert nr1.average(method='samples').A.shape == (30, 30)


def test_read_lin_sources_and_mbc_blade_count_in_second_place():
    files = sorted(DATA.glob('ws03.0.*.lin'))
    by_list = ltp.read_lin(files)
    by_glob = ltp.read_lin(str(DATA / 'ws03.0.*.lin'))
    assert np.array_equal(by_list.samples[0], by_glob.samples[0])
    with pytest.raises(ValueError, match="no file matches"):
        ltp.read_lin(str(DATA / 'nothing*.lin'))
    a, _ = ltp.mbc(by_list, 3)
    b, _ = ltp.mbc(by_list, nblades=3)
    assert np.array_equal(a.samples[0], b.samples[0])
    drop = ltp.read_lin(files, remove_states='Nacelle yaw')
    assert drop.nstates == 28 and not any('yaw' in d for d in drop.state_descriptions)


#
# Campbell diagrams from files
#

# openfast_toolbox's IdentifyModes (its commit d34b283) on its own files, with its test's
# BladeLen 40 and TowerLen 55: mode number (1-based, the modes of Im λ > 0 by natural
# frequency) -> label, for every mode it names.  The Standstill_ForID_ED table is the
# toolbox's test_modesID reference table; the others are its output (test_modesID asserts
# modes 1, 2, 3, 7, 47, 50, 51, 58, 59, 60 of the EDHD file).  The toolbox reads the file
# format without derivative orders (Standstill_old) as first-order states.
TOOLBOX_LABELS = {
    'Standstill_ForID_ED.1.lin': {
        1: '1st Tower SS', 2: '1st Tower FA', 3: '1st Blade Edge (Collective)',
        4: '1st Blade Flap (Regressive)', 5: '1st Blade Flap (Progressive)',
        6: '1st Blade Flap (Collective)', 7: '1st Blade Edge (Regressive)',
        8: '1st Blade Edge (Progressive)', 9: '2nd Blade Flap (Regressive)',
        10: '2nd Blade Flap (Collective)', 11: '2nd Blade Flap (Progressive)',
        12: '1st Drivetrain Torsion', 13: '2nd Tower FA', 14: '2nd Tower SS'},
    'StandstillSemi_ForID_EDHD.1.lin': {
        1: 'Platform sway', 2: 'Platform surge', 3: 'Platform yaw', 5: 'Platform pitch',
        6: 'Platform roll', 7: 'Platform heave', 47: '1st Blade Flap (Regressive)',
        50: '1st Blade Flap (Progressive)', 51: '1st Blade Edge (Collective)',
        52: '1st Blade Flap (Collective)', 53: '1st Blade Edge (Progressive)',
        56: '1st Blade Edge (Regressive)', 58: '2nd Blade Flap (Regressive)',
        59: '2nd Blade Flap (Progressive)', 60: '2nd Blade Flap (Collective)'},
    'Main_Rotating.*.lin': {
        1: '1st Blade Flap (Regressive)', 2: '1st Blade Flap (Collective)',
        3: '1st Blade Flap (Progressive)', 4: '1st Blade Edge (Regressive)',
        5: '1st Blade Edge (Progressive)', 6: '2nd Blade Flap (Regressive)',
        7: '2nd Blade Flap (Collective)', 8: '2nd Blade Flap (Progressive)',
        9: 'Generator DOF (not shown)'},
    'ws03.0.*.lin': {
        1: '1st Tower SS', 2: '1st Tower FA', 3: '1st Blade Edge (Collective)',
        4: '1st Blade Flap (Progressive)', 5: '1st Blade Flap (Collective)',
        6: '1st Blade Edge (Regressive)', 7: '1st Blade Flap (Regressive)',
        8: '1st Blade Edge (Progressive)', 9: '2nd Blade Flap (Regressive)',
        10: '2nd Blade Flap (Collective)', 11: '2nd Blade Flap (Progressive)',
        12: '2nd Tower FA', 13: '2nd Tower SS', 14: '1st Drivetrain Torsion'},
    'ws00.0.1.lin': {
        1: '1st Tower SS', 2: '1st Tower FA', 3: '1st Blade Edge (Collective)',
        4: '1st Blade Flap (Regressive)', 5: '1st Blade Flap (Collective)',
        6: '1st Blade Flap (Progressive)', 7: '1st Blade Edge (Regressive)',
        8: '1st Blade Edge (Progressive)', 9: '2nd Blade Flap (Regressive)',
        10: '2nd Blade Flap (Collective)', 11: '2nd Blade Flap (Progressive)',
        12: '2nd Tower FA', 13: '2nd Tower SS', 14: '1st Drivetrain Torsion'},
    'Standstill.1.lin': {
        1: '1st Tower SS', 2: '1st Tower FA', 3: '1st Blade Edge (Collective)',
        4: '1st Blade Flap (Regressive)', 5: '1st Blade Flap (Progressive)',
        6: '1st Blade Flap (Collective)', 7: '1st Blade Edge (Regressive)',
        8: '1st Blade Edge (Progressive)', 9: '2nd Blade Flap (Regressive)',
        10: '1st Drivetrain Torsion', 11: '2nd Blade Flap (Progressive)',
        12: '2nd Blade Flap (Collective)', 13: '2nd Tower FA', 14: '2nd Tower SS'},
    'BAR_URC_EDBD.1.lin': {
        1: '1st Tower SS', 2: '1st Tower FA', 3: '2nd Tower SS', 4: '2nd Tower FA',
        5: '1st Blade Edge (Regressive)', 8: '1st Blade Flap (Collective)',
        9: '1st Blade Flap (Regressive)', 10: '2nd Blade Flap (Collective)'},
    'Standstill_old.1.lin': {
        1: '1st Tower SS', 2: '1st Blade Flap (Collective)', 3: '1st Blade Edge (Collective)',
        4: '1st Blade Flap (Regressive)', 5: '1st Blade Flap (Progressive)',
        7: '1st Blade Edge (Regressive)', 8: '1st Blade Edge (Progressive)',
        9: '2nd Blade Flap (Regressive)', 10: '2nd Blade Flap (Collective)',
        11: '2nd Blade Flap (Progressive)', 13: '2nd Tower FA', 14: '2nd Tower SS'},
}
# ... and without BladeLen and TowerLen (no scaling): the modes that change (None: unnamed)
TOOLBOX_UNSCALED = {
    'Standstill_ForID_ED.1.lin': {12: None},
    'StandstillSemi_ForID_EDHD.1.lin': {54: '1st Tower FA'},
    'ws03.0.*.lin': {4: '1st Blade Flap (Collective)', 5: '1st Blade Flap (Progressive)',
                     14: None},
    'ws00.0.1.lin': {14: None},
    'Standstill.1.lin': {10: None},
    'BAR_URC_EDBD.1.lin': {5: None, 8: None, 9: None, 10: None},
}
# The default rule against the 37 modes the toolbox names on its identification files and
# the rotating NREL 5 MW files ('Generator DOF (not shown)' is a mode it hides).  Where the
# labels differ on purpose (mode_labels' docstring): the toolbox takes the state whose
# eigenvector magnitude peaks at a mode (a measure that depends on the states' units and
# favours low frequencies), ties by its list order, and guesses modes where no state
# peaks; the participation factors name instead:
COMPARED = ('Standstill_ForID_ED.1.lin', 'StandstillSemi_ForID_EDHD.1.lin',
            'Main_Rotating.*.lin')
DIFFERENT = {
    'Standstill_ForID_ED.1.lin': {3: 'drivetrain', 12: '1st edge collective'},
    'StandstillSemi_ForID_EDHD.1.lin': {47: 'hydrodynamics', 50: '1st tower FA',
                                        51: '1st tower SS', 53: '1st flap cyclic'},
}
_STATES = {'drivetrain': r'Drivetrain', 'hydrodynamics': r'^HD ', 'tower FA': r'tower fore-aft',
           'tower SS': r'tower side-to-side', '1st flap': r'1st flapwise',
           '1st edge': r'1st edgewise'}
# IdentifyModes' names in mode_labels' words (the table of its docstring)
_TOOLBOX_WORDS = {'Generator DOF (not shown)': 'generator', 'Nacelle Yaw (not shown)':
                  'nacelle yaw', '1st Drivetrain Torsion': 'drivetrain', 'Tower': 'tower',
                  'Platform': 'platform', 'Blade Flap': 'flap', 'Blade Edge': 'edge',
                  '(Collective)': 'collective', '(Regressive)': 'BW', '(Progressive)': 'FW'}


def _toolbox_as_ours(label):
    for old, new in _TOOLBOX_WORDS.items():
        label = label.replace(old, new)
    return label


def _stiffness_share(A, desc, order, lam, family):
    """|δλ| / (ε|λ|) when the stiffness of the family's states is scaled by 1 + ε."""
    fam = np.array([re.search(_STATES[family], d) is not None for d in desc])
    rate = np.array(['First time derivative' in d for d in desc])
    disp, rates, first = fam & ~rate & (order == 2), fam & rate, fam & (order == 1)
    B, eps = A.copy(), 1e-6
    B[np.ix_(rates, disp)] *= 1 + eps
    B[np.ix_(first, first)] *= 1 + eps
    return np.abs(np.linalg.eigvals(B) - lam).min() / eps / abs(lam)


def _family(label):
    return next(f for f in _STATES if f in label)


@pytest.fixture(scope='module')
def toolbox_models():
    """Per file set: the multi-blade model, its averaged A, modes, and the modes of Im λ > 0
    by natural frequency."""
    out = {}
    for name in TOOLBOX_LABELS:
        with warnings.catch_warnings():
            warnings.simplefilter('error' if name in COMPARED else 'ignore')
            nr, _ = ltp.mbc(ltp.read_lin(str(DATA / name)), 3)
        A = nr.average(method='samples').A
        modes = ltp.floquet_modes(ltp.ltpss(A, np.zeros((len(A), 0)), np.zeros((0, len(A))),
                                            0, period=2 * np.pi))
        upper = [i for i in np.argsort(np.abs(modes.exponents)) if modes.exponents[i].imag > 0]
        out[name] = nr, A, modes, upper
    return out


def test_mode_labels_equal_identify_modes_of_the_toolbox(toolbox_models):
    agree = 0
    for name in COMPARED:
        nr, A, modes, upper = toolbox_models[name]
        standstill = abs(nr.rotor_speed) < 1e-3          # (0.0002 rad/s in the files)
        labels = ltp.mode_labels(modes, nr)
        for number, theirs in TOOLBOX_LABELS[name].items():
            if theirs == 'Generator DOF (not shown)':
                continue
            theirs = _toolbox_as_ours(theirs)
            if standstill:
                theirs = theirs.replace('BW', 'cyclic').replace('FW', 'cyclic')
            ours = labels[upper[number - 1]]
            other = DIFFERENT.get(name, {}).get(number)
            if other is None:
                assert ours == theirs, (name, number, ours)
                agree += 1
                continue
            # a deliberate difference: the frequency depends on the stiffness of the
            # states we name, 1.5 times or more as much as on those the toolbox names
            assert ours == other, (name, number, ours)
            lam = modes.exponents[upper[number - 1]]
            mine = _stiffness_share(A, nr.state_descriptions, nr.derivative_order, lam,
                                    _family(ours))
            toolbox = _stiffness_share(A, nr.state_descriptions, nr.derivative_order, lam,
                                       _family(theirs))
            assert mine > 1.5 * toolbox, (name, number, mine, toolbox)
    assert agree == 31                                   # of 37 labelled by both
    # a blade family has one collective mode: on the floating platform at standstill the
    # collective and cosine flap coordinates mix in modes 52 and 54 (shares 0.54, 0.53)
    nr, A, modes, upper = toolbox_models['StandstillSemi_ForID_EDHD.1.lin']
    labels = ltp.mode_labels(modes, nr)
    assert [labels[upper[k - 1]] for k in (52, 53, 54)] == [
        '1st flap collective', '1st flap cyclic', '1st flap cyclic']
    # ... and every ElastoDyn blade family of the ElastoDyn files: one collective mode and a
    # cyclic pair (BW and FW when the rotor turns)
    for name, (nr, A, modes, upper) in toolbox_models.items():
        if 'BD' in name:
            continue
        labels = ltp.mode_labels(modes, nr)
        names = [labels[i] for i in upper]
        pair = ['cyclic', 'cyclic'] if abs(nr.rotor_speed) < 1e-3 else ['BW', 'FW']
        for family in ('1st flap', '1st edge', '2nd flap'):
            mine = sorted(n[len(family) + 1:] for n in names if n.startswith(family))
            assert mine == sorted(['collective'] + pair), (name, family, mine)
    # an overdamped collective degree of freedom has two real roots, both collective
    Ab = np.array([[0.0, 1.0], [-4.0, -5.0]])                      # roots -1 and -4
    desc = [f'ED 1st flapwise bending-mode DOF of blade {b}, m' for b in (1, 2, 3)]
    desc += [d.replace('ED ', 'ED First time derivative of ') + '/s' for d in desc]
    rot = ltp.RotorStateSpace(
        ltp.PeriodicMatrix.constant(np.kron(Ab, np.eye(3)), 2 * np.pi), np.zeros((6, 0)),
        np.zeros((0, 6)), np.zeros((0, 0)), 2 * np.pi,
        rotor=dict(rotor_speed=1.0, state_descriptions=desc, rotating_states=np.ones(6, bool),
                   derivative_order=np.full(6, 2)))
    nr, _ = ltp.mbc(rot, 3)
    modes = ltp.floquet_modes(nr)
    labels = ltp.mode_labels(modes, nr)
    real = np.abs(modes.exponents.imag) < 1e-9
    assert np.allclose(np.sort(modes.exponents[real].real), [-4, -1])
    assert [lab for lab, r in zip(labels, real) if r] == ['1st flap collective'] * 2
    assert labels.count('1st flap collective') == 2


def test_mode_labels_openfast_rule_equals_identify_modes(toolbox_models):
    """rule='openfast' names every mode as IdentifyModes does, scaled or not."""
    for name, table in TOOLBOX_LABELS.items():
        nr, A, modes, upper = toolbox_models[name]
        if 'old' in name:                # the toolbox's reading of the old format
            nr = copy.copy(nr)
            nr.derivative_order = np.ones(nr.nstates, int)
        unscaled = {**table, **TOOLBOX_UNSCALED.get(name, {})}
        for lengths, truth in (((40, 55), table), ((None, None), unscaled)):
            labels = ltp.mode_labels(modes, nr, 'openfast', blade_length=lengths[0],
                                     tower_length=lengths[1])
            ours = {k + 1: labels[i] for k, i in enumerate(upper) if labels[i] != 'unidentified'}
            assert ours == {k: _toolbox_as_ours(v) for k, v in truth.items() if v}, \
                (name, lengths)
            # a pair has one name; real modes have none
            for i, lam in enumerate(modes.exponents):
                j = np.argmin(np.abs(modes.exponents - np.conj(lam)))
                assert labels[i] == labels[j] if lam.imag else labels[i] == 'unidentified'
    with pytest.raises(ValueError, match="rule must be"):
        ltp.mode_labels(modes, nr, 'toolbox')
    with pytest.raises(ValueError, match="blade_length must be a positive"):
        ltp.mode_labels(modes, nr, 'openfast', blade_length=-1.0)
    with pytest.raises(ValueError, match="modes must be the modes of sys"):
        ltp.mode_labels(toolbox_models['Main_Rotating.*.lin'][2], nr)


def test_campbell_of_a_folder_tree_exported_and_reloaded(tmp_path):
    speeds = np.array([1.2, 0.6, 0.8, 1.0, 1.3, 1.25])       # rpm 5.7 .. 12.4
    winds = np.array([11.0, 4.0, 6.0, 8.0, 14.0, 12.5])
    write_turbine_study(tmp_path, speeds, winds)
    cd = ltp.campbell_lin(tmp_path, x='rotor_speed')
    order = np.argsort(speeds)
    assert np.allclose(cd.values, speeds[order]) and np.allclose(cd.wind_speed, winds[order])
    assert cd.frame == 'multiblade'
    # frequencies: the hand-made multi-blade model's eigenvalues
    for k, Om in enumerate(cd.values):
        truth = np.linalg.eigvals(turbine_mbc_A(Om))
        assert max(np.abs(truth - lam).min() for lam in cd.exponents[k]) < 1e-7
    upper = [k for k in range(16) if np.mean(cd.damped_frequency[:, k] >= 0) >= 0.5]
    assert {cd.labels[j] for j in upper} == {
        '1st tower FA', '1st tower SS', '1st flap BW', '1st flap collective', '1st flap FW',
        '1st edge BW', '1st edge collective', '1st edge FW'}
    assert cd.mac[:, upper].min() > 0.99
    # the forward whirl of the edge crosses no nP line twice: crossings once per pair
    assert len(cd.crossings) == len(set((t, n) for t, n, _, _ in cd.crossings)) or \
        all(t in upper for t, _, _, _ in cd.crossings)
    # table: CSV without pandas, reloaded
    path = tmp_path / 'campbell.csv'
    cd.to_csv(path)
    with open(path) as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == len(upper) * len(cd.values)
    for row in rows:
        j, value = int(row['track']), float(row['value'])
        k = int(np.flatnonzero(cd.values == value)[0])
        assert float(row['frequency_hz']) == cd.frequency[k, j] / (2 * np.pi)
        assert row['label'] == cd.labels[j]
        assert float(row['rotor_speed_rpm']) == pytest.approx(cd.values[k] * 30 / np.pi)
    pd = pytest.importorskip('pandas')
    df = cd.to_dataframe()
    back = pd.read_csv(path)
    assert np.array_equal(back['frequency_hz'].to_numpy(), df['frequency_hz'].to_numpy())
    # ltp.save / ltp.load
    ltp.save(tmp_path / 'cd.npz', cd)
    loaded = ltp.load(tmp_path / 'cd.npz')
    assert np.array_equal(loaded.exponents, cd.exponents) and loaded.labels == cd.labels
    assert loaded.crossings == cd.crossings and loaded.modes == ()
    # plots in Hz against rpm and wind speed, damping in % and log decrement
    import matplotlib
    matplotlib.use('Agg')
    cplt = cd.plot(x='rpm', frequency_unit='Hz', damping='percent')
    assert cplt.axes[1, 0].get_xlabel() == 'rotor speed [rpm]'
    xs = cplt.lines[0, 0][0].get_xdata()
    assert np.allclose(xs, cd.values * 30 / np.pi)
    cplt = cd.plot(x='wind_speed', damping='logdec')
    assert cplt.axes[1, 0].get_ylabel() == 'logarithmic decrement'
    matplotlib.pyplot.close('all')


def test_campbell_of_files_by_floquet_equals_averaging(tmp_path):
    write_turbine_study(tmp_path, [0.7, 1.1], [5.0, 9.0])
    avg = ltp.campbell_lin(tmp_path)
    flo = ltp.campbell_lin(tmp_path, method='floquet')
    assert avg.xlabel == 'wind speed [m/s]'
    for k in range(2):
        assert max(np.abs(avg.exponents[k] - lam).min() for lam in flo.exponents[k]) < 1e-7
    # clean modes: OpenFAST's rule names them alike
    named = ltp.campbell_lin(tmp_path, label_rule='openfast', blade_length=40, tower_length=80)
    assert named.labels == avg.labels and '1st edge FW' in named.labels
    with pytest.raises(ValueError, match="label_rule must be"):
        ltp.campbell_lin(tmp_path, label_rule='IdentifyModes')
    with pytest.raises(ValueError, match="same rotor_speed"):
        ltp.campbell_lin([sorted(next(tmp_path.glob('ws05.0*')).glob('*.lin'))] * 2,
                         x='rotor_speed')


def test_campbell_accepts_averaged_models():
    rot = uncoupled_blades()

    def averaged(Omega):
        sys = ltp.ltpss(rot.A(0.0), np.zeros((6, 1)), np.zeros((1, 6)), 0,
                        period=2 * np.pi / Omega)
        return ltp.mbc(sys, [[0, 1, 2]], 3, rates=[[3, 4, 5]])[0].average()
    cd = ltp.campbell(averaged, [0.5, 1.0, 1.5], n_jobs=1, branch='principal')
    wd = np.sqrt(4 - 0.01)
    assert np.allclose(np.sort(np.abs(cd.damped_frequency[1])),
                       np.sort(np.repeat([wd - 1, wd, wd + 1], 2)), atol=1e-10)
    # each crossing once (not for both tracks of a complex pair)
    pairs = [(n, round(v, 9)) for _, n, v, _ in cd.crossings]
    assert len(pairs) == len(set(pairs))


# State descriptions as OpenFAST writes them (tests/data/README.md names the sources):
# AeroDyn's unsteady-aero states (UA model 6, r-test Fake5MW_AeroLin_B3_UA6.1.lin) and its
# dynamic-inflow states (DBEMT model 3, second order, r-test
# Fake5MW_AeroLin_B1_UA4_DBEMT3.1.lin), ServoDyn's blade structural controls (OpenFAST
# ServoDyn SrvD_Init_Jacobian_x, as the nacelle's in r-test StC_test_OC4Semi_Linear_Nac.1.lin)
UA6 = [f'AD x4 blade {b}, node {j}, -' for b in (1, 2, 3) for j in (2, 3, 4)]
DBEMT = [f'AD vind ({d}) at blade {b}, node {j}, m/s' for b in (1, 2, 3) for j in (1, 2)
         for d in ('axial', 'tangential')]
DBEMT_RATES = [f'AD First time derivative of vind ({d}) at blade {b}, node {j}, m/s/s'
               for b in (1, 2, 3) for j in (1, 2) for d in ('axial', 'tangential')]
BSTC = [f'SrvD Blade {b} StC 1 local displacement state {c}' for b in (1, 2, 3)
        for c in ('X  m', 'Y  m', 'Z  m', 'dX/dt  m/s', 'dY/dt  m/s', 'dZ/dt  m/s')]


def _blade_modules(Omega, psi):
    """Turbine, AeroDyn and ServoDyn blade states: descriptions, orders, blocks of A."""
    lag = np.diag(-np.tile([5.0, 6.0, 7.0], 3))                     # UA: per node
    k = np.tile([4.0, 4.0, 9.0, 9.0], 3)                              # DBEMT: per node
    inflow = np.block([[np.zeros((12, 12)), np.eye(12)],
                       [-np.diag(k), -0.4 * np.eye(12)]])
    stc = np.zeros((18, 18))
    for b in range(3):
        q = slice(6 * b, 6 * b + 3)
        r = slice(6 * b + 3, 6 * b + 6)
        stc[q, r] = np.eye(3)
        stc[r, q] = -np.diag([2.25, 6.25, 16.0])
        stc[r, r] = -0.3 * np.eye(3)
    return [(turbine_descriptions(), [2] * 16, turbine_A(psi / Omega, Omega)),
            (UA6, [1] * 9, lag), (DBEMT + DBEMT_RATES, [2] * 24, inflow),
            (BSTC, [2] * 18, stc)]


def test_aerodyn_and_servodyn_blade_states_grouped_in_any_module_order(tmp_path):
    # uncoupled isotropic blade states of eigenvalue μ (blade frame) have μ and μ ± jΩ in
    # multi-blade coordinates; the turbine's are those of its hand-made multi-blade model
    Omega, nazimuths = 0.9, 6
    one_blade = [np.array([-5.0, -6.0, -7.0]),
                 np.linalg.eigvals(np.block([[np.zeros((4, 4)), np.eye(4)],
                                             [-np.diag([4.0, 4.0, 9.0, 9.0]), -0.4 * np.eye(4)]])),
                 np.linalg.eigvals(np.block([[np.zeros((3, 3)), np.eye(3)],
                                             [-np.diag([2.25, 6.25, 16.0]), -0.3 * np.eye(3)]]))]
    truth = np.concatenate([np.linalg.eigvals(turbine_mbc_A(Omega))]
                           + [mu + 1j * Omega * k for mu in one_blade for k in (-1, 0, 1)])
    for name, order in (('a', (0, 1, 2, 3)), ('b', (3, 2, 1, 0))):
        for s in range(nazimuths):
            psi = 2 * np.pi * s / nazimuths
            parts = [_blade_modules(Omega, psi)[m] for m in order]
            desc = sum((p[0] for p in parts), [])
            write_lin(tmp_path / f'{name}.{s + 1}.lin', block_diag(*[p[2] for p in parts]),
                      Omega, psi, 8.0, desc, ['blade' in d.lower() for d in desc],
                      sum((p[1] for p in parts), []), digits=16)
        lin = ltp.read_lin(str(tmp_path / f'{name}.*.lin'))
        nr, _ = ltp.mbc(lin, 3)
        labels = dict(zip(lin.state_descriptions, nr.state_labels))
        # every blade state is one coordinate of a triplet named after blade 1's state
        for d in UA6 + DBEMT + DBEMT_RATES + BSTC:
            b = int(d.split('lade ')[1][0])
            assert labels[d].endswith(('_0', '_c1', '_s1')[b - 1]), (d, labels[d])
        ev = np.linalg.eigvals(nr.average(method='samples').A)
        assert len(ev) == len(truth) == 67
        assert max(np.abs(truth - lam).min() for lam in ev) < 1e-9
        assert max(np.abs(ev - lam).min() for lam in truth) < 1e-9


def test_tower_azimuths_dropped_and_operating_point_speeds():
    files = sorted(DATA.glob('Main_Rotating.*.lin'))
    lin = ltp.read_lin(files)
    # MBC3 takes Ω from the generator azimuth's derivative at the operating point, Ω̇
    # from its rate's
    assert np.allclose(lin.sample_speeds, 0.9425)
    assert np.allclose(lin.sample_accelerations, [-7.308e-06, 6.543e-06, 7.905e-06])
    # azimuths (deg) 0.5, 110.1, 230.0: the first only is 55 degrees away from the
    # tower passages at 60, 180 and 300
    kept = ltp.read_lin(files, drop_near_tower=55.0)
    assert np.allclose(np.degrees(kept.azimuths), np.degrees(lin.azimuths[[0]]))
    with pytest.raises(ValueError, match="every file"):
        ltp.read_lin(files[1:], drop_near_tower=55.0)


def test_campbell_frame_follows_the_rotor_speed():
    # rotating-frame models of uncoupled blades: measured in the multi-blade frame of
    # each rotor speed, the exponents are the whirl ones ω ± Ω
    desc = [f'ED 1st edgewise bending-mode DOF of blade {b}, m' for b in (1, 2, 3)]
    desc += [d.replace('ED ', 'ED First time derivative of ') + '/s' for d in desc]

    def rotating(Omega):
        A = ltp.PeriodicMatrix.constant(np.kron(AB, np.eye(3)), 2 * np.pi / Omega)
        return ltp.RotorStateSpace(A, np.zeros((6, 0)), np.zeros((0, 6)), np.zeros((0, 0)),
                                   2 * np.pi / Omega, rotor=dict(
                                       rotor_speed=Omega, state_descriptions=desc,
                                       rotating_states=np.ones(6, bool),
                                       derivative_order=np.full(6, 2)))
    cd = ltp.campbell(rotating, [0.5, 0.8], frame='multiblade', n_jobs=1,
                      branch='principal')
    wd = np.sqrt(4 - 0.01)
    for k, Om in enumerate([0.5, 0.8]):
        assert np.allclose(np.sort(np.abs(cd.damped_frequency[k])),
                           np.sort(np.repeat([wd - Om, wd, wd + Om], 2)), atol=1e-10)
    with pytest.raises(ValueError, match="frame must be 'multiblade'"):
        ltp.campbell(rotating, [0.5, 0.8], frame='rotating', n_jobs=1)
