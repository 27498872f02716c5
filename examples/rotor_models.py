"""Rotor models of the literature for the rotor gallery and its tests.

Ground resonance (Hammond 1974): a four-bladed rotor with rigid blades on
lag hinges at offset e, on a hub with masses Mx, My, springs Kx, Ky and
dampers Cx, Cy.  States ``[x, y, ζ_1..ζ_N, ẋ, ẏ, ζ̇_1..ζ̇_N]`` in the rotating
frame of the blades (lag angles) and the fixed frame of the hub.
"""

import numpy as np

HAMMOND = dict(nblades=4, S=289.1, I=1084.7, e=0.3048, k_lag=0.0, c_lag=4067.5,
               Mx=8026.6, My=3283.6, Kx=1240481.8, Ky=1240481.8, Cx=51078.7,
               Cy=51078.7 / 2)


def hammond_matrices(t, Omega, c_lag=None, data=HAMMOND):
    """Mass, damping and stiffness matrices at time t (blade-1 azimuth Ωt)."""
    N = data['nblades']
    c_lag = np.full(N, data['c_lag']) if c_lag is None else np.asarray(c_lag, float)
    psi = Omega * t + 2 * np.pi * np.arange(N) / N
    S, s, c = data['S'], np.sin(psi), np.cos(psi)
    M, C, K = (np.zeros((N + 2, N + 2)) for _ in range(3))
    M[0, 0], M[1, 1] = data['Mx'], data['My']
    M[0, 2:], M[1, 2:] = -S * s, S * c
    M[2:, 0], M[2:, 1] = -S * s, S * c
    M[2:, 2:] = data['I'] * np.eye(N)
    C[0, 0], C[1, 1] = data['Cx'], data['Cy']
    C[0, 2:], C[1, 2:] = -2 * Omega * S * c, -2 * Omega * S * s
    C[2:, 2:] = np.diag(c_lag)
    K[0, 0], K[1, 1] = data['Kx'], data['Ky']
    K[0, 2:], K[1, 2:] = Omega ** 2 * S * s, -Omega ** 2 * S * c
    K[2:, 2:] = (data['k_lag'] + data['e'] * S * Omega ** 2) * np.eye(N)
    return M, C, K


def hammond_A(t, Omega, c_lag=None):
    """State matrix ``[[0, I], [-M⁻¹K, -M⁻¹C]]`` of the rotating-frame model."""
    M, C, K = hammond_matrices(t, Omega, c_lag)
    d = M.shape[0]
    return np.block([[np.zeros((d, d)), np.eye(d)],
                     [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])


def hammond_groups(N=4):
    """Blade groups of the lag angles and their rates."""
    return [list(range(2, 2 + N))], [list(range(N + 4, 2 * N + 4))]


def flap_A(psi, mu, gamma=12.0, p=1.0):
    """Flapping blade in forward flight, time = azimuth (Peters & Hohenemser 1971)."""
    c = gamma / 8 * (1 + 4 / 3 * mu * np.sin(psi))
    k = p ** 2 + gamma / 8 * (4 / 3 * mu * np.cos(psi) + mu ** 2 * np.sin(2 * psi))
    return np.array([[0.0, 1.0], [-k, -c]])
