"""Higher-harmonic control of a flapping rotor blade in forward flight: the
N/rev load rejected in an independent closed-loop simulation (solve_ivp),
the loop stable by the Nyquist criterion and by Floquet multipliers."""

import numpy as np
import control as ct
import pytest
from control.exception import ControlDimension
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

# Peters & Hohenemser flapping blade: Lock number, flap frequency, advance ratio
GAM, PF, MU = 8.0, 1.1, 0.3
NREV = 3
TR = 2 * np.pi              # time is the azimuth: Ω = 1


def _A(t):
    return np.array([[0.0, 1.0],
                     [-(PF ** 2 + GAM / 8 * (4 / 3 * MU * np.cos(t) + MU ** 2 * np.sin(2 * t))),
                      -GAM / 8 * (1 + 4 / 3 * MU * np.sin(t))]])


def _b(t):
    # pitch input (periodic aerodynamic coefficient)
    return np.array([0.0, GAM / 8 * (1 + 8 / 3 * MU * np.sin(t) + 2 * MU ** 2 * np.sin(t) ** 2)])


def rotor():
    A = ltp.PeriodicMatrix.from_function(_A, TR)
    B = ltp.PeriodicMatrix.from_function(lambda t: _b(t)[:, None], TR)
    return ltp.ltpss(A, B, [[PF ** 2, 0.0]], 0, period=TR, name='blade')


def _steady_nrev(u_fun, nper=30):
    """N/rev cosine and sine amplitudes of the blade's steady output, by solve_ivp."""
    sol = solve_ivp(lambda t, x: _A(t) @ x + _b(t) * u_fun(t), (0, nper * TR), [0.0, 0.0],
                    rtol=1e-10, atol=1e-12, dense_output=True, method='DOP853')
    t = np.linspace((nper - 1) * TR, nper * TR, 4001)
    y = PF ** 2 * sol.sol(t)[0]
    return (2 / TR * np.trapezoid(y * np.cos(NREV * t), t),
            2 / TR * np.trapezoid(y * np.sin(NREV * t), t))


def test_tmatrix_equals_simulated_steady_state():
    T = ltp.hhc_tmatrix(rotor(), NREV)
    col_c = _steady_nrev(lambda t: np.cos(NREV * t))
    col_s = _steady_nrev(lambda t: np.sin(NREV * t))
    np.testing.assert_allclose(T, np.column_stack([col_c, col_s]), atol=1e-6)


def test_hhc_rejects_the_nrev_load_in_closed_loop():
    P = rotor()
    T = ltp.hhc_tmatrix(P, NREV)
    gamma = 0.1
    K = ltp.hhc_controller(T, NREV, gamma)
    # stable by both criteria
    resp = ltp.nyquist_htf((P, K), 8)
    assert resp.stable and resp.open_loop_unstable == 0
    assert np.abs(ltp.floquet_multipliers(ltp.feedback(P, K))).max() < 1
    m = ltp.harmonic_margins((P, K), 8)
    assert m.gain_upper.value > 2

    # independent closed loop: blade + demodulate/integrate/remodulate, N/rev load d
    M = np.linalg.solve(T.T @ T, T.T)
    d = lambda t: 0.5 * np.cos(NREV * t + 0.4)

    def rhs(t, s, on):
        x, th = s[:2], s[2:]
        c, sn = np.cos(NREV * t), np.sin(NREV * t)
        u = -(c * th[0] + sn * th[1]) if on else 0.0
        y = PF ** 2 * x[0]
        dx = _A(t) @ x + _b(t) * u + np.array([0.0, d(t)])
        dth = gamma * M @ np.array([2 * c * y, 2 * sn * y]) if on else np.zeros(2)
        return np.concatenate([dx, dth])

    nper = 15
    t = np.linspace((nper - 1) * TR, nper * TR, 4001)
    amp = []
    for on in (False, True):
        sol = solve_ivp(rhs, (0, nper * TR), np.zeros(4), args=(on,), rtol=1e-10,
                        atol=1e-13, dense_output=True, method='DOP853')
        y = PF ** 2 * sol.sol(t)[0]
        amp.append(abs(2 / TR * np.trapezoid(y * np.exp(-1j * NREV * t), t)))
    reduction_db = 20 * np.log10(amp[0] / amp[1])
    assert amp[0] > 0.01
    print(f"N/rev reduction {reduction_db:.1f} dB")
    assert reduction_db >= 40, reduction_db


def test_lti_plant_hhc_compensator_is_lti():
    # Hall & Wereley: for an LTI plant the HHC compensator is an LTI notch at ω
    G = ct.tf([1], [1, 0.4, 1])
    T = ltp.hhc_tmatrix(G, 2, period=TR)
    K = ltp.hhc_controller(T, 2.0, 0.1)
    with pytest.warns(UserWarning, match='unstable'):     # integrators of θ
        H = ltp.htf(K, 3)(0.37j)
    off = H - np.diag(np.diag(H))
    assert np.abs(off).max() < 1e-12 * np.abs(H).max()


def test_hhc_bad_input():
    with pytest.raises(ControlDimension):
        ltp.hhc_controller(np.eye(3), 1.0, 0.1)
    with pytest.raises(ValueError, match="singular"):
        ltp.hhc_controller(np.zeros((2, 2)), 1.0, 0.1)
    with pytest.raises(ValueError, match="gain"):
        ltp.hhc_controller(np.eye(2), 1.0, -0.1)
    with pytest.raises(ValueError, match="unstable"):
        ltp.hhc_tmatrix(ct.tf([1], [1, -1]), 1, period=TR)
