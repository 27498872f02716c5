"""Tests of the hopper, VHOP and Mathieu example models and their gallery scripts."""

import numpy as np
import pytest
from scipy.linalg import expm

from examples import hopper, mathieu, vhop
from example_scripts import run_script

from ltpcontrol import simulate_hybrid  # noqa: E402
from ltpcontrol import linearize_orbit  # noqa: E402
from systems import fd_period_map_jacobian  # noqa: E402


@pytest.fixture(scope='module')
def hop():
    plant = hopper.hopper_plant()
    return plant, hopper.hopper_orbit(plant)


class TestHopper:
    def test_limit_cycle_reached_by_simulation(self, hop):
        # thesis §3.4.3: 30 cycles of cos 2πt forcing from rest reach the 1 s limit cycle
        plant, orbit = hop
        p = hopper.HOPPER_PARAMS
        rest = [p['x0'] - p['m'] * p['g'] / p['k'], 0.0]
        resp = simulate_hybrid(plant, np.arange(31.0), rest, 'lossless')
        assert resp.modes[-1] == orbit.mode0
        np.testing.assert_allclose(resp.states[:, -1], orbit.x0, atol=1e-5)
        assert orbit.is_stable and len(orbit.switching_times) == 2

    def test_saltation_jacobian_matches_finite_differences(self, hop):
        plant, orbit = hop
        fd = fd_period_map_jacobian(plant, 1.0, orbit.x0, orbit.mode0, 1e-6)
        scale = np.abs(orbit.monodromy).max()
        np.testing.assert_allclose(orbit.monodromy / scale, fd / scale, atol=1e-5)

    def test_return_map_formula_3_43(self, hop):
        # the damping force vanishes at the switch ẋ = 0: S = I, and (3.43) is exact
        plant, orbit = hop
        for S in orbit.saltation_matrices:
            np.testing.assert_allclose(S, np.eye(2), atol=1e-8)
        DP = hopper.piecewise_lti_return_map(orbit)
        np.testing.assert_allclose(DP, orbit.monodromy, atol=1e-8)
        t_hat = orbit.switching_times
        A0 = np.array([[0, 1], [-200.0, -2.0]])
        A1 = np.array([[0, 1], [-200.0, 0.0]])
        # (3.43) on the section at the start of the lossy phase: a cyclic shift of DP
        shifted = expm(A0 * t_hat[0]) @ expm(A1 * (t_hat[1] - t_hat[0])) \
            @ expm(A0 * (1 - t_hat[1]))
        np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(shifted)),
                                   np.sort_complex(orbit.multipliers), atol=1e-8)

    def test_analytic_ltp_model_3_39(self, hop):
        plant, orbit = hop
        analytic = hopper.hopper_ltp(orbit)
        lin = linearize_orbit(plant, orbit)
        for t in np.linspace(0, 1, 17, endpoint=False):
            np.testing.assert_allclose(lin.A(t), analytic.A(t), atol=1e-7)
            np.testing.assert_allclose(lin.B(t), analytic.B(t), atol=1e-8)
            np.testing.assert_allclose(lin.C(t), analytic.C(t), atol=1e-8)
        # square-wave damping flag: mean of A[1, 1] is −c × (lossy fraction)
        lossy = sum(b - a for a, b, m in zip(np.r_[0, orbit.switching_times],
                                             np.r_[orbit.switching_times, 1.0],
                                             orbit.mode_sequence) if m == 0)
        np.testing.assert_allclose(analytic.A.fourier(0)[0, 1, 1].real, -2.0 * lossy,
                                   atol=1e-12)
        np.testing.assert_allclose(analytic.monodromy(), orbit.monodromy, atol=1e-7)

    def test_unknown_parameter(self):
        with pytest.raises(TypeError, match="spring"):
            hopper.hopper_plant(spring=3)


@pytest.fixture(scope='module')
def vorbit():
    """The VHOP plant and its limit cycle, shared by the VHOP tests."""
    plant = vhop.vhop_plant()
    return plant, vhop.vhop_orbit(plant)


