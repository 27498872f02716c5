"""Single-phase grid-following inverter with SOGI-PLL, linearized about its
periodic steady state (used by the gallery example and the benchmarks).

Circuit: converter voltage v_c, filter L_f (resistance R_f), point of common
coupling (PCC) v_pcc, grid inductance L_g to the grid EMF e = E cos ω_g t.
Control: current reference i_ref = I cos θ (in phase with the PLL angle),
proportional-resonant current controller, computation and PWM delay T_d
(first-order Padé), second-order generalized integrator (SOGI) at ω_g on
the measured v_pcc, and a PI phase-locked loop on
q = -v_α' sin θ + v_β' cos θ.

States: i, the resonant pair (r1, r2), the delay state d, the SOGI pair
(a, b), the PLL integrator z and the phase offset φ = θ - ω_g t (8 states).

The steady state is exact: with the PLL locked (q = 0, z = 0, φ constant)
every other signal is a sinusoid at ω_g whose phasor solves a linear system,
and φ equals the phase of the PCC voltage (a scalar fixed point).  About it
the Jacobian is A(t) = A_0 + A_c cos ω_g t + A_s sin ω_g t: an exact Fourier
series with one harmonic.
"""

import numpy as np
from scipy.optimize import brentq

import ltpcontrol as ltp

WG = 2 * np.pi * 50.0
PARAMS = dict(E=325.0, I=20.0, Lf=2e-3, Rf=0.1, Kp=10.0, Kr=400.0, wc=5.0, Td=150e-6,
              k=np.sqrt(2), kpp=2 * 0.7 * 2 * np.pi * 40 / 325.0,
              kip=(2 * np.pi * 40) ** 2 / 325.0)
NAMES = ['i', 'r1', 'r2', 'd', 'a', 'b', 'z', 'phi']


def _linear_part(p, Lg, Lf_only=False):
    """Matrices of the linear dynamics with v_c, i_ref and the PCC voltage
    eliminated; inputs (e, i_ref) or, with Lf_only, (v_pcc, i_ref)."""
    Lf, Rf, Kp, Kr, wc, Td, k = (p[n] for n in ('Lf', 'Rf', 'Kp', 'Kr', 'wc', 'Td', 'k'))
    Ltot = Lf if Lf_only else Lf + Lg
    # v_cmd = Kp (i_ref - i) + 2 Kr wc r2 ;  v_c = -v_cmd + d
    # Ltot di/dt = v_c - Rf i - w  (w = e, or v_pcc when Lf_only)
    # v_pcc = e + Lg di/dt  (not Lf_only) ;  SOGI input v_pcc
    A = np.zeros((6, 6))
    B = np.zeros((6, 2))             # inputs: w, i_ref
    vcmd_x = np.array([-Kp, 0, 2 * Kr * wc, 0, 0, 0])
    vcmd_u = np.array([0.0, Kp])
    vc_x = -vcmd_x + np.array([0, 0, 0, 1.0, 0, 0])
    vc_u = -vcmd_u
    di_x = (vc_x - np.array([Rf, 0, 0, 0, 0, 0])) / Ltot
    di_u = (vc_u - np.array([1.0, 0.0])) / Ltot
    A[0], B[0] = di_x, di_u
    A[1, 2] = 1.0
    A[2] = np.array([-1.0, -WG ** 2, -2 * wc, 0, 0, 0])
    B[2] = [0.0, 1.0]
    A[3] = (2 / Td) * (2 * vcmd_x - np.array([0, 0, 0, 1.0, 0, 0]))
    B[3] = (2 / Td) * 2 * vcmd_u
    if Lf_only:
        vp_x, vp_u = np.zeros(6), np.array([1.0, 0.0])
    else:
        vp_x, vp_u = Lg * di_x, np.array([1.0, 0.0]) + Lg * di_u
    A[4] = k * WG * vp_x + np.array([0, 0, 0, 0, -k * WG, -WG])
    B[4] = k * WG * vp_u
    A[5, 4] = WG
    return A, B, vp_x, vp_u


