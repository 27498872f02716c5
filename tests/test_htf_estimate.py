"""Tests of the nonparametric HTF estimator against an independent LTP simulator.

Truth: the scalar LTP system ``ẋ = a(t) x + b(t)·u, y = c(t) x`` with
``a = a0 + a1 cos ω_p t``, ``b_j = b0 + b1 sin ω_p t``, ``c_o = c0 + c1 cos ω_p t``
is simulated exactly between samples (state transition ``exp ∫a`` and
Gauss-Legendre quadrature of the continuous input), and its HTF comes from
the truncated harmonic-balance formula ``C_T [sI - (A_T - N)]⁻¹ B_T`` with
K = 20 (central block row, ``G_k = H_{0,-k}``).
"""

import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from control.exception import ControlArgument, ControlDimension

from ltpcontrol import chirp_replicas
from ltpcontrol import HTFData
from ltpcontrol import HTFEstimateInfo, estimate_htf
from ltpcontrol import e_rms, nrmse

_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)


def estimate_arrays(*args, **kwargs):
    """`estimate_htf` as arrays: components, omega, std (NaN without dof) and the info."""
    H, info = estimate_htf(*args, return_info=True, **kwargs)
    assert isinstance(H, HTFData) and isinstance(info, HTFEstimateInfo)
    omega, G = H.components()
    std = np.full(G.shape, np.nan) if H.std is None else H.std
    return SimpleNamespace(components=G, omega=omega, std=std, **vars(info))


class ScalarLTP:
    """Scalar-state LTP system with first-harmonic coefficients."""

    def __init__(self, period=1.0, a0=-2.0, a1=0.8, b=((1.0, 0.4),), c=((1.0, 0.3),)):
        self.period = period
        self.wp = 2 * np.pi / period
        self.a0, self.a1 = a0, a1
        self.b = np.array(b, float)          # rows (b0, b1) per input
        self.c = np.array(c, float)          # rows (c0, c1) per output

    def _int_a(self, t):                     # ∫_0^t a(s) ds
        return self.a0 * t + self.a1 / self.wp * np.sin(self.wp * t)

    def simulate(self, signal, t):
        """Output samples (ny, nt) for the continuous input ``signal(t)``."""
        h = t[1] - t[0]
        nodes = t[:-1, None] + (_GL_X[None, :] + 1) * h / 2
        u = np.atleast_2d(signal(nodes.ravel())).reshape(-1, *nodes.shape)
        b = self.b[:, :1, None] + self.b[:, 1:, None] * np.sin(self.wp * nodes)[None]
        # x_{n+1} = e^{∫_{t_n}^{t_{n+1}} a} x_n + ∫ e^{∫_τ^{t_{n+1}} a} b(τ)·u(τ) dτ
        kern = np.exp(self._int_a(t[1:])[:, None] - self._int_a(nodes))
        q = (np.sum(b * u, axis=0) * kern) @ _GL_W * h / 2
        phi = np.exp(self._int_a(t[1:]) - self._int_a(t[:-1]))
        x = np.zeros(t.size)
        for n in range(t.size - 1):
            x[n + 1] = phi[n] * x[n] + q[n]
        return (self.c[:, :1] + self.c[:, 1:] * np.cos(self.wp * t)) * x

    def htf(self, omega, K, ktrue=20):
        """True ``G_k(jω)``, k = -K..K, shape (2K+1, ny, nu, F)."""
        n = 2 * ktrue + 1
        harm = np.arange(-ktrue, ktrue + 1)

        def toeplitz(c0, cplus, cminus):     # block (n, m) = coefficient_{n-m}
            return (np.diag(np.full(n, c0 + 0j)) + np.diag(np.full(n - 1, cplus), -1)
                    + np.diag(np.full(n - 1, cminus), 1))

        a_t = toeplitz(self.a0, self.a1 / 2, self.a1 / 2)
        omega = np.asarray(omega, float)
        res = np.linalg.inv(1j * omega[:, None, None] * np.eye(n)
                            - (a_t - np.diag(1j * harm * self.wp)))      # (F, n, n)
        b_t = np.stack([toeplitz(b0, b1 / 2j, -b1 / 2j) for b0, b1 in self.b])
        c_t = np.stack([toeplitz(c0, c1 / 2, c1 / 2)[ktrue] for c0, c1 in self.c])
        # central block row: H_{0,m} = c_T[0,:] R B_T[:, m];  G_k = H_{0,-k}
        h0 = np.einsum('on,fnp,jpm->fojm', c_t, res, b_t)
        cols = ktrue - np.arange(-K, K + 1)
        return np.transpose(h0[..., cols], (3, 1, 2, 0))


