"""python-control's own test cases replayed on LTI systems written as periodic.

Each case takes the system and the reference value of a case of
python-control's test suite (``control/tests``: statefbk, mateqn, sysnorm,
modelsimp, minreal, timeresp), and checks that the same call answers the
same through ``ltp.*`` and through ``ct.*`` (the bridge), on

* the LTI system written as periodic (``ltp.ltpss(G, T)``), and
* the same system in a random smooth periodic state basis ``x = P(t) z``,
  ``P(t) = expm(M sin ωt)``, where the quantity is invariant (closed-loop
  exponents, norms, Hankel singular values, minimal order, zeros, outputs).

The truth is python-control on the LTI system (or the published number that
python-control's test states).
"""

import warnings

import control as ct
import numpy as np
import pytest
import scipy.linalg as la
from control.exception import ControlArgument

import ltpcontrol as ltp
from analysis_systems import stable_rss, transformed

T = 1.0
W = 2 * np.pi / T
MODULES = [pytest.param(ltp, id='ltp'), pytest.param(ct, id='ct')]


def periodic_basis(G, seed=0, N=8):
    """G in the state basis x = P(t) z, P(t) = expm(M sin ωt) (discrete: P_k, N steps).

    Returns the system and P (a `PeriodicMatrix`; discrete: the stacked P_k).
    """
    n = G.nstates
    M = 0.4 * np.random.default_rng(seed).standard_normal((n, n))
    A, B, C, D = G.A, G.B, G.C, G.D
    if G.isdtime(strict=True):
        # z_{k+1} = P_{k+1}⁻¹ A P_k z_k + P_{k+1}⁻¹ B u_k,  y_k = C P_k z_k + D u_k
        Pk = [la.expm(M * np.sin(W * k / N)) for k in range(N + 1)]
        Az = np.array([la.solve(Pk[k + 1], A @ Pk[k]) for k in range(N)])
        Bz = np.array([la.solve(Pk[k + 1], B) for k in range(N)])
        Cz = np.array([C @ Pk[k] for k in range(N)])
        return ltp.ltpss(Az, Bz, Cz, D, period=N * G.dt, dt=G.dt), np.array(Pk[:N])
    # ż = P⁻¹(A P − Ṗ) z + P⁻¹B u with P⁻¹Ṗ = ω cos(ωt) M; these entire functions
    # are stored by their Fourier series (64 samples: the rest is below 1e-16)
    tk = np.arange(64) * T / 64
    Pk = [la.expm(M * np.sin(W * t)) for t in tk]
    Az = ltp.PeriodicMatrix.from_samples(
        [la.solve(p, A @ p) - W * np.cos(W * t) * M for p, t in zip(Pk, tk)], T)
    Bz = ltp.PeriodicMatrix.from_samples([la.solve(p, B) for p in Pk], T)
    Cz = ltp.PeriodicMatrix.from_samples([C @ p for p in Pk], T)
    return ltp.ltpss(Az, Bz, Cz, D, period=T), ltp.PeriodicMatrix.from_samples(Pk, T)


def as_periodic(G):
    return ltp.ltpss(G, G.dt * 4 if G.isdtime(strict=True) else T)


def sorted_eig(v):
    v = np.asarray(v, complex)
    return v[np.lexsort((v.imag, v.real))]


def closed_loop_exponents(sys, K):
    """Floquet exponents of A − B K (continuous) or log-free multipliers (discrete)."""
    cl = ltp.ltpss(sys.A - sys.B @ K, sys.B, sys.C, sys.D, period=sys.period, dt=sys.dt)
    return ltp.floquet_exponents(cl) if not sys.isdtime() else ltp.floquet_multipliers(cl)


def lti_exponents(G, K, sysp):
    lam = np.linalg.eigvals(G.A - G.B @ K)
    if G.isdtime(strict=True):
        return lam ** sysp.nsteps
    return lam


def assert_same_spectrum(got, want, atol):
    got, want = np.asarray(got, complex), np.asarray(want, complex)
    assert got.shape == want.shape
    # match each wanted value to a distinct nearest computed value
    free = list(got)
    for w in want:
        i = int(np.argmin([abs(g - w) for g in free]))
        assert abs(free[i] - w) < atol, (got, want)
        free.pop(i)


def continuous_exponents_equal(got, want, atol):
    """Floquet exponents are defined modulo jω_p: compare the multipliers (asserts)."""
    assert_same_spectrum(np.exp(np.asarray(got) * T), np.exp(np.asarray(want) * T), atol)
    return True


