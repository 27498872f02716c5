"""Rotors: Floquet modes, multi-blade coordinates and their literature truths.

Independent truths: monodromy matrices by `scipy.integrate.solve_ivp` of the
rotating-frame equations over one period, the principal-harmonic rule
applied to solutions integrated by `solve_ivp`, `control.damp` of the
multi-blade model, and a multi-blade transform written out here for four
blades.
"""

import numpy as np
import pytest
import control as ct
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

import ltpcontrol as ltp
from examples.rotor_models import HAMMOND, flap_A, hammond_A, hammond_groups, hammond_matrices

FAILED = np.array([0.0, 1.0, 1.0, 1.0]) * HAMMOND['c_lag']


def rotating_model(Omega, c_lag=None):
    return ltp.ltpss(lambda t: hammond_A(t, Omega, c_lag), np.zeros((12, 0)),
                     np.zeros((0, 12)), 0, period=2 * np.pi / Omega)


def hammond_mbc(Omega, c_lag=None):
    g, r = hammond_groups()
    return ltp.mbc(rotating_model(Omega, c_lag), g, 4, rates=r)


def monodromy_ivp(Afun, T, n):
    """Φ(T, 0) by solve_ivp of Φ' = A(t)Φ."""
    sol = solve_ivp(lambda t, y: (Afun(t) @ y.reshape(n, n)).ravel(), (0, T),
                    np.eye(n).ravel(), method='DOP853', rtol=1e-12, atol=1e-13)
    return sol.y[:, -1].reshape(n, n)


def growth_ivp(Omega, c_lag=FAILED):
    T = 2 * np.pi / Omega
    mu = np.linalg.eigvals(monodromy_ivp(lambda t: hammond_A(t, Omega, c_lag), T, 12))
    return np.log(np.abs(mu)).max() / T


def growth_ltp(Omega, c_lag=FAILED):
    return ltp.floquet_exponents(rotating_model(Omega, c_lag)).real.max()


def mbc_by_hand(Omega, t, c_lag=None):
    """Multi-blade model of Hammond's rotor written out for four blades."""
    psi = Omega * t + np.pi / 2 * np.arange(4)
    T0 = np.column_stack([np.ones(4), np.cos(psi), np.sin(psi), [1, -1, 1, -1]])
    T1 = np.column_stack([np.zeros(4), -np.sin(psi), np.cos(psi), np.zeros(4)])
    T2 = np.column_stack([np.zeros(4), -np.cos(psi), -np.sin(psi), np.zeros(4)])
    P, dP = np.eye(12), np.zeros((12, 12))
    q, r = slice(2, 6), slice(8, 12)
    P[q, q] = P[r, r] = T0
    P[r, q] = Omega * T1
    dP[q, q] = dP[r, r] = Omega * T1
    dP[r, q] = Omega ** 2 * T2
    return np.linalg.solve(P, hammond_A(t, Omega, c_lag) @ P - dP)


#
# Isotropic rotor: multi-blade coordinates and Floquet modes
#

@pytest.mark.parametrize('Omega', [20.0, 31.0])
def test_mbc_of_isotropic_rotor_is_time_invariant(Omega):
    nr, P = hammond_mbc(Omega)
    times = np.random.default_rng(1).uniform(0, 2 * np.pi / Omega, 9)
    ref = mbc_by_hand(Omega, 0.0)
    scale = np.abs(ref).max()
    for t in times:
        by_hand = mbc_by_hand(Omega, t)
        assert np.abs(by_hand - ref).max() <= 1e-9 * scale          # time-invariant
        assert np.abs(nr.A(t) - by_hand).max() <= 1e-9 * scale      # the library's
    # x = P(t) z maps the multi-blade states back to the rotating frame
    psi = Omega * times[0] + np.pi / 2 * np.arange(4)
    assert np.allclose(P(times[0])[2:6, 3], np.cos(psi))


