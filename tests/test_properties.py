"""Property-based tests of invariants that hold across the public API.

Random systems are drawn from a seed: matrices come from
``numpy.random.default_rng(seed)`` and the state matrix is shifted so that
every eigenvalue has real part at most ``-margin``.  Hypothesis runs
derandomised with few examples so that the suite stays fast.

Invariants:

* LTI limit: an LTP system with constant matrices simulates, samples (ZOH,
  Tustin) and has the HTF ``H_{n,n}(s) = G(s + jnω_p)`` exactly as
  python-control's LTI system;
* the HTF predicts the simulated steady state of a periodic system;
* the Floquet transform preserves the input-output behaviour;
* ``d2c(sample_system(sys, Ts, 'tustin'))`` returns ``sys``;
* the frequency lifting is the discrete-time HTF, and its real form is real
  with the same poles;
* HTF of interconnections: series is the product and parallel the sum of the
  (sufficiently wide) truncated harmonic matrices;
* `fdsubspace` recovers random systems from noise-free data;
* identification and metric functions never modify their input arrays, and
  seeded designs are reproducible;
* PeriodicMatrix algebra: products convolve Fourier coefficients, the
  coefficients are conjugate-symmetric, and exact switching coefficients
  agree with quadrature of the evaluated function.
"""

import warnings

import control as ct
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.linalg import expm

import ltpcontrol as ltp
from systems import damped_mathieu, mathieu

FAST = settings(derandomize=True, max_examples=15, deadline=None, database=None)
FEW = settings(derandomize=True, max_examples=4, deadline=None, database=None)

seeds = st.integers(min_value=0, max_value=2 ** 32 - 1)


#
# Random systems
#

def stable_matrix(rng, n, margin=0.5):
    """Random n x n matrix with every eigenvalue at real part <= -margin."""
    A = rng.standard_normal((n, n))
    shift = np.max(np.linalg.eigvals(A).real) + margin
    return A - shift * np.eye(n)


def random_lti(seed, n=None, m=None, p=None, dt=0):
    rng = np.random.default_rng(seed)
    n = n or int(rng.integers(1, 4))
    m = m or int(rng.integers(1, 3))
    p = p or int(rng.integers(1, 3))
    if dt:
        # discrete time: spectral radius in [0.3, 0.9]
        A = rng.standard_normal((n, n))
        A *= rng.uniform(0.3, 0.9) / np.max(np.abs(np.linalg.eigvals(A)))
    else:
        A = stable_matrix(rng, n, margin=rng.uniform(0.3, 2.0))
    return ct.ss(A, rng.standard_normal((n, m)), rng.standard_normal((p, n)),
                 rng.standard_normal((p, m)), dt)


def bandlimited(rng, rows, cols, K, period, scale=0.3):
    """Random real periodic matrix with harmonics -K..K."""
    coeffs = np.zeros((2 * K + 1, rows, cols), complex)
    coeffs[K] = rng.standard_normal((rows, cols))
    for k in range(1, K + 1):
        ck = scale * (rng.standard_normal((rows, cols)) + 1j * rng.standard_normal((rows, cols)))
        coeffs[K + k], coeffs[K - k] = ck, np.conj(ck)
    return ltp.PeriodicMatrix(coeffs, period)


def oscillation(rng, rows, cols, K, period, scale=0.3):
    """Zero-mean random periodic matrix with harmonics ±1..±K."""
    P = bandlimited(rng, rows, cols, K, period, scale)
    return P - P.fourier(0)[0].real


def random_floquet_form(seed, period=1.0, n=2, m=1, p=1, KB=1, KC=1):
    """Continuous LTP system with constant A and band-limited B, C (exact HTF)."""
    rng = np.random.default_rng(seed)
    A = stable_matrix(rng, n, margin=rng.uniform(0.5, 2.0))
    return ltp.ltpss(A, bandlimited(rng, n, m, KB, period), bandlimited(rng, p, n, KC, period),
                     rng.standard_normal((p, m)), period=period)


def smooth_inputs(rng, t, shape):
    """Sums of three random sinusoids, shape ``shape + (len(t),)``."""
    out = np.zeros(shape + (len(t),))
    for _ in range(3):
        amp = rng.standard_normal(shape + (1,))
        freq = rng.uniform(0.2, 6.0, shape + (1,))
        phase = rng.uniform(0, 2 * np.pi, shape + (1,))
        out += amp * np.sin(freq * t + phase)
    return out