# Systems of python-control's statefbk/sysnorm tests
G_MIMO = ct.ss([[-1.017041847539126, -0.224182952826418, 0.042538079149249],
                [-0.310374015319095, -0.516461581407780, -0.119195790221750],
                [-1.452723568727942, 1.7995860837102088, -1.491935830615152]],
               [[0.312858596637428, -0.164879019209038],
                [-0.864879917324456, 0.627707287528727],
                [-0.030051296196269, 1.093265669039484]],
               [[1.109273297614398, 0.077359091130425, -1.113500741486764],
                [-0.863652821988714, -1.214117043615409, -0.006849328103348]], np.zeros((2, 2)))
G_PLACE = ct.ss([[0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1], [-2, -3, -4, -5.0]],
                [[0, 0], [0, 0], [1, 0], [0, 1.0]], np.eye(4)[:2], np.zeros((2, 2)))


#
# Norms (sysnorm_test)
#

@pytest.mark.parametrize('mod', MODULES)
@pytest.mark.parametrize('G, p, want', [
    (ct.ss(ct.tf([1], [1, 1])), 'inf', 1.0),
    (ct.ss(ct.tf([1], [1, 1])), 2, 0.707106781186547),
    (ct.ss(ct.tf([1], [-1, 1])), 'inf', 1.0),                  # unstable: the L∞ norm
    (G_MIMO, 'inf', 4.276759162964244),
    (G_MIMO, 2, 2.237461821810309),
    (ct.sample_system(ct.ss(ct.tf([1], [1, 1])), 0.1), 'inf', 1.0),
    (ct.sample_system(ct.ss(ct.tf([1], [1, 1])), 0.1), 2, 0.223513699524858),
    (ct.sample_system(ct.ss(ct.tf([1], [-1, 1])), 0.1), 'inf', 1.0),
    (ct.sample_system(G_MIMO, 0.1), 'inf', 4.276759162964228),
    (ct.sample_system(G_MIMO, 0.1), 2, 0.707434962289554),
], ids=['1st-inf', '1st-2', 'unstable-inf', 'mimo-inf', 'mimo-2', 'd1st-inf', 'd1st-2',
        'dunstable-inf', 'dmimo-inf', 'dmimo-2'])
def test_norm(mod, G, p, want):
    assert np.isclose(ct.norm(G, p), want, rtol=1e-5)       # python-control's own case
    systems = [as_periodic(G)]
    if G.nstates == 1 or G.isdtime(strict=True) or p == 2:
        systems.append(periodic_basis(G)[0])   # (a 3-state continuous L∞ takes 20 s)
    for sys in systems:
        assert np.isclose(mod.norm(sys, p, tol=1e-8), want, rtol=1e-6), sys


@pytest.mark.parametrize('mod', MODULES)
def test_norm_unstable_h2_is_inf_with_warning(mod):
    G = ct.ss(ct.tf([1], [-1, 1]))
    with pytest.warns(UserWarning, match="unstable"):
        assert mod.norm(as_periodic(G), 2) == np.inf


#
# LQR, LQE (statefbk_test)
#

@pytest.mark.parametrize('mod', MODULES)
def test_lqr_integrator(mod):
    # python-control: A = 0, B = 1, Q = R = 1 gives K = 1, S = 1, E = -1
    sys = ltp.ltpss([[0.0]], [[1.0]], [[1.0]], 0, period=T)
    K, S, E = mod.lqr(sys, [[1.0]], [[1.0]])
    np.testing.assert_allclose(K(0.3), [[1.0]], atol=1e-9)
    np.testing.assert_allclose(S(0.3), [[1.0]], atol=1e-9)
    np.testing.assert_allclose(E, [-1.0], atol=1e-9)


def multipliers(sys, F, L=None):
    """Floquet multipliers of ``A - B F`` (or ``A - L C``)."""
    A = sys.A - sys.B @ F if L is None else sys.A - L @ sys.C
    return ltp.floquet_multipliers(ltp.ltpss(A, sys.B, sys.C, sys.D, period=sys.period,
                                             dt=sys.dt))


def lti_multipliers(G, M, sysp):
    lam = np.linalg.eigvals(M)
    return lam ** sysp.nsteps if G.isdtime(strict=True) else np.exp(lam * sysp.period)


