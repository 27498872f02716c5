"""Tests of the SLIP example plants (examples/slip_*.py), thesis Chapter 2."""

import doctest

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from examples import slip_data
from examples import slip_identification as sid
from examples import slip_model as sm

LOSSLESS = sm.SLIPParams(m_l=0.0, d=0.0, d_h=0.0, d_v=0.0)


def _throws(n, params, seed, spread=0.0, method="SLIP", speed=(0.3, 2.5)):
    rng = np.random.default_rng(seed)
    apex = np.column_stack([np.zeros(n), rng.uniform(*speed, n), rng.uniform(0.24, 0.48, n)])
    theta = sm.neutral_touchdown_angle(apex, params, method) + rng.uniform(-spread, spread, n)
    return apex, theta


def _apex_errors(pred, ref):
    e_ap = 100 * np.hypot(pred.apex.y - ref.apex.y, pred.apex.z - ref.apex.z) \
        / np.hypot(ref.apex.y, ref.apex.z)
    e_av = 100 * np.abs(pred.apex.vy - ref.apex.vy) / np.abs(ref.apex.vy)
    return np.mean(e_ap), np.mean(e_av)


@pytest.mark.parametrize("module", [sm, slip_data])
def test_docstring_examples(module):
    result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0


def test_boom_gravity_thesis_value():
    # Section 2.3.3: M = 3.4 kg, m = 0.39 kg give g = 9.99 m/s^2
    assert sm.boom_gravity(3.4, 0.39) == pytest.approx(9.99, abs=5e-3)
    assert sm.boom_gravity(3.4, 0.0) == 9.81


def test_flight_closed_form_matches_integration():
    d_h, d_v, g = 0.7, 0.4, 9.99
    x0 = [0.1, 0.5, 1.3, 0.8]
    sol = solve_ivp(lambda t, x: [x[2], x[3], -d_h * x[2], -g - d_v * x[3]], (0, 0.6),
                    x0, rtol=1e-12, atol=1e-14, dense_output=True)
    t = np.linspace(0, 0.6, 7)
    closed = np.array(sm.flight_state(t, x0[0], x0[1], x0[2], x0[3], d_h, d_v, g))
    np.testing.assert_allclose(closed, sol.sol(t), atol=1e-10)
    # touchdown and apex times are roots of (2.6) and (2.8)
    t_td = sm.descent_time(0.4, 0.2, d_v, g)
    assert sm.flight_state(t_td, 0, 0.4, 0, 0, d_h, d_v, g)[1] == pytest.approx(0.2, abs=1e-12)
    t_a = sm.ascent_apex_time(1.5, d_v, g)
    assert sm.flight_state(t_a, 0, 0, 0, 1.5, d_h, d_v, g)[3] == pytest.approx(0, abs=1e-12)


def test_liftoff_collision_momentum():
    vy, vz = sm.liftoff_collision(1.2, 0.9, 3.21, 0.19)
    # (2.21): body momentum shared with the (resting) leg mass
    assert 3.4 * vy == pytest.approx(3.21 * 1.2) and 3.4 * vz == pytest.approx(3.21 * 0.9)


def test_slipd_conserves_energy_without_damping():
    apex, theta = [0.0, 1.2, 0.4], -0.12
    stride = sm.predict_stride(apex, theta, LOSSLESS, "SLIPD")
    t = np.linspace(0, stride.apex.t, 3000)
    y, z, vy, vz = sm.stride_trajectory(apex, theta, LOSSLESS, "SLIPD", t)
    toe = stride.touchdown.y - LOSSLESS.rho0 * np.sin(theta)
    stance = (t >= stride.touchdown.t) & (t < stride.liftoff.t)
    spring = np.where(stance, 0.5 * LOSSLESS.k * (np.hypot(y - toe, z) - LOSSLESS.rho0) ** 2, 0)
    energy = 0.5 * LOSSLESS.m_b * (vy ** 2 + vz ** 2) + LOSSLESS.m_b * LOSSLESS.g * z + spring
    assert np.max(np.abs(energy / energy[0] - 1)) <= 1e-9
    assert stride.apex.z == pytest.approx(apex[2] - (stride.apex.vy ** 2 - apex[1] ** 2)
                                          / (2 * LOSSLESS.g), rel=1e-9)