#
# LTI limit
#

@FAST
@given(seed=seeds, period=st.floats(0.3, 3.0))
def test_lti_limit_forced_response(seed, period):
    G = random_lti(seed)
    sys = ltp.ltpss(G, period)
    rng = np.random.default_rng(seed + 1)
    t = np.linspace(0, 3 * period, 151)
    u = smooth_inputs(rng, t, (G.ninputs,))
    x0 = rng.standard_normal(G.nstates)
    ours = ltp.forced_response(sys, t, u, x0, return_states=True)
    ref = ct.forced_response(G, t, u, x0, return_states=True)
    scale = 1 + np.abs(ref.outputs).max()
    np.testing.assert_allclose(ours.outputs, ref.outputs, atol=1e-9 * scale)
    np.testing.assert_allclose(ours.states, ref.states, atol=1e-9 * scale)


@FAST
@given(seed=seeds)
def test_lti_limit_step_response(seed):
    G = random_lti(seed)
    sys = ltp.ltpss(G, 0.7)
    t = np.linspace(0, 4, 81)
    ours = ltp.step_response(sys, t)
    ref = ct.step_response(G, t)
    np.testing.assert_allclose(np.squeeze(ours.outputs), np.squeeze(ref.outputs),
                               atol=1e-9 * (1 + np.abs(ref.outputs).max()))


@FAST
@given(seed=seeds, period=st.floats(0.5, 5.0), K=st.integers(0, 3),
       sigma=st.floats(-0.2, 0.2), omega=st.floats(-3.0, 3.0))
def test_lti_limit_htf_is_shifted_transfer_function(seed, period, K, sigma, omega):
    G = random_lti(seed)
    H = ltp.htf(ltp.ltpss(G, period), K)
    s = sigma + 1j * omega
    M = H(s)
    wp = 2 * np.pi / period
    ny, nu = G.noutputs, G.ninputs
    for a, n in enumerate(range(-K, K + 1)):
        for b in range(2 * K + 1):
            block = M[a * ny:(a + 1) * ny, b * nu:(b + 1) * nu]
            expected = G(s + 1j * n * wp) if a == b else np.zeros((ny, nu))
            np.testing.assert_allclose(block, np.reshape(expected, (ny, nu)),
                                       atol=1e-9 * (1 + np.abs(expected).max()))


@FAST
@given(seed=seeds, nsteps=st.integers(2, 12), method=st.sampled_from(['zoh', 'tustin']))
def test_lti_limit_sampling_matches_python_control(seed, nsteps, method):
    G = random_lti(seed)
    period = 1.0
    Ts = period / nsteps
    sysd = ltp.sample_system(ltp.ltpss(G, period), Ts, method=method)
    assert sysd.is_lti and sysd.dt == Ts and sysd.nsteps == nsteps
    ref = ct.sample_system(G, Ts, method=method)
    omega = np.linspace(0.1, 0.95 * np.pi / Ts, 7)
    ours = sysd.to_ss().frequency_response(omega).complex
    np.testing.assert_allclose(ours, ref.frequency_response(omega).complex,
                               atol=1e-9 * (1 + np.abs(ours).max()))


@FAST
@given(seed=seeds, period=st.floats(0.2, 3.0))
def test_lti_limit_floquet(seed, period):
    G = random_lti(seed)
    sys = ltp.ltpss(G, period)
    np.testing.assert_allclose(ltp.monodromy(sys), expm(G.A * period), atol=1e-10)
    assert_same_spectrum(ltp.floquet_multipliers(sys), np.exp(np.linalg.eigvals(G.A) * period),
                         1e-10)
    assert ltp.is_stable(sys)


#
# Periodic systems
#

@FEW
@given(q=st.sampled_from([1, 3, 5, 7]), amp=st.floats(0.5, 2.0), phase=st.floats(0, 6.28))
def test_htf_predicts_simulated_steady_state(q, amp, phase):
    sys = mathieu()                          # T = 0.5, |μ| = e^{-1.9 T}
    H = ltp.htf(sys, 2)                      # exact: constant A, K_B = K_C = 1
    h = 0.0025
    t = np.arange(0, 8 + h / 2, h)
    u = amp * np.cos(np.pi * q * t + phase)  # 2 s (4 periods) hold whole input cycles
    y = ltp.forced_response(sys, t, u).outputs
    window = (t >= 6) & (t < 8 - h / 2)
    predicted = H.predict(t[window], u[window]).outputs
    np.testing.assert_allclose(y[window], predicted, atol=1e-3 * np.abs(predicted).max())