@pytest.mark.parametrize('mod', MODULES)
@pytest.mark.parametrize('dt', [0, 0.1])
def test_lqr_and_lqe_match_python_control(mod, dt):
    G = G_MIMO if not dt else ct.sample_system(G_MIMO, dt)
    Q, R = np.diag([1.0, 2.0, 3.0]), np.diag([1.0, 0.5])
    QN, RN = np.diag([1.0, 2.0]), np.diag([0.5, 1.0])
    lqr, lqe = (mod.lqr, mod.lqe) if not dt else (mod.dlqr, mod.dlqe)
    Kc, Sc, _ = (ct.lqr if not dt else ct.dlqr)(G, Q, R)
    Lc, Pc, _ = (ct.lqe if not dt else ct.dlqe)(G, QN, RN)
    sys = as_periodic(G)
    K, S, E = lqr(sys, Q, R)
    L, Pe, F = lqe(sys, QN, RN)
    for got, want in ((K, Kc), (S, Sc), (L, Lc), (Pe, Pc)):
        np.testing.assert_allclose(got(0.0), want, atol=1e-8)
    assert_same_spectrum(multipliers(sys, K), lti_multipliers(G, G.A - G.B @ Kc, sys), 1e-9)
    # the estimator in a periodic state basis: its error dynamics are the same
    sysz, _ = periodic_basis(G, seed=1)
    L, Pe, F = lqe(sysz, QN, RN)
    assert_same_spectrum(multipliers(sysz, None, L), lti_multipliers(G, G.A - Lc @ G.C, sysz),
                         1e-10)


@pytest.mark.parametrize('seed', [1, 2, 3])
def test_lqe_in_a_rotating_basis_is_accurate_to_1e_10(seed):
    # an LTI plant in the rotating basis x_p = R(ωt) x: the Kalman filter's
    # closed-loop exponents are the LTI ones (to 1e-10; measured about 1e-12)
    G = stable_rss(4, 2, 2, seed=seed)
    sysp, _ = transformed(G, T)
    Lc, _, _ = ct.lqe(G, np.eye(2), np.eye(2))
    _, _, F = ltp.lqe(sysp, np.eye(2), np.eye(2))
    continuous_exponents_equal(F, np.linalg.eigvals(G.A - Lc @ G.C), 1e-10)
    assert_same_spectrum(F, np.linalg.eigvals(G.A - Lc @ G.C), 1e-10)


@pytest.mark.parametrize('mod', MODULES)
@pytest.mark.parametrize('dt', [0, 0.1])
def test_lqr_closed_loop_invariant_in_periodic_basis(mod, dt):
    # x = P z, Q_z = Pᵀ Q P: the optimal closed loop has the same multipliers
    G = G_MIMO if not dt else ct.sample_system(G_MIMO, dt)
    Kc, _, _ = (ct.lqr if not dt else ct.dlqr)(G, np.eye(3), np.eye(2))
    sysz, Pm = periodic_basis(G, seed=2)
    Qz = Pm.T @ Pm if not dt else np.swapaxes(Pm, 1, 2) @ Pm
    K, S, E = (mod.lqr if not dt else mod.dlqr)(sysz, Qz, np.eye(2))
    assert_same_spectrum(multipliers(sysz, K), lti_multipliers(G, G.A - G.B @ Kc, sysz),
                         1e-9)


@pytest.mark.parametrize('mod', MODULES)
@pytest.mark.parametrize('dt', [0, 0.1])
def test_lqr_integral_action(mod, dt):
    # python-control's test_lqr_integral_*: K has n + nint columns
    G = stable_rss(4, 4, 2, seed=11, dt=dt, strictly_proper=True)
    G = ct.ss(G.A, G.B, np.eye(4), 0, G.dt)              # full-state output, as there
    C_int = np.eye(2, 4)                                 # integrate the first two states
    Q, R = np.eye(6), np.eye(2)
    Kc, Sc, Ec = (ct.lqr if not dt else ct.dlqr)(G, Q, R, integral_action=C_int)
    K, S, E = (mod.lqr if not dt else mod.dlqr)(as_periodic(G), Q, R, integral_action=C_int)
    assert K.shape == (2, 6)
    np.testing.assert_allclose(K(0.0), Kc, atol=1e-8)
    np.testing.assert_allclose(S(0.0), Sc, atol=1e-8)


@pytest.mark.parametrize('mod', MODULES)
def test_lqr_keywords_work_or_are_refused(mod):
    sys = as_periodic(G_MIMO)
    for method in (None, 'slycot', 'scipy'):
        mod.lqr(sys, np.eye(3), np.eye(2), method=method)
    with pytest.raises((ControlArgument, ValueError, TypeError), match="method"):
        mod.lqr(sys, np.eye(3), np.eye(2), method='nonsense')


