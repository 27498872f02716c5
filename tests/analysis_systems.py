"""Systems with independently known analysis results (LTI references)."""

import numpy as np
import scipy.linalg as la
import control as ct

import ltpcontrol as ltp


def rotation(n, w):
    """Vectorised P(t): rotation by ωt in the first two coordinates, and Ṗ."""
    def P(t):
        scalar, t = np.ndim(t) == 0, np.atleast_1d(t)
        out = np.broadcast_to(np.eye(n), (len(t), n, n)).copy()
        c, s = np.cos(w * t), np.sin(w * t)
        out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = c, -s, s, c
        return out[0] if scalar else out

    def dP(t):
        scalar, t = np.ndim(t) == 0, np.atleast_1d(t)
        out = np.zeros((len(t), n, n))
        c, s = np.cos(w * t), np.sin(w * t)
        out[:, 0, 0], out[:, 0, 1], out[:, 1, 0], out[:, 1, 1] = -w * s, -w * c, w * c, -w * s
        return out[0] if scalar else out
    return P, dP


def transformed(G, T, w=None):
    """Lyapunov transform x_p = P(t) x of the LTI G: A_p = Ṗ P⁻¹ + P A P⁻¹.

    Returns the LTP system and P (vectorised callable).
    """
    n = G.nstates
    P, dP = rotation(n, 2 * np.pi / T if w is None else w)
    A, B, C, D = G.A, G.B, G.C, G.D
    inv = lambda t: np.swapaxes(P(t), -1, -2)
    Ap = lambda t: dP(t) @ inv(t) + P(t) @ A @ inv(t)
    Bp = lambda t: P(t) @ B
    Cp = lambda t: C @ inv(t)
    sys = ltp.ltpss(ltp.PeriodicMatrix.from_function(Ap, T),
                    ltp.PeriodicMatrix.from_function(Bp, T),
                    ltp.PeriodicMatrix.from_function(Cp, T), D, period=T)
    return sys, P


def stable_rss(n, p, m, seed, dt=0, strictly_proper=False):
    """Random stable LTI system with well-separated poles (reproducible)."""
    rng = np.random.default_rng(seed)
    while True:
        A = rng.standard_normal((n, n))
        if dt:
            A *= 0.8 / max(abs(np.linalg.eigvals(A)))
        else:
            A -= (max(np.linalg.eigvals(A).real) + 0.5 + rng.uniform()) * np.eye(n)
        B, C = rng.standard_normal((n, m)), rng.standard_normal((p, n))
        D = np.zeros((p, m)) if strictly_proper else rng.standard_normal((p, m))
        return ct.ss(A, B, C, D, dt)


def zhou_hagiwara_A():
    """A(t) of Zhou & Hagiwara (2002) and Cantoni & Sandberg (2009), T = π.

    Floquet exponents -1 and -2 (vectorised callable).
    """
    def A(t):
        scalar, t = np.ndim(t) == 0, np.atleast_1d(t)
        out = np.empty((len(t), 2, 2))
        out[:, 0, 0] = -1 - np.sin(2 * t) ** 2
        out[:, 0, 1] = 2 - 0.5 * np.sin(4 * t)
        out[:, 1, 0] = -2 - 0.5 * np.sin(4 * t)
        out[:, 1, 1] = -1 - np.cos(2 * t) ** 2
        return out[0] if scalar else out
    return ltp.PeriodicMatrix.from_function(A, np.pi)


def lifted(A, B, C, D):
    """Time-lifted LTI system of a discrete periodic system, built here."""
    N, n = A.shape[0], A.shape[1]
    m, p = B.shape[2], C.shape[1]
    trans = lambda i, k: np.linalg.multi_dot([np.eye(n)] + [A[j] for j in range(i - 1, k, -1)]
                                             + [np.eye(n)])          # A_{i-1}...A_{k+1}
    Phi = trans(N, -1)
    Bl = np.hstack([trans(N, k) @ B[k] for k in range(N)])
    Cl = np.vstack([C[i] @ trans(i, -1) for i in range(N)])
    Dl = np.zeros((N * p, N * m))
    for i in range(N):
        Dl[i * p:(i + 1) * p, i * m:(i + 1) * m] = D[i]
        for k in range(i):
            Dl[i * p:(i + 1) * p, k * m:(k + 1) * m] = C[i] @ trans(i, k) @ B[k]
    return ct.ss(Phi, Bl, Cl, Dl, True)


def pencil_zeros(G):
    """Finite zeros of an LTI system from its Rosenbrock pencil."""
    P = np.block([[G.A, G.B], [G.C, G.D]])
    E = la.block_diag(np.eye(G.nstates), np.zeros_like(G.D))
    z = la.eigvals(P, E)
    return np.sort_complex(z[np.isfinite(z) & (np.abs(z) < 1e8)])