@FEW
@given(seed=seeds)
def test_floquet_transform_preserves_input_output(seed):
    sys = damped_mathieu()
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')     # period doubling is announced by a warning
        sysF, P = ltp.floquet_transform(sys)
    assert sysF.is_floquet_form
    np.testing.assert_allclose(P(0.0), np.eye(sys.nstates), atol=1e-12)
    rng = np.random.default_rng(seed)
    t = np.arange(0, 0.8, 0.01)
    u = smooth_inputs(rng, t, (1, 2))       # two traces in one call
    y = ltp.forced_response(sys, t, u).outputs
    yF = ltp.forced_response(sysF, t, u).outputs
    np.testing.assert_allclose(yF, y, atol=1e-8 * (1 + np.abs(y).max()))


@FAST
@given(seed=seeds, nsteps=st.integers(8, 20), periodic_A=st.booleans())
def test_tustin_round_trip(seed, nsteps, periodic_A):
    sys = random_floquet_form(seed, n=2, m=1, p=1, KB=1, KC=1)
    if periodic_A:          # band-limited A(t): Fourier interpolation of N >= 8 samples is exact
        rng = np.random.default_rng(seed + 7)
        A = sys.A + oscillation(rng, 2, 2, 1, sys.period, scale=0.2)
        sys = ltp.ltpss(A, sys.B, sys.C, sys.D, period=sys.period)
    sysd = ltp.sample_system(sys, sys.period / nsteps, 'tustin')
    back = ltp.d2c(sysd)
    assert back.is_floquet_form == sys.is_floquet_form and back.isctime()
    for t in (0.0, 0.13, 0.61):
        for name in 'ABCD':
            np.testing.assert_allclose(getattr(back, name)(t), getattr(sys, name)(t),
                                       atol=1e-9)


def assert_same_spectrum(actual, desired, atol):
    """Equal multisets of complex numbers (greedy nearest matching)."""
    actual, desired = list(np.ravel(actual)), list(np.ravel(desired))
    assert len(actual) == len(desired)
    for value in desired:
        dist = np.abs(np.array(actual) - value)
        i = int(np.argmin(dist))
        assert dist[i] <= atol * (1 + abs(value)), f"{value} missing from {actual}"
        actual.pop(i)


@FAST
@given(seed=seeds, nsteps=st.integers(4, 12))
def test_zoh_sampling_matches_held_simulation(seed, nsteps):
    """Exact ZOH: the sampled system reproduces the continuous response to held inputs."""
    rng = np.random.default_rng(seed)
    sys = random_floquet_form(seed, n=2, m=1, p=1)
    A = sys.A + oscillation(rng, 2, 2, 1, sys.period, scale=0.3)     # periodic A(t)
    sys = ltp.ltpss(A, sys.B, sys.C, sys.D, period=sys.period)
    Ts = sys.period / nsteps
    sysd = ltp.sample_system(sys, Ts)
    t = np.arange(3 * nsteps + 1) * Ts
    u = rng.standard_normal(t.size)
    yd = ltp.forced_response(sysd, t, u).outputs
    yc = ltp.forced_response(sys, t, u, input_hold='zoh').outputs
    np.testing.assert_allclose(yd, yc, atol=1e-9 * (1 + np.abs(yc).max()))


@FAST
@given(a0=st.floats(0.5, 2.0), a1=st.floats(-1.0, 1.0), phi=st.floats(0.0, 6.28))
def test_estimate_htf_of_periodic_gain(a0, a1, phi):
    """``y = (a0 + a1 cos(ω_p t + φ)) u`` has G_0 = a0 and G_{±1} = a1 e^{±jφ}/2."""
    exc = _CHIRPS
    y = (a0 + a1 * np.cos(2 * np.pi * exc.time + phi)) * exc.inputs
    H = ltp.estimate_htf((exc.time, exc.inputs, y), 1.0, 1, segments=exc.segments)
    _, G = H.components()
    expected = np.array([a1 * np.exp(-1j * phi) / 2, a0, a1 * np.exp(1j * phi) / 2])
    np.testing.assert_allclose(G[:, 0, 0, :], np.repeat(expected[:, None], G.shape[-1], 1),
                               atol=1e-8)


_CHIRPS = ltp.chirp_replicas(1.0, 3, 4.0, 0.1, 10.0, dt=0.02)