@pytest.mark.slow
class TestVhop:

    def test_limit_cycle_from_release(self, vorbit):
        plant, orbit = vorbit
        assert orbit.is_stable
        names = [plant.mode_names[i] for i in orbit.mode_sequence]
        assert names == ['stance', 'flight', 'stance']
        # touchdown resets the toe: two multipliers vanish
        assert np.sum(np.abs(orbit.multipliers) < 1e-10) == 2
        # period: successive touchdowns of a simulation started on the orbit
        resp = simulate_hybrid(plant, np.linspace(0, 4 * vhop.PERIOD, 5), orbit.x0, 'stance')
        touchdowns = resp.event_times[[j == 0 for _, j in resp.event_modes]]
        assert len(touchdowns) == 4
        np.testing.assert_allclose(np.diff(touchdowns), vhop.PERIOD, rtol=0, atol=1e-9)
        np.testing.assert_allclose(resp.states[:, -1], orbit.x0, atol=1e-8)

    def test_saltation_jacobian_matches_finite_differences(self, vorbit):
        plant, orbit = vorbit
        fd = fd_period_map_jacobian(plant, vhop.PERIOD, orbit.x0, orbit.mode0, 1e-6)
        scale = np.abs(orbit.monodromy).max()
        np.testing.assert_allclose(orbit.monodromy / scale, fd / scale, atol=1e-5)
        # the touchdown jump: saltation matrix differs from the identity
        assert max(np.abs(S - np.eye(4)).max() for S in orbit.saltation_matrices) > 1

    def test_rest_on_ground_never_lifts_off(self):
        p = vhop.VHOP_PARAMS
        plant = vhop.vhop_plant()
        rest = [p['l0'] - p['M'] * p['g'] / p['k'], 0, 0, 0]
        resp = simulate_hybrid(plant, np.linspace(0, 30 * vhop.PERIOD, 31), rest, 'stance',
                               rtol=1e-8)
        assert resp.final_mode == 0 and resp.event_times[-1] < 15 * vhop.PERIOD


class TestMathieu:
    def test_mathieu_4_115(self):
        sys = mathieu.mathieu_ltp()
        assert sys.period == 0.5
        t = 0.1
        wp = 4 * np.pi
        np.testing.assert_allclose(sys.A(t), [[0, 1], [-39.4784176, -3.7699112]], atol=1e-6)
        np.testing.assert_allclose(sys.B(t), [[0], [1 + 0.4 * np.cos(wp * t)]], atol=1e-12)
        np.testing.assert_allclose(sys.C(t), [[1 + 0.2 * np.cos(wp * t), 0]], atol=1e-12)
        np.testing.assert_allclose(sys.monodromy(), expm(sys.A(0) * 0.5), atol=1e-9)

    def test_switching_mathieu_4_26(self):
        sys = mathieu.switching_mathieu_ltp()
        pieces = sys.A._pieces
        np.testing.assert_allclose(pieces[0].fourier(1)[1].real,
                                   [[0, 1], [-39.4784, -3.7699]], atol=1e-4)
        np.testing.assert_allclose(pieces[0].fourier(1)[2].real, [[0, 0], [-3.9478, 0]],
                                   atol=1e-4)
        np.testing.assert_allclose(pieces[1].fourier(1)[1].real,
                                   [[0, 1], [-39.4784, -1.2566]], atol=1e-4)
        np.testing.assert_allclose(pieces[1].fourier(1)[2].real, [[0, 0], [-7.8957, 0]],
                                   atol=1e-4)
        wn, wp = 2 * np.pi, 4 * np.pi
        for t, beta, zeta in [(0.1, 0.1, 0.3), (0.4, 0.2, 0.1)]:
            np.testing.assert_allclose(
                sys.A(t), [[0, 1], [-(1 + 2 * beta * np.cos(wp * t)) * wn ** 2, -2 * zeta * wn]],
                atol=1e-10)


@pytest.mark.slow
@pytest.mark.parametrize('script, png', [('plot_hopper_return_map.py', 'hopper_return_map.png')])
def test_gallery_script(script, png, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    run_script(script, run_name='__main__')
    assert (tmp_path / png).stat().st_size > 1000
    out = capsys.readouterr().out
    if script.startswith('plot_hopper'):
        # (3.43) and the exact Jacobian agree; the pair is real around k = 158
        difference = float(out.split('over the sweep:')[1].split()[0])
        assert difference < 1e-7
        low, high = (float(v) for v in out.split('k in [')[1].split(']')[0].split(','))
        assert low <= 158 <= high and high - low < 10
