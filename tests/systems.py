"""Reference systems from the thesis used across the test suite."""

import numpy as np

import ltpcontrol as ltp


def mathieu(wp=4 * np.pi, wn=2 * np.pi, zeta=0.3, beta_b=0.2, beta_c=0.1):
    """Thesis eq. (4.115): constant A, periodic B and C, T = 2π/ω_p."""
    T = 2 * np.pi / wp
    B = ltp.PeriodicMatrix([[[0.0], [beta_b]], [[0.0], [1.0]], [[0.0], [beta_b]]], T)
    C = ltp.PeriodicMatrix([[[beta_c, 0.0]], [[1.0, 0.0]], [[beta_c, 0.0]]], T)
    return ltp.ltpss([[0, 1], [-wn ** 2, -2 * zeta * wn]], B, C, 0, period=T,
                     name='mathieu')


def damped_mathieu(wn=2 * np.pi, zeta=0.1, beta=0.2, T=0.5):
    """Thesis eq. (4.24) with a genuinely periodic A(t)."""
    wp = 2 * np.pi / T
    A = ltp.PeriodicMatrix([[[0, 0], [-beta * wn ** 2, 0]],
                            [[0, 1], [-wn ** 2, -2 * zeta * wn]],
                            [[0, 0], [-beta * wn ** 2, 0]]], T)
    return ltp.ltpss(A, [[0], [1]], [[1, 0]], 0, period=T, name='damped_mathieu')


def switching_mathieu(t_switch=0.25, T=0.5, wn=2 * np.pi):
    """Thesis eq. (4.25) with the Table 4.1 parameters (switch at `t_switch`)."""
    wp = 2 * np.pi / T

    def piece(zeta, beta):
        return ltp.PeriodicMatrix([[[0, 0], [-beta * wn ** 2, 0]],
                                   [[0, 1], [-wn ** 2, -2 * zeta * wn]],
                                   [[0, 0], [-beta * wn ** 2, 0]]], T)
    A = ltp.PeriodicMatrix.switching([piece(0.3, 0.1), piece(0.1, 0.2)],
                                     [0.0, t_switch], T)
    return ltp.ltpss(A, [[0], [1]], [[1, 0]], 0, period=T, name='switching_mathieu')


def fd_period_map_jacobian(plant, period, x0, mode0=0, h=1e-4):
    """Central-difference Jacobian of the simulated period map (independent check)."""
    from ltpcontrol import period_map
    n = len(x0)
    jac = np.empty((n, n))
    for j in range(n):
        dx = np.zeros(n)
        dx[j] = h
        jac[:, j] = (period_map(plant, period, x0 + dx, mode0)[0]
                     - period_map(plant, period, x0 - dx, mode0)[0]) / (2 * h)
    return jac


def random_periodic_plant(n, ninputs=1, seed=0, period=1.0, name=None):
    """Stable random plant with time-varying ``A(t) = A_0 + A_1 cos ω_p t``, one output."""
    rng = np.random.default_rng(seed)
    A0 = rng.standard_normal((n, n)) / np.sqrt(n)
    A0 -= (np.max(np.linalg.eigvals(A0).real) + 1.0) * np.eye(n)
    A1 = 0.3 * rng.standard_normal((n, n)) / np.sqrt(n)
    w = 2 * np.pi / period
    return ltp.ltpss(lambda t: A0 + A1 * np.cos(w * t), rng.standard_normal((n, ninputs)),
                     rng.standard_normal((1, n)), 0, period=period, name=name)


def real_fourier_basis(nharmonics):
    """Unitary V mapping harmonics -K..K to the real basis c_0, c_1, s_1, ..., c_K, s_K.

    Stated from the definitions (independent of the library):
    ``c_0 = e_0``, ``c_n = (e_n + e_{-n})/√2``, ``s_n = j(e_n - e_{-n})/√2``,
    with e_n the unit vector of harmonic n.
    """
    K = nharmonics
    V = np.zeros((2 * K + 1, 2 * K + 1), complex)
    V[K, 0] = 1.0
    for n in range(1, K + 1):
        V[[K + n, K - n], 2 * n - 1] = 1 / np.sqrt(2)
        V[[K + n, K - n], 2 * n] = 1j / np.sqrt(2), -1j / np.sqrt(2)
    return V