@pytest.mark.parametrize('Omega', [20.0, 31.0])
def test_floquet_modes_of_mbc_model_are_its_lti_eigenvalues(Omega):
    nr, _ = hammond_mbc(Omega)
    modes = ltp.floquet_modes(nr)
    wn, zeta, poles = ct.damp(ct.ss(mbc_by_hand(Omega, 0.0), np.zeros((12, 1)),
                                    np.zeros((1, 12)), 0), doprint=False)
    order = np.lexsort((-np.sign(poles.imag), np.round(wn, 9)))
    assert np.allclose(modes.frequency, wn[order], rtol=1e-6, atol=0)
    assert np.allclose(modes.damping, zeta[order], rtol=1e-6, atol=1e-9)
    assert np.allclose(modes.participation.sum(axis=1), 1.0)
    assert modes.liouville_error < 1e-9
    # right and left vectors: eigenvectors of A, bi-orthonormal, also for the
    # double eigenvalue (collective and differential lag modes)
    A0 = mbc_by_hand(Omega, 0.0)
    V, W, lam = modes.vectors, modes.left_vectors, modes.exponents
    assert np.abs(A0 @ V - V * lam).max() < 1e-8 * np.abs(A0).max()
    assert np.abs(W.conj().T @ A0 - lam[:, None] * W.conj().T).max() < 1e-8 * np.abs(
        A0).max() * np.abs(W).max()
    assert np.allclose(W.conj().T @ V, np.eye(12), atol=1e-8)
    # eigenvalue condition numbers of the simple eigenvalues, from scipy's eig
    import scipy.linalg as la
    lam, W, V = la.eig(mbc_by_hand(Omega, 0.0), left=True, right=True)
    kappa = np.linalg.norm(V, axis=0) * np.linalg.norm(W, axis=0) / np.abs(
        np.sum(np.conj(W) * V, axis=0))
    for lam_i, k_i in zip(lam, kappa):
        if np.sum(np.abs(lam - lam_i) < 1e-6 * np.abs(lam).max()) == 1:
            j = np.argmin(np.abs(modes.exponents - lam_i))
            assert np.isclose(modes.condition[j], k_i, rtol=1e-6)


@pytest.mark.parametrize('Omega', [20.0, 31.0])
def test_rotating_frame_exponents_equal_lti_ones_modulo_rotor_speed(Omega):
    lti = np.linalg.eigvals(mbc_by_hand(Omega, 0.0))
    nr, P = hammond_mbc(Omega)
    modes = ltp.floquet_modes(rotating_model(Omega))
    shift = []
    for lam in modes.exponents:
        d = lti - lam
        k = np.round(d.imag / Omega)
        gap = np.abs(d.real) + np.abs(d.imag - k * Omega)
        assert gap.min() < 1e-6 * np.abs(lti).max()
        shift.append(int(k[np.argmin(gap)]))
    # the rotating frame picks, for the whirling (hub-coupled) modes, the branch
    # one rotor speed away, the one the lag angles see; collective and
    # differential modes keep their frequency
    assert set(np.abs(shift)) == {0, 1}
    assert np.all(modes.participation.max(axis=1) > 0.5)
    # measured in the multi-blade frame, the branch is the LTI eigenvalue itself
    Pinv = ltp.PeriodicMatrix.from_function(lambda t: np.linalg.inv(P(t)), P.period, (12, 12))
    framed = ltp.floquet_modes(rotating_model(Omega), frame=Pinv)
    for lam in framed.exponents:
        assert np.abs(lti - lam).min() < 1e-6 * np.abs(lti).max()


#
# Damper failed: Floquet against averaging
#