def _discrete_ltp(seed, nsteps):
    rng = np.random.default_rng(seed)
    n, m, p = int(rng.integers(1, 3)), int(rng.integers(1, 3)), int(rng.integers(1, 3))
    A = rng.standard_normal((nsteps, n, n))
    A *= 0.8 / np.max(np.linalg.norm(A, 2, axis=(1, 2)))          # |μ| <= 0.8^N
    return ltp.ltpss(A, rng.standard_normal((nsteps, n, m)),
                     rng.standard_normal((nsteps, p, n)),
                     rng.standard_normal((nsteps, p, m)), period=1.0, dt=1.0 / nsteps)


@FAST
@given(seed=seeds, half=st.integers(1, 4), theta=st.floats(0.05, 3.0))
def test_frequency_lifting_is_discrete_htf(seed, half, theta):
    nsteps = 2 * half + 1                     # odd N: both keep harmonics -K..K
    sysd = _discrete_ltp(seed, nsteps)
    A, B, C, D = ltp.lift(sysd, real=False)
    z = 1.05 * np.exp(1j * theta)
    lifted = C @ np.linalg.solve(z * np.eye(A.shape[0]) - A, B) + D
    np.testing.assert_allclose(lifted, ltp.htf(sysd, half)(z),
                               atol=1e-9 * (1 + np.abs(lifted).max()))


@FAST
@given(seed=seeds, nsteps=st.integers(2, 9))
def test_real_lifting_is_real_with_the_same_poles(seed, nsteps):
    sysd = _discrete_ltp(seed, nsteps)
    real = ltp.lift(sysd)
    A = ltp.lift(sysd, real=False)[0]
    for M in (real.A, real.B, real.C, real.D):
        assert np.isrealobj(M) and np.all(np.isfinite(M))
    assert_same_spectrum(np.linalg.eigvals(real.A), np.linalg.eigvals(A), 1e-9)
    # time lifting: the period map of both liftings has the Floquet multipliers
    timed = ltp.lift(sysd, method='time')
    assert_same_spectrum(np.linalg.eigvals(timed.A), ltp.floquet_multipliers(sysd), 1e-9)


@FAST
@given(seed=seeds, nsteps=st.integers(2, 6), nperiods=st.integers(2, 4))
def test_time_lifting_reproduces_simulation(seed, nsteps, nperiods):
    sysd = _discrete_ltp(seed, nsteps)
    rng = np.random.default_rng(seed + 3)
    L = nperiods * nsteps
    u = rng.standard_normal((sysd.ninputs, L))
    x0 = rng.standard_normal(sysd.nstates)
    y = ltp.forced_response(sysd, np.arange(L) * sysd.dt, u, x0).outputs
    y = np.reshape(y, (sysd.noutputs, L))
    lifted = ltp.lift(sysd, method='time')
    # stacked signals: u_L[p] = [u[pN]; ...; u[pN + N - 1]]
    uL = u.reshape(sysd.ninputs, nperiods, nsteps).transpose(2, 0, 1).reshape(-1, nperiods)
    yL = ct.forced_response(lifted, np.arange(nperiods) * sysd.period, uL, x0).outputs
    yL = np.reshape(yL, (nsteps, sysd.noutputs, nperiods)).transpose(1, 2, 0).reshape(
        sysd.noutputs, L)
    np.testing.assert_allclose(yL, y, atol=1e-9 * (1 + np.abs(y).max()))


def _central(M, K_wide, K, ny, nu):
    rows = slice((K_wide - K) * ny, (K_wide + K + 1) * ny)
    cols = slice((K_wide - K) * nu, (K_wide + K + 1) * nu)
    return M[rows, cols]


@FAST
@given(seed=seeds, K=st.integers(0, 2), omega=st.floats(-5.0, 5.0))
def test_htf_of_series_is_product_of_htfs(seed, K, omega):
    rng = np.random.default_rng(seed)
    T = 1.0
    # P1: periodic B, constant C;  P2: constant B, periodic C -> series A constant
    P1 = ltp.ltpss(stable_matrix(rng, 2), bandlimited(rng, 2, 1, 1, T),
                   rng.standard_normal((1, 2)), rng.standard_normal((1, 1)), period=T)
    P2 = ltp.ltpss(stable_matrix(rng, 2), rng.standard_normal((2, 1)),
                   bandlimited(rng, 1, 2, 1, T), bandlimited(rng, 1, 1, 1, T), period=T)
    S = ltp.series(P1, P2)
    assert S.is_floquet_form
    s = 1j * omega
    wide = K + 3                          # H2 couples |n - l| <= K_C2 + K_D2
    product = ltp.htf(P2, wide)(s) @ ltp.htf(P1, wide)(s)
    np.testing.assert_allclose(ltp.htf(S, K)(s), _central(product, wide, K, 1, 1),
                               atol=1e-9 * (1 + np.abs(product).max()))
    # parallel: the sum
    Psum = ltp.parallel(P1, P2)
    np.testing.assert_allclose(ltp.htf(Psum, K)(s),
                               ltp.htf(P1, K)(s) + ltp.htf(P2, K)(s), atol=1e-9)


