"""Periodic pole placement and LMI state-feedback design.

Truths: the closed-loop multipliers recomputed from the gains (periodic
Schur form via feedback), python-control's place in the LTI limit, the
periodic LQR (H2 case), and closed-loop norms computed independently from
the time-lifted LTI system (python-control/SLICOT and a discrete Lyapunov
equation), cross-checked with `ltp.norm`.
"""

import numpy as np
import control as ct
import pytest
import scipy.linalg as sla
from control.exception import ControlArgument
from hypothesis import given, settings, strategies as st

import ltpcontrol as ltp


def _plant(seed, N, n, m, scale=0.8):
    rng = np.random.default_rng(seed)
    A = scale * rng.standard_normal((N, n, n))
    B = rng.standard_normal((N, n, m))
    return ltp.ltpss(A, B, np.eye(n), 0, period=0.1 * N, dt=0.1), rng


def _match(got, want):
    got, err = list(got), 0.0
    for w in want:
        i = int(np.argmin([abs(g - w) for g in got]))
        err = max(err, abs(got.pop(i) - w))
    return err


#
# place
#

@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), N=st.integers(1, 6), n=st.integers(1, 4),
       m=st.integers(1, 2), complex_pair=st.booleans())
def test_place_achieves_the_requested_multipliers(seed, N, n, m, complex_pair):
    sysd, rng = _plant(seed, N, n, m)
    # distinct poles (a single input cannot place repeated ones)
    p = (np.linspace(-0.8, 0.8, n) + 0.1 * rng.uniform(-1, 1)).astype(complex)
    if complex_pair and n >= 2:
        p[:2] = 0.3 * np.exp(1j * 0.7), 0.3 * np.exp(-1j * 0.7)
    K = ltp.place(sysd, p)
    got = ltp.floquet_multipliers(ltp.feedback(sysd, K))
    assert _match(got, p) < 1e-8


def test_place_lti_embedding_and_continuous():
    A, B = np.array([[0.5, 1.0], [0.0, 1.2]]), np.array([[0.0], [1.0]])
    sysd = ltp.ltpss(A, B, np.eye(2), 0, period=0.2, dt=0.2)        # N = 1
    K = ltp.place(sysd, [0.2, -0.3])
    assert np.abs(K(0.0) - ct.place(A, B, [0.2, -0.3])).max() < 1e-10
    sysc = ltp.ltpss(A, B, np.eye(2), 0, period=1.0)
    Kc = ltp.place(sysc, [-1.0, -2.0])
    assert np.abs(Kc(0.4) - ct.place(A, B, [-1.0, -2.0])).max() < 1e-10
    # a time-varying continuous plant is placed through sampling
    Ap = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-1 - 0.5 * np.cos(2 * np.pi * t), 0.2]]), 1.0)
    sysp = ltp.ltpss(Ap, B, np.eye(2), 0, period=1.0)
    with pytest.raises(ControlArgument, match="give dt"):
        ltp.place(sysp, [-1.0, -2.0])
    Kd = ltp.place(sysp, [-1.0, -2.0], dt=0.25)
    sampled = ltp.sample_system(sysp, 0.25)
    got = ltp.floquet_multipliers(ltp.feedback(sampled, Kd))
    assert _match(got, np.exp([-1.0, -2.0])) < 1e-8


def test_place_errors_name_the_problem():
    sysd, _ = _plant(1, 3, 2, 1)
    with pytest.raises(ValueError, match="p must hold 2 poles"):
        ltp.place(sysd, [0.1])
    with pytest.raises(ValueError, match="conjugation"):
        ltp.place(sysd, [0.1 + 0.2j, 0.3])
    with pytest.raises(ValueError, match="step must be"):
        ltp.place(sysd, [0.1, 0.2], step=3)
    # second state never reachable: the plant is not reachable over a period
    A = np.array([[[0.5, 0.0], [0.0, 1.5]]] * 2)
    B = np.array([[[1.0], [0.0]]] * 2)
    unreachable = ltp.ltpss(A, B, np.eye(2), 0, period=2.0, dt=1.0)
    with pytest.raises(ValueError, match="not reachable over a period"):
        ltp.place(unreachable, [0.1, 0.2])
    # reachable only through two steps: input 0 at step 0, nothing at step 1
    A2 = np.array([[[0.0, 0.0], [1.0, 0.0]], [[0.0, 0.0], [1.0, 0.0]]])
    B2 = np.array([[[1.0], [0.0]], [[0.0], [0.0]]])
    shift = ltp.ltpss(A2, B2, np.eye(2), 0, period=2.0, dt=1.0)
    with pytest.raises(ValueError, match="p cannot be placed"):
        ltp.place(shift, [0.1, 0.2])


#
# LMI design
#

def _closed_loop(sysd, K, Q, R):
    """Closed loop w -> z = [Q^½ x; R^½ u] with G = I."""
    N = sysd.nsteps
    A, B = sysd.A.sample(N), sysd.B.sample(N)
    Kk = K.sample(N)
    n = A.shape[1]
    C = np.concatenate([np.broadcast_to(sla.sqrtm(Q), (N, n, n)), -sla.sqrtm(R) @ Kk], axis=1)
    return ltp.ltpss(A - B @ Kk, np.eye(n), C, 0, period=sysd.period, dt=sysd.dt)


def _lifted_hinf(sysd, K, Q, R):
    """ℓ2 gain of the closed loop from its time-lifted LTI equivalent."""
    return ct.norm(ltp.lift(_closed_loop(sysd, K, Q, R), method='time'), 'inf')