@pytest.mark.slow
def test_failed_damper_instability_interval_and_peak_equal_monodromy():
    # brackets of 0.1 rad/s around the published values (brentq refuses a bracket without
    # the root), so each root costs a few monodromy integrations
    lo = [brentq(f, 22.75, 22.85, xtol=1e-9) for f in (growth_ltp, growth_ivp)]
    hi = [brentq(f, 34.74, 34.84, xtol=1e-9) for f in (growth_ltp, growth_ivp)]
    assert abs(lo[0] - lo[1]) <= 1e-5 * lo[1] and abs(hi[0] - hi[1]) <= 1e-5 * hi[1]
    assert round(lo[0], 2) == 22.80 and round(hi[0], 2) == 34.79
    peak = minimize_scalar(lambda w: -growth_ivp(w), bounds=(27.7, 28.7), method='bounded',
                           options={'xatol': 1e-3})
    assert 27.8 < peak.x < 28.6                       # an interior maximum
    modes = ltp.floquet_modes(rotating_model(peak.x, FAILED))
    assert abs(modes.exponents.real.max() + peak.fun) <= 1e-5 * abs(peak.fun)
    assert round(-peak.fun, 3) == 0.395

    # MBC + averaging: a narrower interval, a growth five times too small
    def averaged(Omega):
        nr, _ = hammond_mbc(Omega, FAILED)
        return np.linalg.eigvals(nr.average().A).real.max()
    lo_av = brentq(averaged, 25.925, 25.935, xtol=1e-9)
    hi_av = brentq(averaged, 30.595, 30.605, xtol=1e-9)
    assert round(lo_av, 2) == 25.93 and round(hi_av, 2) == 30.60
    peak_av = minimize_scalar(lambda w: -averaged(w), bounds=(27.7, 28.7), method='bounded',
                              options={'xatol': 1e-3})
    assert 27.8 < peak_av.x < 28.6
    assert round(-peak_av.fun, 3) == 0.078 and -peak.fun > 5 * -peak_av.fun


def test_failed_damper_growth_at_one_speed_equals_monodromy():
    assert abs(growth_ltp(28.0) - growth_ivp(28.0)) <= 1e-5 * growth_ivp(28.0)


#
# Flapping blade in forward flight (γ = 12, time = azimuth)
#

def flap_model(mu):
    return ltp.ltpss(lambda t: flap_A(t, mu), np.zeros((2, 0)), np.zeros((0, 2)), 0,
                     period=2 * np.pi)


def flap_growth_ivp(mu):
    mu_ = np.linalg.eigvals(monodromy_ivp(lambda t: flap_A(t, mu), 2 * np.pi, 2))
    return np.log(np.abs(mu_)).max() / (2 * np.pi)


def principal_rule_ivp(mu, nharm=16):
    """Exponents on the principal-harmonic branch, from solve_ivp solutions."""
    T, S = 2 * np.pi, 2 * nharm + 1
    M = monodromy_ivp(lambda t: flap_A(t, mu), T, 2)
    mult, V = np.linalg.eig(M)
    out = []
    times = np.arange(S) * T / S
    for m, v in zip(mult, V.T):
        lam = np.log(m) / T
        sol = solve_ivp(lambda t, x: flap_A(t, mu) @ x, (0, T), v.astype(complex),
                        t_eval=times, method='DOP853', rtol=1e-12, atol=1e-13)
        p = sol.y * np.exp(-lam * times)
        c = np.fft.fft(p, axis=1) / S
        h = np.arange(S) - nharm
        energy = np.sum(np.abs(c[:, h % S]) ** 2, axis=0)
        top = np.flatnonzero(energy >= energy.max() * (1 - 1e-9))
        im = lam.imag + h[top]
        best = top[np.lexsort((-np.sign(np.round(im, 9)), np.round(np.abs(im), 9)))[0]]
        out.append(lam + 1j * h[best])
    return np.array(out)