def test_damping_dissipates_energy():
    apex = [0.0, 1.0, 0.35]
    lossless = sm.predict_stride(apex, -0.1, LOSSLESS.replace(k=6630.0), "SLIPD")
    lossy = sm.predict_stride(apex, -0.1, LOSSLESS.replace(k=6630.0, d=12.7), "SLIPD")
    energy = [s.apex.vy ** 2 / 2 + 9.99 * s.apex.z for s in (lossless, lossy)]
    assert energy[1] < energy[0] - 0.05


def test_cartesian_simulation_matches_polar_slipd():
    params = slip_data.spring_params("medium")
    apex, theta = _throws(3, params, seed=1, spread=0.1, method="AAS")
    pred = sm.predict_stride(apex, theta, params, "SLIPD")
    for i in range(3):
        _, events = slip_data.simulate_stride(apex[i], theta[i], params)
        for name, mine in zip(("touchdown", "bottom", "liftoff", "apex"), pred):
            np.testing.assert_allclose(events[name], [f[i] for f in mine], atol=1e-8)


def test_geyer_is_undamped_uncorrected_aas():
    apex, theta = _throws(20, LOSSLESS, seed=2, spread=0.1)
    y0, vy0, z0, th = sm._prepare(apex, theta, LOSSLESS)
    _, rhod0, p0, _ = sm._touchdown(y0, vy0, z0, th, LOSSLESS)
    geyer = sm._stance_geyer(rhod0, th, p0, LOSSLESS.kappa)
    aas = sm._stance_aas(rhod0, th, p0, LOSSLESS.kappa, 0.0, gravity_correction=False)
    np.testing.assert_allclose(aas.t_lo, geyer.t_lo, rtol=1e-12)
    np.testing.assert_allclose(aas.state(geyer.t_lo), geyer.state(geyer.t_lo), atol=1e-12)


def test_aas_exact_for_vertical_hops():
    params = slip_data.spring_params("soft")
    apex = np.column_stack([np.zeros(4), np.zeros(4), [0.25, 0.3, 0.4, 0.48]])
    aas = sm.predict_stride(apex, 0.0, params, "AAS")
    slipd = sm.predict_stride(apex, 0.0, params, "SLIPD")
    for a, b in zip(aas, slipd):
        np.testing.assert_allclose(a, b, atol=1e-9)


def test_aas_reduces_to_slip_without_damping():
    # thesis ref. [9]: AAS vs numerical SLIP about 0.75 % (position) and
    # 1.4 % (velocity); the gravity correction matters for asymmetric strides
    apex, theta = _throws(40, LOSSLESS, seed=4, spread=0.1)
    ref = sm.predict_stride(apex, theta, LOSSLESS, "SLIP")
    e_ap, e_av = _apex_errors(sm.predict_stride(apex, theta, LOSSLESS, "AAS"), ref)
    g_ap, g_av = _apex_errors(sm.predict_stride(apex, theta, LOSSLESS, "Geyer"), ref)
    assert e_ap < 1.5 and e_av < 4.0
    assert e_ap < g_ap and e_av < g_av


def test_neutral_angle_and_relative_angle_study():
    params = slip_data.spring_params("hard")
    apex, _ = _throws(30, params, seed=5, method="AAS", speed=(0.3, 1.5))
    neutral = sm.neutral_touchdown_angle(apex, params)
    vy1 = sm.predict_stride(apex, neutral, params).apex.vy
    np.testing.assert_allclose(vy1, apex[:, 1], atol=1e-6)
    delta = np.linspace(-0.1, 0.1, 30)
    data = slip_data.StrideSet("hard", neutral + delta, apex, None, None, [])
    errors = 1 + 2 * delta - 30 * delta ** 2
    study = sid.relative_angle_study(data, params, errors, bins=6)
    np.testing.assert_allclose(study["relative"], delta, atol=1e-6)
    assert study["count"].sum() == 30
    np.testing.assert_allclose(study["mean"][0], errors[:5].mean())
    # bin means of a quadratic follow a quadratic up to the in-bin spread
    np.testing.assert_allclose(study["quadratic"], [-30, 2, 1], rtol=0.1)


