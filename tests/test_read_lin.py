"""OpenFAST linearization files: parsing, periodic models, MBC + averaging.

The expected natural frequencies and damping ratios are those of
openfast_toolbox's own MBC tests (``test_mbc3``) on the same files
(tests/data/README.md).
"""

import pathlib

import numpy as np
import pytest

import ltpcontrol as ltp

DATA = pathlib.Path(__file__).parent / 'data'
WS03 = sorted(DATA.glob('ws03.0.*.lin'))


def modes_hz(A):
    """Natural frequencies (Hz) and damping ratios of the oscillatory modes, by frequency."""
    ev = np.linalg.eigvals(A)
    ev = ev[ev.imag > 0]
    f, z = np.abs(ev) / (2 * np.pi), -ev.real / np.abs(ev)
    order = np.argsort(f)
    return f[order], z[order]


def test_nrel5mw_three_azimuths_mbc_average_reproduces_toolbox():
    lin = ltp.read_lin(WS03)
    assert lin.nstates == 30 and lin.ninputs == 0 and lin.interpolation is None
    assert np.isclose(lin.rotor_speed, 0.7301) and lin.nblades is None
    assert list(lin.azimuths) == [0.0067, 2.0948, 5.76]
    assert lin.state_descriptions[6].startswith('ED 1st flapwise bending-mode DOF of blade 1')
    assert np.all(lin.derivative_order == 2) and lin.rotating_states.sum() == 18
    nr, _ = ltp.mbc(lin, nblades=3)
    assert nr.frame == 'multiblade' and nr.state_labels[6] == 'x[6]_0'
    f, z = modes_hz(nr.average(method='samples').A)
    # openfast_toolbox test_mbc3 (ElastoDyn, 3 azimuths)
    # (the toolbox checks 3 and 4 decimals; the match is closer)
    assert np.allclose(f[:3], [0.31402747, 0.33140717, 0.6263423], atol=1e-6)
    assert np.allclose(100 * z[:3], [0.43860177, 6.03443072, 2.48116647], atol=5e-6)
    # a periodic model cannot be formed from these three azimuths
    with pytest.raises(ValueError, match="not uniform and complete"):
        nr.A(0.1)
    with pytest.raises(ValueError, match="method='samples'"):
        nr.average()
    with pytest.raises(ValueError, match="not uniform"):
        ltp.read_lin(WS03, interpolation='fourier')


def test_standstill_file_reproduces_toolbox():
    lin = ltp.read_lin(DATA / 'Standstill.1.lin')
    assert (lin.nstates, lin.ninputs, lin.noutputs) == (28, 6, 108)
    assert list(lin.rotating_inputs[:3]) == [True, True, True]
    f, z = modes_hz(lin.average(method='samples').A)
    assert np.allclose(f[:3], [0.427, 0.450, 0.669], atol=5e-4)
    assert np.allclose(100 * 2 * np.pi * z[:3], [1.9505, 2.1309, 5.0649], atol=5e-5)
    assert np.allclose(lin.average().A, lin.samples[0][0])
    # multi-blade coordinates of a parked rotor: a constant similarity transform
    with pytest.warns(UserWarning, match="left in the rotating frame"):
        nr, P = ltp.mbc(lin, nblades=3)          # 'RootFxc1' is listed twice
    assert nr.rotor_speed == 0 and np.allclose(P(0.0), P(1.3))
    f_nr, z_nr = modes_hz(nr.average(method='samples').A)
    assert np.allclose(f_nr, f, rtol=1e-9) and np.allclose(z_nr, z, rtol=1e-7, atol=1e-12)
    # the three pitch commands become collective and cyclic pitch: B_NR = 𝒯⁻¹ B T_u
    Tu = ltp.coleman_matrix(0.0, 3)
    assert np.allclose(nr.B(0.0)[:, :3], np.linalg.solve(P(0.0), lin.B(0.0)[:, :3] @ Tu))
    # the tip deflections of the three blades form groups: C_NR = T_y⁻¹ C 𝒯
    tip = [lin.output_descriptions.index(f'ED TipDxb{b}, (m)') for b in (1, 2, 3)]
    assert np.allclose(nr.C(0.0)[tip], np.linalg.solve(Tu, lin.C(0.0)[tip] @ P(0.0)))


#
# Synthetic files of a band-limited rotor model at uniform azimuths
#

def write_lin(path, A, B, C, D, omega, psi, rotating=None, order=None, overflow=None,
              wind=8.0):
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    rotating = rotating if rotating is not None else [False] * n
    order = order if order is not None else [1] * n
    lines = ['', 'Linearized model: synthetic', '', 'Simulation information:',
             f'   Rotor Speed:  {omega:.10f} rad/s', f'   Azimuth:  {psi:.10f} rad',
             f'   Wind Speed:  {wind:.4f} m/s', f'   Number of continuous states:  {n}',
             '   Number of discrete states:  0', '   Number of constraint states:  0',
             f'   Number of inputs:  {m}', f'   Number of outputs:  {p}',
             '   Jacobians included in this file?    No', '']

    def table(title, count, flags, orders, what):
        out = [title, '   Row/Column Operating Point  Rotating Frame? Derivative Order '
               'Description', '   ---------- ---------------  ---------------']
        for i in range(count):
            out.append(f'   {i + 1:8d}    0.0E+00   {"T" if flags[i] else "F"}   '
                       f'{orders[i]}   {what} {i + 1} of blade {i % 3 + 1}, m')
        return out + ['']
    lines += table('Order of continuous states:', n, rotating, order, 'state')
    lines += table('Order of continuous state derivatives:', n, rotating, order, 'rate')
    if m:
        lines += table('Order of inputs:', m, [False] * m, [0] * m, 'input')
    if p:
        lines += table('Order of outputs:', p, [False] * p, [0] * p, 'output')
    lines += ['', 'Linearized state matrices:', '']
    for name, M in zip('ABCD', (A, B, C, D)):
        if M.size:
            lines.append(f'{name}: {M.shape[0]} x {M.shape[1]}')
            for r, row in enumerate(M):
                vals = [f'{v: .15E}' for v in row]
                if overflow == (name, r):
                    vals[0] = '**********'
                lines.append('  ' + ' '.join(vals))
            lines.append('')
    path.write_text('\n'.join(lines) + '\n')


