"""Eigen-analysis of the harmonic state space: truncation-edge eigenvalues
are marked, the modes equal the Floquet exponents of an independent
monodromy (solve_ivp), and the sensitivities equal finite differences."""

import warnings

import numpy as np
import control as ct
import pytest
from scipy.integrate import solve_ivp

import ltpcontrol as ltp

T = 2 * np.pi


def mathieu(a, b, c):
    A = ltp.PeriodicMatrix.from_function(
        lambda t: np.array([[0.0, 1.0], [-(a + b * np.cos(t)), -c]]), T)
    return ltp.ltpss(A, [[0.0], [1.0]], [[1.0, 0.0]], 0, period=T)


def monodromy_exponents(a, b, c):
    def rhs(t, x):
        return (np.array([[0.0, 1.0], [-(a + b * np.cos(t)), -c]]) @ x.reshape(2, 2)).ravel()
    sol = solve_ivp(rhs, (0, T), np.eye(2).ravel(), method='DOP853', rtol=1e-12, atol=1e-14)
    mu = np.linalg.eigvals(sol.y[:, -1].reshape(2, 2)).astype(complex)
    return np.log(mu) / T


def _same_mod(x, y, wp=1.0):
    d = x - y
    return np.hypot(d.real, np.remainder(d.imag + wp / 2, wp) - wp / 2)


def test_stable_mathieu_has_no_unmarked_rhp_eigenvalue():
    modes = ltp.harmonic_modes(mathieu(2.0, 3.0, 0.3))
    lam = modes.eigenvalues
    assert np.any(lam.real > 0.1)                 # the artefacts are there ...
    assert np.all(modes.edge[lam.real > 0])       # ... and all of them are marked
    assert not np.any(modes.floquet_consistent[lam.real > 0])
    assert modes.stable
    truth = monodromy_exponents(2.0, 3.0, 0.3)
    for x in modes.exponents:
        assert np.min(_same_mod(x, truth)) < 1e-8
    assert "at the edge" in repr(modes)


def test_unstable_mathieu_mode_is_unmarked():
    modes = ltp.harmonic_modes(mathieu(1.0, 2.0, 0.3))
    assert not modes.stable
    unstable = modes.eigenvalues.real > 0.1
    assert np.any(unstable & modes.floquet_consistent & ~modes.edge)
    truth = monodromy_exponents(1.0, 2.0, 0.3)
    assert abs(modes.exponents[0].real - truth.real.max()) < 1e-8


def test_participation_and_table():
    modes = ltp.harmonic_modes(mathieu(2.0, 3.0, 0.3), 12)
    np.testing.assert_allclose(modes.participation.sum(axis=0), 1.0)
    np.testing.assert_allclose(modes.harmonic_participation.sum(axis=0), 1.0)
    assert modes.harmonic_participation.shape == (25, 2)
    np.testing.assert_allclose(modes.frequency(hz=True), modes.frequency() / (2 * np.pi))
    assert "frequency [Hz]" in modes.table(hz=True)
    # physical exponents: the Floquet exponents shifted by whole harmonics
    shift = (modes.exponents - modes.floquet).imag
    np.testing.assert_allclose(shift, np.round(shift), atol=1e-8)
    np.testing.assert_allclose(modes.exponents.real, modes.floquet.real, atol=1e-10)


def test_lti_modes_are_the_poles():
    G = ct.ss([[-0.5, 5.0], [-5.0, -0.5]], [[0.0], [1.0]], [[1.0, 0.0]], 0)
    modes = ltp.harmonic_modes(ltp.ltpss(G, period=1.0))
    by_imag = lambda z: z[np.argsort(z.imag)]
    np.testing.assert_allclose(by_imag(modes.exponents), by_imag(ct.poles(G)), atol=1e-12)
    np.testing.assert_allclose(modes.damping, 0.5 / np.hypot(0.5, 5.0))
    assert not modes.edge.any()


def test_sensitivity_equals_finite_difference():
    a, b, c, h = 2.0, 3.0, 0.3, 1e-5
    modes = ltp.harmonic_modes(mathieu(a, b, c))
    d = modes.sensitivity([[0.0, 0.0], [-1.0, 0.0]])         # ∂A/∂a
    plus, minus = monodromy_exponents(a + h, b, c), monodromy_exponents(a - h, b, c)
    for lam, dl in zip(modes.exponents, d):
        # follow the branch: the exponent nearest lam ± h dl
        p = plus[np.argmin(_same_mod(plus, lam + h * dl))]
        m = minus[np.argmin(_same_mod(minus, lam - h * dl))]
        fd = (p - m) / (2 * h)
        fd = fd.real + 1j * (np.remainder(fd.imag * 2 * h + 0.5, 1.0) - 0.5) / (2 * h)
        assert abs(fd - dl) < 1e-4 * max(1.0, abs(dl))


def test_bad_inputs():
    with pytest.raises(ValueError, match="discrete"):
        ltp.harmonic_modes(ltp.ltpss(ct.ss([[0.5]], [[1.0]], [[1.0]], 0, 0.1), period=0.2))
    with pytest.raises(ValueError, match="edge_tol"):
        ltp.harmonic_modes(mathieu(2.0, 3.0, 0.3), edge_tol=-1)


def _match(x, y):
    """Largest distance from an element of x to the nearest element of y."""
    return np.abs(x[:, None] - y[None, :]).min(axis=1).max()