def steady_state(Lg, p=PARAMS):
    """(phi, phasors X of the six linear states, |V_pcc|) of the locked orbit."""
    A, B, vp_x, vp_u = _linear_part(p, Lg)
    M = np.linalg.inv(1j * WG * np.eye(6) - A)

    def phasors(phi):
        U = np.array([p['E'], p['I'] * np.exp(1j * phi)])
        X = M @ (B @ U)
        return X, vp_x @ X + vp_u @ U

    def mismatch(phi):
        _, V = phasors(phi)
        return np.angle(V * np.exp(-1j * phi))
    grid = np.linspace(-np.pi / 2, np.pi / 2, 181)
    vals = np.array([mismatch(x) for x in grid])
    i = np.nonzero((np.sign(vals[:-1]) != np.sign(vals[1:]))
                   & (np.abs(vals[:-1] - vals[1:]) < np.pi))[0][0]
    phi = brentq(mismatch, grid[i], grid[i + 1], xtol=1e-15)
    X, V = phasors(phi)
    return phi, X, abs(V)


def _jacobian_parts(Lg, p, Lf_only):
    """A_0, A_c, A_s (A(t) = A_0 + A_c cos ω_g t + A_s sin ω_g t) and B, with the
    linear inputs (w, i_ref) and the PLL closed."""
    phi, X, Vm = steady_state(Lg, p)
    A, B, vp_x, vp_u = _linear_part(p, Lg, Lf_only)
    n = 8
    A0, Ac, As = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    A0[:6, :6] = A
    # i_ref = I cos(θ): ∂/∂φ = -I sin θ*, θ* = ω_g t + φ*
    # sin θ* = sin ω_g t cos φ + cos ω_g t sin φ
    col = B[:, 1] * (-p['I'])
    Ac[:6, 7] += col * np.sin(phi)
    As[:6, 7] += col * np.cos(phi)
    # q = -a sin θ + b cos θ:  ∂q/∂a = -sin θ*, ∂q/∂b = cos θ*, ∂q/∂φ = -|V|
    dq_c, dq_s = np.zeros(n), np.zeros(n)
    dq_c[4], dq_s[4] = -np.sin(phi), -np.cos(phi)
    dq_c[5], dq_s[5] = np.cos(phi), -np.sin(phi)
    dq_0 = np.zeros(n)
    dq_0[7] = -Vm
    for row, gain in ((6, 1.0), (7, p['kpp'])):
        A0[row] += gain * dq_0
        Ac[row] += gain * dq_c
        As[row] += gain * dq_s
    A0[7, 6] += p['kip']
    Bw = np.zeros((n, 1))
    Bw[:6, 0] = B[:, 0]
    return A0, Ac, As, Bw, vp_x


def _periodic(A0, Ac, As):
    # P(t) = P_0 + 2 Re(P_1 e^{jωt}):  cos -> P_1 = A_c/2, sin -> P_1 = -j A_s/2
    P1 = 0.5 * Ac - 0.5j * As
    return ltp.PeriodicMatrix(np.stack([P1.conj(), A0.astype(complex), P1]), 2 * np.pi / WG)


def closed_loop(Lg, p=PARAMS):
    """The whole linearized system (grid included): an autonomous LTP system."""
    A0, Ac, As, _, _ = _jacobian_parts(Lg, p, False)
    return ltp.ltpss(_periodic(A0, Ac, As), np.zeros((8, 1)), np.eye(8), 0,
                     period=2 * np.pi / WG, name='inverter+grid', states=NAMES)


def closed_loop_matrix(Lg, p=PARAMS):
    """t -> A(t) of `closed_loop` (for an independent integration)."""
    A0, Ac, As, _, _ = _jacobian_parts(Lg, p, False)
    return lambda t: A0 + Ac * np.cos(WG * t) + As * np.sin(WG * t)


def admittance(Lg_op, p=PARAMS):
    """Inverter admittance Y: v_pcc -> i (small signal, about the orbit of the
    grid inductance `Lg_op`)."""
    A0, Ac, As, Bw, _ = _jacobian_parts(Lg_op, p, True)
    C = np.zeros((1, 8))
    C[0, 0] = 1.0
    return ltp.ltpss(_periodic(A0, Ac, As), Bw, C, 0, period=2 * np.pi / WG,
                     name='Y', states=NAMES, inputs='v_pcc', outputs='i')


def impedance_loop(Lg, p=PARAMS):
    """Loop ``-Z_g Y`` with ``Z_g = s L_g`` (negative-feedback convention):
    ``v_pcc = L_g di/dt`` closes it.  Biproper: ``L(∞) = L_g/L_f``.

    ``s L_g Y`` is the output derivative ``L_g d/dt (C x) = L_g (C A x + C B u)``
    (C constant), exact for a periodic Y.
    """
    Y = admittance(Lg, p)
    C = Y.C(0.0)
    return ltp.ltpss(Y.A, Y.B, -Lg * (C @ Y.A), -Lg * (C @ Y.B(0.0)), period=Y.period,
                     name='-Zg*Y')