def test_processing_recovers_transitions():
    params = slip_data.spring_params("hard")
    apex, theta = np.array([0.0, 1.1, 0.38]), -0.12
    record = slip_data.record_stride(apex, theta, params, np.random.default_rng(0),
                                     slip_data.IDEAL)
    proc = slip_data.process_record(record, params.rho0)
    _, ev = slip_data.simulate_stride(apex, theta, params)
    assert abs(proc.apex0.t) < 1e-12 and abs(proc.apex0.z - 0.38) < 1e-5
    assert abs(proc.apex0.vy - 1.1) < 2e-3
    assert abs(proc.touchdown.t - ev["touchdown"].t) < 1e-3
    assert abs(proc.bottom.z - ev["bottom"].z) < 1e-4
    assert abs(proc.apex1.t - ev["apex"].t) < 1e-3
    assert abs(proc.apex1.z - ev["apex"].z) < 1e-4 and abs(proc.apex1.y - ev["apex"].y) < 1e-4
    assert 0 < proc.liftoff.t - ev["liftoff"].t < 0.01


def test_prediction_errors_definitions():
    params = slip_data.spring_params("hard")
    apex, theta = _throws(5, params, seed=6, method="AAS")
    pred = sm.predict_stride(apex, theta, params, "SLIPD")
    a1 = np.column_stack([pred.apex.t, pred.apex.y, pred.apex.z, pred.apex.vy])
    b = np.column_stack([pred.bottom.t, pred.bottom.y, pred.bottom.z])
    data = slip_data.StrideSet("hard", theta, apex, a1, b, [])
    np.testing.assert_allclose(sid.prediction_errors(data, params, "SLIPD"), 0, atol=1e-6)
    scaled = data._replace(apex1=a1 * 1.1, bottom=b * 1.1)
    err = sid.prediction_errors(scaled, params, "SLIPD")
    np.testing.assert_allclose(err, 100 * 0.1 / 1.1, rtol=1e-5)


def test_flight_damping_regression():
    rng = np.random.default_rng(7)
    sets = [slip_data.generate_strides("hard", 12, rng)]
    d_h, vy0 = sid.identify_flight_damping(sets)
    assert d_h == pytest.approx(0.3, rel=0.1)
    assert np.max(np.abs(vy0[0] - [s.apex0.vy for s in sets[0].strides])) < 0.02


def test_vertical_identification_recovers_masses():
    """Vertical hops (2.25) on clean measured data recover masses and legs.

    The leg mass (liftoff collision) and the vertical flight damping both
    take energy out of the ascent, so their estimates trade off and scatter
    by a few percent with 15 hops per spring; the fit is unbiased on
    clean data (stride-to-stride parameter variation and the boom mode,
    left out here, belong to the realism study of the gallery example).
    """
    rng = np.random.default_rng(8)
    hops = {s: slip_data.generate_strides(s, 15, rng, vertical=True,
                                          perturbations=slip_data.CLEAN)
            for s in ("soft", "hard")}
    est = sid.identify_vertical(hops, 3.4, slip_data.MONOPOD,
                                {"soft": 2915.0, "hard": 6282.0})
    assert est["m_l"] == pytest.approx(0.19, rel=0.06)
    assert est["d_v"] == pytest.approx(0.06, abs=0.015)
    for s in hops:
        k, d = est["springs"][s]
        assert k == pytest.approx(slip_data.SPRINGS[s][0], rel=0.01)
        assert d == pytest.approx(slip_data.SPRINGS[s][1], rel=0.03)