def test_harmonic_ss_marks_and_warns_on_stable_mathieu():
    sys = mathieu(2.0, 3.0, 0.3)
    with pytest.warns(UserWarning, match="truncation edge") as rec:
        Hs = ltp.harmonic_ss(sys, 1)
    msg = " ".join(str(w.message) for w in rec)
    assert "floquet_exponents" in msg and "harmonic_modes" in msg
    m = Hs.modes
    lam = m.eigenvalues
    # the marked eigenvalues are the poles of the returned state space
    poles = ct.poles(Hs)
    assert len(poles) == len(lam) and _match(poles, lam) < 1e-9 and _match(lam, poles) < 1e-9
    rhp = lam.real > 0
    assert np.any(lam.real > 0.1)                 # the artefacts are there ...
    assert np.all(m.edge[rhp])                    # ... every one is marked
    assert not np.any(m.floquet_consistent[rhp])
    top = lam[np.argmax(lam.real)]
    assert f"{top:.4g}" in msg or f"{top.conjugate():.4g}" in msg   # and named
    # the same classification as harmonic_modes at the same truncation
    ref = ltp.harmonic_modes(sys, Hs.nstates // 4)
    assert _match(ref.eigenvalues[ref.edge], lam[m.edge]) < 1e-9
    assert np.count_nonzero(ref.edge) == np.count_nonzero(m.edge)
    assert m.stable
    truth = monodromy_exponents(2.0, 3.0, 0.3)
    for x in m.exponents:
        assert np.min(_same_mod(x, truth)) < 1e-8


def test_harmonic_ss_edge_keyword():
    sys = mathieu(2.0, 3.0, 0.3)
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        Hs = ltp.harmonic_ss(sys, 1, edge='ignore')
    assert np.any(Hs.modes.edge)
    with pytest.raises(ValueError, match="edge"):
        ltp.harmonic_ss(sys, 1, edge='remove')
    # 'drop': exact modal truncation, the poles are the unmarked eigenvalues only
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        Hd = ltp.harmonic_ss(sys, 1, edge='drop')
    m = Hd.modes
    poles = ct.poles(Hd)
    kept = m.eigenvalues[~m.edge]
    assert len(poles) == len(kept) and _match(poles, kept) < 1e-9 and _match(kept, poles) < 1e-9
    assert poles.real.max() == pytest.approx(monodromy_exponents(2.0, 3.0, 0.3).real.max(),
                                             abs=1e-8)
    for s in (0.3j, 1.7j):
        np.testing.assert_allclose(Hd(s), Hs(s), rtol=0, atol=1e-8 * np.abs(Hs(s)).max())


def test_harmonic_ss_lti_as_periodic_no_warning_and_exact():
    G = ct.ss([[-0.5, 5.0], [-5.0, -0.5]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.2]])
    sys = ltp.ltpss(G, period=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        H0 = ltp.harmonic_ss(sys, 0)
        H2 = ltp.harmonic_ss(sys, 2)
    for X, Y in ((H0.A, G.A), (H0.B, G.B), (H0.C, G.C), (H0.D, G.D)):
        assert np.array_equal(X, Y)
    for s in (0.3j, 2.0 + 1j):
        assert H2(s)[0, 0] == pytest.approx(complex(G(s)), rel=1e-13)
    assert not H2.modes.edge.any() and H2.modes.floquet_consistent.all()


def test_harmonic_ss_unstable_mathieu_genuine_exponent_unmarked():
    sys = mathieu(1.0, 2.0, 0.3)
    with pytest.warns(UserWarning) as rec:
        Hs = ltp.harmonic_ss(sys, 1)
    assert any("is unstable" in str(w.message) for w in rec)
    m = Hs.modes
    truth = monodromy_exponents(1.0, 2.0, 0.3)
    assert truth.real.max() > 0.1
    assert abs(m.exponents[0].real - truth.real.max()) < 1e-8
    # the genuine right-half-plane eigenvalues: Floquet-consistent, not at the edge
    genuine = (m.eigenvalues.real > 0.1) & m.floquet_consistent & ~m.edge
    assert np.any(genuine)
    assert np.min(_same_mod(m.eigenvalues[genuine], truth.real.max())) < 1e-8
    # and the warning names none of them as an artefact
    msg = " ".join(str(w.message) for w in rec)
    for z in m.eigenvalues[genuine]:
        assert f"{z:.4g}" not in msg
    # dropping the marked eigenvalues keeps the genuine instability
    with pytest.warns(UserWarning, match="is unstable"):
        Hd = ltp.harmonic_ss(sys, 1, edge='drop')
    assert ct.poles(Hd).real.max() == pytest.approx(truth.real.max(), abs=1e-8)


def test_htf_to_ss_marks_edges_as_harmonic_ss():
    sys = mathieu(2.0, 3.0, 0.3)
    H = ltp.htf(sys, 1)
    with pytest.warns(UserWarning, match="not Floquet exponents") as rec:
        Hs = H.to_ss()
    assert rec[0].filename == __file__                       # points at the user's call
    ref = ltp.harmonic_ss(sys, 1, edge='ignore')
    assert np.array_equal(Hs.A, ref.A) and np.array_equal(Hs.modes.edge, ref.modes.edge)
    assert Hs.modes.edge.any()
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        Hd = H.to_ss(edge='drop')
    drop = ltp.harmonic_ss(sys, 1, edge='drop')
    assert Hd.nstates == drop.nstates < Hs.nstates
    assert _match(ct.poles(Hd), ct.poles(drop)) < 1e-9
    with pytest.raises(ValueError, match="edge"):
        H.to_ss(edge='remove')