@pytest.fixture(scope="module")
def replica_data():
    """Seven phase-shifted chirp replicas (0-4 Hz, 20 s, 8 s gaps), T = 1 s."""
    system = ScalarLTP()
    exc = chirp_replicas(1.0, 7, 20.0, 0.0, 4.0, dt=0.01, gap=8.0)
    y = system.simulate(exc.signal, exc.time)[0]
    return system, exc, y


@pytest.fixture(scope="module")
def single_record():
    """One 60-s chirp in an 80-s record with output noise (σ = 0.002)."""
    system = ScalarLTP()
    exc = chirp_replicas(1.0, 1, 60.0, 0.0, 4.0, dt=0.01, gap=20.0)
    y = system.simulate(exc.signal, exc.time)[0]
    noise = 0.002 * np.random.default_rng(0).standard_normal(y.size)
    return system, exc, y + noise


def test_simulator_matches_harmonic_balance():
    # steady-state response to cos(ωt): DFT line at ω + nω_p equals G_n(ω + nω_p)/2
    system = ScalarLTP(a1=1.5, b=((1.0, 0.7),), c=((1.0, 0.4),))
    t = np.arange(0, 40, 0.01)
    w = 2 * np.pi * 0.25
    y = system.simulate(lambda s: np.cos(w * s), t)[0]
    keep = t >= 12                                    # 28 s: whole periods of both
    for n in range(-2, 3):
        line = 2 * np.mean(y[keep] * np.exp(-1j * (w + n * system.wp) * t[keep]))
        true = system.htf([w + n * system.wp], 2)[n + 2, 0, 0, 0]
        assert abs(line - true) < 1e-9


def test_replicas_noise_free_match_truth(replica_data):
    system, exc, y = replica_data
    est = estimate_arrays((exc.time, exc.inputs, y), 1.0, 2, segments=exc.segments)
    assert est.success
    assert est.components.shape == (5, 1, 1, est.omega.size)
    assert est.identified.all()                       # default: fully excited band
    assert est.omega[0] == 0 and est.omega[-1] > 2 * np.pi * 2.5
    true = system.htf(est.omega, 2)
    err = np.abs(est.components - true)
    # ≤ 1 % of each component's magnitude over the band (k = -1, 0, 1) ...
    assert np.max(err[1:4] / np.abs(true[1:4])) < 0.01
    # ... and ≤ 1 % of its peak for the small second harmonics
    assert np.all(np.max(err, axis=-1) < 0.01 * np.max(np.abs(true), axis=-1))
    assert np.max(est.cond) < 200                     # replicas decouple Φ_UU


def test_reported_std_covers_errors(replica_data):
    system, exc, y = replica_data
    rng = np.random.default_rng(7)
    sigma = 0.01
    noisy = y + sigma * rng.standard_normal(y.size)
    est = estimate_arrays((exc.time, exc.inputs, noisy), 1.0, 2, segments=exc.segments)
    # noise variance of one DFT coefficient: dt · T_w · σ²
    assert est.noise_var[0] == pytest.approx(0.01 * 29 * sigma ** 2, rel=0.2)
    z = np.abs(est.components - system.htf(est.omega, 2)) / est.std
    # complex Gaussian errors: P(|e| < σ) = 1 - e^{-1}, P(|e| < 2σ) = 1 - e^{-4}
    assert 0.55 < np.mean(z < 1) < 0.72
    assert np.mean(z < 2) > 0.95


