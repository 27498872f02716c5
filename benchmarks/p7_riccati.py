"""P7: stabilizing periodic Riccati solution, n = 4 to 20 states.

Workload: ``A(t) = A_0 + A_1 cos(ω_p t) + A_2 sin(ω_p t)`` (random, the
averaged plant unstable) with the period T = 0.1 s short compared with
the closed-loop time constants (about 1 s), the usual regime of rotors and
gaits, ``B`` constant with two inputs, ``Q = I``,
``R = I``; the answer is ``X(0)`` of the stabilizing periodic solution of
``-Ẋ = AᵀX + XA - XBR⁻¹BᵀX + Q``.

* ours: ``ltp.care`` (Hamiltonian step factors, collapsed cyclic pencil,
  ordered QZ, backward flow).
* peer: the naive route, backward integration of the Riccati ODE (n²
  states, numpy right-hand side) with `scipy.integrate.solve_ivp` from
  ``X(T) = 0``, period after period, until ``X(0)`` changes by less than
  1e-10 between periods (RK45 with the loosest rtol of 1e-8, ..., 1e-11
  that reaches the accuracy target; the time of that single run counts).

Accuracy: ``max|X(0) - X_ref| / max|X_ref|``.  Reference: the Hamiltonian
monodromy ``Ψ(T, 0)`` integrated in one shot (DOP853, rtol 1e-13; its
multipliers are moderate because T is short) and ``X_ref = V U⁻¹`` from
its ordered Schur form, an algorithm and integrator independent of both
sides.  Both must reach 1e-8.
"""

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import schur

from _common import median_time, row, timed

import ltpcontrol as ltp

TOL = 1e-8
FULL = dict(sizes=(4, 8, 12, 20), repeats=3)
QUICK = dict(sizes=(4,), repeats=1)
# peer: integrator tolerances tried (loosest first) and the periodicity test
RTOLS = (1e-8, 1e-9, 1e-10, 1e-11)
PERIODIC_TOL = 1e-10


def plant(n, seed=0, T=0.1):
    rng = np.random.default_rng(seed + n)
    A0 = rng.standard_normal((n, n)) / np.sqrt(n) + 0.3 * np.eye(n)
    A1 = 0.5 * (rng.standard_normal((n, n)) - 1j * rng.standard_normal((n, n))) / np.sqrt(n)
    A = ltp.PeriodicMatrix([A1.conj() / 2, A0, A1 / 2], T)
    B = rng.standard_normal((n, 2))
    return A, B


def ours(A, B):
    X, _, _ = ltp.care(A, B, np.eye(A.shape[0]), np.eye(2))
    return X(0.0)


def backward(A, B, tol, rtol, atol, method='RK45', max_periods=2000):
    """Integrate -Ẋ = AᵀX + XA - XBBᵀX + I backwards until X(0) is periodic."""
    n = A.shape[0]
    A0, A1 = A.fourier(1)[1].real, A.fourier(1)[2]
    BB = B @ B.T
    T = A.period
    w = 2 * np.pi / T

    def rhs(t, x):
        X = x.reshape(n, n)
        At = A0 + 2 * (A1 * np.exp(1j * w * t)).real
        return -(At.T @ X + X @ At - X @ BB @ X + np.eye(n)).ravel()

    X = np.zeros((n, n))
    for _ in range(max_periods):
        sol = solve_ivp(rhs, (T, 0.0), X.ravel(), method=method, rtol=rtol, atol=atol)
        Xn = sol.y[:, -1].reshape(n, n)
        change = np.abs(Xn - X).max() / max(1.0, np.abs(Xn).max())
        X = Xn
        if change < tol:
            break
    return X


def reference(A, B):
    """``X(0)`` from the stable invariant subspace of the one-shot Hamiltonian monodromy."""
    n = A.shape[0]
    BB = B @ B.T
    T = A.period
    A0, A1 = A.fourier(1)[1].real, A.fourier(1)[2]
    w = 2 * np.pi / T

    def rhs(t, z):
        At = A0 + 2 * (A1 * np.exp(1j * w * t)).real
        H = np.block([[At, -BB], [-np.eye(n), -At.T]])
        return (H @ z.reshape(2 * n, 2 * n)).ravel()

    sol = solve_ivp(rhs, (0.0, T), np.eye(2 * n).ravel(), method='DOP853', rtol=1e-13,
                    atol=1e-14)
    Psi = sol.y[:, -1].reshape(2 * n, 2 * n)
    _, Z, sdim = schur(Psi, output='real', sort='iuc')
    assert sdim == n
    return np.linalg.solve(Z[:n, :n].T, Z[n:, :n].T).T


def run(quick=False, log=print):
    cfg = QUICK if quick else FULL
    rows = []
    for n in cfg['sizes']:
        log(f"P7: periodic care, n = {n}")
        A, B = plant(n)
        ref = reference(A, B)
        t_ours, times, X = median_time(lambda: ours(A, B), cfg['repeats'])
        # the peer with the loosest tolerance of the ladder that reaches TOL (one run)
        scale = np.abs(ref).max()
        for rtol in RTOLS:
            t_peer, Xp = timed(backward, A, B, PERIODIC_TOL, rtol=rtol, atol=0.1 * rtol)
            if np.abs(Xp - ref).max() / scale <= TOL:
                break
        err_ours = float(np.abs(X - ref).max() / scale)
        err_peer = float(np.abs(Xp - ref).max() / scale)
        rows.append(row(
            f'P7-{n}', f'stabilizing periodic Riccati solution X(0), n = {n}',
            ours='ltp.care (collapsed cyclic Hamiltonian pencil)',
            peer=f'solve_ivp RK45 (rtol {rtol:g}) backward Riccati ODE until periodic',
            t_ours=t_ours, t_peer=t_peer, err_ours=err_ours, err_peer=err_peer, tol=TOL,
            target=50, target_met=None if quick else t_peer / t_ours >= 50,
            checks={'ours <= tol': err_ours <= TOL}, matched=err_peer <= TOL,
            extra=dict(ours_times=times, peer_rtol=rtol)))
    return rows