def band_limited(psi):
    A0 = np.array([[-1.0, 2.0], [-3.0, -0.5]])
    return A0 + np.array([[0.3, 0], [0.1, 0.2]]) * np.cos(psi) \
        + np.array([[0, 0.4], [0.2, 0]]) * np.sin(2 * psi)


def write_set(tmp_path, psis, omega=2.0, **kw):
    files = []
    for i, psi in enumerate(psis):
        f = tmp_path / f'op.{i + 1}.lin'
        write_lin(f, band_limited(psi), np.array([[1.0], [0.5]]), np.array([[1.0, 0.0]]),
                  np.zeros((1, 1)), omega, psi, **kw)
        files.append(f)
    return files


def test_uniform_azimuths_give_the_trigonometric_interpolant(tmp_path):
    psis = 0.1 + 2 * np.pi * np.arange(8) / 8
    files = write_set(tmp_path, psis)
    lin = ltp.read_lin(files[::-1])                     # any order
    assert lin.interpolation == 'fourier' and np.isclose(lin.period, np.pi)
    assert np.isclose(lin.azimuth0, 0.1)
    for t in np.random.default_rng(3).uniform(0, lin.period, 5):
        assert np.allclose(lin.A(t), band_limited(0.1 + 2.0 * t), atol=1e-9)
    held = ltp.read_lin(files, interpolation='hold')
    assert np.allclose(held.A(0.5 * lin.period / 8), band_limited(psis[0]))
    # the Fourier mean equals the sample mean for band-limited data
    assert np.allclose(lin.average().A, lin.average(method='samples').A)
    assert np.allclose(lin.average().A, band_limited(0.0) - [[0.3, 0], [0.1, 0.2]])


def test_bad_file_sets_raise_clear_errors(tmp_path):
    psis = 2 * np.pi * np.arange(4) / 4
    files = write_set(tmp_path, psis)
    with pytest.raises(ValueError, match="same azimuth"):
        ltp.read_lin(files + files[:1])
    other = tmp_path / 'other'
    other.mkdir()
    slow = write_set(other, [0.3], omega=2.5)
    with pytest.raises(ValueError, match="different operating points"):
        ltp.read_lin(files + slow)
    with pytest.raises(ValueError, match="different models"):
        ltp.read_lin(files[:1] + WS03[:1])
    (tmp_path / 'nu').mkdir()
    nonuniform = write_set(tmp_path / 'nu', [0.0, 1.0, 2.5, 4.0])
    lin = ltp.read_lin(nonuniform)
    assert lin.interpolation is None
    with pytest.raises(ValueError, match="not uniform"):
        ltp.read_lin(nonuniform, interpolation='hold')
    with pytest.raises(ValueError, match="interpolation"):
        ltp.read_lin(files, interpolation='spline')
    with pytest.raises(ValueError, match="not an OpenFAST"):
        ltp.read_lin(DATA / 'README.md')


def test_overflow_fields(tmp_path):
    f = tmp_path / 'ovf.1.lin'
    write_lin(f, band_limited(0.0), np.ones((2, 1)), np.ones((1, 2)), np.zeros((1, 1)),
              2.0, 0.0, overflow=('A', 1))
    with pytest.raises(ValueError, match=r"A\[1, 0\] overflowed"):
        ltp.read_lin(f)
    lin = ltp.read_lin(f, overflow=0.0)
    assert lin.samples[0][0, 1, 0] == 0.0


def test_mbc_of_files_checks_blade_groups(tmp_path):
    # six first-order rotating states: two degrees of freedom of three blades
    n = 6
    A = -np.eye(n)
    files = []
    for i, psi in enumerate(2 * np.pi * np.arange(6) / 6):
        f = tmp_path / f'rot.{i}.lin'
        write_lin(f, A, np.zeros((n, 0)), np.zeros((0, n)), np.zeros((0, 0)), 1.0, psi,
                  rotating=[True] * n, order=[1] * n)
        files.append(f)
    lin = ltp.read_lin(files)
    nr, _ = ltp.mbc(lin, nblades=3)
    assert np.allclose(nr.A(0.3), -np.eye(n) - np.kron(np.eye(2), [[0, 0, 0], [0, 0, 1],
                                                                    [0, -1, 0]]))
    with pytest.raises(ValueError, match="wrong blade count"):
        ltp.mbc(lin, nblades=4)
    with pytest.raises(ValueError, match="blades"):
        ltp.mbc(lin, nblades=2)