def test_too_few_replicas_warns_ill_conditioned(replica_data):
    system, exc, y = replica_data
    # five copies of one window (same cycle phase) cannot separate five components
    with pytest.warns(UserWarning, match="ill-conditioned"):
        est = estimate_arrays((exc.time, exc.inputs, y), 1.0, 2, segments=exc.segments[[0] * 5])
    assert np.min(est.cond) > 1e8 and np.all(np.isfinite(est.components))
    assert not est.success and "ill-conditioned" in est.message


def test_large_alpha_gives_straight_lines(single_record):
    system, exc, y = single_record
    lim = (2 * np.pi * 1.5, 2 * np.pi * 2.5)
    est = estimate_arrays((exc.time, exc.inputs, y), 1.0, 1, alpha=1e10, omega_limits=lim)
    g = est.components[:, 0, 0]
    assert np.max(np.abs(np.diff(g, 2, axis=-1))) < 1e-8 * np.max(np.abs(g))
    # independent truth: least squares over affine components a_k + b_k ω
    U = np.fft.fft(exc.inputs) * 0.01
    Y = np.fft.fft(y) * 0.01
    ns, L = U.size, 80
    m = np.round(est.omega / (2 * np.pi / L)).astype(int)
    reg = np.stack([U[(m - k * L) % ns] for k in (-1, 0, 1)], axis=1)   # (F, 3)
    design = np.concatenate([reg, reg * est.omega[:, None]], axis=1)
    coef = np.linalg.lstsq(design, Y[m], rcond=None)[0]
    affine = coef[:3, None] + coef[3:, None] * est.omega[None, :]
    assert np.allclose(g, affine, rtol=0, atol=1e-5 * np.max(np.abs(affine)))


def test_gcv_beats_unregularised_single_record(single_record):
    system, exc, y = single_record
    lim = (2 * np.pi * 1.2, 2 * np.pi * 2.8)
    data = (exc.time, exc.inputs, y)
    raw = estimate_arrays(data, 1.0, 1, alpha=1e-9, omega_limits=lim)
    gcv = estimate_arrays(data, 1.0, 1, alpha='gcv', omega_limits=lim, progress=False)
    assert 1e-6 < gcv.alpha < 1e6
    true = system.htf(gcv.omega, 1)
    err_raw = np.median(np.abs(raw.components - true) / np.abs(true), axis=-1)
    err_gcv = np.median(np.abs(gcv.components - true) / np.abs(true), axis=-1)
    assert np.all(err_gcv < 0.5 * err_raw)
    assert np.all(err_gcv < 0.03)
    assert np.isfinite(gcv.gcv) and gcv.dof > 0
    assert np.all(np.isfinite(gcv.std)) and np.all(gcv.std > 0)


def test_mimo_two_inputs_two_outputs():
    system = ScalarLTP(b=((1.0, 0.4), (0.5, -0.6)), c=((1.0, 0.3), (0.2, 0.5)))
    exc = chirp_replicas(1.0, 7, 12.0, 0.0, 3.0, dt=0.02, gap=8.0)
    # second input: the same replicas delayed by half a record (uncorrelated)
    nseg = exc.segments.shape[0]
    rec_len = exc.segments[0, 1] * 0.02
    u2 = lambda t: exc.signal(t - rec_len * nseg)
    t = np.arange(2 * exc.time.size) * 0.02
    sig = lambda s: np.stack([exc.signal(s), u2(s)])
    y = system.simulate(sig, t)
    segs = np.vstack([exc.segments, exc.segments + exc.time.size])
    est = estimate_arrays((t, sig(t), y), 1.0, 1, segments=segs)
    assert est.components.shape[:3] == (3, 2, 2)
    true = system.htf(est.omega, 1)
    assert np.max(np.abs(est.components - true)) < 0.01 * np.max(np.abs(true))