def _h2(sysd, K, Q, R):
    """Per-period average H2 norm from the lifted observability gramian."""
    N = sysd.nsteps
    A, B = sysd.A.sample(N), sysd.B.sample(N)
    Kk = K.sample(N)
    Acl = A - B @ Kk
    W = [Q + Kk[k].T @ R @ Kk[k] for k in range(N)]
    # Y_0 = Φᵀ Y_0 Φ + Σ_k Φ(k, 0)ᵀ W_k Φ(k, 0), then Y_k backwards
    phi, acc = np.eye(A.shape[1]), 0
    for k in range(N):
        acc = acc + phi.T @ W[k] @ phi
        phi = Acl[k] @ phi
    Y = [None] * (N + 1)
    Y[0] = Y[N] = sla.solve_discrete_lyapunov(phi.T, acc)
    for k in range(N - 1, 0, -1):
        Y[k] = Acl[k].T @ Y[k + 1] @ Acl[k] + W[k]
    return np.sqrt(np.mean([np.trace(Y[k + 1]) for k in range(N)]))


@pytest.mark.parametrize("N", [2, 3])
def test_lmi_h2_matches_dlqr(N):
    sysd, _ = _plant(7, N, 3, 2, scale=1.0)
    Q, R = np.diag([1.0, 2.0, 0.5]), np.diag([1.0, 0.3])
    res = ltp.lmi_statefbk(sysd, Q, R, objective='h2')
    assert res.status == 'optimal' and res.solver == 'CLARABEL'
    K, X, _ = ltp.dlqr(sysd, Q, R)
    optimal = np.sqrt(np.mean(np.trace(X.sample(N), axis1=1, axis2=2)))
    achieved = _h2(sysd, res.K, Q, R)
    assert abs(ltp.norm(_closed_loop(sysd, res.K, Q, R), 2) - achieved) < 1e-9 * achieved
    assert achieved <= res.bound * (1 + 1e-7)
    assert abs(res.bound - optimal) < 1e-6 * optimal
    assert abs(achieved - optimal) < 1e-6 * optimal
    assert np.abs(res.K.sample(N) - K.sample(N)).max() < 1e-3 * np.abs(K.sample(N)).max()
    # the certificate bounds the closed-loop controllability gramian
    assert np.all(np.linalg.eigvalsh(res.certificate) > 0)


def test_lmi_hinf_bound_is_the_achieved_norm():
    sysd, _ = _plant(11, 3, 3, 2, scale=1.0)
    Q, R = np.eye(3), np.eye(2)
    res = ltp.lmi_statefbk(sysd, Q, R, objective='hinf')
    assert res.status == 'optimal'
    achieved = _lifted_hinf(sysd, res.K, Q, R)
    assert abs(ltp.norm(_closed_loop(sysd, res.K, Q, R), 'inf') - achieved) < 1e-6 * achieved
    assert achieved <= res.bound * (1 + 1e-6)
    assert achieved >= res.bound * (1 - 1e-4)
    # no worse than the H2-optimal gain in the H∞ sense
    K2, _, _ = ltp.dlqr(sysd, Q, R)
    assert achieved <= _lifted_hinf(sysd, K2, Q, R) * (1 + 1e-6)


def test_lmi_decay_rate_certificate():
    sysd, _ = _plant(5, 4, 3, 1, scale=1.0)
    res = ltp.lmi_statefbk(sysd, objective='decay', rate=0.6)
    assert res.status == 'optimal' and res.bound == 0.6
    assert np.max(np.abs(res.multipliers)) <= 0.6 ** 4 * (1 + 1e-6)
    got = ltp.floquet_multipliers(ltp.feedback(sysd, res.K))
    assert _match(got, res.multipliers) < 1e-10
    # V_k(x) = xᵀ P_k⁻¹ x decreases by ρ² per step
    P, Kk = res.certificate, res.K.sample(4)
    A, B = sysd.A.sample(4), sysd.B.sample(4)
    for k in range(4):
        Acl = A[k] - B[k] @ Kk[k]
        M = 0.36 * np.linalg.inv(P[k]) - Acl.T @ np.linalg.inv(P[(k + 1) % 4]) @ Acl
        assert np.linalg.eigvalsh(M).min() > -1e-7


def test_lmi_decay_rate_bisection():
    sysd, _ = _plant(5, 2, 2, 1, scale=1.0)
    res = ltp.lmi_statefbk(sysd, objective='decay')
    assert res.status == 'optimal' and 0 < res.bound < 1
    assert np.max(np.abs(res.multipliers)) <= res.bound ** 2 * (1 + 1e-6)
    with pytest.raises(ValueError, match="infeasible"):
        ltp.lmi_statefbk(sysd, objective='decay', rate=0.5 * res.bound)


def test_lmi_bad_input():
    sysd, _ = _plant(2, 2, 2, 1)
    with pytest.raises(ControlArgument, match="discrete-time"):
        ltp.lmi_statefbk(ltp.ltpss(np.eye(2), np.ones((2, 1)), np.eye(2), 0, period=1.0))
    with pytest.raises(ValueError, match="objective"):
        ltp.lmi_statefbk(sysd, objective='h3')
    with pytest.raises(ValueError, match="R must be positive definite"):
        ltp.lmi_statefbk(sysd, R=[[0.0]])
    with pytest.raises(ValueError, match="Q must have shape"):
        ltp.lmi_statefbk(sysd, Q=np.eye(3))
    with pytest.raises(ValueError, match="rate"):
        ltp.lmi_statefbk(sysd, objective='decay', rate=1.5)
    # an unstable mode that the input cannot reach: infeasible, raised
    A = np.array([[[0.5, 0.0], [0.0, 1.5]]] * 2)
    B = np.array([[[1.0], [0.0]]] * 2)
    bad = ltp.ltpss(A, B, np.eye(2), 0, period=2.0, dt=1.0)
    with pytest.raises(ValueError, match="infeasible"):
        ltp.lmi_statefbk(bad, objective='h2')