@FAST
@given(seed=seeds, discrete=st.booleans())
def test_fdsubspace_recovers_random_systems(seed, discrete):
    G = random_lti(seed, dt=0.1 if discrete else 0)
    omega = np.linspace(0.2, 0.95 * np.pi / 0.1, 40) if discrete else np.logspace(-1, 1.5, 40)
    data = ct.frd(G, omega)
    model = ltp.fdsubspace(data, order=G.nstates)
    assert model.nstates == G.nstates and model.dt == G.dt
    check = omega[::3] * 1.01
    ref = G.frequency_response(check).complex
    np.testing.assert_allclose(model.frequency_response(check).complex, ref,
                               atol=1e-6 * (1 + np.abs(ref).max()))


#
# Inputs are not modified; seeded results are reproducible
#

def _frozen(*arrays):
    out = []
    for a in arrays:
        a = np.array(a)
        a.flags.writeable = False
        out.append(a)
    return out


@FEW
@given(seed=seeds)
def test_identification_does_not_modify_inputs(seed):
    rng = np.random.default_rng(seed)
    T, dt = 1.0, 0.02
    exc = ltp.chirp_replicas(T, 3, 4.0, 0.1, 10.0, dt=dt)
    gain = 1 + rng.uniform(0.2, 0.8) * np.cos(2 * np.pi * exc.time / T)
    t, u, y, segs = _frozen(exc.time, exc.inputs, gain * exc.inputs, exc.segments)
    copies = [a.copy() for a in (t, u, y, segs)]
    H = ltp.estimate_htf((t, u, y), T, 1, segments=segs)
    for before, after in zip(copies, (t, u, y, segs)):
        np.testing.assert_array_equal(before, after)

    w, G = H.components()
    ref = G.copy()
    ref_frozen, = _frozen(ref)
    ltp.estimate_delays(H, ref_frozen)
    p0, = _frozen([1.0])
    ltp.fit_htf(lambda p, om: p[0] * ref_frozen, H, p0)
    np.testing.assert_array_equal(ref_frozen, ref)

    Gd = random_lti(seed)
    omega, data = _frozen(np.logspace(-1, 1, 25),
                          Gd.frequency_response(np.logspace(-1, 1, 25)).complex)
    weights, = _frozen(np.ones(25))
    data_copy = data.copy()
    ltp.fdsubspace(data, omega, Gd.nstates, weights=weights)
    np.testing.assert_array_equal(data, data_copy)

    yy, yh = _frozen(rng.standard_normal(50), rng.standard_normal(50))
    ltp.e_rms(yy, yh), ltp.nrmse(yy, yh)

    tt = np.arange(1000) * 1e-3
    xs, us = _frozen(np.sin(2 * np.pi * 3 * tt), np.cos(2 * np.pi * 3 * tt))
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        ltp.hybrid_ls(_frozen(tt)[0], xs, us, 1.0, [0.0], nharmonics=0)


@FAST
@given(seed=seeds)
def test_seeded_designs_are_reproducible(seed):
    kw = dict(dt=0.01, nperiods=4, nexperiments=3, phases='random')
    a = ltp.multisine(('band', 1.0, 20.0), 1.0, seed=seed, **kw)
    b = ltp.multisine(('band', 1.0, 20.0), 1.0, seed=seed, **kw)
    c = ltp.multisine(('band', 1.0, 20.0), 1.0, seed=seed + 1, **kw)
    np.testing.assert_array_equal(a.inputs, b.inputs)
    assert not np.allclose(a.inputs, c.inputs)
    gen = ltp.multisine(('band', 1.0, 20.0), 1.0, seed=np.random.default_rng(seed), **kw)
    np.testing.assert_array_equal(gen.inputs, a.inputs)
    np.testing.assert_allclose(a.signal(a.time), a.inputs, atol=1e-12)
    # experiment r is experiment 0 delayed by r T / R
    for r in range(3):
        np.testing.assert_allclose(a.signal(a.time)[0, r], a.signal(a.time - r / 3)[0, 0],
                                   atol=1e-9)