def test_time_response_data_input(replica_data):
    import control as ct
    system, exc, y = replica_data
    resp = ct.TimeResponseData(exc.time, y, inputs=exc.inputs)
    a = estimate_arrays(resp, 1.0, 1, segments=exc.segments)
    b = estimate_arrays([(exc.time, exc.inputs, y)], 1.0, 1, segments=exc.segments)
    assert np.allclose(a.components, b.components)


def test_time_origin_is_phase_reference(replica_data):
    # relabelling time t -> t + τ shifts the cycle phase: G'_k = G_k e^{-jkω_p τ}
    system, exc, y = replica_data
    tau = 0.3
    est = estimate_arrays((exc.time + tau, exc.inputs, y), 1.0, 2, segments=exc.segments)
    k = np.arange(-2, 3)[:, None, None, None]
    true = system.htf(est.omega, 2) * np.exp(-1j * k * system.wp * tau)
    assert np.max(np.abs(est.components[1:4] - true[1:4]) / np.abs(true[1:4])) < 0.01


def test_unequal_windows_are_cut_with_warning(replica_data):
    system, exc, y = replica_data
    segs = exc.segments.copy()
    segs[-1, 1] -= 150                                 # last window: 27 periods
    with pytest.warns(UserWarning, match="cut to the common 27 periods"):
        est = estimate_arrays((exc.time, exc.inputs, y), 1.0, 2, segments=segs)
    true = system.htf(est.omega, 2)
    assert np.max(np.abs(est.components[1:4] - true[1:4]) / np.abs(true[1:4])) < 0.01


def test_returns_htf_that_predicts_new_inputs(replica_data):
    system, exc, y = replica_data
    H = estimate_htf((exc.time, exc.inputs, y), 1.0, 2, segments=exc.segments,
                     name='hop')
    assert isinstance(H, HTFData) and H.name == 'hop' and H.nharmonics == 2
    H2, info = estimate_htf((exc.time, exc.inputs, y), 1.0, 2, segments=exc.segments,
                            return_info=True)
    w, G = H.components()
    assert np.array_equal(w, H2.omega) and np.array_equal(G, H2.components()[1])
    assert H.std.shape == G.shape and info.identified.all()
    assert info.success and info.cond.shape == w.shape and info.alpha == 0
    with pytest.raises(AttributeError):          # frozen, like OptimizeResult's fields
        info.alpha = 1.0
    # validation on an input not used for training: steady-state response to a
    # sum of two sines whose output lines all lie in the estimated band
    t = np.arange(0, 60, 0.01)
    u = lambda s: 0.5 * np.cos(2 * np.pi * 0.3 * s) + np.sin(2 * np.pi * 0.45 * s)
    yv = system.simulate(u, t)[0]
    keep = t >= 40                                    # 20 periods of T and of u
    y_hat = H.predict(t[keep], u(t[keep])).outputs
    assert e_rms(yv[keep], y_hat) < 0.5


def test_no_residual_dof_gives_no_std(replica_data):
    system, exc, y = replica_data
    H, info = estimate_htf((exc.time, exc.inputs, y), 1.0, 3, segments=exc.segments,
                           return_info=True)
    assert H.std is None and info.dof == pytest.approx(0, abs=1e-6)


LIMITS = (0.0, 2 * np.pi * 15)          # G_3 reaches 12 + 3.6 Hz


@pytest.fixture(scope="module")
def narrow_band():
    """ω_p = 4 Hz, three replicas of a 0-3 Hz chirp: no ω excites all of |k| <= 3."""
    system = ScalarLTP(period=0.25)
    exc = chirp_replicas(0.25, 3, 10.0, 0.0, 3.0, dt=0.01, gap=8.0)
    return system, exc, system.simulate(exc.signal, exc.time)[0]


