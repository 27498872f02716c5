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


# A 16-state isotropic wind turbine: tower fore-aft and side-side, flap and edge of three
# blades (rotating frame).  Fore-aft couples with the collective flap, side-side with the
# cyclic edge (Coleman's in-plane coupling); tower ~0.32 Hz, flap ~0.7 Hz, edge ~1.1 Hz.
TURBINE = dict(M_tower=3.0, k_tower=12.0, c_tower=0.02, I_flap=1.0, S_flap=0.3,
               k_flap=19.4, c_flap=0.3, I_edge=1.0, S_edge=0.3, k_edge=49.0, c_edge=0.07,
               e=0.1)

TURBINE_DOFS = (
    ['ED 1st tower fore-aft bending mode DOF (internal DOF index = DOF_TFA1), m',
     'ED 1st tower side-to-side bending mode DOF (internal DOF index = DOF_TSS1), m']
    + [f'ED 1st flapwise bending-mode DOF of blade {b} (internal DOF index = DOF_BF({b},1)), m'
       for b in (1, 2, 3)]
    + [f'ED 1st edgewise bending-mode DOF of blade {b} (internal DOF index = DOF_BE({b},1)), m'
       for b in (1, 2, 3)])


def turbine_descriptions():
    """Descriptions of the 16 states in OpenFAST's order (displacements, then rates)."""
    rates = [d.replace('ED ', 'ED First time derivative of ', 1).replace(', m', ', m/s')
             for d in TURBINE_DOFS]
    return list(TURBINE_DOFS) + rates


def turbine_A(t, Omega, data=TURBINE):
    """Rotating-frame state matrix of the isotropic turbine at time t (ψ_1 = Ωt)."""
    psi = Omega * t + 2 * np.pi * np.arange(3) / 3
    d = data
    M, C, K = (np.zeros((8, 8)) for _ in range(3))
    M[0, 0] = M[1, 1] = d['M_tower']
    M[0, 2:5] = M[2:5, 0] = d['S_flap']
    M[1, 5:] = M[5:, 1] = -d['S_edge'] * np.sin(psi)
    M[2:5, 2:5] = d['I_flap'] * np.eye(3)
    M[5:, 5:] = d['I_edge'] * np.eye(3)
    C[0, 0] = C[1, 1] = d['c_tower']
    C[1, 5:] = -2 * Omega * d['S_edge'] * np.cos(psi)
    C[2:5, 2:5] = d['c_flap'] * np.eye(3)
    C[5:, 5:] = d['c_edge'] * np.eye(3)
    K[0, 0] = K[1, 1] = d['k_tower']
    K[1, 5:] = Omega ** 2 * d['S_edge'] * np.sin(psi)
    K[2:5, 2:5] = (d['k_flap'] + d['I_flap'] * Omega ** 2) * np.eye(3)
    K[5:, 5:] = (d['k_edge'] + d['e'] * d['S_edge'] * Omega ** 2) * np.eye(3)
    return np.block([[np.zeros((8, 8)), np.eye(8)],
                     [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])


def turbine_mbc_A(Omega, t=0.0, data=TURBINE):
    """The turbine's state matrix in multi-blade coordinates, transformed by hand.

    ``x = P(ψ) z`` with the three-blade transform ``[1, cos ψ_b, sin ψ_b]``
    written out (and its derivatives ``Ω T1``, ``Ω² T2`` for the rates):
    ``A_NR = P⁻¹ (A P - Ṗ)``; constant in time for this isotropic rotor.
    """
    psi = Omega * t + 2 * np.pi * np.arange(3) / 3
    T0 = np.column_stack([np.ones(3), np.cos(psi), np.sin(psi)])
    T1 = np.column_stack([np.zeros(3), -np.sin(psi), np.cos(psi)])
    T2 = np.column_stack([np.zeros(3), -np.cos(psi), -np.sin(psi)])
    P, dP = np.eye(16), np.zeros((16, 16))
    for q, r in ((slice(2, 5), slice(10, 13)), (slice(5, 8), slice(13, 16))):
        P[q, q] = P[r, r] = T0
        P[r, q] = Omega * T1
        dP[q, q] = dP[r, r] = Omega * T1
        dP[r, q] = Omega ** 2 * T2
    return np.linalg.solve(P, turbine_A(t, Omega, data) @ P - dP)


def write_turbine_study(root, speeds, winds=None, nazimuths=36, digits=10):
    """The turbine's ``.lin`` files: a folder per operating point, a file per azimuth.

    Folder ``wsWW.W_rpmRR.RR`` for rotor speed Ω (rad/s) and wind speed
    (8 m/s when `winds` is None), files ``Main.1.lin`` ... at azimuths
    ``2πk/nazimuths``, printed with `digits` significant digits.
    """
    desc = turbine_descriptions()
    rotating = ['blade' in d for d in desc]
    winds = np.full(len(speeds), 8.0) if winds is None else winds
    for Omega, wind in zip(speeds, winds):
        folder = root / f'ws{wind:04.1f}_rpm{Omega * 30 / np.pi:05.2f}'
        folder.mkdir()
        for k in range(nazimuths):
            psi = 2 * np.pi * k / nazimuths
            write_lin(folder / f'Main.{k + 1}.lin', turbine_A(psi / Omega, Omega), Omega, psi,
                      wind, desc, rotating, [2] * 16, digits=digits)
    return root


def write_lin(path, A, rotor_speed, azimuth, wind_speed, descriptions, rotating, orders,
              digits=10):
    """Write a state matrix as an OpenFAST ``.lin`` file (no inputs or outputs)."""
    n = A.shape[0]
    lines = ['', 'Linearized model: synthetic turbine', '', 'Simulation information:',
             f'   Rotor Speed:                         {rotor_speed:.4f} rad/s',
             f'   Azimuth:                             {azimuth:.4f} rad',
             f'   Wind Speed:                          {wind_speed:.4f} m/s',
             f'   Number of continuous states:        {n}',
             '   Number of discrete states:           0',
             '   Number of constraint states:         0',
             '   Number of inputs:                    0',
             '   Number of outputs:                   0',
             '   Jacobians included in this file?    No', '']
    for title in ('Order of continuous states:', 'Order of continuous state derivatives:'):
        lines += [title, '   Row/Column Operating Point   Rotating Frame? Derivative Order '
                  'Description', '   ---------- ---------------   --------------- '
                  '---------------- -----------']
        lines += [f'   {i + 1:8d}    0.000000000E+00   {"T" if rotating[i] else "F"}   '
                  f'{orders[i]}   {descriptions[i]}' for i in range(n)]
        lines.append('')
    lines += ['', 'Linearized state matrices:', '', f'A: {n} x {n}']
    lines += ['  ' + ' '.join(f'{v: .{digits - 1}E}' for v in row) for row in A]
    path.write_text('\n'.join(lines) + '\n')