def test_simulation_and_estimation_are_deterministic():
    sys = mathieu()
    t = np.arange(0, 2, 0.01)
    u = np.sin(5 * t)
    y1 = ltp.forced_response(sys, t, u).outputs
    y2 = ltp.forced_response(sys, t, u).outputs
    np.testing.assert_array_equal(y1, y2)


#
# PeriodicMatrix algebra
#

def _random_pm(rng, rows, cols, K, period=1.0):
    return bandlimited(rng, rows, cols, K, period, scale=1.0)


@FAST
@given(seed=seeds, Ka=st.integers(0, 3), Kb=st.integers(0, 3))
def test_fourier_of_product_is_convolution(seed, Ka, Kb):
    rng = np.random.default_rng(seed)
    P, Q = _random_pm(rng, 2, 3, Ka), _random_pm(rng, 3, 2, Kb)
    K = Ka + Kb
    R = (P @ Q).fourier(K)
    p, q = P.fourier(Ka), Q.fourier(Kb)
    expected = np.zeros_like(R)
    for i, k in enumerate(range(-Ka, Ka + 1)):
        for j, l in enumerate(range(-Kb, Kb + 1)):
            expected[k + l + K] += p[i] @ q[j]
    np.testing.assert_allclose(R, expected, atol=1e-12)
    t = rng.uniform(0, 1, 5)
    np.testing.assert_allclose((P @ Q)(t), P(t) @ Q(t), atol=1e-12)
    np.testing.assert_allclose((P + 2.0 * P)(t), 3 * P(t), atol=1e-12)


@FAST
@given(seed=seeds, K=st.integers(0, 5), kind=st.sampled_from(['function', 'switching',
                                                             'samples']))
def test_fourier_coefficients_are_conjugate_symmetric(seed, K, kind):
    rng = np.random.default_rng(seed)
    a, b = rng.standard_normal(2)
    if kind == 'function':
        P = ltp.PeriodicMatrix.from_function(
            lambda t: np.array([[a * np.cos(2 * np.pi * t) + np.sin(4 * np.pi * t) ** 2,
                                 b * np.exp(np.sin(2 * np.pi * t))]]), 1.0)
    elif kind == 'switching':
        P = ltp.PeriodicMatrix.switching([[[a, 1.0]], [[b, -1.0]]],
                                         [0.0, rng.uniform(0.1, 0.9)], 1.0)
    else:
        P = ltp.PeriodicMatrix.from_samples(rng.standard_normal((7, 1, 2)), 1.0)
    c = P.fourier(K)
    np.testing.assert_allclose(c, np.conj(c[::-1]), atol=1e-12)
    values = P(rng.uniform(0, 3, 4))
    assert np.isrealobj(values) and values.shape == (4, 1, 2)
    np.testing.assert_allclose(P(0.3), P(1.3), atol=1e-12)


def _quadrature_fourier(P, K, nsamp=4096):
    """Midpoint-rule coefficients of the evaluated function (reference)."""
    t = (np.arange(nsamp) + 0.5) * P.period / nsamp
    values = P(t)
    ks = np.arange(-K, K + 1)
    kernel = np.exp(-2j * np.pi * np.outer(ks, t) / P.period) / nsamp
    return np.einsum('kt,tij->kij', kernel, values)


@FAST
@given(seed=seeds, tsw=st.floats(0.1, 0.9))
def test_switching_fourier_matches_quadrature(seed, tsw):
    rng = np.random.default_rng(seed)
    pieces = [_random_pm(rng, 1, 1, 1), _random_pm(rng, 1, 1, 2)]
    P = ltp.PeriodicMatrix.switching(pieces, [0.0, tsw], 1.0)
    np.testing.assert_allclose(P.fourier(3), _quadrature_fourier(P, 3), atol=2e-3)


def test_switching_piece_with_shorter_period():
    piece = ltp.PeriodicMatrix([[[0.5]], [[0.0]], [[0.5]]], 0.5)     # cos(4πt)
    P = ltp.PeriodicMatrix.switching([piece, [[0.0]]], [0.0, 0.5], 1.0)
    np.testing.assert_allclose(P.fourier(3), _quadrature_fourier(P, 3), atol=1e-3)