@pytest.mark.parametrize("alpha", [0.0, 1e-3])
def test_narrow_band_estimates_excited_components(narrow_band, alpha):
    system, exc, y = narrow_band
    est = estimate_arrays((exc.time, exc.inputs, y), 0.25, 3, segments=exc.segments,
                    alpha=alpha, omega_limits=LIMITS)
    ident = est.identified[:, 0, 0]
    # at most two shifted inputs |ω - 4k Hz| <= 3 Hz (+ leakage) per output frequency
    assert ident.sum(axis=0).max() == 2 and ident.any(axis=0).all()
    true = system.htf(est.omega, 3)
    f = est.omega / (2 * np.pi)
    for k in range(-3, 4):
        row, g, gt = ident[k + 3], est.components[k + 3, 0, 0], true[k + 3, 0, 0]
        # identified exactly where U(ω - kω_p) carries the chirp (|ω - kω_p| <~ 3.6 Hz)
        assert np.all(row[np.abs(f - 4 * k) <= 3.0])
        assert not np.any(row[np.abs(f - 4 * k) > 3.7])
        if alpha == 0:
            assert np.all(np.isnan(g[~row])) and np.all(np.isfinite(g[row]))
        assert np.array_equal(np.isnan(est.std[k + 3, 0, 0]), ~row)
        band = np.abs(f - 4 * k) <= 2.9
        err = np.abs(g - gt)[band]
        if k in (0, 1):
            assert np.max(err / np.abs(gt[band])) < 0.01
        elif k == 2:                       # 3 % of G_0: 1 % of its peak
            assert np.max(err) < 0.01 * np.max(np.abs(gt))
    # G_{-k}(jω), k > 0, needs U(ω + kω_p) >= 4 Hz: identified only through
    # G_{-k}(jω) = conj G_k(-jω) on negative frequencies
    assert not ident[:3].any()
    if alpha > 0:
        # the penalty is not extrapolated beyond the identified range ...
        assert np.array_equal(np.isfinite(est.components), est.identified)
        # ... but bridges gaps inside it: a high threshold cuts the chirp's
        # spectral ripple into excited and unexcited stretches
        with pytest.warns(UserWarning, match="interpolated"):
            gap = estimate_arrays((exc.time, exc.inputs, y), 0.25, 3, alpha=alpha,
                            segments=exc.segments, omega_limits=LIMITS, threshold=0.5)
        g1, id1 = gap.components[4, 0, 0], gap.identified[4, 0, 0]
        inside = (gap.omega > gap.omega[id1][0]) & (gap.omega < gap.omega[id1][-1])
        assert np.sum(inside & ~id1) > 5 and np.all(np.isfinite(g1[inside]))
        # G_1 is measured where identified (the bridge near ω_p, where U(ω - ω_p)
        # is weak, is a smooth guess across the peak of |G_1|)
        true1 = system.htf(gap.omega, 3)[4, 0, 0]
        assert np.max(np.abs(g1 - true1)[id1]) < 0.01 * np.max(np.abs(true1))
    H, info = estimate_htf((exc.time, exc.inputs, y), 0.25, 3, segments=exc.segments,
                           alpha=alpha, omega_limits=LIMITS, return_info=True)
    # the HTF marks what the data do not determine as NaN, like the estimate
    np.testing.assert_array_equal(np.isnan(H.components()[1]), np.isnan(est.components))
    assert np.all(np.isnan(H.components()[1][:3]))
    assert np.array_equal(info.identified, est.identified)