def _exact_set(spring, n, seed, params=None, method="SLIPD"):
    """Strides predicted by `method` with the true parameters: exact data."""
    params = slip_data.spring_params(spring) if params is None else params
    apex, theta = _throws(n, slip_data.spring_params(spring), seed, spread=0.12,
                          method="AAS")
    pred = sm.predict_stride(apex, theta, params, method)
    ok = np.isfinite(pred.apex.t) & (pred.apex.vy > 0.3)
    a1 = np.column_stack([pred.apex.t, pred.apex.y, pred.apex.z, pred.apex.vy])
    b = np.column_stack([pred.bottom.t, pred.bottom.y, pred.bottom.z])
    return slip_data.StrideSet(spring, theta[ok], apex[ok], a1[ok], b[ok], [])


def test_aas_liftoff_momentum():
    """AAS against SLIPD with the true parameters on damped, asymmetric strides.

    (2.20) averages a momentum that grows linearly from touchdown to
    liftoff, so the liftoff momentum is ``2 p_hat - p_td``; lifting off with
    it ("final") rather than with the average (literal reading) removes most
    of the apex velocity error.  What remains is in line with the AAS-SLIPD
    differences of thesis ref. [9] (0.75 % position, 1.4 % velocity).
    """
    data = _exact_set("hard", 40, 11)
    params = slip_data.spring_params("hard")
    final = sid.prediction_errors(data, params, "AAS").mean(axis=0)
    pred = sm.predict_stride(data.apex0, data.theta_td, params, "AAS",
                             liftoff_momentum="average")
    average = 100 * np.abs(pred.apex.vy - data.apex1[:, 3]) / data.apex1[:, 3]
    assert final[0] < 1.0 and final[1] < 1.5
    assert final[1] < 0.6 * average.mean()
    with pytest.raises(ValueError, match="liftoff_momentum"):
        sm.predict_stride(data.apex0, data.theta_td, params, "AAS", liftoff_momentum="mean")


@pytest.fixture(scope="module")
def hard_clean():
    return slip_data.generate_strides("hard", 30, np.random.default_rng(9),
                                      perturbations=slip_data.CLEAN)


def test_leg_identification_recovers_truth(hard_clean):
    """Leg fits on clean synthetic data with known k, d (hard spring).

    The data are sampled, quantised, filtered and differentiated like the
    robot's, but the robot is exactly the extended SLIP.  SLIPD, whose
    stance map is exact, must recover k and d within 2 %.  AAS cannot: its
    stance approximation (cos(theta) ~ 1 along the leg, linearised
    centrifugal term) leaves prediction errors of about 0.7 % in position
    and 1 % in velocity even with the true parameters, and the fit trades
    them against k and d.  The resulting bias is -1.5 to -4.5 % in k and
    -2 to -5 % in d for the hard spring, depending on the mix of strides,
    on exact data as well, and grows as the spring softens; the bounds
    below check that it stays this small.  The lossless
    numerical SLIP compensates the missing damping with a stiffer leg.
    """
    truth = slip_data.spring_params("hard")
    start = truth.replace(k=1.1 * truth.k, d=0.8 * truth.d)
    k, d, _ = sid.fit_leg(hard_clean, start, "SLIPD")
    assert k == pytest.approx(truth.k, rel=0.02) and d == pytest.approx(truth.d, rel=0.02)
    k_aas, d_aas, _ = sid.fit_leg(hard_clean, start, "AAS")
    assert k_aas == pytest.approx(truth.k, rel=0.05) and d_aas == pytest.approx(truth.d, rel=0.07)
    assert k_aas < k and d_aas < d
    k_slip, _, _ = sid.fit_leg(hard_clean, start, "SLIP")
    assert k_slip > 1.05 * truth.k