#
# Pole placement (statefbk_test testPlace, testPlace_varga_*)
#

@pytest.mark.parametrize('name', ['place', 'place_varga', 'acker'])
def test_place(name):
    p = np.array([-0.5 + 1j, -0.5 - 1j, -5.0566, -8.6659])      # statefbk_test testPlace
    G = G_PLACE if name != 'acker' else G_PLACE[:, 0]
    Kc = np.atleast_2d(getattr(ct, name)(G.A, G.B, p))
    np.testing.assert_allclose(sorted_eig(np.linalg.eigvals(G.A - G.B @ Kc)), sorted_eig(p),
                               atol=1e-6)
    sys = as_periodic(G)
    for K in (getattr(ct, name)(sys, None, p), ltp.place(sys, p)):
        continuous_exponents_equal(closed_loop_exponents(sys, K), p, 1e-6)
    # a periodic continuous plant is placed through sampling: python-control's
    # call has no sampling time, so the error says what to give
    sysz, _ = periodic_basis(G, seed=3)
    with pytest.raises(ControlArgument, match="give dt"):
        getattr(ct, name)(sysz, None, p)


def test_place_refuses_keywords_without_meaning():
    with pytest.raises(ControlArgument, match="dtime and alpha"):
        ct.place_varga(as_periodic(G_PLACE), None, [-1, -2, -3, -4], alpha=-1.0)
    with pytest.raises(ControlArgument, match="B=None"):
        ct.place(as_periodic(G_PLACE), G_PLACE.B, [-1, -2, -3, -4])


#
# Gramians and matrix equations (statefbk_test testGram*, mateqn_test)
#

@pytest.mark.parametrize('mod', MODULES)
@pytest.mark.parametrize('kind', ['c', 'o'])
def test_gram(mod, kind):
    # python-control's testGramWc: A, B, C below give Wc = [[18.5, 24.5], [24.5, 32.5]]
    G = ct.ss([[1., -2.], [3., -4.]], [[5., 6.], [7., 8.]], [[4., 5.], [6., 7.]],
              [[13., 14.], [15., 16.]])
    G = ct.ss(G.A - 0 * np.eye(2), G.B, G.C, G.D)
    want = ct.gram(G, kind)
    np.testing.assert_allclose(mod.gram(as_periodic(G), kind)(0.2), want, rtol=1e-8)


@pytest.mark.parametrize('dt', [0, 1])
def test_lyap_care_dare_with_constant_matrices(dt):
    A = np.array([[-1.0, 0.3], [0.2, -2.0]]) * (0.3 if dt else 1)
    Q, B, R = np.array([[2.0, 0.5], [0.5, 1.0]]), np.array([[1.0], [0.5]]), np.array([[1.0]])
    if not dt:
        X = ltp.lyap(ltp.PeriodicMatrix.constant(A, T), Q)
        np.testing.assert_allclose(X(0.4), ct.lyap(A, Q), atol=1e-9)
        Xc = ltp.care(ltp.PeriodicMatrix.constant(A, T), B, Q, R)[0]
        np.testing.assert_allclose(Xc(0.4), ct.care(A, B, Q, R)[0], atol=1e-8)
    else:
        X = ltp.dlyap(np.array([A, A]), Q)
        np.testing.assert_allclose(X[0], ct.dlyap(A, Q), atol=1e-9)
        Xd = ltp.dare(np.array([A, A]), np.array([B, B]), Q, R)[0]
        np.testing.assert_allclose(Xd[0], ct.dare(A, B, Q, R)[0], atol=1e-9)


#
# Hankel singular values, balanced reduction, minimal realization
#

@pytest.mark.parametrize('mod', MODULES)
def test_hsvd(mod):
    # modelsimp_test testHSVD
    G = ct.ss([[1., -2.], [3., -4.]], [[5.], [7.]], [[6., 8.]], [[9.]])
    want = ct.hankel_singular_values(G)
    call = mod.hsvd if mod is ltp else mod.hankel_singular_values
    got = call(as_periodic(G))
    np.testing.assert_allclose(np.ravel(got)[:2], want, rtol=1e-8)
    sysz, _ = periodic_basis(G, seed=4)
    got = call(sysz)           # pointwise in t: the LTI values at every t
    np.testing.assert_allclose(np.atleast_2d(got)[0], want, rtol=1e-6)