def test_partial_frequencies_keep_fully_excited_estimates(replica_data):
    # omega_limits adds partially identified frequencies; where every component
    # is identified the per-frequency estimate is unchanged
    _, exc, y = replica_data
    full = estimate_arrays((exc.time, exc.inputs, y), 1.0, 2, segments=exc.segments)
    part = estimate_arrays((exc.time, exc.inputs, y), 1.0, 2, segments=exc.segments,
                     omega_limits=(0.0, 2 * np.pi * 6))
    assert part.omega.size > full.omega.size
    assert np.array_equal(part.omega[:full.omega.size], full.omega)
    assert np.array_equal(part.components[..., :full.omega.size], full.components)
    assert not part.identified[..., full.omega.size:].all(axis=(0, 1, 2)).any()


# ----------------------------------------------------------------- bad input
def test_record_shorter_than_one_period():
    t = np.arange(50) * 0.01
    with pytest.raises(ValueError, match="shorter than one period"):
        estimate_arrays((t, np.sin(t), np.cos(t)), 1.0, 1, alpha=1.0)


def test_period_not_commensurate_with_sampling():
    t = np.arange(1000) * 0.01
    with pytest.raises(ValueError, match="integer number of samples per period"):
        estimate_arrays((t, np.sin(t), np.cos(t)), 1.005, 1, alpha=1.0)


def test_nan_in_data(replica_data):
    _, exc, y = replica_data
    bad = y.copy()
    bad[10] = np.nan
    with pytest.raises(ValueError, match="outputs must be finite"):
        estimate_arrays((exc.time, exc.inputs, bad), 1.0, 1, segments=exc.segments)


def test_nharmonics_too_large_for_band(replica_data):
    _, exc, y = replica_data
    with pytest.raises(ValueError, match="too large for the excited band.*omega_limits"):
        estimate_arrays((exc.time, exc.inputs, y), 1.0, 5, segments=exc.segments)


def test_no_identifiable_frequency_in_limits(replica_data):
    # inputs excited up to 4 Hz: no shift |k| <= 2 reaches outputs at 40-45 Hz
    _, exc, y = replica_data
    with pytest.raises(ValueError, match="no output frequency in omega_limits"):
        estimate_arrays((exc.time, exc.inputs, y), 1.0, 2, segments=exc.segments,
                  omega_limits=(2 * np.pi * 40, 2 * np.pi * 45))


def test_zero_input_rejected():
    t = np.arange(500) * 0.01
    with pytest.raises(ValueError, match="identically zero"):
        estimate_arrays((t, np.zeros(500), np.sin(t)), 1.0, 1, alpha=1.0)


def test_gcv_on_pure_noise_warns_at_range_edge(single_record):
    # output unrelated to the input: the smoothest fit (affine, ≈ 0) wins
    _, exc, _ = single_record
    y = 0.01 * np.random.default_rng(5).standard_normal(exc.time.size)
    with pytest.warns(UserWarning, match="edge of the searched range"):
        est = estimate_arrays((exc.time, exc.inputs, y), 1.0, 1, alpha='gcv', progress=False,
                        omega_limits=(2 * np.pi * 1.2, 2 * np.pi * 2.8))
    assert est.alpha == pytest.approx(1e6)


def test_alpha_zero_needs_enough_records(single_record):
    _, exc, y = single_record
    with pytest.raises(ValueError, match="at least"):
        estimate_arrays((exc.time, exc.inputs, y), 1.0, 1)


def test_unexcited_frequencies_in_limits_warn(replica_data):
    _, exc, y = replica_data
    # output frequencies up to 6 Hz have U(ω - 2ω_p) excited (chirp 0-4 Hz + leakage)
    with pytest.warns(UserWarning, match="unexcited: 42 dropped, 0 interpolated"):
        est = estimate_arrays((exc.time, exc.inputs, y), 1.0, 2, segments=exc.segments,
                        omega_limits=(0.0, 2 * np.pi * 8))
    assert 2 * np.pi * 6 < est.omega[-1] < 2 * np.pi * 7