@pytest.mark.parametrize("spring", ["hard", "softer"])
def test_aas_bias_is_its_stance_approximation(spring):
    """The AAS leg bias comes from the AAS stance map, not from the fit.

    The same cost (2.33) and optimiser recover k and d to 0.01 % from exact
    transitions of AAS itself and of SLIPD (each fitted with its own map).
    Fitting AAS to exact SLIPD transitions over the thesis's range of
    throws (apex speed 0.3-2.5 m/s, height 0.24-0.48 m) moves k and d by
    several percent, more for the softer spring, whose leg compresses by up
    to a third (measured with these throws: -2.7 % / -5.9 % hard,
    -9.5 % / -18 % softer).  A 2 % recovery is within reach of SLIPD only.
    """
    truth = slip_data.spring_params(spring)
    start = truth.replace(k=1.1 * truth.k, d=0.8 * truth.d)
    exact = {method: _exact_set(spring, 30, 13, method=method) for method in ("AAS", "SLIPD")}
    for method, own in exact.items():
        k, d, cost = sid.fit_leg(own, start, method, max_nfev=100)
        assert k == pytest.approx(truth.k, rel=1e-4) and d == pytest.approx(truth.d, rel=1e-4)
        assert cost < 0.01
    k, d, cost = sid.fit_leg(exact["SLIPD"], start, "AAS", max_nfev=100)
    assert k < 0.98 * truth.k and d < 0.95 * truth.d and cost > 1.0


def test_lossless_fits_stiffen_with_leg_damping():
    """Leg damping in the data pushes the lossless fits to stiffer legs.

    A lossless leg returns all the stance energy, so with damped data it
    over-predicts the apex energy and the fit stiffens the leg.  For the
    numerical SLIP this gives k above the truth.  Geyer's approximation is
    biased soft on its own (about -10 % on exact lossless SLIP strides, from
    its small-angle, constant-momentum stance), so its damped fit stays
    below the truth here: the thesis's +75 % (Table 2.5) is not reproduced
    by this synthetic robot, only the direction of the damping effect.
    """
    params = slip_data.spring_params("hard")
    lossless = params.replace(d=0.0)
    damped, undamped = _exact_set("hard", 30, 12), _exact_set("hard", 30, 12, lossless)
    for method in ("SLIP", "Geyer"):
        k_damped, _, _ = sid.fit_leg(damped, params, method)
        k_lossless, _, _ = sid.fit_leg(undamped, lossless, method)
        assert k_damped > 1.02 * k_lossless
    assert k_lossless < 0.95 * params.k      # Geyer's own bias
    assert k_damped < params.k


def test_cross_validation_ordering():
    rng = np.random.default_rng(10)
    e_ap = {}
    for spring in ("hard", "softer"):
        data = slip_data.generate_strides(spring, 16, rng)
        params = slip_data.spring_params(spring)
        for method in sm.METHODS:
            res = sid.cross_validate(data, params, method, folds=3, fold_nfev=2)
            assert res.test.shape == (3, 3) and res.k.shape == (3,)
            assert np.isfinite(res.stride_test).mean() > 0.9
            e_ap[spring, method] = res.test[:, 0].mean()
    for spring in ("hard", "softer"):
        lossless = min(e_ap[spring, "SLIP"], e_ap[spring, "Geyer"])
        assert e_ap[spring, "SLIPD"] <= 1.25 * e_ap[spring, "AAS"]
        assert e_ap[spring, "AAS"] < 0.5 * lossless
    assert e_ap["softer", "AAS"] > e_ap["hard", "AAS"]
    table = sid.format_table([res])
    assert "softer" in table and "Geyer" in table


def test_input_validation():
    with pytest.raises(ValueError, match="method"):
        sm.predict_stride([0, 1, 0.3], -0.1, LOSSLESS, method="RK4")
    with pytest.raises(ValueError, match="k must be positive"):
        sm.SLIPParams(k=-1.0)
    with pytest.raises(ValueError, match="apex"):
        sm.predict_stride([0, 1], -0.1, LOSSLESS)
    with pytest.raises(ValueError, match="theta_td"):
        sm.predict_stride([0, 1, 0.3], 2.0, LOSSLESS)
    with pytest.raises(TypeError, match="params"):
        sm.predict_stride([0, 1, 0.3], -0.1, {"k": 1.0})
    with pytest.raises(ValueError, match="spring"):
        slip_data.spring_params("titanium")
    with pytest.raises(ValueError, match="folds"):
        sid.cross_validate(slip_data.StrideSet("hard", np.zeros(3), np.zeros((3, 3)),
                                               None, None, []), LOSSLESS, "AAS", folds=5)
    assert np.isnan(sm.predict_stride([0, 1, 0.1], -0.1, LOSSLESS).apex.t)