@pytest.mark.parametrize('mu', [0.0, 0.1, 0.2])
def test_flap_principal_frequencies_and_dampings(mu):
    modes = ltp.floquet_modes(flap_model(mu))
    truth = principal_rule_ivp(mu)
    truth = truth[np.lexsort((-np.sign(truth.imag), np.round(np.abs(truth), 9)))]
    assert np.allclose(modes.frequency, np.abs(truth), rtol=1e-6, atol=0)
    assert np.allclose(modes.damping, -truth.real / np.abs(truth), rtol=1e-6, atol=1e-9)
    # hover: the blade's own frequency, damping γ/16
    if mu == 0:
        assert np.allclose(modes.exponents, np.linalg.eigvals(flap_A(0.0, 0.0))[[0, 1]]
                           [np.argsort(-np.linalg.eigvals(flap_A(0.0, 0.0)).imag)])


@pytest.mark.slow
def test_flap_stability_boundary_equals_monodromy():
    def growth_ltp_flap(mu):
        return ltp.floquet_modes(flap_model(mu)).exponents.real.max()
    mu_ltp = brentq(growth_ltp_flap, 1.0, 1.5, xtol=1e-10)
    mu_ivp = brentq(flap_growth_ivp, 1.0, 1.5, xtol=1e-10)
    assert abs(mu_ltp - mu_ivp) <= 1e-5 * mu_ivp


def test_discrete_floquet_modes_equal_continuous_ones_sampled():
    sys = flap_model(0.2)
    sysd = sys.sample(2 * np.pi / 64)
    cont, disc = ltp.floquet_modes(sys), ltp.floquet_modes(sysd)
    assert np.allclose(disc.multipliers, cont.multipliers, rtol=1e-9)
    assert np.allclose(disc.frequency, cont.frequency, rtol=1e-9)
    assert np.allclose(disc.damping, cont.damping, rtol=1e-9)
    assert disc.liouville_error < 1e-9


#
# Bad input
#

def test_mbc_rejects_wrong_blade_count():
    g, r = hammond_groups()
    sys = rotating_model(20.0)
    with pytest.raises(ValueError, match="nblades = 3"):
        ltp.mbc(sys, g, 3, rates=r)
    with pytest.raises(ValueError, match="once|two groups"):
        ltp.mbc(sys, g, 4, rates=g)
    with pytest.raises(ValueError, match="revolutions"):
        ltp.mbc(sys, g, 4, rates=r, rotor_speed=13.0)
    with pytest.raises(ct.ControlArgument, match="rotating is needed"):
        ltp.mbc(sys, nblades=4)


def test_floquet_modes_rejects_bad_frame():
    with pytest.raises(ct.ControlDimension, match="columns"):
        ltp.floquet_modes(flap_model(0.1), frame=np.eye(3))


def test_stiff_multipliers_keep_relative_accuracy():
    # exponents 0 and -24 exactly (multipliers 1 and e^{-48π} = 1.6e-66)
    A = lambda t: np.array([[0.0, 1.0], [-10 * np.cos(t), -24 - 10 * np.sin(t)]])
    sys = ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=2 * np.pi)
    modes = ltp.floquet_modes(sys, nharmonics=24)
    small = modes.multipliers[np.argmin(np.abs(modes.multipliers))]
    assert abs(small / np.exp(-48 * np.pi) - 1) < 1e-8
    assert np.allclose(np.sort(modes.exponents.real), [-24.0, 0.0], atol=1e-9)
    assert modes.liouville_error < 1e-10
    # a discrete product of 400 graded steps
    rng = np.random.default_rng(0)
    steps = np.array([np.diag([1.0, 0.5, 0.1]) + 0.01 * rng.standard_normal((3, 3))
                      for _ in range(400)])
    sysd = ltp.ltpss(steps, np.zeros((400, 3, 1)), np.zeros((400, 1, 3)), 0, period=400.0,
                     dt=1.0)
    modes = ltp.floquet_modes(sysd)
    logdet = np.sum(np.linalg.slogdet(steps)[1])
    # per-step exponents ρ = μ^{1/N}: the multiplier 0.1^400 itself underflows
    assert abs(400 * np.sum(np.log(np.abs(modes.exponents))) - logdet) < 1e-9 * abs(logdet)