@pytest.mark.parametrize("kwargs, exc_type, match", [
    ({"alpha": -1.0}, ValueError, "alpha"),
    ({"alpha": "lcurve"}, ValueError, "alpha"),
    ({"threshold": 2.0}, ValueError, "threshold"),
    ({"segments": [[0.5, 3]]}, ControlDimension, "segments"),
    ({"omega_limits": (3.0, 1.0)}, ValueError, "omega_limits"),
    ({"bogus": 1}, TypeError, "bogus"),
])
def test_argument_errors(replica_data, kwargs, exc_type, match):
    _, exc, y = replica_data
    with pytest.raises(exc_type, match=match):
        estimate_htf((exc.time, exc.inputs, y), 1.0, 1, **kwargs)


def test_data_type_errors():
    t = np.arange(200) * 0.01
    with pytest.raises(ControlArgument, match="data"):
        estimate_arrays("abc", 1.0, 1)
    with pytest.raises(ControlArgument, match=r"data\[0\]"):
        estimate_arrays([np.ones(3)], 1.0, 1)
    with pytest.raises(ControlDimension, match="must have the same experiments"):
        estimate_arrays((t, np.ones(199), np.ones(200)), 1.0, 1)
    with pytest.raises(ValueError, match="uniformly"):
        estimate_arrays((t ** 2, np.ones(200), np.ones(200)), 1.0, 1)
    with pytest.raises(ValueError, match="period"):
        estimate_arrays((t, np.ones(200), np.ones(200)), -1.0, 1)


def test_metrics():
    y = np.sin(np.linspace(0, 10, 500))
    assert e_rms(y, y) == 0
    assert e_rms(y, 0.9 * y) == pytest.approx(10.0)
    assert nrmse(y, 0.9 * y) == pytest.approx(0.1)
    with pytest.raises(ControlDimension, match="y_hat"):
        nrmse(y, y[:-1])
    with pytest.raises(ValueError, match="y "):
        nrmse(np.zeros(5), np.ones(5))


# ---------------------------------------------------------------- calibration
@pytest.fixture(scope="module")
def ten_replicas():
    """Ten phase-shifted chirp replicas (0-4 Hz, 10 s, 8 s gaps) of the default plant."""
    system = ScalarLTP()
    exc = chirp_replicas(1.0, 10, 10.0, 0.0, 4.0, dt=0.01, gap=8.0)
    return system, exc, system.simulate(exc.signal, exc.time)[0]


def test_unmodelled_harmonics_are_detected(ten_replicas):
    # a(t) is periodic: G_k decays with |k| but never vanishes.  With K = 1 the
    # residual holds G_{±2}: the noise variance is inflated many times.
    system, exc, y = ten_replicas
    noisy = y + 0.01 * np.random.default_rng(3).standard_normal(y.size)
    with pytest.warns(UserWarning, match=r"unmodelled harmonics: the inputs shifted by "
                                         r"±2ω_p .*\|k\| > 1"):
        H, info = estimate_htf((exc.time, exc.inputs, noisy), 1.0, 1,
                               segments=exc.segments, return_info=True)
    assert "unmodelled harmonics" in info.message
    test = info.harmonic_test
    assert test["pvalue"] < 1e-6 and test["variance_ratio"] > 3