@pytest.mark.parametrize('mod', MODULES)
def test_balred_keeps_the_leading_hankel_values(mod):
    G = ct.ss([[-15., -7.5, -6.25, -1.875], [8., 0., 0., 0.], [0., 4., 0., 0.],
               [0., 0., 1., 0.]], [[2.], [0.], [0.], [0.]], [[0.5, 0.6875, 0.7031, 0.5]],
              [[0.]])                                   # modelsimp_test testBalredTruncate
    call = mod.balred if mod is ltp else mod.balanced_reduction
    red = call(as_periodic(G), 2)
    want = ct.balanced_reduction(G, 2)
    np.testing.assert_allclose(ct.hankel_singular_values(red.to_ss()),
                               ct.hankel_singular_values(want), rtol=1e-8)


def _mixed_system():
    """4 states: a minimal 2-state part, one unreachable and one unobservable mode."""
    A = np.diag([-1.0, -2.0, -3.0, -4.0])
    B = np.array([[1.0], [1.0], [0.0], [1.0]])          # mode 3 unreachable
    C = np.array([[1.0, 1.0, 1.0, 0.0]])                # mode 4 unobservable
    return ct.ss(A, B, C, 0)


@pytest.mark.slow
@pytest.mark.parametrize('mod', MODULES)
def test_minreal_mixed_modes(mod):
    G = _mixed_system()
    assert ct.minreal(G, verbose=False).nstates == 2
    for sys, _ in ((as_periodic(G), None), periodic_basis(G, seed=5)):
        assert mod.minreal(sys, verbose=False).nstates == 2


@pytest.mark.parametrize('mod', MODULES)
def test_minreal_default_tolerance_is_python_controls(mod):
    s = ct.tf('s')
    h = (s + 1) * (s + 2.00000000001) / (s + 2) / (s ** 2 + s + 1)
    # python-control's test takes the transfer function path (pole-zero
    # cancellation within 1000 sqrt(eps)|z|): 2 states
    want = ct.minreal(h, verbose=False).den[0][0].size - 1
    assert mod.minreal(as_periodic(ct.ss(h)), verbose=False).nstates == want == 2


def test_minreal_verbose_prints_as_python_control(capsys):
    ct.minreal(as_periodic(_mixed_system()))
    assert "2 states have been removed" in capsys.readouterr().out


#
# Zeros
#

@pytest.mark.slow
@pytest.mark.parametrize('mod', MODULES)
def test_zeros(mod):
    G = ct.ss(ct.tf([1.0, 0.5], [1.0, 3.0, 2.0]))                 # zero -0.5
    want = ct.zeros(G)
    for sys, _ in ((as_periodic(G), None), periodic_basis(G, seed=6)):
        assert continuous_exponents_equal(mod.zeros(sys), want, 1e-8)


#
# Time responses (timeresp_test)
#

@pytest.mark.parametrize('name', ['forced_response', 'step_response', 'initial_response',
                                  'impulse_response'])
@pytest.mark.parametrize('dt', [0, 0.1])
def test_time_responses(name, dt):
    G = G_MIMO if not dt else ct.sample_system(G_MIMO, dt)
    t = np.arange(0, 30) * 0.1
    u = np.vstack([np.sin(t), np.cos(2 * t)])
    x0 = np.array([1.0, -1.0, 0.5])
    args = {'forced_response': (t, u, x0), 'step_response': (t,),
            'initial_response': (t, x0), 'impulse_response': (t,)}[name]
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')                  # impulse: discrete warnings
        want = getattr(ct, name)(G, *args)
        for sys, Pm in ((as_periodic(G), None), periodic_basis(G, seed=7, N=10)):
            P0 = np.eye(3) if Pm is None else (Pm(0.0) if not dt else Pm[0])
            a = list(args)
            if name in ('forced_response', 'initial_response'):
                a[-1] = la.solve(P0, x0)              # the same initial state, z0 = P(0)⁻¹x0
            for mod in (ltp, ct):
                got = getattr(mod, name)(sys, *a)
                np.testing.assert_allclose(got.outputs, want.outputs, atol=1e-8)


@pytest.mark.parametrize('mod', MODULES)
def test_discrete_forced_response_without_time_vector(mod):
    # timeresp_test: forced_response(dsys, U=u) uses T = arange(n) dt
    G = ct.sample_system(G_MIMO, 0.1)
    u = np.vstack([np.ones(20), np.linspace(0, 1, 20)])
    want = ct.forced_response(G, U=u)
    got = mod.forced_response(as_periodic(G), U=u)
    np.testing.assert_allclose(got.time, want.time)
    np.testing.assert_allclose(got.outputs, want.outputs, atol=1e-10)