@pytest.mark.parametrize("seed", [3, 4])
def test_std_calibrated_when_k_is_too_small(ten_replicas, seed):
    # With K = 1 the residual holds G_{±2} U(ω ∓ 2ω_p), many times the noise.  The
    # noise variance comes from the fit with G_{±2} modelled instead: it equals the
    # true variance of one output DFT bin, dt² N σ², and the std describe the errors
    # of the K = 1 components (the residual's variance would make them 2-6× too large).
    system, exc, y = ten_replicas
    sigma = 0.01
    noisy = y + sigma * np.random.default_rng(seed).standard_normal(y.size)
    with pytest.warns(UserWarning, match=r"unmodelled harmonics.*std uses the noise "
                                         r"variance of the fit with G_\{±2\} modelled"):
        H, info = estimate_htf((exc.time, exc.inputs, noisy), 1.0, 1,
                               segments=exc.segments, return_info=True)
    dt, nsamples = 0.01, 1900                # 19 periods of 100 samples per window
    noise_var = info.noise_var[0]
    assert noise_var == pytest.approx(dt ** 2 * nsamples * sigma ** 2, rel=0.15)
    inflation = info.residual[0] ** 2 / noise_var
    assert inflation > 2
    z2 = (np.abs(H.components()[1] - system.htf(H.omega, 1)) / H.std) ** 2
    # complex Gaussian errors: E|e|²/σ² = 1 (a few % of G_{±3} and aliasing remain)
    assert np.mean(z2) == pytest.approx(1, abs=0.25)


def test_two_sigma_coverage_when_k_is_large_enough(ten_replicas):
    system, exc, y = ten_replicas
    z = []
    for seed in range(6):
        noisy = y + 0.03 * np.random.default_rng(seed).standard_normal(y.size)
        with warnings.catch_warnings():
            warnings.simplefilter("error")       # K = 3 passes the harmonic test
            H, info = estimate_htf((exc.time, exc.inputs, noisy), 1.0, 3,
                                   segments=exc.segments, return_info=True)
        assert info.harmonic_test["pvalue"] > 1e-3 and info.success
        z.append(np.abs(H.components()[1] - system.htf(H.omega, 3)) / H.std)
    z = np.concatenate([zi.ravel() for zi in z])
    # complex Gaussian errors: P(|e| < 2σ) = 1 - e^{-4} = 0.982
    assert 0.9 < np.mean(z < 2) < 0.99
    assert np.mean(z ** 2) == pytest.approx(1, abs=0.1)


@pytest.mark.parametrize("nreplicas, nharmonics", [(3, 1), (6, 2)])
def test_minimum_replicas_warn_about_aliasing(nreplicas, nharmonics):
    # G_{K+1} aliases into G_{K+1-R} with R phase-shifted replicas; harmonics beyond K
    # are large here (a1 = 2), and too few windows are left to detect them
    system = ScalarLTP(a1=2.0)
    exc = chirp_replicas(1.0, nreplicas, 10.0, 0.0, 4.0, dt=0.01, gap=8.0)
    y = system.simulate(exc.signal, exc.time)[0]
    K = nharmonics
    with pytest.warns(UserWarning, match=rf"G_{K + 1} into G_{K + 1 - nreplicas}"):
        H = estimate_htf((exc.time, exc.inputs, y), 1.0, K, segments=exc.segments)
    err = np.abs(H.components()[1] - system.htf(H.omega, K))
    rel = np.max(err, axis=-1) / np.max(np.abs(system.htf(H.omega, K)), axis=-1)
    assert rel.max() > 0.05                  # the warning is not a false alarm


def test_enough_replicas_keep_errors_small_or_warn():
    # default-style design with 2(2K+1) + 1 replicas on a plant with harmonics beyond K
    system = ScalarLTP(a1=2.0)
    for K in (1, 2):
        exc = chirp_replicas(1.0, 2 * (2 * K + 1) + 1, 10.0, 0.0, 4.0, dt=0.01, gap=8.0)
        y = system.simulate(exc.signal, exc.time)[0]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            H = estimate_htf((exc.time, exc.inputs, y), 1.0, K, segments=exc.segments)
        true = system.htf(H.omega, K)
        rel = np.max(np.abs(H.components()[1] - true), axis=-1) / np.max(np.abs(true),
                                                                        axis=-1)
        warned = any(f"±{K + 1}ω_p" in str(w.message) for w in caught)
        assert rel.max() <= 0.05 or warned
        assert warned                            # harmonics beyond K are reported

